#!/bin/bash
# Issue 36's figures in one sitting on today's engine (the default build of 370e2dd), the
# campaigns' lanes held at autogroup nice 19 (about 1.5 % of a core): the reference impact
# (fresh surface, 1 and 2 threads, with its ceiling), one impact on a surface worn by 150
# impacts, the 3-impact sample and the 32-per-Dg sweep row on one thread.
#   G=/work/bins/grit-370e2dd W=/work/idle bash bench.sh
set -u
mkdir -p "$W"; cd "$W"
for r in 1 2 3; do
  "$G" bench impact --repeat 1 --json > impact-$r.json 2> impact-$r.err
done
"$G" bench impact --after 150 --threads 1 --repeat 2 --json > worn.json 2> worn.err
for r in 1 2 3; do
  /usr/bin/time -f "$r %U %e" -a -o times45.txt "$G" sample --angle 45 --impacts 3 --seed 3 --threads 1 --json -o s45.json > /dev/null 2>&1
done
md5sum s45.json > md5.txt
rm -rf sweep32
/usr/bin/time -f "sweep %U %e" -o times-sweep.txt "$G" bench sweep --angle 45 --ppd 32 --variants default --samples 5 --impacts 70 --threads 1 --out sweep32 > sweep32.log 2>&1
echo done > finished
