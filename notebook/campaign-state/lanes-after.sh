#!/bin/bash
# Runs the lanes of box-first.sh once the box pair's long run (PID) has ended, for a session
# that restarted big by hand on a fresh machine (session 46): two lanes, one worker and one
# thread each, in box-first.sh's order.
#   bash notebook/campaign-state/lanes-after.sh BIG_PID     (from the repository's root)
BIG=$1
B=${B:-/work/bins/grit-9d98f72-native-pgo}
R=${R:-/work/runs}
while kill -0 "$BIG" 2>/dev/null; do sleep 30; done
echo "$(date -u +%FT%TZ) end box32big (lanes-after.sh saw its process go)" >> "$R/lanes.log"
run() { # name spec out [extra flags]
  local name=$1 spec=$2 out=$3; shift 3
  echo "$(date -u +%FT%TZ) start $name $*" >> "$R/lanes.log"
  nice -n 12 "$B" run "$spec" --out "$out" --threads 1 "$@" >> "$R/$name.log" 2>&1
  echo "$(date -u +%FT%TZ) end $name (exit $?)" >> "$R/lanes.log"
}
(run ppd48 examples/resolution48-steady.json "$R/ppd48" --workers 1
 run ppd16c examples/resolution16-balanced.json "$R/ppd16c" --workers 1) &
(run ppd24b examples/resolution24-balanced.json "$R/ppd24b" --workers 1
 run paper examples/paper.json "$R/paper" --workers 1) &
wait
