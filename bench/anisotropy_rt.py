"""Real-time KHR_materials_anisotropy against the ground truth (issue 25): metal
spheres of increasing anisotropyStrength (and a turned direction) under the bundled
environment, rendered by ``render_realtime`` (``engine`` khronos: the split sum with
the prefiltered environment looked up once along the Sample Viewer's bent normal,
:func:`pbrkit.rendering.ibl_lookups.khr_anisotropic_reflection`, and the isotropic DFG;
``engine`` pbrkit: filtered importance sampling of the lobe itself,
:mod:`pbrkit.rendering.anisotropic_ibl`) and by the ground truth (``render_reference``:
the anisotropic GGX lobe integrated against the environment), compared per sphere
in 8-bit sRGB levels (mean |grey| and the signed mean).  The column "isotropic
lookup" is the real-time render of the same sphere at strength 0 (what a renderer
that ignores the extension shows) against the anisotropic ground truth.

    PYTHONPATH=src python bench/anisotropy_rt.py [--spp 256] [--size 96]
    PYTHONPATH=src python bench/anisotropy_rt.py --held-apart [--spp 256]

Prints a Markdown table.  The five spheres here are the set filtered importance
sampling's sample count was tuned on; ``--held-apart`` measures it on data it was not
tuned on: the anisotropy asset of tests/engines/test_engine_khr_extensions.py (16 spheres of
other roughness, strength and rotation, its mesh tangents, the Khronos target's bake
at intensity 0.25) through ``pbrkit render``, with and without
``--energy-compensation`` (whose multiple scattering is not filtered importance
sampling's), per row of the asset.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from pbrkit.rendering.realtime import render_realtime
from pbrkit.rendering.reference import render_reference
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


def held_apart(spp):
    """Per row of the in-engine anisotropy asset, mean |grey| (signed mean) of each
    real-time engine against the ground truth, in 8-bit sRGB levels."""
    import sys
    import tempfile
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "support"))
    import engine_assets as assets
    from engine_compare import bake_khronos, sphere_mask
    from engine_compare import encode_srgb8 as _encode

    name = "anisotropy"
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        bake_dir = bake_khronos(root / "bake")
        scene_file = assets.write_asset_scene(name, root, bake_dir)
        t = time.perf_counter()
        truth = _encode(assets.pbrkit_render(scene_file, ["--mode", "reference", "--spp", str(spp), "--no-occlusion",
                                                          "--tonemap", "none"], root / "truth.exr"))
        t_truth = time.perf_counter() - t
        plain = [o for o in assets.PBRKIT_OPTIONS if o != "--energy-compensation"]
        images = {"pbrkit (FIS)": _encode(assets.pbrkit_render(scene_file, ["--engine", "pbrkit", *plain],
                                                                root / "fis.exr")),
                  "pbrkit + energy compensation": _encode(assets.pbrkit_render(
                      scene_file, ["--engine", "pbrkit", *assets.PBRKIT_OPTIONS], root / "ec.exr")),
                  "khronos": _encode(assets.pbrkit_render(scene_file, assets.ENGINE_OPTIONS, root / "khronos.exr"))}
    index = assets.asset_index(name)
    mask = sphere_mask(index)
    spheres = assets.asset_spheres(name)
    columns = 4
    ref = truth.astype(np.float64).mean(-1)
    print(f"held apart: tests/engines/test_engine_khr_extensions.py's {name} asset, ground truth {spp} spp, direct "
          f"({t_truth:.1f} s); 8-bit sRGB levels, mean |grey| (signed mean: real time minus ground truth)\n")
    print("| row of the asset | " + " | ".join(images) + " |")
    print("|---|" + "---|" * len(images))
    for row in range(len(spheres) // columns):
        sel = mask & (index // columns == row)
        row_materials = [s["material"] for s in spheres[row * columns:(row + 1) * columns]]
        cells = []
        for image in images.values():
            d = image.astype(np.float64).mean(-1) - ref
            cells.append(f"{np.abs(d[sel]).mean():.2f} ({d[sel].mean():+.2f})")
        print(f"| {row} ({label_of(row_materials)}) | {' | '.join(cells)} |")
    sel = mask & (index >= 0)
    cells = []
    for image in images.values():
        d = image.astype(np.float64).mean(-1) - ref
        cells.append(f"{np.abs(d[sel]).mean():.2f} ({d[sel].mean():+.2f})")
    print(f"| all {len(spheres)} spheres | {' | '.join(cells)} |")


def label_of(materials):
    """A row's label: what its four spheres share or vary."""
    ext = [m["extensions"].get("KHR_materials_anisotropy", {}) for m in materials]
    rough = sorted({m["roughness"] for m in materials})
    strength = sorted({e.get("anisotropyStrength", 0.0) for e in ext})
    rotation = sorted({round(e.get("anisotropyRotation", 0.0), 2) for e in ext})
    part = lambda name, xs: f"{name} {', '.join(f'{x:g}' for x in xs)}"  # noqa: E731
    return "; ".join(part(n, xs) for n, xs in (("roughness", rough), ("strength", strength),
                                                ("rotation", rotation)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=256)
    parser.add_argument("--size", type=int, default=96)
    parser.add_argument("--held-apart", action="store_true",
                        help="measure on the in-engine test's anisotropy asset (not the tuning spheres)")
    args = parser.parse_args()
    if args.held_apart:
        held_apart(args.spp)
        return
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
