#!/bin/bash
# Copies every checkpoint of the running campaigns out of their databases (the farm drops a
# job's checkpoint when its campaign finishes): grit study budget needs the surfaces.
while true; do
  for c in paper ppd48 ppd24b ppd16c; do
    mkdir -p /work/runs/ckpt-keep/$c
    sqlite3 /work/runs/$c/grit.db "select j.cell_index||'-'||j.sample_index||'-'||k.units_done, k.job_id from checkpoints k join jobs j on j.id = k.job_id" 2>/dev/null |
    while IFS='|' read name id; do
      f=/work/runs/ckpt-keep/$c/c$name.ckpt
      [ -e "$f" ] || sqlite3 /work/runs/$c/grit.db "select writefile('$f', data) from checkpoints where job_id=$id" >/dev/null 2>&1
    done
  done
  sleep 600
done
