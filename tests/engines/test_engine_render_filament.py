"""Filament renders a sphere grid from pbrkit's ``--target filament`` bake, and the
render agrees with ``pbrkit render --mode realtime`` of the same scene (issue 10).

The test bakes the bundled environment with the CLI (``pbrkit bake ENV --size 64
--min-size 4 --target filament``: 5 levels, as many as cmgen's default chain),
writes a scene of 2 x 4 spheres (top row dielectric, bottom row metallic;
roughness 0.25, 0.5, 0.75, 1 left to right) and the same spheres as a glTF
(one UV-sphere mesh per material), and renders it twice:

* pbrkit: ``pbrkit render scene.json --mode realtime --tonemap none --diffuse sh
  --energy-compensation -o pbrkit.exr`` with ``model = "filament"`` materials
  (Filament's BRDF: GGX, height-correlated Smith, Schlick, Lambert; the DFG table
  of the bake, which is Filament's multiscatter (DFG1, DFG2) form; SH diffuse
  from the bake's 9 coefficients, which the ``sh`` key of filament/ibl.ktx holds
  pre-scaled; Filament's energy compensation 1 + f0 (1 / DFG2 - 1)).
* Filament 1.53.4 (``tests/engines/pages/filament_render.html``, headless
  Chromium, SwiftShader): ``createIblFromKtx1(filament/ibl.ktx)`` built into the
  light with ``irradianceSh(3, ibl.shfloats)`` as the manifest says, gltfio's
  ubershader materials, the same pinhole camera, no punctual lights,
  post-processing off, read back as float (linear) from an RGBA32F target.

Both images are encoded the same way (clip to [0, 1], sRGB, 8 bits) and compared
over the pixels both renders cover with a sphere, the silhouette pixels left out
(a mesh's polygonal outline is not the sphere's).

Measured (sRGB 8-bit levels over the 10480 sphere pixels, silhouettes left out):
engine vs ``pbrkit render --engine filament`` grey mean 0.26, p95 1, max 2: the
issue's goal (1 level) is met.  With pbrkit's own IBL evaluation (``--engine
pbrkit``) the difference is 3.10 (p95 11.0, max 30; per channel 3.42 / 3.13 /
2.77): three things Filament does, which ``--engine filament`` reproduces and an
isolation model (:func:`split_sum_model`: the split sum in numpy from pbrkit's own
pieces, the bake's DFG table, SH and cube sampler) measures one by one; the model
reproduces pbrkit's render exactly (0.00) with pbrkit's choices and the engine to
grey mean 0.26 (p95 1, max 2) with Filament's three:

1. chain and lod curve: Filament samples filament/ibl.ktx (levels at r_m = 1 -
   sqrt(1 - m / (M - 1))) at lod = (M - 1) r (2 - r); pbrkit, given a bake folder,
   the generic chain at lod = r (M - 1).  Both hit a level exactly at r = 0.5 and
   1; at 0.25 and 0.75 they blend different levels.  (Grey mean against the
   engine, as each choice alone is added to pbrkit's / left out of Filament's:
   2.88 / 0.55.)
2. dominant direction: Filament looks the chain up along mix(R, n, alpha^2)
   (``getReflectedVector`` -> ``getSpecularDominantDirection``), pbrkit along R;
   at r = 1 that is n, not R: the rough metal sphere is 9.9 levels off.  (1.63 /
   1.91.)
3. (1 - E) diffuse: Filament's IBL diffuse is diffuseColor * SH(n) * (1 - E),
   E = DFG1 + f0 (DFG2 - DFG1) (``evaluateIBL``); pbrkit's ``filament`` model has
   no weight on Lambert.  Isolated in the engine (zero SH) it is 1 - E to 0.25%
   (E 0.012 .. 0.21 here, median 0.037).  (2.15 / 1.38.)

gltfio's ubershaders also have specular anti-aliasing on (kernel roughness from
the screen-space normal derivatives, variance 0.15): the page sets
``_specularAntiAliasingVariance`` = 0 for the comparisons; with the default the
engine moves by 0.20 levels on average (1.0 on the r = 0.25 metal).
"""

from __future__ import annotations

import json
import os
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from engine_pages import needs_engines, run_page

pytestmark = [needs_engines(), pytest.mark.slow]  # bake ~5 s, render ~5 s, Filament page ~10 s

WIDTH, HEIGHT = 256, 128
ROUGHNESS = (0.25, 0.5, 0.75, 1.0)
# (metallic, base colour) per row, top to bottom: nothing reaches 1 in linear radiance
ROWS = ((0.0, (0.60, 0.35, 0.18)), (1.0, (0.27, 0.24, 0.18)))  # the sun's highlight on the r = 0.25 metal: 0.95
RADIUS = 0.42
CAMERA = {"position": [0.0, 0.0, 6.0], "look_at": [0.0, 0.0, 0.0], "up": [0.0, 1.0, 0.0], "fov": 24.0}
NEAR, FAR = 0.5, 50.0
# Filament's default variance (MaterialInstance::setSpecularAntiAliasingVariance); 0 = off
SPECULAR_AA_DEFAULT = 0.15
# engine vs pbrkit with pbrkit's own IBL evaluation (--engine pbrkit): measured 3.10 / 11.0 / 3.42, plus a margin
GREY_MEAN_BOUND, GREY_P95_BOUND, CHANNEL_MEAN_BOUND = 3.4, 12.0, 3.7


def sphere_centres():
    """(row, column, centre) of each sphere: rows top (dielectric) to bottom (metal)."""
    out = []
    for i in range(len(ROWS)):
        for j in range(len(ROUGHNESS)):
            out.append((i, j, [1.0 * (j - (len(ROUGHNESS) - 1) / 2), 0.5 - 1.0 * i, 0.0]))
    return out


def material_name(i, j):
    return f"m{i}{j}"


# ------------------------------------------------------------------ pbrkit side


def run_cli(*args, cwd=None):
    proc = subprocess.run([sys.executable, "-m", "pbrkit", *map(str, args)], check=False, capture_output=True,
                          text=True, cwd=cwd, timeout=600)
    assert proc.returncode == 0, f"pbrkit {' '.join(map(str, args))}: {proc.stderr[-2000:]}"
    return proc


def bake(bake_dir):
    """``pbrkit bake`` of the bundled environment with the filament target."""
    from pbrkit.data import environment_path

    run_cli("bake", environment_path(), "-o", bake_dir, "--size", 64, "--min-size", 4, "--target", "filament",
            "--quiet")
    return Path(bake_dir)


def write_scene(bake_dir, scene_dir, model="filament", diffuse="lambert"):
    """The pbrkit scene file of the grid, environment = the bake folder."""
    materials, objects = {}, []
    for i, j, centre in sphere_centres():
        metallic, base = ROWS[i]
        materials[material_name(i, j)] = {"model": model, "base_color": list(base), "metallic": metallic,
                                          "roughness": ROUGHNESS[j], "diffuse": diffuse}
        objects.append({"type": "sphere", "center": centre, "radius": RADIUS, "material": material_name(i, j)})
    scene = {"camera": dict(CAMERA, width=WIDTH, height=HEIGHT, supersample=1),
             "environment": {"bake": str(Path(bake_dir).resolve()), "intensity": 1.0},
             "materials": materials, "objects": objects}
    path = Path(scene_dir) / f"scene_{model}_{diffuse}.json"
    path.write_text(json.dumps(scene, indent=1))
    return path


PBRKIT_OPTIONS = ("--mode", "realtime", "--tonemap", "none", "--diffuse", "sh", "--energy-compensation")


def pbrkit_linear(bake_dir, scene_dir, model="filament", diffuse="lambert", engine="pbrkit"):
    """Linear float (H, W, 3) of ``pbrkit render`` (EXR) of the scene; ``engine``
    ``filament`` renders as Filament does (``--engine filament``)."""
    from pbrkit.io.exr import read_exr

    scene = write_scene(bake_dir, scene_dir, model, diffuse)
    out = Path(scene_dir) / f"pbrkit_{model}_{diffuse}_{engine}.exr"
    run_cli("render", scene, "-o", out, *PBRKIT_OPTIONS, "--engine", engine)
    image = np.asarray(read_exr(out), dtype=np.float64)
    return image[..., :3]


def to_srgb8(linear):
    """Clip to [0, 1], sRGB-encode and round to 8 bits, as ``pbrkit render -o
    x.png --tonemap none`` (:func:`pbrkit.io.png.write_png`) does."""
    from pbrkit.core.color import linear_to_srgb

    return np.rint(linear_to_srgb(np.clip(linear, 0.0, 1.0)) * 255.0).astype(np.uint8)


def pbrkit_image(bake_dir, scene_dir):
    """``pbrkit render --mode realtime --engine filament`` of the grid as sRGB uint8 (H, W, 3)."""
    return to_srgb8(pbrkit_linear(bake_dir, scene_dir, engine="filament"))


# ---------------------------------------------------------------- Filament side


def uv_sphere(radius, stacks=64, slices=128):
    """Positions, normals (float32) and uint16 triangle indices of a UV sphere
    about the origin, counter-clockwise seen from outside."""
    theta = np.linspace(0.0, np.pi, stacks + 1)
    phi = np.linspace(0.0, 2.0 * np.pi, slices + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    n = np.stack([np.sin(t) * np.sin(p), np.cos(t), np.sin(t) * np.cos(p)], axis=-1).reshape(-1, 3)
    idx = []
    row = slices + 1
    for a in range(stacks):
        for b in range(slices):
            v0, v1, v2, v3 = a * row + b, a * row + b + 1, (a + 1) * row + b, (a + 1) * row + b + 1
            idx += [v0, v2, v3, v0, v3, v1]
    return (n * radius).astype(np.float32), n.astype(np.float32), np.asarray(idx, dtype=np.uint16)


def spheres_glb(path):
    """A GLB of the grid: one mesh per material over one shared UV sphere, glTF
    metallic-roughness materials (reflectance 0.5 = f0 0.04, as the scene's)."""
    pos, nrm, idx = uv_sphere(RADIUS)
    chunks = [pos.tobytes(), nrm.tobytes(), idx.tobytes()]
    offsets, blob = [], b""
    for c in chunks:
        offsets.append(len(blob))
        blob += c + b"\0" * (-len(c) % 4)
    cells = sphere_centres()
    gltf = {
        "asset": {"version": "2.0", "generator": "pbrkit tests/engines/test_engine_render_filament.py"},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(cells)))}],
        "nodes": [{"name": material_name(i, j), "mesh": k, "translation": c} for k, (i, j, c) in enumerate(cells)],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": k}]}
                   for k in range(len(cells))],
        "materials": [{"name": material_name(i, j),
                       "pbrMetallicRoughness": {"baseColorFactor": [*ROWS[i][1], 1.0], "metallicFactor": ROWS[i][0],
                                                "roughnessFactor": ROUGHNESS[j]}} for i, j, _ in cells],
        "buffers": [{"byteLength": len(blob)}],
        "bufferViews": [{"buffer": 0, "byteOffset": offsets[0], "byteLength": len(chunks[0]), "target": 34962},
                        {"buffer": 0, "byteOffset": offsets[1], "byteLength": len(chunks[1]), "target": 34962},
                        {"buffer": 0, "byteOffset": offsets[2], "byteLength": len(chunks[2]), "target": 34963}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3",
                       "min": pos.min(axis=0).tolist(), "max": pos.max(axis=0).tolist()},
                      {"bufferView": 1, "componentType": 5126, "count": len(nrm), "type": "VEC3"},
                      {"bufferView": 2, "componentType": 5123, "count": len(idx), "type": "SCALAR"}],
    }
    text = json.dumps(gltf).encode()
    text += b" " * (-len(text) % 4)
    total = 12 + 8 + len(text) + 8 + len(blob)
    data = (struct.pack("<III", 0x46546C67, 2, total) + struct.pack("<II", len(text), 0x4E4F534A) + text
            + struct.pack("<II", len(blob), 0x004E4942) + blob)
    Path(path).write_bytes(data)
    return path


def run_render_page(data, timeout=180):
    """``filament_render.html`` on ``data``: the harness's report."""
    return run_page("filament_render.html", data=data, timeout=timeout)


def engine_linear(bake_dir, scene_dir, variants=({"sh": True, "specularAAVariance": 0.0},)):
    """Filament's linear float RGBA (H, W, 4) per variant, rows top first, and the report."""
    bake_dir, scene_dir = Path(bake_dir).resolve(), Path(scene_dir).resolve()
    data = scene_dir / "filament_data"
    data.mkdir(exist_ok=True)
    manifest = json.loads((bake_dir / "manifest.json").read_text())
    files = manifest["targets"]["filament"]["files"]
    for key in ("ibl", "skybox"):
        target = data / files[key]
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes((bake_dir / files[key]).read_bytes())
    spheres_glb(data / "spheres.glb")
    job = {"glb": "spheres.glb", "ibl": files["ibl"], "sky": files["skybox"], "width": WIDTH, "height": HEIGHT,
           "camera": {"eye": CAMERA["position"], "center": CAMERA["look_at"], "up": CAMERA["up"],
                      "fov": CAMERA["fov"], "near": NEAR, "far": FAR},
           "variants": list(variants)}
    (data / "render.json").write_text(json.dumps(job))
    report = run_render_page(data)
    images = [np.asarray(img, dtype=np.float64).reshape(HEIGHT, WIDTH, 4)[::-1] for img in report["result"]["images"]]
    return images, report


def engine_image(bake_dir, scene_dir):
    """Filament's render of the grid (gltfio's specular anti-aliasing off) as sRGB uint8
    (H, W, 3), encoded as :func:`to_srgb8`; ``scene_dir`` receives the page's data."""
    images, _ = engine_linear(bake_dir, scene_dir)
    return to_srgb8(images[0][..., :3])


# ------------------------------------------------------------------ comparison


def sphere_mask(erode=1):
    """Pixels whose centre ray hits a sphere (the pbrkit camera's rays, analytic),
    with the ``erode``-pixel silhouette band removed."""
    pos, target, up = (np.asarray(CAMERA[k], dtype=np.float64) for k in ("position", "look_at", "up"))
    forward = (target - pos) / np.linalg.norm(target - pos)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    tan = np.tan(np.radians(CAMERA["fov"]) / 2.0)
    ys = (1.0 - 2.0 * (np.arange(HEIGHT) + 0.5) / HEIGHT) * tan
    xs = (2.0 * (np.arange(WIDTH) + 0.5) / WIDTH - 1.0) * tan * WIDTH / HEIGHT
    yy, xx = np.meshgrid(ys, xs, indexing="ij")
    d = forward + xx[..., None] * right + yy[..., None] * true_up
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    hit = np.zeros((HEIGHT, WIDTH), dtype=bool)
    for _, _, c in sphere_centres():
        oc = pos - np.asarray(c)
        b = np.sum(d * oc, axis=-1)
        hit |= b * b - (oc @ oc - RADIUS * RADIUS) > 0.0
    inner = hit.copy()
    for _ in range(erode):
        shrunk = inner.copy()
        shrunk[1:] &= inner[:-1]
        shrunk[:-1] &= inner[1:]
        shrunk[:, 1:] &= inner[:, :-1]
        shrunk[:, :-1] &= inner[:, 1:]
        inner = shrunk
    return hit, inner


def differences(a, b, mask):
    """Per-channel and grey (mean of the channels) absolute difference in 8-bit levels
    over ``mask``: {"mean": [r, g, b], "grey_mean", "grey_p95", "max"}."""
    d = np.abs(a.astype(np.int32) - b.astype(np.int32))[mask].astype(np.float64)
    signed = (a.astype(np.int32) - b.astype(np.int32))[mask].astype(np.float64)
    grey = np.abs(signed.mean(axis=1))
    return {"mean": d.mean(axis=0).round(3).tolist(), "grey_mean": round(float(grey.mean()), 3),
            "grey_p95": round(float(np.percentile(grey, 95)), 3), "max": int(d.max()),
            "signed_mean": signed.mean(axis=0).round(3).tolist()}


def per_sphere(a, b, inner):
    """Grey mean absolute difference per sphere, rows top to bottom."""
    pos = np.asarray(CAMERA["position"])
    tan = np.tan(np.radians(CAMERA["fov"]) / 2.0)
    out = np.zeros((len(ROWS), len(ROUGHNESS)))
    yy, xx = np.mgrid[0:HEIGHT, 0:WIDTH]
    for i, j, c in sphere_centres():
        depth = pos[2] - c[2]
        px = (c[0] / (depth * tan * WIDTH / HEIGHT) + 1.0) / 2.0 * WIDTH
        py = (1.0 - c[1] / (depth * tan)) / 2.0 * HEIGHT
        rpix = RADIUS / (depth * tan) / 2.0 * HEIGHT
        m = inner & ((xx + 0.5 - px) ** 2 + (yy + 0.5 - py) ** 2 < rpix * rpix)
        g = (a.astype(np.float64) - b.astype(np.float64))[m].mean(axis=1)
        out[i, j] = np.abs(g).mean()
    return out.round(2)


# ------------------------------------------------------------------ isolation


def surface():
    """Per pixel of the inner mask (sphere_mask): unit normal n, view v (towards the
    eye), (row, column) of the material, from the pbrkit camera's centre rays."""
    pos, target, up = (np.asarray(CAMERA[k], dtype=np.float64) for k in ("position", "look_at", "up"))
    forward = (target - pos) / np.linalg.norm(target - pos)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    tan = np.tan(np.radians(CAMERA["fov"]) / 2.0)
    ys = (1.0 - 2.0 * (np.arange(HEIGHT) + 0.5) / HEIGHT) * tan
    xs = (2.0 * (np.arange(WIDTH) + 0.5) / WIDTH - 1.0) * tan * WIDTH / HEIGHT
    yy, xx = np.meshgrid(ys, xs, indexing="ij")
    d = forward + xx[..., None] * right + yy[..., None] * true_up
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    best = np.full((HEIGHT, WIDTH), np.inf)
    n = np.zeros((HEIGHT, WIDTH, 3))
    cell = np.zeros((HEIGHT, WIDTH, 2), dtype=int)
    for i, j, c in sphere_centres():
        oc = pos - np.asarray(c)
        b = np.sum(d * oc, axis=-1)
        disc = b * b - (oc @ oc - RADIUS * RADIUS)
        t = -b - np.sqrt(np.maximum(disc, 0.0))
        take = (disc > 0.0) & (t < best)
        best[take] = t[take]
        n[take] = (pos + t[take, None] * d[take] - np.asarray(c)) / RADIUS
        cell[take] = (i, j)
    return n, -d, cell


def split_sum_model(bake_dir, chain="generic", dominant=False, one_minus_e=False):
    """Linear (H, W, 3) of the grid's IBL by the split sum, from pbrkit's pieces
    (the bake's DFG table, its SH irradiance, pbrkit's trilinear cube sampler),
    with Filament's choices switchable: ``chain`` "generic" (the bake's chain at
    lod = r (M - 1): what ``pbrkit render`` does) or "filament" (filament/ibl.ktx
    as pbrkit reads it, at lod = (M - 1) r (2 - r)); ``dominant``: look up along
    mix(R, n, alpha^2) instead of R; ``one_minus_e``: diffuse times (1 - E).
    Energy compensation 1 + f0 (1 / DFG2 - 1) always (both renders have it)."""
    from pbrkit.albedo.tables import table_bilinear
    from pbrkit.ibl.cubemap import CubeSampler
    from pbrkit.ibl.sh import irradiance_from_sh
    from pbrkit.io.bake_files import load_bake
    from pbrkit.io.ktx1 import read_ktx1

    b = load_bake(bake_dir)
    n, v, cell = surface()
    rough = np.asarray(ROUGHNESS)[cell[..., 1]]
    metal = np.asarray([r[0] for r in ROWS])[cell[..., 0]]
    base = np.asarray([r[1] for r in ROWS])[cell[..., 0]]
    nov = np.maximum(np.sum(n * v, axis=-1), 1e-4)
    r = 2.0 * nov[..., None] * n - v
    if dominant:
        alpha = rough**2
        r = r + (n - r) * (alpha * alpha)[..., None]
        r /= np.linalg.norm(r, axis=-1, keepdims=True)
    if chain == "generic":
        levels = [np.asarray(x, dtype=np.float64) for x in b.specular]
        lod = rough * (len(levels) - 1)
    else:
        levels = [np.asarray(x, dtype=np.float64)[..., :3]
                  for x in read_ktx1(Path(bake_dir) / "filament" / "ibl.ktx")[1]]
        lod = (len(levels) - 1) * rough * (2.0 - rough)
    prefiltered = CubeSampler(levels)(r.reshape(-1, 3), lod.reshape(-1)).reshape(HEIGHT, WIDTH, 3)
    tables = np.ascontiguousarray(np.asarray(b.lut, dtype=np.float64)[None, ..., :2])
    dfg = np.array([[table_bilinear(tables, 0, a, c, k) for k in (0, 1)]
                    for a, c in zip(nov.reshape(-1), rough.reshape(-1), strict=True)]).reshape(HEIGHT, WIDTH, 2)
    f0 = 0.04 * (1.0 - metal)[..., None] + base * metal[..., None]
    e = dfg[..., :1] + f0 * (dfg[..., 1:] - dfg[..., :1])
    ec = 1.0 + f0 * (1.0 / dfg[..., 1:] - 1.0)
    irradiance = np.maximum(irradiance_from_sh(np.asarray(b.sh, dtype=np.float64), n), 0.0)
    diffuse = base * (1.0 - metal)[..., None] * irradiance / np.pi
    if one_minus_e:
        diffuse = diffuse * (1.0 - e)
    return prefiltered * e * ec + diffuse


# ------------------------------------------------------------------ the tests


@pytest.fixture(scope="module")
def renders(tmp_path_factory):
    work = tmp_path_factory.mktemp("filament_render")
    bake_dir = bake(work / "bake")
    linear = pbrkit_linear(bake_dir, work)
    as_filament = pbrkit_linear(bake_dir, work, engine="filament")
    spec_only = pbrkit_linear(bake_dir, work, diffuse="none")
    images, report = engine_linear(bake_dir, work, variants=(
        {"sh": True, "specularAAVariance": 0.0}, {"sh": False, "specularAAVariance": 0.0},
        {"sh": True, "specularAAVariance": SPECULAR_AA_DEFAULT}))
    hit, inner = sphere_mask()
    engine8, pbrkit8, filament8 = to_srgb8(images[0][..., :3]), to_srgb8(linear), to_srgb8(as_filament)
    from pbrkit.io.png import write_png

    shots = [work] + ([Path(os.environ["PBRKIT_ENGINE_SHOTS"])] if os.environ.get("PBRKIT_ENGINE_SHOTS") else [])
    for folder in shots:
        folder.mkdir(parents=True, exist_ok=True)
        write_png(folder / "filament_engine.png", engine8 / 255.0, srgb=False)
        write_png(folder / "filament_pbrkit.png", filament8 / 255.0, srgb=False)
    return {"work": work, "bake": bake_dir, "pbrkit": linear, "pbrkit_spec": spec_only, "engine": images,
            "report": report, "hit": hit, "inner": inner, "engine8": engine8, "pbrkit8": pbrkit8,
            "filament8": filament8}


@pytest.fixture(scope="module")
def models(renders):
    """sRGB 8-bit images of :func:`split_sum_model` per (chain, dominant, one_minus_e)."""
    keys = [("generic", False, False), ("filament", True, True), ("generic", True, True), ("filament", False, True),
            ("filament", True, False), ("filament", False, False), ("generic", True, False),
            ("generic", False, True)]
    return {k: to_srgb8(split_sum_model(renders["bake"], *k)) for k in keys}


def test_scene_is_covered_and_nothing_clips(renders):
    inner = renders["inner"]
    engine = renders["engine"][0]
    assert renders["hit"].sum() > inner.sum()
    result = renders["report"]["result"]
    assert result["materials"] == 8 and result["iblLevels"] == 5
    np.testing.assert_array_equal(np.float32(result["shfloats"]), np.float32(
        json.loads((renders["bake"] / "manifest.json").read_text())["targets"]["filament"]["conventions"]
        ["sh_values"]).reshape(-1))
    # Filament covers the analytic spheres (alpha 1); pbrkit's render is finite there
    assert np.all(engine[inner][:, 3] > 0.999)
    assert inner.sum() > 0.15 * WIDTH * HEIGHT
    for image in (renders["pbrkit"][inner], engine[inner][:, :3]):
        assert 0.0 < np.min(image) and np.max(image) < 1.0, "a sphere pixel clips: the 8-bit comparison is blind there"


def test_images_saved(renders):
    from pbrkit.io.png import read_ldr

    for name, key in (("filament_engine.png", "engine8"), ("filament_pbrkit.png", "filament8")):
        assert renders[key].shape == (HEIGHT, WIDTH, 3) and renders[key].dtype == np.uint8
        back = to_srgb8(np.asarray(read_ldr(renders["work"] / name), dtype=np.float64)[..., :3])
        np.testing.assert_array_equal(back, renders[key])
    assert engine_image.__name__ == "engine_image" and pbrkit_image.__name__ == "pbrkit_image"


def test_render_agrees_with_pbrkit_realtime_as_filament(renders):
    """The engine against ``pbrkit render --mode realtime --engine filament`` (its
    chain at lod (M - 1) r (2 - r), the dominant direction, the (1 - E) diffuse,
    Filament's energy compensation; specular AA off in the engine): within one
    8-bit grey level on average, the issue's goal (measured 0.26, p95 1, max 2)."""
    inner = renders["inner"]
    stats = differences(renders["engine8"], renders["filament8"], inner)
    print("\nfilament vs pbrkit realtime --engine filament:", stats)
    print("per sphere (grey mean abs):\n", per_sphere(renders["engine8"], renders["filament8"], inner))
    assert stats["grey_mean"] <= 1.0 and stats["grey_p95"] <= 2.0 and max(stats["mean"]) <= 1.0


def test_pbrkits_own_ibl_differs_by_filaments_three_choices(renders):
    """With pbrkit's own IBL evaluation (``--engine pbrkit``) the same render differs
    by about 3 levels (measured 3.10, p95 11, channels 3.42 / 3.13 / 2.77): the three
    choices of the module docstring, which the tests below measure one by one."""
    inner = renders["inner"]
    stats = differences(renders["engine8"], renders["pbrkit8"], inner)
    print("\nfilament vs pbrkit realtime (engine pbrkit):", stats)
    assert 1.5 <= stats["grey_mean"] <= GREY_MEAN_BOUND
    assert stats["grey_p95"] <= GREY_P95_BOUND
    assert max(stats["mean"]) <= CHANNEL_MEAN_BOUND


def test_split_sum_model_with_pbrkits_choices_is_pbrkits_render(renders, models):
    """The isolation model with pbrkit's choices reproduces the CLI render: the
    differences below are Filament's choices, not the model."""
    stats = differences(models[("generic", False, False)], renders["pbrkit8"], renders["inner"])
    print("\nmodel (pbrkit's choices) vs pbrkit render:", stats)
    assert stats["grey_mean"] <= 0.05 and stats["max"] <= 1


def test_split_sum_model_with_filaments_choices_is_the_engine(renders, models):
    """With Filament's chain and lod curve, its dominant direction and its (1 - E)
    diffuse weight the model agrees with the engine within a fraction of a level:
    nothing else (DFG table, SH evaluation, sampling, tessellation) matters at 8 bits."""
    inner = renders["inner"]
    stats = differences(models[("filament", True, True)], renders["engine8"], inner)
    print("\nmodel (Filament's choices) vs engine:", stats)
    print(per_sphere(models[("filament", True, True)], renders["engine8"], inner))
    assert stats["grey_mean"] <= 0.3 and stats["grey_p95"] <= 1.0 and max(stats["mean"]) <= 0.4


def test_each_filament_choice_is_needed(renders, models):
    """Leaving any one of Filament's three choices out of the model leaves more than
    half a level; adding one at a time to pbrkit's shows each one's size."""
    inner, e8 = renders["inner"], renders["engine8"]
    full = differences(models[("filament", True, True)], e8, inner)["grey_mean"]
    names = {0: "chain + lod curve", 1: "dominant direction", 2: "(1 - E) diffuse"}
    left_out, added = {}, {}
    for k, name in names.items():
        key = [("filament", True, True)[i] if i != k else ("generic", False, False)[i] for i in range(3)]
        left_out[name] = differences(models[tuple(key)], e8, inner)["grey_mean"]
        key = [("generic", False, False)[i] if i != k else ("filament", True, True)[i] for i in range(3)]
        added[name] = differences(models[tuple(key)], e8, inner)["grey_mean"]
    print(f"\nall three: {full}; one left out: {left_out}; only one of them: {added}")
    for name in names.values():
        assert left_out[name] > full + 0.2, name


def test_engine_diffuse_is_weighted_by_one_minus_e(renders, models):
    """Filament's IBL diffuse, isolated in the engine (full render minus the render
    with zero SH), over pbrkit's (full minus ``diffuse = "none"``) is 1 - E with E
    from the bake's DFG table: Filament weights Lambert by 1 - E, pbrkit does not."""
    _, _, cell = surface()
    diel = renders["inner"] & (cell[..., 0] == 0)
    engine = renders["engine"][0][..., :3] - renders["engine"][1][..., :3]
    ours = renders["pbrkit"] - renders["pbrkit_spec"]
    with_e = split_sum_model(renders["bake"], "generic", False, True)
    without = split_sum_model(renders["bake"], "generic", False, False)
    expected = 1.0 + (with_e - without)[diel] / ours[diel]
    ratio = engine[diel] / ours[diel]
    rel = np.abs(ratio / expected - 1.0)
    print(f"\nengine / pbrkit diffuse: median {np.median(ratio):.4f}, 1 - E median {np.median(expected):.4f} "
          f"(E {1 - expected.max():.3f} .. {1 - expected.min():.3f}); relative mismatch p95 "
          f"{np.percentile(rel, 95):.2e}")
    assert np.all(ours[diel] > 1e-3)
    assert np.percentile(rel, 95) < 0.005 and np.median(rel) < 0.002
    assert np.median(ratio) < 0.975  # far from 1: the weight is there


def test_specular_antialiasing_off_switch_works(renders):
    """gltfio's ubershaders have specular AA on; ``_specularAntiAliasingVariance`` = 0
    switches it off (the comparisons above use that).  With Filament's default it
    adds its kernel roughness where normals change fast (low roughness, silhouettes)."""
    inner = renders["inner"]
    default = to_srgb8(renders["engine"][2][..., :3])
    stats = differences(default, renders["engine8"], inner)
    print("\nspecular AA default (0.15) vs off:", stats, "\n", per_sphere(default, renders["engine8"], inner))
    print("engine (AA default) vs pbrkit:", differences(default, renders["pbrkit8"], inner))
    assert stats["max"] > 0 and stats["grey_mean"] < 0.5
