"""Timing helper shared by the benchmark scripts (not a benchmark itself)."""

import statistics
import time


def timed(fn, n: int = 7):
    """(the last result of ``fn``, median wall time in s of ``n`` calls)."""
    out, ts = None, []
    for _ in range(n):
        t0 = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t0)
    return out, statistics.median(ts)


def median_time(fn, n: int = 7) -> float:
    """Median wall time (s) of ``n`` calls of ``fn``."""
    return timed(fn, n)[1]
