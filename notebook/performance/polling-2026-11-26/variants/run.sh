#!/bin/bash
# Polling inside each step (`pollstep`) against polling through the whole run (`pollrun`, kept):
# three alternated rounds of `grit bench impact --repeat 5 --json`. Medians:
#   python3 notebook/performance/medians.py notebook/performance/polling-2026-11-26/variants pollstep pollrun
for r in 1 2 3; do for b in pollstep pollrun; do
  /work/bins/grit-$b bench impact --repeat 5 --json > $b-$r.json
done; done
