#!/bin/bash
# Waits for process PID to end (0: not at all), then runs the named campaigns one after another:
# W workers (default one) of one thread each, nice 12, logs in $R/NAME.log, starts and ends in
# $R/lanes.log. A lane whose order has to change is stopped and started again with the new order
# (a running bash script must not be edited; replace this file by rename only).
#   bash notebook/campaign-state/then.sh PID NAME...      (from the repository's root)
# NAME: a line of campaigns.tsv with a spec.
B=${B:-/work/bins/grit-5604815-native}
R=${R:-/work/runs}
# W: workers (one thread each); 2 for the last campaign once it runs alone on both cores.
W=${W:-1}
list=$(dirname "$0")/campaigns.tsv
pid=$1; shift
field() { # name column: the campaign's spec (2) or folder (3); fails unless then.sh can run it
  awk -v n="$1" -v c="$2" '!/^#/ && $1 == n && $2 != "-" { print $c; found = 1 } END { exit !found }' "$list"
}
[ $# -gt 0 ] || { echo "then.sh: name at least one campaign" >&2; exit 2; }
for name in "$@"; do
  field "$name" 2 >/dev/null || {
    echo "then.sh: unknown campaign '$name' (one of: $(awk '!/^#/ && $2 != "-" { print $1 }' "$list" | paste -sd' '))" >&2
    exit 2
  }
done
if [ "$pid" != 0 ]; then
  while kill -0 "$pid" 2>/dev/null; do sleep 30; done
  echo "$(date -u +%FT%TZ) then.sh saw process $pid go" >> "$R/lanes.log"
fi
for name in "$@"; do
  echo "$(date -u +%FT%TZ) start $name --workers $W (then.sh)" >> "$R/lanes.log"
  nice -n 12 "$B" run "$(field "$name" 2)" --out "$R/$(field "$name" 3)" --threads 1 --workers "$W" >> "$R/$name.log" 2>&1
  echo "$(date -u +%FT%TZ) end $name (exit $?, then.sh)" >> "$R/lanes.log"
done
