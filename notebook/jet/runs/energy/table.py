import json, statistics as st, sys
def load(f):
    d=json.load(open(f)); return d
def first_loss(d):
    for s in d['series']:
        if s['mass_loss_kg_m']>0: return round(s['t_s']*1e6)
    return None
for name in ['cold','energy']:
    rows=[load(f'{name}-s{s}.json') for s in (1,2,3)]
    def at(d,t):
        return min(d['series'], key=lambda s: abs(s['t_s']-t))
    fl=[first_loss(d) for d in rows]
    def ms(xs):
        return f"{st.mean(xs):.4g} ± {st.stdev(xs):.2g}"
    L=[at(d,2e-4)['mass_loss_kg_m']*1e3 for d in rows]
    C05=[at(d,5e-5)['crater_depth_m']*1e6 for d in rows]
    C=[at(d,2e-4)['crater_depth_m']*1e6 for d in rows]
    W=[at(d,2e-4)['crater_width_m']*1e6 for d in rows]
    E=[at(d,2e-4)['max_plastic_strain'] for d in rows]
    wall=[d['wall_s'] for d in rows]
    print(f"| {name} | {', '.join(map(str,fl))} | {ms(L)} | {ms(C05)} | {ms(C)} | {ms(W)} | {ms(E)} | {ms(wall)} |")
