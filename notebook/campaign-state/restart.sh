#!/bin/bash
# Brings the long campaigns back on a new machine, as the sessions' notes did by hand: builds the
# pinned binary (5604815 with the certified radial return of
# notebook/performance/certified-return-2026-12-07/ and the half pairs four at a time of
# notebook/performance/chunked-pairs-2026-12-07/, built for the CPU and guided by the profile
# kept in notebook/performance/pgo-2026-12-06/) unless it is there, refuses it unless it computes
# the campaigns' bits, restores each named campaign from this folder's saves unless its run folder
# exists, then starts one lane per argument (then.sh), the checkpoint keeper and save-every.sh.
#   bash notebook/campaign-state/restart.sh [--no-start] SESSION LANE...   (from the repository's root)
# LANE: campaign names run one after another in one lane, joined by commas (ppd48,ppd64, or
# paper,paper-shapes). SESSION names save-every.sh's files (e.g. s53). --no-start stops after the
# restore (R may name a scratch folder for a trial; keep-fast.sh watches /work/runs alone, so the
# lanes are started only with the default R). W=2 gives each lane's campaigns two workers: for
# paper-shapes once it is the only campaign left (`W=2 restart.sh SESSION paper-shapes`).
set -euo pipefail
start=1
if [ "${1:-}" = "--no-start" ]; then start=0; shift; fi
[ $# -ge 2 ] || { echo "usage: restart.sh [--no-start] SESSION LANE..." >&2; exit 2; }
session=$1; shift
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
B=${B:-/work/bins/grit-5604815-chunk-native-pgo}
R=${R:-/work/runs}
commit=5604815
# The patches applied with their own author as committer and date give this commit on any machine.
patched=a9dccb05472a57fab2af92445bc9f39e29a0e3e4
patch=$repo/notebook/performance/chunked-pairs-2026-12-07/campaign.patch
src=/work/campaign-src
if [ ! -x "$B" ]; then
  echo "$(date -u +%FT%TZ) building $B (about 6 minutes on an idle machine)"
  mkdir -p "$(dirname "$B")" /work/pgo
  xz -dc "$repo/notebook/performance/pgo-2026-12-06/grit.profdata.xz" > /work/pgo/grit.profdata
  if [ ! -d $src ]; then
    git -C "$repo" worktree add --detach $src "$commit"
    (cd $src && GIT_COMMITTER_NAME="Seed 137f0062 maintainers" \
      GIT_COMMITTER_EMAIL=maintainers@users.noreply.h-seed-137f0062.example \
      git am --committer-date-is-author-date -q "$patch")
  fi
  [ "$(git -C $src rev-parse HEAD)" = "$patched" ] || { echo "restart.sh: $src is not $patched" >&2; exit 1; }
  (cd $src && RUSTFLAGS="-C target-cpu=native -Cprofile-use=/work/pgo/grit.profdata" \
    CARGO_TARGET_DIR=/work/target-pgo-cert cargo build --release --bin grit)
  cp /work/target-pgo-cert/release/grit "$B"
fi
# The campaigns' bits: the engine fingerprints and the two 3-impact samples' md5s.
want="impact engine 0a408d93d042d5e9
jet engine    d0bf534f1dd852f9
45: 74caabe3743c6901ba7e418413522ec2
90: 8e58805186dcdf9ab6880fca705c687a"
got=$(bash "$here/bits.sh" "$B" 2>&1) || true
[ "$got" = "$want" ] || { echo "restart.sh: $B computes other bits:"$'\n'"$got"$'\n'"not"$'\n'"$want" >&2; exit 1; }
echo "$B computes the campaigns' bits"
mkdir -p "$R"
for lane in "$@"; do
  for name in ${lane//,/ }; do
    if [ -e "$R/$name/grit.db" ]; then
      echo "$name: $R/$name/grit.db exists, not restored"
    elif [ ! -e "$here/$name.sql" ]; then
      echo "$name: no save in $here, starts from its spec when its lane gets to it"
    else
      bash "$here/restore.sh" "$here/$name.sql" "$R/$name"
    fi
  done
done
[ "$start" = 1 ] || exit 0
[ "$R" = /work/runs ] || { echo "restart.sh: lanes start only in /work/runs (keep-fast.sh)" >&2; exit 2; }
cd "$repo"
for lane in "$@"; do
  B=$B R=$R W=${W:-1} setsid nohup bash "$here/then.sh" 0 ${lane//,/ } > /dev/null 2>&1 < /dev/null &
done
setsid nohup bash "$repo/notebook/erosion/walls-2026-11-29/keep-fast.sh" > /dev/null 2>&1 < /dev/null &
RUNS=$R setsid nohup bash "$here/save-every.sh" 2700 "$session" >> "$R/save-every.log" 2>&1 < /dev/null &
sleep 5
pgrep -af "then.sh|keep-fast|save-every|$(basename "$B") run" || true
