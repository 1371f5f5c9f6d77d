"""Medians of bench.sh's rounds: python3 medians.py (in this folder)."""
import glob, json, statistics as st

for b in ("old", "new"):
    runs = [json.load(open(f)) for f in sorted(glob.glob(f"impact-{b}-*.json"))]
    med = lambda f: st.median(f(r) for r in runs)
    one = med(lambda r: r["wall_1_thread_s"])
    ps1 = med(lambda r: r["particles"] * r["steps"] / r["wall_1_thread_s"])
    print(f"{b}: {len(runs)} rounds; 1 thread {one:.3f} s ({ps1 / 1e6:.3f} M particle-steps/s), "
          f"2 threads {med(lambda r: r['wall_s']):.3f} s "
          f"({med(lambda r: r['particle_steps_per_s_per_thread']) / 1e6:.3f} M per thread), "
          f"speed-up {med(lambda r: r['speedup_1_to_2']):.2f}, "
          f"full step over ceiling {med(lambda r: r['ceiling']['full_step_over_ceiling']):.2f}, "
          f"ceiling {med(lambda r: r['ceiling']['particle_steps_per_s']) / 1e6:.2f} M")
    stages = runs[0]["stages_1_thread"].keys()
    print("   1-thread stages (s): " + ", ".join(
        f"{k} {med(lambda r: r['stages_1_thread'][k]):.3f}" for k in stages))
t = {}
for line in open("times45.txt"):
    b, _, user, _ = line.split()
    t.setdefault(b, []).append(float(user))
print("3-impact sample, user s: old " + " ".join(map(str, t["old"])) + "; new "
      + " ".join(map(str, t["new"])) + f"; ratio of medians {st.median(t['new']) / st.median(t['old']):.3f}")
