"""Benchmark: ``pbrkit render`` on the built-in sphere grid (49 spheres).

    python bench/render.py [--size 1024] [--gt-size 512] [--spp 32] [--repeat 5] [--env PATH]

Prints, measured in one run (Numba compilation excluded by a warm-up call):

- real time: the 1024 x 1024 grid with 4 punctual lights (directional, point,
  two spots, shadow rays) and split-sum IBL from a 256^2 bake of the
  environment; the bake itself is timed separately (issue 5 target: <= 1 s
  for the render on the 2-core machine);
- ground truth under ``rooitou_park_1k.hdr`` (a clear sky with an unclipped
  sun): paths per second of the direct-lighting estimator (environment +
  BRDF sampling with MIS, two shadow/continuation rays per path), and the
  noise per sample -- the mean over surface pixels of the per-path variance of
  the luminance relative to the squared mean luminance -- for MIS and for BRDF
  sampling alone (issue 5 aim: >= 15 M paths/s on 2 cores, noise per sample no
  worse than BRDF-only sampling).  The spheres do not occlude one another in
  this measurement (``occlusion=False``) unless ``--occlusion`` is given;
- area lights (issue 11): the same real-time grid with a rect, a disk and a
  sphere light added (LTC, :mod:`pbrkit.rendering.area_lights`), its time against
  the grid without them measured in the same run; and the built-in ``area``
  scene (five spheres on a floor under a rect light) as ground truth with
  occlusion: paths per second and noise per sample with light sampling + BRDF
  sampling (MIS) against BRDF sampling alone, the efficiency ratio being what
  the spherical-rectangle sampling buys;
- styles (issue 12): each ``--style`` preset on the same grid, against the plain
  real-time render of the same run (goal: at most 1.5x).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np
from _timing import best_and_median

from pbrkit.core.color import luminance
from pbrkit.rendering.area_lights import AreaLight
from pbrkit.rendering.environment import EnvironmentLight
from pbrkit.rendering.geometry import Geometry
from pbrkit.rendering.lights import Light
from pbrkit.rendering.realtime import render_realtime
from pbrkit.rendering.reference import render_reference
from pbrkit.rendering.scene import EnvironmentSpec, builtin_scene

DEFAULT_ENV = Path(__file__).resolve().parents[2] / "shared" / "data" / "env" / "rooitou_park_1k.hdr"
HELMET = Path(__file__).resolve().parents[2] / "shared" / "data" / "models" / "DamagedHelmet.glb"

LIGHTS = (
    Light(type="directional", direction=(-0.3, -1.0, -0.5), intensity=2.0),
    Light(type="point", position=(0.0, 0.0, 6.0), intensity=30.0, range=40.0),
    Light(type="spot", position=(-6.0, 8.0, 6.0), direction=(0.5, -0.7, -0.5), intensity=80.0,
          inner_cone_angle=0.3, outer_cone_angle=0.6),
    Light(type="spot", position=(6.0, -8.0, 6.0), direction=(-0.5, 0.7, -0.5), intensity=80.0, color=(0.6, 0.8, 1.0),
          inner_cone_angle=0.2, outer_cone_angle=0.5, falloff="ue4"),
)


def grid_scene(size, env_spec):
    """The built-in sphere grid at size^2 under ``env_spec`` with :data:`LIGHTS`."""
    scene = builtin_scene("spheres", size, size, env_spec)
    return type(scene)(camera=scene.camera, environment=scene.environment, materials=scene.materials,
                       objects=scene.objects, lights=LIGHTS, source="spheres + 4 lights")


def helmet_scene(env_spec):
    """The DamagedHelmet (:data:`HELMET`) at 512^2 under ``env_spec``."""
    from pbrkit.rendering.scene import Camera, GltfObject, Scene

    return Scene(camera=Camera(position=(0.0, 0.0, 3.2), look_at=(0.0, 0.0, 0.0), fov=40.0, width=512, height=512),
                 environment=env_spec, objects=(GltfObject(file=str(HELMET)),), source="DamagedHelmet")


def relative_noise_per_sample(result):
    """Mean over surface pixels of spp * stderr(Y)^2 / mean(Y)^2 (the luminance variance of
    one path relative to the pixel's value; stderr of Y from the channel stderrs, an upper
    bound when the channels are positively correlated)."""
    spp = result.stats["spp"]
    y = luminance(result.image)
    se = luminance(result.stderr)
    sel = result.mask & (y > 0)
    return float(np.mean(spp * se[sel] ** 2 / y[sel] ** 2))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=1024, help="real-time image side")
    parser.add_argument("--gt-size", type=int, default=512, help="ground-truth image side")
    parser.add_argument("--spp", type=int, default=32, help="ground-truth samples per pixel")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--bake-size", type=int, default=256)
    parser.add_argument("--env", type=Path, default=DEFAULT_ENV)
    parser.add_argument("--occlusion", action="store_true", help="let the spheres occlude one another")
    parser.add_argument("--sections", default="realtime,reference,area,styles,helmet",
                        help="comma-separated sections to run (the real-time baseline always runs)")
    args = parser.parse_args()
    if not args.env.exists():
        sys.exit(f"environment {args.env} not found (needs ../shared/data/env)")
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = float("nan")
    print(f"cores: {os.cpu_count()}, load average {load:.2f}; environment {args.env.name}")

    env_spec = EnvironmentSpec(file=str(args.env))
    scene = grid_scene(args.size, env_spec)
    env = EnvironmentLight(env_spec)
    t0 = time.perf_counter()
    baked = env.bake(size=args.bake_size)
    print(f"bake {args.bake_size}^2 ({len(baked.specular)} levels): {time.perf_counter() - t0:.2f} s "
          "(first call, Numba compilation included)")
    geometry = Geometry(scene)
    render_realtime(scene, geometry, env, bake=baked)  # warm-up (compilation)
    results = []

    def realtime():
        results.append(render_realtime(scene, geometry, env, bake=baked))

    best, median = best_and_median(realtime, args.repeat)
    stages = results[-1].stats["timings"]
    print(f"real time {args.size}x{args.size}, 4 lights + IBL: best {best:.3f} s, median {median:.3f} s "
          "(goal <= 0.5 s, issue 15)")
    print("  stages of the last run: " + ", ".join(f"{k} {v:.3f}" for k, v in stages.items() if k != "bake"))

    sections = set(args.sections.split(","))
    if "reference" in sections:
        reference(args, env_spec, env)
    if "area" in sections:
        area_lights(args, scene, env, baked, best)
    if "styles" in sections:
        styles(args, scene, env, baked, best)
    if "helmet" in sections:
        helmet(args, env_spec, env, baked)


def helmet(args, env_spec, env, baked):
    """Issue 15's glTF figure: the DamagedHelmet (its 2048^2 textures) at 512^2 in real
    time, the render alone and with the model's loading (glTF, textures, tangents)."""
    if not HELMET.exists():
        print(f"helmet: skipped ({HELMET} not found: needs ../shared/data/models)")
        return
    scene = helmet_scene(env_spec)
    geometry = Geometry(scene)
    render_realtime(scene, geometry, env, bake=baked)  # warm-up
    best, median = best_and_median(lambda: render_realtime(scene, geometry, env, bake=baked), args.repeat)
    load_best, load_median = best_and_median(lambda: render_realtime(scene, Geometry(scene), env, bake=baked),
                                             args.repeat)
    print(f"real time DamagedHelmet 512x512: best {best:.3f} s, median {median:.3f} s (goal <= 2 s); with the "
          f"model's loading: best {load_best:.3f} s, median {load_median:.3f} s")


def reference(args, env_spec, env):
    """Ground-truth paths per second and noise per sample (module docstring)."""
    gt_scene = builtin_scene("spheres", args.gt_size, args.gt_size, env_spec)
    gt_geometry = Geometry(gt_scene)
    occlusion = bool(args.occlusion)
    render_reference(gt_scene, spp=2, geometry=gt_geometry, env=env, occlusion=occlusion)  # warm-up
    for strategy in ("mis", "brdf"):
        res = render_reference(gt_scene, spp=args.spp, geometry=gt_geometry, env=env, strategy=strategy,
                               occlusion=occlusion)
        s = res.stats
        noise = relative_noise_per_sample(res)
        print(f"ground truth {args.gt_size}x{args.gt_size}, {args.spp} spp, {strategy:4s}: "
              f"{s['surface_paths'] / 1e6:.2f} M paths in {s['timings']['sampling']:.2f} s = "
              f"{s['paths_per_second'] / 1e6:.2f} M paths/s; noise per sample (relative variance) {noise:.4g}; "
              f"efficiency 1 / (noise x time per path) {s['paths_per_second'] / noise / 1e6:.3g} M")


AREA_LIGHTS = (AreaLight(type="rect", position=(0.0, 12.0, 10.0), normal=(0.0, -0.7, -0.7), width=8.0, height=3.0,
                         intensity=5.0),
               AreaLight(type="disk", position=(-10.0, 0.0, 8.0), normal=(0.8, 0.0, -0.6), radius=2.0, intensity=4.0),
               AreaLight(type="sphere", position=(10.0, -6.0, 6.0), radius=1.5, intensity=6.0))


def area_lights(args, scene, env, baked, best_without):
    """The issue-11 figures (module docstring)."""
    lit = type(scene)(camera=scene.camera, environment=scene.environment, materials=scene.materials,
                      objects=scene.objects, lights=scene.lights, area_lights=AREA_LIGHTS,
                      source="spheres + 4 lights + 3 area lights")
    geometry = Geometry(lit)
    render_realtime(lit, geometry, env, bake=baked)  # warm-up (compilation)
    results = []
    best, median = best_and_median(lambda: results.append(render_realtime(lit, geometry, env, bake=baked)),
                                   args.repeat)
    stage = results[-1].stats["timings"].get("area_lights", float("nan"))
    print(f"real time {args.size}x{args.size}, 4 lights + IBL + rect, disk and sphere lights (LTC): best {best:.3f} s,"
          f" median {median:.3f} s = {best / best_without:.2f}x the render without them (area-light stage "
          f"{stage:.3f} s)")
    area = builtin_scene("area", args.gt_size)
    area_geometry = Geometry(area)
    area_env = EnvironmentLight(area.environment)
    render_reference(area, spp=2, geometry=area_geometry, env=area_env)  # warm-up
    figures = {}
    for strategy in ("mis", "brdf"):
        res = render_reference(area, spp=args.spp, geometry=area_geometry, env=area_env, strategy=strategy)
        s = res.stats
        noise = relative_noise_per_sample(res)
        figures[strategy] = s["paths_per_second"] / noise
        print(f"ground truth 'area' {area.camera.width}x{area.camera.height}, {args.spp} spp, occlusion, "
              f"{strategy:4s}: {s['paths_per_second'] / 1e6:.2f} M paths/s; noise per sample {noise:.4g}; "
              f"efficiency {figures[strategy] / 1e6:.3g} M")
    print(f"  light sampling + MIS is {figures['mis'] / figures['brdf']:.1f}x as efficient as BRDF sampling alone")

def styles(args, scene, env, baked, best_without):
    """Issue 12's figure: each style preset on the same 1024^2 grid with its 4 lights,
    against the plain real-time render measured in the same run (goal: at most 1.5x)."""
    from pbrkit.npr.render import render_styled
    from pbrkit.npr.style import STYLE_PRESETS

    geometry = Geometry(scene)
    for name in ("toon", "toon-per-light", "mtoon", "hatching", "outline"):
        style = STYLE_PRESETS[name]
        render_styled(scene, style, geometry, env, bake=baked)  # warm-up (compilation, the hatching map)
        results = []
        best, median = best_and_median(lambda: results.append(render_styled(scene, style, geometry, env,
                                                                            bake=baked)), args.repeat)
        t = results[-1].stats["timings"]
        print(f"style {name:15s} {args.size}x{args.size}: best {best:.3f} s, median {median:.3f} s = "
              f"{best / best_without:.2f}x the plain real-time render (shading {t['shading']:.3f} s, outlines "
              f"{t['outlines']:.3f} s)")


if __name__ == "__main__":
    main()
