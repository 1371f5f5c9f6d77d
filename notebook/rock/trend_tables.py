"""Issue 37 part 5: the three rock trend campaigns beside the AWJ paper.
Reads the results.json of examples/rock-trends.json, rock-massflow.json and rock-400.json
(grit run --out DIR) and prints each trend with its fit and standard errors.
Usage: python3 notebook/rock/trend_tables.py TRENDS_DIR MASSFLOW_DIR R400_DIR"""
import json
import math
import sys


def load(d):
    return json.load(open(f"{d}/results.json"))


def fit(xs, ys):
    """Least-squares line through (x, y) over every sample: slope, its standard error,
    intercept."""
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    b = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx
    a = my - b * mx
    res = sum((y - a - b * x) ** 2 for x, y in zip(xs, ys))
    se = math.sqrt(res / (n - 2) / sxx) if n > 2 else float("nan")
    return b, se, a


def per_sample(c, key, scale):
    return [s[key] * scale for s in c["per_sample"]]


def rock_at_t(s, key, scale=1.0):
    return (s.get("rock") or {}).get(key, 0.0) * scale


def ms(v):
    n = len(v)
    m = sum(v) / n
    sd = math.sqrt(sum((x - m) ** 2 for x in v) / (n - 1)) if n > 1 else float("nan")
    return m, sd


def trends(r):
    print("## v_jet trend (paper Fig. 26, 30 ms: Cd and Cw linear in v_jet, Cd steeper; "
          "sandstone craters larger)")
    t_ms = r["cells"][0]["time_ms"]
    print(f"at {t_ms} ms; mean ± std over samples; slopes fitted through every sample, ± s.e.")
    groups = {}
    for c in r["cells"]:
        groups.setdefault(c["material"], []).append(c)
    print(f"{'material':<24} {'v m/s':>6} {'n':>2} {'Cd mm':>13} {'Cw mm':>13} {'loss g/m':>13} "
          f"{'fractured':>9} {'cracks':>6}")
    for mat, cells in groups.items():
        xs, cd, cw = [], [], []
        for c in sorted(cells, key=lambda c: c["velocity_m_s"]):
            d = per_sample(c, "crater_depth_m", 1e3)
            w = per_sample(c, "crater_width_m", 1e3)
            l = per_sample(c, "mass_loss_kg_m", 1e3)
            fr = [rock_at_t(s, "fractured_particles") for s in c["per_sample"]]
            cr = [rock_at_t(s, "crack_count") for s in c["per_sample"]]
            xs += [c["velocity_m_s"]] * len(d)
            cd += d
            cw += w
            (md, sd), (mw, sw), (ml, sl) = ms(d), ms(w), ms(l)
            print(f"{mat:<24} {c['velocity_m_s']:>6.0f} {len(d):>2} {md:6.3f} ± {sd:5.3f} "
                  f"{mw:6.3f} ± {sw:5.3f} {ml:6.3f} ± {sl:5.3f} {ms(fr)[0]:9.0f} {ms(cr)[0]:6.1f}")
        bd, sed, _ = fit(xs, cd)
        bw, sew, _ = fit(xs, cw)
        print(f"{mat:<24} slopes: dCd/dv = {bd*1e3:6.2f} ± {sed*1e3:5.2f} µm/(m/s) "
              f"({bd/sed:+.1f} s.e.), dCw/dv = {bw*1e3:6.2f} ± {sew*1e3:5.2f} µm/(m/s) "
              f"({bw/sew:+.1f} s.e.)")
    print()


def massflow(r):
    print("## M trend (paper Figs. 27-28, 350 m/s, 30 ms: Cd 6.58 -> 9.51 mm from 0.02 to 0.06 "
          "kg/s, linear up to M_cri = 0.055, then a jump with a bottom crack; Cw about 1.73 mm)")
    print(f"{'M kg/s':>7} {'n':>2} {'Cd mm':>13} {'Cw mm':>13} {'loss g/m':>13} "
          f"{'bottom crack mm':>15} {'cracks':>6} {'fractured':>9}")
    xs, cd, loss = [], [], []
    rows = []
    for c in sorted(r["cells"], key=lambda c: c["mass_flow_kg_s"]):
        d = per_sample(c, "crater_depth_m", 1e3)
        w = per_sample(c, "crater_width_m", 1e3)
        l = per_sample(c, "mass_loss_kg_m", 1e3)
        b = [rock_at_t(s, "crack_depth_below_crater_m", 1e3) for s in c["per_sample"]]
        cr = [rock_at_t(s, "crack_count") for s in c["per_sample"]]
        fr = [rock_at_t(s, "fractured_particles") for s in c["per_sample"]]
        m = c["mass_flow_kg_s"]
        rows.append((m, ms(d)[0], ms(l)[0]))
        if m <= 0.055:
            xs += [m] * len(d)
            cd += d
            loss += l
        (md, sd), (mw, sw), (ml, sl), (mb, sb) = ms(d), ms(w), ms(l), ms(b)
        print(f"{m:7.3f} {len(d):>2} {md:6.3f} ± {sd:5.3f} {mw:6.3f} ± {sw:5.3f} "
              f"{ml:6.3f} ± {sl:5.3f} {mb:7.3f} ± {sb:5.3f} {ms(cr)[0]:6.1f} {ms(fr)[0]:9.0f}")
    bd, sed, ad = fit(xs, cd)
    bl, sel, al = fit(xs, loss)
    print(f"fit over M <= 0.055: dCd/dM = {bd:.2f} ± {sed:.2f} mm per kg/s ({bd/sed:+.1f} s.e.), "
          f"dloss/dM = {bl:.2f} ± {sel:.2f} g/m per kg/s ({bl/sel:+.1f} s.e.)")
    for m, d, l in rows:
        if m > 0.055:
            print(f"at M = {m}: Cd {d:.3f} mm against {ad + bd*m:.3f} from the line; "
                  f"loss {l:.3f} against {al + bl*m:.3f}")
    print(f"paper: dCd/dM = {(9.51-6.58)/0.04:.1f} mm per kg/s over 0.02-0.06 at 30 ms")
    print()


def r400(r):
    print("## 400 m/s (paper Figs. 22-23: two radial cracks from the water hammer at 0.125 ms, "
          "before the grains at 0.25 ms; loss from the start, linear after 0.9 ms; Cw constant "
          "and Cd linear after 4 ms)")
    c = r["cells"][0]
    firsts = [s.get("first_grain_slice") for s in c["per_sample"]]
    ser = c["mean_series"]
    print("first grain touching the target, per sample: slice",
          firsts, "t =", [round(ser[k - 1]["t_s"] * 1e6, 1) if k else None for k in firsts], "µs")
    print(f"{'t µs':>6} {'Cd mm':>6} {'Cw mm':>6} {'loss g/m':>8} {'cracks':>6} {'length mm':>9} "
          f"{'fractured':>9}")
    step = max(1, len(ser) // 24)
    for p in ser[::step] + ([ser[-1]] if (len(ser) - 1) % step else []):
        rk = p.get("rock") or {}
        g = lambda k: (rk.get(k) or {}).get("mean", float("nan"))
        print(f"{p['t_s']*1e6:6.1f} {p['crater_depth_m']*1e3:6.3f} {p['crater_width_m']*1e3:6.3f} "
              f"{p['mass_loss_kg_m']*1e3:8.3f} {g('crack_count'):6.2f} "
              f"{g('crack_length_m')*1e3:9.3f} {g('fractured_particles'):9.0f}")
    # The linear stage: slopes of the mean loss over successive 50 µs windows against the
    # last window's; the onset is the first window from which every later one agrees with the
    # late slope within 2 standard errors of the fits.
    pts = [(p["t_s"] * 1e3, p["mass_loss_kg_m"] * 1e3) for p in ser]  # ms, g/m
    w = max(3, round(0.05 / (pts[1][0] - pts[0][0])))
    wins = []
    for k in range(0, len(pts) - w + 1, w):
        xs, ys = zip(*pts[k:k + w])
        b, se, _ = fit(list(xs), list(ys))
        wins.append((xs[0], xs[-1], b, se))
    late = wins[-1]
    onset = None
    for i in range(len(wins)):
        if all(abs(b - late[2]) <= 2 * math.hypot(se, late[3]) for _, _, b, se in wins[i:]):
            onset = wins[i][0]
            break
    print("loss slope per 50 µs window (g/m per ms):",
          ", ".join(f"{a*1e3:.0f}-{z*1e3:.0f} µs {b:.1f}±{se:.1f}" for a, z, b, se in wins))
    print(f"linear from {onset*1e3:.0f} µs on (every later window within 2 s.e. of the last)"
          if onset is not None else "no linear stage within the run")
    s3 = c["stage3"]
    print("stage 3:", "steady" if s3["steady"] else "not steady", "-", s3["reason"])
    print()


if __name__ == "__main__":
    dirs = sys.argv[1:4]
    for f, d in zip([trends, massflow, r400], dirs):
        try:
            f(load(d))
        except FileNotFoundError:
            print(f"(no results in {d} yet)\n")
