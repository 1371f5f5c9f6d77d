#!/bin/bash
# Per-change table: each binary's `bench impact --json` (1 and 2 threads), alternated over ROUNDS rounds.
ROUNDS=${ROUNDS:-5}
OUT=/work/runs/bench-table
BINS="0-base 1-fold-rates 2-pair-quotients 3-volumes-once 4-ref-distance-flag 5-u32-pairs 6-same-body-lists 7-counting-sort 8-contact-bbox campaign s10-retry $EXTRA"
cd /tmp
for r in $(seq 1 $ROUNDS); do
  for b in $BINS; do
    /work/bins/grit-$b bench impact --json > $OUT/$b-r$r.json 2> $OUT/$b-r$r.err
    echo "$(date -u +%T) round $r $b rc=$?"
  done
done
