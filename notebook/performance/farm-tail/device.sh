#!/usr/bin/env bash
# The farm past two cores, for a session lent a 16-CPU machine (issue 36 part 3): what the
# CPUs are, and one campaign on 2, 8 and 16 one-thread workers, then 8 workers pinned one per
# physical core. Carry target/release/grit; run from the repository root; results under $OUT.
set -euo pipefail
out=${OUT:-/tmp/farm-tail}
mkdir -p "$out"
lscpu > "$out/lscpu.txt"
grit=$PWD/target/release/grit
spec=$out/spec.json
echo '{"name": "farm-tail", "seed": 7, "angles_deg": [45], "shapes": ["hexagon"], "samples": 32,
 "impacts": 24, "spacing_m": 1.6e-5, "distribution_range_dg": 1.0}' > "$spec"
timed() { # label, then the command
  local label=$1 t0 t1
  shift
  rm -rf "$out/run-$label"
  t0=$(date +%s%N)
  "$@" --out "$out/run-$label" --quiet > "$out/run-$label.log" 2>&1
  t1=$(date +%s%N)
  echo "$label $(( (t1 - t0) / 1000000 )) ms" | tee -a "$out/times.txt"
}
for w in 2 8 16; do
  timed "w$w" "$grit" run "$spec" --workers "$w" --threads 1
done
# One logical CPU per physical core: the first CPU lscpu lists for each (core, socket).
cores=$(lscpu -p=CPU,CORE,SOCKET | grep -v '^#' | sort -t, -k3,3n -k2,2n -u | cut -d, -f1 | paste -sd,)
echo "one CPU per core: $cores" | tee -a "$out/times.txt"
timed "w8-pinned" taskset -c "$cores" "$grit" run "$spec" --workers 8 --threads 1
