"""A sphere grid rendered by the Khronos glTF Sample Viewer 1.1.0 (npm
``@khronosgroup/gltf-viewer``) with ``pbrkit bake --target khronos``, against
``pbrkit render --mode realtime`` of the same scene (issue 10), in headless Chromium.

The scene is the one of ``test_engine_render_three.py`` (2 x 4 spheres: dielectric
and metal rows, roughness 0.25 .. 1, 256 x 128, environment intensity 0.25); the
test writes it as a glTF (one UV sphere mesh, 96 x 48 segments, per-sphere nodes and
materials, the camera) for the viewer, which ``pages/khronos_render.html`` loads
with ``ResourceLoader.loadGltf`` and lights with ``loadPbrkitEnvironment`` (the
module pbrkit ships), environmentRotation 0, ``iblIntensity`` 0.25, tone map
"None", no punctual lights.  pbrkit renders it with ``--mode realtime --tonemap
none --diffuse cube --energy-compensation`` (the viewer's diffuse is the Lambertian
cube E / pi, the bake's irradiance cube / pi; it adds multiple scattering).

Output encoding: the viewer's "None" tone map writes pow(c, 1 / 2.2), not sRGB;
:func:`engine_image` decodes the canvas with gamma 2.2 and encodes it as sRGB 8-bit
(what pbrkit's PNG is), which costs at most half a level of requantisation.

Measured (256 x 128, 14 172 sphere pixels): mean |grey| 1.22, p95 6.7; per channel
mean 1.33 / 1.32 / 1.16, p95 8 / 7 / 5; the dielectric row 0.63, the metal row 1.82
(without ``--energy-compensation`` 5.85).  What differs is the viewer's IBL Fresnel (``getIBLGGXFresnel``), which
:func:`viewer_model` re-implements in numpy (it reproduces the viewer's render,
next-to-last test); swapping its terms for pbrkit's shows their sizes:

* Fdez-Aguera's multiple scattering FmsEms (added to the specular weight of metals
  and dielectrics, taken from the dielectric's diffuse) instead of Filament's
  compensation 1 + F0 (1 / DFG2 - 1) on F0 A + B: 0.89 levels on average, p95 6.7
  (the rough coloured metals);
* the roughness-dependent Fresnel on the LUT, k_S = F0 + (max(1 - r, F0) - F0)
  (1 - n.v)^5 in k_S A + B, where pbrkit uses F0 A + B: 0.09, p95 0.7;
* the dielectric's diffuse weight 1 - (k_S A + B + FmsEms), where pbrkit's is
  1 - F*(n.v, 0.04, r) (Lagarde's k_S alone, no A, B): 0.28, p95 1.3.

With the three swapped the model is pbrkit's image to 0.06 levels on average (p95
0.3).  With pbrkit's own IBL the goal of one grey level on average is met by the
dielectric row (0.63) but not by the whole grid (1.22): the multiple-scattering
term accounts for the excess.  ``pbrkit render --engine khronos`` reproduces the
viewer's terms and agrees with it to 0.29 levels on average (p95 1).

The lookup (mirror direction, lod = r (M - 1), the same chain) and the
Lambertian cube are pbrkit's own, so the rest is rasterisation (tessellation,
cube filtering) and 8-bit rounding (the gamma-2.2 to sRGB requantisation is
about 0.2 levels of it).
"""

from __future__ import annotations

import base64
import math
from pathlib import Path

import numpy as np
import pytest
from engine_compare import (
    CAMERA,
    H,
    INTENSITY,
    W,
    agreement,
    bilinear,
    encode_srgb8,
    gamma22_to_srgb8,
    run_cli,
    save_shots,
    sphere_hits,
    sphere_mask,
    spheres,
    write_scene,
)
from engine_compare import bake_khronos as bake  # the name bench/engines.py calls on each engine's module
from engine_pages import needs_engines, run_page

# a CLI bake, two pbrkit renders and a Chromium page: about 30 s on 2 cores (cold Numba cache)
pytestmark = [needs_engines(), pytest.mark.slow]

RENDER_OPTIONS = ["--mode", "realtime", "--tonemap", "none", "--diffuse", "cube", "--energy-compensation"]
RINGS, SEGMENTS = 48, 96


def write_gltf(folder, sheen_roughness=None):
    """The grid as glTF 2.0 (pygltflib): a unit UV sphere (positions = normals), one node
    per sphere (translation, uniform scale) with its own material, and the camera
    (node at CAMERA's position looking down -Z, yfov and aspect of CAMERA).  With
    ``sheen_roughness`` every material is black (base colour 0, dielectric) under a white
    KHR_materials_sheen of that sheen roughness."""
    import pygltflib as g

    assert CAMERA["look_at"] == [0.0, 0.0, 0.0] and CAMERA["position"][:2] == [0.0, 0.0]
    theta = np.linspace(0.0, np.pi, RINGS + 1)
    phi = np.linspace(0.0, 2 * np.pi, SEGMENTS + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    pos = np.stack([np.sin(t) * np.sin(p), np.cos(t), np.sin(t) * np.cos(p)], axis=-1).reshape(-1, 3)
    pos = pos.astype(np.float32)
    idx = []
    for i in range(RINGS):
        for j in range(SEGMENTS):
            a, b = i * (SEGMENTS + 1) + j, (i + 1) * (SEGMENTS + 1) + j
            idx += [a, b, a + 1, a + 1, b, b + 1]
    idx = np.asarray(idx, np.uint32)
    blob = pos.tobytes() + pos.tobytes() + idx.tobytes()
    n = len(pos)
    grid = spheres()
    gltf = g.GLTF2(
        asset=g.Asset(version="2.0"),
        buffers=[g.Buffer(uri="grid.bin", byteLength=len(blob))],
        bufferViews=[g.BufferView(buffer=0, byteOffset=0, byteLength=12 * n, target=g.ARRAY_BUFFER),
                     g.BufferView(buffer=0, byteOffset=12 * n, byteLength=12 * n, target=g.ARRAY_BUFFER),
                     g.BufferView(buffer=0, byteOffset=24 * n, byteLength=4 * len(idx),
                                  target=g.ELEMENT_ARRAY_BUFFER)],
        accessors=[g.Accessor(bufferView=0, componentType=g.FLOAT, count=n, type=g.VEC3,
                              min=pos.min(0).tolist(), max=pos.max(0).tolist()),
                   g.Accessor(bufferView=1, componentType=g.FLOAT, count=n, type=g.VEC3),
                   g.Accessor(bufferView=2, componentType=g.UNSIGNED_INT, count=len(idx), type=g.SCALAR)],
        materials=[_material(g, i, s, sheen_roughness) for i, s in enumerate(grid)],
        extensionsUsed=["KHR_materials_sheen"] if sheen_roughness is not None else [],
        meshes=[g.Mesh(primitives=[g.Primitive(attributes=g.Attributes(POSITION=0, NORMAL=1), indices=2,
                                               material=i)]) for i in range(len(grid))],
        cameras=[g.Camera(type="perspective", perspective=g.Perspective(
            yfov=math.radians(CAMERA["fov"]), aspectRatio=W / H, znear=0.1, zfar=100.0))],
        nodes=[g.Node(camera=0, translation=CAMERA["position"])]
        + [g.Node(mesh=i, translation=s["center"], scale=[s["radius"]] * 3) for i, s in enumerate(grid)],
        scenes=[g.Scene(nodes=list(range(len(grid) + 1)))],
        scene=0,
    )
    (Path(folder) / "grid.bin").write_bytes(blob)
    gltf.save_json(str(Path(folder) / "grid.gltf"))
    return Path(folder) / "grid.gltf"


def _material(g, i, s, sheen_roughness):
    if sheen_roughness is None:
        return g.Material(name=f"m{i}", pbrMetallicRoughness=g.PbrMetallicRoughness(
            baseColorFactor=[*s["base_color"], 1.0], metallicFactor=s["metallic"], roughnessFactor=s["roughness"]))
    return g.Material(name=f"sheen{i}", pbrMetallicRoughness=g.PbrMetallicRoughness(
        baseColorFactor=[0.0, 0.0, 0.0, 1.0], metallicFactor=0.0, roughnessFactor=s["roughness"]),
        extensions={"KHR_materials_sheen": {"sheenColorFactor": [1.0, 1.0, 1.0],
                                            "sheenRoughnessFactor": float(sheen_roughness)}})


def pbrkit_linear(bake_dir, scene_dir, options=RENDER_OPTIONS):
    """``pbrkit render SCENE --mode realtime --tonemap none ...`` as linear EXR, (H, W, 3)."""
    from pbrkit.io.exr import read_exr

    scene = write_scene(scene_dir, bake_dir)
    out = Path(scene_dir) / "pbrkit.exr"
    run_cli(["render", scene, "-o", out, *options, "-q"])
    return read_exr(out)[..., :3].astype(np.float64)


ENGINE_OPTIONS = ["--mode", "realtime", "--tonemap", "none", "--engine", "khronos"]


def pbrkit_image(bake_dir, scene_dir):
    """pbrkit's real-time render of the grid as the Sample Viewer evaluates the IBL
    (``--engine khronos``), 8-bit sRGB (H, W, 3)."""
    return encode_srgb8(pbrkit_linear(bake_dir, scene_dir, ENGINE_OPTIONS))


def viewer_canvas(bake_dir, sheen_roughness=None, nosheen=False):
    """The viewer's canvas, 8-bit (H, W, 3) in its own encoding pow(c, 1 / 2.2); the grid
    of :func:`write_gltf` (``sheen_roughness``), the bake's sheen files left out with
    ``nosheen``."""
    bake_dir = Path(bake_dir)
    write_gltf(bake_dir, sheen_roughness)
    query = "&".join(["folder=khronos/", "gltf=grid.gltf", f"width={W}", f"height={H}", f"intensity={INTENSITY}",
                      f"nosheen={int(bool(nosheen))}"])
    report = run_page("khronos_render.html", data=bake_dir, query=query, timeout=120)
    result = report["result"]
    assert (result["width"], result["height"]) == (W, H) and result["mipCount"] == 5
    assert result["sheen"] is not bool(nosheen)
    rgba = np.frombuffer(base64.b64decode(result["rgba8"]), np.uint8).reshape(H, W, 4)[::-1]
    return np.ascontiguousarray(rgba[..., :3])


def engine_image(bake_dir, scene_dir):
    """The Sample Viewer's render of the grid, as 8-bit sRGB (H, W, 3) (its canvas is
    gamma 2.2: decoded and re-encoded)."""
    return gamma22_to_srgb8(viewer_canvas(bake_dir))


# ---------------------------------------------- the viewer's IBL, re-implemented


def viewer_model(bake_dir, scene_dir, fresnel="viewer", multiple="viewer", diffuse_weight="viewer"):
    """Linear (H, W, 3) image of the grid as the Sample Viewer 1.1.0 shades it
    (``getIBLRadianceGGX``, ``getIBLGGXFresnel``, ``getDiffuseLight``, the pbr shader's
    mixes), or with terms replaced by pbrkit's: ``fresnel="schlick"`` (F0 A + B:
    no roughness-dependent Fresnel), ``multiple="filament"`` (Filament's compensation
    instead of FmsEms), ``diffuse_weight="fstar"`` (pbrkit's 1 - F*)."""
    from pbrkit.ibl.cubemap import CubeSampler
    from pbrkit.io.ktx2 import read_ktx2

    folder = Path(bake_dir) / "khronos"
    index, n, d = sphere_hits(scene_dir)
    hit = index >= 0
    grid = spheres()
    r = np.array([s["roughness"] for s in grid])[index[hit]][:, None]
    metal = np.array([s["metallic"] for s in grid])[index[hit]][:, None]
    base = np.array([s["base_color"] for s in grid])[index[hit]]
    n, v = n[hit], -d[hit]
    nv = np.clip(np.sum(n * v, -1), 0.0, 1.0)[:, None]
    chain = [np.asarray(lv, np.float64)[..., :3] for lv in read_ktx2(folder / "specular.ktx2")[1]]
    radiance = CubeSampler(chain)(2.0 * nv * n - v, (len(chain) - 1.0) * r[:, 0])
    lambertian = CubeSampler([np.asarray(read_ktx2(folder / "lambertian.ktx2")[1][0], np.float64)[..., :3]])(n)
    fab = bilinear(np.asarray(read_ktx2(folder / "lut_ggx.ktx2")[1][0], np.float64), nv[:, 0], r[:, 0])
    a, b = fab[:, :1], fab[:, 1:]
    k_rough = (1.0 - nv) ** 5

    def weight(f0):
        k_s = f0 + (np.maximum(1.0 - r, f0) - f0) * k_rough if fresnel == "viewer" else f0
        fss_ess = k_s * a + b
        if multiple == "filament":
            return fss_ess * (1.0 + f0 * (1.0 / (a + b) - 1.0))
        ems = 1.0 - (a + b)
        f_avg = f0 + (1.0 - f0) / 21.0
        return fss_ess + ems * fss_ess * f_avg / (1.0 - f_avg * ems)

    w_metal = weight(base)
    w_diel = weight(np.full_like(base, 0.04))
    kd = 1.0 - w_diel
    if diffuse_weight == "fstar":
        kd = 1.0 - (0.04 + (np.maximum(1.0 - r, 0.04) - 0.04) * k_rough)
    dielectric = lambertian * base * kd + radiance * w_diel
    image = np.zeros((H, W, 3))
    image[hit] = (dielectric * (1 - metal) + radiance * w_metal * metal) * INTENSITY
    return image


# ------------------------------------------------------------------------ tests


@pytest.fixture(scope="module")
def renders(tmp_path_factory):
    root = tmp_path_factory.mktemp("khronos_render")
    bake_dir = bake(root / "bake")
    scene_dir = root / "scene"
    scene_dir.mkdir()
    pbrkit8_no_ec = encode_srgb8(pbrkit_linear(bake_dir, scene_dir, RENDER_OPTIONS[:-1]))
    pbrkit_lin = pbrkit_linear(bake_dir, scene_dir)
    pbrkit8 = encode_srgb8(pbrkit_lin)
    as_engine8 = encode_srgb8(pbrkit_linear(bake_dir, scene_dir, ENGINE_OPTIONS))
    canvas = viewer_canvas(bake_dir)
    engine8 = gamma22_to_srgb8(canvas)
    save_shots(root, "khronos", engine8, as_engine8)
    index = sphere_hits(scene_dir)[0]
    return {"bake": bake_dir, "scene": scene_dir, "pbrkit8": pbrkit8, "pbrkit_lin": pbrkit_lin, "as_engine8": as_engine8,
            "pbrkit8_no_ec": pbrkit8_no_ec, "canvas": canvas, "engine8": engine8, "index": index,
            "mask": sphere_mask(index), "root": root}


def test_the_viewer_renders_the_grid(renders):
    from scipy.ndimage import maximum_filter

    e, index = renders["engine8"], renders["index"]
    assert np.all(e[~maximum_filter(index >= 0, size=3)] == 0)
    for i in range(len(spheres())):
        mean = e[renders["mask"] & (index == i)].mean()
        assert 10 < mean < 250, (i, mean)
    assert renders["pbrkit_lin"][renders["mask"]].max() < 1.0


def test_the_viewer_renders_sheen_from_the_bound_tables(renders):
    """Black dielectric spheres under a white KHR_materials_sheen (sheen roughness 0.5):
    with the bake's charlie.ktx2, lut_charlie.ktx2 and lut_sheen_E.ktx2 bound the sheen
    lights every sphere; with them left out (the black textures bound before pbrkit baked
    sheen) only the dielectric's 4 % specular remains.  The sheen pixels must be clearly
    brighter, most brighter, and none black on a sphere's interior.  Measured (256 x 128,
    bake size 128): 41.2 grey levels on average against 17.2 without, the gain 24.1 on
    average, 10 at its 5th percentile, positive at every sphere pixel."""
    from scipy.ndimage import maximum_filter

    bake_dir, index, mask = renders["bake"], renders["index"], renders["mask"]
    with_sheen = gamma22_to_srgb8(viewer_canvas(bake_dir, sheen_roughness=0.5)).astype(np.float64)
    without = gamma22_to_srgb8(viewer_canvas(bake_dir, sheen_roughness=0.5, nosheen=True)).astype(np.float64)
    assert np.all(with_sheen[~maximum_filter(index >= 0, size=3)] == 0)
    gain = (with_sheen - without).mean(-1)[mask]
    assert gain.mean() > 10.0 and np.mean(gain > 0) > 0.9, (gain.mean(), np.mean(gain > 0))
    assert np.mean(with_sheen.mean(-1)[mask] > 5) > 0.99
    for i in range(len(spheres())):
        assert with_sheen[mask & (index == i)].mean() > without[mask & (index == i)].mean() + 5, i


def test_viewer_agrees_with_pbrkit_realtime(renders):
    """Measured (256 x 128, 14 172 sphere pixels): mean |grey| 1.22, p95 6.7; per
    channel mean (1.33, 1.32, 1.16), p95 (8, 7, 5).  Dielectric row 0.63 (p95 1.7),
    metal row 1.82 (p95 8.3).  Without --energy-compensation: 5.85 (p95 29)."""
    got = agreement(renders["engine8"], renders["pbrkit8"], renders["mask"])
    assert got["grey_mean"] <= 1.4 and got["grey_p95"] <= 8, got
    assert max(got["mean"]) <= 1.5 and max(got["p95"]) <= 9, got
    dielectric = renders["mask"] & (renders["index"] < 4)
    got = agreement(renders["engine8"], renders["pbrkit8"], dielectric)
    assert got["grey_mean"] <= 0.9 and got["grey_p95"] <= 3, got
    without = agreement(renders["engine8"], renders["pbrkit8_no_ec"], renders["mask"])
    assert without["grey_mean"] > 4.5, without


def test_khronos_agrees_with_pbrkit_realtime_as_khronos(renders):
    """The engine against ``pbrkit render --mode realtime --engine khronos`` (the
    engine's own IBL evaluation reproduced by pbrkit's real-time path): within one
    8-bit grey level on average, the issue's goal.  Measured: 0.29 (p95 1), dielectric row 0.20, metal row 0.38."""
    got = agreement(renders["engine8"], renders["as_engine8"], renders["mask"])
    assert got["grey_mean"] <= 1.0 and got["grey_p95"] <= 3 and max(got["mean"]) <= 1.0, got


def test_the_difference_is_the_viewer_s_fresnel(renders):
    """viewer_model reproduces the viewer's canvas (0.03 levels on average, in its own
    gamma-2.2 encoding); its terms, swapped one at a time for pbrkit's, move the image
    by (mean |grey|, p95): multiple scattering 0.89, 6.7; diffuse weight 0.28, 1.3;
    roughness-dependent Fresnel 0.09, 0.7; all three swapped, it is pbrkit's image to
    0.06 (p95 0.3)."""
    mask, bake_dir, scene_dir = renders["mask"], renders["bake"], renders["scene"]
    full = viewer_model(bake_dir, scene_dir)
    canvas = np.round(np.clip(full, 0.0, 1.0) ** (1.0 / 2.2) * 255.0)
    assert agreement(canvas, renders["canvas"], mask)["grey_mean"] <= 0.1
    assert agreement(encode_srgb8(full), renders["pbrkit8"], mask)["grey_mean"] >= 1.0
    sizes = {}
    for name, kwargs in {"fresnel": {"fresnel": "schlick"}, "multiple": {"multiple": "filament"},
                         "diffuse_weight": {"diffuse_weight": "fstar"}}.items():
        sizes[name] = agreement(encode_srgb8(viewer_model(bake_dir, scene_dir, **kwargs)), encode_srgb8(full),
                                mask)["grey_mean"]
    assert sizes["multiple"] > 0.6 and 0.15 < sizes["diffuse_weight"] < 0.5 and 0.03 < sizes["fresnel"] < 0.3, sizes
    swapped = viewer_model(bake_dir, scene_dir, fresnel="schlick", multiple="filament", diffuse_weight="fstar")
    assert agreement(encode_srgb8(swapped), renders["pbrkit8"], mask)["grey_mean"] <= 0.15


def test_saved_images(renders):
    import imageio.v3 as iio

    for name, key in (("khronos_engine.png", "engine8"), ("khronos_pbrkit.png", "as_engine8")):
        assert np.array_equal(iio.imread(renders["root"] / name), renders[key])
