#!/bin/bash
# Starts the long runs of issue 40 on the pinned binary in two lanes, one engine thread each,
# so that exactly one thread runs per core: a run starts when the one before it in its lane
# has finished. Run from the repository's root after restore.sh has put the folders back:
#   bash notebook/campaign-state/start.sh
# One thread per core rather than every run at once under autogroup weights: the same 3-impact
# sample costs 6-9 % more CPU time beside ten engine threads (or three) than two side by side
# (notebook/performance/oversubscribed-2026-12-01/). The lanes' order is the priority: the
# paired box runs first (their verdict decides whether the campaigns' box is wide enough);
# then lane a takes the 48 rung and after it the 16 rung, lane b the 24 rung (a few CPU-hours
# to its end) and after it the seed's campaign.
B=${B:-/work/bins/grit-9d98f72-native-pgo}
R=${R:-/work/runs}
run() { # name spec out [extra flags]
  local name=$1 spec=$2 out=$3; shift 3
  echo "$(date -u +%FT%TZ) start $name" >> "$R/lanes.log"
  nice -n 12 "$B" run "$spec" --out "$out" --workers 1 --threads 1 "$@" >> "$R/$name.log" 2>&1
  echo "$(date -u +%FT%TZ) end $name (exit $?)" >> "$R/lanes.log"
}
lane_a() {
  run box32big notebook/erosion/box32-420/big.json "$R/box32/big" --checkpoint-every 20
  run ppd48 examples/resolution48-steady.json "$R/ppd48"
  run ppd16c examples/resolution16-balanced.json "$R/ppd16c"
}
lane_b() {
  run box32std notebook/erosion/box32-420/std.json "$R/box32/std" --checkpoint-every 20
  run ppd24b examples/resolution24-balanced.json "$R/ppd24b"
  run paper examples/paper.json "$R/paper"
}
mkdir -p "$R/box32"
export -f run lane_a lane_b
export B R
setsid nohup bash -c lane_a > /dev/null 2>&1 &
setsid nohup bash -c lane_b > /dev/null 2>&1 &
setsid nohup bash notebook/erosion/box16-300/keep.sh "$R/box32" big std > "$R/keep-box32.log" 2>&1 &
setsid nohup nice -n 15 bash notebook/erosion/walls-2026-11-29/keep-fast.sh > "$R/keep-fast.log" 2>&1 &
echo "lanes started; see $R/lanes.log"
