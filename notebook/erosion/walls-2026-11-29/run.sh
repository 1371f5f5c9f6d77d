#!/bin/bash
# surface_profile --walls on every kept checkpoint of the four campaigns, then the paired
# growth per region over the intervals the kept checkpoints span.
# usage: run.sh SURFACE_PROFILE KEPT_DIR OUT_DIR
set -euo pipefail
bin=$1 kept=$2 out=$3
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
(cd "$kept" && "$bin" --walls paper/*.ckpt ppd48/*.ckpt ppd24b/*.ckpt ppd16c/*.ckpt) > "$out/walls.tsv"
python3 "$here/summarise.py" "$out/walls.tsv" paper 5 220 240
python3 "$here/summarise.py" "$out/walls.tsv" ppd48 0 300 320
