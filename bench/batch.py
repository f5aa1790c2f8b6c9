"""Benchmark of ``pbrkit batch bake`` on Dask against the best sequential loop (issue 14).

    python bench/batch.py [--count 8] [--size 256] [--repeat 4] [--skip-512] [--data DIR]

Inputs: the 1k HDRIs of ``../shared/data/env`` (Poly Haven), cycled to
``--count`` files with distinct names (or copies of the bundled environment
when that folder is absent).  Every measurement below runs in this one
invocation, interleaved (sequential, batch 2 x 1, batch 1 x 2, the order
rotating from round to round), best of ``--repeat``; the rounds' paired
ratios are printed too, since the shared machine's load varies:

1. Sequential: the same ``bake`` + ``write_bake`` calls ``pbrkit bake`` makes,
   one input after the other in this process, after a warm-up bake (Numba's
   kernels loaded), with Numba's default threads (all cores).
2. Batch, end to end as the command runs it (:func:`pbrkit.app.batch.run_batch`
   in a fresh process, timed from its call to its return: LocalCluster start,
   the tasks, the summary and gallery, shutdown), into a fresh folder each
   time: ``--workers 2 --threads 1`` (2 worker processes, 1 Numba thread
   each) and ``--workers 1 --threads 2``, both with the dashboard (the
   default), and 2 x 1 with ``--no-dashboard``.  Goal: the faster default one
   within 1.1x of the best sequential loop.
3. Overheads of the 2 x 1 batch: the fixed cost (cluster start + shutdown +
   summary) and the per-task overhead, (task phase x workers - sum of the
   tasks' own times) / tasks; and a re-run where every input is up to date
   (each task hashes its input and reads its manifest).
4. The estimate for 700 HDRIs at 512 on 8 machines like this one: a batch of
   ``--count`` bakes at 512 on this machine gives the per-input time of one
   machine; 700 inputs on 8 machines are ceil(700 / 8) = 88 inputs per machine.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data" / "env"


def prepare_inputs(folder, count, data=DATA):
    """``count`` HDR files with distinct names in ``folder``: the .hdr files of ``data``
    (default the shared 1k HDRIs) cycled, or copies of the bundled map."""
    from pbrkit.data import environment_path

    sources = sorted(p for p in Path(data).glob("*.hdr")) if Path(data).is_dir() else []
    sources = sources or [environment_path()]
    paths = []
    for k in range(count):
        src = sources[k % len(sources)]
        dst = folder / f"{src.stem}_{k}{src.suffix}"
        shutil.copyfile(src, dst)
        paths.append(dst)
    return paths


def sequential(paths, out, options):
    """One loop of ``pbrkit bake``'s calls over ``paths``; seconds."""
    from pbrkit.ibl.bake import bake
    from pbrkit.io.bake_files import write_bake

    t0 = time.perf_counter()
    for p in paths:
        b = bake(p, size=options["size"], min_size=options["min_size"], irradiance_size=options["irradiance_size"],
                 lut_size=options["lut_size"])
        write_bake(b, out / p.stem)
    return time.perf_counter() - t0


def batch(paths, out, options, workers, threads, dashboard=True):
    """One batch, end to end, timed around :func:`pbrkit.app.batch.run_batch` in a
    fresh process that has run no kernel, as the command's is (so its LocalCluster
    forks its workers); (wall seconds, summary)."""
    import json
    import subprocess

    spec = json.dumps({"paths": [str(p) for p in paths], "out": str(out), "options": options, "workers": workers,
                       "threads": threads, "dashboard": dashboard})
    done = subprocess.run([sys.executable, __file__, "--child", spec], capture_output=True, text=True, check=True)
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert result["summary"]["counts"]["failed"] == 0, result["summary"]
    return result["wall"], result["summary"]


def child(spec):
    """Run in a fresh process: the batch of ``spec``; print one JSON line."""
    import json

    from pbrkit.app.batch import run_batch

    spec = json.loads(spec)
    t0 = time.perf_counter()
    summary = run_batch("bake", [Path(p) for p in spec["paths"]], spec["out"], spec["options"],
                        workers=spec["workers"], threads=spec["threads"], dashboard=spec["dashboard"])
    print(json.dumps({"wall": time.perf_counter() - t0, "summary": summary}))


def overheads(wall, summary):
    """(fixed seconds, per-task overhead seconds, first-task extra seconds) of a batch."""
    tasks = [o["seconds"] for o in summary["inputs"]]
    fixed = wall - summary["tasks_seconds"]
    per_task = (summary["tasks_seconds"] * summary["workers"] - sum(tasks)) / len(tasks)
    firsts = {}
    for o in summary["inputs"]:  # outcomes in input order; a worker's first input is the first it took
        firsts.setdefault(o["pid"], o["seconds"])
    first_extra = statistics.mean(firsts.values()) - statistics.median(tasks)
    return fixed, per_task, first_extra


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=8)
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--repeat", type=int, default=4)
    parser.add_argument("--skip-512", action="store_true")
    parser.add_argument("--data", type=Path, default=DATA, help="folder of .hdr inputs (default ../shared/data/env)")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        return child(args.child)
    warnings.simplefilter("ignore")
    from pbrkit.app.batch import bake_jobs_options, default_workers
    from pbrkit.core.jit import cache_directory

    cores = default_workers()
    load = os.getloadavg()[0]
    print(f"pbrkit batch benchmark: {cores} cores, load average {load:.1f} at start, Numba cache {cache_directory()}")
    options = bake_jobs_options(size=args.size)
    with tempfile.TemporaryDirectory(prefix="pbrkit-bench-batch-") as tmp:
        tmp = Path(tmp)
        (tmp / "in").mkdir()
        paths = prepare_inputs(tmp / "in", args.count, args.data)
        print(f"inputs: {len(paths)} x {paths[0].name.rsplit('_', 1)[0]}... "
              f"({', '.join(sorted({p.stem.rsplit('_', 1)[0] for p in paths}))})")
        sequential(paths[:1], tmp / "warm", options)  # Numba's kernels loaded (compiled if the cache is cold)
        # the workers' first batch fills nothing more: the cache is shared (PBRKIT_CACHE_DIR)
        times = {"sequential": [], "batch 2x1": [], "batch 1x2": [], "2x1 no dash": []}
        summaries = {}
        configs = {"batch 2x1": (2, 1), "batch 1x2": (1, 2), "2x1 no dash": (2, 1, False)}
        names = list(times)
        for r in range(args.repeat):
            for name in names[r % len(names):] + names[:r % len(names)]:  # the order rotates
                out = tmp / f"{name.replace(' ', '')}-{r}"
                if name == "sequential":
                    times[name].append(sequential(paths, out, options))
                else:
                    wall, summary = batch(paths, out, options, *configs[name])
                    times[name].append(wall)
                    if wall == min(times[name]):
                        summaries[name] = (wall, summary)
                    if name == "batch 2x1" and r == args.repeat - 1:  # up to date: every input skipped
                        skip_wall, skipped = batch(paths, out, options, 2, 1)
                        assert skipped["counts"]["skipped"] == len(paths)
                shutil.rmtree(out)
            print(f"round {r + 1} (load average {os.getloadavg()[0]:.1f}): "
                  + ", ".join(f"{k} {v[-1]:.2f} s" for k, v in times.items())
                  + "; ratios " + ", ".join(f"{k} {times[k][-1] / times['sequential'][-1]:.3f}" for k in configs))
        best = {k: min(v) for k, v in times.items()}
        seq = best["sequential"]
        print(f"\n== {len(paths)} bakes at {args.size} (bake + write), best of {args.repeat} ==")
        for name, t in best.items():
            phase = ""
            if name in summaries:
                s = summaries[name][1]
                phase = (f"; task phase {s['tasks_seconds']:.2f} s, tasks' own times "
                         f"{sum(o['seconds'] for o in s['inputs']):.2f} s")
            paired = ""
            if name != "sequential":
                ratios = [b / a for a, b in zip(times["sequential"], times[name])]
                paired = f", median of the rounds' ratios {statistics.median(ratios):.3f}"
            print(f"{name:12s} {t:7.2f} s  ({t / len(paths):.2f} s per input)  ratio of the bests {t / seq:.3f}"
                  + paired + phase)
        faster = min(("batch 2x1", "batch 1x2"), key=lambda k: best[k])
        print(f"faster batch configuration: {faster} (workers x Numba threads); goal <= 1.1x: "
              f"{best[faster] / seq:.3f}x {'met' if best[faster] / seq <= 1.1 else 'NOT met'}")
        wall, summary = summaries["batch 2x1"]
        fixed, per_task, first_extra = overheads(wall, summary)
        print(f"\n== overheads of the best 2x1 batch ({wall:.2f} s) ==")
        print(f"fixed: {fixed:.2f} s (LocalCluster start {summary['start_seconds']:.2f} s, shutdown + summary "
              f"{wall - summary['start_seconds'] - summary['tasks_seconds']:.2f} s)")
        print(f"per task: {per_task:.3f} s of worker time outside the tasks (scheduling, transfer, idle tail)")
        print(f"first task on each worker: +{first_extra:.2f} s over the median task (imports, kernels loaded "
              f"from the cache)")
        print(f"re-run with every input up to date: {skip_wall:.2f} s in all, "
              f"{skipped['tasks_seconds'] / len(paths) * skipped['workers']:.3f} s of worker time per input")
        if not args.skip_512:
            opt512 = bake_jobs_options(size=512)
            t512 = []
            for r in range(args.repeat):
                out = tmp / f"b512-{r}"
                wall512, s512 = batch(paths, out, opt512, *configs[faster])
                t512.append((wall512, s512))
                shutil.rmtree(out)
            wall512, s512 = min(t512, key=lambda x: x[0])
            per_input = s512["tasks_seconds"] / len(paths)
            fixed512 = wall512 - s512["tasks_seconds"]
            per_machine = math.ceil(700 / 8)
            total = per_machine * per_input + fixed512
            print(f"\n== 700 HDRIs at 512 on 8 machines like this one ({faster}) ==")
            print(f"measured: {len(paths)} bakes at 512 in {wall512:.2f} s, task phase {s512['tasks_seconds']:.2f} s "
                  f"= {per_input:.2f} s per input per machine, fixed {fixed512:.2f} s")
            print(f"estimate: ceil(700 / 8) = {per_machine} inputs per machine x {per_input:.2f} s + {fixed512:.1f} s "
                  f"= {total:.0f} s ({total / 60:.1f} min); one machine alone: 700 x {per_input:.2f} s = "
                  f"{700 * per_input / 60:.1f} min")
    print(f"load average at the end: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    sys.exit(main())
