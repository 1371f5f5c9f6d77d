#!/usr/bin/env bash
# The farm past two cores, for a session lent a 16-CPU machine (issue 36 part 3). Separates
# the candidate causes of the 74 % at 16 workers:
#  1. the machine: K identical one-sample campaigns run side by side as separate processes
#     (no shared coordinator, no tail), K = 1, 8 pinned one per physical core, 8 unpinned, 16;
#     each copy's wall time against K = 1 is the contention (hyper-threads, memory, clocks);
#  2. the farm: one 32-sample campaign on 16, 8 (unpinned and pinned) and 2 one-thread workers;
#     its database keeps each report's time, for the idle time of each worker.
# Carry the grit binary as $GRIT (default target/device/grit); results under $OUT.
set -euo pipefail
out=${OUT:-/tmp/farm-tail}
grit=${GRIT:-$PWD/target/device/grit}
impacts=${IMPACTS:-24}
# IMPACTS below 21 is a smoke test of this script: the spec then allows short samples.
short=$([[ $impacts -lt 21 ]] && echo ', "allow_short_samples": true' || true)
mkdir -p "$out"
lscpu > "$out/lscpu.txt"
lscpu -p=CPU,CORE,SOCKET,NODE > "$out/lscpu-p.txt"
nproc > "$out/nproc.txt"
"$grit" version > "$out/version.txt"
mhz() { awk '/MHz/ {s += $4; n++} END {printf "%.0f", s / n}' /proc/cpuinfo; }
spec() { # samples, file
  echo "{\"name\": \"farm-tail\", \"seed\": 7, \"angles_deg\": [45], \"shapes\": [\"hexagon\"],
 \"samples\": $1, \"impacts\": $impacts, \"spacing_m\": 1.6e-5, \"distribution_range_dg\": 1.0$short}" > "$2"
}
spec 1 "$out/one.json"
spec 32 "$out/spec.json"
ms() { echo $(( $(date +%s%N) / 1000000 )); }
# One logical CPU per physical core: the first CPU lscpu lists for each (core, socket).
cores=$(grep -v '^#' "$out/lscpu-p.txt" | sort -t, -k3,3n -k2,2n -u | cut -d, -f1 | paste -sd,)
echo "one CPU per core: $cores" | tee -a "$out/times.txt"
IFS=, read -ra core_list <<< "$cores"

side_by_side() { # label, K, pin (yes/no)
  local label=$1 k=$2 pin=$3 i pids=() t0
  t0=$(ms)
  for ((i = 0; i < k; i++)); do
    local cmd=("$grit" run "$out/one.json" --workers 1 --threads 1 --out "$out/sbs-$label-$i" --quiet)
    if [[ $pin == yes ]]; then cmd=(taskset -c "${core_list[$((i % ${#core_list[@]}))]}" "${cmd[@]}"); fi
    ( s=$(ms); "${cmd[@]}" > "$out/sbs-$label-$i.log" 2>&1; echo "$label copy $i $(( $(ms) - s )) ms" >> "$out/sbs.txt" ) &
    pids+=($!)
  done
  sleep 2; echo "$label clock during: $(mhz) MHz" >> "$out/sbs.txt"
  wait "${pids[@]}"
  echo "$label all $(( $(ms) - t0 )) ms" | tee -a "$out/sbs.txt"
}
echo "idle clock: $(mhz) MHz" >> "$out/sbs.txt"
side_by_side k1 1 no
side_by_side k8pinned 8 yes
side_by_side k8 8 no
side_by_side k16 16 no

timed() { # label, then the command
  local label=$1 t0
  shift
  rm -rf "$out/run-$label"
  t0=$(ms)
  "$@" --out "$out/run-$label" --quiet > "$out/run-$label.log" 2>&1
  echo "$label $(( $(ms) - t0 )) ms" | tee -a "$out/times.txt"
}
timed w16 "$grit" run "$out/spec.json" --workers 16 --threads 1
timed w8 "$grit" run "$out/spec.json" --workers 8 --threads 1
timed w8-pinned taskset -c "$cores" "$grit" run "$out/spec.json" --workers 8 --threads 1
timed w2 "$grit" run "$out/spec.json" --workers 2 --threads 1
# Only the databases come back: the checkpoints are large and not needed.
find "$out" \( -name checkpoints -type d -prune -o -name "*.svg" -o -name "*.png" \) -exec rm -rf {} +
