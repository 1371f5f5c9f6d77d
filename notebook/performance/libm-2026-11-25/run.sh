#!/bin/bash
# Three rounds of `grit bench impact --repeat 5 --json`, alternating the build that takes pow,
# exp, log, sin and cos from the system libm (`final`, commit 608f02f) and the one that takes
# them from the `libm` crate (`libm`); expects both as /work/bins/grit-NAME. Medians:
# python3 notebook/performance/medians.py notebook/performance/libm-2026-11-25 final libm
for r in 1 2 3; do for b in final libm; do /work/bins/grit-$b bench impact --repeat 5 --json > $b-$r.json; done; done
