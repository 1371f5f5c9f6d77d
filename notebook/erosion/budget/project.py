"""What a running campaign still costs: per cell, the steps its samples have left to a target
impact count, from each cell's own growth of steps per impact (least squares over its records
past impact 40, once a cell has reached impact 200; younger cells borrow the campaign's
steepest line), at a measured cost
per step.
Usage: python3 project.py DB MS_PER_STEP ANGLE=TARGET...   e.g. ... 3.0 90=500 30=420"""
import sqlite3, sys


def fit(points):
    """Least-squares line (a, b) of steps against impact; None below two impacts."""
    n = len(points)
    if n < 2:
        return None
    mx = sum(x for x, _ in points) / n
    my = sum(y for _, y in points) / n
    sxx = sum((x - mx) ** 2 for x, _ in points)
    if sxx == 0:
        return None
    b = sum((x - mx) * (y - my) for x, y in points) / sxx
    return my - b * mx, b


def main():
    db, ms = sys.argv[1], float(sys.argv[2])
    targets = {float(a): int(n) for a, n in (t.split('=') for t in sys.argv[3:])}
    c = sqlite3.connect(db, uri=True)
    rows = c.execute("""select cl.angle_deg, j.id, u.unit, json_extract(u.record, '$.outcome.steps')
        from units u join jobs j on j.id = u.job_id join cells cl
        on cl.campaign_id = j.campaign_id and cl.cell_index = j.cell_index""").fetchall()
    samples = dict(c.execute("select angle_deg, samples from cells"))
    cells = {}
    for angle, job, unit, steps in rows:
        cell = cells.setdefault(angle, {'done': {}, 'pts': []})
        cell['done'][job] = max(cell['done'].get(job, 0), unit)
        if unit > 40:
            cell['pts'].append((unit, steps))
    fits = {a: fit(v['pts']) for a, v in cells.items()}
    steepest = max((fits[a] for a, v in cells.items()
                    if fits[a] and max(u for u, _ in v['pts']) >= 200), key=lambda f: f[1], default=None)
    total = 0.0
    print('| angle | samples | impacts done (min–max) | target | steps per impact, fit | CPU-h left |')
    print('|---|---|---|---|---|---|')
    for angle in sorted(set(targets) | set(cells)):
        n_target = targets.get(angle)
        if n_target is None:
            continue
        cell = cells.get(angle, {'done': {}, 'pts': []})
        grown = max((u for u, _ in cell['pts']), default=0) >= 200
        f = fits.get(angle) if grown else None
        borrowed = f is None
        if borrowed:
            f = steepest or (0.0, 0.0)
        a, b = f
        done = list(cell['done'].values()) + [0] * (samples[angle] - len(cell['done']))
        steps = sum(sum(a + b * k for k in range(d + 1, n_target + 1)) for d in done)
        hours = steps * ms / 1e3 / 3600
        total += hours
        print(f'| {angle:g}° | {samples[angle]} | {min(done)}–{max(done)} | {n_target} | '
              f'{a:.0f} + {b:.2f}·n{" (borrowed)" if borrowed else ""} | {hours:.1f} |')
    print(f'\ntotal: {total:.1f} CPU-hours at {ms} ms per step')


if __name__ == '__main__':
    main()
