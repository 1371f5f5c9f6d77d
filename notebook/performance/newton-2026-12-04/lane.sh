#!/bin/bash
# Runs the new engine's half of the radial return's check (check-new.json, 7ee7c32) in lane b,
# one worker and one thread at nice 12 as the campaigns' lanes do, then hands the lane back to
# its campaigns; pairs.sh computes the old engine's half:
#   B_NEW=BINARY bash notebook/performance/newton-2026-12-04/lane.sh [NAME...]
# (from the repository's root; NAMEs as for then.sh, default ppd24b paper). Logs in $R.
R=${R:-/work/runs}
echo "$(date -u +%FT%TZ) start newton-new --workers 1 (newton lane.sh)" >> "$R/lanes.log"
nice -n 12 "${B_NEW:?name the new build}" run notebook/performance/newton-2026-12-04/check-new.json \
  --out "$R/newton-new" --threads 1 --workers 1 >> "$R/newton-new.log" 2>&1
echo "$(date -u +%FT%TZ) end newton-new (exit $?, newton lane.sh)" >> "$R/lanes.log"
[ $# -gt 0 ] || set -- ppd24b paper
exec bash notebook/campaign-state/then.sh 0 "$@"
