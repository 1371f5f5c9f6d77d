#!/bin/bash
# Idle-machine figures of issue 36: the default builds of a7975ea (new) and 108ab49 (old, before
# the one-thread scatter and the inlined pair terms), alternated.
OLD=/work/bins/grit-108ab49 NEW=/work/bins/grit-a7975ea
cd /work/idle
for r in 1 2 3 4 5; do
  for b in old new; do
    G=$OLD; [ $b = new ] && G=$NEW
    $G bench impact --repeat 1 --json > impact-$b-$r.json 2> impact-$b-$r.err
  done
done
for r in 1 2 3; do
  for b in old new; do
    G=$OLD; [ $b = new ] && G=$NEW
    /usr/bin/time -f "$b $r %U %e" -a -o times45.txt $G sample --angle 45 --impacts 3 --seed 3 --threads 1 --json -o s45-$b.json > /dev/null 2>&1
  done
done
md5sum s45-*.json
