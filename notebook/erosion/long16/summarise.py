"""The damage balance over 800 impacts at 16 per Dg (long16): per cell, in windows of W impacts,
the mean over samples of loss and damage added per g of grain (mg/g), their ratio, and each
sample's loss over impacts LO..800 as the long-window rate (mean ± s.e.).
Usage: python3 summarise.py DB [W=80] [LO=401]"""
import json, sqlite3, statistics as st, sys

db = sys.argv[1]
w = int(sys.argv[2]) if len(sys.argv) > 2 else 80
lo = int(sys.argv[3]) if len(sys.argv) > 3 else 401
c = sqlite3.connect(db, uri=True)
rows = c.execute("""select c.angle_deg, j.sample_index, u.unit, u.record, u.damage_kg_m
  from units u join jobs j on j.id = u.job_id join cells c
  on c.campaign_id = j.campaign_id and c.cell_index = j.cell_index order by 1, 2, 3""").fetchall()
cells = {}
for angle, s, unit, rec, dmg in rows:
    r = json.loads(rec)
    cells.setdefault(angle, {}).setdefault(s, []).append((r['grain_mass_kg'], r['mass_loss_kg'], dmg))
se = lambda x: st.stdev(x) / len(x) ** 0.5 if len(x) > 1 else float('nan')
rate = lambda v, a, b, k: 1e3 * sum(x[k] for x in v[a:b]) / sum(x[0] for x in v[a:b])
for angle, samples in sorted(cells.items()):
    n = max(len(v) for v in samples.values())
    full = [v for v in samples.values() if len(v) == n]
    print(f"{angle:.0f}°: {len(full)} samples of {n} impacts")
    print("  impacts    loss (mg/g)    damage added   ratio")
    for a in range(0, n - w + 1, w):
        L = [rate(v, a, a + w, 1) for v in full]
        A = [rate(v, a, a + w, 2) for v in full]
        print(f"  {a + 1:3d}-{a + w:3d}  {st.mean(L):5.2f} ± {se(L):4.2f}   {st.mean(A):5.2f} ± {se(A):4.2f}   {st.mean(L) / st.mean(A):4.2f}")
    L = [rate(v, lo - 1, n, 1) for v in full]
    A = [rate(v, lo - 1, n, 2) for v in full]
    print(f"  long window {lo}-{n}: loss {st.mean(L):.2f} ± {se(L):.2f}, damage added {st.mean(A):.2f} ± {se(A):.2f}, ratio {st.mean(L) / st.mean(A):.2f}")
