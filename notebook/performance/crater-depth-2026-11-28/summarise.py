"""Means over samples, per impact count, of surface_profile's columns (Dg).
Usage: python3 summarise.py FILE.tsv"""
import csv, statistics as st, sys

rows = list(csv.DictReader(open(sys.argv[1]), delimiter='\t'))
by = {}
for x in rows:
    by.setdefault(int(x['impacts']), []).append(x)
cols = ['lips_dg', 'floor_dg', 'band_recession_dg', 'floor_below_lips_dg']
print('impacts\tsamples\t' + '\t'.join(cols))
for k in sorted(by):
    v = by[k]
    print(f"{k}\t{len(v)}\t" + '\t'.join(f"{st.mean(float(x[c]) for x in v):.3f}" for c in cols))
