#!/bin/bash
# Three rounds of `grit bench impact --repeat 5 --json`, alternating the build before
# (`head`, commit 6d9e351) and the one with fewer powers in the radial return (`pow1`);
# expects both as /work/bins/grit-NAME. Medians:
# python3 notebook/performance/medians.py notebook/performance/stress-2026-11-25 head pow1
for r in 1 2 3; do for b in head pow1; do /work/bins/grit-$b bench impact --repeat 5 --json > $b-$r.json; done; done
