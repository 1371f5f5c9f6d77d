#!/bin/bash
# Saves every long run's database (campaigns.tsv) with its checkpoints into this folder (save.sh), then
# restores each save into a scratch folder (restore.sh) and checks it: integrity, at least the
# units the live database held just before the save (the runs go on writing), and every
# checkpoint's SHA-256 against its data.
#   bash notebook/campaign-state/save-all.sh [RUNS_DIR]
# A save without checkpoints costs a replay from impact 0 of every sample in flight when the
# machine is replaced (2.8 CPU-hours for the 24 rung's 90° cell in session 41), so all go with them.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
runs=${1:-/work/runs}
scratch=$(mktemp -d)
failed=0
trap 'rm -rf "$scratch"' EXIT
while read -r name _ folder <&3; do
  db=$runs/$folder/grit.db
  [ -e "$db" ] || { echo "$name: no $db, skipped"; continue; }
  live=$(sqlite3 "file:$db?mode=ro" "select count(*) from units")
  bash "$here/save.sh" "$db" "$here/$name.sql" --checkpoints
  bash "$here/restore.sh" "$here/$name.sql" "$scratch/$name" > /dev/null
  if python3 - "$scratch/$name/grit.db" "$name" "$live" <<'PY'
import hashlib, sqlite3, sys
db, name, live = sys.argv[1:]
c = sqlite3.connect(db)
ok = c.execute("pragma integrity_check").fetchone()[0]
units = c.execute("select count(*) from units").fetchone()[0]
ck = c.execute("select data, sha256 from checkpoints").fetchall()
bad = sum(hashlib.sha256(d).hexdigest() != s for d, s in ck)
verdict = "ok" if ok == "ok" and bad == 0 and units >= int(live) else "MISMATCH"
print(f"{name}: {verdict}; {units} units (live before the save: {live}), {len(ck)} checkpoints,"
      f" integrity {ok}, {bad} bad checkpoint hashes")
sys.exit(0 if verdict == "ok" else 1)
PY
  then :; else failed=1; fi
done 3< <(grep -v '^#' "$here/campaigns.tsv")
exit $failed
