"""What a running campaign still costs, from its own database.

usage: remaining.py DB END [SINCE_UTC | MS_PER_STEP]
  DB         a campaign's grit.db (opened read-only)
  END        impacts per sample a cell is assumed to run to before it balances (the balanced
             cells so far: 280 at 15°, 380-420 at 45°, 480-520 at 90°); one number for every
             cell, or a default with angles of their own after it: 420,90=520
  SINCE_UTC  measure the CPU per step over the impacts stored since then (default: the last
             hour), e.g. 2026-12-07T00:11
  MS_PER_STEP  or the CPU per step given, for a campaign not running now (scale another
             campaign's by its particles: they go as 1/Δx²)

Each impact's cost is its steps (`outcome.steps` of the stored record) times the time per step.
The time per step is measured here: with one worker, consecutive impacts of one job are stored
one impact's wall time apart, which is its CPU time while the worker has a core. The steps of
impacts not yet run are extrapolated per cell by a straight line through its last 120 impacts'
mean steps (the crater deepens steadily, so the steps grow with the impact number); a cell with
fewer than 40 impacts takes the mean of the campaign's other cells' lines. Cells whose jobs are
all done are final and left out. Prints each open cell's impacts to go and CPU-hours, and the
total, and each open cell's steps and CPU-s per impact at its furthest sample (the line's value).
"""
import sqlite3
import statistics
import sys
import time
from collections import defaultdict
from datetime import datetime, timezone

db = sys.argv[1]
default_end, *own = sys.argv[2].split(",")
ends = {float(a): int(e) for a, e in (o.split("=") for o in own)}
given = None
since = time.time() - 3600
if len(sys.argv) > 3:
    try:
        given = float(sys.argv[3]) / 1000
    except ValueError:
        since = datetime.fromisoformat(sys.argv[3]).replace(tzinfo=timezone.utc).timestamp()
con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)

rows = [] if given else con.execute(
    "select u.job_id, u.unit, u.created_ms, json_extract(u.record, '$.outcome.steps') "
    "from units u where u.created_ms > ? order by u.created_ms",
    (int(since * 1000),),
).fetchall()
per_step = [
    (b[2] - a[2]) / 1000 / b[3]
    for a, b in zip(rows, rows[1:])
    if a[0] == b[0] and b[1] == a[1] + 1
]
if not per_step and not given:
    sys.exit("remaining.py: no consecutive impacts stored in the window; give another SINCE_UTC or MS_PER_STEP")
s_step = given or statistics.median(per_step)

# Mean steps per impact number, per cell.
steps = defaultdict(lambda: defaultdict(list))
for cell, unit, st in con.execute(
    "select j.cell_index, u.unit, json_extract(u.record, '$.outcome.steps') "
    "from units u join jobs j on j.id = u.job_id"
):
    steps[cell][unit].append(st)


def line(cell):
    """Least-squares line of mean steps against impact number over the cell's last 120."""
    xs = sorted(steps[cell])[-120:]
    ys = [statistics.mean(steps[cell][u]) for u in xs]
    mx, my = statistics.mean(xs), statistics.mean(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx else 0.0
    return lambda u: my + slope * (u - mx)


cells = con.execute(
    "select j.cell_index, count(*), group_concat(j.units_done), min(j.state = 'done'), c.angle_deg "
    "from jobs j join cells c on c.campaign_id = j.campaign_id and c.cell_index = j.cell_index "
    "group by j.cell_index order by j.cell_index"
).fetchall()
lines = {c: line(c) for c in steps if len(steps[c]) >= 40}
total = 0.0
print(f"CPU per step: {s_step * 1000:.2f} ms " + ("(given)" if given else f"(median of {len(per_step)} impacts)"))
print("cell  angle  samples  done per sample  steps, CPU-s per impact now  to  impacts to go  CPU-h")
for cell, n, done, finished, angle in cells:
    if finished:
        continue  # every job done: the cell is final (a cell to grow is extended at once)
    end = ends.get(float(angle), int(default_end))
    done = [int(d) for d in done.split(",")]
    go = sum(max(end - d, 0) for d in done)
    if cell in lines:
        f = lines[cell]
    elif lines:
        f = lambda u: statistics.mean(g(u) for g in lines.values())  # noqa: E731
    else:
        sys.exit("remaining.py: no cell has 40 impacts to extrapolate from")
    now = f(max(done))
    cost = sum(f(u) for d in done for u in range(d + 1, end + 1))
    hours = cost * s_step / 3600
    total += hours
    print(f"{cell:4}  {angle:5g}  {n:7}  {min(done)}-{max(done):<14}  {now:6.0f}, {now * s_step:5.1f}{'':16}  {end:3}  {go:12}  {hours:5.1f}")
print(f"total {total:.1f} CPU-hours to {sys.argv[2]} impacts per sample")
