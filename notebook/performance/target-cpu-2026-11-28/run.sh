#!/bin/bash
# Alternates two builds of one commit on the same 3-impact sample (32 per Dg, 45°, seed 3, one
# thread) and records each run's user CPU time and the md5 of its full JSON output.
# usage: run.sh OLD_BINARY NEW_BINARY PAIRS > times.tsv
exec "$(dirname "$0")/../pairs.sh" "$1" "$2" "${3:-8}" --angle 45 --impacts 3 --seed 3
