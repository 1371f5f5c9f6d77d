"""Means ± standard errors over the samples of each `surface_profile --stock` table given:
the damage stock (mg per g of one grain) under the aim band and outside it, with the surface
line's length (Dg), one Markdown row per file, sorted by rung, angle and impacts."""
import statistics as st
import sys


def mean_se(v):
    m = st.mean(v)
    se = st.stdev(v) / len(v) ** 0.5 if len(v) > 1 else float("nan")
    return m, se


rows = []
for f in sys.argv[1:]:
    lines = [l.split("\t") for l in open(f).read().splitlines()]
    head, body = lines[0], lines[1:]
    if not body:
        continue
    col = lambda name: [float(r[head.index(name)]) for r in body]
    stock, band = col("stock"), col("band_stock")
    outside = [s - b for s, b in zip(stock, band)]
    deep = [a + b for a, b in zip(col("d<0.4"), col("d>=0.4"))]
    rows.append((f, int(body[0][1]), float(body[0][2]), len(body), col("line_dg"), band, outside, deep))


def key(r):
    name = r[0].rsplit("/", 1)[-1]
    return (int(name.split("-")[0]), r[2], r[1])


print("| rung (per Dg) | angle | impacts | samples | surface line (Dg) | stock under the band | stock outside it | of it ≥ 0.2 Dg deep (all) |")
print("|---|---|---|---|---|---|---|---|")
for f, n, angle, k, line, band, outside, deep in sorted(rows, key=key):
    rung = f.rsplit("/", 1)[-1].split("-")[0]
    cells = [mean_se(line), mean_se(band), mean_se(outside), mean_se(deep)]
    print(
        f"| {rung} | {angle:g}° | {n} | {k} | {cells[0][0]:.2f} ± {cells[0][1]:.2f} | "
        + " | ".join(f"{m:.0f} ± {s:.0f}" for m, s in cells[1:])
        + " |"
    )

# How fast each part grows between consecutive tables of one rung and angle, per impact, paired
# over the samples both have (the checkpoint's name carries the sample).
def by_sample(f):
    lines = [l.split("\t") for l in open(f).read().splitlines()]
    head = lines[0]
    out = {}
    for r in lines[1:]:
        sample = r[0].rsplit("/", 1)[-1].split("-")[1]
        stock, band = float(r[head.index("stock")]), float(r[head.index("band_stock")])
        out[sample] = (band, stock - band)
    return out


print()
print("| rung | angle | impacts | samples | under the band, per impact | outside it, per impact |")
print("|---|---|---|---|---|---|")
ordered = sorted(rows, key=key)
for a, b in zip(ordered, ordered[1:]):
    if key(a)[:2] != key(b)[:2]:
        continue
    sa, sb = by_sample(a[0]), by_sample(b[0])
    common = sorted(set(sa) & set(sb))
    if len(common) < 2:
        continue
    span = b[1] - a[1]
    band = mean_se([(sb[k][0] - sa[k][0]) / span for k in common])
    out = mean_se([(sb[k][1] - sa[k][1]) / span for k in common])
    rung = a[0].rsplit("/", 1)[-1].split("-")[0]
    print(f"| {rung} | {a[2]:g}° | {a[1]}–{b[1]} | {len(common)} | {band[0]:+.2f} ± {band[1]:.2f} | {out[0]:+.2f} ± {out[1]:.2f} |")
