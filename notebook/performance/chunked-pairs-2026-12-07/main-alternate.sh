#!/bin/bash
# alternated one-thread reference impacts: old (f935deb) and chunked pairs
for i in $(seq 1 $1); do
  for b in grit-f935deb grit-f935deb-chunk; do
    /usr/bin/time -f "%U" -o t.txt /work/bins/$b bench impact --threads 1 --json $2 > o.json 2>/dev/null
    printf "%s\t%s\t%s\t%s\t%s\n" "$i" "$b" "$(cat t.txt)" "$(python3 -c 'import json;d=json.load(open("o.json"));print(d["wall_s"], d["stages"]["kernel_sums"])')" >> times$3.tsv
  done
done
