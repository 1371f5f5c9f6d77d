"""Interim damage balance of a farm database: per cell, over each sample's impacts lo..hi that
carry damage, mean loss and damage added per g of grain (mg/g) with standard errors."""
import sqlite3, sys, json, statistics as st
db, lo, hi = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
c = sqlite3.connect(db)
rows = c.execute("""select j.cell_index, j.sample_index, u.unit, u.record, u.damage_kg_m
  from units u join jobs j on j.id=u.job_id where u.unit between ? and ? order by 1,2,3""", (lo, hi)).fetchall()
cells = {}
for cell, s, unit, rec, dmg in rows:
    if dmg is None: continue
    r = json.loads(rec)
    cells.setdefault(cell, {}).setdefault(s, []).append((r['grain_mass_kg'], r['mass_loss_kg'], dmg))
for cell, samples in sorted(cells.items()):
    full = [v for v in samples.values() if len(v) == hi - lo + 1]
    if len(full) < 2: continue
    L = [1e3*sum(x[1] for x in v)/sum(x[0] for x in v) for v in full]
    A = [1e3*sum(x[2] for x in v)/sum(x[0] for x in v) for v in full]
    D = [l-a for l, a in zip(L, A)]
    se = lambda x: st.stdev(x)/len(x)**0.5
    print(f"cell {cell}: {len(full)} samples, impacts {lo}-{hi}: loss {st.mean(L):.2f} ± {se(L):.2f}, damage added {st.mean(A):.2f} ± {se(A):.2f}, ratio {st.mean(L)/st.mean(A):.2f}, diff {st.mean(D):.2f} ± {se(D):.2f} ({abs(st.mean(D))/se(D):.1f} s.e.)")
