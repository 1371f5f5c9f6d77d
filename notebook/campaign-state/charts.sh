#!/bin/bash
# Draws each running campaign's damage-balance charts from a copy of its database:
#   charts.sh GRIT OUT RUN_DIR…
# GRIT: a grit binary with the balance chart (commit fd9ed8b or later); it serves the copy
# read-only on a free local port, fetches the results with every sample's series and draws
# them; OUT/<campaign>/ gets the damage_balance_*.png charts. With RESULTS_DIR set, the
# campaign's results without the per-impact series are also written to RESULTS_DIR/<campaign>.json
# (the snapshots that docs/results.md quotes).
set -euo pipefail
grit=$1
out=$2
shift 2
tmp=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$tmp"' EXIT
port=8951
for run in "$@"; do
  name=$(basename "$run")
  sqlite3 "file:$run/grit.db?mode=ro" ".backup '$tmp/$name.db'"
  "$grit" serve --db "$tmp/$name.db" --listen 127.0.0.1:$port > "$tmp/$name.log" 2>&1 &
  pid=$!
  for _ in $(seq 50); do
    "$grit" status --coordinator http://127.0.0.1:$port > "$tmp/$name.status" 2>/dev/null && break
    sleep 0.2
  done
  id=$(awk 'NR == 1 {print $1}' "$tmp/$name.status")
  mkdir -p "$out/$name"
  "$grit" results "$id" --raw -o "$tmp/$name.json" --coordinator http://127.0.0.1:$port > /dev/null
  if [ -n "${RESULTS_DIR:-}" ]; then
    "$grit" results "$id" -o "$RESULTS_DIR/$name.json" --coordinator http://127.0.0.1:$port > /dev/null
  fi
  kill $pid
  "$grit" plot "$tmp/$name.json" --out "$tmp/charts-$name" > /dev/null
  cp "$tmp"/charts-$name/damage_balance_*.png "$out/$name/"
  port=$((port + 1))
done
