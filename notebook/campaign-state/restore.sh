#!/bin/bash
# Rebuilds a campaign folder from save.sh's files:
#   restore.sh FILE.sql OUT_DIR
# writes OUT_DIR/grit.db from FILE.sql and, where FILE.checkpoints.db.xz exists beside it,
# puts its checkpoints back, so `grit run SPEC --out OUT_DIR` resumes each job from its state.
set -euo pipefail
sql=$1
dir=$2
[ -e "$dir/grit.db" ] && { echo "restore.sh: $dir/grit.db exists; not overwriting it" >&2; exit 2; }
mkdir -p "$dir"
sqlite3 "$dir/grit.db" < "$sql"
ck=${sql%.sql}.checkpoints.db.xz
if [ -e "$ck" ]; then
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  xz -dc "$ck" > "$tmp/ck.db"
  sqlite3 "$dir/grit.db" "ATTACH '$tmp/ck.db' AS k;
    INSERT INTO checkpoints (job_id, units_done, data, updated_ms, sha256)
      SELECT job_id, units_done, data, updated_ms, sha256 FROM k.checkpoints;"
fi
echo "$dir/grit.db: $(sqlite3 "$dir/grit.db" 'PRAGMA integrity_check') ;" \
  "$(sqlite3 "$dir/grit.db" 'SELECT count(*) FROM units') units," \
  "$(sqlite3 "$dir/grit.db" 'SELECT count(*) FROM checkpoints') checkpoints"
