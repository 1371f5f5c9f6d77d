#!/bin/bash
# Waits for process PID to end (0: not at all), then runs the named campaigns one after another
# as lanes-after.sh's lanes do: W workers (default one) of one thread each, nice 12, logs in $R/NAME.log,
# starts and ends in $R/lanes.log. For a lane whose order has to change while lanes-after.sh
# runs (a running bash script must not be edited).
#   bash notebook/campaign-state/then.sh PID NAME...      (from the repository's root)
# NAME: ppd48, ppd64, box48-big, ppd16c, ppd24b, paper or paper-shapes.
B=${B:-/work/bins/grit-5604815-native}
R=${R:-/work/runs}
# W: workers (one thread each); 2 for the last campaign once it runs alone on both cores.
W=${W:-1}
pid=$1; shift
spec_of() {
  case "$1" in
    ppd48) echo examples/resolution48-steady.json ;;
    ppd64) echo examples/resolution64-steady.json ;;
    box48-big) echo notebook/erosion/box48-460/big.json ;;
    ppd16c) echo examples/resolution16-balanced.json ;;
    ppd24b) echo examples/resolution24-balanced.json ;;
    paper) echo examples/paper.json ;;
    paper-shapes) echo examples/paper-shapes.json ;;
    *) return 1 ;;
  esac
}
[ $# -gt 0 ] || { echo "then.sh: name at least one campaign" >&2; exit 2; }
for name in "$@"; do
  spec_of "$name" >/dev/null || { echo "then.sh: unknown campaign '$name' (ppd48, ppd64, box48-big, ppd16c, ppd24b, paper, paper-shapes)" >&2; exit 2; }
done
if [ "$pid" != 0 ]; then
  while kill -0 "$pid" 2>/dev/null; do sleep 30; done
  echo "$(date -u +%FT%TZ) then.sh saw process $pid go" >> "$R/lanes.log"
fi
for name in "$@"; do
  echo "$(date -u +%FT%TZ) start $name --workers $W (then.sh)" >> "$R/lanes.log"
  nice -n 12 "$B" run "$(spec_of "$name")" --out "$R/$name" --threads 1 --workers "$W" >> "$R/$name.log" 2>&1
  echo "$(date -u +%FT%TZ) end $name (exit $?, then.sh)" >> "$R/lanes.log"
done
