#!/usr/bin/env python3
"""Medians of pairs.sh tables: old and new user CPU time, their ratio, per-pair ratios, md5 count.

usage: medians_pairs.py times-*.tsv
"""
import sys,statistics as st
for f in sys.argv[1:]:
    rows=[l.split('\t') for l in open(f).read().split('\n')[1:] if l]
    o={r[0]:float(r[2]) for r in rows if r[1]=='old'}; n={r[0]:float(r[2]) for r in rows if r[1]=='new'}
    md5=set(r[4] for r in rows)
    rat=[n[k]/o[k] for k in o]
    print(f"{f}: pairs {len(rat)} median old {st.median(o.values()):.3f} new {st.median(n.values()):.3f} ratio of medians {st.median(n.values())/st.median(o.values()):.3f} pair ratios {min(rat):.3f}-{max(rat):.3f} md5s {len(md5)}")
