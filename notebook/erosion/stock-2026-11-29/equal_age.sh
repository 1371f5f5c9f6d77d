#!/bin/bash
# Loss and damage added of every rung over the same impacts (equal age), from the campaigns'
# databases (live, or restored with notebook/campaign-state/restore.sh):
#   bash equal_age.sh RUNS_DIR
# RUNS_DIR holds ppd16c/, ppd24b/, paper/ and ppd48/, each with its grit.db. Prints one line per
# rung, cell and window, in mg/g per impact (balance_interim.py).
set -euo pipefail
runs=$1
b=$(dirname "$0")/../balance_interim.py
for w in "41 80" "81 120" "121 160" "161 200" "201 280"; do
  read -r lo hi <<< "$w"
  for r in "ppd16c 0 16/45" "ppd24b 0 24/45" "paper 2 32/45" "ppd48 0 48/45" \
           "ppd16c 1 16/90" "ppd24b 1 24/90" "paper 5 32/90" "ppd48 1 48/90"; do
    read -r db cell tag <<< "$r"
    python3 "$b" "file:$runs/$db/grit.db?mode=ro" "$lo" "$hi" | grep "^cell $cell:" | sed "s|^|$tag |" || true
  done
done
