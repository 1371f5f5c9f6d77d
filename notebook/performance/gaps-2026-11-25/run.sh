#!/bin/bash
# Three rounds of `grit bench impact --repeat 5 --json`, alternating the build before the
# serial stretches were taken out of the step (`slim`, commit f5ba175) and the build after
# (`gaps`); expects both as /work/bins/grit-NAME. Medians:
# python3 notebook/performance/medians.py notebook/performance/gaps-2026-11-25 slim gaps
for r in 1 2 3; do for b in slim gaps; do /work/bins/grit-$b bench impact --repeat 5 --json > $b-$r.json; done; done
