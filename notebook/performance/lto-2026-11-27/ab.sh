#!/bin/bash
# Alternates the plain and the LTO build, campaigns paused during each timed run.
for r in 1 2 3 4; do
  for b in c540121 lto-exp; do
    pkill -STOP -f "grit-c540121 run"; sleep 1
    s=$(date +%s.%N)
    /work/bins/grit-$b sample --angle 45 --impacts 4 --seed 3 --threads 1 --json -o /tmp/ab-$b.json > /dev/null 2>&1
    e=$(date +%s.%N)
    pkill -CONT -f "grit-c540121 run"
    echo "$r $b $(echo "$e - $s" | bc)"
    sleep 10
  done
done
