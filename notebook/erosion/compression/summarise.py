#!/usr/bin/env python3
"""Tables and a chart from the CSVs of `examples/stored_compression.rs` (standard library only).

usage: python3 summarise.py DIR [CONFIG ...]
Prints markdown tables of 10-impact window means and writes DIR/pressure.svg.
"""
import csv
import sys
from pathlib import Path

K = 166.7e9  # bulk modulus of AISI 304 in the engine (E / 3(1 - 2 nu)), Pa
RHO0 = 7890.0
WINDOWS = [(1, 10), (41, 50), (91, 100), (141, 150), (191, 200), (241, 250), (291, 300)]
COLOURS = {"small": "#1f77b4", "wide": "#d62728", "sponge": "#2ca02c", "shallow": "#9467bd",
           "wide-r1": "#ff7f0e", "small-nofilter": "#17becf", "wide-nofilter": "#8c564b"}


def load(path):
    rows = {}
    with open(path) as f:
        for r in csv.DictReader(f):
            rows.setdefault(r["region"], {})[int(r["impact"])] = r
    return rows


def window_mean(by_impact, lo, hi, key):
    vals = [float(by_impact[k][key]) for k in range(lo, hi + 1) if k in by_impact]
    return (sum(vals) / len(vals), len(vals)) if vals else (None, 0)


def table(data):
    print("| box | impacts | band p (MPa) | band ρ | band ρ0/det F | band ρ0/det F_geo | "
          "band ρ − ρ0/det F | p from ρ0/det F (MPa) | deep p (MPa) | side p (MPa) | "
          "side ρ − ρ0/det F | fixed ρ − ρ0/det F | all free ρ − ρ0/det F | erosion (mg/g) |")
    print("|" + "---|" * 14)
    for cfg, rows in data.items():
        band, deep, side, fixed, every = (rows.get(r, {}) for r in
                                          ("band_0.5_0.75", "deep_0.5", "side_0.8", "fixed", "all"))
        for lo, hi in WINDOWS:
            p, n = window_mean(band, lo, hi, "mean_p_eos")
            if n < hi - lo + 1:
                continue
            m = lambda reg, key: window_mean(reg, lo, hi, key)[0]
            rho_kin = m(band, "mean_rho_kin")
            print(f"| {cfg} | {lo}–{hi} | {p / 1e6:.0f} | {m(band, 'mean_rho'):.1f} | "
                  f"{rho_kin:.1f} | {m(band, 'mean_rho_geo'):.1f} | "
                  f"{m(band, 'mean_drift'):+.1f} | {K * (rho_kin / RHO0 - 1) / 1e6:.0f} | "
                  f"{m(deep, 'mean_p_eos') / 1e6:.0f} | {m(side, 'mean_p_eos') / 1e6:.0f} | "
                  f"{m(side, 'mean_drift'):+.1f} | {m(fixed, 'mean_drift'):+.1f} | "
                  f"{m(every, 'mean_drift'):+.1f} | {float(every[hi]['erosion_mg_g']):.2f} |")


def svg(data, out):
    w, h, left, top, pw, ph = 760, 420, 70, 20, 640, 340
    imax = max(max(r["band_0.5_0.75"]) for r in data.values())
    pmin, pmax = -600.0, 600.0
    x = lambda k: left + pw * k / imax
    y = lambda p: top + ph * (pmax - p) / (pmax - pmin)
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" '
             'font-family="sans-serif" font-size="12">',
             f'<rect x="{left}" y="{top}" width="{pw}" height="{ph}" fill="none" stroke="#000"/>']
    for p in range(int(pmin), int(pmax) + 1, 200):
        parts.append(f'<line x1="{left}" x2="{left + pw}" y1="{y(p)}" y2="{y(p)}" '
                     'stroke="#ddd"/>')
        parts.append(f'<text x="{left - 6}" y="{y(p) + 4}" text-anchor="end">{p}</text>')
    for k in range(0, imax + 1, 50):
        parts.append(f'<text x="{x(k)}" y="{top + ph + 16}" text-anchor="middle">{k}</text>')
    parts.append(f'<text x="{left + pw / 2}" y="{h - 4}" text-anchor="middle">impacts</text>')
    parts.append(f'<text x="14" y="{top + ph / 2}" transform="rotate(-90 14 {top + ph / 2})" '
                 'text-anchor="middle">mean pressure 0.5–0.75 Dg deep (MPa)</text>')
    ly = top + 14
    for cfg, rows in data.items():
        band = rows["band_0.5_0.75"]
        ks = sorted(k for k in band if k > 0)
        c = COLOURS.get(cfg, "#000")
        for key, dash, label in (("mean_p_eos", "", "from ρ (what the engine uses)"),
                                 ("mean_rho_kin", "5,4", "from ρ0/det F (positions)")):
            pts = []
            for k in ks:
                win = [band[j] for j in range(max(1, k - 9), k + 1) if j in band]
                if key == "mean_p_eos":
                    v = sum(float(r[key]) for r in win) / len(win) / 1e6
                else:
                    v = sum(K * (float(r[key]) / RHO0 - 1) for r in win) / len(win) / 1e6
                pts.append(f"{x(k):.1f},{y(max(pmin, min(pmax, v))):.1f}")
            parts.append(f'<polyline fill="none" stroke="{c}" stroke-width="1.5" '
                         f'stroke-dasharray="{dash}" points="{" ".join(pts)}"/>')
            parts.append(f'<line x1="{left + 10}" x2="{left + 40}" y1="{ly - 4}" y2="{ly - 4}" '
                         f'stroke="{c}" stroke-width="1.5" stroke-dasharray="{dash}"/>')
            parts.append(f'<text x="{left + 46}" y="{ly}">{cfg}: {label}</text>')
            ly += 15
    parts.append("</svg>")
    Path(out).write_text("\n".join(parts) + "\n")


def main():
    d = Path(sys.argv[1])
    cfgs = sys.argv[2:] or [p.stem for p in sorted(d.glob("*.csv"))
                            if not p.stem.startswith("probe")]
    data = {c: load(d / f"{c}.csv") for c in cfgs}
    table(data)
    svg(data, d / "pressure.svg")


if __name__ == "__main__":
    main()
