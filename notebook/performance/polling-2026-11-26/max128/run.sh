#!/bin/bash
# With polling (dd7e38a) against the same with tasks of at most 128 particles instead of 256
# (`max128`: MAX_LEN in crates/grit-sph/src/stages/mod.rs; not kept). Three alternated rounds of
# `grit bench impact --repeat 5 --json`. Medians:
#   python3 notebook/performance/medians.py notebook/performance/polling-2026-11-26/max128 dd7e38a max128
for r in 1 2 3; do for b in dd7e38a max128; do
  /work/bins/grit-$b bench impact --repeat 5 --json > $b-$r.json
done; done
