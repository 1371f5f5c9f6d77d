#!/bin/bash
# Commits a finished campaign's results where the docs expect them (issue 40's deliverables):
#   finish.sh GRIT RUN_DIR RESULTS.json CHART_DIR
# e.g. finish.sh target/release/grit /work/runs/paper docs/erosion/paper-results.json docs/erosion/paper
# GRIT serves a copy of RUN_DIR's database read-only, refuses a campaign that is not done,
# writes its results (without per-impact series) to RESULTS.json, the PNG charts (with the
# damage-balance charts, from the series) into CHART_DIR, and `grit compare`'s tables into
# CHART_DIR/compare.md. The README and docs text is written by hand from these.
set -euo pipefail
grit=$1
run=$2
results=$3
charts=$4
tmp=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$tmp"' EXIT
port=8971
mkdir -p "$(dirname "$results")"
sqlite3 "file:$run/grit.db?mode=ro" ".backup '$tmp/grit.db'"
"$grit" serve --db "$tmp/grit.db" --listen 127.0.0.1:$port > "$tmp/serve.log" 2>&1 &
for _ in $(seq 50); do
  "$grit" status --coordinator http://127.0.0.1:$port > "$tmp/status" 2>/dev/null && break
  sleep 0.2
done
read -r id state _ < "$tmp/status"
if [ "$state" != "done" ]; then
  echo "finish.sh: campaign $id in $run is $state, not done" >&2
  exit 2
fi
"$grit" results "$id" -o "$results" --coordinator http://127.0.0.1:$port > /dev/null
"$grit" results "$id" --raw -o "$tmp/raw.json" --coordinator http://127.0.0.1:$port > /dev/null
"$grit" plot "$tmp/raw.json" --out "$tmp/charts" > "$tmp/plot.txt"
mkdir -p "$charts"
cp "$tmp"/charts/*.png "$charts/"
"$grit" compare "$results" > "$charts/compare.md"
echo "$results, $(ls "$charts"/*.png | wc -l) charts and $charts/compare.md written"
