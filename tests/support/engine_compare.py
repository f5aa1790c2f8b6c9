"""Shared test helper: comparing an engine's render with pbrkit's (tests/engines/): the
sphere grid of the three.js and Sample Viewer comparisons (2 x 4 spheres, dielectric and
metal rows, its camera and scene file), the analytic sphere hits under pbrkit's camera,
the pixel mask without silhouettes, the agreement in 8-bit levels, the 8-bit encodings
(pbrkit's sRGB and the Sample Viewer's gamma 2.2), three r187's DFG table with GL's
bilinear lookup, the bundled environment baked for the Sample Viewer, ``pbrkit`` run in
process, and the screenshots kept for inspection."""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import numpy as np
from engine_pages import ENGINES

from pbrkit.core.color import linear_to_srgb


W, H = 256, 128
ROUGHNESS = (0.25, 0.5, 0.75, 1.0)
COLOURS = {0.0: ([0.8, 0.35, 0.2], [0.3, 0.6, 0.35], [0.25, 0.35, 0.7], [0.7, 0.7, 0.7]),
           1.0: ([0.95, 0.75, 0.4], [0.9, 0.9, 0.9], [0.95, 0.6, 0.5], [0.6, 0.8, 0.9])}


CAMERA = {"position": [0.0, 0.0, 6.0], "look_at": [0.0, 0.0, 0.0], "up": [0.0, 1.0, 0.0], "fov": 22.0,
          "width": W, "height": H}
#: The environment's intensity in both renders (scene.environmentIntensity in three): the
#: bundled sky reaches 3.4 on the smooth metals at 1, which would clip at 8 bits.
INTENSITY = 0.25


def spheres():
    """The grid: row 0 dielectric, row 1 metal, roughness left to right."""
    return [{"center": [-1.5 + j, 0.5 - row, 0.0], "radius": 0.45, "base_color": COLOURS[metal][j],
             "metallic": metal, "roughness": r}
            for row, metal in enumerate((0.0, 1.0)) for j, r in enumerate(ROUGHNESS)]


def write_scene(scene_dir, bake_dir):
    """The pbrkit scene file of the grid, environment = the bake folder."""
    grid = spheres()
    scene = {"camera": CAMERA, "environment": {"bake": str(Path(bake_dir).resolve()), "intensity": INTENSITY},
             "materials": {f"m{i}": {"model": "gltf", "base_color": s["base_color"], "metallic": s["metallic"],
                                     "roughness": s["roughness"]} for i, s in enumerate(grid)},
             "objects": [{"type": "sphere", "center": s["center"], "radius": s["radius"], "material": f"m{i}"}
                         for i, s in enumerate(grid)]}
    path = Path(scene_dir) / "scene.json"
    path.write_text(json.dumps(scene, indent=1))
    return path


def run_cli(args):
    """``pbrkit ARGS`` in process (Typer's runner); asserts it succeeds."""
    from typer.testing import CliRunner

    from pbrkit.cli import app

    result = CliRunner().invoke(app, [str(a) for a in args])
    assert result.exit_code == 0, result.output


def encode_srgb8(linear):
    """Linear RGB as 8-bit sRGB, as pbrkit's PNG writer encodes it: clip to [0, 1], sRGB, round."""
    return np.round(np.clip(linear_to_srgb(np.clip(linear, 0.0, 1.0)), 0.0, 1.0) * 255.0).astype(np.uint8)


def sphere_hits(scene_dir, camera=CAMERA, grid=None):
    """Per pixel centre: the index of the sphere hit (-1: none), its unit normal, and the
    view ray direction, from pbrkit's camera model of the scene file."""
    from pbrkit.rendering.sources import resolve_scene

    grid = spheres() if grid is None else grid
    cam = resolve_scene(str(Path(scene_dir) / "scene.json")).camera
    h, w = cam.height, cam.width
    d = cam.ray_directions(*np.meshgrid(np.arange(h) + 0.5, np.arange(w) + 0.5, indexing="ij"))
    origin = np.asarray(camera["position"], np.float64)
    index = np.full((h, w), -1)
    normal = np.zeros((h, w, 3))
    nearest = np.full((h, w), np.inf)
    for i, s in enumerate(grid):
        oc = origin - np.asarray(s["center"])
        b = d @ oc
        disc = b * b - (oc @ oc - s["radius"] ** 2)
        t = np.where(disc > 0, -b - np.sqrt(np.maximum(disc, 0.0)), np.inf)
        closer = t < nearest
        nearest[closer] = t[closer]
        index[closer] = i
        normal[closer] = ((origin + t[..., None] * d - s["center"]) / s["radius"])[closer]
    return index, normal, d


def sphere_mask(index):
    """Sphere pixels whose 8 neighbours are on the same sphere (no silhouette pixels)."""
    from scipy.ndimage import minimum_filter

    return (index >= 0) & (minimum_filter(index, size=3) == index) & (-minimum_filter(-index, size=3) == index)


def agreement(a, b, mask):
    """Mean and 95th percentile of |a - b| in 8-bit levels, per channel and grey (mean of RGB)."""
    diff = np.abs(a.astype(np.float64) - b.astype(np.float64))[mask]
    grey = np.abs(a.astype(np.float64).mean(-1) - b.astype(np.float64).mean(-1))[mask]
    return {"mean": diff.mean(0).round(3).tolist(), "p95": np.percentile(diff, 95, axis=0).tolist(),
            "grey_mean": round(float(grey.mean()), 3), "grey_p95": float(np.percentile(grey, 95))}


def three_dfg_table():
    """three r187's built-in DFG table (``DFGLUTData.js``, 16 x 16 RG16F): [n.v][roughness] -> (A, B)."""
    src = (ENGINES / "node_modules" / "three" / "src" / "renderers" / "shaders" / "DFGLUTData.js").read_text()
    body = src[src.index("new Uint16Array( ["):src.index("] );")]
    values = np.array([int(x, 16) for x in re.findall(r"0x[0-9a-fA-F]{4}", body)], np.uint16)
    return values.view(np.float16).astype(np.float64).reshape(16, 16, 2)


def bilinear(table, u, v):
    """GL LINEAR + CLAMP_TO_EDGE lookup of table[v][u] at uv in [0, 1]."""
    n_v, n_u = table.shape[:2]

    def pair(x, n):
        x = np.clip(x * n - 0.5, 0.0, n - 1.0)
        i0 = np.floor(x).astype(int)
        return i0, np.minimum(i0 + 1, n - 1), (x - i0)[..., None]

    u0, u1, fu = pair(np.asarray(u, float), n_u)
    v0, v1, fv = pair(np.asarray(v, float), n_v)
    return ((table[v0, u0] * (1 - fu) + table[v0, u1] * fu) * (1 - fv)
            + (table[v1, u0] * (1 - fu) + table[v1, u1] * fu) * fv)


def save_shots(root, prefix, engine8, pbrkit8):
    """Both PNGs into ``root`` and, when PBRKIT_ENGINE_SHOTS names a folder, into it."""
    import imageio.v3 as iio

    folders = [Path(root)] + ([Path(os.environ["PBRKIT_ENGINE_SHOTS"])] if os.environ.get("PBRKIT_ENGINE_SHOTS")
                              else [])
    for folder in folders:
        folder.mkdir(parents=True, exist_ok=True)
        iio.imwrite(folder / f"{prefix}_engine.png", engine8)
        iio.imwrite(folder / f"{prefix}_pbrkit.png", pbrkit8)


#: The bake of the Khronos Sample Viewer's comparisons.
KHRONOS_BAKE_OPTIONS = ["--size", "128", "--min-size", "8", "--target", "khronos"]


def bake_khronos(bake_dir):
    """``pbrkit bake <bundled environment> -o bake_dir --size 128 --min-size 8 --target khronos``."""
    from pbrkit.data import environment_path

    run_cli(["bake", environment_path(), "-o", bake_dir, *KHRONOS_BAKE_OPTIONS, "-q"])
    return Path(bake_dir)


def gamma22_to_srgb8(canvas):
    """The viewer's pow(c, 1 / 2.2) 8-bit output as sRGB 8-bit."""
    return np.round(linear_to_srgb((canvas / 255.0) ** 2.2) * 255.0).astype(np.uint8)
