"""Paired comparison of two campaigns that differ only in the surface box (same seeds, so
sample s of cell c meets the same grains in both): per cell and 40-impact window, loss, damage
added (mg per g of grain) and steps per impact in each box, and the paired difference B - A
with its standard error over the samples.
Usage: python3 compare.py DB_A DB_B [WINDOW]"""
import sqlite3, statistics as st, sys


def load(db):
    """{(angle, sample): {impact: (grain, loss, damage, steps)}}"""
    c = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    rows = c.execute("""select c.angle_deg, j.sample_index, u.unit,
        json_extract(u.record, '$.grain_mass_kg'), json_extract(u.record, '$.mass_loss_kg'),
        u.damage_kg_m, json_extract(u.record, '$.outcome.steps')
        from units u join jobs j on j.id = u.job_id join cells c
        on c.campaign_id = j.campaign_id and c.cell_index = j.cell_index""").fetchall()
    out = {}
    for angle, s, unit, g, loss, dmg, steps in rows:
        out.setdefault((angle, s), {})[unit] = (g, loss, dmg, steps)
    return out


def window(v, lo, hi):
    w = [v.get(u) for u in range(lo, hi + 1)]
    if None in w:
        return None
    g = sum(x[0] for x in w)
    return (1e3 * sum(x[1] for x in w) / g, 1e3 * sum(x[2] for x in w) / g,
            sum(x[3] for x in w) / len(w))


def ms(x):
    m = st.mean(x)
    return m, (st.stdev(x) / len(x) ** 0.5 if len(x) > 1 else float('nan'))


def main():
    a, b = load(sys.argv[1]), load(sys.argv[2])
    step = int(sys.argv[3]) if len(sys.argv) > 3 else 40
    names = ("loss", "damage added", "steps/impact")
    for angle in sorted({k[0] for k in a}):
        top = max(max(v) for k, v in a.items() if k[0] == angle)
        for lo in range(1, top + 1, step):
            hi = lo + step - 1
            pairs = []
            for k in sorted(a):
                if k[0] != angle or k not in b:
                    continue
                wa, wb = window(a[k], lo, hi), window(b[k], lo, hi)
                if wa and wb:
                    pairs.append((wa, wb))
            if not pairs:
                continue
            cols = []
            for i, name in enumerate(names):
                ma, sa = ms([p[0][i] for p in pairs])
                mb, sb = ms([p[1][i] for p in pairs])
                md, sd = ms([p[1][i] - p[0][i] for p in pairs])
                cols.append(f"{name} {ma:.3g} ± {sa:.2g} | {mb:.3g} ± {sb:.2g} | diff {md:+.3g} ± {sd:.2g}")
            print(f"{angle:g}° {lo}-{hi} n={len(pairs)}: " + "; ".join(cols))


if __name__ == '__main__':
    main()
