#!/bin/bash
# Three rounds of `grit bench impact --repeat 5 --json`, alternating the build with the pair
# record in double precision (`head`, commit 6d9e351) and one that stores it in single
# precision (`f32a`: x_ij, W and dW/dr / r as f32, 16 bytes, widened to f64 where read; not
# kept); expects both as /work/bins/grit-NAME. Medians:
# python3 notebook/performance/medians.py notebook/performance/f32-2026-11-25 head f32a
for r in 1 2 3; do for b in head f32a; do /work/bins/grit-$b bench impact --repeat 5 --json > $b-$r.json; done; done
