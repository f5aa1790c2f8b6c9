"""What the sheen outputs (the Charlie-prefiltered chain and the sheen table) add to a
size-256 bake of the bundled environment (issue 25's goal: at most 25 %): the same bake
with and without them, interleaved in one process, medians of 9 after a warm-up.

    PYTHONPATH=src python bench/sheen_bake_cost.py
"""

from __future__ import annotations

import statistics
import time

from pbrkit.data import environment_path
from pbrkit.ibl.bake import bake


def main(repeats=9):
    env = str(environment_path())
    for sheen in (True, False):
        bake(env, size=256, sheen=sheen)
    times = {True: [], False: []}
    for i in range(repeats):
        for sheen in ((True, False) if i % 2 == 0 else (False, True)):
            t = time.perf_counter()
            bake(env, size=256, sheen=sheen)
            times[sheen].append(time.perf_counter() - t)
    with_, without = statistics.median(times[True]), statistics.median(times[False])
    print(f"size-256 bake: with the sheen outputs {with_:.3f} s, without {without:.3f} s, "
          f"ratio {with_ / without:.3f}")


if __name__ == "__main__":
    main()
