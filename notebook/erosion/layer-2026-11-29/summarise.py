"""The damage stock under the aim band, split into the skin (the top SKIN_DX particle layers)
and the rest, and the mean damage of the top three layers, from `surface_profile --band-depth`
output.

usage: summarise.py BAND_DEPTH.tsv [--pool FROM TO] [LABEL=PATTERN ...]
Without --pool, one row per (label, angle, particles per Dg, impacts), ± the standard error over
its checkpoints. With --pool, one row per (label, angle, particles per Dg): each sample's
checkpoints with FROM <= impacts <= TO are averaged, ± the standard error over samples (a
checkpoint named cCELL-SAMPLE-UNITS.ckpt). A checkpoint's label is the first LABEL whose
PATTERN occurs in its path (default: its folder's name). Stock and mass are in mg per g of one
grain.
"""
import collections
import re
import statistics as st
import sys

SKIN_DX = 2.5


def mean_se(xs):
    if len(xs) < 2:
        return f"{xs[0]:.0f}"
    return f"{st.mean(xs):.0f} ± {st.stdev(xs) / len(xs) ** 0.5:.0f}"


def read(path, labels):
    """Per checkpoint: (label, angle, ppd, impacts, sample) and its bins {(lo, hi): [stock, mass]}."""
    bins = collections.defaultdict(lambda: collections.defaultdict(lambda: [0.0, 0.0]))
    key = {}
    for row in [l.rstrip("\n").split("\t") for l in open(path)][1:]:
        ckpt, impacts, angle, ppd, _line, lo, hi, stock, mass = row
        label = next((l for l, p in labels if p in ckpt), ckpt.split("/")[-2])
        sample = re.search(r"c(\d+)-(\d+)-\d+\.ckpt$", ckpt)
        key[ckpt] = (label, float(angle), float(ppd), int(impacts),
                     sample.group(2) if sample else ckpt)
        b = bins[ckpt][(float(lo), float(hi))]
        b[0] += float(stock)
        b[1] += float(mass)
    return key, bins


def figures(b):
    """Skin stock, stock below it, and per top layer (stock, mass)."""
    skin = sum(s for (lo, hi), (s, m) in b.items() if hi <= SKIN_DX)
    deep = sum(s for (lo, hi), (s, m) in b.items() if hi > SKIN_DX)
    layers = [b[k] for k in sorted(b)[:3]]
    return skin, deep, layers


def row(name, n, per_unit, ppd):
    skin = [f[0] for f in per_unit]
    deep = [f[1] for f in per_unit]
    mean_d = []
    for k in range(3):
        s = sum(f[2][k][0] for f in per_unit)
        m = sum(f[2][k][1] for f in per_unit)
        mean_d.append(f"{s / m:.2f}" if m > 0 else "–")
    print(f"| {name} | {n} | {mean_se(skin)} | {mean_se(deep)} |"
          f" {mean_se([a + b for a, b in zip(skin, deep)])} | {st.mean(skin) * ppd:.0f} |"
          f" {' / '.join(mean_d)} |")


def main():
    args = sys.argv[2:]
    pool = None
    if args[:1] == ["--pool"]:
        pool = (int(args[1]), int(args[2]))
        args = args[3:]
    key, bins = read(sys.argv[1], [a.split("=", 1) for a in args])
    unit = "samples" if pool else "checkpoints"
    print(f"| run, angle, per Dg, impacts | {unit} | skin (top {SKIN_DX} Δx) | below it | all |"
          " skin × per Dg | mean D, layers 1 / 2 / 3 |")
    print("|---|---|---|---|---|---|---|")
    groups = collections.defaultdict(list)
    for ckpt, (label, angle, ppd, impacts, sample) in key.items():
        if pool is None:
            groups[(label, angle, ppd, impacts)].append(figures(bins[ckpt]))
        elif pool[0] <= impacts <= pool[1]:
            groups[(label, angle, ppd, sample)].append(figures(bins[ckpt]))
    if pool is None:
        for (label, angle, ppd, impacts), fs in sorted(groups.items()):
            row(f"{label}, {angle:.0f}°, {ppd:.0f}, {impacts}", len(fs), fs, ppd)
        return
    by_cell = collections.defaultdict(list)
    for (label, angle, ppd, sample), fs in groups.items():
        n = len(fs)
        layers = [[sum(f[2][k][j] for f in fs) / n for j in range(2)] for k in range(3)]
        by_cell[(label, angle, ppd)].append(
            (sum(f[0] for f in fs) / n, sum(f[1] for f in fs) / n, layers))
    for (label, angle, ppd), fs in sorted(by_cell.items()):
        row(f"{label}, {angle:.0f}°, {ppd:.0f}, {pool[0]}–{pool[1]}", len(fs), fs, ppd)


if __name__ == "__main__":
    main()
