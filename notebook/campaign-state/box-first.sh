#!/bin/bash
# Replaces start.sh's lanes once they run (session 45): the paired box runs decide whether the
# campaigns' box is wide enough, and big is their long pole (3 samples, one worker in lane a,
# about 12 h of a core on this machine against 1.7 h for std). When std ends, big is stopped
# with SIGINT (its worker releases each job with a checkpoint) and restarted with two workers,
# one thread each, so the pair ends in about half the time; after it, lanes-after.sh runs the
# lanes' other runs in start.sh's order.
#   bash notebook/campaign-state/box-first.sh STD_PID BIG_PID     (from the repository's root)
# Kill start.sh's two lane shells first (their grit children go on), or they start the next run.
STD=$1 BIG=$2
B=${B:-/work/bins/grit-9d98f72-native-pgo}
R=${R:-/work/runs}
while kill -0 "$STD" 2>/dev/null; do sleep 30; done
echo "$(date -u +%FT%TZ) end box32std (box-first.sh saw its process go)" >> "$R/lanes.log"
kill -INT "$BIG" 2>/dev/null
while kill -0 "$BIG" 2>/dev/null; do sleep 5; done
echo "$(date -u +%FT%TZ) box32big stopped; restarted with two workers" >> "$R/lanes.log"
echo "$(date -u +%FT%TZ) start box32big --workers 2 --checkpoint-every 20" >> "$R/lanes.log"
nice -n 12 "$B" run notebook/erosion/box32-420/big.json --out "$R/box32/big" --threads 1 \
  --workers 2 --checkpoint-every 20 >> "$R/box32big.log" 2>&1 &
# The lanes' other runs, once big ends.
exec bash "$(dirname "$0")/lanes-after.sh" $!
