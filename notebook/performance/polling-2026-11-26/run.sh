#!/bin/bash
# Three rounds of `grit bench impact --repeat 5 --json` and of the same on the surface after 30
# impacts (`--after 30 --repeat 3`), alternating the build before (`1f84742`) and the one whose
# runs keep the pool's other worker polling (`poll`, `grit_sph::polling`); expects
# both as /work/bins/grit-NAME. Medians:
#   python3 notebook/performance/medians.py notebook/performance/polling-2026-11-26 1f84742 poll
#   python3 notebook/performance/medians.py notebook/performance/polling-2026-11-26 after30-1f84742 after30-poll
for r in 1 2 3; do for b in 1f84742 poll; do
  /work/bins/grit-$b bench impact --repeat 5 --json > $b-$r.json
  /work/bins/grit-$b bench impact --after 30 --repeat 3 --json > after30-$b-$r.json
done; done
