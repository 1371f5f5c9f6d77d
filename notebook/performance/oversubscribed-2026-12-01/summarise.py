"""Medians and means of the user CPU seconds in times.txt (one line per run: NAME USER WALL),
grouped by the condition letter that starts the name.
Usage: python3 summarise.py times.txt"""
import statistics as st, sys

names = {'A': 'beside every run (10 engine threads)', 'B': 'two side by side, runs stopped',
         'C': 'one alone, runs stopped', 'D': 'three side by side, runs stopped'}
groups = {}
for line in open(sys.argv[1]):
    name, user, _ = line.split()
    groups.setdefault(name[0], []).append(float(user))
for k in sorted(groups):
    x = groups[k]
    se = st.stdev(x) / len(x) ** 0.5 if len(x) > 1 else float('nan')
    print(f'{k} {names[k]}: n {len(x)}, median {st.median(x):.2f}, mean {st.mean(x):.2f} ± {se:.2f} s')
