"""Paired A/B timing of the ground truth and the real time on the built-in sphere grid (49
plain ``gltf`` materials): two source trees (a base and a candidate) in two warm worker processes,
called alternately (the order swapped every pair), so that both see the same load.

    python bench/reference_ab.py BASE_ROOT NEW_ROOT [--pairs 31]

Each worker renders, after a warm-up (Numba compilation, or its disk cache), the
sphere grid at 128 x 128 with the lane engine (direct lighting, 128 spp), the fused
kernel (2 bounces, 32 spp), the wavefront loop (2 bounces, 8 spp) and the real time at 512 x 512
(a size-128 bake made once; the time of every stage after it); the script prints
each case's median sampling time per tree, the median and interquartile range of the
paired ratios new / base, and whether the images are identical.  Each tree gets its own
Numba cache directory (``XDG_CACHE_HOME`` under the system's temporary directory).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

CASES = {"lanes": dict(spp=128, bounces=0), "fused": dict(spp=32, bounces=2),
         "wavefront": dict(spp=8, bounces=2, engine="wavefront"), "realtime": None}


def worker():
    import importlib

    try:  # the subpackage's name since issue 26 (pbrkit.render before: older trees)
        package = importlib.import_module("pbrkit.rendering")
    except ImportError:
        package = importlib.import_module("pbrkit.render")
    name = package.__name__
    EnvironmentLight = importlib.import_module(f"{name}.environment").EnvironmentLight
    Geometry = importlib.import_module(f"{name}.geometry").Geometry
    render_reference = importlib.import_module(f"{name}.reference").render_reference
    builtin_scene = importlib.import_module(f"{name}.scene").builtin_scene
    render_realtime = importlib.import_module(f"{name}.realtime").render_realtime

    scene = builtin_scene("spheres", 128, 128)
    geometry = Geometry(scene)
    env = EnvironmentLight(scene.environment)
    large = builtin_scene("spheres", 512, 512)
    large_geometry = Geometry(large)
    baked = env.bake(size=128)

    def realtime():
        result = render_realtime(large, large_geometry, env, bake=baked)
        timings = result.stats["timings"]
        return sum(v for k, v in timings.items() if k not in ("load", "bake", "total")), result.image

    for name, kw in CASES.items():
        realtime() if kw is None else render_reference(scene, geometry=geometry, env=env, **kw)
    print("ready", flush=True)
    for line in sys.stdin:
        name, seed = line.split()
        if CASES[name] is None:
            seconds, image = realtime()
        else:
            result = render_reference(scene, geometry=geometry, env=env, seed=int(seed), **CASES[name])
            seconds, image = result.stats["timings"]["sampling"], result.image
        print(json.dumps([seconds, float(image.mean())]), flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("base")
    parser.add_argument("new")
    parser.add_argument("--pairs", type=int, default=31)
    args = parser.parse_args()

    def spawn(root, tag):
        env = dict(os.environ, PYTHONPATH=os.path.join(root, "src"),
                   XDG_CACHE_HOME=os.path.join(tempfile.gettempdir(), f"pbrkit-ab-{tag}"))
        p = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--worker"], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, text=True, env=env, cwd=root)
        if p.stdout.readline().strip() != "ready":
            raise SystemExit(f"the worker of {root} did not start")
        return p

    a = spawn(os.path.abspath(args.base), "base")
    b = spawn(os.path.abspath(args.new), "new")

    def run(p, name, seed):
        p.stdin.write(f"{name} {seed}\n")
        p.stdin.flush()
        return json.loads(p.stdout.readline())

    for name in CASES:
        ta, tb, same = [], [], True
        for r in range(args.pairs):
            results = {}
            for p in ((a, b) if r % 2 == 0 else (b, a)):
                results[id(p)] = run(p, name, r)
            ta.append(results[id(a)][0])
            tb.append(results[id(b)][0])
            same &= results[id(a)][1] == results[id(b)][1]
        ratio = np.array(tb) / np.array(ta)
        print(f"{name}: base {np.median(ta):.4f} s, new {np.median(tb):.4f} s, new / base {np.median(ratio):.3f} "
              f"(IQR {np.percentile(ratio, 25):.3f}-{np.percentile(ratio, 75):.3f}), identical images: {same}",
              flush=True)
    for p in (a, b):
        p.stdin.close()
        p.wait()


if __name__ == "__main__":
    if "--worker" in sys.argv:
        worker()
    else:
        main()
