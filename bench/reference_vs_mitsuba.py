"""Benchmark: pbrkit's ground truth against Mitsuba 3 on the same scenes, back to back.

    python bench/reference_vs_mitsuba.py [--size 256] [--spp 1024] [--repeat 3] [--scenes furnace,overcast,sunny]
                            [--variants llvm_ad_rgb]

Each scene is one sphere (radius 1, seen from 4.5 units with a 32 degree field of
view, about half of the pixels) under an environment, rendered by both with
direct lighting: one environment sample and one BRDF sample per pixel sample,
combined by multiple importance sampling with the power heuristic (pbrkit's
``render_reference(bounces=0)``; Mitsuba's ``direct`` integrator, whose defaults
are one emitter and one BSDF sample, the same estimator).

- ``furnace``: a white constant environment and a GGX conductor, alpha 0.25,
  F = 1 (pbrkit ``cook_torrance`` metallic 1, roughness 0.5, separable Smith,
  Fresnel ``none``; Mitsuba ``roughconductor``, ``material: none``, which uses
  separable Smith masking and visible-normal sampling as pbrkit does);
- ``overcast`` and ``sunny``: a tinted GGX conductor (specular colour
  (0.95, 0.64, 0.3), same lobe) under ``kloofendal_overcast_1k.hdr`` and
  ``rooitou_park_1k.hdr`` from ``../shared/data/env`` (a clear sky with the sun
  unclipped); without ``../shared/data`` they are skipped with a message and a
  ``bundled`` scene under pbrkit's CC0 map runs instead.  Mitsuba's map is turned
  so that its directions are pbrkit's (CONVENTIONS.md: u = 0.5 + atan2(z, x) / 2 pi).

Printed per scene, best and median of ``--repeat`` alternating runs (pbrkit, then
Mitsuba, with a different seed each time; the first call of each, which compiles
kernels, is a warm-up and not counted):

- samples/s: pixels x spp / the wall time of the whole render call (pbrkit's
  ``render_reference`` including its primary rays; Mitsuba's ``mi.render`` and
  the copy of the image out of Dr.Jit, its kernel already compiled and cached);
- noise per sample: the mean over pixels inside the sphere (one pixel in from its
  silhouette) of spp (Y_a - Y_b)^2 / 2 / Y^2 for two renders a, b with different
  seeds (Y the luminance): the variance of one sample relative to the pixel's
  value, measured the same way for both renderers;
- time to equal noise: Mitsuba's (time per sample x noise per sample) over
  pbrkit's; above 1 pbrkit reaches a given noise sooner;
- agreement: the mean luminance inside the sphere of both, relative (the
  furnace is the directional albedo in both; under maps Mitsuba filters texels
  bilinearly where pbrkit takes the nearest, so expect a few tenths of a percent).

Mitsuba is optional: ``pip install mitsuba`` (and Debian's ``libllvm19`` for the
LLVM variants).  Without it pbrkit's figures are printed alone with a message.
Both use every core of the machine (Numba's threads; Dr.Jit's thread pool).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from pbrkit.core.color import luminance
from pbrkit.rendering.environment import EnvironmentLight
from pbrkit.rendering.geometry import Geometry
from pbrkit.rendering.reference import render_reference
from pbrkit.rendering.scene import (
    Camera,
    EnvironmentSpec,
    MaterialSpec,
    Scene,
    Sphere,
    bundled_environment,
)

ENV_DIR = Path(__file__).resolve().parents[2] / "shared" / "data" / "env"
TINT = (0.95, 0.64, 0.3)
ALPHA = 0.25
SCENES = {
    "furnace": (None, (1.0, 1.0, 1.0)),
    "overcast": (ENV_DIR / "kloofendal_overcast_1k.hdr", TINT),
    "sunny": (ENV_DIR / "rooitou_park_1k.hdr", TINT),
    "bundled": ("bundled", TINT),
}
# Mitsuba's envmap (identity transform) shows along world direction v what pbrkit's equirect
# shows along (v_z, v_y, -v_x) (measured: radiance correlation 0.9994 over random directions,
# none of the other 47 signed axis permutations above 0.02), so its to_world is that rotation.
MITSUBA_ENV_TO_WORLD = [[0.0, 0.0, 1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [-1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]


def pbrkit_scene(env_file, tint, size):
    camera = Camera(position=(0.0, 0.0, 4.5), look_at=(0.0, 0.0, 0.0), fov=32.0, width=size, height=size)
    env = EnvironmentSpec(color=(1.0, 1.0, 1.0)) if env_file is None else EnvironmentSpec(file=str(env_file))
    material = MaterialSpec(model="cook_torrance", name="m", metallic=1.0, roughness=ALPHA ** 0.5,
                            masking="separable", fresnel="none", diffuse="none", specular_color=tint)
    return Scene(camera=camera, environment=env, materials={"default": MaterialSpec(), "m": material},
                 objects=(Sphere(center=(0.0, 0.0, 0.0), radius=1.0, material="m"),), lights=())


def mitsuba_scene(mi, env_file, tint, size, spp):
    if env_file is None:
        emitter = {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}}
    else:
        emitter = {"type": "envmap", "filename": str(env_file),
                   "to_world": mi.ScalarTransform4f(MITSUBA_ENV_TO_WORLD)}
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "direct"},
        "sensor": {"type": "perspective", "fov": 32.0, "fov_axis": "y",
                   "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 4.5], target=[0, 0, 0], up=[0, 1, 0]),
                   "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"},
                            "pixel_format": "rgb"},
                   "sampler": {"type": "independent", "sample_count": spp}},
        "emitter": emitter,
        "sphere": {"type": "sphere", "center": [0, 0, 0], "radius": 1.0,
                   "bsdf": {"type": "roughconductor", "material": "none", "distribution": "ggx", "alpha": ALPHA,
                            "specular_reflectance": {"type": "rgb", "value": list(tint)}}},
    })


def noise_per_sample(a, b, spp, inside):
    """Mean over ``inside`` of spp (Y_a - Y_b)^2 / 2 / Y^2 (module docstring)."""
    ya = luminance(a)[inside]
    yb = luminance(b)[inside]
    y = 0.5 * (ya + yb)
    keep = y > 0
    return float(np.mean(spp * (ya - yb)[keep] ** 2 / 2.0 / y[keep] ** 2))


def interior(mask):
    """The pixels of ``mask`` whose four neighbours are in it too (away from the silhouette)."""
    m = mask.copy()
    m[1:, :] &= mask[:-1, :]
    m[:-1, :] &= mask[1:, :]
    m[:, 1:] &= mask[:, :-1]
    m[:, :-1] &= mask[:, 1:]
    return m


def load_mitsuba(variant):
    try:
        import mitsuba as mi
    except ImportError:
        return None, "Mitsuba 3 is not installed (pip install mitsuba; Debian libllvm19 for its LLVM variants)"
    try:
        mi.set_variant(variant)
    except Exception as exc:  # a variant that this build or machine lacks
        return None, f"Mitsuba variant {variant} is not available here ({exc})"
    return mi, None


def compare(names, size=256, spp=1024, repeat=3, variants=("llvm_ad_rgb",), out=print):
    """Render each scene of ``names`` in pbrkit and in each Mitsuba variant, back to back
    (module docstring); print the figures with ``out`` and return one dict per
    (scene, variant) with ``pbrkit`` and ``mitsuba`` samples/s (best, median), noise
    per sample, the samples/s ratio (best, median) and the time-to-equal-noise ratio
    (``mitsuba`` None where Mitsuba was skipped)."""
    if not ENV_DIR.is_dir() and any(SCENES[n][0] not in (None, "bundled") for n in names):
        out(f"{ENV_DIR} not found (needs ../shared/data/env): the map scenes are skipped, "
            "the bundled map's scene runs instead")
        names = [n for n in names if SCENES[n][0] in (None, "bundled")] + ["bundled"]
    repeat = max(repeat, 2)
    samples = size * size * spp
    out(f"{size}^2 pixels, {spp} spp ({samples / 1e6:.0f} M samples per render), best / median of {repeat} runs")
    rows = []
    for name in names:
        env_file, tint = SCENES[name]
        if env_file == "bundled":
            env_file = bundled_environment()
        scene = pbrkit_scene(env_file, tint, size)
        geometry = Geometry(scene)
        env = EnvironmentLight(scene.environment)
        render_reference(scene, spp=2, geometry=geometry, env=env)  # compile (warm-up)
        times, images = [], []
        for r in range(repeat):
            t0 = time.perf_counter()
            result = render_reference(scene, spp=spp, seed=r + 1, geometry=geometry, env=env)
            times.append(time.perf_counter() - t0)
            images.append(result.image)
        inside = interior(result.mask)
        pb_noise = noise_per_sample(images[0], images[1], spp, inside)
        pb_best, pb_median = samples / min(times), samples / statistics.median(times)
        pb_mean = float(np.mean(luminance(images[0])[inside]))
        out(f"{name}: pbrkit reference  {pb_best / 1e6:6.1f} M samples/s (median {pb_median / 1e6:.1f}), "
            f"noise per sample {pb_noise:.4f}")
        for variant in variants:
            row = {"scene": name, "variant": variant, "pbrkit": (pb_best, pb_median), "pbrkit_noise": pb_noise,
                   "mitsuba": None}
            rows.append(row)
            mi, why = load_mitsuba(variant)
            if mi is None:
                out(f"{name}: Mitsuba skipped: {why}")
                continue
            ms = mitsuba_scene(mi, env_file, tint, size, spp)
            np.asarray(mi.render(ms, spp=spp))  # compile (warm-up)
            mtimes, mimages = [], []
            for r in range(repeat):
                t0 = time.perf_counter()
                mimages.append(np.array(mi.render(ms, spp=spp, seed=r + 1))[..., :3].astype(np.float64))
                mtimes.append(time.perf_counter() - t0)
            mi_best, mi_median = samples / min(mtimes), samples / statistics.median(mtimes)
            mi_noise = noise_per_sample(mimages[0], mimages[1], spp, inside)
            mi_mean = float(np.mean(luminance(mimages[0])[inside]))
            equal_noise = (mi_noise / mi_best) / (pb_noise / pb_best)
            row.update(mitsuba=(mi_best, mi_median), mitsuba_noise=mi_noise,
                       ratio=(pb_best / mi_best, pb_median / mi_median), equal_noise=equal_noise,
                       agreement=pb_mean / mi_mean - 1.0)
            out(f"{name}: Mitsuba {variant:12s} {mi_best / 1e6:6.1f} M samples/s (median {mi_median / 1e6:.1f}), "
                f"noise per sample {mi_noise:.4f}")
            out(f"{name}: pbrkit / Mitsuba {variant}: samples/s {pb_best / mi_best:.2f}x best, "
                f"{pb_median / mi_median:.2f}x median; time to equal noise {equal_noise:.2f}x in pbrkit's favour; "
                f"mean inside the sphere {pb_mean:.4f} vs {mi_mean:.4f} ({(pb_mean / mi_mean - 1) * 100:+.2f}%)")
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=256, help="image side in pixels")
    parser.add_argument("--spp", type=int, default=1024, help="samples per pixel")
    parser.add_argument("--repeat", type=int, default=3, help="timed runs of each renderer per scene")
    parser.add_argument("--scenes", default="furnace,overcast,sunny",
                        help=f"comma-separated, from {', '.join(SCENES)}")
    parser.add_argument("--variants", default="llvm_ad_rgb",
                        help="comma-separated Mitsuba variants to measure (e.g. llvm_ad_rgb,scalar_rgb)")
    args = parser.parse_args()
    names = [s for s in args.scenes.split(",") if s]
    for name in names:
        if name not in SCENES:
            sys.exit(f"unknown scene {name!r}; choose from {', '.join(SCENES)}")
    compare(names, args.size, args.spp, args.repeat, [v for v in args.variants.split(",") if v])


if __name__ == "__main__":
    main()
