"""The GLSL of KHR_materials_sheen and KHR_materials_iridescence (``pbrkit_khr.glsl``,
issue 25 step 5) against pbrkit's Python, in WebGL2 (headless Chromium, SwiftShader),
as tests/shaders/test_shaders.py checks the other files: every function of the file is
evaluated over a grid of float32 inputs (``tests/engines/pages/shaders.js``) and
compared with :mod:`pbrkit.microfacet.charlie`, :mod:`pbrkit.brdf.lobes.sheen` and
:func:`pbrkit.brdf.fresnel.f_iridescence` at the same inputs.

The page's one 2-D table (``u_lut``) is here the E_sheen table (pbrkit/data/
sheen_albedo.npy, its values in .r), and its cube (``u_cube``) a small random
pyramid standing for a Charlie-prefiltered environment.  Tolerances: the default
of tests/shaders/test_shaders.py, |gl - pbrkit| <= 1e-4 |pbrkit| (+ an absolute floor where
a value crosses or approaches 0), unless a case says why it needs more.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from engine_pages import needs_engines, run_page
from shader_cases import (CUBE_LEVELS, CUBE_SIZE, WIDTH, N, Case, assert_cases_match, f32, random_cosines,
                          random_units, sheen_bxdf, vec4s)

from pbrkit import shaders
from pbrkit.brdf import fresnel
from pbrkit.brdf.bxdf import Cosines
from pbrkit.brdf.lobes.sheen import SHEEN, SHEEN_TABLE_FILE, sheen_albedo_lookup, sheen_albedo_scaling
from pbrkit.microfacet import charlie

KHR_FILE = "pbrkit_khr.glsl"


def reference_sheen_ibl(prefiltered, sheen_albedo, sheen_color):
    """The split-sum sheen radiance of the glTF Sample Viewer's getIBLRadianceCharlie
    (sheen light times sheen colour times the LUT's white-lobe albedo), transcribed
    independently: pbrkit has no Python function for it."""
    return np.asarray(prefiltered) * np.asarray(sheen_color) * np.asarray(sheen_albedo)[:, None]


def reference_sheen_direction(n, v):
    """The direction the Sample Viewer samples its Charlie cube at: normalize(reflect(-v, n))."""
    d = -v + 2.0 * np.sum(n * v, axis=1, keepdims=True) * n
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def _sheen_roughness(rng):
    r = f32(rng.uniform(0.0, 1.0, N))
    r[:6] = (0.0, 1.0, 1e-3, 0.05, 0.5, 0.1)
    return r


def _sheen_cases(rng, table):
    cases = []
    add = cases.append
    r = _sheen_roughness(rng)
    add(Case("charlieAlpha", ("pbrkit_charlieAlpha",), "pbrkit_charlieAlpha(a.x)", [vec4s(r)],
             charlie.charlie_alpha(r)[:, None]))

    # D: sheen roughness >= 0.1 (alpha >= 0.01, exponent 1 / (2 alpha) <= 50) on most rows, where
    # pow's float32 relative error (~ exponent x 1e-7) stays well inside 1e-4; the delta limit
    # (r = 0: alpha = 1e-12) on a few, where D is 0 but at n.h = 0
    noh = random_cosines(rng, -0.2)
    r = f32(np.where(np.arange(N) < 8, 0.0, rng.uniform(0.1, 1.0, N)))
    noh[:8] = (0.0, 1.0, 0.5, -0.1, 0.0, 0.3, 1e-3, 0.999)
    alpha = f32(charlie.charlie_alpha(r))
    add(Case("D_Charlie", ("D_Charlie",), "D_Charlie(a.x, a.y)", [vec4s(noh, alpha)],
             charlie.d_charlie(noh, alpha)[:, None], atol=1e-30))

    nol, nov, r = random_cosines(rng), random_cosines(rng)[rng.permutation(N)], _sheen_roughness(rng)
    nol[8:16] = (0.5, 0.4999, 0.5001, 0.0, -0.5, 0.2, 1.0, 0.7)  # the fit's mirror at 0.5, the horizon
    alpha = f32(charlie.charlie_alpha(r))
    add(Case("Lambda_Charlie", ("pbrkit_lambdaSheenFit", "Lambda_Charlie", "G2_Charlie", "V_Charlie"),
             "vec4(Lambda_Charlie(a.x, a.z), G2_Charlie(a.x, a.y, a.z), V_Charlie(a.x, a.y, a.z), "
             "pbrkit_lambdaSheenFit(a.x, a.z))", [vec4s(nol, nov, alpha)],
             np.stack([charlie.lambda_charlie(nol, alpha), charlie.g2_charlie(nol, nov, alpha),
                       charlie.v_charlie(nol, nov, alpha), charlie._lambda_fit(nol, alpha)], axis=1),
             atol=1e-5))  # the fit L(x) crosses 0 between x = 0.5 and 1
    add(Case("V_Ashikhmin", ("V_Ashikhmin",), "V_Ashikhmin(a.x, a.y)", [vec4s(nol, nov)],
             charlie.v_ashikhmin(nol, nov)[:, None]))

    # the lobe, through pbrkit's own SHEEN lobe (value at weight 1)
    noh, nol, nov = random_cosines(rng), random_cosines(rng, -0.2)[rng.permutation(N)], random_cosines(rng, -0.2)[rng.permutation(N)]
    r = f32(np.where(np.arange(N) < 4, 0.0, rng.uniform(0.1, 1.0, N)))
    color = f32(rng.uniform(0.0, 1.0, (N, 3)))
    value = np.array([SHEEN.value(sheen_bxdf(color[i], r[i]),
                                  Cosines(nol[i], nov[i], noh[i], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
                                  (1.0, 1.0, 1.0), 1.0) for i in range(N)])
    add(Case("sheenBRDF", ("pbrkit_sheenBRDF",), "vec4(pbrkit_sheenBRDF(b.xyz, a.w, a.x, a.y, a.z), 0.0)",
             [vec4s(noh, nol, nov, r), vec4s(color)], value, atol=1e-30))

    # E_sheen: grid points (exact table values), the edges, and off the table (clamped)
    rows, cols = table.shape
    nov, r = f32(rng.uniform(-0.1, 1.1, N)), f32(rng.uniform(-0.1, 1.1, N))
    j, i = rng.integers(0, cols, 64), rng.integers(0, rows, 64)
    nov[:64], r[:64] = f32(j / (cols - 1)), f32(i / (rows - 1))
    nov[64:68], r[64:68] = (0.0, 1.0, 0.0, 1.0), (0.0, 0.0, 1.0, 1.0)
    looked_up = np.array([sheen_albedo_lookup(float(nov[k]), float(r[k])) for k in range(N)])
    add(Case("fetchSheenAlbedo", ("pbrkit_fetchSheenAlbedo",), "pbrkit_fetchSheenAlbedo(u_lut, a.x, a.y)",
             [vec4s(nov, r)], looked_up[:, None], rtol=1e-5, atol=1e-6))
    # the GPU's own bilinear filter: as sampleDFG in tests/shaders/test_shaders.py, weights of limited
    # precision (8 fractional bits is common): 1/256 of the largest step between neighbouring texels
    step = max(np.abs(np.diff(table, axis=0)).max(), np.abs(np.diff(table, axis=1)).max())
    add(Case("sampleSheenAlbedo", ("pbrkit_sampleSheenAlbedo",), "pbrkit_sampleSheenAlbedo(u_lut, a.x, a.y)",
             [vec4s(nov, r)], looked_up[:, None], rtol=0.0, atol=step / 256.0))
    color = f32(rng.uniform(0.0, 1.0, (N, 3)))
    color[:4] = np.array([0.0, 1.0, 0.5, 0.25])[:, None]
    scaling = np.array([sheen_albedo_scaling(float(color[k].max()), float(nov[k]), float(r[k])) for k in range(N)])
    add(Case("sheenAlbedoScaling", ("pbrkit_sheenAlbedoScaling",),
             "pbrkit_sheenAlbedoScaling(b.xyz, pbrkit_fetchSheenAlbedo(u_lut, a.x, a.y))",
             [vec4s(nov, r), vec4s(color)], scaling[:, None], atol=2e-6))  # 1 - cE crosses 0

    prefiltered = f32(rng.uniform(0.0, 4.0, (N, 3)))
    e = f32(table[rng.integers(0, rows, N), rng.integers(0, cols, N)])
    add(Case("sheenIBL", ("pbrkit_sheenIBL",), "vec4(pbrkit_sheenIBL(c.xyz, a.x, b.xyz), 0.0)",
             [vec4s(e), vec4s(color), vec4s(prefiltered)], reference_sheen_ibl(prefiltered, e, color),
             atol=1e-6))
    return cases


def _sheen_cube_case(rng):
    """pbrkit_sampleSheen: the cube sampled at reflect(-v, n), lod = sheenRoughness (M - 1), against
    pbrkit's trilinear cube sampler -- at level 0's texel centres (r = 0) and in the faces'
    interiors at random r, as sampleSpecular in tests/shaders/test_shaders.py (clear of the seams)."""
    from pbrkit.ibl.cubemap import cube_texel_directions, face_direction, sample_cube
    from pbrkit.ibl.prefilter import level_of_roughness

    pyramid = [f32(rng.uniform(0, 1, (6, CUBE_SIZE >> m, CUBE_SIZE >> m, 4))) for m in range(CUBE_LEVELS)]
    centres = cube_texel_directions(CUBE_SIZE).reshape(-1, 3)
    take = rng.choice(centres.shape[0], N // 2, replace=False)
    face = rng.integers(0, 6, N // 2)
    sc, tc = rng.uniform(-0.5, 0.5, N // 2), rng.uniform(-0.5, 0.5, N // 2)
    inner = np.array([face_direction(f, s, t) for f, s, t in zip(face, sc, tc)], dtype=float)
    target = np.concatenate([centres[take], inner / np.linalg.norm(inner, axis=1, keepdims=True)])
    n = random_units(rng)
    v = f32(2.0 * np.sum(n * target, axis=1, keepdims=True) * n - target)  # reflect(-v, n) = target
    dirs = reference_sheen_direction(n, v)
    rough = f32(np.concatenate([np.zeros(N // 2), rng.uniform(0, 1, N // 2)]))
    expected = sample_cube([p.astype(np.float64) for p in pyramid], dirs, level_of_roughness(rough, CUBE_LEVELS))
    level_step = max(np.abs(pyramid[m] - pyramid[m].mean()).max() for m in range(CUBE_LEVELS)) * 2.0
    return Case("sampleSheen", ("pbrkit_sampleSheen",),
                f"vec4(pbrkit_sampleSheen(u_cube, a.xyz, b.xyz, a.w, {CUBE_LEVELS}.0), 0.0)",
                [vec4s(n, rough), vec4s(v)], expected[:, :3], rtol=0.0, atol=level_step / 256.0,
                extra={"cube": {"size": CUBE_SIZE, "levels": [[f.reshape(-1).tolist() for f in level]
                                                             for level in pyramid]}})


#: GLSL ES 3.00 leaves the precision of cos open; Vulkan (SwiftShader's contract, and what GPUs meet)
#: asks 2^-11 absolute within [-pi, pi], and SwiftShader's is off by up to 1.9e-4 there (measured).  Each
#: of X, Y, Z carries one such error (times its lobes' amplitude, 1), the Rec.709 rows sum |M| up to 5.28:
#: the sensitivity's bound is 2^-11 x 5.28 = 2.6e-3 (measured: 5.4e-4).
SENSITIVITY_ATOL = 2.0 ** -11 * max(sum(abs(m) for m in row) for row in fresnel.XYZ_TO_REC709)
#: F_Iridescence adds 2 (C1 S1 + C2 S2): 2 (|C1| + |C2|) < 0.5 on this grid (0.497, computed once from
#: pbrkit.brdf.fresnel._film_channel), so half the sensitivity's bound (measured: 1.5e-4).
IRIDESCENCE_ATOL = 0.5 * SENSITIVITY_ATOL


def _iridescence_inputs(rng):
    """cos theta_1, film IOR, thickness (nm), base f0 (RGB) and outside IOR: air above on most
    rows, a clear coat (1.5) above on some (a film of lower index: phase flips, and total
    internal reflection into the film at grazing angles); no film (thickness 0) on a few."""
    cos = f32(rng.uniform(0.0, 1.0, N))
    cos[:6] = (1.0, 0.0, 0.5, 1e-4, 0.999, 0.2)
    film = f32(rng.uniform(1.0, 2.4, N))
    thickness = f32(rng.uniform(0.0, 1200.0, N))
    thickness[6:24] = 0.0
    thickness[24:40] = f32(rng.uniform(0.0, 5.0, 16))  # thin: the film barely colours
    f0 = f32(rng.uniform(0.0, 1.0, (N, 3)))
    f0[40:80] = 0.04
    outside = f32(np.where(rng.uniform(size=N) < 0.25, 1.5, 1.0))
    outside[:4] = 1.0
    # keep the film's IOR away from the base's (the phase of the second interface flips there)
    base = fresnel.ior_from_f0(f0.astype(np.float64) + 1e-4)
    near = np.any(np.abs(base - film[:, None]) < 1e-3, axis=1)
    film = f32(np.where(near, film + 0.01, film))
    # and away from the critical angle, where cos theta_2 is not a well-conditioned function of float32 inputs
    sin2 = (outside / film) ** 2 * (1.0 - cos * cos)
    cos = f32(np.where(np.abs(sin2 - 1.0) < 1e-2, 1.0, cos))
    return cos, film, thickness, f0, outside


def _iridescence_cases(rng):
    cases = []
    add = cases.append
    f0 = f32(rng.uniform(0.0, 0.9, (N, 3)))
    f0[:3] = (0.0, 0.04, 1.0)
    add(Case("iorFromF0", ("pbrkit_iorFromF0",), "vec4(pbrkit_iorFromF0(a.xyz), 0.0)", [vec4s(f0)],
             fresnel.ior_from_f0(f0)))

    # the sensitivity: OPD up to 2 x 2 x 2.4 x 1200 nm (the second fringe of the thickest film), phases
    # 0 or pi and twice those, as F_Iridescence passes them, and arbitrary ones.  Tolerance: the GPU's
    # cos (SENSITIVITY_ATOL), not float32 arithmetic (which alone stays within 1e-5)
    opd = f32(rng.uniform(0.0, 11520.0, N))
    opd[:4] = (0.0, 1.0, 500.0, 5000.0)
    shift = f32(np.where(rng.uniform(size=(N, 3)) < 0.5, rng.integers(0, 5, (N, 3)) * (np.pi / 2),
                          rng.uniform(0.0, 4.0 * np.pi, (N, 3))))
    shift[0] = 0.0
    add(Case("thinFilmSensitivity", ("pbrkit_thinFilmSensitivity",),
             "vec4(pbrkit_thinFilmSensitivity(a.x, b.xyz), 0.0)", [vec4s(opd), vec4s(shift)],
             np.stack(fresnel.thin_film_sensitivity(opd, shift[:, 0], shift[:, 1], shift[:, 2]), axis=1),
             atol=SENSITIVITY_ATOL))

    cos, film, thickness, f0, outside = _iridescence_inputs(rng)
    expected = np.stack(fresnel.f_iridescence(cos, film, thickness, f0[:, 0], f0[:, 1], f0[:, 2], outside), axis=1)
    add(Case("F_Iridescence", ("F_Iridescence",), "vec4(F_Iridescence(a.x, a.y, a.z, b.xyz, a.w), 0.0)",
             [vec4s(cos, film, thickness, outside), vec4s(f0)], expected, atol=IRIDESCENCE_ATOL))
    base_ior = f32(rng.uniform(1.0, 3.0, N))
    base_ior[:2] = (1.5, 1.0)
    film = f32(np.where(np.abs(base_ior - film) < 1e-3, film + 0.01, film))
    expected = np.stack(fresnel.f_iridescence_dielectric(cos, film, thickness, base_ior, outside), axis=1)
    add(Case("F_IridescenceDielectric", ("F_IridescenceDielectric",),
             "vec4(F_IridescenceDielectric(a.x, a.y, a.z, b.x, a.w), 0.0)",
             [vec4s(cos, film, thickness, outside), vec4s(base_ior)], expected, atol=IRIDESCENCE_ATOL))
    return cases


@pytest.fixture(scope="module")
def webgl_khr_results(tmp_path_factory):
    root = tmp_path_factory.mktemp("shaders_khr")
    shaders.write_shaders(root / "shaders")
    rng = np.random.default_rng(20251025)
    table = np.load(SHEEN_TABLE_FILE)
    cases = _sheen_cases(rng, table) + [_sheen_cube_case(rng)] + _iridescence_cases(rng)
    rg = np.stack([table, np.zeros_like(table)], axis=-1)  # the page uploads RG32F; E in .r
    spec = {"files": [f"shaders/{name}" for name in shaders.GLSL_FILES], "width": WIDTH,
            "lut": {"width": table.shape[1], "height": table.shape[0], "data": rg.reshape(-1).tolist()},
            "cases": [{"name": c.name, "expr": c.expr, "count": N,
                       "inputs": [x.reshape(-1).tolist() for x in c.inputs]} for c in cases]}
    for c in cases:
        spec.update(c.extra)
    (root / "cases.json").write_text(json.dumps(spec))
    report = run_page("shaders.html", data=root, timeout=120)
    return cases, report["result"]


def test_khr_functions_are_listed():
    """pbrkit_khr.glsl is one of the files written, after pbrkit_brdf.glsl (whose terms it calls)."""
    names = {f["name"]: f["file"] for f in shaders.functions()}
    assert KHR_FILE in shaders.GLSL_FILES
    assert shaders.GLSL_FILES.index(KHR_FILE) > shaders.GLSL_FILES.index("pbrkit_brdf.glsl")
    for name in ("D_Charlie", "V_Charlie", "V_Ashikhmin", "pbrkit_sheenBRDF", "pbrkit_fetchSheenAlbedo",
                 "pbrkit_sampleSheenAlbedo", "pbrkit_sheenAlbedoScaling", "pbrkit_sampleSheen", "pbrkit_sheenIBL",
                 "F_Iridescence", "F_IridescenceDielectric", "pbrkit_thinFilmSensitivity"):
        assert names[name] == KHR_FILE, name
    assert "sheen_albedo" in shaders.shader_manifest()["conventions"]


@needs_engines()
def test_every_khr_function_is_tested_in_webgl2(webgl_khr_results):
    cases, result = webgl_khr_results
    covered = {name for c in cases for name in c.covers}
    assert covered == {f["name"] for f in shaders.functions() if f["file"] == KHR_FILE}
    assert set(result["results"]) == {c.name for c in cases}


@needs_engines()
def test_khr_glsl_matches_pbrkit_in_webgl2(webgl_khr_results):
    cases, result = webgl_khr_results
    assert_cases_match(cases, result, 24)
