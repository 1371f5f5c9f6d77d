#!/bin/bash
# bits.sh BIN: the campaigns' fingerprints and 3-impact md5s, as restart.sh checks them
B=$1; tmp=$(mktemp -d)
$B version | grep -E "impact|jet"
for a in 45 90; do $B sample --angle $a --impacts 3 --seed 3 --threads 1 --json -o $tmp/s$a.json >/dev/null 2>&1; echo "$a: $(md5sum < $tmp/s$a.json | cut -c1-32)"; done
rm -rf $tmp
