for r in 1 2 3; do
  /work/bins/grit-old17 bench impact --repeat 5 --json > d-old17-$r.json 2> d-old17-$r.err
  /work/bins/grit-new bench impact --repeat 5 --json > d-new17-$r.json 2> d-new17-$r.err
done
touch DONE
