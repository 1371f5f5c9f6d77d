"""The two boxes' stocks paired sample by sample, from `surface_profile --band-depth` and
`--walls` run on the kept checkpoints of both runs (paths .../std/cC-S-N.ckpt, .../big/cC-S-N.ckpt).

usage: paired.py BAND_DEPTH.tsv WALLS.tsv IMPACTS...
Per cell and age: the stock under the band (|x| <= 0.5 Dg), its skin (top 2.5 dx) and the
rest, and the whole surface's stock, in each box and the paired difference big - std, mean ±
standard error over the samples both boxes have (mg per g of one grain).
"""
import collections
import math
import re
import sys

ANGLE = {"0": "45°", "1": "90°"}


def key(path):
    m = re.search(r"(std|big)/c(\d+)-(\d+)-\d+\.ckpt$", path)
    return (m.group(1), m.group(2), m.group(3)) if m else None


def mean_se(xs):
    m = sum(xs) / len(xs)
    if len(xs) < 2:
        return f"{m:.0f}"
    return f"{m:.0f} ± {math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1) / len(xs)):.0f}"


def main():
    band, walls, ages = sys.argv[1], sys.argv[2], [int(a) for a in sys.argv[3:]]
    v = collections.defaultdict(lambda: collections.defaultdict(float))
    for r in [l.rstrip("\n").split("\t") for l in open(band)][1:]:
        k = key(r[0])
        if k:
            at = (k, int(r[1]))
            v[at]["band"] += float(r[7])
            v[at]["skin" if float(r[6]) <= 2.5 else "below"] += float(r[7])
    rows = [l.rstrip("\n").split("\t") for l in open(walls)]
    col = rows[0].index("stock")
    for r in rows[1:]:
        k = key(r[0])
        if k:
            v[(k, int(r[1]))]["whole"] = float(r[col])
    print("| cell | impacts | samples | measure | 3.0 Dg box | 4.5 Dg box | difference |")
    print("|---|---|---|---|---|---|---|")
    for cell in ("0", "1"):
        for age in ages:
            samples = sorted({k[2] for (k, n) in v if k[1] == cell and n == age and k[0] == "big"
                              and (("std", cell, k[2]), age) in v})
            if not samples:
                continue
            for what in ("band", "skin", "below", "whole"):
                s = [v[(("std", cell, x), age)][what] for x in samples]
                b = [v[(("big", cell, x), age)][what] for x in samples]
                print(f"| {ANGLE[cell]} | {age} | {len(samples)} | {what} | {mean_se(s)} |"
                      f" {mean_se(b)} | {mean_se([q - p for p, q in zip(s, b)])} |")


if __name__ == "__main__":
    main()
