#!/bin/bash
# Diagnostic: the build of 1f84742 alone (`plain`) and beside two busy loops at the idle
# scheduling class (`spin`, `chrt --idle 0`), which keep both virtual CPUs from halting.
# Medians:
#   python3 notebook/performance/medians.py notebook/performance/polling-2026-11-26/idle-spinners plain spin
for r in 1 2 3; do
  /work/bins/grit-1f84742 bench impact --repeat 5 --json > plain-$r.json
  chrt --idle 0 bash -c 'while :; do :; done' & s1=$!
  chrt --idle 0 bash -c 'while :; do :; done' & s2=$!
  sleep 1
  /work/bins/grit-1f84742 bench impact --repeat 5 --json > spin-$r.json
  kill $s1 $s2; wait $s1 $s2 2>/dev/null
done
