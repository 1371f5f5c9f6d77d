"""Where the rock's fractured particles failed (issue 37): for each target particle that reaches
D = 1, its pressure, damage and von Mises stress one snapshot before (notebook/rock/README.md,
session 27). Usage: python3 failure_pressure.py SNAPSHOT_DIR [T_PA]"""
import re, glob, collections, sys
files = sorted(glob.glob(sys.argv[1] + '/scene-*.vtu'))
def arrays(path):
    s = open(path).read()
    out = {}
    for m in re.finditer(r'<DataArray type="\w+" Name="(\w+)" NumberOfComponents="(\d+)" format="ascii">(.*?)</DataArray>', s, re.S):
        out[m.group(1)] = (int(m.group(2)), m.group(3).split())
    return out
first = {}; prev = {}
bodies = collections.Counter()
for k, f in enumerate(files):
    a = arrays(f)
    ids = a['id'][1]; body = a['body'][1]; dmg = a['damage'][1]; p = a['pressure_pa'][1]; vm = a['von_mises_pa'][1]
    for i, pid in enumerate(ids):
        if k == 0: bodies[body[i]] += 1
        d = float(dmg[i]); P = float(p[i]); q = float(vm[i])
        if d >= 1.0 and pid not in first and body[i] == '0':
            first[pid] = (k, prev.get(pid))
        prev[pid] = (P, d, q, body[i])
print('bodies at slice 1:', dict(bodies))
cls = collections.Counter(); bykslice = collections.Counter()
T = float(sys.argv[2]) if len(sys.argv) > 2 else 4e6  # sandstone preset's tensile limit
for pid, (k, pv) in first.items():
    bykslice[(k+1)//10] += 1
    if pv is None: cls['no previous'] += 1; continue
    P, d, q, b = pv
    if P <= -0.9 * T * (1 - d): cls['at tensile cut (P<=-0.9T(1-D))'] += 1
    elif P < 0: cls['tension, above cut'] += 1
    elif P < 10e6: cls['compression 0-10 MPa'] += 1
    else: cls['compression >10 MPa'] += 1
print('fractured:', len(first))
for c, n in cls.most_common(): print(f'  {c}: {n}')
print('first fracture per µs:', sorted(bykslice.items()))
import statistics as st
ds = [pv[1] for k, pv in first.values() if pv]
print('D one slice (0.1 µs) before failure: quartiles', [round(x,3) for x in st.quantiles(ds, n=4)], 'share with D>0:', sum(d>0 for d in ds)/len(ds))
Ps = [pv[0]/1e6 for k, pv in first.values() if pv]
print('P one slice before (MPa): quartiles', [round(x,1) for x in st.quantiles(Ps, n=4)])
qs = [pv[2]/1e6 for k, pv in first.values() if pv]
print('von Mises one slice before (MPa): quartiles', [round(x,1) for x in st.quantiles(qs, n=4)])
