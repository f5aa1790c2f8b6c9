"""Benchmark: issue 15's figures in one run (ground truth against Mitsuba 3, real time,
start-up, cold start), each beside its goal and a baseline measured in the same run.

    python bench/speed.py [--repeat 3] [--skip-cold] [--skip-mitsuba]

1. Ground truth: ``bench/reference_vs_mitsuba.py``'s furnace, overcast and sunny
   spheres (256^2, 1024 spp) in pbrkit and Mitsuba ``llvm_ad_rgb`` back to back:
   samples/s and time to equal noise (goal: pbrkit >= 1.0x Mitsuba).
2. Real time: the 1024^2 sphere grid with 4 punctual lights and IBL (256^2 bake),
   best of 5 (goal <= 0.5 s); the DamagedHelmet (``../shared/data/models``) at
   512^2 (goal <= 2 s), with and without its loading.
3. Start-up: a whole ``python -m pbrkit lut --kind dfg --size 128 -o t.npy``
   process, best and median of 7, the table in pbrkit's result cache (goal
   <= 0.3 s); the same with ``--no-cache`` (it integrates, with Numba's kernel
   cache warm) and ``python -c pass`` as baselines.
4. Cold start: ``pbrkit demo`` with an empty cache folder (``PBRKIT_CACHE_DIR``
   pointing at a new temporary folder: nothing compiled, nothing memoised),
   with the parallel warm-up and without it (``PBRKIT_NO_WARM_UP=1``), then
   warm (goal: the first run <= 30 s).  ``--skip-cold`` leaves this out (it takes
   about three minutes).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _timing import best_and_median
from reference_vs_mitsuba import compare
from render import DEFAULT_ENV, HELMET, grid_scene, helmet_scene


def _process_times(argv, repeat, env=None, cwd=None):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run(argv, check=True, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        times.append(time.perf_counter() - t0)
    return min(times), statistics.median(times)


def realtime(repeat):
    from pbrkit.data import environment_path
    from pbrkit.rendering.environment import EnvironmentLight
    from pbrkit.rendering.geometry import Geometry
    from pbrkit.rendering.realtime import render_realtime
    from pbrkit.rendering.scene import EnvironmentSpec

    spec = EnvironmentSpec(file=str(DEFAULT_ENV if DEFAULT_ENV.exists() else environment_path()))
    grid = grid_scene(1024, spec)
    env = EnvironmentLight(spec)
    baked = env.bake(size=256)
    geometry = Geometry(grid)
    render_realtime(grid, geometry, env, bake=baked)  # compile
    out = {"grid": best_and_median(lambda: render_realtime(grid, geometry, env, bake=baked), max(repeat, 5))}
    print(f"real time, 1024^2 grid, 4 lights + IBL: best {out['grid'][0]:.3f} s, median {out['grid'][1]:.3f} s "
          "(goal <= 0.5 s)")
    if HELMET.exists():
        helmet = helmet_scene(spec)
        geometry = Geometry(helmet)
        render_realtime(helmet, geometry, env, bake=baked)
        out["helmet"] = best_and_median(lambda: render_realtime(helmet, geometry, env, bake=baked), repeat)
        out["helmet_load"] = best_and_median(lambda: render_realtime(helmet, Geometry(helmet), env, bake=baked),
                                             repeat)
        print(f"real time, DamagedHelmet 512^2: render {out['helmet'][0]:.3f} s, with loading "
              f"{out['helmet_load'][0]:.3f} s (goal <= 2 s)")
    else:
        print(f"helmet: skipped ({HELMET} not found: needs ../shared/data/models)")
    return out


def startup():
    with tempfile.TemporaryDirectory() as tmp:
        lut = [sys.executable, "-m", "pbrkit", "lut", "--kind", "dfg", "--size", "128", "-o", "t.npy", "-q"]
        subprocess.run(lut, check=True, cwd=tmp)  # fills the result cache (and compiles, if needed)
        out = {"lut": _process_times(lut, 7, cwd=tmp),
               "lut_no_cache": _process_times(lut + ["--no-cache"], 3, cwd=tmp),
               "python": _process_times([sys.executable, "-c", "pass"], 5)}
    print(f"start-up, pbrkit lut --kind dfg --size 128 (cached table): best {out['lut'][0]:.2f} s, median "
          f"{out['lut'][1]:.2f} s (goal <= 0.3 s); integrating (--no-cache, warm kernels): "
          f"{out['lut_no_cache'][0]:.2f} s; python -c pass: {out['python'][0]:.2f} s")
    return out


def cold_start():
    out = {}
    demo = [sys.executable, "-m", "pbrkit", "demo", "-q", "-o"]
    for label, extra in (("cold", {}), ("cold_no_warm_up", {"PBRKIT_NO_WARM_UP": "1"})):
        with tempfile.TemporaryDirectory() as tmp:
            env = dict(os.environ, PBRKIT_CACHE_DIR=str(Path(tmp) / "cache"), **extra)
            out[label] = _process_times(demo + [str(Path(tmp) / "demo")], 1, env=env)[0]
            if label == "cold":
                out["warm"] = _process_times(demo + [str(Path(tmp) / "demo2")], 1, env=env)[0]
    print(f"cold start, first pbrkit demo: {out['cold']:.1f} s with the parallel warm-up, "
          f"{out['cold_no_warm_up']:.1f} s without (goal <= 30 s); warm: {out['warm']:.1f} s")
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--skip-cold", action="store_true", help="leave out the cold start (about 3 minutes)")
    parser.add_argument("--skip-mitsuba", action="store_true", help="leave out the ground truth against Mitsuba")
    args = parser.parse_args()
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = float("nan")
    print(f"cores: {os.cpu_count()}, load average {load:.2f}\n")
    rows = [] if args.skip_mitsuba else compare(["furnace", "overcast", "sunny"], repeat=args.repeat)
    print()
    rt = realtime(args.repeat)
    st = startup()
    cold = None if args.skip_cold else cold_start()

    print("\nsummary (goal; measured; baseline in this run)")
    for row in rows:
        if row["mitsuba"] is None:
            print(f"  ground truth {row['scene']}: {row['pbrkit'][0] / 1e6:.1f} M samples/s (Mitsuba not run)")
            continue
        verdict = "met" if row["ratio"][0] >= 1.0 else "NOT met"
        print(f"  ground truth {row['scene']}: >= 1.0x Mitsuba {row['variant']}; {row['ratio'][0]:.2f}x "
              f"({row['pbrkit'][0] / 1e6:.1f} vs {row['mitsuba'][0] / 1e6:.1f} M samples/s), time to equal noise "
              f"{row['equal_noise']:.2f}x; {verdict}")
    print(f"  real time grid 1024^2: <= 0.5 s; {rt['grid'][0]:.3f} s; {'met' if rt['grid'][0] <= 0.5 else 'NOT met'}")
    if "helmet" in rt:
        print(f"  DamagedHelmet 512^2: <= 2 s; {rt['helmet'][0]:.3f} s ({rt['helmet_load'][0]:.3f} s with loading); "
              f"{'met' if rt['helmet_load'][0] <= 2.0 else 'NOT met'}")
    print(f"  warm pbrkit lut: <= 0.3 s; {st['lut'][1]:.2f} s median; integrating {st['lut_no_cache'][0]:.2f} s, "
          f"python alone {st['python'][0]:.2f} s; {'met' if st['lut'][1] <= 0.3 else 'NOT met'}")
    if cold:
        print(f"  first pbrkit demo: <= 30 s; {cold['cold']:.1f} s; without the warm-up {cold['cold_no_warm_up']:.1f} s, "
              f"warm {cold['warm']:.1f} s; {'met' if cold['cold'] <= 30 else 'NOT met'}")


if __name__ == "__main__":
    main()
