#!/bin/bash
# Copies the layer runs' checkpoints (every 20 impacts, --checkpoint-every 20) out of their
# databases before the next one replaces them; surface_profile --band-depth reads them.
while true; do
  for c in l24 l32; do
    d=/work/runs/layer/$c; mkdir -p /work/runs/layer/keep/$c
    sqlite3 "file:$d/grit.db?mode=ro" "select j.cell_index||'-'||j.sample_index, k.units_done, k.job_id from checkpoints k join jobs j on j.id = k.job_id" 2>/dev/null |
    while IFS='|' read name n id; do
      f=/work/runs/layer/keep/$c/c$name-$n.ckpt
      [ -e "$f" ] || sqlite3 "file:$d/grit.db?mode=ro" "select writefile('$f', data) from checkpoints where job_id=$id and units_done=$n" >/dev/null 2>&1
    done
  done
  sleep 10
done
