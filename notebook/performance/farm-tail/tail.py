"""Predicted farm efficiency from the spread of job lengths (issue 36 part 3).

Usage: python3 tail.py DB [impacts]
Job length = the engine steps of a sample's first `impacts` impacts (records' outcome.steps;
one impact's cost is its steps times a per-step cost that is the same for every impact of
one scene). Jobs are handed out in queue order to whichever worker is free first (the farm's
pull), and the makespan on W workers is compared with the ideal total/W.
"""
import json, sqlite3, sys, statistics as st, heapq, random

db = sys.argv[1]; n = int(sys.argv[2]) if len(sys.argv) > 2 else 24
c = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
tabs = {r[0] for r in c.execute("select name from sqlite_master where type='table'")}
t, k = ("units", "unit") if "units" in tabs else ("impacts", "impact")
jobs = {}
for j, u, rec in c.execute(f"select job_id, {k}, record from {t} where {k} <= ? order by job_id, {k}", (n,)):
    jobs.setdefault(j, []).append(json.loads(rec)["outcome"]["steps"])
lengths = [sum(v) for v in jobs.values() if len(v) == n]
m = st.mean(lengths)
print(f"{len(lengths)} jobs of {n} impacts: mean {m:.0f} steps, cv {st.stdev(lengths)/m:.3f}, "
      f"max/mean {max(lengths)/m:.3f}")

def makespan(ls, w):
    free = [0.0] * w
    for l in ls:
        heapq.heapreplace(free, free[0] + l)
    return max(free)

rng = random.Random(1)
for jobs_n in (32, 64):
    for w in (2, 8, 16):
        effs = []
        for _ in range(2000):
            ls = [rng.choice(lengths) for _ in range(jobs_n)]
            effs.append(sum(ls) / w / makespan(ls, w))
        effs.sort()
        print(f"{jobs_n} jobs on {w:2d} workers: efficiency {st.mean(effs):.3f} "
              f"(5-95 %: {effs[100]:.3f}-{effs[1900]:.3f})")
