#!/bin/bash
# Impacts 241-260 of the seed's campaign's 45° samples, resumed from the campaign's own
# checkpoints at 240 (c2-J-240.ckpt, kept by notebook/erosion/budget/keep.sh) with another
# binary, one thread each, in turn; compare.py then sets them against the campaign's records.
# usage: B=BINARY K=CHECKPOINT_DIR OUT=DIR bash resume45.sh
set -u
mkdir -p "$OUT"; cd "$OUT"
for i in $(seq 0 24); do
  [ -s s$i.json ] && continue
  /usr/bin/time -f "%U %S %e" -o s$i.time "$B" sample --resume "$K/c2-$i-240.ckpt" --impacts 260 --threads 1 --json -o s$i.json.tmp > /dev/null 2> s$i.err && mv s$i.json.tmp s$i.json
done
