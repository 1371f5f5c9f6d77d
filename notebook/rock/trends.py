"""The v_jet trend (issue 37 part 5) from notebook/rock/trends/*.json: per material and speed,
Cd, Cw and the mass loss at the last slice (mean ± sample sd over the seeds), and the
least-squares slopes of Cd and Cw against v_jet through the cell means.
Usage: python3 notebook/rock/trends.py [DIR]"""
import glob, json, statistics as st, sys, os

d = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "trends")
cells = {}
for f in sorted(glob.glob(os.path.join(d, "*.json"))):
    r = json.load(open(f))
    m, v = r["params"]["material"], r["params"]["velocity_m_s"]
    last = r["series"][-1]
    cells.setdefault((m, v), []).append(last)

def ms(xs):
    return st.mean(xs), (st.stdev(xs) if len(xs) > 1 else float("nan"))

def slope(xs, ys):
    mx, my = st.mean(xs), st.mean(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)

print(f"{'material':10s} {'v m/s':>6s} {'n':>2s} {'t us':>5s} {'Cd mm':>14s} {'Cw mm':>14s} {'loss g/m':>14s} {'fractured':>10s} {'cracks':>7s}")
for m in ("sandstone", "granite"):
    vs, cds, cws = [], [], []
    for v in sorted(x for (mm, x) in cells if mm == m):
        pts = cells[(m, v)]
        cd, cw, lo = (ms([p[k] * s for p in pts]) for k, s in
                      (("crater_depth_m", 1e3), ("crater_width_m", 1e3), ("mass_loss_kg_m", 1e3)))
        fr = st.mean(p["fractured_particles"] for p in pts)
        cr = st.mean(p["crack_count"] for p in pts)
        print(f"{m:10s} {v:6.0f} {len(pts):2d} {pts[0]['t_s']*1e6:5.1f} {cd[0]:7.3f} ± {cd[1]:5.3f} {cw[0]:7.3f} ± {cw[1]:5.3f} {lo[0]:7.3f} ± {lo[1]:5.3f} {fr:10.0f} {cr:7.1f}")
        vs.append(v); cds.append(cd[0]); cws.append(cw[0])
    if len(vs) > 1:
        print(f"{m:10s} slopes: dCd/dv = {slope(vs, cds)*1e3:.2f} µm/(m/s), dCw/dv = {slope(vs, cws)*1e3:.2f} µm/(m/s)")
