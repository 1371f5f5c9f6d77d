#!/usr/bin/env python3
"""Tables from `grit study budget --json` outputs (notebook/erosion-log.md, session 26).

  summarise.py angles BASE.json [VARIANT.json ...]   per angle, normalised at 45°, Oka beside;
                                                     variants paired impact by impact with BASE
  summarise.py mechanism FILE.json ...               per angle: share of the removed mass by its
                                                     damage before the impact, and the largest
                                                     strain one impact gave one particle
  summarise.py life LIFE.json [WINDOW]               one sample's life in windows of WINDOW
                                                     impacts: loss, damage added, damage stock
"""
import gzip, json, math, sys

OKA = {15: 0.83, 30: 1.04, 45: 1.00, 60: 0.88, 75: 0.77, 90: 0.73}


def load(path):
    """A study's JSON, gzipped (as committed here) or not."""
    with (gzip.open if path.endswith(".gz") else open)(path, "rt") as f:
        return json.load(f)


def mg_per_g(r, key):
    return 1e3 * r[key] / r["grain_mass_kg"]


def mean_se(xs):
    n = len(xs)
    m = sum(xs) / n
    if n < 2:
        return m, float("nan")
    v = sum((x - m) ** 2 for x in xs) / (n - 1)
    return m, math.sqrt(v / n)


def angles(base, variants):
    rows = load(base)["rows"]
    by = {}
    for r in rows:
        by.setdefault(r["angle_deg"], []).append(r)
    ref = {k: mean_se([mg_per_g(r, k) for r in by[45.0]])[0] for k in ("mass_loss_kg", "plastic_kg", "damage_kg")}
    print(f"# {base}: per impact, mg per g of grain, mean ± s.e.; n = normalised at 45°")
    print("angle  n   loss         Σm·Δε_p       Σm·ΔD        ΔD/Δε_p  loss/ΔD  n-loss n-Δε_p n-ΔD  Oka")
    for a in sorted(by):
        rs = by[a]
        loss = mean_se([mg_per_g(r, "mass_loss_kg") for r in rs])
        pl = mean_se([mg_per_g(r, "plastic_kg") for r in rs])
        dm = mean_se([mg_per_g(r, "damage_kg") for r in rs])
        print(f"{a:5.0f} {len(rs):3d}  {loss[0]:5.2f}±{loss[1]:4.2f}  {pl[0]:6.2f}±{pl[1]:4.2f}  {dm[0]:5.2f}±{dm[1]:4.2f}"
              f"  {dm[0] / pl[0]:7.3f}  {loss[0] / dm[0]:7.2f}  {loss[0] / ref['mass_loss_kg']:6.2f} {pl[0] / ref['plastic_kg']:6.2f}"
              f" {dm[0] / ref['damage_kg']:5.2f}  {OKA.get(int(a), float('nan')):.2f}")
    for v in variants:
        vrows = {(r["seed"], r["impact"]): r for r in load(v)["rows"]}
        print(f"\n# {v} against {base}, paired (same surfaces, same grains): ratio of sums, Σm·ΔD normalised at 45°")
        print("angle  Σm·Δε_p ratio  Σm·ΔD ratio  ΔD/Δε_p   n-ΔD (base → variant)")
        vref = sum(mg_per_g(vrows[(r["seed"], r["impact"])], "damage_kg") for r in by[45.0]) / len(by[45.0])
        for a in sorted(by):
            rs = by[a]
            vs = [vrows[(r["seed"], r["impact"])] for r in rs]
            p0 = sum(r["plastic_kg"] for r in rs); p1 = sum(r["plastic_kg"] for r in vs)
            d0 = sum(r["damage_kg"] for r in rs); d1 = sum(r["damage_kg"] for r in vs)
            dm0 = mean_se([mg_per_g(r, "damage_kg") for r in rs])[0]
            dm1 = sum(mg_per_g(r, "damage_kg") for r in vs) / len(vs)
            print(f"{a:5.0f}  {p1 / p0:12.3f}  {d1 / d0:11.3f}  {d1 / p1:8.3f}   {dm0 / ref['damage_kg']:.2f} → {dm1 / vref:.2f}")


def life(path, window):
    rows = load(path)["rows"]
    by = {}
    for r in rows:
        by.setdefault(r["seed"], []).append(r)
    print(f"# {path}: windows of {window} impacts, mean over {len(by)} samples, mg per g of grain per impact")
    print("impacts    loss   Σm·ΔD  loss/ΔD  stock at start (mg per g of one grain)")
    n = max(len(v) for v in by.values())
    for lo in range(0, n, window):
        sel = [r for v in by.values() for r in v[lo:lo + window]]
        if not sel:
            break
        loss = sum(mg_per_g(r, "mass_loss_kg") for r in sel) / len(sel)
        dmg = sum(mg_per_g(r, "damage_kg") for r in sel) / len(sel)
        stock = sum(mg_per_g(v[lo], "damage_stock_kg") for v in by.values() if len(v) > lo) / len(by)
        print(f"{lo + 1:4d}-{lo + window:<4d} {loss:6.2f}  {dmg:6.2f}  {loss / dmg if dmg else float('nan'):7.2f}  {stock:8.1f}")


def mechanism(paths):
    print("file  angle  impacts  removed with D before the impact <1/4 <1/2 <3/4 >=3/4   largest Δε_p of one particle in one impact: median, max")
    for path in paths:
        rows = load(path)["rows"]
        for a in sorted({r["angle_deg"] for r in rows}):
            rs = [r for r in rows if r["angle_deg"] == a]
            cut = [sum(r["removed_by_start_damage_kg"][i] for r in rs) for i in range(4)]
            tot = sum(cut) or float("nan")
            # base.json came from the first build of the study, before the field existed.
            de = sorted(r["max_plastic_increment"] for r in rs if "max_plastic_increment" in r)
            peak = f"{de[len(de) // 2]:.2f}, {de[-1]:.2f}" if de else "-"
            print(f"{path}  {a:4.0f}  {len(rs):5d}  " + " ".join(f"{c / tot:5.2f}" for c in cut)
                  + f"   {peak}")


if __name__ == "__main__":
    if sys.argv[1] == "angles":
        angles(sys.argv[2], sys.argv[3:])
    elif sys.argv[1] == "mechanism":
        mechanism(sys.argv[2:])
    else:
        life(sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 20)
