"""Removal events per impact across the resolution ladder, read from campaign databases.

Usage: python3 events.py DB [DB ...]   (schema 5 `impacts` or schema 6 `units` tables)
Prints, per cell, for the first N impacts every sample has: incubation (first loss), the share
of impacts that remove material, particles and mass per removal event, and the mean
cumulative loss over grain mass at impacts 40/60/80.
"""
import json, sqlite3, statistics as st, sys, math

def rows(db):
    c = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    tabs = {r[0] for r in c.execute("select name from sqlite_master where type='table'")}
    t, k = ("units", "unit") if "units" in tabs else ("impacts", "impact")
    cells = {ci: (a, json.loads(p)) for ci, a, p in c.execute("select cell_index, angle_deg, params from cells")}
    out = {}
    for job, ci, rec in c.execute(f"select j.id, j.cell_index, u.record from {t} u join jobs j on j.id=u.job_id order by j.id, u.{k}"):
        out.setdefault(ci, {}).setdefault(job, []).append(json.loads(rec))
    return cells, out

def main():
  for db in sys.argv[1:]:
    cells, data = rows(db)
    for ci, jobs in sorted(data.items()):
        angle, p = cells[ci]
        dx = p["spacing_m"]; ppd = p["grain_diameter_m"] / dx
        n = min(len(v) for v in jobs.values())
        full = [v for v in jobs.values() if len(v) >= 80]
        if not full:
            continue
        n = min(len(v) for v in full)
        first, ev_p, ev_m, hits, imp = [], [], [], 0, 0
        cum = {40: [], 60: [], 80: []}
        for v in full:
            v = v[:n]
            f = next((r["impact"] for r in v if r["mass_loss_kg"] > 0), None)
            first.append(f if f else n + 1)
            lost = g = 0.0
            for r in v:
                lost += r["mass_loss_kg"]; g += r["grain_mass_kg"]
                if r["impact"] in cum:
                    cum[r["impact"]].append(lost / g * 1e3)
                if f and r["impact"] >= f:
                    imp += 1
                    if r["mass_loss_kg"] > 0:
                        hits += 1
                        ev_p.append(r["outcome"]["removed_particles"]); ev_m.append(r["mass_loss_kg"] * 1e9)
        pm = 7890 * dx * dx * 1e9
        def ms(x):
            return f"{st.mean(x):.2f}±{(st.stdev(x)/math.sqrt(len(x)) if len(x)>1 else 0):.2f}" if x else "-"
        print(f"{db.split('/')[-2]:>7} {angle:>4.0f}° ppd {ppd:4.1f} samples {len(full):2d} impacts {n:3d} | "
              f"first loss {st.mean(first):5.1f} (min {min(first)}) | hit share {hits/max(imp,1):.2f} | "
              f"particles/event {ms(ev_p)} (median {st.median(ev_p) if ev_p else '-'}, max {max(ev_p) if ev_p else '-'}) | "
              f"µg/m per event {ms(ev_m)} = {st.mean(ev_m)/pm if ev_m else 0:.1f} particles of {pm:.2f} | "
              f"cum mg/g @40/60/80 {ms(cum[40])} {ms(cum[60])} {ms(cum[80])}")


if __name__ == "__main__":
    main()
