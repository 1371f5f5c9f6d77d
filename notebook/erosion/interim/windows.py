"""Interim erosion per 20-impact window of a running campaign, read from its database.

Usage: python3 windows.py DB [DB ...]
For each cell, over the samples that have completed at least N impacts (N = the most impacts
every counted sample has, rounded down to 20): mean ± s.e. over samples of mass lost over
grain mass (mg/g) in each 20-impact window. Interim only: the farm's steady rule and the
results file decide the reported rate.
"""
import math, statistics as st, sys
sys.path.insert(0, __file__.rsplit("/", 2)[0] + "/events")
from events import rows

W = 20
for db in sys.argv[1:]:
    cells, data = rows(db)
    print(db)
    for ci, jobs in sorted(data.items()):
        angle, p = cells[ci]
        ppd = p["grain_diameter_m"] / p["spacing_m"]
        runs = sorted(((len(v), v) for v in jobs.values() if len(v) >= W), key=lambda t: t[0])
        if not runs:
            continue
        # the deepest window count reached by at least 5 samples (or all, if fewer)
        need = min(5, len(runs))
        n = (runs[-need][0] // W) * W
        use = [v for ln, v in runs if ln >= n]
        cols = []
        for k in range(0, n, W):
            xs = [sum(r["mass_loss_kg"] for r in v[k:k + W]) / sum(r["grain_mass_kg"] for r in v[k:k + W]) * 1e3 for v in use]
            se = st.stdev(xs) / math.sqrt(len(xs)) if len(xs) > 1 else float("nan")
            cols.append(f"{k + 1}-{k + W}: {st.mean(xs):.2f}±{se:.2f}")
        print(f"  {angle:>4}° {ppd:.0f}/Dg n={len(use)}  " + "  ".join(cols))
