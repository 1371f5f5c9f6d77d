# Paired comparison of cell 0's samples of two grit.db files (same campaign seed and cell index,
# so the same grains and aim points) at a common impact count N:
#   python3 paired.py A/grit.db B/grit.db N [FROM]
# prints per sample the cumulative mass loss at N and the slope over impacts FROM+1..N (the last
# 20 by default), and the paired means.
import sqlite3, sys, statistics as st
def series(db, cell=0):
    c = sqlite3.connect(f'file:{db}?mode=ro', uri=True)
    out = {}
    for s, imp, g, m in c.execute("select j.sample_index, i.impact, i.grain_mass_kg, i.mass_loss_kg from impacts i join jobs j on j.id=i.job_id where j.cell_index=? order by j.sample_index, i.impact", (cell,)):
        out.setdefault(s, []).append((imp, g, m))
    return out
def slope(rows):  # least-squares slope of cumulative loss vs cumulative grain mass
    cg, cm, xs, ys = 0, 0, [], []
    for _, g, m in rows:
        cg += g; cm += m; xs.append(cg); ys.append(cm)
    mx, my = st.mean(xs), st.mean(ys)
    return sum((x-mx)*(y-my) for x, y in zip(xs, ys)) / sum((x-mx)**2 for x in xs)
a, b, n = series(sys.argv[1]), series(sys.argv[2]), int(sys.argv[3])
lo = int(sys.argv[4]) if len(sys.argv) > 4 else n - 20
rows = []
for s in sorted(set(a) & set(b)):
    if len(a[s]) < n or len(b[s]) < n: continue
    ca = sum(m for _, _, m in a[s][:n]) / sum(g for _, g, _ in a[s][:n]) * 1e3
    cb = sum(m for _, _, m in b[s][:n]) / sum(g for _, g, _ in b[s][:n]) * 1e3
    sa, sb = slope(a[s][lo:n]) * 1e3, slope(b[s][lo:n]) * 1e3
    first = lambda r: next((i for i, _, m in r if m > 0), None)
    rows.append((s, ca, cb, sa, sb, first(a[s]), first(b[s][:n])))
    print(f"sample {s}: cumulative {ca:.3f} vs {cb:.3f} mg/g; slope {sa:.2f} vs {sb:.2f}; first loss {first(a[s][:n])} vs {first(b[s][:n])}")
for k, name in ((1, 'cumulative'), (3, f'slope over {lo + 1}-{n}')):
    d = [r[k+1] - r[k] for r in rows]
    if len(d) > 1:
        print(f"{name}: A {st.mean(r[k] for r in rows):.3f}, B {st.mean(r[k+1] for r in rows):.3f}, paired diff {st.mean(d):+.3f} ± {st.stdev(d)/len(d)**0.5:.3f} (s.e., {len(d)} samples)")
