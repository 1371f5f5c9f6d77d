"""Shared by summarise.py, across.py and history.py: kept checkpoints' names and paired means."""
import math
import sys


def which(ckpt, campaign):
    """(cell, sample) of a kept checkpoint path .../CAMPAIGN/cCELL-SAMPLE-IMPACTS.ckpt, or None.

    The impacts a checkpoint holds are read from it, not from this name."""
    parts = ckpt.split("/")
    if len(parts) < 2 or parts[-2] != campaign:
        return None
    c, s, _ = parts[-1][1:].removesuffix(".ckpt").split("-")
    return c, int(s)


def paired(by, lo, hi, what):
    """The samples of `by` (sample -> impacts -> values) that have both LO and HI."""
    pairs = [v for v in by.values() if lo in v and hi in v]
    if not pairs:
        sys.exit(f"no sample of {what} has checkpoints at both {lo} and {hi}")
    return pairs


def mean_se(xs):
    """Mean and standard error over samples."""
    m = sum(xs) / len(xs)
    if len(xs) < 2:
        return m, float("nan")
    return m, math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1) / len(xs))
