"""Markdown tables from equal_age.sh's output (stdin): per angle, one row per window, loss and
damage added (mg/g per impact, ± s.e. over samples) of each rung that has every sample there."""
import re
import sys

pat = re.compile(
    r"^(\d+)/(\d+) cell \d+: (\d+) samples, impacts (\d+)-(\d+): loss ([\d.]+) ± ([\d.]+), "
    r"damage added ([\d.]+) ± ([\d.]+)"
)
data = {}
for line in sys.stdin:
    m = pat.match(line)
    if m:
        rung, angle, n, lo, hi, l, ls, d, ds = m.groups()
        data[(angle, f"{lo}–{hi}", int(rung))] = (n, l, ls, d, ds)
rungs = [16, 24, 32, 48]
# Samples per cell of each rung's campaign: the seed's 25 at 32 per Dg, 15 elsewhere.
FULL = {16: 15, 24: 15, 32: 25, 48: 15}
for angle in ("45", "90"):
    print(f"\n{angle}°: loss / damage added, mg/g per impact\n")
    print("| impacts | " + " | ".join(f"{r} per Dg" for r in rungs) + " |")
    print("|---|" + "---|" * len(rungs))
    windows = sorted({w for (a, w, _) in data if a == angle}, key=lambda w: int(w.split("–")[0]))
    for w in windows:
        cells = []
        for r in rungs:
            v = data.get((angle, w, r))
            short = f" ({v[0]} of {FULL[r]} samples)" if v and int(v[0]) < FULL[r] else ""
            cells.append(f"{v[1]} ± {v[2]} / {v[3]} ± {v[4]}{short}" if v else "–")
        print(f"| {w} | " + " | ".join(cells) + " |")
