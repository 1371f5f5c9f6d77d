#!/bin/bash
# grit study budget over 8 worn (80-impact) 32-per-Dg surfaces per angle of /work/runs/paper
cd /work/runs/budget
B=/work/bins/grit-budget
nice -n 5 $B study budget ckpt/*.ckpt --impacts 3 --threads 2 --json > base.json 2> base.err
nice -n 5 $B study budget ckpt/*.ckpt --impacts 3 --threads 2 --json --patch '{"material":{"damage":{"d3":0}}}' > d3zero.json 2> d3zero.err
nice -n 5 $B study budget ckpt/*.ckpt --impacts 3 --threads 2 --json --patch '{"friction":0}' > mu0.json 2> mu0.err
