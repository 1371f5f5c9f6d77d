"""Local incidence on worn surfaces, from `surface_profile --incidence` and `--columns` rows.

Per campaign, nominal angle and stage (impacts pooled in blocks of 40): the angle between each
swept grain's path and the surface where it first touches it,
  - on each sample's own surface (slope of its column tops over +-0.1 Dg), and
  - on the mean surface of the stage's samples (same grain, same touch point), which keeps the
    trench every sample shares and averages away each sample's own roughness,
and what that spread would do to a rate if each grain eroded as a flat surface does at its
local angle, under two angle laws:
  - grit's own damage per impact against nominal angle (docs/erosion.md, *Why the angle curve
    is not Oka's*: 0.66, 0.83, 1, 1.71, 1.82, 2.06 at 15..90 degrees on the paper campaign's
    80-impact surfaces; linear between, 0 at 0 degrees);
  - Oka's g(alpha) for silica on AISI 304 (Hv 1.8 GPa), seed eq. 35.
The factor is mean f(local) over the grains / f(nominal).
Usage: python3 summarise.py incidence.tsv[.xz] columns.tsv[.xz]"""
import csv, lzma, math, statistics as st, sys

from by_angle import trench_angle

GRIT = [(0, 0.0), (15, 0.66), (30, 0.83), (45, 1.0), (60, 1.71), (75, 1.82), (90, 2.06)]
HV = 1.8
N1, N2 = 0.71 * HV ** 0.14, 2.4 * HV ** -0.94


def grit_f(a):
    for (a0, f0), (a1, f1) in zip(GRIT, GRIT[1:]):
        if a <= a1:
            return f0 + (f1 - f0) * (a - a0) / (a1 - a0)
    return GRIT[-1][1]


def oka(a):
    s = math.sin(math.radians(a))
    return s ** N1 * (1 + HV * (1 - s)) ** N2


def key(r):
    return (r['checkpoint'].split('/')[-2], float(r['angle_deg']), int(r['impacts']) // 40)


def q(v, p):
    v = sorted(v)
    return v[min(len(v) - 1, int(p * len(v)))]


def rows(path):
    f = lzma.open(path, 'rt') if path.endswith('.xz') else open(path)
    return list(csv.DictReader(f, delimiter='\t'))


incidence, columns = rows(sys.argv[1]), rows(sys.argv[2])
groups, tops = {}, {}
for r in incidence:
    groups.setdefault(key(r), []).append(r)
for r in columns:
    tops.setdefault(key(r), {}).setdefault(float(r['x_dg']), []).append(float(r['top_dg']))

print('| campaign | nominal | impacts | surfaces | grains | local angle, own surface: 10 % | 50 % '
      '| 90 % | within ±10° | on the mean surface: 10 % | 50 % | 90 % | within ±10° '
      '| factor, grit\'s law | factor, Oka\'s law |')
print('|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|')
for k, g in sorted(groups.items()):
    run, ang, _ = k
    loc = [float(r['local_deg']) for r in g]
    impacts = sorted({int(r['impacts']) for r in g})
    span = f'{impacts[0]}' if len(impacts) == 1 else f'{impacts[0]}–{impacts[-1]}'
    surfaces = len({r['checkpoint'] for r in g})
    within = lambda v: sum(abs(a - ang) <= 10 for a in v) / len(v)
    shared = ''
    if k in tops:
        profile = {x: st.mean(v) for x, v in tops[k].items()}
        mean_loc = [trench_angle(profile, float(r['contact_x_dg']), ang) for r in g]
        shared = (f'{q(mean_loc, .1):.0f}° | {q(mean_loc, .5):.0f}° | {q(mean_loc, .9):.0f}° '
                  f'| {within(mean_loc):.0%}')
    else:
        shared = ' | | | '
    rg = st.mean(grit_f(a) for a in loc) / grit_f(ang)
    ro = st.mean(oka(a) for a in loc) / oka(ang)
    print(f'| {run} | {ang:.0f}° | {span} | {surfaces} | {len(loc)} | {q(loc, .1):.0f}° '
          f'| {q(loc, .5):.0f}° | {q(loc, .9):.0f}° | {within(loc):.0%} | {shared} '
          f'| {rg:.2f} | {ro:.2f} |')
