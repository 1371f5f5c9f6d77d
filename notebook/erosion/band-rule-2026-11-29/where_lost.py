"""Where the loss is made: `surface_profile --removed` rows pooled per cell and block of impacts.
usage: where_lost.py REMOVED.tsv BLOCK [FIRST]
Per angle and block: the mass removed per impact (mg/g) under the aim band (|x| <= 0.5 Dg),
within 0.5 Dg outside it on each side (the trench's walls and lips), and further out, mean ±
standard error over the samples that have every pair of the block."""
import collections
import math
import re
import sys


def mean_se(xs):
    m = sum(xs) / len(xs)
    if len(xs) < 2:
        return f"{m:.2f}"
    return f"{m:.2f} ± {math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1) / len(xs)):.2f}"


def zone(lo, hi):
    mid = 0.5 * (lo + hi)
    if abs(mid) <= 0.5:
        return "band"
    if abs(mid) <= 1.0:
        return "upstream walls" if mid < 0 else "downstream walls"
    return "further out"


ZONES = ["band", "upstream walls", "downstream walls", "further out"]


def pool(path, block, first=0):
    """{(angle, sample, block start): {zone: removed}} over the samples that have every pair of
    the block (mg per g of one grain, summed over the block's pairs)."""
    got = collections.defaultdict(lambda: collections.defaultdict(float))
    span = collections.defaultdict(int)
    rows = [l.rstrip("\n").split("\t") for l in open(path)][1:]
    for r in rows:
        s = re.search(r"c(\d+)-(\d+)-\d+\.ckpt$", r[0]).group(2)
        a, b, angle = int(r[1]), int(r[2]), r[3]
        if a < first:
            continue
        start = first + (a - first) // block * block
        if b > start + block:
            continue
        got[(angle, s, start)][zone(float(r[4]), float(r[5]))] += float(r[6])
        if float(r[4]) == float(rows[0][4]):
            span[(angle, s, start)] += b - a
    return {k: v for k, v in got.items() if span[k] == block}


def main():
    path, block = sys.argv[1], int(sys.argv[2])
    first = int(sys.argv[3]) if len(sys.argv) > 3 else 0
    got = pool(path, block, first)
    print("| angle | impacts | samples | all | " + " | ".join(ZONES) + " | share outside the band |")
    print("|---|---|---|---|" + "---|" * len(ZONES) + "---|")
    for angle, start in sorted({(k[0], k[2]) for k in got}, key=lambda k: (float(k[0]), k[1])):
        keys = [k for k in got if k[0] == angle and k[2] == start]
        per = {z: [got[k][z] / block for k in keys] for z in ZONES}
        alls = [sum(got[k].values()) / block for k in keys]
        out = [1 - got[k]["band"] / sum(got[k].values()) for k in keys if sum(got[k].values()) > 0]
        print(f"| {angle}° | {start + 1}–{start + block} | {len(keys)} | {mean_se(alls)} | "
              + " | ".join(mean_se(per[z]) for z in ZONES) + f" | {mean_se(out) if out else '-'} |")


if __name__ == "__main__":
    main()
