"""A sphere grid rendered by three.js r187 (npm ``three`` 0.187.0) with
``pbrkit bake --target three``, against ``pbrkit render --mode realtime`` of the
same scene (issue 10), in headless Chromium.

The test bakes the bundled environment (``--size 128 --min-size 8``: 5 levels),
writes a scene file of 2 x 4 spheres (row 1 dielectric, row 2 metal; roughness
0.25, 0.5, 0.75, 1; base colours that do not clip), renders it with
``pbrkit render --mode realtime --tonemap none --diffuse cube
--energy-compensation`` and with ``pages/three_render.html`` (``scene.environment
= loadPbrkitCubeKTX2(...)``, MeshStandardMaterial spheres, no lights, no tone
mapping, sRGB output, the same camera), and compares the 8-bit sRGB images over
the sphere pixels (the spheres' silhouettes eroded by one pixel).

Options: ``--energy-compensation`` (three adds Fdez-Aguera's multiple scattering;
without it the rough metals are up to 2.8 x darker in pbrkit: 8.7 grey levels on
average instead of 3.7); ``--diffuse cube`` (three's irradiance is pi x the last,
roughness-1 level of the chain, neither pbrkit's SH nor its cube; the cube is
closer).  Both renders scale the environment by 0.25 (``intensity`` /
``scene.environmentIntensity``) so that the smooth metals do not clip.

What remains (measured on this scene, 256 x 128, 14 172 sphere pixels: mean |grey|
3.70, p95 15; per channel mean 3.68 / 3.58 / 3.92, p95 15 / 14 / 16; the dielectric
row 0.62, the metal row 6.8): three's shader does things pbrkit's real-time path
does not.  :func:`three_model` re-implements three r187's IBL for
MeshStandardMaterial in numpy (it reproduces three's render to 0.06 grey levels on
average, p95 0.3), and swapping one of its terms for pbrkit's changes the image by
(mean |grey|, p95):

* the lookup direction mixed toward the normal by r^4
  (``envmap_physical_pars_fragment``: ``mix(reflect, n, pow4(r))``): 1.3, 7;
* Fdez-Aguera's multiple scattering (``computeMultiscattering``: adds
  Fms Ems E / pi and takes Fss Ess + Fms Ems from the diffuse) instead of
  Filament's compensation 1 + F0 (1 / DFG2 - 1): 1.6, 7;
* the roughness three adds from screen-space normal derivatives
  (``geometryRoughness``, and the 0.045 floor): 0.8, 4;
* Filament's level curve on three's chain vs pbrkit's lod = r (M - 1) on its own
  (the interpolation between levels): 0.3, 2;
* three's built-in 16 x 16 DFG table vs the bake's 128 x 128 one: 0.16, 1;
* pi x the last level vs the irradiance cube for E: 0.10, 1.

With all of them swapped the model differs from pbrkit's image by 0.29 on average
(p95 1.3): pbrkit's F* diffuse weight and cube filtering.  The rough metals carry
almost all of the difference (the dielectric row alone agrees to 0.6 levels).
``pbrkit render --engine three`` reproduces those terms (all but three's own DFG
table) and agrees with three.js to 0.34 levels on average (p95 2): the issue's
goal of one grey level; the tests also keep the comparison with pbrkit's own IBL
(3.70) and the decomposition above.
"""

from __future__ import annotations

import base64
import json
from pathlib import Path

import numpy as np
import pytest
from engine_compare import (CAMERA, INTENSITY, H, W, agreement, bilinear, encode_srgb8, run_cli, save_shots,
                            sphere_hits, sphere_mask, spheres, three_dfg_table, write_scene)
from engine_pages import needs_engines, run_page

# a CLI bake, two pbrkit renders and a Chromium page: about 30 s on 2 cores (cold Numba cache)
pytestmark = [needs_engines(), pytest.mark.slow]

RENDER_OPTIONS = ["--mode", "realtime", "--tonemap", "none", "--diffuse", "cube", "--energy-compensation"]
BAKE_OPTIONS = ["--size", "128", "--min-size", "8", "--target", "three"]


def bake(bake_dir):
    """``pbrkit bake <bundled environment> -o bake_dir --size 128 --min-size 8 --target three``."""
    from pbrkit.data import environment_path

    run_cli(["bake", environment_path(), "-o", bake_dir, *BAKE_OPTIONS, "-q"])
    return Path(bake_dir)


def pbrkit_linear(bake_dir, scene_dir, options=RENDER_OPTIONS):
    """``pbrkit render SCENE --mode realtime --tonemap none ...`` as linear EXR, (H, W, 3)."""
    from pbrkit.io.exr import read_exr

    scene = write_scene(scene_dir, bake_dir)
    out = Path(scene_dir) / "pbrkit.exr"
    run_cli(["render", scene, "-o", out, *options, "-q"])
    return read_exr(out)[..., :3].astype(np.float64)


ENGINE_OPTIONS = ["--mode", "realtime", "--tonemap", "none", "--engine", "three"]


def pbrkit_image(bake_dir, scene_dir):
    """pbrkit's real-time render of the grid as three.js evaluates the IBL (``--engine
    three``), 8-bit sRGB (H, W, 3) (the EXR encoded as the PNG writer does: clip, sRGB,
    round)."""
    return encode_srgb8(pbrkit_linear(bake_dir, scene_dir, ENGINE_OPTIONS))


def _run_page(bake_dir, float_too=False):
    query = "&".join(["cube=three/specular.ktx2", "float=1" if float_too else "float=0",
                      "scene=" + json.dumps({"camera": CAMERA, "spheres": spheres(),
                                             "environment_intensity": INTENSITY})])
    report = run_page("three_render.html", data=bake_dir, query=query, timeout=120)
    result = report["result"]
    assert result["three"] == "187" and (result["width"], result["height"]) == (W, H)
    rgba = np.frombuffer(base64.b64decode(result["rgba8"]), np.uint8).reshape(H, W, 4)[::-1]  # GL rows: bottom up
    linear = None
    if float_too:
        linear = np.frombuffer(base64.b64decode(result["linear"]), np.float32).reshape(H, W, 4)[::-1, :, :3]
    return np.ascontiguousarray(rgba[..., :3]), linear, result


def engine_image(bake_dir, scene_dir):
    """three.js's render of the grid (its canvas, 8-bit sRGB), (H, W, 3)."""
    return _run_page(bake_dir)[0]


# ------------------------------------------------- three r187's IBL, re-implemented


def three_model(bake_dir, scene_dir, mix=True, geometry_roughness=True, lut="three", multiple="three",
                irradiance="three", levels="three"):
    """Linear (H, W, 3) image of the grid as three r187's MeshStandardMaterial shades it
    from ``scene.environment`` (``lights_physical_pars_fragment``,
    ``envmap_physical_pars_fragment``, ``lights_fragment_begin``), or with one of its
    terms replaced by pbrkit's: ``mix=False`` (mirror direction, no mix toward n by
    r^4), ``geometry_roughness=False`` (no derivative roughness, no 0.045 floor),
    ``lut="pbrkit"`` (the bake's DFG table), ``multiple="filament"`` (Filament's
    compensation instead of Fdez-Aguera's term), ``irradiance="cube"`` (the bake's
    irradiance cube instead of pi x the last level), ``levels="generic"`` (the generic
    chain at lod = r (M - 1))."""
    from pbrkit.ibl.cubemap import CubeSampler
    from pbrkit.io.ktx2 import read_ktx2

    bake_dir = Path(bake_dir)
    index, n, d = sphere_hits(scene_dir)
    hit = index >= 0
    grid = spheres()
    rough = np.array([s["roughness"] for s in grid])[index[hit]]
    metal = np.array([s["metallic"] for s in grid])[index[hit]][:, None]
    base = np.array([s["base_color"] for s in grid])[index[hit]]
    v = -d
    nv = np.clip(np.sum(n * v, -1), 0.0, 1.0)
    r = rough
    if geometry_roughness:  # max |dFdx n|, |dFdy n| (coarse: one difference per 2 x 2 quad)
        dx = np.zeros_like(n)
        dy = np.zeros_like(n)
        dx[:, 0:-1:2] = n[:, 1::2] - n[:, 0:-1:2]
        dx[:, 1::2] = dx[:, 0:-1:2]
        dy[0:-1:2] = n[1::2] - n[0:-1:2]
        dy[1::2] = dy[0:-1:2]
        extra = np.max(np.maximum(np.abs(dx), np.abs(dy)), -1)[hit]
        r = np.minimum(np.maximum(rough, 0.045) + extra, 1.0)
    n, v, nv = n[hit], v[hit], nv[hit]
    refl = 2.0 * nv[:, None] * n - v
    if mix:
        refl = refl + (n - refl) * (r ** 4)[:, None]
        refl /= np.linalg.norm(refl, axis=-1, keepdims=True)
    mirror = np.array([-1.0, 1.0, 1.0])  # the three chain is stored x mirrored
    three_chain = [np.asarray(lv, np.float64)[..., :3] for lv in read_ktx2(bake_dir / "three" / "specular.ktx2")[1]]
    sample = CubeSampler(three_chain)
    top = len(three_chain) - 1.0
    if levels == "three":
        radiance = sample(refl * mirror, top * r * (2.0 - r))
    else:
        generic = [np.asarray(lv, np.float64)[..., :3] for lv in read_ktx2(bake_dir / "specular.ktx2")[1]]
        radiance = CubeSampler(generic)(refl, (len(generic) - 1.0) * r)
    if irradiance == "three":
        e = np.pi * sample(n * mirror, np.full(len(n), top))
    else:
        e = CubeSampler([np.asarray(read_ktx2(bake_dir / "irradiance.ktx2")[1][0], np.float64)[..., :3]])(n)
    if lut == "three":
        fab = bilinear(three_dfg_table(), r, nv)
    else:  # the bake's (DFG1, DFG2) [roughness][n.v] as (A, B) = (DFG2 - DFG1, DFG1)
        dfg = bilinear(np.load(bake_dir / "brdf_lut.npy")[..., :2].astype(np.float64), nv, r)
        fab = np.stack([dfg[:, 1] - dfg[:, 0], dfg[:, 0]], -1)
    a, b = fab[:, :1], fab[:, 1:]

    def scattering(f0):
        single = f0 * a + b
        ems = 1.0 - (a + b)
        favg = f0 + (1.0 - f0) / 21.0
        return single, single * favg / (1.0 - ems * favg) * ems

    single_d, multi_d = scattering(np.full_like(base, 0.04))
    single_m, multi_m = scattering(base)
    single = single_d * (1 - metal) + single_m * metal
    multi = multi_d * (1 - metal) + multi_m * metal
    taken = single_d + multi_d
    if multiple == "filament":
        f0 = 0.04 * (1 - metal) + base * metal
        single = single * (1.0 + f0 * (1.0 / (a + b) - 1.0))
        multi = 0.0 * multi
        taken = single_d
    image = np.zeros((H, W, 3))
    image[hit] = radiance * single + (multi + base * (1 - metal) * (1.0 - taken)) * e / np.pi
    return image * INTENSITY


# ------------------------------------------------------------------------ tests


@pytest.fixture(scope="module")
def renders(tmp_path_factory):
    root = tmp_path_factory.mktemp("three_render")
    bake_dir = bake(root / "bake")
    scene_dir = root / "scene"
    scene_dir.mkdir()
    pbrkit8_no_ec = encode_srgb8(pbrkit_linear(bake_dir, scene_dir, RENDER_OPTIONS[:-1]))
    pbrkit_lin = pbrkit_linear(bake_dir, scene_dir)
    pbrkit8 = encode_srgb8(pbrkit_lin)
    as_engine8 = encode_srgb8(pbrkit_linear(bake_dir, scene_dir, ENGINE_OPTIONS))
    engine8, engine_lin, result = _run_page(bake_dir, float_too=True)
    save_shots(root, "three", engine8, as_engine8)
    index = sphere_hits(scene_dir)[0]
    return {"bake": bake_dir, "scene": scene_dir, "pbrkit8": pbrkit8, "pbrkit_lin": pbrkit_lin, "as_engine8": as_engine8,
            "pbrkit8_no_ec": pbrkit8_no_ec, "engine8": engine8, "engine_lin": engine_lin, "index": index,
            "mask": sphere_mask(index), "result": result, "root": root}


def test_the_page_renders_the_grid(renders):
    """Every sphere is there, lit by the bake (no black or white spheres), the background
    is the clear colour, and nothing clips: the comparison below is of real renders."""
    from scipy.ndimage import maximum_filter

    assert renders["result"]["environmentLevels"] == 5
    e, index = renders["engine8"], renders["index"]
    assert np.all(e[~maximum_filter(index >= 0, size=3)] == 0)
    for i in range(len(spheres())):
        mean = e[renders["mask"] & (index == i)].mean()
        assert 10 < mean < 250, (i, mean)
    assert renders["pbrkit_lin"][renders["mask"]].max() < 1.0


def test_three_agrees_with_pbrkit_realtime(renders):
    """Measured (256 x 128, 14 172 sphere pixels): mean |grey| 3.70, p95 15; per channel
    mean (3.68, 3.58, 3.92), p95 (15, 14, 16).  Dielectric row alone: 0.62 (p95 1.7);
    metal row 6.8 (p95 18).  The causes are three's shader terms (module docstring,
    next test)."""
    got = agreement(renders["engine8"], renders["pbrkit8"], renders["mask"])
    assert got["grey_mean"] <= 4.2 and got["grey_p95"] <= 17, got
    assert max(got["mean"]) <= 4.5 and max(got["p95"]) <= 18, got
    dielectric = renders["mask"] & (renders["index"] >= 0) & (renders["index"] < 4)
    got = agreement(renders["engine8"], renders["pbrkit8"], dielectric)
    assert got["grey_mean"] <= 0.9 and got["grey_p95"] <= 3, got
    # without --energy-compensation the rough metals are far off (8.7): the option matters
    without = agreement(renders["engine8"], renders["pbrkit8_no_ec"], renders["mask"])
    assert without["grey_mean"] > 7.0, without


def test_three_agrees_with_pbrkit_realtime_as_three(renders):
    """The engine against ``pbrkit render --mode realtime --engine three`` (the
    engine's own IBL evaluation reproduced by pbrkit's real-time path): within one
    8-bit grey level on average, the issue's goal.  Measured: 0.34 (p95 2), dielectric row 0.04, metal row 0.64."""
    got = agreement(renders["engine8"], renders["as_engine8"], renders["mask"])
    assert got["grey_mean"] <= 1.0 and got["grey_p95"] <= 3 and max(got["mean"]) <= 1.0, got


def test_the_difference_is_three_s_shader_terms(renders):
    """three_model reproduces three's render; replacing each of its terms by pbrkit's
    moves it by the amounts in the module docstring, and all of them together bring
    it to pbrkit's image."""
    mask, bake_dir, scene_dir = renders["mask"], renders["bake"], renders["scene"]
    full = three_model(bake_dir, scene_dir)
    assert agreement(encode_srgb8(full), renders["engine8"], mask)["grey_mean"] <= 0.2
    assert agreement(encode_srgb8(full), renders["pbrkit8"], mask)["grey_mean"] >= 3.0
    sizes = {}
    for name, kwargs in {"mix": {"mix": False}, "multiple": {"multiple": "filament"},
                         "geometry_roughness": {"geometry_roughness": False}, "levels": {"levels": "generic"},
                         "lut": {"lut": "pbrkit"}, "irradiance": {"irradiance": "cube"}}.items():
        sizes[name] = agreement(encode_srgb8(three_model(bake_dir, scene_dir, **kwargs)), encode_srgb8(full),
                                mask)["grey_mean"]
    assert sizes["mix"] > 1.0 and sizes["multiple"] > 1.2 and sizes["geometry_roughness"] > 0.5, sizes
    assert max(sizes["levels"], sizes["lut"], sizes["irradiance"]) < 0.5, sizes
    swapped = three_model(bake_dir, scene_dir, mix=False, geometry_roughness=False, lut="pbrkit",
                          multiple="filament", irradiance="cube", levels="generic")
    assert agreement(encode_srgb8(swapped), renders["pbrkit8"], mask)["grey_mean"] <= 0.5


def test_saved_images(renders):
    import imageio.v3 as iio

    for name, key in (("three_engine.png", "engine8"), ("three_pbrkit.png", "as_engine8")):
        assert np.array_equal(iio.imread(renders["root"] / name), renders[key])
