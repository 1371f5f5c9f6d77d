#!/bin/bash
# The 48- and 32-per-Dg sweep rows (issue 36), one thread each, one after the other, same binary.
# usage: OUT=DIR [GRIT=BINARY] bash run.sh   (about 70 min of one core beside two campaigns)
G=$(realpath "${GRIT:-target/release/grit}")
OUT=${OUT:?set OUT to a folder}; mkdir -p "$OUT"; cd "$OUT"
for p in 48 32; do
  date -u +"start $p %H:%M:%S"
  /usr/bin/time -v $G bench sweep --angle 45 --ppd $p --variants default --samples 5 --impacts 70 --threads 1 --out "$OUT/ppd$p" > ppd$p.log 2>&1
  date -u +"end $p %H:%M:%S"
done
