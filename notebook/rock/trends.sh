#!/bin/sh
# Issue 37 part 5, the v_jet trend on the reduced scene: sandstone and granite at 313, 343 and
# 370 m/s, 0.04 kg/s, 0.05 ms in slices of 5 µs, Δx = 100 µm, seeds 1-3, one thread each.
# Usage: sh notebook/rock/trends.sh GRIT OUTDIR
G=${1:-grit}; OUT=${2:-notebook/rock/trends}
mkdir -p "$OUT"
for m in sandstone granite; do for v in 313 343 370; do for s in 1 2 3; do
  f="$OUT/$m-$v-s$s.json"
  [ -s "$f" ] || "$G" jet --material $m --velocity-m-s $v --mass-flow-kg-s 0.04 --time-ms 0.05 \
    --slice-ms 0.005 --spacing-m 1e-4 --seed $s --threads 1 --json -o "$f" > /dev/null
done; done; done
