"""Real-time KHR_materials_transmission and KHR_materials_volume against the ground
truth (issue 25): spheres of each kind under the bundled environment, rendered by
``render_realtime`` (``engine`` pbrkit and khronos: the transmitted light from the
prefiltered environment, :mod:`pbrkit.rendering.transmission_ibl`) and by the ground
truth (``render_reference``, 8 bounces: light refracts into a solid sphere and out
again), compared per sphere in 8-bit sRGB levels (mean |grey| and the signed mean).

    PYTHONPATH=src python bench/transmission_rt.py [--spp 256] [--size 96]

Prints a Markdown table.  What it measures is the approximation: one refraction
(into the volume only) and a fixed path length (the volume's thickness) in place of
the real path, and the environment in place of what lies behind.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from pbrkit.core.color import linear_to_srgb
from pbrkit.rendering.realtime import render_realtime
from pbrkit.rendering.reference import render_reference
from pbrkit.rendering.scene import Camera, EnvironmentSpec, MaterialSpec, Scene, Sphere, bundled_environment

#: (label, material keys): one sphere each, left to right.
SPHERES = (
    ("thin wall, r 0.05", dict(transmission=1.0, roughness=0.05)),
    ("thin wall, r 0.4", dict(transmission=1.0, roughness=0.4)),
    ("volume (diameter), r 0.05", dict(transmission=1.0, roughness=0.05, thickness=1.0)),
    ("volume, attenuation", dict(transmission=1.0, roughness=0.05, thickness=1.0, attenuation_distance=0.5,
                                 attenuation_color=(0.9, 0.5, 0.2))),
    ("half transmission, r 0.3", dict(transmission=0.5, roughness=0.3)),
    ("volume, dispersion 1 (ior 1.8)", dict(transmission=1.0, roughness=0.05, thickness=1.0, ior=1.8, dispersion=1.0)),
)


def sphere_row(spheres, size, **base):
    """A row of spheres (radius 0.5), one per (label, material keys) of ``spheres`` over the
    material keys ``base``, under the bundled environment (intensity 0.5), far camera;
    ``size`` x ``size`` / 2 pixels per two spheres."""
    materials = {"default": MaterialSpec()}
    objects = []
    for k, (_, keys) in enumerate(spheres):
        name = f"s{k}"
        materials[name] = MaterialSpec(name=name, **{**base, **keys})
        objects.append(Sphere(center=(1.2 * (k - (len(spheres) - 1) / 2), 0.0, 0.0), radius=0.5, material=name))
    cam = Camera(position=(0.0, 0.0, 12.0), look_at=(0.0, 0.0, 0.0), fov=7.0, width=size * len(spheres) // 2,
                 height=size // 2)
    return Scene(camera=cam, environment=EnvironmentSpec(file=str(bundled_environment()), intensity=0.5),
                 materials=materials, objects=tuple(objects))


def scene(size):
    return sphere_row(SPHERES, size, base_color=(1.0, 1.0, 1.0), metallic=0.0)


def sphere_columns(s):
    """Each pixel's sphere of a :func:`sphere_row` scene: the nearest projected centre along x."""
    cam = s.camera
    _, cols = cam.project(np.array([o.center for o in s.objects]))
    return np.broadcast_to(np.argmin(np.abs(np.arange(cam.width)[:, None] + 0.5 - cols[None, :]), axis=1),
                           (cam.height, cam.width))


def srgb8(x):
    """8-bit sRGB levels of linear values (clipped to [0, 1])."""
    return np.round(255.0 * linear_to_srgb(np.clip(x, 0.0, 1.0)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=256)
    parser.add_argument("--size", type=int, default=96)
    args = parser.parse_args()
    s = scene(args.size)
    t = time.perf_counter()
    truth = render_reference(s, spp=args.spp, bounces=8)
    t_truth = time.perf_counter() - t
    rt = {e: render_realtime(s, bake_size=128, engine=e) for e in ("pbrkit", "khronos")}
    column = sphere_columns(s)
    mask = truth.mask & rt["pbrkit"].mask
    ref8 = srgb8(truth.image).mean(-1)
    print(f"ground truth {args.spp} spp, 8 bounces ({t_truth:.1f} s); 8-bit sRGB levels, mean |grey| "
          "(signed mean: real time minus ground truth)\n")
    print("| sphere | pbrkit | khronos | ground-truth noise |")
    print("|---|---|---|---|")
    noise = np.abs(srgb8(truth.image + truth.stderr).mean(-1) - ref8)
    for k, (name, _) in enumerate(SPHERES):
        sel = mask & (column == k)
        cells = []
        for e in ("pbrkit", "khronos"):
            d = srgb8(rt[e].image).mean(-1) - ref8
            cells.append(f"{np.abs(d[sel]).mean():.2f} ({d[sel].mean():+.2f})")
        print(f"| {name} | {cells[0]} | {cells[1]} | {noise[sel].mean():.2f} |")


if __name__ == "__main__":
    main()
