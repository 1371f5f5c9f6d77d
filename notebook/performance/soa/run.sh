#!/bin/sh
# Alternates the binaries named on the command line (paths under /work/bins) in ROUNDS rounds of
# `grit bench impact --threads 1 --repeat 3 --json`, one JSON per binary and round, into OUT.
# Usage: OUT=dir ROUNDS=3 run.sh grit-soa-base grit-soa-A ...
set -e
: "${OUT:?}" "${ROUNDS:=3}"
mkdir -p "$OUT"
for r in $(seq 1 "$ROUNDS"); do
  for b in "$@"; do
    /work/bins/$b bench impact --threads 1 --repeat 3 --json > "$OUT/$b-$r.json" 2>/dev/null
    python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(sys.argv[2], sys.argv[3], round(d['wall_1_thread_s'],4), round(d['particle_steps_per_s_per_thread']/1e6,3), round(d['ceiling']['full_step_over_ceiling'],2), round(d['stages_1_thread'].get('kernel_sums',0),3), round(d['stages_1_thread'].get('forces',0),3))" "$OUT/$b-$r.json" "$b" "$r"
  done
done
