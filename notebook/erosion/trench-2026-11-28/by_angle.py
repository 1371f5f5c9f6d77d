"""Damage and loss per impact against the local angle each grain met, on a running campaign.

For every kept checkpoint of one cell (sample s after k impacts) the impacts k+1 .. k+20 of
that sample (up to its next kept checkpoint) are placed on the surface at k with the grains
they fired (orientation and aim from their records) by `surface_profile --grains`; impact k+1
meets exactly that surface, later ones a surface a few impacts older. The local angle is read
twice: on the sample's own surface (only for k+1, the exact surface) and on the stage's mean
surface (the trench, for every impact; stages with at least 10 samples). Each impact's damage
added and mass loss are divided by their stage's mean (impacts k+1..k+20 over its samples),
which takes out the slow trend with wear, then averaged per bin of local angle.
Usage: python3 by_angle.py SURFACE_PROFILE KEPT RUN CELL DB OUT
  e.g. by_angle.py target/release/examples/surface_profile /work/runs/ckpt-keep paper 2 \
       /work/runs/paper/grit.db /tmp/trench/paper45"""
import csv, math, os, re, sqlite3, statistics as st, subprocess, sys

exe, kept, run, cell, db, out = sys.argv[1:7]
cell = int(cell)
os.makedirs(out, exist_ok=True)
WINDOW, MIN_SAMPLES, HALF_WIDTH_DG = 20, 10, 0.1

ckpts = {}
for f in os.listdir(os.path.join(kept, run)):
    m = re.fullmatch(r'c(\d+)-(\d+)-(\d+)\.ckpt', f)
    if m and int(m[1]) == cell:
        ckpts.setdefault(int(m[2]), []).append(int(m[3]))
con = sqlite3.connect(f'file:{db}?mode=ro', uri=True)
units = {}
for s, u, o, a, d, l, g in con.execute(
        "select j.sample_index, u.unit, json_extract(u.record,'$.orientation_rad'), "
        "json_extract(u.record,'$.aim_x_m'), json_extract(u.record,'$.outcome.damage_added_kg'), "
        "json_extract(u.record,'$.mass_loss_kg'), json_extract(u.record,'$.grain_mass_kg') "
        "from units u join jobs j on j.id = u.job_id where j.cell_index = ?", (cell,)):
    units[(s, u)] = (o, a, d, l, g)

stage_count = {}
for s, ks in ckpts.items():
    for k in ks:
        stage_count[k] = stage_count.get(k, 0) + 1
stages = {k for k, n in stage_count.items() if n >= MIN_SAMPLES}

rows = []  # (checkpoint, sample, k, unit)
for s, ks in sorted(ckpts.items()):
    ks.sort()
    for i, k in enumerate(ks):
        stop = min(k + WINDOW, ks[i + 1] if i + 1 < len(ks) else k + WINDOW)
        if k not in stages:
            stop = k + 1
        for u in range(k + 1, stop + 1):
            if (s, u) in units:
                rows.append((f'{run}/c{cell}-{s}-{k}.ckpt', s, k, u))
with open(os.path.join(out, 'grains.tsv'), 'w') as f:
    f.write('checkpoint\tunit\torientation_rad\taim_x_m\n')
    for c, s, k, u in rows:
        o, a = units[(s, u)][:2]
        f.write(f'{c}\t{u}\t{o!r}\t{a!r}\n')
exe = os.path.abspath(exe)
touches = subprocess.run([exe, '--grains', os.path.abspath(os.path.join(out, 'grains.tsv'))],
                         cwd=kept, capture_output=True, text=True, check=True).stdout
open(os.path.join(out, 'touches.tsv'), 'w').write(touches)
stage_paths = sorted({c for c, s, k, u in rows if k in stages})
columns = subprocess.run([exe, '--columns'] + stage_paths, cwd=kept, capture_output=True,
                         text=True, check=True).stdout
open(os.path.join(out, 'columns.tsv'), 'w').write(columns)

profiles = {}
for r in csv.DictReader(columns.splitlines(), delimiter='\t'):
    profiles.setdefault(int(r['impacts']), {}).setdefault(float(r['x_dg']), []).append(float(r['top_dg']))
profiles = {k: {x: st.mean(v) for x, v in p.items()} for k, p in profiles.items()}


def trench_angle(k, x0, nominal):
    p = profiles[k]
    near = [x for x in p if abs(x - x0) <= HALF_WIDTH_DG]
    mx, my = st.mean(near), st.mean(p[x] for x in near)
    sl = sum((x - mx) * (p[x] - my) for x in near) / sum((x - mx) ** 2 for x in near)
    return math.degrees(math.asin(abs(math.sin(math.radians(nominal) + math.atan(sl)))))


impacts = []
for r in csv.DictReader(touches.splitlines(), delimiter='\t'):
    k, u = int(r['impacts']), int(r['unit'])
    s = int(re.fullmatch(r'.*c\d+-(\d+)-\d+\.ckpt', r['checkpoint'])[1])
    o, a, d, l, g = units[(s, u)]
    nominal = float(r['angle_deg'])
    impacts.append(dict(s=s, k=k, u=u, nominal=nominal, own=float(r['local_deg']) if u == k + 1 else None,
                        trench=trench_angle(k, float(r['contact_x_dg']), nominal) if k in stages else None,
                        damage=d / g * 1e3, loss=l / g * 1e3))
by_stage = {}
for i in impacts:
    by_stage.setdefault(i['k'], []).append(i)
for k, v in by_stage.items():
    md, ml = st.mean(i['damage'] for i in v), st.mean(i['loss'] for i in v)
    for i in v:
        i['rd'], i['rl'] = i['damage'] / md, (i['loss'] / ml if ml > 0 else None)

nominal = impacts[0]['nominal']
edges = [0, nominal - 25, nominal - 10, nominal + 10, nominal + 25, 91]


def clustered(b, key):
    """Mean ± standard error clustered by sample (a sample's impacts share its surface)."""
    v = [i for i in b if i[key] is not None]
    if len(v) < 2:
        return ''
    m = st.mean(i[key] for i in v)
    by = {}
    for i in v:
        by[i['s']] = by.get(i['s'], 0.0) + i[key] - m
    if len(by) < 2:
        return f'{m:.2f} (one sample)'
    return f'{m:.2f} ± {math.sqrt(sum(x * x for x in by.values())) / len(v):.2f}'


def table(key, label, sel):
    print(f'\n{label}: {len(sel)} impacts; damage added and loss per impact over their stage\'s mean, '
          '± s.e. clustered by sample\n')
    print('| local angle | impacts | share | damage added | loss |')
    print('|---|---|---|---|---|')
    for lo, hi in zip(edges, edges[1:]):
        b = [i for i in sel if lo <= i[key] < hi]
        if len(b) < 2:
            continue
        print(f'| {max(lo, 0):.0f}–{min(hi, 90):.0f}° | {len(b)} | {len(b) / len(sel):.0%} '
              f'| {clustered(b, "rd")} | {clustered(b, "rl")} |')


print(f'{run}, cell {cell} ({nominal:.0f}°), stages {min(by_stage)}–{max(by_stage)}')
table('trench', 'On the stage\'s mean surface (the trench), impacts k+1..k+20',
      [i for i in impacts if i['trench'] is not None and i['rl'] is not None])
late = [i for i in impacts if i['trench'] is not None and i['rl'] is not None and i['k'] >= 240]
if late:
    table('trench', 'The same from stages 240 on', late)
table('own', 'On the sample\'s own surface, impacts k+1 only',
      [i for i in impacts if i['own'] is not None and i['rl'] is not None])
