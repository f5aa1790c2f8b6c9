"""The GLSL of the extended glTF material (``pbrkit_khr_material.glsl``, issue 25 item 5):
KHR_materials_ior and KHR_materials_specular, KHR_materials_clearcoat, the whole BRDF
with KHR_materials_sheen, and the extensions' real-time IBL (pbrkit's and the Khronos
Sample Viewer's, with KHR_materials_transmission / _volume's transmitted light and the
viewer's thin-film mix: :mod:`pbrkit.render.transmission_ibl`), KHR_materials_dispersion (each
channel's IOR and lookup) and KHR_materials_anisotropy (its frame, D, V, specular lobe, BRDF
and bent-normal IBL direction), against pbrkit's Python in WebGL2
(headless Chromium, SwiftShader), as
tests/test_shaders.py and tests/test_shaders_khr.py check the other files: each function
over a grid of float32 inputs, compared with :mod:`pbrkit.brdf.shading.gltf` (its
extended ``setup``, ``_specular_mix_weight``, ``ibl_*``), :mod:`pbrkit.brdf.lobes.clearcoat`,
:func:`pbrkit.brdf.operators.fresnel_coat`, :func:`pbrkit.brdf.models.gltf` (the whole
material at random (l, v, n, material)), the real-time renderer's own IBL kernel
(``pbrkit.render.realtime._ibl_kernel``, the whole IBL of the material) and
:mod:`pbrkit.render.khronos_ibl`; the anisotropy's against :func:`pbrkit.brdf.bxdf.shading_frame`,
:func:`pbrkit.brdf.models.evaluate` with a tangent and :func:`pbrkit.render.ibl_lookups.khr_anisotropic_reflection`;
the dispersion's against :mod:`pbrkit.brdf.transmission` and
:func:`pbrkit.render.transmission_ibl.transmission_lookups`.

The page's 2-D table (``u_lut``) is the E_sheen table, as in tests/test_shaders_khr.py:
the BRDF and the IBL's scaling read E through ``pbrkit_fetchSheenAlbedo``.  Tolerances:
1e-4 relative (+ an absolute floor where a value crosses or approaches 0); the dispersion's
IORs, directions and roughness absolute (a few float32 ulps).
"""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest
from engine_pages import needs_engines, run_page
from test_shaders import WIDTH, N, Case, _alphas, _cosines, _f32, _unit, _vec4s, assert_cases_match
from test_shaders_khr import _sheen_bxdf

from pbrkit import shaders
from pbrkit.brdf import models
from pbrkit.brdf.bxdf import Cosines
from pbrkit.brdf.fresnel import f0_from_ior
from pbrkit.brdf.lobes import Lobe
from pbrkit.brdf.lobes.clearcoat import CLEARCOAT, clearcoat_weight
from pbrkit.brdf.lobes.sheen import SHEEN_TABLE_FILE
from pbrkit.brdf.material import Material
from pbrkit.brdf.operators import fresnel_coat
from pbrkit.brdf.shading import gltf
from pbrkit.brdf.shading.registry import COLUMNS
from pbrkit.core.jit import dual_use
from pbrkit.microfacet.roughness import alpha_from_roughness
from pbrkit.render import khronos_ibl

FILE = "pbrkit_khr_material.glsl"
#: The page's expression for a pbrkit_KHRMaterial from the inputs d, e, f, g: base d.xyz,
#: metallic d.w, roughness g.w, sheen colour e.xyz, sheen roughness e.w, clearcoat f.x, its
#: roughness f.y, specular f.z, specular colour g.xyz, ior f.w (a, b, c and h: the case's own).
MATERIAL = "pbrkit_KHRMaterial(d.xyz, d.w, g.w, e.xyz, e.w, f.x, f.y, f.z, g.xyz, f.w)"


def _materials(rng, mirror_rows=None):
    """N random extended materials (float32): some rows at the extensions' defaults, some
    without sheen or coat, ior 0 and 1 on a few, specular colours above 1 (F0 clamped at 1)."""
    m = SimpleNamespace()
    m.base = _f32(rng.uniform(0, 1, (N, 3)))
    m.metallic = _f32(np.where(rng.uniform(size=N) < 0.3, rng.integers(0, 2, N), rng.uniform(0, 1, N)))
    lo = np.full(N, 0.03) if mirror_rows is None else np.where(mirror_rows, 0.3, 0.03)
    m.roughness = _f32(rng.uniform(lo, 1.0))
    m.sheen_color = _f32(np.where(rng.uniform(size=(N, 1)) < 0.3, 0.0, rng.uniform(0, 1, (N, 3))))
    m.sheen_roughness = _f32(np.where(rng.uniform(size=N) < 0.1, 0.0, rng.uniform(0.1, 1.0, N)))
    m.clearcoat = _f32(np.where(rng.uniform(size=N) < 0.3, 0.0, rng.uniform(0, 1, N)))
    m.clearcoat_roughness = _f32(rng.uniform(lo, 1.0))
    m.specular = _f32(np.where(rng.uniform(size=N) < 0.2, 1.0, rng.uniform(0, 1, N)))
    m.specular_color = _f32(np.where(rng.uniform(size=(N, 1)) < 0.2, 1.0, rng.uniform(0, 3, (N, 3))))
    m.ior = _f32(np.where(rng.uniform(size=N) < 0.2, 1.5, rng.uniform(1.0, 3.0, N)))
    m.ior[2:6] = (0.0, 1.0, 0.0, 1.0)
    # the core material on the first rows (every extension at its default)
    m.sheen_color[6:12], m.clearcoat[6:12], m.specular[6:12], m.specular_color[6:12], m.ior[6:12] = 0, 0, 1, 1, 1.5
    return m


def _material_inputs(m):
    """Inputs d, e, f, g of MATERIAL."""
    return [_vec4s(m.base, m.metallic), _vec4s(m.sheen_color, m.sheen_roughness),
            _vec4s(m.clearcoat, m.clearcoat_roughness, m.specular, m.ior), _vec4s(m.specular_color, m.roughness)]


def _inputs(m, a=None, b=None, c=None, h=None):
    """The page's eight inputs: the case's a, b, c, h around the material's d, e, f, g."""
    none = _vec4s()
    return [none if x is None else x for x in (a, b, c)] + _material_inputs(m) + [none if h is None else h]


def _params(m):
    """pbrkit's packed parameter rows (registry COLUMNS) of the materials."""
    c = COLUMNS
    p = np.zeros((N, c.double_sided + 1))
    p[:, c.base_color:c.base_color + 3] = m.base
    p[:, c.metallic], p[:, c.roughness] = m.metallic, m.roughness
    p[:, c.sheen_color:c.sheen_color + 3], p[:, c.sheen_roughness] = m.sheen_color, m.sheen_roughness
    p[:, c.clearcoat], p[:, c.clearcoat_roughness] = m.clearcoat, m.clearcoat_roughness
    p[:, c.specular], p[:, c.specular_color:c.specular_color + 3] = m.specular, m.specular_color
    p[:, c.ior] = m.ior
    return p


def _bxdfs(m):
    """The BxDF of each material by the extended model's own setup."""
    p = _params(m)
    codes = np.zeros((1, 5), dtype=np.int64)
    return [gltf.setup(codes, 0, p, q, COLUMNS, float(m.roughness[q]), float(m.metallic[q]), *map(float, m.base[q]))
            for q in range(N)]


def _c(nol=0.0, nov=0.0, noh=0.0, voh=0.0):
    return Cosines(float(nol), float(nov), float(noh), float(voh), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@dual_use(inline=True)
def _base_value(b, c, ec, w):  # a stand-in lobe beneath the coat: its value is the base colour
    return b.base[0] * w, b.base[1] * w, b.base[2] * w


@dual_use(inline=True)
def _layer_value(b, c, ec, w):  # and above it: F0
    return b.f0[0] * w, b.f0[1] * w, b.f0[2] * w



def _setup_cases(rng, m, bx):
    cases = []
    add = cases.append
    dielectric = np.minimum(f0_from_ior(m.ior)[:, None] * m.specular_color, 1.0) * m.specular[:, None]
    assert np.allclose(dielectric.max(axis=1), [b.dielectric_f0 for b in bx], rtol=1e-12, atol=0)
    add(Case("dielectricF0", ("pbrkit_dielectricF0",), "vec4(pbrkit_dielectricF0(f.w, g.xyz, f.z), 0.0)",
             _inputs(m), dielectric, atol=1e-7))
    add(Case("f0f90", ("pbrkit_f0MetallicKHR", "pbrkit_f90MetallicKHR"),
             "vec4(pbrkit_f0MetallicKHR(d.xyz, d.w, pbrkit_dielectricF0(f.w, g.xyz, f.z)), "
             "pbrkit_f90MetallicKHR(f.z, d.w))", _inputs(m), np.array([[*b.f0, b.f90] for b in bx]), atol=1e-7))
    voh = _cosines(rng, 0.0)
    expected = np.array([gltf._specular_mix_weight(b, _c(voh=voh[q])) for q, b in enumerate(bx)])
    add(Case("specularMixWeight", ("pbrkit_specularMixWeight",),
             "pbrkit_specularMixWeight(a.x, pbrkit_dielectricF0(f.w, g.xyz, f.z), f.z)", _inputs(m, _vec4s(voh)),
             expected[:, None], atol=5e-7))  # 1 - F approaches 0 at grazing v.h: a few float32 ulps of 1

    # the coat lobe: as D_GGX and V_SmithGGX in tests/test_shaders.py, n.h close to 1 only at r >= 0.3
    noh, nol, nov = _cosines(rng), _cosines(rng, -0.2)[rng.permutation(N)], _cosines(rng, -0.2)[rng.permutation(N)]
    cr = _f32(np.where(noh > 0.999, rng.uniform(0.3, 1.0, N), rng.uniform(0.0, 1.0, N)))
    cr[:3] = (0.0, 1.0, 0.03)
    expected = []
    for q in range(N):
        extra = (0.0, 0.0, 0.0, 0.0, 1.0, float(alpha_from_roughness(cr[q])), 0.0, 0.0)
        b = _sheen_bxdf((0.0, 0.0, 0.0), 0.0)._replace(extra=extra)
        expected.append(CLEARCOAT.value(b, _c(nol[q], nov[q], noh[q]), (1.0, 1.0, 1.0), 1.0)[0])
    add(Case("clearcoatBRDF", ("pbrkit_clearcoatBRDF",), "pbrkit_clearcoatBRDF(a.x, a.y, a.z, a.w)",
             [_vec4s(noh, nol, nov, cr)], np.array(expected)[:, None], atol=1e-30))

    # the layering operator itself, with stand-in lobes: the base colour beneath, F0 above
    layered = fresnel_coat(gltf.GLTF_IOR, clearcoat_weight, Lobe("base", _base_value, None, None, None, None),
                           Lobe("layer", _layer_value, None, None, None, None))
    nov = _cosines(rng, 0.0)
    expected = np.array([layered.value(b, _c(nov=nov[q]), (1.0, 1.0, 1.0), 1.0) for q, b in enumerate(bx)])
    add(Case("fresnelCoat", ("pbrkit_clearcoatWeight", "pbrkit_fresnelCoat"),
             "vec4(pbrkit_fresnelCoat(d.xyz, pbrkit_f0MetallicKHR(d.xyz, d.w, pbrkit_dielectricF0(f.w, g.xyz, f.z)), "
             "pbrkit_clearcoatWeight(f.x, a.x)), 0.0)", _inputs(m, _vec4s(nov)), expected, atol=1e-7))
    return cases


def _brdf_case(rng):
    """The whole material: BRDF_glTFExtended against pbrkit.brdf.models.gltf with every extension,
    at tests/test_shaders.py's directions (half of them near the mirror direction)."""
    from test_shaders import _directions

    l, v, n = _directions(rng)
    mirror = np.arange(N) >= N // 2  # _directions' near-mirror rows: r >= 0.3 (as BRDF_glTF's case)
    m = _materials(rng, mirror)
    material = Material(base_color=m.base, metallic=m.metallic, roughness=m.roughness, sheen_color=m.sheen_color,
                        sheen_roughness=m.sheen_roughness, clearcoat=m.clearcoat,
                        clearcoat_roughness=m.clearcoat_roughness, specular=m.specular,
                        specular_color=m.specular_color, ior=m.ior)
    return Case("BRDF_glTFExtended", ("BRDF_glTFExtended",),
                f"vec4(BRDF_glTFExtended(a.xyz, b.xyz, c.xyz, {MATERIAL}, "
                "pbrkit_fetchSheenAlbedo(u_lut, dot(c.xyz, b.xyz), e.w)), 0.0)",
                _inputs(m, _vec4s(l), _vec4s(v), _vec4s(n)), models.gltf(l, v, n, material), rtol=1e-4, atol=1e-6)


def reference_albedo_f90(dfg, f0, f90):
    """The split sum with F90 of pbrkit.render.realtime's _ibl_kernel, albedo = DFG1 F90 + F0
    (DFG2 - DFG1), transcribed: the kernel's line has no Python function of its own."""
    return dfg[:, :1] * np.asarray(f90).reshape(-1, 1) + f0 * (dfg[:, 1:2] - dfg[:, :1])


def _ibl_cases(rng, m, bx, dfg_table):
    """pbrkit's real-time IBL of the material (engine "pbrkit").  Inputs: a = (n.v, DFG at (n.v, r),
    the coat's DFG2), b, c, h = (prefiltered, irradiance, the coat's prefiltered) RGB, the sheen's
    prefiltered RGB in (b.w, c.w, h.w); E_sheen from the table at (n.v, sheenRoughness)."""
    cases = []
    add = cases.append
    nov = _f32(np.maximum(_cosines(rng, 0.0), 1e-4))  # the renderer's floor
    j, i = rng.integers(0, dfg_table.shape[0], (2, N)), rng.integers(0, dfg_table.shape[1], (2, N))
    dfg, coat_dfg = _f32(dfg_table[j[0], i[0]]), _f32(dfg_table[j[1], i[1]])
    pref, irr = _f32(rng.uniform(0, 4, (N, 3))), _f32(rng.uniform(0, 4, (N, 3)))
    coat_pref, sheen_pref = _f32(rng.uniform(0, 4, (N, 3))), _f32(rng.uniform(0, 4, (N, 3)))
    inputs = _inputs(m, _vec4s(nov, dfg, coat_dfg[:, 1]), _vec4s(pref, sheen_pref[:, 0]),
                     _vec4s(irr, sheen_pref[:, 1]), _vec4s(coat_pref, sheen_pref[:, 2]))
    e_sheen = "pbrkit_fetchSheenAlbedo(u_lut, a.x, e.w)"
    sheen = "vec3(b.w, c.w, h.w)"

    f0, f90 = np.array([b.f0 for b in bx]), np.array([b.f90 for b in bx])
    add(Case("specularAlbedoDFGF90", ("pbrkit_specularAlbedoDFGF90",),
             "vec4(pbrkit_specularAlbedoDFGF90(a.yz, pbrkit_f0MetallicKHR(d.xyz, d.w, pbrkit_dielectricF0(f.w, g.xyz, "
             "f.z)), pbrkit_f90MetallicKHR(f.z, d.w)), 0.0)", inputs, reference_albedo_f90(dfg, f0, f90), atol=1e-7))
    dummy = np.zeros(4)
    weight = np.array([gltf.ibl_specular_diffuse_weight(b, float(nov[q]), False, dummy) for q, b in enumerate(bx)])
    add(Case("specularDiffuseWeightIBL", ("pbrkit_specularDiffuseWeightIBL",),
             "pbrkit_specularDiffuseWeightIBL(a.x, g.w, pbrkit_dielectricF0(f.w, g.xyz, f.z), f.z)", inputs,
             weight[:, None], atol=1e-7))
    add(Case("clearcoatRoughnessIBL", ("pbrkit_clearcoatRoughnessIBL",), "pbrkit_clearcoatRoughnessIBL(f.x, f.y)",
             inputs, np.array([gltf.ibl_coat_roughness(b) for b in bx])[:, None]))
    scale = np.array([gltf.ibl_extensions_base_scale(b, float(nov[q])) for q, b in enumerate(bx)])
    add(Case("extensionsIBLBaseScale", ("pbrkit_extensionsIBLBaseScale",),
             f"pbrkit_extensionsIBLBaseScale(a.x, f.x, e.xyz, {e_sheen})", inputs, scale[:, None],
             atol=2e-6))  # 1 - cE crosses 0 (as sheenAlbedoScaling in tests/test_shaders_khr.py)
    table = np.zeros((2, 2))
    extras = np.array([gltf.ibl_extensions_extras(b, float(nov[q]), float(coat_dfg[q, 0]), float(coat_dfg[q, 1]),
                                                  table, tuple(irr[q]), tuple(coat_pref[q]), tuple(sheen_pref[q]),
                                                  0.5, 0.9, (1.0, 1.0, 1.0))[0]  # no film: the base's DFG unused
                       for q, b in enumerate(bx)])
    add(Case("extensionsIBL", ("pbrkit_extensionsIBL",),
             f"vec4(pbrkit_extensionsIBL(a.x, f.x, a.w, h.xyz, e.xyz, {e_sheen}, {sheen}), 0.0)", inputs, extras,
             atol=1e-6))

    # the whole of it, as _ibl_kernel composes those functions for engine "pbrkit" (no energy compensation)
    diffuse_color = np.array([b.diffuse_color for b in bx])
    expected = (pref * reference_albedo_f90(dfg, f0, f90) + diffuse_color * (weight / np.pi)[:, None] * irr) \
        * scale[:, None] + extras
    add(Case("glTFExtendedIBL", ("pbrkit_glTFExtendedIBL",),
             f"vec4(pbrkit_glTFExtendedIBL(a.x, {MATERIAL}, a.yz, b.xyz, c.xyz, vec2(0.0, a.w), h.xyz, {e_sheen}, "
             f"{sheen}), 0.0)", inputs, expected, atol=1e-6))
    return cases


def _renderer_cases(rng, m, dfg_table):
    """pbrkit_glTFExtendedIBL and pbrkit_sampleViewerExtensionsIBL against the renderer itself:
    pbrkit.render.realtime's _ibl_kernel (engines "pbrkit", no energy compensation, and "khronos") on
    the materials packed as a scene's (material_tables), at random (n, v); the kernel's own n.v (floored
    at 1e-4), DFG lookups at (n.v, r) and at (n.v, the coat's roughness from its _reflection_kernel)
    are the GLSL's inputs, as _ibl_cases lays them out."""
    from pbrkit.albedo.tables import table_bilinear
    from pbrkit.brdf.bxdf import NO_TANGENT
    from pbrkit.render import realtime
    from pbrkit.render.material_spec import MaterialSpec
    from pbrkit.render.materials import material_tables

    specs = [SimpleNamespace(spec=MaterialSpec(
        name=f"m{q}", base_color=tuple(m.base[q]), metallic=float(m.metallic[q]), roughness=float(m.roughness[q]),
        sheen_color=tuple(m.sheen_color[q]), sheen_roughness=float(m.sheen_roughness[q]),
        clearcoat=float(m.clearcoat[q]), clearcoat_roughness=float(m.clearcoat_roughness[q]),
        specular=float(m.specular[q]), specular_color=tuple(m.specular_color[q]), ior=float(m.ior[q])))
        for q in range(N)]
    mi, mf = material_tables(specs)
    n, v = _unit(rng), _unit(rng)
    v = np.where(np.sum(n * v, axis=1, keepdims=True) < 0.0, -v, v)
    mat = np.arange(N)
    base = np.ascontiguousarray(m.base)
    refl, coat_r, sheen_r = np.empty((N, 3)), np.empty(N), np.empty(N)
    no_tangent = np.tile(NO_TANGENT, (N, 1))  # (isotropic materials: no frame needed)
    realtime._reflection_kernel(mi, mf, mat, n, v, m.roughness, m.metallic, base, no_tangent, refl, coat_r,
                                sheen_r)
    tables = np.ascontiguousarray(np.asarray(dfg_table, dtype=np.float64)[None, ..., :2])
    pref, irr = _f32(rng.uniform(0, 4, (N, 3))), _f32(rng.uniform(0, 4, (N, 3)))
    coat_pref, sheen_pref = _f32(rng.uniform(0, 4, (N, 3))), _f32(rng.uniform(0, 4, (N, 3)))
    out, ec = np.empty((N, 3)), np.empty((N, 3))
    realtime._ibl_kernel(mi, mf, mat, np.zeros(N, dtype=np.int64), tables, n, v, m.roughness, m.metallic, base,
                         np.ones(N), pref, irr, coat_pref, coat_r, sheen_pref, np.zeros(N), np.zeros((1, 3)),
                         np.zeros((1, 2)), False, realtime.sheen_albedo_table(), realtime.fresnel_mix_albedo_table(), False, False,
                         realtime.ENGINES.index("pbrkit"), out, ec)
    nov = np.maximum(np.sum(n * v, axis=1), 1e-4)
    dfg = np.array([[table_bilinear(tables, 0, nov[q], float(m.roughness[q]), k) for k in range(2)]
                    for q in range(N)])
    coat2 = np.array([table_bilinear(tables, 0, nov[q], coat_r[q], 1) if coat_r[q] >= 0.0 else 0.0
                      for q in range(N)])
    inputs = _inputs(m, _vec4s(nov, dfg, coat2), _vec4s(pref, sheen_pref[:, 0]), _vec4s(irr, sheen_pref[:, 1]),
                     _vec4s(coat_pref, sheen_pref[:, 2]))
    cases = [Case("glTFExtendedIBL_renderer", ("pbrkit_glTFExtendedIBL",),
                  f"vec4(pbrkit_glTFExtendedIBL(a.x, {MATERIAL}, a.yz, b.xyz, c.xyz, vec2(0.0, a.w), h.xyz, "
                  "pbrkit_fetchSheenAlbedo(u_lut, a.x, e.w), vec3(b.w, c.w, h.w)), 0.0)", inputs, out.copy(),
                  atol=1e-6)]

    # the same kernel as the Sample Viewer (engine "khronos"): Karis' (A, B) = (DFG2 - DFG1, DFG1), the
    # Charlie LUT's value per pixel; the core materials' rows take its core path (_engine_ibl)
    charlie = _f32(rng.uniform(0.0, 0.5, N))
    realtime._ibl_kernel(mi, mf, mat, np.zeros(N, dtype=np.int64), tables, n, v, m.roughness, m.metallic, base,
                         np.ones(N), pref, irr, coat_pref, coat_r, sheen_pref, charlie, np.zeros((1, 3)),
                         np.zeros((1, 2)), False, realtime.sheen_albedo_table(), realtime.fresnel_mix_albedo_table(), False, False,
                         realtime.ENGINES.index("khronos"), out, ec)
    inputs = _inputs(m, _vec4s(nov, dfg[:, 1] - dfg[:, 0], dfg[:, 0], charlie), *inputs[1:3], inputs[7])
    cases.append(Case("sampleViewerExtensionsIBL_renderer", ("pbrkit_sampleViewerExtensionsIBL",),
                      f"vec4(pbrkit_sampleViewerExtensionsIBL(a.x, {MATERIAL}, a.yz, b.xyz, c.xyz, h.xyz, "
                      "vec3(b.w, c.w, h.w), a.w, pbrkit_fetchSheenAlbedo(u_lut, a.x, e.w)), 0.0)", inputs, out.copy(),
                      atol=1e-6))
    return cases


def _sample_viewer_cases(rng, m):
    """The Sample Viewer's IBL (pbrkit.render.khronos_ibl).  Inputs: a = (n.v, Karis' (A, B), the Charlie
    LUT's value), b, c, h = (radiance, irradiance, the coat's radiance) RGB, the sheen's radiance RGB in
    (b.w, c.w, h.w)."""
    cases = []
    add = cases.append
    nov = _f32(np.maximum(_cosines(rng, 0.0), 1e-4))
    ab = _f32(rng.uniform(0.0, 0.5, (N, 2)))  # A + B <= 1: E_ms >= 0
    charlie = _f32(rng.uniform(0.0, 0.5, N))
    rad, irr = _f32(rng.uniform(0, 4, (N, 3))), _f32(rng.uniform(0, 4, (N, 3)))
    coat_rad, sheen_rad = _f32(rng.uniform(0, 4, (N, 3))), _f32(rng.uniform(0, 4, (N, 3)))
    inputs = _inputs(m, _vec4s(nov, ab, charlie), _vec4s(rad, sheen_rad[:, 0]), _vec4s(irr, sheen_rad[:, 1]),
                     _vec4s(coat_rad, sheen_rad[:, 2]))
    a, b = ab[:, 0], ab[:, 1]
    f0 = np.minimum(f0_from_ior(m.ior)[:, None] * m.specular_color, 1.0)
    rows = [(float(nov[q]), float(m.roughness[q]), float(a[q]), float(b[q])) for q in range(N)]  # scalar helpers
    fresnel = np.array([[khronos_ibl.sample_viewer_fresnel(x, r, float(f0[q, k]), float(m.specular[q]), aq, bq)
                         for k in range(3)] for q, (x, r, aq, bq) in enumerate(rows)])
    viewer_f0 = "min(pbrkit_f0FromIOR(f.w) * g.xyz, vec3(1.0))"
    add(Case("sampleViewerFresnel", ("pbrkit_sampleViewerFresnel",),
             f"vec4(pbrkit_sampleViewerFresnel(a.x, g.w, {viewer_f0}, f.z, a.yz), 0.0)", inputs, fresnel, atol=1e-7))
    base = np.array([[khronos_ibl.sample_viewer_base(x, r, float(m.base[q, k]), float(m.metallic[q]), float(f0[q, k]),
                                                     float(m.specular[q]), aq, bq, float(rad[q, k]), float(irr[q, k]))
                      for k in range(3)] for q, (x, r, aq, bq) in enumerate(rows)])
    add(Case("sampleViewerBase", ("pbrkit_sampleViewerBase",),
             f"vec4(pbrkit_sampleViewerBase(a.x, g.w, d.xyz, d.w, {viewer_f0}, f.z, a.yz, b.xyz, c.xyz), 0.0)",
             inputs, base, atol=1e-6))
    params = _params(m)
    expected = np.array([[khronos_ibl.sample_viewer_extensions_ibl(
        params, q, float(m.base[q, k]), float(m.metallic[q]), float(m.roughness[q]), float(nov[q]), float(a[q]),
        float(b[q]), float(rad[q, k]), float(irr[q, k]), float(coat_rad[q, k]), float(sheen_rad[q, k]),
        float(charlie[q]), k, *(float(x) for x in m.base[q]), 0.0, float(nov[q])) for k in range(3)]
        for q in range(N)])
    add(Case("sampleViewerExtensionsIBL", ("pbrkit_sampleViewerExtensionsIBL",),
             f"vec4(pbrkit_sampleViewerExtensionsIBL(a.x, {MATERIAL}, a.yz, b.xyz, c.xyz, h.xyz, vec3(b.w, c.w, h.w), "
             "a.w, pbrkit_fetchSheenAlbedo(u_lut, a.x, e.w)), 0.0)", inputs, expected, atol=1e-6))
    return cases


def _transmission_cases(rng):
    """Real-time KHR_materials_transmission / _volume and the Sample Viewer's thin-film mix,
    each against its Python counterpart at random inputs."""
    from pbrkit.brdf.transmission import absorption
    from pbrkit.render.transmission_ibl import ior_roughness, transmission_direction

    cases = []
    r, ior = _f32(rng.uniform(0, 1, N)), _f32(rng.uniform(1.0, 3.0, N))
    ior[:8] = 1.0
    cases.append(Case("iorRoughness", ("pbrkit_iorRoughness",), "vec4(pbrkit_iorRoughness(a.x, a.y), 0.0, 0.0, 0.0)",
                      [_vec4s(r, ior)], ior_roughness(r.astype(float), ior.astype(float))[:, None], atol=1e-7))
    n = _f32(_unit(rng))
    v = _unit(rng)
    v = _f32(np.where(np.sum(n * v, axis=1, keepdims=True) < 0.0, -v, v))
    thickness = _f32(np.where(rng.uniform(size=N) < 0.3, 0.0, rng.uniform(0.01, 2.0, N)))
    direction = transmission_direction(n.astype(float), v.astype(float), ior.astype(float), thickness)
    cases.append(Case("transmissionDirection", ("pbrkit_transmissionDirection",),
                      "vec4(pbrkit_transmissionDirection(a.xyz, b.xyz, c.x, c.y), 0.0)",
                      [_vec4s(n), _vec4s(v), _vec4s(ior, thickness)], direction, atol=1e-5))
    colour = _f32(rng.uniform(0.05, 1.0, (N, 3)))
    colour[:4] = 1.0
    distance = _f32(np.where(rng.uniform(size=N) < 0.2, 0.0, rng.uniform(0.1, 3.0, N)))
    params = np.zeros((N, COLUMNS.double_sided + 1))
    params[:, COLUMNS.attenuation_color:COLUMNS.attenuation_color + 3] = colour
    params[:, COLUMNS.attenuation_distance] = distance
    attenuation = np.array([absorption(params, q, float(thickness[q])) for q in range(N)])
    cases.append(Case("volumeAttenuation", ("pbrkit_volumeAttenuation",),
                      "vec4(pbrkit_volumeAttenuation(a.x, b.xyz, a.y), 0.0)", [_vec4s(thickness, distance),
                                                                                _vec4s(colour)],
                      attenuation, atol=1e-7))
    base, metallic = _f32(rng.uniform(0, 1, (N, 3))), _f32(rng.uniform(0, 1, N))
    transmission, weight = _f32(rng.uniform(0, 1, N)), _f32(rng.uniform(0, 1, N))
    light = _f32(rng.uniform(0, 4, (N, 3)))
    p = np.zeros((N, COLUMNS.double_sided + 1))
    p[:, COLUMNS.transmission] = transmission
    p[:, COLUMNS.specular] = 1.0
    p[:, COLUMNS.ior] = 1.5
    codes = np.zeros((1, 5), dtype=np.int64)
    tw = np.array([gltf.ibl_transmission(gltf.setup(codes, 0, p, q, COLUMNS, 0.5, float(metallic[q]),
                                                    *map(float, base[q]))) for q in range(N)])
    cases.append(Case("transmissionIBL", ("pbrkit_transmissionIBL",),
                      "vec4(pbrkit_transmissionIBL(a.xyz, a.w, b.x, b.y, c.xyz), 0.0)",
                      [_vec4s(base, metallic), _vec4s(transmission, weight), _vec4s(light)],
                      tw[:, None] * base * weight[:, None] * light, atol=1e-7))
    diffuse, f0 = _f32(rng.uniform(0, 2, (N, 3))), _f32(rng.uniform(0, 1, (N, 3)))
    ab = _f32(np.stack([rng.uniform(0, 0.9, N), rng.uniform(0, 0.1, N)], axis=1))
    expected = np.array([[khronos_ibl.sample_viewer_transmission(float(diffuse[q, k]), float(transmission[q]),
                                                                 float(f0[q, k]), float(ab[q, 0]), float(ab[q, 1]),
                                                                 float(light[q, k]), float(base[q, k]))
                          for k in range(3)] for q in range(N)])
    cases.append(Case("sampleViewerTransmission", ("pbrkit_sampleViewerTransmission",),
                      "vec4(pbrkit_sampleViewerTransmission(a.xyz, a.w, b.xyz, c.xy, h.xyz, d.xyz), 0.0)",
                      [_vec4s(diffuse, transmission), _vec4s(f0), _vec4s(ab), _vec4s(base), _vec4s(), _vec4s(),
                       _vec4s(), _vec4s(light)], expected, atol=1e-6))
    nov, k = _f32(rng.uniform(0.05, 1.0, N)), _f32(rng.uniform(0, 1, N))
    film_d, film_m = _f32(rng.uniform(0, 1, (N, 3))), _f32(rng.uniform(0, 1, (N, 3)))
    radiance = _f32(rng.uniform(0, 4, (N, 3)))
    expected = np.array([[khronos_ibl.sample_viewer_film(
        float(nov[q]), float(r[q]), float(diffuse[q, c]), float(base[q, c]), float(metallic[q]), float(f0[q, c]),
        float(weight[q]), float(ab[q, 0]), float(ab[q, 1]), float(radiance[q, c]), float(k[q]), float(film_d[q, c]),
        float(film_d[q].max()), float(film_m[q, c])) for c in range(3)] for q in range(N)])
    cases.append(Case("sampleViewerFilm", ("pbrkit_sampleViewerFilm",),
                      "vec4(pbrkit_sampleViewerFilm(a.x, a.y, b.xyz, c.xyz, a.z, d.xyz, a.w, e.xy, f.xyz, b.w, g.xyz, "
                      "h.xyz), 0.0)",
                      [_vec4s(nov, r, metallic, weight), _vec4s(diffuse, k), _vec4s(base), _vec4s(f0), _vec4s(ab),
                       _vec4s(radiance), _vec4s(film_d), _vec4s(film_m)], expected, atol=1e-6))
    return cases


def _dispersion_cases(rng):
    """KHR_materials_dispersion: each channel's IOR against pbrkit.brdf.transmission.dispersion_iors and
    sample_viewer_dispersion_iors (ior in [1, 2.5] with 1 and KHR_materials_ior's 0 on a few rows, dispersion
    in [0, 3] with 0, and on a few rows far above 3, where Cauchy's red IOR is clamped at 1), and each
    channel's lookup (direction and roughness) against the renderer's own
    pbrkit.render.transmission_ibl.transmission_lookups, whose sampler records what it is asked for."""
    from pbrkit.brdf.transmission import dispersion_iors, sample_viewer_dispersion_iors
    from pbrkit.render.geometry import Surface
    from pbrkit.render.material_spec import MaterialSpec
    from pbrkit.render.materials import material_tables
    from pbrkit.render.transmission_ibl import transmission_lookups

    cases = []
    ior = _f32(rng.uniform(1.0, 2.5, N))
    dispersion = _f32(np.where(rng.uniform(size=N) < 0.2, 0.0, rng.uniform(0.0, 3.0, N)))
    ior[:6], dispersion[:6] = (1.0, 1.0, 1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 3.0, 0.0, 0.5, 3.0)
    dispersion[6:12] = _f32(rng.uniform(67.0, 150.0, 6))  # red below 1 unclamped (20 / 0.30106 = 66.4)
    ior[12:16], dispersion[12:16] = 2.5, (0.0, 1.0, 3.0, 0.1)
    iors = dispersion_iors(ior, dispersion)
    assert np.all(iors[6:12, 0] == 1.0) and np.all(iors[12:, 0] > 1.0)
    inputs = [_vec4s(ior, dispersion)]
    # (rtol: float32's 523655 / lambda^2 - 1.5168 cancels to -1.6e-4 at the d line, its error of ~1e-7 magnified
    # by (ior - 1) dispersion / 20, up to 11 on the rows far above 3)
    cases.append(Case("dispersionIors", ("pbrkit_dispersionIors",), "vec4(pbrkit_dispersionIors(a.x, a.y), 0.0)",
                      inputs, iors, rtol=1e-6, atol=1e-6))
    cases.append(Case("sampleViewerDispersionIors", ("pbrkit_sampleViewerDispersionIors",),
                      "vec4(pbrkit_sampleViewerDispersionIors(a.x, a.y), 0.0)", inputs,
                      sample_viewer_dispersion_iors(ior, dispersion), rtol=0.0, atol=1e-6))

    # the lookups: thin walls (thickness 0) on some rows, v above n, a channel per row
    n = _unit(rng)
    v = _unit(rng)
    v = _f32(np.where(np.sum(n * v, axis=1, keepdims=True) < 0.0, -v, v))
    thickness = _f32(np.where(rng.uniform(size=N) < 0.3, 0.0, rng.uniform(0.01, 2.0, N)))
    r = _f32(rng.uniform(0.0, 1.0, N))
    r[16:20] = (0.0, 1.0, 0.0, 1.0)
    channel = np.arange(N) % 3
    specs = [SimpleNamespace(spec=MaterialSpec(name=f"m{q}", transmission=1.0, thickness=float(thickness[q]),
                                   ior=float(ior[q]), dispersion=float(dispersion[q]))) for q in range(N)]
    codes, params = material_tables(specs)
    surface = Surface(_f32(rng.normal(size=(N, 3))), n, n, np.arange(N), np.ones((N, 3)), np.zeros(N), r,
                      np.ones(N), np.zeros((N, 3)))
    for engine, name, glsl_iors in (("pbrkit", "dispersionLookup", "pbrkit_dispersionIors"),
                                    ("khronos", "dispersionLookup_khronos", "pbrkit_sampleViewerDispersionIors")):
        asked = []

        def sampler(directions, lod):  # what each lookup asks for: the plain one, then channels 0, 1, 2
            asked.append((directions.copy(), lod.copy()))
            return np.zeros((len(lod), 3))

        transmission_lookups(codes, params, surface, v, (0.0, 0.0, 5.0), sampler, lambda d: d, 2, engine)
        assert len(asked) == 4  # (levels 2: lod = the lookup's roughness)
        rows = np.arange(N)
        direction = np.stack([asked[1 + c][0] for c in range(3)])[channel, rows]
        roughness = np.stack([asked[1 + c][1] for c in range(3)])[channel, rows]
        expr = f"pbrkit_dispersionLookup(a.xyz, b.xyz, a.w, {glsl_iors}(c.x, c.y), c.z, int(c.w))"
        inputs = [_vec4s(n, r), _vec4s(v), _vec4s(ior, dispersion, thickness, channel)]
        covers = ("pbrkit_dispersionLookup", glsl_iors)
        if engine == "pbrkit":  # the Sample Viewer's direction is the camera's ray to the exit point: not this one
            cases.append(Case(name, covers, f"vec4({expr}.xyz, 0.0)", inputs, direction, rtol=0.0, atol=2e-6))
        cases.append(Case(name + "_roughness", covers, f"vec4({expr}.w, 0.0, 0.0, 0.0)", inputs, roughness[:, None],
                          rtol=0.0, atol=1e-6))
    return cases


def _tangents(rng, n):
    """Random glTF TANGENTs (N, 4) at the unit normals n: neither unit nor orthogonal to n (their part across
    n at least a fifth of their length), handedness w = -1 or +1 (and a few 0 and -0.5: the sign counts)."""
    t = rng.normal(size=(N, 3)) * rng.uniform(0.5, 2.0, (N, 1))
    for _ in range(100):
        across = t - np.sum(t * n, axis=1, keepdims=True) * n
        bad = np.linalg.norm(across, axis=1) < 0.2 * np.linalg.norm(t, axis=1)
        if not bad.any():
            break
        t[bad] = rng.normal(size=(int(bad.sum()), 3))
    w = np.where(rng.uniform(size=N) < 0.5, -1.0, 1.0)
    w[4:8] = (0.0, -0.5, 0.0, -0.5)
    return _f32(np.concatenate([t, w[:, None]], axis=1))


def _rotations(rng):
    """anisotropyRotation in [-4, 4] radians (float32), with 0 and the quarter turns on a few rows."""
    rotation = rng.uniform(-4.0, 4.0, N)
    rotation[:16] = (0.0, 0.0, 0.0, 0.0, np.pi / 2, -np.pi / 2, np.pi, -np.pi, 0.0, np.pi / 2, np.pi, 3.0,
                     2 * np.pi, -2 * np.pi, 1.0, -1.0)
    return _f32(rotation)


def _direction(rotation):
    """The GLSL's direction (cos, sin) of each rotation, computed on the CPU (the README's u_AnisotropyRotation)."""
    return np.stack([np.cos(rotation), np.sin(rotation)], axis=1)


def _frames(n, tangent, rotation):
    """pbrkit's anisotropy frame (t, b) of each row (pbrkit.brdf.bxdf.shading_frame)."""
    from pbrkit.brdf.bxdf import shading_frame

    frames = [shading_frame.py_func(*n[q], SimpleNamespace(anisotropic=True, rotation=float(rotation[q])),
                                    tuple(tangent[q])) for q in range(N)]
    return np.array([f[0] for f in frames]), np.array([f[1] for f in frames])


def _anisotropy_material(base, metallic, roughness, strength, rotation, tangent, **extensions):
    """The Material of the rows, its rotation turned for handedness w < 0: pbrkit.brdf.models.evaluate takes
    tangents of handedness +1, and the frame of (T, w = -1) turned by theta is the frame of (T, +1) turned by
    -theta (cos theta T + sin theta (-(n x T)), with anisotropicB = n x anisotropicT either way)."""
    turned = np.where(tangent[:, 3] < 0.0, -rotation, rotation)
    # the same angle in the declared [-pi, pi] (float32 pi lies just above it)
    turned = np.clip(np.remainder(turned + np.pi, 2.0 * np.pi) - np.pi, -np.pi, np.pi)
    return Material(base_color=base, metallic=metallic, roughness=roughness, anisotropy_strength=strength,
                    anisotropy_rotation=turned, **extensions)


def _anisotropy_cases(rng):
    """KHR_materials_anisotropy: the frame against pbrkit.brdf.bxdf.shading_frame (tangents not unit, not
    orthogonal to n, of either handedness, turned), alpha_t against the model's setup, D and V against
    pbrkit's anisotropic GGX and the model's V (pbrkit.brdf.shading.gltf._v_khr), the specular lobe and the
    whole BRDF against pbrkit.brdf.models.evaluate("gltf", ..., t=tangent) (checked first against the
    README's transcription in tests/reference_brdf.py), and the bent-normal lookup direction against
    pbrkit.render.ibl_lookups.khr_anisotropic_reflection."""
    import reference_brdf as ref
    from test_shaders import _directions

    from pbrkit.brdf import distributions
    from pbrkit.brdf.bxdf import Cosines as FrameCosines
    from pbrkit.brdf.shading.gltf import _v_khr
    from pbrkit.render.realtime import khr_anisotropic_reflection

    cases = []
    add = cases.append
    n = _unit(rng)
    tangent, rotation = _tangents(rng, n), _rotations(rng)
    t, b = _frames(n, tangent, rotation)
    inputs = [_vec4s(n), tangent, _vec4s(_direction(rotation))]
    add(Case("anisotropicFrame_t", ("pbrkit_anisotropicFrame",), "pbrkit_anisotropicFrame(a.xyz, b, c.xy)[0]",
             inputs, t, rtol=0.0, atol=1e-6))
    add(Case("anisotropicFrame_b", ("pbrkit_anisotropicFrame",), "pbrkit_anisotropicFrame(a.xyz, b, c.xy)[1]",
             inputs, b, rtol=0.0, atol=1e-6))

    r, strength = _f32(rng.uniform(0.0, 1.0, N)), _f32(rng.uniform(0.0, 1.0, N))
    r[:4], strength[:6] = (0.0, 1.0, 0.0, 0.5), (0.0, 1.0, 1.0, 0.0, 1.0, 0.0)
    params = np.zeros((N, COLUMNS.double_sided + 1))
    params[:, COLUMNS.anisotropy_strength] = strength
    codes = np.zeros((1, 5), dtype=np.int64)
    alpha_t = np.array([gltf.setup(codes, 0, params, q, COLUMNS, float(r[q]), 0.0, 0.0, 0.0, 0.0).alpha_x
                        for q in range(N)])
    add(Case("anisotropicAlphaT", ("pbrkit_anisotropicAlphaT",),
             "pbrkit_anisotropicAlphaT(pbrkit_alphaFromRoughness(a.x), a.y)", [_vec4s(r, strength)],
             alpha_t[:, None], atol=1e-7))

    # D and V at directions in the frame: n.x from tests/test_shaders.py's cosines (many near 1 and 0), the
    # azimuth uniform; alpha_b from 1e-3 to 1, alpha_t = mix(alpha_b, 1, s^2)
    def local(lo):
        c = _cosines(rng, lo)[rng.permutation(N)]
        phi = rng.uniform(0.0, 2.0 * np.pi, N)
        s = np.sqrt(np.maximum(1.0 - c * c, 0.0))
        return c, _f32(s * np.cos(phi)), _f32(s * np.sin(phi))

    alpha_b = _alphas(rng)
    alpha_t = _f32(alpha_b + (1.0 - alpha_b) * rng.uniform(0.0, 1.0, N) ** 2)
    noh, toh, boh = local(-0.2)
    add(Case("dGGXAnisotropic", ("pbrkit_dGGXAnisotropic",), "pbrkit_dGGXAnisotropic(a.x, a.y, a.z, b.x, b.y)",
             [_vec4s(noh, toh, boh), _vec4s(alpha_t, alpha_b)],
             distributions.d_ggx_anisotropic(noh, toh, boh, alpha_t, alpha_b)[:, None]))
    (nol, tol, bol), (nov, tov, bov) = local(-0.2), local(-0.2)
    bxdf = gltf.setup(codes, 0, params, 1, COLUMNS, 0.5, 0.0, 0.0, 0.0, 0.0)  # an anisotropic BxDF (strength 1)
    assert bxdf.anisotropic
    expected = np.array([_v_khr.py_func(bxdf._replace(alpha_x=float(alpha_t[q]), alpha_y=float(alpha_b[q])),
                                        FrameCosines(*map(float, (nol[q], nov[q], 0.0, 0.0, tol[q], bol[q], tov[q],
                                                                  bov[q], 0.0, 0.0)))) for q in range(N)])
    add(Case("vGGXAnisotropic", ("pbrkit_vGGXAnisotropic",), "pbrkit_vGGXAnisotropic(a.x, a.y, a.z, b.x, b.y, b.z, "
             "c.x, c.y)", [_vec4s(nol, tol, bol), _vec4s(nov, tov, bov), _vec4s(alpha_t, alpha_b)],
             expected[:, None], atol=1e-30))

    # the specular lobe and the whole material at tests/test_shaders.py's directions (the near-mirror half at
    # r >= 0.3, as BRDF_glTF's case)
    l, v, n = _directions(rng)
    mirror = np.arange(N) >= N // 2
    tangent, rotation = _tangents(rng, n), _rotations(rng)
    rough = _f32(rng.uniform(np.where(mirror, 0.3, 0.03), 1.0))
    strength = _f32(np.where(rng.uniform(size=N) < 0.2, 1.0, rng.uniform(0.01, 1.0, N)))
    # the lobe: metals (f0 = base colour, f90 1) and, on odd rows, black dielectrics with KHR_materials_specular
    # (f0 = min(f0(ior) specularColor, 1) specular, f90 = specular): no diffuse either way
    odd = np.arange(N) % 2 == 1
    f0 = _f32(rng.uniform(0, 1, (N, 3)))
    specular, specular_color = _f32(rng.uniform(0, 1, N)), _f32(rng.uniform(0, 2, (N, 3)))
    ior = _f32(rng.uniform(1.0, 3.0, N))
    dielectric_f0 = _f32(np.minimum(f0_from_ior(ior)[:, None] * specular_color, 1.0) * specular[:, None])
    f0 = np.where(odd[:, None], dielectric_f0, f0)
    f90 = np.where(odd, specular, 1.0)
    material = _anisotropy_material(np.where(odd[:, None], 0.0, f0), np.where(odd, 0.0, 1.0), rough, strength,
                                    rotation, tangent, specular=np.where(odd, specular, 1.0),
                                    specular_color=np.where(odd[:, None], specular_color, 1.0),
                                    ior=np.where(odd, ior, 1.5))
    expected = models.evaluate("gltf", l, v, n, material, t=tangent[:, :3])
    # (1e-6: float32 unit vectors are unit to ~1e-7, where the README's form of V and pbrkit's differ)
    metal = ~odd
    with np.errstate(invalid="ignore"):  # its h at l = -v (row 1)
        readme = ref.gltf_anisotropy_brdf(l[metal], v[metal], n[metal], tangent[metal, :3],
                                          np.where(tangent[metal, 3] < 0.0, -1.0, 1.0), f0[metal], 1.0, rough[metal],
                                          strength[metal], rotation[metal])
    assert np.allclose(expected[metal], readme, rtol=1e-6, atol=1e-9)
    add(Case("anisotropicSpecular", ("pbrkit_anisotropicSpecular",),
             "pbrkit_anisotropicSpecular(a.xyz, b.xyz, pbrkit_anisotropicFrame(c.xyz, d, f.xy), e.xyz, e.w, b.w, c.w)",
             [_vec4s(l), _vec4s(v, rough), _vec4s(n, strength), tangent, _vec4s(f0, f90), _vec4s(_direction(rotation))],
             expected,
             rtol=1e-4, atol=1e-6))

    base = _f32(rng.uniform(0, 1, (N, 3)))
    metallic = _f32(np.where(rng.uniform(size=N) < 0.3, rng.integers(0, 2, N), rng.uniform(0, 1, N)))
    strength = _f32(np.where(rng.uniform(size=N) < 0.15, 0.0, strength))  # 0: the core model (BRDF_glTF)
    material = _anisotropy_material(base, metallic, rough, strength, rotation, tangent)
    expected = models.evaluate("gltf", l, v, n, material, t=tangent[:, :3])
    on = strength > 0.0
    with np.errstate(invalid="ignore"):
        readme = ref.gltf_anisotropy_brdf(l[on], v[on], n[on], tangent[on, :3],
                                          np.where(tangent[on, 3] < 0.0, -1.0, 1.0), base[on], metallic[on], rough[on],
                                          strength[on], rotation[on])
    assert np.allclose(expected[on], readme, rtol=1e-6, atol=1e-9)
    add(Case("BRDF_glTFAnisotropic", ("BRDF_glTFAnisotropic",),
             "BRDF_glTFAnisotropic(a.xyz, b.xyz, c.xyz, d, e.xyz, e.w, b.w, c.w, f.xy)",
             [_vec4s(l), _vec4s(v, rough), _vec4s(n, strength), tangent, _vec4s(base, metallic),
              _vec4s(_direction(rotation))],
             expected, rtol=1e-4, atol=1e-6))

    # the lookup direction: v above n, anisotropicB of a turned frame, strength and r in [0, 1] with their ends
    n = _unit(rng)
    v = _unit(rng)
    v = _f32(np.where(np.sum(n * v, axis=1, keepdims=True) < 0.0, -v, v))
    tangent, rotation = _tangents(rng, n), _rotations(rng)
    _, b = _frames(n, tangent, rotation)
    b = _f32(b)
    strength, r = _f32(rng.uniform(0.0, 1.0, N)), _f32(rng.uniform(0.0, 1.0, N))
    strength[:8], r[:8] = (0.0, 1.0, 1.0, 0.0, 1.0, 0.5, 1.0, 0.0), (0.0, 0.0, 1.0, 1.0, 0.5, 0.0, 0.0, 0.5)
    expected = np.array([khr_anisotropic_reflection(*n[q], *v[q], tuple(b[q]), float(strength[q]),
                                                    float(r[q])) for q in range(N)])
    add(Case("anisotropicReflection", ("pbrkit_anisotropicReflection",),
             "pbrkit_anisotropicReflection(a.xyz, b.xyz, c.xyz, a.w, b.w)",
             [_vec4s(n, strength), _vec4s(v, r), _vec4s(b)], expected, rtol=0.0, atol=2e-6))
    return cases


@pytest.fixture(scope="module")
def webgl_material_results(tmp_path_factory):
    from pbrkit.albedo.tables import lookup_table

    root = tmp_path_factory.mktemp("shaders_khr_material")
    shaders.write_shaders(root / "shaders")
    rng = np.random.default_rng(20251127)
    table = np.load(SHEEN_TABLE_FILE)
    dfg, _ = lookup_table("dfg", 16)
    m = _materials(rng)
    bx = _bxdfs(m)
    cases = (_setup_cases(rng, m, bx) + [_brdf_case(rng)] + _ibl_cases(rng, m, bx, dfg) + _renderer_cases(rng, m, dfg)
             + _sample_viewer_cases(rng, m) + _transmission_cases(rng) + _anisotropy_cases(rng)
             + _dispersion_cases(rng))
    rg = np.stack([table, np.zeros_like(table)], axis=-1)  # the page uploads RG32F; E in .r
    spec = {"files": [f"shaders/{name}" for name in shaders.GLSL_FILES], "width": WIDTH,
            "lut": {"width": table.shape[1], "height": table.shape[0], "data": rg.reshape(-1).tolist()},
            "cases": [{"name": c.name, "expr": c.expr, "count": N,
                       "inputs": [x.reshape(-1).tolist() for x in c.inputs]} for c in cases]}
    (root / "cases.json").write_text(json.dumps(spec))
    report = run_page("shaders.html", data=root, timeout=120)
    return cases, report["result"]


def test_material_functions_are_listed():
    """pbrkit_khr_material.glsl is written after pbrkit_brdf.glsl and pbrkit_khr.glsl (whose terms it calls)."""
    names = {f["name"]: f["file"] for f in shaders.functions()}
    assert FILE in shaders.GLSL_FILES
    assert shaders.GLSL_FILES.index(FILE) > shaders.GLSL_FILES.index("pbrkit_khr.glsl")
    for name in ("BRDF_glTFExtended", "pbrkit_clearcoatBRDF", "pbrkit_dielectricF0", "pbrkit_glTFExtendedIBL",
                 "pbrkit_sampleViewerExtensionsIBL", "pbrkit_anisotropicFrame", "BRDF_glTFAnisotropic",
                 "pbrkit_anisotropicReflection", "pbrkit_dispersionIors", "pbrkit_dispersionLookup"):
        assert names[name] == FILE, name


@needs_engines()
def test_every_material_function_is_tested_in_webgl2(webgl_material_results):
    cases, result = webgl_material_results
    covered = {name for c in cases for name in c.covers}
    assert covered == {f["name"] for f in shaders.functions() if f["file"] == FILE}
    assert set(result["results"]) == {c.name for c in cases}


@needs_engines()
def test_material_glsl_matches_pbrkit_in_webgl2(webgl_material_results):
    cases, result = webgl_material_results
    assert_cases_match(cases, result, 34)
