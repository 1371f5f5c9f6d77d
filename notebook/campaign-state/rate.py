#!/usr/bin/env python3
"""Each long run's progress since a time: impacts stored, steps, and steps per second of wall.
   rate.py [SINCE_UTC like 2026-12-02T02:00] [RUNS_DIR]
One engine thread per run, so steps per second of wall is what that run's core delivers; the
same figure on two days says how fast the machine was (the cost per step also grows with
the surface's age, so compare a run with itself over short spans)."""
import datetime, json, os, sqlite3, sys

since = sys.argv[1] if len(sys.argv) > 1 else None
runs = sys.argv[2] if len(sys.argv) > 2 else "/work/runs"
t0 = 0
if since:
    t0 = int(datetime.datetime.fromisoformat(since).replace(tzinfo=datetime.timezone.utc).timestamp() * 1000)
for name in ["box32/big", "box32/std", "ppd48", "ppd24b", "paper", "ppd16c"]:
    db = os.path.join(runs, name, "grit.db")
    if not os.path.exists(db):
        continue
    c = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    rows = c.execute("select created_ms, record from units where created_ms >= ? order by created_ms", (t0,)).fetchall()
    total = c.execute("select count(*) from units").fetchone()[0]
    if len(rows) < 2:
        print(f"{name:10s} {total:6d} units, {len(rows)} since")
        continue
    steps = sum(json.loads(r)["outcome"]["steps"] for _, r in rows[1:])
    span = (rows[-1][0] - rows[0][0]) / 1000
    print(f"{name:10s} {total:6d} units, {len(rows):4d} since, {steps / (len(rows) - 1):7.0f} steps/impact, "
          f"{steps / span:6.1f} steps/s over {span / 60:5.1f} min")
