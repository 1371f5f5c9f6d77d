#!/bin/bash
# Alternates two builds on one `grit sample` command and records each run's user CPU time and
# the md5 of its JSON output (-o), so a speed ratio comes with a bits check.
# usage: pairs.sh OLD_BINARY NEW_BINARY PAIRS SAMPLE_ARGS... > times.tsv
set -euo pipefail
old=$1 new=$2 pairs=$3
shift 3
tmp=$(mktemp -d)
printf 'pair\tbuild\tuser_s\twall_s\tmd5\n'
for i in $(seq 1 "$pairs"); do
  for b in old new; do
    bin=${!b}
    /usr/bin/time -f '%U %e' -o "$tmp/t" "$bin" sample "$@" --threads 1 --json \
      -o "$tmp/out.json" > /dev/null
    read -r u w < "$tmp/t"
    printf '%s\t%s\t%s\t%s\t%s\n' "$i" "$b" "$u" "$w" "$(md5sum < "$tmp/out.json" | cut -c1-32)"
  done
done
rm -r "$tmp"
