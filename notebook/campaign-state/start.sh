#!/bin/bash
# Starts every long run of issue 40 on the pinned binary, each in its own autogroup with its
# CPU weight (nice has no effect between setsid processes: campaigns.md, session 35), and the
# checkpoint keepers. Run from the repository's root after restore.sh has put the folders back:
#   bash notebook/campaign-state/start.sh
# Weights (session 44): the paired box runs first, since their verdict decides whether the
# campaigns' 3.0-Dg box is wide enough; then the seed's campaign and the 48 rung; the 24 and 16
# rungs last.
B=${B:-/work/bins/grit-9d98f72-native-pgo}
R=${R:-/work/runs}
start() { # name autogroup workers spec out [extra flags]
  local name=$1 ag=$2 w=$3 spec=$4 out=$5; shift 5
  setsid nohup nice -n 12 "$B" run "$spec" --out "$out" --workers "$w" --threads 1 "$@" \
    >> "$R/$name.log" 2>&1 &
  local pid=$!
  sleep 1
  echo "$ag" > /proc/$pid/autogroup
  echo "$name: pid $pid, $(cat /proc/$pid/autogroup)"
}
mkdir -p "$R/box32"
start box32big -10 3 notebook/erosion/box32-420/big.json "$R/box32/big" --checkpoint-every 20
start box32std -5 1 notebook/erosion/box32-420/std.json "$R/box32/std" --checkpoint-every 20
start paper 0 1 examples/paper.json "$R/paper"
start ppd48 0 1 examples/resolution48-steady.json "$R/ppd48"
start ppd24b 8 1 examples/resolution24-balanced.json "$R/ppd24b"
start ppd16c 8 1 examples/resolution16-balanced.json "$R/ppd16c"
setsid nohup bash notebook/erosion/box16-300/keep.sh "$R/box32" big std > "$R/keep-box32.log" 2>&1 &
setsid nohup nice -n 15 bash notebook/erosion/walls-2026-11-29/keep-fast.sh > "$R/keep-fast.log" 2>&1 &
