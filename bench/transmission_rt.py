"""Real-time KHR_materials_transmission and KHR_materials_volume against the ground
truth (issue 25): spheres of each kind under the bundled environment, rendered by
``render_realtime`` (``engine`` pbrkit and khronos: the transmitted light from the
prefiltered environment, :mod:`pbrkit.render.transmission_ibl`) and by the ground
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

from pbrkit.render.realtime import render_realtime
from pbrkit.render.reference import render_reference
from pbrkit.render.scene import Camera, EnvironmentSpec, MaterialSpec, Scene, Sphere, bundled_environment

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


def scene(size):
    materials = {"default": MaterialSpec()}
    objects = []
    for k, (_, keys) in enumerate(SPHERES):
        name = f"s{k}"
        materials[name] = MaterialSpec(name=name, base_color=(1.0, 1.0, 1.0), metallic=0.0, **keys)
        objects.append(Sphere(center=(1.2 * (k - (len(SPHERES) - 1) / 2), 0.0, 0.0), radius=0.5, material=name))
    cam = Camera(position=(0.0, 0.0, 12.0), look_at=(0.0, 0.0, 0.0), fov=7.0, width=size * len(SPHERES) // 2,
                 height=size // 2)
    return Scene(camera=cam, environment=EnvironmentSpec(file=str(bundled_environment()), intensity=0.5),
                 materials=materials, objects=tuple(objects))


def srgb8(x):
    x = np.clip(x, 0.0, 1.0)
    return np.round(255.0 * np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1.0 / 2.4) - 0.055))


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
    cam = s.camera
    centres = np.array([o.center for o in s.objects])
    _, cols = cam.project(centres)  # each pixel's sphere: the nearest projected centre along x
    column = np.broadcast_to(np.argmin(np.abs(np.arange(cam.width)[:, None] + 0.5 - cols[None, :]), axis=1),
                             (cam.height, cam.width))
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
