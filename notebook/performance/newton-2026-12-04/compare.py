"""Paired comparison of the 16-per-Dg erosion of the old engine (0a408d93d042d5e9) and the new
one (the radial return in ln Δε) on the same 25 samples at 45 and 90 degrees, impacts 1..N.

  python3 compare.py RUNS_DIR [N]

New engine: newton-new/grit.db (check-new.json, seed 2024). Old engine, the same job seeds:
samples 0-14 from ppd16c/grit.db (resolution16-balanced.json, seed 2024), samples 15-24 from
newton-pairs/old-cC-sS.json (pairs.sh). Per pair: whether every impact's mass loss is bitwise
the same, the largest relative difference of an impact's damage added, and of its rebound
ratio. Per cell and engine: the seed's slope over impacts N-19..N, cumulative loss and damage
added over 1..N (mg per g of grain), mean and standard error over the samples present in both."""
import json, math, sqlite3, sys

runs = sys.argv[1]
N = int(sys.argv[2]) if len(sys.argv) > 2 else 200
ANGLES = {0: 45, 1: 90}


def from_db(db, cell, si):
    c = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    row = c.execute("select id from jobs where cell_index=? and sample_index=?", (cell, si)).fetchone()
    if row is None:
        return None
    recs = [json.loads(r) for (r,) in c.execute(
        "select record from units where job_id=? and unit<=? order by unit", (row[0], N))]
    return recs if len(recs) == N else None


def from_json(path):
    try:
        recs = json.load(open(path))["impacts"][:N]
    except FileNotFoundError:
        return None
    return recs if len(recs) == N else None


def slope(recs, first, last):
    cg = cl = 0.0
    xs, ys = [], []
    for k, r in enumerate(recs, 1):
        cg += r["grain_mass_kg"]
        cl += r["mass_loss_kg"]
        if first <= k <= last:
            xs.append(cg)
            ys.append(cl)
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def mean_se(v):
    m = sum(v) / len(v)
    return m, math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1) / len(v)) if len(v) > 1 else float("nan")


measures = {
    f"slope {N-19}-{N}": lambda r: 1e3 * slope(r, N - 19, N),
    f"loss 1-{N}": lambda r: 1e3 * sum(x["mass_loss_kg"] for x in r) / sum(x["grain_mass_kg"] for x in r),
    f"damage 1-{N}": lambda r: 1e3 * sum(x["outcome"]["damage_added_kg"] for x in r) / sum(x["grain_mass_kg"] for x in r),
}
print("| angle | pairs | impacts with bitwise equal loss | largest relative difference of damage added / rebound |")
print("|---|---|---|---|")
cells = {}
for cell, angle in ANGLES.items():
    pairs = []
    for si in range(25):
        new = from_db(f"{runs}/newton-new/grit.db", cell, si)
        old = from_db(f"{runs}/ppd16c/grit.db", cell, si) if si < 15 else \
            from_json(f"{runs}/newton-pairs/old-c{cell}-s{si}.json")
        if new is not None and old is not None:
            pairs.append((si, old, new))
    same = sum(o["mass_loss_kg"] == n["mass_loss_kg"] for _, old, new in pairs for o, n in zip(old, new))
    dd = max((abs(o["outcome"]["damage_added_kg"] - n["outcome"]["damage_added_kg"]) / o["outcome"]["damage_added_kg"]
              for _, old, new in pairs for o, n in zip(old, new) if o["outcome"]["damage_added_kg"]), default=0)
    dr = max((abs(o["outcome"]["rebound_ratio"] - n["outcome"]["rebound_ratio"]) / abs(o["outcome"]["rebound_ratio"])
              for _, old, new in pairs for o, n in zip(old, new) if o["outcome"]["rebound_ratio"]), default=0)
    print(f"| {angle}° | {len(pairs)} | {same} of {N * len(pairs)} | {dd:.1e} / {dr:.1e} |")
    cells[angle] = pairs
print()
print("| angle | measure (mg/g) | old engine | new engine | new − old, paired |")
print("|---|---|---|---|---|")
for angle, pairs in cells.items():
    if len(pairs) < 2:
        continue
    for name, f in measures.items():
        o = [f(old) for _, old, _ in pairs]
        n = [f(new) for _, _, new in pairs]
        (mo, so), (mn, sn), (md, sd) = mean_se(o), mean_se(n), mean_se([b - a for a, b in zip(o, n)])
        print(f"| {angle}° | {name} | {mo:.4f} ± {so:.4f} | {mn:.4f} ± {sn:.4f} | {md:+.1e} ± {sd:.1e} |")
