"""One sample's stock across the box at each of its kept checkpoints, from `surface_profile --across`.

usage: history.py ACROSS.tsv CAMPAIGN CELL SAMPLE
Prints a row per checkpoint (by the impacts it holds): the stock per 0.25 Dg strip from the
box's left (upstream) side to its right, in mg per g of one grain.
"""
import sys

from kept import which

path, campaign, cell, sample = sys.argv[1:5]
rows = {}
for line in open(path).read().splitlines()[1:]:
    ckpt, n, _, x0, _, stock = line.split("\t")
    if which(ckpt, campaign) == (cell, int(sample)):
        rows.setdefault(int(n), {})[float(x0)] = float(stock)
if not rows:
    sys.exit(f"no checkpoint of {campaign} cell {cell} sample {sample}")
strips = sorted(next(iter(rows.values())))
print("| impacts | " + " | ".join(f"{x:+.2f}" for x in strips) + " |")
print("|---" * (len(strips) + 1) + "|")
for n in sorted(rows):
    print(f"| {n} | " + " | ".join(f"{rows[n][x]:.0f}" for x in strips) + " |")
