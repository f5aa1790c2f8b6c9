"""The GLSL of the extended glTF material (``pbrkit_khr_material.glsl``, issue 25 item 5):
KHR_materials_ior and KHR_materials_specular, KHR_materials_clearcoat (with the coat's own
normal from a clearcoatNormalTexture), the whole BRDF with KHR_materials_sheen (and with the
coat's normal, against :func:`pbrkit.brdf.models.evaluate`'s ``coat_normal``), and the
extensions' real-time IBL, the coat's Fresnel at n_c.v (pbrkit's and the Khronos
Sample Viewer's, with KHR_materials_transmission / _volume's transmitted light and the
viewer's thin-film mix: :mod:`pbrkit.rendering.transmission_ibl`), KHR_materials_dispersion (each
channel's IOR and lookup) and KHR_materials_anisotropy (its frame, D, V, specular lobe, BRDF
and bent-normal IBL direction), against pbrkit's Python in WebGL2
(headless Chromium, SwiftShader), as
tests/shaders/test_shaders.py and tests/shaders/test_shaders_khr.py check the other files: each function
over a grid of float32 inputs, compared with :mod:`pbrkit.brdf.shading.gltf` (its
extended ``setup``, ``_specular_mix_weight``, ``ibl_*``), :mod:`pbrkit.brdf.lobes.clearcoat`,
:func:`pbrkit.brdf.operators.fresnel_coat`, :func:`pbrkit.brdf.models.gltf` (the whole
material at random (l, v, n, material)), the real-time renderer's own IBL kernel
(``pbrkit.rendering.realtime._ibl_kernel``, the whole IBL of the material) and
:mod:`pbrkit.rendering.khronos_ibl`; the anisotropy's against :func:`pbrkit.brdf.bxdf.shading_frame`,
:func:`pbrkit.brdf.models.evaluate` with a tangent and :func:`pbrkit.rendering.ibl_lookups.khr_anisotropic_reflection`;
the dispersion's against :mod:`pbrkit.brdf.transmission` and
:func:`pbrkit.rendering.transmission_ibl.transmission_lookups`; the coat's normal against
:func:`pbrkit.rendering.textures.tangent_space_normal`.  The cases of the functions that take
a tangent frame (anisotropy, the coat's normal) are in tests/support/shader_frame_cases.py.

The page's 2-D table (``u_lut``) is the E_sheen table, as in tests/shaders/test_shaders_khr.py:
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
from shader_cases import WIDTH, N, Case, assert_cases_match, f32, random_cosines, random_units, sheen_bxdf, vec4s
from shader_frame_cases import anisotropy_cases, clearcoat_normal_cases

from pbrkit import shaders
from pbrkit.brdf import models
from pbrkit.brdf.bxdf import EXTRA_SLOTS, Cosines
from pbrkit.brdf.fresnel import f0_from_ior
from pbrkit.brdf.lobes import Lobe
from pbrkit.brdf.lobes.clearcoat import CLEARCOAT, CLEARCOAT_ALPHA_SLOT, CLEARCOAT_SLOT, clearcoat_weight
from pbrkit.brdf.lobes.sheen import SHEEN_TABLE_FILE
from pbrkit.brdf.material import Material
from pbrkit.brdf.operators import fresnel_coat
from pbrkit.brdf.shading import gltf
from pbrkit.brdf.shading.registry import COLUMNS, LAYOUT
from pbrkit.core.jit import dual_use
from pbrkit.microfacet.roughness import alpha_from_roughness
from pbrkit.rendering import khronos_ibl

FILE = "pbrkit_khr_material.glsl"
#: The page's expression for a pbrkit_KHRMaterial from the inputs d, e, f, g: base d.xyz,
#: metallic d.w, roughness g.w, sheen colour e.xyz, sheen roughness e.w, clearcoat f.x, its
#: roughness f.y, specular f.z, specular colour g.xyz, ior f.w (a, b, c and h: the case's own).
MATERIAL = "pbrkit_KHRMaterial(d.xyz, d.w, g.w, e.xyz, e.w, f.x, f.y, f.z, g.xyz, f.w)"


def _materials(rng, mirror_rows=None):
    """N random extended materials (float32): some rows at the extensions' defaults, some
    without sheen or coat, ior 0 and 1 on a few, specular colours above 1 (F0 clamped at 1)."""
    m = SimpleNamespace()
    m.base = f32(rng.uniform(0, 1, (N, 3)))
    m.metallic = f32(np.where(rng.uniform(size=N) < 0.3, rng.integers(0, 2, N), rng.uniform(0, 1, N)))
    lo = np.full(N, 0.03) if mirror_rows is None else np.where(mirror_rows, 0.3, 0.03)
    m.roughness = f32(rng.uniform(lo, 1.0))
    m.sheen_color = f32(np.where(rng.uniform(size=(N, 1)) < 0.3, 0.0, rng.uniform(0, 1, (N, 3))))
    m.sheen_roughness = f32(np.where(rng.uniform(size=N) < 0.1, 0.0, rng.uniform(0.1, 1.0, N)))
    m.clearcoat = f32(np.where(rng.uniform(size=N) < 0.3, 0.0, rng.uniform(0, 1, N)))
    m.clearcoat_roughness = f32(rng.uniform(lo, 1.0))
    m.specular = f32(np.where(rng.uniform(size=N) < 0.2, 1.0, rng.uniform(0, 1, N)))
    m.specular_color = f32(np.where(rng.uniform(size=(N, 1)) < 0.2, 1.0, rng.uniform(0, 3, (N, 3))))
    m.ior = f32(np.where(rng.uniform(size=N) < 0.2, 1.5, rng.uniform(1.0, 3.0, N)))
    m.ior[2:6] = (0.0, 1.0, 0.0, 1.0)
    # the core material on the first rows (every extension at its default)
    m.sheen_color[6:12], m.clearcoat[6:12], m.specular[6:12], m.specular_color[6:12], m.ior[6:12] = 0, 0, 1, 1, 1.5
    return m


def _material_inputs(m):
    """Inputs d, e, f, g of MATERIAL."""
    return [vec4s(m.base, m.metallic), vec4s(m.sheen_color, m.sheen_roughness),
            vec4s(m.clearcoat, m.clearcoat_roughness, m.specular, m.ior), vec4s(m.specular_color, m.roughness)]


def _inputs(m, a=None, b=None, c=None, h=None, i=None):
    """The page's inputs: the case's a, b, c, h (and i) around the material's d, e, f, g."""
    none = vec4s()
    return ([none if x is None else x for x in (a, b, c)] + _material_inputs(m) + [none if h is None else h]
            + ([] if i is None else [i]))


def _params(m):
    """pbrkit's packed parameter rows (registry COLUMNS) of the materials."""
    c = COLUMNS
    p = np.zeros((N, LAYOUT.size))
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
    voh = random_cosines(rng, 0.0)
    expected = np.array([gltf._specular_mix_weight(b, _c(voh=voh[q])) for q, b in enumerate(bx)])
    add(Case("specularMixWeight", ("pbrkit_specularMixWeight",),
             "pbrkit_specularMixWeight(a.x, pbrkit_dielectricF0(f.w, g.xyz, f.z), f.z)", _inputs(m, vec4s(voh)),
             expected[:, None], atol=5e-7))  # 1 - F approaches 0 at grazing v.h: a few float32 ulps of 1

    # the coat lobe: as D_GGX and V_SmithGGX in tests/shaders/test_shaders.py, n.h close to 1 only at r >= 0.3
    noh, nol, nov = random_cosines(rng), random_cosines(rng, -0.2)[rng.permutation(N)], random_cosines(rng, -0.2)[rng.permutation(N)]
    cr = f32(np.where(noh > 0.999, rng.uniform(0.3, 1.0, N), rng.uniform(0.0, 1.0, N)))
    cr[:3] = (0.0, 1.0, 0.03)
    expected = []
    for q in range(N):
        extra = [0.0] * EXTRA_SLOTS  # (the coat normal's slots 0: the shading normal)
        extra[CLEARCOAT_SLOT], extra[CLEARCOAT_ALPHA_SLOT] = 1.0, float(alpha_from_roughness(cr[q]))
        b = sheen_bxdf((0.0, 0.0, 0.0), 0.0)._replace(extra=tuple(extra))
        expected.append(CLEARCOAT.value(b, _c(nol[q], nov[q], noh[q]), (1.0, 1.0, 1.0), 1.0)[0])
    add(Case("clearcoatBRDF", ("pbrkit_clearcoatBRDF",), "pbrkit_clearcoatBRDF(a.x, a.y, a.z, a.w)",
             [vec4s(noh, nol, nov, cr)], np.array(expected)[:, None], atol=1e-30))

    # the layering operator itself, with stand-in lobes: the base colour beneath, F0 above
    layered = fresnel_coat(gltf.GLTF_IOR, clearcoat_weight, Lobe("base", _base_value, None, None, None, None),
                           Lobe("layer", _layer_value, None, None, None, None))
    nov = random_cosines(rng, 0.0)
    expected = np.array([layered.value(b, _c(nov=nov[q]), (1.0, 1.0, 1.0), 1.0) for q, b in enumerate(bx)])
    add(Case("fresnelCoat", ("pbrkit_clearcoatWeight", "pbrkit_fresnelCoat"),
             "vec4(pbrkit_fresnelCoat(d.xyz, pbrkit_f0MetallicKHR(d.xyz, d.w, pbrkit_dielectricF0(f.w, g.xyz, f.z)), "
             "pbrkit_clearcoatWeight(f.x, a.x)), 0.0)", _inputs(m, vec4s(nov)), expected, atol=1e-7))
    return cases


def _brdf_case(rng):
    """The whole material: BRDF_glTFExtended against pbrkit.brdf.models.gltf with every extension,
    at shader_cases.random_directions' directions (half of them near the mirror direction)."""
    from shader_cases import random_directions

    l, v, n = random_directions(rng)
    mirror = np.arange(N) >= N // 2  # random_directions' near-mirror rows: r >= 0.3 (as BRDF_glTF's case)
    m = _materials(rng, mirror)
    material = Material(base_color=m.base, metallic=m.metallic, roughness=m.roughness, sheen_color=m.sheen_color,
                        sheen_roughness=m.sheen_roughness, clearcoat=m.clearcoat,
                        clearcoat_roughness=m.clearcoat_roughness, specular=m.specular,
                        specular_color=m.specular_color, ior=m.ior)
    return Case("BRDF_glTFExtended", ("BRDF_glTFExtended",),
                f"vec4(BRDF_glTFExtended(a.xyz, b.xyz, c.xyz, {MATERIAL}, "
                "pbrkit_fetchSheenAlbedo(u_lut, dot(c.xyz, b.xyz), e.w)), 0.0)",
                _inputs(m, vec4s(l), vec4s(v), vec4s(n)), models.gltf(l, v, n, material), rtol=1e-4, atol=1e-6)


def _coat_normal_brdf_case(rng):
    """The whole material with the coat's own normal n_c: BRDF_glTFExtendedCoatNormal against
    pbrkit.brdf.models.evaluate("gltf", ..., coat_normal=n_c) at _brdf_case's directions, n_c = n on a few
    rows, n tilted by up to 64 degrees on most (n_c.l or n_c.v <= 0 on some: no coat lobe, the weight at
    |n_c.v|) and near the coat's mirror direction h = normalize(l + v) on a quarter.  Where n.h or n_c.h
    exceeds 0.99 the base's or the coat's roughness is at least 0.3 (as the near-mirror rows of BRDF_glTF's
    case: D's peak is too steep for float32's h at smaller r)."""
    from shader_cases import random_directions

    l, v, n = random_directions(rng)
    h = l + v
    length = np.linalg.norm(h, axis=1, keepdims=True)
    h = h / np.maximum(length, 1e-300)
    nc = n + random_units(rng) * rng.uniform(0.0, 0.9, (N, 1))  # tilted by up to asin(0.9), 64 degrees
    near = (rng.uniform(size=N) < 0.25) & (length[:, 0] > 1e-3)
    nc[near] = h[near] + 0.05 * rng.normal(size=(int(near.sum()), 3))
    nc = f32(nc / np.linalg.norm(nc, axis=1, keepdims=True))
    nc[:8] = n[:8]
    m = _materials(rng)
    noh, ncoh = np.sum(n * h, axis=1), np.sum(nc * h, axis=1)
    m.roughness = np.where(noh > 0.99, f32(rng.uniform(0.3, 1.0, N)), m.roughness)
    m.clearcoat_roughness = np.where(ncoh > 0.99, f32(rng.uniform(0.3, 1.0, N)), m.clearcoat_roughness)
    material = Material(base_color=m.base, metallic=m.metallic, roughness=m.roughness, sheen_color=m.sheen_color,
                        sheen_roughness=m.sheen_roughness, clearcoat=m.clearcoat,
                        clearcoat_roughness=m.clearcoat_roughness, specular=m.specular,
                        specular_color=m.specular_color, ior=m.ior)
    expected = models.evaluate("gltf", l, v, n, material, coat_normal=nc)
    # the tilted coat counts: on many lit rows its value differs from the shading normal's coat
    lit = (np.sum(n * l, axis=1) > 0.0) & (np.sum(n * v, axis=1) > 0.0) & (m.clearcoat > 0.0)
    plain = models.gltf(l, v, n, material)
    differs = lit & ~np.all(np.isclose(expected, plain, rtol=1e-3, atol=1e-9), axis=1)
    coat_lit = (np.sum(nc * l, axis=1) > 0.0) & (np.sum(nc * v, axis=1) > 0.0)
    assert differs.sum() > N // 4 and (differs & coat_lit).sum() > N // 8 and (differs & ~coat_lit).sum() > 10
    return Case("BRDF_glTFExtendedCoatNormal", ("BRDF_glTFExtendedCoatNormal",),
                f"vec4(BRDF_glTFExtendedCoatNormal(a.xyz, b.xyz, c.xyz, h.xyz, {MATERIAL}, "
                "pbrkit_fetchSheenAlbedo(u_lut, dot(c.xyz, b.xyz), e.w)), 0.0)",
                _inputs(m, vec4s(l), vec4s(v), vec4s(n), vec4s(nc)), expected, rtol=1e-4, atol=1e-6)


def reference_albedo_f90(dfg, f0, f90):
    """The split sum with F90 of pbrkit.rendering.realtime's _ibl_kernel, albedo = DFG1 F90 + F0
    (DFG2 - DFG1), transcribed: the kernel's line has no Python function of its own."""
    return dfg[:, :1] * np.asarray(f90).reshape(-1, 1) + f0 * (dfg[:, 1:2] - dfg[:, :1])


def _ibl_cases(rng, m, bx, dfg_table):
    """pbrkit's real-time IBL of the material (engine "pbrkit").  Inputs: a = (n.v, DFG at (n.v, r),
    the coat's DFG2), b, c, h = (prefiltered, irradiance, the coat's prefiltered) RGB, the sheen's
    prefiltered RGB in (b.w, c.w, h.w), i.x = n_c.v (the view's cosine to the coat's own normal, drawn
    apart from n.v); E_sheen from the table at (n.v, sheenRoughness)."""
    cases = []
    add = cases.append
    nov = f32(np.maximum(random_cosines(rng, 0.0), 1e-4))  # the renderer's floor
    coat_nov = f32(np.maximum(random_cosines(rng, 0.0)[rng.permutation(N)], 1e-4))
    coat_nov[:4] = nov[:4]  # and the coat about the shading normal
    j, i = rng.integers(0, dfg_table.shape[0], (2, N)), rng.integers(0, dfg_table.shape[1], (2, N))
    dfg, coat_dfg = f32(dfg_table[j[0], i[0]]), f32(dfg_table[j[1], i[1]])
    pref, irr = f32(rng.uniform(0, 4, (N, 3))), f32(rng.uniform(0, 4, (N, 3)))
    coat_pref, sheen_pref = f32(rng.uniform(0, 4, (N, 3))), f32(rng.uniform(0, 4, (N, 3)))
    inputs = _inputs(m, vec4s(nov, dfg, coat_dfg[:, 1]), vec4s(pref, sheen_pref[:, 0]),
                     vec4s(irr, sheen_pref[:, 1]), vec4s(coat_pref, sheen_pref[:, 2]), vec4s(coat_nov))
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
    scale = np.array([gltf.ibl_extensions_base_scale(b, float(nov[q]), float(coat_nov[q])) for q, b in enumerate(bx)])
    add(Case("extensionsIBLBaseScale", ("pbrkit_extensionsIBLBaseScale",),
             f"pbrkit_extensionsIBLBaseScale(i.x, f.x, e.xyz, {e_sheen})", inputs, scale[:, None],
             atol=2e-6))  # 1 - cE crosses 0 (as sheenAlbedoScaling in tests/shaders/test_shaders_khr.py)
    table = np.zeros((2, 2))
    extras = np.array([gltf.ibl_extensions_extras(b, float(nov[q]), float(coat_nov[q]), float(coat_dfg[q, 0]),
                                                  float(coat_dfg[q, 1]), table, tuple(irr[q]), tuple(coat_pref[q]),
                                                  tuple(sheen_pref[q]), 0.5, 0.9, (1.0, 1.0, 1.0))[0]
                       for q, b in enumerate(bx)])  # (no film: the base's DFG unused)
    add(Case("extensionsIBL", ("pbrkit_extensionsIBL",),
             f"vec4(pbrkit_extensionsIBL(i.x, f.x, a.w, h.xyz, e.xyz, {e_sheen}, {sheen}), 0.0)", inputs, extras,
             atol=1e-6))

    # the whole of it, as _ibl_kernel composes those functions for engine "pbrkit" (no energy compensation)
    diffuse_color = np.array([b.diffuse_color for b in bx])
    expected = (pref * reference_albedo_f90(dfg, f0, f90) + diffuse_color * (weight / np.pi)[:, None] * irr) \
        * scale[:, None] + extras
    add(Case("glTFExtendedIBL", ("pbrkit_glTFExtendedIBL",),
             f"vec4(pbrkit_glTFExtendedIBL(a.x, i.x, {MATERIAL}, a.yz, b.xyz, c.xyz, vec2(0.0, a.w), h.xyz, "
             f"{e_sheen}, {sheen}), 0.0)", inputs, expected, atol=1e-6))
    return cases


def _renderer_cases(rng, m, dfg_table):
    """pbrkit_glTFExtendedIBL and pbrkit_sampleViewerExtensionsIBL against the renderer itself:
    pbrkit.rendering.realtime's _ibl_kernel (engines "pbrkit", no energy compensation, and "khronos") on
    the materials packed as a scene's (material_tables), at random (n, v), most with a coat normal of their
    own (the rows' coat_normal: n tilted); the kernel's own n.v and n_c.v (floored at 1e-4), DFG lookups at
    (n.v, r) and at (n_c.v, the coat's roughness from its _reflection_kernel) are the GLSL's inputs, as
    _ibl_cases lays them out."""
    from pbrkit.albedo.tables import table_bilinear
    from pbrkit.brdf.bxdf import NO_TANGENT
    from pbrkit.rendering import realtime
    from pbrkit.rendering.material_spec import MaterialSpec
    from pbrkit.rendering.materials import material_tables

    specs = [SimpleNamespace(spec=MaterialSpec(
        name=f"m{q}", base_color=tuple(m.base[q]), metallic=float(m.metallic[q]), roughness=float(m.roughness[q]),
        sheen_color=tuple(m.sheen_color[q]), sheen_roughness=float(m.sheen_roughness[q]),
        clearcoat=float(m.clearcoat[q]), clearcoat_roughness=float(m.clearcoat_roughness[q]),
        specular=float(m.specular[q]), specular_color=tuple(m.specular_color[q]), ior=float(m.ior[q])))
        for q in range(N)]
    mi, mf = material_tables(specs)
    n, v = random_units(rng), random_units(rng)
    v = np.where(np.sum(n * v, axis=1, keepdims=True) < 0.0, -v, v)
    nc = n + random_units(rng) * rng.uniform(0.0, 1.0, (N, 1))
    nc /= np.linalg.norm(nc, axis=1, keepdims=True)
    own = rng.uniform(size=N) < 0.8
    mf[own, COLUMNS.coat_normal:COLUMNS.coat_normal + 3] = nc[own]
    nc[~own] = n[~own]
    mat = np.arange(N)
    base = np.ascontiguousarray(m.base)
    refl, coat_r, sheen_r = np.empty((N, 3)), np.empty(N), np.empty(N)
    no_tangent = np.tile(NO_TANGENT, (N, 1))  # (isotropic materials: no frame needed)
    realtime._reflection_kernel(mi, mf, mat, n, v, m.roughness, m.metallic, base, no_tangent, refl, coat_r,
                                sheen_r)
    tables = np.ascontiguousarray(np.asarray(dfg_table, dtype=np.float64)[None, ..., :2])
    pref, irr = f32(rng.uniform(0, 4, (N, 3))), f32(rng.uniform(0, 4, (N, 3)))
    coat_pref, sheen_pref = f32(rng.uniform(0, 4, (N, 3))), f32(rng.uniform(0, 4, (N, 3)))
    out, ec = np.empty((N, 3)), np.empty((N, 3))
    realtime._ibl_kernel(mi, mf, mat, np.zeros(N, dtype=np.int64), tables, n, v, m.roughness, m.metallic, base,
                         np.ones(N), pref, irr, coat_pref, coat_r, sheen_pref, np.zeros(N), np.zeros((1, 3)),
                         np.zeros((1, 2)), False, realtime.sheen_albedo_table(), realtime.fresnel_mix_albedo_table(), False, False,
                         realtime.ENGINES.index("pbrkit"), out, ec)
    nov = np.maximum(np.sum(n * v, axis=1), 1e-4)
    coat_nov = np.maximum(np.sum(nc * v, axis=1), 1e-4)
    assert np.mean(np.abs(coat_nov - nov) > 0.05) > 0.5
    dfg = np.array([[table_bilinear(tables, 0, nov[q], float(m.roughness[q]), k) for k in range(2)]
                    for q in range(N)])
    coat2 = np.array([table_bilinear(tables, 0, coat_nov[q], coat_r[q], 1) if coat_r[q] >= 0.0 else 0.0
                      for q in range(N)])
    inputs = _inputs(m, vec4s(nov, dfg, coat2), vec4s(pref, sheen_pref[:, 0]), vec4s(irr, sheen_pref[:, 1]),
                     vec4s(coat_pref, sheen_pref[:, 2]), vec4s(coat_nov))
    cases = [Case("glTFExtendedIBL_renderer", ("pbrkit_glTFExtendedIBL",),
                  f"vec4(pbrkit_glTFExtendedIBL(a.x, i.x, {MATERIAL}, a.yz, b.xyz, c.xyz, vec2(0.0, a.w), h.xyz, "
                  "pbrkit_fetchSheenAlbedo(u_lut, a.x, e.w), vec3(b.w, c.w, h.w)), 0.0)", inputs, out.copy(),
                  atol=1e-6)]

    # the same kernel as the Sample Viewer (engine "khronos"): Karis' (A, B) = (DFG2 - DFG1, DFG1), the
    # Charlie LUT's value per pixel; the core materials' rows take its core path (_engine_ibl)
    charlie = f32(rng.uniform(0.0, 0.5, N))
    realtime._ibl_kernel(mi, mf, mat, np.zeros(N, dtype=np.int64), tables, n, v, m.roughness, m.metallic, base,
                         np.ones(N), pref, irr, coat_pref, coat_r, sheen_pref, charlie, np.zeros((1, 3)),
                         np.zeros((1, 2)), False, realtime.sheen_albedo_table(), realtime.fresnel_mix_albedo_table(), False, False,
                         realtime.ENGINES.index("khronos"), out, ec)
    inputs = _inputs(m, vec4s(nov, dfg[:, 1] - dfg[:, 0], dfg[:, 0], charlie), *inputs[1:3], inputs[7], inputs[8])
    cases.append(Case("sampleViewerExtensionsIBL_renderer", ("pbrkit_sampleViewerExtensionsIBL",),
                      f"vec4(pbrkit_sampleViewerExtensionsIBL(a.x, i.x, {MATERIAL}, a.yz, b.xyz, c.xyz, h.xyz, "
                      "vec3(b.w, c.w, h.w), a.w, pbrkit_fetchSheenAlbedo(u_lut, a.x, e.w)), 0.0)", inputs, out.copy(),
                      atol=1e-6))
    return cases


def _sample_viewer_cases(rng, m):
    """The Sample Viewer's IBL (pbrkit.rendering.khronos_ibl).  Inputs: a = (n.v, Karis' (A, B), the Charlie
    LUT's value), b, c, h = (radiance, irradiance, the coat's radiance) RGB, the sheen's radiance RGB in
    (b.w, c.w, h.w), i.x = n_c.v (drawn apart from n.v)."""
    cases = []
    add = cases.append
    nov = f32(np.maximum(random_cosines(rng, 0.0), 1e-4))
    ab = f32(rng.uniform(0.0, 0.5, (N, 2)))  # A + B <= 1: E_ms >= 0
    charlie = f32(rng.uniform(0.0, 0.5, N))
    coat_nov = f32(np.maximum(random_cosines(rng, 0.0)[rng.permutation(N)], 1e-4))
    coat_nov[:4] = nov[:4]
    rad, irr = f32(rng.uniform(0, 4, (N, 3))), f32(rng.uniform(0, 4, (N, 3)))
    coat_rad, sheen_rad = f32(rng.uniform(0, 4, (N, 3))), f32(rng.uniform(0, 4, (N, 3)))
    inputs = _inputs(m, vec4s(nov, ab, charlie), vec4s(rad, sheen_rad[:, 0]), vec4s(irr, sheen_rad[:, 1]),
                     vec4s(coat_rad, sheen_rad[:, 2]), vec4s(coat_nov))
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
        float(charlie[q]), k, *(float(x) for x in m.base[q]), 0.0, float(coat_nov[q])) for k in range(3)]
        for q in range(N)])
    add(Case("sampleViewerExtensionsIBL", ("pbrkit_sampleViewerExtensionsIBL",),
             f"vec4(pbrkit_sampleViewerExtensionsIBL(a.x, i.x, {MATERIAL}, a.yz, b.xyz, c.xyz, h.xyz, "
             "vec3(b.w, c.w, h.w), a.w, pbrkit_fetchSheenAlbedo(u_lut, a.x, e.w)), 0.0)", inputs, expected, atol=1e-6))
    return cases


def _transmission_cases(rng):
    """Real-time KHR_materials_transmission / _volume and the Sample Viewer's thin-film mix,
    each against its Python counterpart at random inputs."""
    from pbrkit.brdf.transmission import absorption
    from pbrkit.rendering.transmission_ibl import ior_roughness, transmission_direction

    cases = []
    r, ior = f32(rng.uniform(0, 1, N)), f32(rng.uniform(1.0, 3.0, N))
    ior[:8] = 1.0
    cases.append(Case("iorRoughness", ("pbrkit_iorRoughness",), "vec4(pbrkit_iorRoughness(a.x, a.y), 0.0, 0.0, 0.0)",
                      [vec4s(r, ior)], ior_roughness(r.astype(float), ior.astype(float))[:, None], atol=1e-7))
    n = f32(random_units(rng))
    v = random_units(rng)
    v = f32(np.where(np.sum(n * v, axis=1, keepdims=True) < 0.0, -v, v))
    thickness = f32(np.where(rng.uniform(size=N) < 0.3, 0.0, rng.uniform(0.01, 2.0, N)))
    direction = transmission_direction(n.astype(float), v.astype(float), ior.astype(float), thickness)
    cases.append(Case("transmissionDirection", ("pbrkit_transmissionDirection",),
                      "vec4(pbrkit_transmissionDirection(a.xyz, b.xyz, c.x, c.y), 0.0)",
                      [vec4s(n), vec4s(v), vec4s(ior, thickness)], direction, atol=1e-5))
    colour = f32(rng.uniform(0.05, 1.0, (N, 3)))
    colour[:4] = 1.0
    distance = f32(np.where(rng.uniform(size=N) < 0.2, 0.0, rng.uniform(0.1, 3.0, N)))
    params = np.zeros((N, LAYOUT.size))
    params[:, COLUMNS.attenuation_color:COLUMNS.attenuation_color + 3] = colour
    params[:, COLUMNS.attenuation_distance] = distance
    attenuation = np.array([absorption(params, q, float(thickness[q])) for q in range(N)])
    cases.append(Case("volumeAttenuation", ("pbrkit_volumeAttenuation",),
                      "vec4(pbrkit_volumeAttenuation(a.x, b.xyz, a.y), 0.0)", [vec4s(thickness, distance),
                                                                                vec4s(colour)],
                      attenuation, atol=1e-7))
    base, metallic = f32(rng.uniform(0, 1, (N, 3))), f32(rng.uniform(0, 1, N))
    transmission, weight = f32(rng.uniform(0, 1, N)), f32(rng.uniform(0, 1, N))
    light = f32(rng.uniform(0, 4, (N, 3)))
    p = np.zeros((N, LAYOUT.size))
    p[:, COLUMNS.transmission] = transmission
    p[:, COLUMNS.specular] = 1.0
    p[:, COLUMNS.ior] = 1.5
    codes = np.zeros((1, 5), dtype=np.int64)
    tw = np.array([gltf.ibl_transmission(gltf.setup(codes, 0, p, q, COLUMNS, 0.5, float(metallic[q]),
                                                    *map(float, base[q]))) for q in range(N)])
    cases.append(Case("transmissionIBL", ("pbrkit_transmissionIBL",),
                      "vec4(pbrkit_transmissionIBL(a.xyz, a.w, b.x, b.y, c.xyz), 0.0)",
                      [vec4s(base, metallic), vec4s(transmission, weight), vec4s(light)],
                      tw[:, None] * base * weight[:, None] * light, atol=1e-7))
    diffuse, f0 = f32(rng.uniform(0, 2, (N, 3))), f32(rng.uniform(0, 1, (N, 3)))
    ab = f32(np.stack([rng.uniform(0, 0.9, N), rng.uniform(0, 0.1, N)], axis=1))
    expected = np.array([[khronos_ibl.sample_viewer_transmission(float(diffuse[q, k]), float(transmission[q]),
                                                                 float(f0[q, k]), float(ab[q, 0]), float(ab[q, 1]),
                                                                 float(light[q, k]), float(base[q, k]))
                          for k in range(3)] for q in range(N)])
    cases.append(Case("sampleViewerTransmission", ("pbrkit_sampleViewerTransmission",),
                      "vec4(pbrkit_sampleViewerTransmission(a.xyz, a.w, b.xyz, c.xy, h.xyz, d.xyz), 0.0)",
                      [vec4s(diffuse, transmission), vec4s(f0), vec4s(ab), vec4s(base), vec4s(), vec4s(),
                       vec4s(), vec4s(light)], expected, atol=1e-6))
    nov, k = f32(rng.uniform(0.05, 1.0, N)), f32(rng.uniform(0, 1, N))
    film_d, film_m = f32(rng.uniform(0, 1, (N, 3))), f32(rng.uniform(0, 1, (N, 3)))
    radiance = f32(rng.uniform(0, 4, (N, 3)))
    expected = np.array([[khronos_ibl.sample_viewer_film(
        float(nov[q]), float(r[q]), float(diffuse[q, c]), float(base[q, c]), float(metallic[q]), float(f0[q, c]),
        float(weight[q]), float(ab[q, 0]), float(ab[q, 1]), float(radiance[q, c]), float(k[q]), float(film_d[q, c]),
        float(film_d[q].max()), float(film_m[q, c])) for c in range(3)] for q in range(N)])
    cases.append(Case("sampleViewerFilm", ("pbrkit_sampleViewerFilm",),
                      "vec4(pbrkit_sampleViewerFilm(a.x, a.y, b.xyz, c.xyz, a.z, d.xyz, a.w, e.xy, f.xyz, b.w, g.xyz, "
                      "h.xyz), 0.0)",
                      [vec4s(nov, r, metallic, weight), vec4s(diffuse, k), vec4s(base), vec4s(f0), vec4s(ab),
                       vec4s(radiance), vec4s(film_d), vec4s(film_m)], expected, atol=1e-6))
    return cases


def _dispersion_cases(rng):
    """KHR_materials_dispersion: each channel's IOR against pbrkit.brdf.transmission.dispersion_iors and
    sample_viewer_dispersion_iors (ior in [1, 2.5] with 1 and KHR_materials_ior's 0 on a few rows, dispersion
    in [0, 3] with 0, and on a few rows far above 3, where Cauchy's red IOR is clamped at 1), and each
    channel's lookup (direction and roughness) against the renderer's own
    pbrkit.rendering.transmission_ibl.transmission_lookups, whose sampler records what it is asked for."""
    from pbrkit.brdf.transmission import dispersion_iors, sample_viewer_dispersion_iors
    from pbrkit.rendering.geometry import Surface
    from pbrkit.rendering.material_spec import MaterialSpec
    from pbrkit.rendering.materials import material_tables
    from pbrkit.rendering.transmission_ibl import transmission_lookups

    cases = []
    ior = f32(rng.uniform(1.0, 2.5, N))
    dispersion = f32(np.where(rng.uniform(size=N) < 0.2, 0.0, rng.uniform(0.0, 3.0, N)))
    ior[:6], dispersion[:6] = (1.0, 1.0, 1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 3.0, 0.0, 0.5, 3.0)
    dispersion[6:12] = f32(rng.uniform(67.0, 150.0, 6))  # red below 1 unclamped (20 / 0.30106 = 66.4)
    ior[12:16], dispersion[12:16] = 2.5, (0.0, 1.0, 3.0, 0.1)
    iors = dispersion_iors(ior, dispersion)
    assert np.all(iors[6:12, 0] == 1.0) and np.all(iors[12:, 0] > 1.0)
    inputs = [vec4s(ior, dispersion)]
    # (rtol: float32's 523655 / lambda^2 - 1.5168 cancels to -1.6e-4 at the d line, its error of ~1e-7 magnified
    # by (ior - 1) dispersion / 20, up to 11 on the rows far above 3)
    cases.append(Case("dispersionIors", ("pbrkit_dispersionIors",), "vec4(pbrkit_dispersionIors(a.x, a.y), 0.0)",
                      inputs, iors, rtol=1e-6, atol=1e-6))
    cases.append(Case("sampleViewerDispersionIors", ("pbrkit_sampleViewerDispersionIors",),
                      "vec4(pbrkit_sampleViewerDispersionIors(a.x, a.y), 0.0)", inputs,
                      sample_viewer_dispersion_iors(ior, dispersion), rtol=0.0, atol=1e-6))

    # the lookups: thin walls (thickness 0) on some rows, v above n, a channel per row
    n = random_units(rng)
    v = random_units(rng)
    v = f32(np.where(np.sum(n * v, axis=1, keepdims=True) < 0.0, -v, v))
    thickness = f32(np.where(rng.uniform(size=N) < 0.3, 0.0, rng.uniform(0.01, 2.0, N)))
    r = f32(rng.uniform(0.0, 1.0, N))
    r[16:20] = (0.0, 1.0, 0.0, 1.0)
    channel = np.arange(N) % 3
    specs = [SimpleNamespace(spec=MaterialSpec(name=f"m{q}", transmission=1.0, thickness=float(thickness[q]),
                                   ior=float(ior[q]), dispersion=float(dispersion[q]))) for q in range(N)]
    codes, params = material_tables(specs)
    surface = Surface(f32(rng.normal(size=(N, 3))), n, n, np.arange(N), np.ones((N, 3)), np.zeros(N), r,
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
        inputs = [vec4s(n, r), vec4s(v), vec4s(ior, dispersion, thickness, channel)]
        covers = ("pbrkit_dispersionLookup", glsl_iors)
        if engine == "pbrkit":  # the Sample Viewer's direction is the camera's ray to the exit point: not this one
            cases.append(Case(name, covers, f"vec4({expr}.xyz, 0.0)", inputs, direction, rtol=0.0, atol=2e-6))
        cases.append(Case(name + "_roughness", covers, f"vec4({expr}.w, 0.0, 0.0, 0.0)", inputs, roughness[:, None],
                          rtol=0.0, atol=1e-6))
    return cases


@pytest.fixture(scope="module")
def webgl_material_results(tmp_path_factory):
    from pbrkit.albedo.lut import lookup_table

    root = tmp_path_factory.mktemp("shaders_khr_material")
    shaders.write_shaders(root / "shaders")
    rng = np.random.default_rng(20251127)
    table = np.load(SHEEN_TABLE_FILE)
    dfg, _ = lookup_table("dfg", 16)
    m = _materials(rng)
    bx = _bxdfs(m)
    cases = (_setup_cases(rng, m, bx) + [_brdf_case(rng)] + _ibl_cases(rng, m, bx, dfg) + _renderer_cases(rng, m, dfg)
             + _sample_viewer_cases(rng, m) + _transmission_cases(rng) + anisotropy_cases(rng)
             + _dispersion_cases(rng) + clearcoat_normal_cases(rng) + [_coat_normal_brdf_case(rng)])
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
    for name in ("BRDF_glTFExtended", "BRDF_glTFExtendedCoatNormal", "pbrkit_clearcoatNormal", "pbrkit_clearcoatBRDF",
                 "pbrkit_dielectricF0", "pbrkit_glTFExtendedIBL",
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
