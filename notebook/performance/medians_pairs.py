#!/usr/bin/env python3
"""Medians of pairs.sh tables: old and new user CPU time, their ratio, per-pair ratios, md5 count.

usage: medians_pairs.py times-*.tsv
"""
import statistics as st
import sys

for f in sys.argv[1:]:
    rows = [line.split("\t") for line in open(f).read().split("\n")[1:] if line]
    old = {r[0]: float(r[2]) for r in rows if r[1] == "old"}
    new = {r[0]: float(r[2]) for r in rows if r[1] == "new"}
    ratios = [new[k] / old[k] for k in old]
    mo, mn = st.median(old.values()), st.median(new.values())
    print(
        f"{f}: pairs {len(ratios)} median old {mo:.3f} new {mn:.3f} ratio of medians {mn / mo:.3f} "
        f"pair ratios {min(ratios):.3f}-{max(ratios):.3f} md5s {len({r[4] for r in rows})}"
    )
