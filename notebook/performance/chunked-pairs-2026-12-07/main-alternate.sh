#!/bin/bash
# Alternates two builds of main on `grit bench impact --threads 1 --json [EXTRA]`, PAIRS times,
# and appends to timesSUFFIX.tsv: round, build, user CPU of the whole command (with the
# untimed impacts of --after), then the timed impact's wall and its kernel-sum stage (s).
#   bash main-alternate.sh OLD NEW PAIRS "EXTRA" SUFFIX     (binaries' paths)
old=$1 new=$2 pairs=$3 extra=$4 suffix=$5
for i in $(seq 1 "$pairs"); do
  for b in "$old" "$new"; do
    /usr/bin/time -f "%U" -o t.txt "$b" bench impact --threads 1 --json $extra > o.json 2>/dev/null
    printf "%s\t%s\t%s\t%s\n" "$i" "$(basename "$b")" "$(cat t.txt)" \
      "$(python3 -c 'import json;d=json.load(open("o.json"));print(d["wall_s"], d["stages"]["kernel_sums"])')" \
      >> "times$suffix.tsv"
  done
done
