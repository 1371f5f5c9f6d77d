#!/bin/bash
# Where the loss is made: `surface_profile --removed` on the kept checkpoints (each sample's
# in impact order; the campaigns' keepers' at multiples of 20 only), then where_lost.py.
# usage: where.sh SURFACE_PROFILE RUNS_DIR OUT_DIR   (RUNS_DIR holds box300/keep, layer/keep, ckpt-keep)
set -euo pipefail
bin=$1 runs=$2 out=$3
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
cd "$runs"
# c{cell}-{sample}-{impacts}.ckpt, sorted by cell, sample, impacts; keep multiples of 20
order() {
  for f in "$@"; do
    b=${f##*/c}; b=${b%.ckpt}; set -- ${b//-/ }
    [ $(($3 % 20)) -eq 0 ] && echo "$1 $2 $3 $f"
  done | sort -k1,1n -k2,2n -k3,3n | awk '{print $4}'
}
for run in box300/keep/std box300/keep/big layer/keep/l24 layer/keep/l32 ckpt-keep/paper ckpt-keep/ppd48; do
  name=${run##*/}
  "$bin" --removed $(order "$run"/*.ckpt) > "$out/$name.tsv"
done
for name in std big l24 l32; do echo "## $name"; python3 "$here/where_lost.py" "$out/$name.tsv" 40; done
echo "## l32, 80-impact blocks"; python3 "$here/where_lost.py" "$out/l32.tsv" 80
echo "## paper"; python3 "$here/where_lost.py" "$out/paper.tsv" 20 220
echo "## ppd48"; python3 "$here/where_lost.py" "$out/ppd48.tsv" 20 300
