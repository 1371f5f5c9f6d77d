#!/bin/sh
# The jet scene at 0.2 ms, seeds 1-3: copper on its cold curve (COLD: a build of e83395d)
# against copper with its energy equation (NEW: this commit's build), side by side on one
# thread each. Run from this folder; `python3 table.py` prints the notebook/jet-log.md table of the energy equation (docs/jet.md#energy).
# The *-verify.txt files are `grit verify --only jet --quick` of e83395d (cold) and of two
# diagnostic builds that also gave the water an energy equation (not kept).
COLD=${COLD:-grit-e83395d}
NEW=${NEW:-grit}
S=../default-scene.json
for s in 1 2 3; do
  $COLD jet --scene $S --time-ms 0.2 --spacing-m 1e-4 --seed $s --threads 1 --json -o cold-s$s.json > /dev/null 2>&1 &
  $NEW jet --scene $S --time-ms 0.2 --spacing-m 1e-4 --seed $s --threads 1 --json -o energy-s$s.json > /dev/null 2>&1
  wait
done
