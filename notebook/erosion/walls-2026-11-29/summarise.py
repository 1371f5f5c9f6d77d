"""Damage stock by region of the box, and its growth per impact, from `surface_profile --walls`.

usage: summarise.py WALLS.tsv CAMPAIGN CELL LO HI
Takes the checkpoints of CAMPAIGN's CELL (paths .../CAMPAIGN/cCELL-SAMPLE-IMPACTS.ckpt) at LO and
HI impacts, pairs them by sample, and prints each region's stock at HI and its growth per impact
over LO..HI (mean ± standard error over samples; mg per g of one grain).
"""
import sys

from kept import mean_se, paired, which

path, campaign, cell, lo, hi = sys.argv[1:6]
lo, hi = int(lo), int(hi)
rows = [line.rstrip("\n").split("\t") for line in open(path)]
head, rows = rows[0], rows[1:]
col = {name: i for i, name in enumerate(head)}


def regions(r):
    v = {k: float(r[col[k]]) for k in head[4:]}
    return {
        "all": v["stock"],
        "interior": v["stock"] - v["edges<0.5"],
        "edges (≤0.5 Dg)": v["edges<0.5"],
        "upstream side (≤0.5)": v["left<0.5"],
        "downstream side (≤0.5)": v["right<0.5"],
        "bottom (≤0.5)": v["bottom<0.5"],
        "at the walls (≤0.1)": v["sides<0.1"] + v["bottom<0.1"],
    }


by = {}
for r in rows:
    w = which(r[0], campaign)
    n = int(r[col["impacts"]])
    if w and w[0] == cell and n in (lo, hi):
        by.setdefault(w[1], {})[n] = regions(r)
pairs = paired(by, lo, hi, f"{campaign} cell {cell}")


print(f"{campaign} cell {cell}, impacts {lo}-{hi}, {len(pairs)} samples")
print("| region | stock at %d | growth per impact |" % hi)
print("|---|---|---|")
for k in pairs[0][hi]:
    level = mean_se([p[hi][k] for p in pairs])
    grow = mean_se([(p[hi][k] - p[lo][k]) / (hi - lo) for p in pairs])
    print(f"| {k} | {level[0]:.0f} ± {level[1]:.0f} | {grow[0]:+.2f} ± {grow[1]:.2f} |")
