#!/bin/bash
# The loss over the 80 impacts after the stock under the aim band stops growing, against the
# loss where the whole-surface balance comes (or the latest window where it has not yet), read
# from the campaigns' databases. The band-flat ages come from the stock series in
# ../layer-2026-11-29/series.md and ../stock-2026-11-29/ (see README.md).
# usage: run.sh RUNS_DIR   (RUNS_DIR holds ppd16c/, ppd24b/, paper/, ppd48/, long16/)
set -euo pipefail
runs=$1
p=$(cd "$(dirname "$0")/.." && pwd)/balance_interim.py
w() { echo "## $1 $2-$3"; python3 "$p" "file:$runs/$1/grit.db?mode=ro" "$2" "$3"; }
w ppd16c 141 220; w ppd16c 161 240
w ppd24b 61 140; w ppd24b 221 300; w ppd24b 321 380; w ppd24b 381 440
w paper 61 140; w paper 101 180; w paper 161 240; w paper 241 280; w paper 361 420
w ppd48 101 180; w ppd48 261 320
if [ -f "$runs/long16/grit.db" ]; then w long16 561 800; fi
