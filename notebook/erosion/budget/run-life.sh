#!/bin/bash
# Whole-life budgets at 16 per Dg: the ppd16b campaign's first two samples per angle (its own
# job seeds), 400 impacts, so the first 240/180 reproduce the campaign's records.
cd /work/runs/budget
while pgrep -f run.sh >/dev/null; do sleep 30; done
B=/work/bins/grit-budget2
nice -n 5 $B study budget --scene scene16-45.json --angle 45 --seeds 10475206250991968183,9005204567979501331 --impacts 400 --threads 2 --json > life16-45.json 2> life16-45.err
nice -n 5 $B study budget --scene scene16-45.json --angle 90 --seeds 11473585605353737402,7891817924966397080 --impacts 400 --threads 2 --json > life16-90.json 2> life16-90.err
nice -n 5 $B study budget ckpt48/*.ckpt --impacts 2 --threads 2 --json > base48.json 2> base48.err
nice -n 5 $B study budget ckpt/c*-s[0-3].ckpt --impacts 2 --threads 2 --json > max32.json 2> max32.err
