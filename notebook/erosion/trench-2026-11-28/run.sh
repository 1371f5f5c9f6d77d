#!/bin/bash
# Local incidence on the campaigns' worn surfaces. Usage: run.sh SURFACE_PROFILE KEPT PPD24B OUT
#   SURFACE_PROFILE: target/release/examples/surface_profile
#   KEPT: the keeper's folder (/work/runs/ckpt-keep: paper/ and ppd48/ checkpoints)
#   PPD24B: a folder of the ppd24b campaign's checkpoints, named like the keeper's
#   OUT: where incidence.tsv and columns.tsv go
set -euo pipefail
E=$(realpath "$1"); K=$2; P=$3; OUT=$4
mkdir -p "$OUT"
list() {
  (cd "$K" && for n in 5 10 80 160 240 300 360; do ls paper/c2-*-$n.ckpt; done; ls paper/c0-*-280.ckpt ppd48/c0-*-200.ckpt)
}
for mode in incidence columns; do
  { (cd "$K" && "$E" --$mode $(list)); (cd "$(dirname "$P")" && "$E" --$mode $(basename "$P")/*.ckpt | tail -n +2); } > "$OUT/$mode.tsv"
done
python3 "$(dirname "$0")/summarise.py" "$OUT/incidence.tsv" "$OUT/columns.tsv"
