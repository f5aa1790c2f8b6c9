"""Shared timing helper for the benchmark scripts (run them as ``python bench/NAME.py``)."""

from __future__ import annotations

import time


def best_and_median(fn, repeat):
    """Best and median wall time of ``repeat`` calls of ``fn``."""
    times = []
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    times.sort()
    return times[0], times[len(times) // 2]
