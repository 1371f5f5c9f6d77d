"""Interim damage balance of a farm database: per cell, over each sample's impacts lo..hi that
carry damage, mean loss and damage added per g of grain (mg/g) with standard errors.
Usage: python3 balance_interim.py DB LO HI. `load` and `rates` serve long16/summarise.py too."""
import json, sqlite3, statistics as st, sys


def load(db):
    """Every impact with its damage recorded: {(cell, angle): {sample: {impact: (grain, loss, damage)}}}."""
    c = sqlite3.connect(db, uri=True)
    rows = c.execute("""select j.cell_index, c.angle_deg, j.sample_index, u.unit, u.record, u.damage_kg_m
      from units u join jobs j on j.id = u.job_id join cells c
      on c.campaign_id = j.campaign_id and c.cell_index = j.cell_index
      where u.damage_kg_m is not null""").fetchall()
    cells = {}
    for cell, angle, s, unit, rec, dmg in rows:
        r = json.loads(rec)
        cells.setdefault((cell, angle), {}).setdefault(s, {})[unit] = (r['grain_mass_kg'], r['mass_loss_kg'], dmg)
    return cells


def rates(samples, lo, hi):
    """Loss and damage added per g of grain (mg/g) over impacts lo..hi, one each per sample that has them all."""
    loss, added = [], []
    for v in samples.values():
        w = [v.get(u) for u in range(lo, hi + 1)]
        if None in w:
            continue
        g = sum(x[0] for x in w)
        loss.append(1e3 * sum(x[1] for x in w) / g)
        added.append(1e3 * sum(x[2] for x in w) / g)
    return loss, added


def se(x):
    return st.stdev(x) / len(x) ** 0.5 if len(x) > 1 else float('nan')


if __name__ == '__main__':
    db, lo, hi = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    for (cell, _), samples in sorted(load(db).items()):
        L, A = rates(samples, lo, hi)
        if len(L) < 2:
            continue
        D = [l - a for l, a in zip(L, A)]
        print(f"cell {cell}: {len(L)} samples, impacts {lo}-{hi}: loss {st.mean(L):.2f} ± {se(L):.2f}, damage added {st.mean(A):.2f} ± {se(A):.2f}, ratio {st.mean(L)/st.mean(A):.2f}, diff {st.mean(D):.2f} ± {se(D):.2f} ({abs(st.mean(D))/se(D):.1f} s.e.)")
