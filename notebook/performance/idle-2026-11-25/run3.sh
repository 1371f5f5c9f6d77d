for r in 1 2 3; do
  for b in hp9be15c1 old17 new; do
    /work/bins/grit-$b bench impact --repeat 5 --json > e-$b-$r.json 2> e-$b-$r.err
  done
done
touch DONE3
