"""Timing helper shared by the benchmark scripts (not a benchmark itself)."""

import statistics
import time


def median_time(fn, n: int = 7) -> float:
    """Median wall time (s) of ``n`` calls of ``fn``."""
    ts = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)
