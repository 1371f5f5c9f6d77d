#!/bin/bash
# surface_profile --walls and --across on every kept checkpoint of the four campaigns, then the
# paired growth per region and per strip over the intervals the kept checkpoints span.
# usage: run.sh SURFACE_PROFILE KEPT_DIR OUT_DIR
set -euo pipefail
bin=$1 kept=$2 out=$3
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
cd "$kept"
"$bin" --walls paper/*.ckpt ppd48/*.ckpt ppd24b/*.ckpt ppd16c/*.ckpt > "$out/walls.tsv"
"$bin" --across paper/*.ckpt ppd48/*.ckpt ppd24b/*.ckpt ppd16c/*.ckpt > "$out/across.tsv"
for args in "paper 5 220 240" "ppd48 0 300 320"; do
  python3 "$here/summarise.py" "$out/walls.tsv" $args
  python3 "$here/across.py" "$out/across.tsv" $args
done
python3 "$here/history.py" "$out/across.tsv" ppd24b 1 7
python3 "$here/history.py" "$out/across.tsv" ppd16c 1 0
