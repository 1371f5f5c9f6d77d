#!/bin/bash
# surface_profile --band-depth on the kept checkpoints (the campaigns' keepers, the paired box
# run's and the layer runs'; the 16 rung's own are left out: box16-300's std run has its seed
# and box, and its checkpoints are the same bytes), then the skin and the stock below it pooled per cell over the
# windows of the table in docs/results.md, and the series every 20 impacts.
# usage: run.sh SURFACE_PROFILE RUNS_DIR OUT_DIR   (RUNS_DIR holds ckpt-keep/, box300/, layer/)
set -euo pipefail
bin=$1 runs=$2 out=$3
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
cd "$runs"
"$bin" --band-depth ckpt-keep/paper/*.ckpt ckpt-keep/ppd48/*.ckpt ckpt-keep/ppd24b/*.ckpt \
  box300/keep/std/*.ckpt layer/keep/*/*.ckpt > "$out/band-depth.tsv"
for w in "140 200" "240 300" "240 400"; do
  python3 "$here/summarise.py" "$out/band-depth.tsv" --pool $w
done
python3 "$here/summarise.py" "$out/band-depth.tsv" > "$out/series.md"
