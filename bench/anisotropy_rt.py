"""Real-time KHR_materials_anisotropy against the ground truth (issue 25): metal
spheres of increasing anisotropyStrength (and a turned direction) under the bundled
environment, rendered by ``render_realtime`` (``engine`` khronos: the split sum with
the prefiltered environment looked up once along the Sample Viewer's bent normal,
:func:`pbrkit.render.ibl_lookups.khr_anisotropic_reflection`, and the isotropic DFG;
``engine`` pbrkit: filtered importance sampling of the lobe itself,
:mod:`pbrkit.render.anisotropic_ibl`) and by the ground truth (``render_reference``:
the anisotropic GGX lobe integrated against the environment), compared per sphere
in 8-bit sRGB levels (mean |grey| and the signed mean).  The column "isotropic
lookup" is the real-time render of the same sphere at strength 0 (what a renderer
that ignores the extension shows) against the anisotropic ground truth.

    PYTHONPATH=src python bench/anisotropy_rt.py [--spp 256] [--size 96]

Prints a Markdown table.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from pbrkit.render.realtime import render_realtime
from pbrkit.render.reference import render_reference
from transmission_rt import sphere_columns, sphere_row, srgb8

#: (label, material keys): one sphere each, left to right (a grey metal, roughness 0.3).
SPHERES = (
    ("strength 0", dict(anisotropy_strength=0.0)),
    ("strength 0.5", dict(anisotropy_strength=0.5)),
    ("strength 1", dict(anisotropy_strength=1.0)),
    ("strength 1, rotation pi/2", dict(anisotropy_strength=1.0, anisotropy_rotation=0.5 * math.pi)),
    ("strength 1, r 0.05", dict(anisotropy_strength=1.0, roughness=0.05)),
)


def scene(size, isotropic=False):
    spheres = [(label, dict(keys, anisotropy_strength=0.0, anisotropy_rotation=0.0) if isotropic else keys)
               for label, keys in SPHERES]
    return sphere_row(spheres, size, base_color=(0.9, 0.9, 0.9), metallic=1.0, roughness=0.3)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=256)
    parser.add_argument("--size", type=int, default=96)
    args = parser.parse_args()
    s = scene(args.size)
    t = time.perf_counter()
    truth = render_reference(s, spp=args.spp, bounces=0)
    t_truth = time.perf_counter() - t
    rt = {e: render_realtime(s, bake_size=128, engine=e) for e in ("pbrkit", "khronos")}
    rt["isotropic"] = render_realtime(scene(args.size, isotropic=True), bake_size=128, engine="pbrkit")
    column = sphere_columns(s)
    mask = truth.mask & rt["pbrkit"].mask
    ref8 = srgb8(truth.image).mean(-1)
    print(f"ground truth {args.spp} spp, direct ({t_truth:.1f} s); 8-bit sRGB levels, mean |grey| "
          "(signed mean: real time minus ground truth)\n")
    print("| sphere (grey metal, r 0.3) | pbrkit | khronos | isotropic lookup | ground-truth noise |")
    print("|---|---|---|---|---|")
    noise = np.abs(srgb8(truth.image + truth.stderr).mean(-1) - ref8)
    for k, (name, _) in enumerate(SPHERES):
        sel = mask & (column == k)
        cells = []
        for e in ("pbrkit", "khronos", "isotropic"):
            d = srgb8(rt[e].image).mean(-1) - ref8
            cells.append(f"{np.abs(d[sel]).mean():.2f} ({d[sel].mean():+.2f})")
        print(f"| {name} | {' | '.join(cells)} | {noise[sel].mean():.2f} |")


if __name__ == "__main__":
    main()
