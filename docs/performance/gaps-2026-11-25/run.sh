#!/bin/bash
# Three rounds of `grit bench impact --repeat 5 --json`, alternating the build before the
# serial stretches were taken out of the step (`slim`, commit f5ba175) and the build after
# (`gaps`); expects both as /work/bins/grit-NAME. Summarise: python3 ../slim-2026-11-25/summarise.py
# does the same medians for its own names; here `python3 summarise.py`.
for r in 1 2 3; do for b in slim gaps; do /work/bins/grit-$b bench impact --repeat 5 --json > $b-$r.json; done; done
