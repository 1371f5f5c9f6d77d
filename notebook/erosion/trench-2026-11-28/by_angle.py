"""Damage and loss per impact against the local angle each grain met.

Two sources of impacts:
  campaign: a running campaign's database and the keeper's checkpoints. For every kept
    checkpoint of one cell (sample s after k impacts) the impacts k+1 .. k+20 of that sample
    (up to its next kept checkpoint) are placed on the surface at k with the grains they fired
    (orientation and aim from their records) by `surface_profile --grains`; impact k+1 meets
    exactly that surface, later ones a surface a few impacts older, so the own-surface angle
    is kept only for k+1.
  run: the output of `surface_profile --run`, where every impact's touch and local angle were
    taken on the exact surface just before it.
The local angle is read on the sample's own surface and on the stage's mean surface (the
trench: the column tops averaged over the samples at k, stages with at least 5 samples), at
the same touch point. Each impact's damage added and loss are divided by their stage's mean
(impacts k+1..k+20 over the samples), which takes out the slow trend with wear, then averaged
per bin of local angle; standard errors clustered by sample.
Usage: python3 by_angle.py campaign SURFACE_PROFILE KEPT RUN CELL DB OUT
         e.g. campaign target/release/examples/surface_profile /work/runs/ckpt-keep paper 2 \\
              /work/runs/paper/grit.db /tmp/trench/paper45
       python3 by_angle.py run PREFIX   (PREFIX-impacts.tsv and PREFIX-columns.tsv, or their .xz)"""
import csv, lzma, math, os, re, sqlite3, statistics as st, subprocess, sys

WINDOW, MIN_SAMPLES, HALF_WIDTH_DG = 20, 5, 0.1


def from_campaign(exe, kept, run, cell, db, out):
    cell = int(cell)
    os.makedirs(out, exist_ok=True)
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
        units[(s, u)] = (o, a, d / g * 1e3, l / g * 1e3)
    count = {}
    for ks in ckpts.values():
        for k in ks:
            count[k] = count.get(k, 0) + 1
    stages = {k for k, n in count.items() if n >= MIN_SAMPLES}
    rows = []
    for s, ks in sorted(ckpts.items()):
        ks.sort()
        for i, k in enumerate(ks):
            stop = min(k + WINDOW, ks[i + 1] if i + 1 < len(ks) else k + WINDOW)
            if k not in stages:
                stop = k + 1
            rows += [(f'{run}/c{cell}-{s}-{k}.ckpt', s, k, u) for u in range(k + 1, stop + 1)
                     if (s, u) in units]
    grains = os.path.abspath(os.path.join(out, 'grains.tsv'))
    with open(grains, 'w') as f:
        f.write('checkpoint\tunit\torientation_rad\taim_x_m\n')
        for c, s, k, u in rows:
            o, a = units[(s, u)][:2]
            f.write(f'{c}\t{u}\t{o!r}\t{a!r}\n')
    exe = os.path.abspath(exe)
    touches = subprocess.run([exe, '--grains', grains], cwd=kept, capture_output=True,
                             text=True, check=True).stdout
    stage_paths = sorted({c for c, s, k, u in rows if k in stages})
    columns = subprocess.run([exe, '--columns'] + stage_paths, cwd=kept, capture_output=True,
                             text=True, check=True).stdout
    impacts = []
    for r in csv.DictReader(touches.splitlines(), delimiter='\t'):
        k, u = int(r['impacts']), int(r['unit'])
        s = int(re.fullmatch(r'.*c\d+-(\d+)-\d+\.ckpt', r['checkpoint'])[1])
        impacts.append(dict(s=s, k=k, nominal=float(r['angle_deg']), x=float(r['contact_x_dg']),
                            own=float(r['local_deg']) if u == k + 1 else None,
                            damage=units[(s, u)][2], loss=units[(s, u)][3]))
    return f'{run}, cell {cell}', impacts, profiles(csv.DictReader(columns.splitlines(), delimiter='\t'))


def text(path):
    """A table file, or its committed .xz copy."""
    return open(path) if os.path.exists(path) else lzma.open(path + '.xz', 'rt')


def from_run(prefix):
    impacts = []
    for r in csv.DictReader(text(prefix + '-impacts.tsv'), delimiter='\t'):
        n = int(r['impact'])
        impacts.append(dict(s=int(r['sample']), k=(n - 1) // WINDOW * WINDOW,
                            nominal=float(r['angle_deg']), x=float(r['contact_x_dg']),
                            own=float(r['local_deg']), damage=float(r['damage_mg_g']),
                            loss=float(r['loss_mg_g'])))
    return os.path.basename(prefix), impacts, profiles(
        csv.DictReader(text(prefix + '-columns.tsv'), delimiter='\t'))


def profiles(rows):
    """Mean column top per stage over its samples, for stages with enough samples."""
    tops, samples = {}, {}
    for r in rows:
        k = int(r['impacts'])
        tops.setdefault(k, {}).setdefault(float(r['x_dg']), []).append(float(r['top_dg']))
        samples.setdefault(k, set()).add(r.get('checkpoint') or r.get('sample'))
    return {k: {x: st.mean(v) for x, v in p.items()} for k, p in tops.items()
            if len(samples[k]) >= MIN_SAMPLES}


def trench_angle(p, x0, nominal):
    near = [x for x in p if abs(x - x0) <= HALF_WIDTH_DG]
    mx, my = st.mean(near), st.mean(p[x] for x in near)
    sl = sum((x - mx) * (p[x] - my) for x in near) / sum((x - mx) ** 2 for x in near)
    return math.degrees(math.asin(abs(math.sin(math.radians(nominal) + math.atan(sl)))))


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


def table(key, label, sel, edges):
    print(f'\n{label}: {len(sel)} impacts; damage added and loss per impact over their '
          'stage\'s mean, ± s.e. clustered by sample\n')
    print('| local angle | impacts | share | damage added | loss |')
    print('|---|---|---|---|---|')
    for lo, hi in zip(edges, edges[1:]):
        b = [i for i in sel if lo <= i[key] < hi]
        if len(b) >= 2:
            print(f'| {max(lo, 0):.0f}–{min(hi, 90):.0f}° | {len(b)} | {len(b) / len(sel):.0%} '
                  f'| {clustered(b, "rd")} | {clustered(b, "rl")} |')


def main():
    if sys.argv[1:2] == ['campaign'] and len(sys.argv) == 8:
        title, impacts, prof = from_campaign(*sys.argv[2:8])
    elif sys.argv[1:2] == ['run'] and len(sys.argv) == 3:
        title, impacts, prof = from_run(sys.argv[2])
    else:
        sys.exit(__doc__)
    for i in impacts:
        i['trench'] = trench_angle(prof[i['k']], i['x'], i['nominal']) if i['k'] in prof else None
    by_stage = {}
    for i in impacts:
        by_stage.setdefault(i['k'], []).append(i)
    for v in by_stage.values():
        md, ml = st.mean(i['damage'] for i in v), st.mean(i['loss'] for i in v)
        for i in v:
            i['rd'], i['rl'] = i['damage'] / md, (i['loss'] / ml if ml > 0 else None)
    nominal = impacts[0]['nominal']
    edges = [0, nominal - 25, nominal - 10, nominal + 10, nominal + 25, 91]
    print(f'{title} ({nominal:.0f}°), stages {min(by_stage)}–{max(by_stage)}')
    trench = [i for i in impacts if i['trench'] is not None and i['rl'] is not None]
    table('trench', 'On the stage\'s mean surface (the trench), impacts k+1..k+20', trench, edges)
    late = [i for i in trench if i['k'] >= 240]
    if late:
        table('trench', 'The same from stages 240 on', late, edges)
    table('own', 'On the sample\'s own surface, just before the impact',
          [i for i in impacts if i['own'] is not None and i['rl'] is not None], edges)


if __name__ == '__main__':
    main()
