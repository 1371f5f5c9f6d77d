#!/bin/bash
# Alternates two builds of one commit on the same 3-impact sample (32 per Dg, 45°, seed 3, one
# thread) and records each run's user CPU time and the md5 of its full JSON output.
# usage: run.sh OLD_BINARY NEW_BINARY PAIRS > times.tsv
set -euo pipefail
old=$1 new=$2 pairs=${3:-8}
tmp=$(mktemp -d)
printf 'pair\tbuild\tuser_s\twall_s\tmd5\n'
for i in $(seq 1 "$pairs"); do
  for b in old new; do
    bin=${!b}
    /usr/bin/time -f '%U %e' -o "$tmp/t" "$bin" sample --angle 45 --impacts 3 --seed 3 \
      --threads 1 --json -o "$tmp/out.json" > /dev/null
    read -r u w < "$tmp/t"
    printf '%s\t%s\t%s\t%s\t%s\n' "$i" "$b" "$u" "$w" "$(md5sum < "$tmp/out.json" | cut -c1-32)"
  done
done
rm -r "$tmp"
