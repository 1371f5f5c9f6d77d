"""Medians over the rounds of `grit bench impact --repeat 5 --json` files NAME-ROUND.json in a
folder, one line per build name (standard library only).

    python3 notebook/performance/medians.py notebook/performance/slim-2026-11-25 head slim
"""
import json
import pathlib
import statistics as st
import sys

folder = pathlib.Path(sys.argv[1])
for name in sys.argv[2:]:
    rows = [json.loads(f.read_text()) for f in sorted(folder.glob(f"{name}-*.json"))]
    med = lambda f: st.median(f(x) for x in rows)
    print(
        f"{name}: wall 2 threads {med(lambda x: x['wall_s']):.3f} s, 1 thread {med(lambda x: x['wall_1_thread_s']):.3f} s, "
        f"kernel sums {med(lambda x: x['stages']['kernel_sums']):.3f} s, forces {med(lambda x: x['stages']['forces']):.3f} s, "
        f"neighbours {med(lambda x: x['stages']['neighbours']):.3f} s, stress {med(lambda x: x['stages']['stress']):.3f} s, "
        f"speed-up {med(lambda x: x['speedup_1_to_2']):.2f}, per thread {med(lambda x: x['particle_steps_per_s_per_thread']) / 1e6:.3f} M, "
        f"step/ceiling {med(lambda x: x['ceiling']['full_step_over_ceiling']):.2f}"
    )
