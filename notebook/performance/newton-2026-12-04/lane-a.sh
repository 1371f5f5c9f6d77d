#!/bin/bash
# Lane a's share of the radial return's check: waits for process PID (the box run; 0: not at
# all), runs the old engine's 10 extra samples (check-old.json) with one worker and one thread
# at nice 12, then hands the lane to then.sh's campaigns (default ppd16c ppd48). Lane b runs
# check-new.json.
#   B_OLD=BINARY bash notebook/performance/newton-2026-12-04/lane-a.sh PID [NAME...]
R=${R:-/work/runs}
pid=$1; shift
# 0: at once (kill -0 0 would ask after this very process group, which is always there).
if [ "$pid" != 0 ]; then
  while kill -0 "$pid" 2>/dev/null; do sleep 30; done
fi
echo "$(date -u +%FT%TZ) lane-a.sh saw process $pid go; start newton-old --workers 1" >> "$R/lanes.log"
nice -n 12 "${B_OLD:?name the old build}" run notebook/performance/newton-2026-12-04/check-old.json \
  --out "$R/newton-old" --threads 1 --workers 1 >> "$R/newton-old.log" 2>&1
echo "$(date -u +%FT%TZ) end newton-old (exit $?, lane-a.sh)" >> "$R/lanes.log"
[ $# -gt 0 ] || set -- ppd16c ppd48
exec bash notebook/campaign-state/then.sh 0 "$@"
