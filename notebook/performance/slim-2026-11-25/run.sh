#!/bin/bash
# Three rounds of `grit bench impact --repeat 5 --json`, alternating the build before the 32-byte
# pair record (`head`, commit a70b2b6) and the build with it (`slim`); expects both as
# /work/bins/grit-NAME. Medians: python3 notebook/performance/medians.py notebook/performance/slim-2026-11-25 head slim
for r in 1 2 3; do for b in head slim; do /work/bins/grit-$b bench impact --repeat 5 --json > $b-$r.json; done; done
