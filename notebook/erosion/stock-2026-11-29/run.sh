#!/bin/bash
# Where each rung's damage stock sits, from the checkpoints the keeper copied out of the running
# campaigns (/work/runs/ckpt-keep, notebook/erosion/budget/keep.sh):
#   bash run.sh KEEP_DIR OUT_DIR
# needs `cargo build --release --example surface_profile -p grit-erosion` (commit of this folder
# or later). Cell c0 of paper is 15°, c2 45°, c5 90°; ppd48 and ppd24b: c0 45°, c1 90°.
set -euo pipefail
keep=$1
out=$2
sp=$(dirname "$0")/../../../target/release/examples/surface_profile
mkdir -p "$out"
one() { # name campaign cell impacts
  ls "$keep/$2"/c$3-*-$4.ckpt > /dev/null 2>&1 || return 0
  "$sp" --stock "$keep/$2"/c$3-*-$4.ckpt > "$out/$1-$4.tsv"
}
for n in 120 200 280; do one 48-45 ppd48 0 $n; done
for n in 120 200 280 360 420; do one 32-45 paper 2 $n; done
for n in 80 120 160 200; do one 32-90 paper 5 $n; done
for n in 360 380; do one 24-45 ppd24b 0 $n; done
for n in 360 400 440; do one 24-90 ppd24b 1 $n; done
python3 "$(dirname "$0")/summarise.py" "$out"/*.tsv
