"""The damage stock under the aim band, split into the skin (the top SKIN_DX particle layers)
and the rest, and the mean damage per layer, from `surface_profile --band-depth` output.

usage: summarise.py BAND_DEPTH.tsv [LABEL=PATTERN ...]
Rows are grouped by (label, angle, particles per Dg, impacts); a checkpoint's label is the
first LABEL whose PATTERN occurs in its path (default: its folder's name). Stock and mass are
in mg per g of one grain; ± is the standard error over the checkpoints of a group.
"""
import collections
import statistics as st
import sys

SKIN_DX = 2.5


def label_of(path, labels):
    for label, pattern in labels:
        if pattern in path:
            return label
    return path.split("/")[-2]


def mean_se(xs):
    if len(xs) < 2:
        return f"{xs[0]:.0f}"
    return f"{st.mean(xs):.0f} ± {st.stdev(xs) / len(xs) ** 0.5:.0f}"


def main():
    labels = [a.split("=", 1) for a in sys.argv[2:]]
    rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1])][1:]
    per_ckpt = collections.defaultdict(lambda: collections.defaultdict(lambda: [0.0, 0.0]))
    group_of = {}
    for path, impacts, angle, ppd, _line, lo, hi, stock, mass in rows:
        group_of[path] = (label_of(path, labels), float(angle), float(ppd), int(impacts))
        b = per_ckpt[path][(float(lo), float(hi))]
        b[0] += float(stock)
        b[1] += float(mass)
    groups = collections.defaultdict(list)
    for path, bins in per_ckpt.items():
        groups[group_of[path]].append(bins)
    print("| run | angle | per Dg | impacts | checkpoints | skin (top 2.5 Δx) | below it | all |"
          " skin × per Dg | mean D, layers 1 / 2 / 3 |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for key in sorted(groups):
        label, angle, ppd, impacts = key
        cks = groups[key]
        skin = [sum(s for (lo, hi), (s, m) in b.items() if hi <= SKIN_DX) for b in cks]
        deep = [sum(s for (lo, hi), (s, m) in b.items() if hi > SKIN_DX) for b in cks]
        layers = sorted(cks[0])[:3]
        mean_d = []
        for k in layers:
            s = sum(b[k][0] for b in cks)
            m = sum(b[k][1] for b in cks)
            mean_d.append(f"{s / m:.2f}" if m > 0 else "–")
        print(f"| {label} | {angle:.0f}° | {ppd:.0f} | {impacts} | {len(cks)} | {mean_se(skin)} |"
              f" {mean_se(deep)} | {mean_se([a + b for a, b in zip(skin, deep)])} |"
              f" {st.mean(skin) * ppd:.0f} | {' / '.join(mean_d)} |")


if __name__ == "__main__":
    main()
