"""Impacts LO-HI of one cell: the campaign's records (its database) against the same samples
resumed from the campaign's checkpoints by another binary (sJ.json files of `grit sample
--resume ... --json -o`). Per sample, loss and damage added over the window per grain mass
(mg/g) and steps per impact; then the means, standard errors and the paired differences.

usage: python3 compare.py "file:DB?mode=ro" CELL DIR LO HI
"""
import json
import os
import sqlite3
import statistics as st
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "erosion"))
from balance_interim import se  # noqa: E402

db, cell, d, lo, hi = sys.argv[1], int(sys.argv[2]), sys.argv[3], int(sys.argv[4]), int(sys.argv[5])
con = sqlite3.connect(db, uri=True)


def window(recs):
    """(loss, damage) in mg/g and mean steps over the window, or None when incomplete."""
    w = [r for r in recs if lo <= r["impact"] <= hi]
    if len(w) != hi - lo + 1:
        return None
    g = sum(r["grain_mass_kg"] for r in w)
    loss = sum(r["mass_loss_kg"] for r in w) / g * 1e3
    dmg = sum(r["outcome"]["damage_added_kg"] for r in w) / g * 1e3
    steps = sum(r["outcome"]["steps"] for r in w) / len(w)
    return loss, dmg, steps


def mean_se(xs):
    return st.mean(xs), se(xs)


rows = []
for f in sorted(os.listdir(d)):
    if not (f.startswith("s") and f.endswith(".json")):
        continue
    i = int(f[1:-5])
    new = window(json.load(open(os.path.join(d, f)))["impacts"])
    recs = [
        json.loads(r)
        for (r,) in con.execute(
            "select u.record from units u join jobs j on j.id = u.job_id"
            " where j.cell_index = ? and j.sample_index = ? and u.unit between ? and ?",
            (cell, i, lo, hi),
        )
    ]
    old = window(recs)
    if new is None or old is None:
        continue
    rows.append((i, old, new))
    print(f"sample {i:2d}: loss {old[0]:.2f} -> {new[0]:.2f}, damage {old[1]:.2f} -> {new[1]:.2f}, steps {old[2]:.0f} -> {new[2]:.0f}")

if len(rows) < 2:
    sys.exit(f"{len(rows)} samples with both windows complete")
print(f"{len(rows)} samples, impacts {lo}-{hi}")
for k, name in [(0, "loss (mg/g)"), (1, "damage added (mg/g)"), (2, "steps per impact")]:
    o = mean_se([r[1][k] for r in rows])
    n = mean_se([r[2][k] for r in rows])
    diff = mean_se([r[2][k] - r[1][k] for r in rows])
    z = diff[0] / diff[1] if diff[1] > 0 else float("nan")
    print(f"{name}: campaign {o[0]:.3f} ± {o[1]:.3f}, resumed {n[0]:.3f} ± {n[1]:.3f}, "
          f"paired difference {diff[0]:+.3f} ± {diff[1]:.3f} ({z:+.1f} s.e.), ratio {n[0] / o[0]:.3f}")
