"""The damage stock across the box, strip by strip, and its growth, from `surface_profile --across`.

usage: across.py ACROSS.tsv CAMPAIGN CELL LO HI
Pairs CAMPAIGN's CELL checkpoints at LO and HI impacts by sample (paths
.../CAMPAIGN/cCELL-SAMPLE-IMPACTS.ckpt) and prints, per 0.25 Dg strip (x from the box's
middle; a grain at an angle travels towards +x), the stock at HI and its growth per impact over
LO..HI, mean ± standard error over the samples, in mg per g of one grain.
"""
import sys

from kept import mean_se, paired, which

path, campaign, cell, lo, hi = sys.argv[1:6]
lo, hi = int(lo), int(hi)
by = {}
for line in open(path).read().splitlines()[1:]:
    ckpt, n, _, x0, x1, stock = line.split("\t")
    w = which(ckpt, campaign)
    n = int(n)
    if w and w[0] == cell and n in (lo, hi):
        by.setdefault(w[1], {}).setdefault(n, {})[(float(x0), float(x1))] = float(stock)
pairs = paired(by, lo, hi, f"{campaign} cell {cell}")


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
