#!/bin/bash
# Runs save-all.sh every SECONDS (default 3600) and, where the box runs' keeper has a folder,
# big's removed-mass table, so that the work tree holds a recent state of every run when a
# session ends without warning (a checkout of the next session may recover uncommitted files;
# committed saves are still made at each session's end).
#   bash notebook/campaign-state/save-every.sh [SECONDS] [SESSION]     (from the repository's root)
# SP names the surface_profile example, as for removed-so-far.sh.
every=${1:-3600} session=${2:-now}
here=$(cd "$(dirname "$0")" && pwd)
runs=${RUNS:-/work/runs}
while true; do
  sleep "$every"
  echo "$(date -u +%FT%TZ) save-every.sh: saving"
  bash "$here/save-all.sh" "$runs" || echo "$(date -u +%FT%TZ) save-every.sh: save-all.sh failed"
  if [ -d "$runs/box32/keep/big" ] && [ -n "${SP:-}" ]; then
    bash "$here/../erosion/box32-420/removed-so-far.sh" "$runs/box32/keep/big" \
      "$here/../erosion/box32-420/removed-big-$session.tsv.xz" || true
  fi
done
