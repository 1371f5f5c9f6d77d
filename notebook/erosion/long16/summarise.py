"""The damage balance over 800 impacts at 16 per Dg (long16): per cell, in windows of W impacts,
the mean over samples of loss and damage added per g of grain (mg/g), their ratio, and each
sample's loss over impacts LO..800 as the long-window rate (mean ± s.e.).
Usage: python3 summarise.py DB [W=80] [LO=401]"""
import statistics as st, sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from balance_interim import load, rates, se

db = sys.argv[1]
w = int(sys.argv[2]) if len(sys.argv) > 2 else 80
lo = int(sys.argv[3]) if len(sys.argv) > 3 else 401
for (_, angle), samples in sorted(load(db).items()):
    n = max(len(v) for v in samples.values())
    full = {s: v for s, v in samples.items() if len(v) == n}
    print(f"{angle:.0f}°: {len(full)} samples of {n} impacts")
    print("  impacts    loss (mg/g)    damage added   ratio")
    for a in range(1, n - w + 2, w):
        L, A = rates(full, a, a + w - 1)
        print(f"  {a:3d}-{a + w - 1:3d}  {st.mean(L):5.2f} ± {se(L):4.2f}   {st.mean(A):5.2f} ± {se(A):4.2f}   {st.mean(L) / st.mean(A):4.2f}")
    L, A = rates(full, lo, n)
    print(f"  long window {lo}-{n}: loss {st.mean(L):.2f} ± {se(L):.2f}, damage added {st.mean(A):.2f} ± {se(A):.2f}, ratio {st.mean(L) / st.mean(A):.2f}")
