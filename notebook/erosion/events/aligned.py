"""Erosion rate in 20-impact windows counted from each sample's own first loss.

Usage: python3 aligned.py DB [DB ...]
For each cell: mean over samples (± s.e.) of mass lost over grain mass (mg/g) in impacts
f..f+19, f+20..f+39, ... after each sample's first loss f, for the windows every counted
sample has completed; also the same per-impact loss in µg/m.
"""
import json, sqlite3, statistics as st, sys, math
from events import rows

W = 20
for db in sys.argv[1:]:
    cells, data = rows(db)
    for ci, jobs in sorted(data.items()):
        angle, p = cells[ci]
        ppd = p["grain_diameter_m"] / p["spacing_m"]
        per = []
        for v in jobs.values():
            f = next((i for i, r in enumerate(v) if r["mass_loss_kg"] > 0), None)
            if f is None:
                continue
            ws = []
            k = f
            while k + W <= len(v):
                lost = sum(r["mass_loss_kg"] for r in v[k:k + W]); g = sum(r["grain_mass_kg"] for r in v[k:k + W])
                ws.append(lost / g * 1e3); k += W
            per.append(ws)
        out = []
        for w in range(6):
            xs = [ws[w] for ws in per if len(ws) > w]
            if len(xs) < 2:
                break
            out.append(f"{st.mean(xs):.2f}±{st.stdev(xs)/math.sqrt(len(xs)):.2f}(n{len(xs)})")
        print(f"{db.split('/')[-2]:>6} {angle:>3.0f}° ppd {ppd:4.1f}: " + "  ".join(out))
