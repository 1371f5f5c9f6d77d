"""First loss and windowed rates of two campaigns with the same seed, sample by sample.

Usage: python3 paired.py A.db B.db   (samples of the same cell index and sample index see the
same grains and aims, so their difference is the model's, not the draw's)
"""
import sqlite3, sys, json, statistics as st, math
from events import rows

def per_sample(db):
    c = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    idx = {j: (ci, s) for j, ci, s in c.execute("select id, cell_index, sample_index from jobs")}
    cells, data = rows(db)
    out = {}
    for ci, jobs in data.items():
        for j, v in jobs.items():
            out[idx[j]] = v
    return cells, out

(ca, a), (cb, b) = per_sample(sys.argv[1]), per_sample(sys.argv[2])
def first(v):
    return next((r["impact"] for r in v if r["mass_loss_kg"] > 0), None)
def window(v, lo, hi):
    w = [r for r in v if lo <= r["impact"] <= hi]
    if len(w) < hi - lo + 1:
        return None
    return sum(r["mass_loss_kg"] for r in w) / sum(r["grain_mass_kg"] for r in w) * 1e3
for ci in sorted({k[0] for k in b}):
    keys = sorted(k for k in b if k[0] == ci and k in a)
    fa = [first(a[k]) for k in keys]; fb = [first(b[k]) for k in keys]
    print(f"cell {ci} ({ca[ci][0]:.0f}°), {len(keys)} paired samples")
    print("  first loss A:", fa)
    print("  first loss B:", fb)
    for lo in range(1, 161, 20):
        wa = [window(a[k], lo, lo + 19) for k in keys]; wb = [window(b[k], lo, lo + 19) for k in keys]
        pa = [x for x in wa if x is not None]; pb = [x for x in wb if x is not None]
        if len(pb) < 2:
            break
        f = lambda x: f"{st.mean(x):.2f}±{st.stdev(x)/math.sqrt(len(x)):.2f}(n{len(x)})"
        print(f"  impacts {lo:3d}-{lo+19:3d}: A {f(pa)}  B {f(pb)}")
