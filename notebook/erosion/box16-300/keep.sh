#!/bin/bash
# Copies the paired box runs' checkpoints (every 20 impacts, --checkpoint-every 20) out of their
# databases before the next one replaces them; surface_profile --walls reads them.
while true; do
  for c in std big; do
    d=/work/runs/box300/$c; mkdir -p /work/runs/box300/keep/$c
    sqlite3 "file:$d/grit.db?mode=ro" "select j.cell_index||'-'||j.sample_index, k.units_done, k.job_id from checkpoints k join jobs j on j.id = k.job_id" 2>/dev/null |
    while IFS='|' read name n id; do
      f=/work/runs/box300/keep/$c/c$name-$n.ckpt
      [ -e "$f" ] || sqlite3 "file:$d/grit.db?mode=ro" "select writefile('$f', data) from checkpoints where job_id=$id and units_done=$n" >/dev/null 2>&1
    done
  done
  sleep 10
done
