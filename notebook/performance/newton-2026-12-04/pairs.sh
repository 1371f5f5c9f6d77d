#!/bin/bash
# The old engine's half of the paired check: samples 15-24 of check-new.json's two cells with
# the campaigns' binary, each job's own parameters and seed (read from the new run's database),
# by `grit sample --scene CELL.json --seed SEED` (the farm's job, bit for bit: checked on sample
# 0 against ppd16c's first 5 impacts); samples 0-14 are ppd16c's (the same seeds). One thread at
# nice 12; a sample whose file is there is skipped, so a rerun goes on. Then lane a's campaigns.
#   B_OLD=BINARY bash notebook/performance/newton-2026-12-04/pairs.sh [NAME...]
R=${R:-/work/runs}
db=$R/newton-new/grit.db
out=$R/newton-pairs
mkdir -p "$out"
echo "$(date -u +%FT%TZ) start newton-pairs (pairs.sh)" >> "$R/lanes.log"
for cell in 0 1; do
  sqlite3 "file:$db?mode=ro" "select params from cells where cell_index=$cell" > "$out/cell$cell.json"
  for s in $(seq 15 24); do
    f=$out/old-c$cell-s$s.json
    [ -s "$f" ] && continue
    seed=$(sqlite3 "file:$db?mode=ro" "select seed from jobs where cell_index=$cell and sample_index=$s")
    seed=$(python3 -c "print($seed % 2**64)")
    nice -n 12 "${B_OLD:?name the old build}" sample --scene "$out/cell$cell.json" --seed "$seed" \
      --impacts 200 --threads 1 --json -o "$f.part" > /dev/null 2>> "$R/newton-pairs.log" \
      && mv "$f.part" "$f"
  done
done
echo "$(date -u +%FT%TZ) end newton-pairs (pairs.sh)" >> "$R/lanes.log"
[ $# -gt 0 ] || set -- ppd16c ppd48
exec bash notebook/campaign-state/then.sh 0 "$@"
