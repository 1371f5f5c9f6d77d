#!/bin/bash
# Prints what makes a binary the campaigns' own: its engine fingerprints and the md5s of the
# 45° and 90° 3-impact samples (seed 3, one thread). restart.sh compares them with the
# campaigns'; a new build is checked the same way.
#   bash notebook/campaign-state/bits.sh BIN
set -euo pipefail
B=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$B" version | grep -E "^(impact|jet) engine"
for a in 45 90; do
  "$B" sample --angle "$a" --impacts 3 --seed 3 --threads 1 --json -o "$tmp/s$a.json" > /dev/null 2>&1
  echo "$a: $(md5sum < "$tmp/s$a.json" | cut -c1-32)"
done
