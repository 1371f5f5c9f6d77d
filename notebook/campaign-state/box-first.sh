#!/bin/bash
# Replaces start.sh's lanes once they run (session 45): the paired box runs decide whether the
# campaigns' box is wide enough, and big is their long pole (3 samples, one worker in lane a,
# about 12 h of a core on this machine against 1.7 h for std). When std ends, big is stopped
# with SIGINT (its worker releases each job with a checkpoint) and restarted with two workers,
# one thread each, so the pair ends in about half the time; after it, the lanes' other runs go
# on in start.sh's order.
#   bash notebook/campaign-state/box-first.sh STD_PID BIG_PID     (from the repository's root)
# Kill start.sh's two lane shells first (their grit children go on), or they start the next run.
STD=$1 BIG=$2
B=${B:-/work/bins/grit-9d98f72-native-pgo}
R=${R:-/work/runs}
while kill -0 "$STD" 2>/dev/null; do sleep 30; done
echo "$(date -u +%FT%TZ) end box32std (box-first.sh saw its process go)" >> "$R/lanes.log"
kill -INT "$BIG" 2>/dev/null
while kill -0 "$BIG" 2>/dev/null; do sleep 5; done
echo "$(date -u +%FT%TZ) box32big stopped; restarted with two workers" >> "$R/lanes.log"
run() { # name spec out [extra flags]
  local name=$1 spec=$2 out=$3; shift 3
  echo "$(date -u +%FT%TZ) start $name $*" >> "$R/lanes.log"
  nice -n 12 "$B" run "$spec" --out "$out" --threads 1 "$@" >> "$R/$name.log" 2>&1
  echo "$(date -u +%FT%TZ) end $name (exit $?)" >> "$R/lanes.log"
}
run box32big notebook/erosion/box32-420/big.json "$R/box32/big" --workers 2 --checkpoint-every 20
(run ppd48 examples/resolution48-steady.json "$R/ppd48" --workers 1
 run ppd16c examples/resolution16-balanced.json "$R/ppd16c" --workers 1) &
(run ppd24b examples/resolution24-balanced.json "$R/ppd24b" --workers 1
 run paper examples/paper.json "$R/paper" --workers 1) &
wait
