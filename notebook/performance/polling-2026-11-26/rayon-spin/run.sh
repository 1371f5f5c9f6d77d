#!/bin/bash
# Diagnostic, not kept: the build of 1f84742 (`head`) against the same source built on a copy of
# rayon-core 1.13.0 whose idle workers yield 4 000 000 rounds before sleeping instead of 32
# (`spin2`: src/sleep/mod.rs, ROUNDS_UNTIL_SLEEPY, through [patch.crates-io]), so every worker,
# the calling one included, spins through the whole run. Three alternated rounds of
# `grit bench impact --repeat 5 --json`. Medians:
#   python3 notebook/performance/medians.py notebook/performance/polling-2026-11-26/rayon-spin head spin2
for r in 1 2 3; do
  /work/bins/grit-1f84742 bench impact --repeat 5 --json > head-$r.json
  /work/bins/grit-spin2 bench impact --repeat 5 --json > spin2-$r.json
done
