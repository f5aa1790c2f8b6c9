"""Proof inside Babylon.js (npm ``babylonjs`` 9.35.0, headless Chromium, WebGL2 via
SwiftShader) that ``pbrkit bake --target babylon`` renders as pbrkit does: Babylon
loads ``babylon/environment.env`` through its own public
``CubeTexture.CreateFromPrefilteredData`` as ``scene.environmentTexture`` of a
right-handed scene and draws a 2 x 4 sphere grid (metallic 0 / 1, roughness 0.2,
0.4, 0.6, 0.8) with ``PBRMaterial`` (page: ``engines/pages/babylon_render.js``);
``pbrkit render --mode realtime`` draws the same scene file from the same bake.  The
two are compared on the sphere pixels in 8-bit sRGB.

pbrkit's side: ``model = "urp_mobile"``, ``--diffuse sh --energy-compensation
--tonemap none``, which is what Babylon's PBRMaterial computes with its 9.35 defaults
(read from its shaders ``pbrBlockReflectivity``, ``pbrBlockReflectance``,
``pbrBlockFinalLitComponents``, ``pbrBRDFFunctions``):

* ``brdf.useLegacySpecularEnergyConservation`` (default on): diffuse colour
  base (1 - 0.04)(1 - metallic), no specular weight on the diffuse; f0 =
  mix(0.04, base, metallic), f90 = 1.  pbrkit's ``urp_mobile`` has exactly this
  (0.96 (1 - metallic) base, Lambert, metallic f0, height-correlated DFG table);
  ``gltf`` would weight the diffuse by 1 - F* and use the separable table.
* ``brdf.useEnergyConservation`` (default on): specular x 1 + F0 (1 / DFG.y - 1),
  pbrkit's ``--energy-compensation`` (Filament's formula, the same).
* height-correlated Smith, split-sum (F90 - F0) DFG.x + F0 DFG.y: the bake's table.
* SH irradiance E / pi from the .env's polynomial: ``--diffuse sh``.
* no tone mapping: ``--tonemap none``.  The page writes linear radiance (image
  processing "by post process", none attached) into a float target; both images are
  encoded here with pbrkit's PNG encoding (sRGB IEC 61966-2-1, rint), which the
  test checks against pbrkit's own PNG.

Babylon's extras turned off on the page: ``brdf.mixIblRadianceWithIrradiance``
(default on; it blends the prefiltered radiance towards the irradiance by alphaG:
+4.2 grey levels here), ``baseDiffuseModel`` Lambert (the default E-Oren-Nayar
bends the SH lookup only for a diffuse roughness > 0), radiance / horizon
occlusion and specular anti-aliasing (no AO texture, no bump map: no effect),
``forceIrradianceInFragment`` (per-pixel SH, as pbrkit).

Measured (``test_terms``, by variants of one page run): Babylon shading pbrkit's
generic chain at pbrkit's lod = r (M - 1) (``linearSpecularLOD``, ``invertZ``) is
pbrkit's image to 0.04 grey levels, so every formula matches; what separates the
target's render from pbrkit's (0.45 levels) is the target's chain, prefiltered at
Babylon's levels alpha = 2^(m / 0.8) / N and blended between them at lod =
0.8 log2(N alpha) (0.43), then Babylon's 8-bit RGBD environment-BRDF texture vs
pbrkit's table (0.08) and the .env's RGBD faces vs the half-float DDS (0.04).

Babylon's canvas (its own output path) is the linear render encoded with
x^(1/2.2), not sRGB (1.6 grey levels from pbrkit's PNG); the Engine option
``useExactSrgbConversions`` makes it sRGB (0.64) but also decodes every RGBD
texture (the .env, its BRDF texture) with the sRGB curve instead of the 2.2 power
they are written with (the .env render moves by 0.38 grey levels).

``engine_image`` / ``pbrkit_image`` give the two images for a gallery; with
``PBRKIT_ENGINE_SHOTS=DIR`` the test also saves them there as
``babylon_engine.png`` and ``babylon_pbrkit.png``.
"""

import base64
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest
from engine_pages import needs_engines, run_page

from pbrkit.core.color import linear_to_srgb
from pbrkit.data import environment_path
from pbrkit.io.images import read_image

pytestmark = [needs_engines(), pytest.mark.slow]

BAKE_SIZE = 128
MIN_SIZE = 4  # generic levels r = 0, 0.2, ..., 1: the roughness values below sit on levels
WIDTH, HEIGHT = 256, 128
SEGMENTS = 96
CAMERA = {"position": [0.0, 0.0, 6.0], "look_at": [0.0, 0.0, 0.0], "up": [0.0, 1.0, 0.0], "fov": 20.0,
          "width": WIDTH, "height": HEIGHT}
RADIUS = 0.42
MASK_SHRINK = 0.95  # compare pixels whose ray hits the sphere shrunk by 5%: no silhouette pixels
ROUGHNESS = (0.2, 0.4, 0.6, 0.8)
# linear base colours low enough that no compared pixel clips (the sky reaches ~4.3 x the base
# colour on the r = 0.2 metal); the brightest compared pixel is 0.91
COLOURS = {0.0: ([0.50, 0.20, 0.12], [0.18, 0.45, 0.22], [0.18, 0.26, 0.55], [0.45, 0.45, 0.45]),
           1.0: ([0.21, 0.16, 0.07], [0.40, 0.25, 0.20], [0.50, 0.50, 0.50], [0.36, 0.40, 0.58])}
MODEL = "urp_mobile"
PBRKIT_OPTIONS = ["--mode", "realtime", "--diffuse", "sh", "--energy-compensation", "--tonemap", "none"]
# the page's variants (each one linear render): cube file, DFG texture, overrides of the page's settings
VARIANTS = {
    "babylon": {"texture": "env", "lut": "babylon"},  # the target as Babylon takes it: the result
    "table": {"texture": "env", "lut": "table"},  # pbrkit's DFG table as scene.environmentBRDFTexture
    "table_dds": {"texture": "dds", "lut": "table"},  # ... and the target's half-float DDS, not the .env
    # pbrkit's generic chain sampled at pbrkit's lod = r (M - 1) (linearSpecularLOD, invertZ)
    "generic": {"texture": "generic", "lut": "table"},
    "mix": {"texture": "env", "lut": "babylon", "brdf": {"mixIblRadianceWithIrradiance": True}},  # its default
    "no_ec": {"texture": "env", "lut": "babylon", "brdf": {"useEnergyConservation": False}},
}


def spheres():
    out = []
    for row, metallic in enumerate((0.0, 1.0)):
        for col, r in enumerate(ROUGHNESS):
            out.append({"center": [-1.5 + col, 0.5 - row, 0.0], "radius": RADIUS, "metallic": metallic,
                        "roughness": r, "base_color": COLOURS[metallic][col]})
    return out


def bake(bake_dir):
    """``pbrkit bake`` of the bundled environment with the babylon target."""
    subprocess.run([sys.executable, "-m", "pbrkit", "bake", str(environment_path()), "-o", str(bake_dir),
                    "--size", str(BAKE_SIZE), "--min-size", str(MIN_SIZE), "--target", "babylon", "--quiet"],
                   check=True, capture_output=True, text=True)
    return Path(bake_dir)


def write_scene(scene_dir, bake_dir):
    """``scene.toml`` (pbrkit), ``scene.json`` (the page) and ``scene_exact.json`` (the
    page with ``useExactSrgbConversions``) of the same sphere grid, lit by the bake in
    ``bake_dir``, in ``scene_dir``; returns the folder."""
    scene_dir = Path(scene_dir)
    scene_dir.mkdir(parents=True, exist_ok=True)
    bake_dir = Path(bake_dir).resolve()
    lines = ["[camera]"]
    lines += [f"{k} = {json.dumps(v)}" for k, v in CAMERA.items()]
    lines += ["", "[environment]", f"bake = {json.dumps(str(bake_dir))}", ""]
    for i, s in enumerate(spheres()):
        lines += [f"[materials.m{i}]", f'model = "{MODEL}"', f"base_color = {json.dumps(s['base_color'])}",
                  f"metallic = {s['metallic']}", f"roughness = {s['roughness']}", ""]
    for i, s in enumerate(spheres()):
        lines += ["[[objects]]", 'type = "sphere"', f"center = {json.dumps(s['center'])}",
                  f"radius = {s['radius']}", f'material = "m{i}"', ""]
    (scene_dir / "scene.toml").write_text("\n".join(lines))
    lut = np.load(bake_dir / "brdf_lut.npy").astype("<f4")  # [r row, n.v column, (DFG1, DFG2)]
    rgba = np.zeros(lut.shape[:2] + (4,), dtype="<f4")
    rgba[..., :2] = lut
    rgba[..., 3] = 1
    rgba.tofile(scene_dir / "lut.bin")
    levels = len(json.loads((bake_dir / "manifest.json").read_text())["outputs"]["specular"]["roughness"])
    page = {"camera": CAMERA, "spheres": spheres(), "segments": SEGMENTS,
            "env": "/data/bake/babylon/environment.env", "dds": "/data/bake/babylon/specular.dds",
            "generic": {"url": "/data/bake/specular.dds", "lodScale": (levels - 1) / math.log2(BAKE_SIZE)},
            "lut": {"url": "/data/scene/lut.bin", "size": int(lut.shape[0])},
            "variants": [dict(name=k, **v) for k, v in VARIANTS.items()], "canvas": "babylon"}
    (scene_dir / "scene.json").write_text(json.dumps(page, indent=1))
    exact = dict(page, engineOptions={"useExactSrgbConversions": True},
                 variants=[dict(name=k, **VARIANTS[k]) for k in ("babylon", "table_dds")])
    (scene_dir / "scene_exact.json").write_text(json.dumps(exact, indent=1))
    return scene_dir


def _scene(bake_dir, scene_dir):
    if not (Path(scene_dir) / "scene.json").exists():
        write_scene(scene_dir, bake_dir)
    return Path(scene_dir)


def srgb8(linear):
    """8-bit sRGB as pbrkit's PNG writer makes it (clip to [0, 1], IEC 61966-2-1, rint)."""
    return np.rint(linear_to_srgb(np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)) * 255).astype(np.uint8)


def gamma8(linear):
    """8-bit x^(1/2.2): Babylon's default linear -> gamma conversion (``toGammaSpace``)."""
    return np.rint(np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0) ** (1 / 2.2) * 255).astype(np.uint8)


# Babylon's own IBL evaluation with its defaults, reproduced by pbrkit's real-time path
ENGINE_OPTIONS = ["--mode", "realtime", "--tonemap", "none", "--engine", "babylon"]


def _render(bake_dir, scene_dir, out, options=PBRKIT_OPTIONS):
    scene_dir = _scene(bake_dir, scene_dir)
    subprocess.run([sys.executable, "-m", "pbrkit", "render", str(scene_dir / "scene.toml"), "-o", str(out),
                    *options], check=True, capture_output=True, text=True)
    return out


def pbrkit_linear(bake_dir, scene_dir, options=PBRKIT_OPTIONS):
    """``pbrkit render --mode realtime`` of the scene as EXR: linear float (H, W, 3)."""
    out = _render(bake_dir, scene_dir, Path(scene_dir) / f"pbrkit_{len(options)}.exr", options)
    return read_image(out)[..., :3].astype(np.float64)


def pbrkit_image(bake_dir, scene_dir):
    """``pbrkit render --mode realtime --tonemap none --engine babylon`` of the scene as
    PNG: uint8 (H, W, 3) (for the gallery, next to Babylon with its defaults)."""
    out = _render(bake_dir, scene_dir, Path(scene_dir) / "pbrkit_babylon.png", ENGINE_OPTIONS)
    return np.asarray(iio.imread(out))[..., :3]


def pbrkit_png(bake_dir, scene_dir):
    """``pbrkit render --mode realtime --tonemap none`` (pbrkit's own IBL, the options of
    PBRKIT_OPTIONS) of the scene as PNG: uint8 (H, W, 3)."""
    out = _render(bake_dir, scene_dir, Path(scene_dir) / "pbrkit.png")
    return np.asarray(iio.imread(out))[..., :3]


def run_render_page(bake_dir, scene_dir, spec="scene.json", timeout=180):
    """harness.mjs on pages/babylon_render.html, serving the bake as ``/data/bake`` and
    the scene folder as ``/data/scene``: the report's "result" (fails the test with the
    page's error otherwise; judges the report itself, as test_engine_babylon does)."""
    scene_dir = _scene(bake_dir, scene_dir)
    data = scene_dir / "served"
    data.mkdir(exist_ok=True)
    for name, target in (("bake", Path(bake_dir)), ("scene", scene_dir)):
        link = data / name
        if not link.exists():
            link.symlink_to(target.resolve(), target_is_directory=True)
    return run_page("babylon_render.html", data=data, query=f"scene=/data/scene/{spec}", timeout=timeout)["result"]


def engine_linear(result, variant="babylon"):
    """A variant's linear float RGBA (H, W, 4), top row first (alpha = coverage)."""
    raw = np.frombuffer(base64.b64decode(result["variants"][variant]["linear"]), dtype="<f4")
    return raw.reshape(result["height"], result["width"], 4).astype(np.float64)


def canvas_pixels(result):
    """Babylon's canvas (its own image processing and 8-bit output): uint8 (H, W, 4)."""
    raw = np.frombuffer(base64.b64decode(result["canvas"]["rgba"]), dtype=np.uint8)
    return raw.reshape(result["height"], result["width"], 4)


def engine_image(bake_dir, scene_dir):
    """Babylon's render of the scene from the target's .env with its defaults (variant
    ``mix``), encoded as pbrkit's PNGs are (sRGB): uint8 (H, W, 3)."""
    return srgb8(engine_linear(run_render_page(bake_dir, scene_dir), "mix")[..., :3])


def sphere_mask(shrink=1.0):
    """(mask, labels): pixels whose centre ray hits a sphere of radius shrink x RADIUS
    (pbrkit's pinhole: vertical fov, pixel centres, top row first), and which sphere."""
    t = math.tan(math.radians(CAMERA["fov"]) / 2)
    x = ((np.arange(WIDTH) + 0.5) / WIDTH * 2 - 1) * t * WIDTH / HEIGHT
    y = (1 - (np.arange(HEIGHT) + 0.5) / HEIGHT * 2) * t
    d = np.stack(np.broadcast_arrays(x[None, :], y[:, None], -np.ones((HEIGHT, WIDTH))), axis=-1)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    o = np.array(CAMERA["position"])
    labels = np.full((HEIGHT, WIDTH), -1)
    for i, s in enumerate(spheres()):
        oc = o - np.array(s["center"])
        b = d @ oc
        labels[b * b - (oc @ oc - (shrink * s["radius"]) ** 2) > 0] = i
    return labels >= 0, labels


def agreement(a, b, mask):
    """|a - b| in 8-bit levels over ``mask``: mean and 95th percentile per channel and
    for grey (the mean of R, G, B), and the mean signed a - b per channel."""
    a = a[..., :3].astype(np.float64)[mask]
    b = b[..., :3].astype(np.float64)[mask]
    d = np.abs(a - b)
    grey = np.abs(a.mean(axis=1) - b.mean(axis=1))
    return {"mean": d.mean(axis=0), "p95": np.percentile(d, 95, axis=0), "grey_mean": float(grey.mean()),
            "grey_p95": float(np.percentile(grey, 95)), "signed": (a - b).mean(axis=0)}


def describe(name, s):
    m, p, g = s["mean"], s["p95"], s["signed"]
    return (f"{name}: grey mean {s['grey_mean']:.3f} p95 {s['grey_p95']:.2f}; R G B mean "
            f"{m[0]:.3f} {m[1]:.3f} {m[2]:.3f}, p95 {p[0]:.1f} {p[1]:.1f} {p[2]:.1f}; "
            f"signed {g[0]:+.3f} {g[1]:+.3f} {g[2]:+.3f}")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("babylon_render")
    bake_dir = bake(folder / "bake")
    scene_dir = write_scene(folder / "scene", bake_dir)
    linear = pbrkit_linear(bake_dir, scene_dir)
    png = pbrkit_png(bake_dir, scene_dir)
    as_babylon = srgb8(pbrkit_linear(bake_dir, scene_dir, ENGINE_OPTIONS))
    result = run_render_page(bake_dir, scene_dir)
    exact = run_render_page(bake_dir, scene_dir, "scene_exact.json")
    mask, labels = sphere_mask(MASK_SHRINK)
    return {"folder": folder, "bake": bake_dir, "scene": scene_dir, "linear": linear, "png": png,
            "as_babylon": as_babylon,
            "result": result, "exact": exact, "mask": mask, "labels": labels,
            "engine": {k: srgb8(engine_linear(result, k)[..., :3]) for k in VARIANTS}}


def test_babylon_loads_the_target_and_compiles_the_stated_shader(run):
    r = run["result"]
    assert r["version"] == "9.35.0" and r["useRightHandedSystem"] is True
    env = r["environment"]["env"]
    assert env == {"size": BAKE_SIZE, "lodGenerationScale": 0.8, "isRGBD": False, "invertZ": False,
                   "hasPolynomial": True}
    expect = {"REFLECTION": True, "REFLECTIONMAP_3D": True, "REFLECTIONMAP_OPPOSITEZ": True,
              "LODBASEDMICROSFURACE": True, "LINEARSPECULARREFLECTION": False, "REALTIME_FILTERING": False,
              "USESPHERICALFROMREFLECTIONMAP": True, "SPHERICAL_HARMONICS": True, "USESPHERICALINVERTEX": False,
              "ENVIRONMENTBRDF": True, "BRDF_V_HEIGHT_CORRELATED": True, "MS_BRDF_ENERGY_CONSERVATION": True,
              "LEGACY_SPECULAR_ENERGY_CONSERVATION": True, "MIX_IBL_RADIANCE_WITH_IRRADIANCE": False,
              "BASE_DIFFUSE_MODEL": 2, "RADIANCEOCCLUSION": False, "HORIZONOCCLUSION": False, "SPECULARAA": False,
              "METALLICWORKFLOW": True, "IMAGEPROCESSINGPOSTPROCESS": True}
    for key in ("defines", "metallicDefines"):
        got = r["variants"]["babylon"][key]
        assert {k: got[k] for k in expect} == expect, key
    assert r["variants"]["mix"]["defines"]["MIX_IBL_RADIANCE_WITH_IRRADIANCE"] is True
    assert r["variants"]["no_ec"]["defines"]["MS_BRDF_ENERGY_CONSERVATION"] is False
    assert r["variants"]["generic"]["defines"]["LINEARSPECULARREFLECTION"] is True
    canvas = r["canvas"]["defines"]
    # image processing in the material (applyImageProcessing: its toGammaSpace always, and
    # none of the optional steps; IMAGEPROCESSING is only defined when one of them is on)
    assert canvas["IMAGEPROCESSINGPOSTPROCESS"] is False
    assert not any(canvas[k] for k in ("IMAGEPROCESSING", "TONEMAPPING", "EXPOSURE", "CONTRAST", "VIGNETTE", "DITHER"))


def test_same_camera_and_spheres(run):
    """Babylon's coverage (alpha of the float target) is pbrkit's analytic spheres: the
    camera, fov, aspect and handedness agree; the compared pixels are all covered."""
    covered = engine_linear(run["result"])[..., 3] > 0.5
    full, _ = sphere_mask(1.0)
    assert np.all(covered[run["mask"]])
    assert np.count_nonzero(covered != full) < 0.01 * np.count_nonzero(full)
    # every sphere is there, top row dielectric
    assert set(np.unique(run["labels"][run["mask"]])) == set(range(8))


def test_pbrkit_png_is_the_exr_encoded_here(run):
    """The encoding applied to Babylon's linear render is pbrkit's PNG encoding."""
    assert run["png"].shape == (HEIGHT, WIDTH, 3)
    assert np.array_equal(run["png"], srgb8(run["linear"]))
    # nothing compared clips, and the test image is not dark
    assert run["linear"][run["mask"]].max() < 0.95
    assert run["png"][run["mask"]].mean() > 80


def test_sphere_grid_agrees_with_pbrkit_realtime(run):
    """The issue's criterion (<= 1 grey level on average), met with room: measured 0.45
    (R G B 0.42 0.43 0.50), p95 2 levels; the asserted bounds are those plus a margin."""
    s = agreement(run["engine"]["babylon"], run["png"], run["mask"])
    print(describe("Babylon (target .env, its BRDF texture) vs pbrkit", s))
    assert s["grey_mean"] <= 0.6
    assert np.all(s["mean"] <= 0.65)
    assert s["grey_p95"] <= 3.0 and np.all(s["p95"] <= 3.0)
    assert np.all(np.abs(s["signed"]) <= 0.3)  # no bias


def test_babylon_defaults_agree_with_pbrkit_realtime_as_babylon(run):
    """Babylon with its defaults (``mixIblRadianceWithIrradiance`` on, its BRDF
    texture, the target's .env) against ``pbrkit render --engine babylon`` (its chain at
    its lod, the radiance mixed towards E / pi by alpha_G, its energy conservation and
    legacy diffuse): within one 8-bit grey level on average, the issue's goal."""
    s = agreement(run["engine"]["mix"], run["as_babylon"], run["mask"])
    print(describe("Babylon (defaults) vs pbrkit --engine babylon", s))
    assert s["grey_mean"] <= 1.0 and np.all(s["mean"] <= 1.0) and s["grey_p95"] <= 3.0


def test_babylon_shades_pbrkit_chain_as_pbrkit_does(run):
    """Babylon sampling pbrkit's generic chain at pbrkit's lod with pbrkit's DFG table
    gives pbrkit's image: model, energy compensation, SH, orientation all match
    (measured 0.04 grey levels, p95 0.33)."""
    s = agreement(run["engine"]["generic"], run["png"], run["mask"])
    print(describe("Babylon on pbrkit's generic chain vs pbrkit", s))
    assert s["grey_mean"] <= 0.1 and s["grey_p95"] <= 0.5
    assert np.all(s["p95"] <= 1.0)
    linear = engine_linear(run["result"], "generic")[..., :3][run["mask"]]
    rel = np.abs(linear / run["linear"][run["mask"]] - 1)
    assert np.percentile(rel, 99) < 0.01


def test_terms(run):
    """The terms between the result and pbrkit, each isolated by one change inside Babylon."""
    e, m = run["engine"], run["mask"]
    terms = {
        "chain (target chain at Babylon's lod vs generic chain at pbrkit's lod)": agreement(e["table_dds"], e["generic"], m),
        "BRDF texture (Babylon's RGBD PNG vs pbrkit's table)": agreement(e["babylon"], e["table"], m),
        "RGBD .env vs half-float DDS": agreement(e["table"], e["table_dds"], m),
        "mixIblRadianceWithIrradiance on (Babylon default)": agreement(e["mix"], e["babylon"], m),
        "useEnergyConservation off": agreement(e["no_ec"], e["babylon"], m),
    }
    for name, s in terms.items():
        print(describe(name, s))
    chain, lut, rgbd, mix, ec = (t["grey_mean"] for t in terms.values())
    assert 0.2 <= chain <= 0.6  # the dominant term: measured 0.43
    assert lut <= 0.15 and rgbd <= 0.1  # measured 0.08, 0.04
    assert chain > 2 * (lut + rgbd)
    assert mix > 2.0  # measured 4.2: why it is turned off
    assert ec > 1.0  # measured 3.1: why --energy-compensation is on


def test_babylon_brdf_texture_against_pbrkit_table(run):
    """Babylon's own environment-BRDF texture (an RGBD PNG expanded to half float,
    256^2, R = (F90 - F0) weight, G = F0 weight at uv = (n.v, roughness)) is pbrkit's
    height-correlated (DFG1, DFG2) table to its 8-bit precision: measured mean
    |diff| 0.0008 / 0.0028, max 0.07 (what the 0.08-level BRDF-texture term is)."""
    from scipy.ndimage import map_coordinates

    t = run["result"]["brdfTexture"]
    assert (t["width"], t["height"], t["texelsKind"]) == (256, 256, "Float32Array")
    theirs = np.frombuffer(base64.b64decode(t["texels"]), dtype="<f4").reshape(256, 256, 4)
    table = np.load(run["bake"] / "brdf_lut.npy")
    n = table.shape[0]
    centres = (np.arange(256) + 0.5) / 256 * n - 0.5  # Babylon's texel centres in the table's texels
    rows, cols = np.meshgrid(centres, centres, indexing="ij")
    for c, (mean_bound, max_bound) in enumerate(((0.002, 0.1), (0.005, 0.1))):
        ours = map_coordinates(table[..., c].astype(np.float64), [rows, cols], order=1, mode="nearest")
        d = np.abs(theirs[..., c] - ours)
        print(f"Babylon BRDF texture channel {c} vs pbrkit DFG{c + 1}: mean {d.mean():.5f}, max {d.max():.4f}")
        assert d.mean() <= mean_bound and d.max() <= max_bound
        assert np.abs(theirs[::-1, :, c] - ours).mean() > 0.05  # rows: v = roughness, row 0 smooth


def test_canvas_output(run):
    """Babylon's canvas is the linear render through x^(1/2.2), not sRGB; with the Engine
    option useExactSrgbConversions it is sRGB, but RGBD textures then decode with the
    sRGB curve too."""
    r, m = run["result"], run["mask"]
    canvas = canvas_pixels(r)
    assert np.all(canvas[..., 3][m] == 255)
    gamma = gamma8(engine_linear(r)[..., :3])
    assert np.abs(canvas[..., :3][m].astype(int) - gamma[m]).max() <= 1
    vs_png = agreement(canvas, run["png"], m)
    vs_gamma = agreement(canvas, gamma8(run["linear"]), m)
    print(describe("canvas (x^(1/2.2)) vs pbrkit PNG (sRGB)", vs_png))
    print(describe("canvas vs pbrkit encoded x^(1/2.2)", vs_gamma))
    assert vs_gamma["grey_mean"] <= 0.6 and vs_png["grey_mean"] > 1.0  # measured 0.43, 1.64
    x = run["exact"]
    exact_canvas = agreement(canvas_pixels(x), run["png"], m)
    rgbd_shift = agreement(srgb8(engine_linear(x)[..., :3]), run["engine"]["babylon"], m)
    dds_shift = agreement(srgb8(engine_linear(x, "table_dds")[..., :3]), run["engine"]["table_dds"], m)
    print(describe("useExactSrgbConversions: canvas vs pbrkit PNG", exact_canvas))
    print(describe("useExactSrgbConversions: .env render shift", rgbd_shift))
    assert exact_canvas["grey_mean"] <= 0.8  # measured 0.64
    assert rgbd_shift["grey_mean"] > 0.1 and dds_shift["grey_mean"] < 0.01  # measured 0.38, 0


def test_gallery_images(run, tmp_path):
    engine = run["engine"]["mix"]
    pbrkit = run["as_babylon"]
    assert engine.shape == pbrkit.shape == (HEIGHT, WIDTH, 3) and engine.dtype == pbrkit.dtype == np.uint8
    folders = [tmp_path]
    if os.environ.get("PBRKIT_ENGINE_SHOTS"):
        folders.append(Path(os.environ["PBRKIT_ENGINE_SHOTS"]))
    for folder in folders:
        folder.mkdir(parents=True, exist_ok=True)
        for name, image in (("babylon_engine.png", engine), ("babylon_pbrkit.png", pbrkit)):
            iio.imwrite(folder / name, image)
            assert np.array_equal(np.asarray(iio.imread(folder / name))[..., :3], image)
