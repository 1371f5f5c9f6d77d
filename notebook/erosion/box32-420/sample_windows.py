"""One sample's loss and damage added (mg/g) over spans of impacts in the paired box runs,
with ../box16/compare.py's reading of the databases.
Usage: python3 sample_windows.py STD.db BIG.db SAMPLE LO-HI...   (e.g. 0 1-420 241-420)"""
import os, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "box16"))
import compare  # noqa: E402

std, big, sample = compare.load(sys.argv[1]), compare.load(sys.argv[2]), int(sys.argv[3])
for span in sys.argv[4:]:
    lo, hi = map(int, span.split("-"))
    a, b = compare.window(std[(45.0, sample)], lo, hi), compare.window(big[(45.0, sample)], lo, hi)
    print(f"{lo}-{hi}: std loss {a[0]:.2f} damage {a[1]:.2f} | big loss {b[0]:.2f} damage {b[1]:.2f}")
