#!/bin/bash
# big's removed mass by strip for every pair of consecutive kept checkpoints (`surface_profile
# --removed`), written before the session's machine goes: the kept checkpoints are not saved
# with the run, and the next session's keeper starts from the checkpoints the save restores,
# so the files of successive sessions join into one table (drop repeated rows).
#   removed-so-far.sh KEEP_DIR OUT.tsv.xz     (KEEP_DIR: /work/runs/box32/keep/big)
# SP names the surface_profile example (`cargo build --release -p grit-erosion --example
# surface_profile`; the default is session 46's native build).
set -euo pipefail
keep=$1 out=$2
sp=${SP:-/work/target-native/release/examples/surface_profile}
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
for s in $(ls "$keep" | sed -E 's/^c[0-9]+-([0-9]+)-[0-9]+\.ckpt$/\1/' | sort -un); do
  files=$(ls "$keep" | grep -E "^c[0-9]+-$s-[0-9]+\.ckpt$" | sort -t- -k3 -n | sed "s|^|$keep/|")
  [ "$(echo "$files" | wc -l)" -ge 2 ] || continue   # one checkpoint: no pair yet
  "$sp" --removed $files | { [ -s "$tmp" ] && tail -n +2 || cat; } >> "$tmp"
done
xz -9 -c "$tmp" > "$out"
echo "$out: $(($(xz -dc "$out" | wc -l) - 1)) rows"
