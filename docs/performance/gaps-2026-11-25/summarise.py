"""Medians over the rounds of run.sh's JSON files in this folder (standard library only)."""
import json
import pathlib
import statistics as st

here = pathlib.Path(__file__).parent
for b in ["slim", "gaps"]:
    rows = [json.loads(f.read_text()) for f in sorted(here.glob(f"{b}-*.json"))]
    med = lambda f: st.median(f(x) for x in rows)
    print(
        f"{b}: wall 2 threads {med(lambda x: x['wall_s']):.3f} s, 1 thread {med(lambda x: x['wall_1_thread_s']):.3f} s, "
        f"kernel sums {med(lambda x: x['stages']['kernel_sums']):.3f} s, forces {med(lambda x: x['stages']['forces']):.3f} s, "
        f"speed-up {med(lambda x: x['speedup_1_to_2']):.2f}, per thread {med(lambda x: x['particle_steps_per_s_per_thread']) / 1e6:.3f} M, "
        f"step/ceiling {med(lambda x: x['ceiling']['full_step_over_ceiling']):.2f}"
    )
