#!/bin/bash
# Runs the 25-sample check of the radial return in ln Δε (7ee7c32) in lane b, one worker and
# one thread at nice 12 as the campaigns' lanes do, then hands the lane back to its campaigns:
#   B_NEW=BINARY B_OLD=BINARY bash notebook/performance/newton-2026-12-04/lane.sh [NAME...]
# (from the repository's root; NAMEs as for then.sh, default ppd24b paper). Logs in $R.
R=${R:-/work/runs}
here=notebook/performance/newton-2026-12-04
check() { # name spec binary
  echo "$(date -u +%FT%TZ) start $1 --workers 1 (newton lane.sh)" >> "$R/lanes.log"
  nice -n 12 "$3" run "$2" --out "$R/$1" --threads 1 --workers 1 >> "$R/$1.log" 2>&1
  echo "$(date -u +%FT%TZ) end $1 (exit $?, newton lane.sh)" >> "$R/lanes.log"
}
check newton-new "$here/check-new.json" "${B_NEW:?name the new build}"
check newton-old "$here/check-old.json" "${B_OLD:?name the old build}"
[ $# -gt 0 ] || set -- ppd24b paper
exec bash notebook/campaign-state/then.sh 0 "$@"
