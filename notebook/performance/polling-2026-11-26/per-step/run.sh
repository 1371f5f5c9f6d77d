#!/bin/bash
# Three rounds of `grit bench impact --repeat 5 --json` and of the same on the surface after 30
# impacts (`--after 30 --repeat 3`), alternating the build before (`1f84742`) and a first
# version that polled inside each `World::step` only (`pollstep`, not kept); expects both as
# /work/bins/grit-NAME. Medians:
#   python3 notebook/performance/medians.py notebook/performance/polling-2026-11-26/per-step 1f84742 pollstep
#   python3 notebook/performance/medians.py notebook/performance/polling-2026-11-26/per-step after30-1f84742 after30-pollstep
for r in 1 2 3; do for b in 1f84742 pollstep; do
  /work/bins/grit-$b bench impact --repeat 5 --json > $b-$r.json
  /work/bins/grit-$b bench impact --after 30 --repeat 3 --json > after30-$b-$r.json
done; done
