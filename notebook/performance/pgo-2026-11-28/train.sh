#!/bin/bash
# Training runs for a profile-guided build of the campaigns' pinned commit: the impacts the
# campaigns run (one thread; worn surfaces at 32 and 48 per Dg from kept checkpoints, and a
# fresh surface at 45° and 90°), each with the instrumented binary, which writes raw profiles
# into the folder given at build time (-Cprofile-generate=DIR).
# usage: train.sh INSTRUMENTED_BINARY PAPER_CHECKPOINT PPD48_CHECKPOINT
set -euo pipefail
bin=$1 paper=$2 ppd48=$3
tmp=$(mktemp -d)
"$bin" sample --angle 45 --impacts 3 --seed 3 --threads 1 --json -o "$tmp/a.json" > /dev/null
"$bin" sample --angle 90 --impacts 3 --seed 3 --threads 1 --json -o "$tmp/b.json" > /dev/null
# --impacts is the total when resuming: two more impacts on each worn surface.
n=$(( $(basename "$paper" .ckpt | cut -d- -f3) + 2 ))
"$bin" sample --resume "$paper" --impacts "$n" --threads 1 --json -o "$tmp/c.json" > /dev/null
n=$(( $(basename "$ppd48" .ckpt | cut -d- -f3) + 1 ))
"$bin" sample --resume "$ppd48" --impacts "$n" --threads 1 --json -o "$tmp/d.json" > /dev/null
rm -r "$tmp"
