#!/bin/bash
# Copies the checkpoints of small runs with --checkpoint-every 20 out of their databases
# (DIR/NAME/grit.db) into DIR/keep/NAME before the next one replaces them; surface_profile reads
# them. Used for the paired box runs (keep.sh /work/runs/box300 std big) and the layer runs
# (keep.sh /work/runs/layer l24 l32).
# usage: keep.sh DIR NAME...
dir=$1; shift
while true; do
  for c in "$@"; do
    d=$dir/$c; mkdir -p "$dir/keep/$c"
    sqlite3 "file:$d/grit.db?mode=ro" "select j.cell_index||'-'||j.sample_index, k.units_done, k.job_id from checkpoints k join jobs j on j.id = k.job_id" 2>/dev/null |
    while IFS='|' read name n id; do
      f=$dir/keep/$c/c$name-$n.ckpt
      [ -e "$f" ] || sqlite3 "file:$d/grit.db?mode=ro" "select writefile('$f', data) from checkpoints where job_id=$id and units_done=$n" >/dev/null 2>&1
    done
  done
  sleep 10
done
