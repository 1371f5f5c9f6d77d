#!/bin/bash
# Writes a campaign database as SQL text, for the repository: the machine that runs a long
# campaign may be replaced between sessions (2026-11-27 lost two, 2026-11-28 one), and git
# stores each later copy as a small delta of this text.
#   save.sh DB FILE.sql            the database without its checkpoints
#   save.sh DB FILE.sql --checkpoints
#                                  also FILE.checkpoints.db.xz: the checkpoints table alone
#                                  (xz keeps ~43 % of it; checkpoints differ in every float
#                                  from one save to the next, so each save is a new blob)
# Restore with restore.sh. Without checkpoints a job that was in flight or whose cell grows
# again is computed again from impact 0 (same bits); its stored impacts are kept.
set -euo pipefail
db=$1
out=$2
with_checkpoints=${3:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
sqlite3 "file:$db?mode=ro" "VACUUM INTO '$tmp/copy.db'"
if [ "$with_checkpoints" = "--checkpoints" ]; then
  ck=${out%.sql}.checkpoints.db
  sqlite3 "$tmp/copy.db" "ATTACH '$tmp/ck.db' AS k;
    CREATE TABLE k.checkpoints AS SELECT job_id, units_done, data, updated_ms, sha256 FROM checkpoints;"
  xz -9 -T1 -c "$tmp/ck.db" > "$ck.xz.tmp"
  mv "$ck.xz.tmp" "$ck.xz"
elif [ -n "$with_checkpoints" ]; then
  echo "save.sh: third argument must be --checkpoints (got $with_checkpoints)" >&2
  exit 2
fi
sqlite3 "$tmp/copy.db" "DELETE FROM checkpoints;"
sqlite3 "$tmp/copy.db" ".dump" > "$out.tmp"
mv "$out.tmp" "$out"
