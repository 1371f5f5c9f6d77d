"""Compares the 16-per-Dg erosion of two engines on 25 samples at 45 and 90 degrees, per impact
window: the old engine's samples are ppd16c's 15 (seed 2024, first N impacts) and
newton-check-16-old's 10 (seed 2025); the new engine's are newton-check-16's 25 (seed 2024).

  python3 compare.py RUNS_DIR [N]     (RUNS_DIR holds ppd16c/, newton-old/, newton-new/)

Per sample: the least-squares slope of cumulative loss against cumulative grain mass over
impacts N-19..N (the seed's rule), the same over N-59..N, the cumulative loss over 1..N and
the damage added over 1..N, each per grain mass (mg/g). Per cell: mean, standard error, and
the new-old difference in combined standard errors."""
import json, math, sqlite3, sys

runs = sys.argv[1]
N = int(sys.argv[2]) if len(sys.argv) > 2 else 200
ANGLES = {0: 45, 1: 90}


def samples(db, limit=None):
    """{angle: [[(grain, loss, damage) per impact 1..N] per sample]}"""
    c = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    out = {45: [], 90: []}
    jobs = c.execute("select id, cell_index, sample_index from jobs order by cell_index, sample_index")
    for jid, cell, si in jobs.fetchall():
        if limit is not None and si >= limit:
            continue
        rows = c.execute("select unit, record from units where job_id=? and unit<=? order by unit", (jid, N)).fetchall()
        if len(rows) < N:
            continue
        seq = []
        for u, rec in rows:
            r = json.loads(rec)
            seq.append((r["grain_mass_kg"], r["mass_loss_kg"], r["outcome"]["damage_added_kg"]))
        out[ANGLES[cell]].append(seq)
    return out


def slope(seq, first, last):
    """LSQ slope of cumulative loss on cumulative grain mass over impacts first..last (1-based)."""
    cg = cl = 0.0
    xs, ys = [], []
    for k, (g, l, _) in enumerate(seq, 1):
        cg += g
        cl += l
        if first <= k <= last:
            xs.append(cg)
            ys.append(cl)
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def stats(vals):
    n = len(vals)
    m = sum(vals) / n
    sd = math.sqrt(sum((v - m) ** 2 for v in vals) / (n - 1))
    return m, sd / math.sqrt(n), n


measures = {
    f"slope {N-19}-{N}": lambda s: 1e3 * slope(s, N - 19, N),
    f"slope {N-59}-{N}": lambda s: 1e3 * slope(s, N - 59, N),
    f"loss 1-{N}": lambda s: 1e3 * sum(x[1] for x in s) / sum(x[0] for x in s),
    f"damage 1-{N}": lambda s: 1e3 * sum(x[2] for x in s) / sum(x[0] for x in s),
}
old = samples(f"{runs}/ppd16c/grit.db", limit=15)
extra = samples(f"{runs}/newton-old/grit.db")
new = samples(f"{runs}/newton-new/grit.db")
print(f"| angle | measure (mg/g) | old engine (0a408d93) | new engine | new − old | in combined s.e. |")
print("|---|---|---|---|---|---|")
for a in (45, 90):
    o = old[a] + extra[a]
    for name, f in measures.items():
        mo, so, no = stats([f(s) for s in o])
        mn, sn, nn = stats([f(s) for s in new[a]])
        d = mn - mo
        z = d / math.hypot(so, sn)
        print(f"| {a}° | {name} | {mo:.3f} ± {so:.3f} (n={no}) | {mn:.3f} ± {sn:.3f} (n={nn}) | {d:+.3f} ({100*d/mo:+.1f} %) | {z:+.2f} |")
