#!/bin/bash
# Runs the lanes of box-first.sh once the box pair's long run (PID) has ended, for a session
# that restarted big by hand on a fresh machine (session 46): two lanes, one worker and one
# thread each, in box-first.sh's order.
#   bash notebook/campaign-state/lanes-after.sh BIG_PID [b-now|b-last]   (from the repository's root)
# With b-now, lane b starts at once and only lane a waits for big: for when big is down to its
# last job and leaves a core idle (its two workers hold one job each, and big's last sample is
# the long one). With b-last, lane b starts once big's database has one unfinished job left.
BIG=$1
B=${B:-/work/bins/grit-9d98f72-native-pgo}
R=${R:-/work/runs}
wait_big() {
  while kill -0 "$BIG" 2>/dev/null; do sleep 30; done
  echo "$(date -u +%FT%TZ) end box32big (lanes-after.sh saw its process go)" >> "$R/lanes.log"
}
run() { # name spec out [extra flags]
  local name=$1 spec=$2 out=$3; shift 3
  echo "$(date -u +%FT%TZ) start $name $*" >> "$R/lanes.log"
  nice -n 12 "$B" run "$spec" --out "$out" --threads 1 "$@" >> "$R/$name.log" 2>&1
  echo "$(date -u +%FT%TZ) end $name (exit $?)" >> "$R/lanes.log"
}
last_job() {
  while [ "$(sqlite3 "file:$R/box32/big/grit.db?mode=ro" \
      "select count(*) from jobs where state in ('queued', 'leased')")" -gt 1 ]; do
    kill -0 "$BIG" 2>/dev/null || return 0
    sleep 60
  done
  echo "$(date -u +%FT%TZ) box32big down to its last job (lanes-after.sh b-last)" >> "$R/lanes.log"
}
case "${2:-}" in
  b-now) ;;
  b-last) last_job ;;
  '') wait_big ;;
  *) echo "lanes-after.sh: unknown mode '$2' (b-now, b-last or none)" >&2; exit 2 ;;
esac
(if [ -n "${2:-}" ]; then wait_big; fi
 run ppd48 examples/resolution48-steady.json "$R/ppd48" --workers 1
 run ppd16c examples/resolution16-balanced.json "$R/ppd16c" --workers 1) &
(run ppd24b examples/resolution24-balanced.json "$R/ppd24b" --workers 1
 run paper examples/paper.json "$R/paper" --workers 1) &
wait
