#!/bin/bash
# Writes a campaign database as SQL text without its checkpoints, for the repository: the
# machine that runs a long campaign may be replaced between sessions (2026-11-27 lost two),
# and git stores each later copy as a small delta of this text. Restore with
#   sqlite3 OUT_DIR/grit.db < FILE.sql
# and run the same `grit run SPEC --out OUT_DIR` command: finished jobs stay finished; a job
# that was in flight has no checkpoint, so its sample is computed again from impact 0 and its
# stored impacts are kept.
set -euo pipefail
db=$1
out=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
sqlite3 "file:$db?mode=ro" "VACUUM INTO '$tmp/copy.db'"
sqlite3 "$tmp/copy.db" "DELETE FROM checkpoints;"
sqlite3 "$tmp/copy.db" ".dump" > "$out.tmp"
mv "$out.tmp" "$out"
