"""The damage stock across the box, strip by strip, and its growth, from `surface_profile --across`.

usage: across.py ACROSS.tsv CAMPAIGN CELL LO HI
Pairs CAMPAIGN's CELL checkpoints at LO and HI impacts by sample (paths
.../CAMPAIGN/cCELL-SAMPLE-IMPACTS.ckpt) and prints, per 0.25 Dg strip (x from the box's
middle; a grain at an angle travels towards +x), the stock at HI and its growth per impact over
LO..HI, mean ± standard error over the samples, in mg per g of one grain.
"""
import math
import sys

path, campaign, cell, lo, hi = sys.argv[1:6]
lo, hi = int(lo), int(hi)
by = {}
for line in open(path).read().splitlines()[1:]:
    ckpt, n, _, x0, x1, stock = line.split("\t")
    parts = ckpt.split("/")
    if len(parts) < 2 or parts[-2] != campaign:
        continue
    # The impacts a checkpoint holds are its own, not its file name's.
    c, s, _ = parts[-1][1:].removesuffix(".ckpt").split("-")
    n = int(n)
    if c == cell and n in (lo, hi):
        by.setdefault(int(s), {}).setdefault(n, {})[(float(x0), float(x1))] = float(stock)
pairs = [v for v in by.values() if lo in v and hi in v]
if not pairs:
    sys.exit(f"no sample of {campaign} cell {cell} has checkpoints at both {lo} and {hi}")


def mean_se(xs):
    m = sum(xs) / len(xs)
    if len(xs) < 2:
        return m, float("nan")
    return m, math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1) / len(xs))


print(f"{campaign} cell {cell}, impacts {lo}-{hi}, {len(pairs)} samples")
print(f"| x (Dg) | stock at {hi} | growth per impact |")
print("|---|---|---|")
for strip in sorted(pairs[0][hi]):
    level = mean_se([p[hi][strip] for p in pairs])
    grow = mean_se([(p[hi][strip] - p[lo][strip]) / (hi - lo) for p in pairs])
    print(
        f"| {strip[0]:+.2f} to {strip[1]:+.2f} | {level[0]:.0f} ± {level[1]:.0f} "
        f"| {grow[0]:+.3f} ± {grow[1]:.3f} |"
    )
