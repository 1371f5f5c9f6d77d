#!/bin/bash
# Three rounds of `grit bench impact --after 30 --repeat 3 --json` (the second reference scene:
# the surface after 30 impacts, where most particles carry plastic strain and heat), alternating
# the build before (`pow1`, fewer powers in the radial return) and the one that keeps each
# particle's zero-rate yield stress between steps (`memo`); expects both as /work/bins/grit-NAME.
# Medians: python3 notebook/performance/medians.py notebook/performance/memo-2026-11-25 pow1 memo
for r in 1 2 3; do for b in pow1 memo; do /work/bins/grit-$b bench impact --after 30 --repeat 3 --json > $b-$r.json; done; done
