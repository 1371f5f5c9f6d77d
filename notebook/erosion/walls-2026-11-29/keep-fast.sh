#!/bin/bash
# Every minute, copies every campaign's checkpoints at multiples of 20 impacts (the keeper
# proper looks every 10 minutes, too rarely to catch them): the stock inside the box at each
# 20-impact window is what judges stationarity away from the box's fixed sides.
# The campaigns are campaigns.tsv's, read at each pass so that a new line joins without a restart.
list=$(cd "$(dirname "$0")/../../campaign-state" && pwd)/campaigns.tsv
while true; do
  while read -r c _ folder <&3; do
    [ -e /work/runs/$folder/grit.db ] || continue
    mkdir -p /work/runs/ckpt-keep/$c
    sqlite3 /work/runs/$folder/grit.db "select j.cell_index||'-'||j.sample_index, k.units_done, k.job_id from checkpoints k join jobs j on j.id = k.job_id where k.units_done % 20 = 0" 2>/dev/null |
    while IFS='|' read name n id; do
      f=/work/runs/ckpt-keep/$c/c$name-$n.ckpt
      [ -e "$f" ] || sqlite3 /work/runs/$folder/grit.db "select writefile('$f', data) from checkpoints where job_id=$id and units_done=$n" >/dev/null 2>&1
    done
  done 3< <(grep -v '^#' "$list")
  sleep 50
done
