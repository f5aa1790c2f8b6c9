"""Real-time rendering (:func:`render_realtime`) is what an engine does with a bake
(:mod:`pbrkit.ibl.bake`): punctual lights evaluated with the model (with exact
shadow rays, as an ideal shadow map), plus split-sum image-based lighting
(Karis 2013, "Real Shading in Unreal Engine 4", "Image based lighting"):

- specular: the prefiltered chain sampled trilinearly (seam-aware,
  :class:`pbrkit.ibl.cubemap.CubeSampler`) in the mirror direction
  R = 2 (n.v) n - v at the fractional level ``level_of_roughness(r, M)``,
  times the DFG table (:mod:`pbrkit.albedo.tables`, texel centres, bilinear, clamp)
  as lerp(DFG1, DFG2, F0) = DFG1 + F0 (DFG2 - DFG1) (Filament sec. 5.3.4.3;
  f90 = 1).  The table's visibility matches the material's masking
  (height-correlated: the bake's table; separable; Schlick-GGX with
  k = alpha / 2 for UE4, whose IBL uses that remap; ``engine`` khronos: the
  bake's, the Sample Viewer's lut_ggx); F0 is the model's (the
  metallic workflow's lerp, the exact conductor's F(1) for
  ``exact-conductor``, the constant colour S for ``fresnel = "none"``, where
  the albedo is S DFG2).  Optional energy compensation multiplies the
  specular lobes by 1 + F0 (1 / DFG2 - 1) (Filament sec. 4.7.2,
  :func:`pbrkit.albedo.tables.filament_energy_compensation`).
- diffuse: the model's own diffuse colour (base_color (1 - metallic), URP's
  0.96 (1 - metallic)) / pi * E(n) * w, with E from the bake's SH
  (:func:`pbrkit.ibl.sh.irradiance_from_sh`) or its irradiance cube, and w
  the model's diffuse weighting (:func:`pbrkit.brdf.dispatch.ibl_diffuse_weight`): 1 for the models
  whose diffuse lobe has none, and for ``gltf``, whose diffuse is weighted by
  1 - F(v.h) (``fresnel_mix``), Lagarde's 1 - F*(n.v, 0.04, r)
  (:func:`pbrkit.brdf.diffuse.kd_ibl`; seed 000), or with
  ``diffuse_weight="exact"`` the exact directional albedo of that weight
  (:func:`fresnel_mix_albedo_table`), which is what a constant environment
  gives.
- the glTF occlusion texture scales both IBL terms; emission is added.
- KHR_materials_anisotropy: the lookup along the Sample Viewer's bent normal
  (:func:`khr_anisotropic_reflection`), and for ``engine`` pbrkit filtered
  importance sampling of the anisotropic lobe in place of the split sum's one
  lookup and table (:mod:`pbrkit.rendering.anisotropic_ibl`).

Known approximations of the real-time path (what ``compare`` measures,
:data:`APPROXIMATIONS`): the split sum itself (n = v = r in the prefilter,
the lobe's shape, the levels and the table's texels), the F* diffuse weight
(``gltf``), the SH truncation of the irradiance, and for the other models
Lambert in place of Burley and GGX in place of Beckmann / Blinn-Phong for the
IBL.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace
from functools import lru_cache

import numpy as np

from ..choices import RENDER_ENGINES
from ..albedo.tables import filament_energy_compensation, table_bilinear
from ..brdf.dispatch import (
    fresnel_constant,
    split_sum_f90,
    ibl_base_scale,
    ibl_coat_roughness,
    ibl_khronos_extensions,
    ibl_sheen_roughness,
    ibl_diffuse_weight,
    ibl_extras,
    ibl_has_diffuse,
    ibl_has_extras,
    ibl_transmission,
    split_sum_f0,
)
from ..brdf.bxdf import NO_TANGENT
from ..brdf.fresnel import f0_from_ior, f_schlick
from ..brdf.shading.gltf import gltf_fresnel_mix_weight
from ..brdf.shading.registry import COLUMNS, EXTENDED_CODES, model
from ..core.jit import dual_use, row_kernel
from ..core.quadrature import gauss_legendre_01
from ..engines import ENGINES as ENGINE_TABLE
from ..engines.babylon import babylon_ibl
from ..engines.filament import filament_diffuse_weight
from ..engines.khronos import sample_viewer_ibl
from ..engines.three import three_ibl
from ..io.bake_files import load_target_chain
from ..brdf.lobes.clearcoat import coat_local_nov, coat_tilted
from ..brdf.lobes.sheen import sheen_albedo_lookups
from .anisotropic_ibl import anisotropic_ibl
from .area_lights import area_light_ltc
from .ibl_lookups import khr_anisotropic_reflection, reflection_direction, specular_dominant_direction, three_roughness
from .khronos_ibl import sample_viewer_extensions_ibl

#: The codes of the models' extended forms (:data:`pbrkit.brdf.shading.registry.EXTENDED_CODES`).
_EXTENDED = np.array(sorted(EXTENDED_CODES.values()), dtype=np.int64)
from .environment import EnvironmentLight
from .geometry import Geometry
from .materials import (COAT_F0, coat_normals, emission_seen, for_materials, hit_bxdf, material_tables,
                        per_hit_tables)
from .primary import RenderResult, _background, _primary, _resolve
from .punctual import punctual_radiance, surface_tangents, tangent_of
from .transmission_ibl import transmission_lookups

__all__ = [
    "render_realtime",
    "reflection_direction",
    "khr_anisotropic_reflection",
    "sheen_albedo_table",
    "fresnel_mix_albedo_table",
    "DIFFUSE_WEIGHTS",
    "ENGINES",
    "render_engine",
    "specular_dominant_direction",
    "three_roughness",
    "APPROXIMATIONS",
]

#: How the real-time path weights the ``gltf`` diffuse (:func:`pbrkit.brdf.shading.gltf.ibl_diffuse_weight`).
DIFFUSE_WEIGHTS = ("fstar", "exact")

#: Whose image-based lighting the real-time path evaluates (:func:`render_realtime`):
#: ``pbrkit`` (the module docstring), or what an engine's shaders do with its bake
#: (``pbrkit bake --target``; :data:`pbrkit.engines.ENGINES`): ``filament`` (1.53),
#: ``khronos`` (the glTF Sample Viewer 1.1), ``three`` (three.js r187
#: MeshStandardMaterial), ``babylon`` (Babylon.js 9.35 PBRMaterial with its defaults).
ENGINES = RENDER_ENGINES  # pbrkit.choices
# the kernels' engine codes (Engine.code: the index in ENGINES; 0 is pbrkit's own)
_ENGINE_FILAMENT = ENGINE_TABLE["filament"].code
_ENGINE_KHRONOS = ENGINE_TABLE["khronos"].code
_ENGINE_THREE = ENGINE_TABLE["three"].code
_ENGINE_BABYLON = ENGINE_TABLE["babylon"].code
#: The parameter row's anisotropy column, and KHR_materials_anisotropy's strength's.
_ANISOTROPY = COLUMNS.anisotropy
_ANISOTROPY_STRENGTH = COLUMNS.anisotropy_strength

#: The approximations of the real-time path, in the order ``compare`` swaps them for
#: exact computations (:func:`pbrkit.rendering.run.approximation_split`).
APPROXIMATIONS = {
    "sh": "irradiance from 9 SH coefficients instead of the exact irradiance cube (diffuse)",
    "fstar": "diffuse weight 1 - F*(n.v, 0.04, r) instead of the exact albedo of 1 - F(v.h) (glTF diffuse)",
    "split_sum": "prefiltered environment (n = v = r) x DFG table instead of the integral of the lobe "
                 "against the environment (specular), with what remains",
    "split_sum_ltc": "split sum (environment) and LTC (area lights) instead of the integrals of the lobe "
                     "against the environment and over the lights (specular), with what remains",
}

_INV_PI = 1.0 / math.pi

# ================================================================ real time


def render_engine(name):
    """The :class:`pbrkit.engines.Engine` whose IBL ``render_realtime(engine=name)``
    evaluates, None for pbrkit's own; ValueError naming :data:`ENGINES` otherwise."""
    if name not in ENGINES:
        raise ValueError(f"unknown engine {name!r}; use one of {', '.join(ENGINES)}")
    return None if name == "pbrkit" else ENGINE_TABLE[name]


def _engine_chain(bake, env, engine):
    """The chain an engine samples (:attr:`pbrkit.engines.Engine.curve`: Filament's
    levels for filament and three, Babylon's for babylon): the in-memory bake's, or
    for a bake folder the texels of the engine's target files
    (:func:`pbrkit.io.bake_files.load_target_chain`)."""
    curve = ENGINE_TABLE[engine].curve
    chain = getattr(bake, "chains", {}).get(curve)
    if chain is None and env.spec.bake is not None:
        chain = load_target_chain(env.spec.bake, engine)
        bake.chains[curve] = chain
    if chain is None and env.environment is not None:  # an image environment baked earlier without the chain
        from ..ibl.bake import bake as bake_environment

        o = bake.manifest["options"]
        fresh = bake_environment(env.environment, size=o["size"], min_size=o["min_size"],
                                 irradiance_size=o["irradiance_size"], lut_size=o["lut_size"], chains=(curve,))
        chain = bake.chains[curve] = fresh.chains[curve]
    if chain is None:
        raise ValueError(f"engine {engine!r} needs a bake with its chain (pbrkit bake --target {engine})")
    return chain.levels


@lru_cache(maxsize=8)
def _extra_lut(visibility, size):
    from ..albedo.lut import lookup_table

    return lookup_table("dfg", size, visibility)[0]


def _lut_for(spec, bake_lut):
    """The DFG table whose visibility is the material's specular lobe's (its masking's
    table, :meth:`pbrkit.brdf.lobes.microfacet.Microfacet.table_name`: module
    docstring), and its name."""
    name = model(spec.model).compiled.specular.parts.table_name(spec.masking)
    if name == "height-correlated":
        return np.asarray(bake_lut), name
    return _extra_lut(name, bake_lut.shape[0]), name


def _charlie_rows(bake, n, v, sheen_roughness, engine):
    """Per pixel, the Charlie LUT (the Khronos IBL sampler's ``lut_charlie``, its blue
    channel: the sheen lobe's split-sum albedo) at (n.v, sheenRoughness) for the Sample
    Viewer's sheen (``engine="khronos"``; 0 elsewhere): channel 0 of the bake's
    ``sheen_lut`` (rows sheenRoughness, columns n.v, texel centres: what the Khronos
    target writes to the LUT's blue channel) when it has one, else the same albedo
    E(n.v, sheenRoughness) from the bundled table
    (:func:`pbrkit.brdf.lobes.sheen.sheen_albedo_lookups`)."""
    out = np.zeros(n.shape[0])
    rows = np.flatnonzero(sheen_roughness >= 0.0)
    if engine != "khronos" or not rows.size:
        return out
    nov = np.clip(np.sum(n[rows] * v[rows], axis=1), 1e-4, 1.0)
    lut = bake.sheen_lut
    if lut is None:
        out[rows] = sheen_albedo_lookups(nov, sheen_roughness[rows])
    else:
        from ..albedo.tables import sample_table

        out[rows] = sample_table(np.asarray(lut, dtype=np.float64)[..., 0], nov, sheen_roughness[rows])
    return out


def _sheen_lookups(bake, env, sampler, n, v, sheen_roughness, levels):
    """The sheen's prefiltered radiance of the pixels with a sheen (roughness >= 0,
    :func:`pbrkit.brdf.dispatch.ibl_sheen_roughness`; 0 elsewhere), about the mirror
    direction of the unbent normal as the Khronos Sample Viewer's getIBLRadianceCharlie
    looks it up: in the bake's Charlie-prefiltered chain (``bake.sheen``, level
    sheenRoughness (M - 1), :func:`pbrkit.ibl.sheen.prefilter_charlie`), prefiltered
    from the bake's level 0 here the first time a bake without one needs it (then
    kept with the bake)."""
    from ..ibl.cubemap import CubeSampler
    from ..ibl.sheen import prefilter_charlie

    out = np.zeros((n.shape[0], 3))
    rows = np.flatnonzero(sheen_roughness >= 0.0)
    if not rows.size:
        return out
    if not len(bake.sheen):
        bake.sheen, bake.sheen_roughness, _ = prefilter_charlie(np.asarray(bake.specular[0]), len(bake.specular))
    nov = np.sum(n[rows] * v[rows], axis=1, keepdims=True)
    direction = env.to_env_frame(2.0 * nov * n[rows] - v[rows])
    chain = CubeSampler([np.asarray(x) for x in bake.sheen])
    out[rows] = chain(direction, sheen_roughness[rows] * (len(bake.sheen) - 1.0)) * env.intensity
    return out


@row_kernel(3)
def _reflection_kernel(start, stop, mi, mf, mat, n, v, rough, metal, base, tan, out, coat_out, sheen_out):
    """The lookup direction (:func:`reflection_direction`) of every pixel, and the
    perceptual roughness of its model's coat and sheen lookups (-1 without one,
    :func:`pbrkit.brdf.dispatch.ibl_coat_roughness`, :func:`~pbrkit.brdf.dispatch.ibl_sheen_roughness`)."""
    for i in range(start, stop):
        m = mat[i]
        b, t, bt = hit_bxdf(mi, mf, m, rough[i], metal[i], base[i, 0], base[i, 1], base[i, 2], n[i, 0], n[i, 1],
                            n[i, 2], tangent_of(tan, i))
        strength = mf[m, _ANISOTROPY_STRENGTH] if b.anisotropic else 0.0
        if strength > 0.0:
            r = khr_anisotropic_reflection(n[i, 0], n[i, 1], n[i, 2], v[i, 0], v[i, 1], v[i, 2], bt, strength,
                                           rough[i])
        else:
            anisotropy = mf[m, _ANISOTROPY] if b.anisotropic else 0.0
            r = reflection_direction(n[i, 0], n[i, 1], n[i, 2], v[i, 0], v[i, 1], v[i, 2], t, bt, anisotropy,
                                     rough[i])
        out[i, 0] = r[0]
        out[i, 1] = r[1]
        out[i, 2] = r[2]
        coat_out[i] = ibl_coat_roughness(b)
        sheen_out[i] = ibl_sheen_roughness(b)


def _view_albedo_table(weight_of_loh, size, nodes):
    """integral of g(l.h) (n.l) dl over the upper hemisphere at mu = n.v = (i + 0.5) / size,
    for a factor g of l.h = v.h alone (no roughness), by a Gauss-Legendre product rule in
    (cos theta_l, phi) (the integrand is smooth: a function of the direction's components
    under a square root)."""
    x, w = gauss_legendre_01(nodes)
    phi = np.pi * x  # symmetric in phi: integrate over [0, pi] and double
    mu_v = (np.arange(size) + 0.5) / size
    v = np.stack([np.sqrt(1.0 - mu_v * mu_v), np.zeros(size), mu_v], axis=-1)[:, None, None, :]
    ml = x[:, None]
    sl = np.sqrt(1.0 - ml * ml)
    l = np.stack(np.broadcast_arrays(sl * np.cos(phi)[None, :], sl * np.sin(phi)[None, :], ml), axis=-1)[None]
    h = l + v
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    loh = np.sum(l * h, axis=-1)
    integrand = weight_of_loh(loh) * ml[None]
    return 2.0 * np.pi * np.einsum("mtp,t,p->m", integrand, w, w)


@lru_cache(maxsize=1)
def sheen_albedo_table(size=64, nodes=64):
    """Directional albedo of Disney's sheen lobe per unit sheen colour,
    S(mu) = integral of (1 - l.h)^5 (n.l) dl over the upper hemisphere (Burley
    2012, App. B), at mu = n.v = (i + 0.5) / size (:func:`_view_albedo_table`);
    a shader looks it up linearly."""
    return _view_albedo_table(lambda loh: f_schlick(loh, 0.0, 1.0), size, nodes)


@lru_cache(maxsize=1)
def fresnel_mix_albedo_table(size=64, nodes=64):
    """The exact directional albedo of the glTF diffuse lobe per unit diffuse colour,
    W(mu) = integral of (1 - F_0.04(v.h)) (n.l) / pi dl over the upper hemisphere
    (:func:`pbrkit.brdf.shading.gltf.gltf_fresnel_mix_weight`), at mu = n.v = (i + 0.5) / size
    (:func:`_view_albedo_table`).  No roughness: the diffuse lobe has none.  Under a
    constant environment the diffuse radiance is W(n.v) E / pi exactly; the
    real-time F* weight approximates it."""
    return _view_albedo_table(gltf_fresnel_mix_weight, size, nodes) / math.pi


@dual_use
def _engine_ibl(engine, base, metallic, r, nov, a, b, radiance, irradiance):
    """One channel of the IBL of a metallic-roughness material as engine ``engine``
    (its code) evaluates it (:attr:`pbrkit.engines.Engine.shading`), from the
    prefiltered ``radiance`` (its chain, its lod), the ``irradiance`` E it uses and
    Karis' (A, B) = (``a``, ``b``) of the DFG table: the Sample Viewer's
    (:func:`pbrkit.engines.khronos.sample_viewer_ibl`), three.js's
    (:func:`pbrkit.engines.three.three_ibl`) or Babylon.js's
    (:func:`pbrkit.engines.babylon.babylon_ibl`)."""
    if engine == _ENGINE_BABYLON:
        return babylon_ibl(base, metallic, r, nov, a, b, radiance, irradiance)
    if engine == _ENGINE_KHRONOS:
        return sample_viewer_ibl(base, metallic, r, nov, a, b, radiance, irradiance)
    return three_ibl(base, metallic, r, nov, a, b, radiance, irradiance)


@row_kernel(5)
def _ibl_kernel(start, stop, mi, mf, mat, lut_index, tables, n, v, rough, metal, base, occlusion, prefiltered, irradiance,
                coat_prefiltered, coat_roughness, sheen_prefiltered, charlie, transmitted, dfg_sampled, sampled,
                sheen_table, diffuse_table, exact_diffuse, energy_compensation, engine, out, ec_out):
    """Split-sum IBL per pixel (module docstring); writes the radiance and the
    energy-compensation factor (for the punctual lights).  ``engine`` (:data:`ENGINES`
    index) 1 is Filament's evaluation (``evaluateIBL``): the diffuse colour weighted
    by 1 - E per channel, E = DFG1 + F0 (DFG2 - DFG1) the specular albedo, in place of
    the model's own weighting; 2 and 3 are the metallic-roughness evaluations of
    the Sample Viewer and three.js (:func:`_engine_ibl`).  ``transmitted``: the light
    through each hit (:func:`pbrkit.rendering.transmission_ibl.transmission_lookups`; read
    only for a material that transmits).  ``dfg_sampled`` (with ``sampled``): per pixel
    the (DFG1, DFG2) of :func:`pbrkit.rendering.anisotropic_ibl.anisotropic_ibl` in place of
    the table's (NaN: the table's)."""
    for i in range(start, stop):
        m = mat[i]
        b, tt, bt = hit_bxdf(mi, mf, m, rough[i], metal[i], base[i, 0], base[i, 1], base[i, 2], n[i, 0], n[i, 1],
                             n[i, 2], NO_TANGENT)
        nov = max(n[i, 0] * v[i, 0] + n[i, 1] * v[i, 1] + n[i, 2] * v[i, 2], 1e-4)
        # the view's cosine to the coat's normal (KHR_materials_clearcoat's clearcoatNormal): n.v without one
        coat_nov = nov
        if coat_tilted(b):
            coat_nov = max(coat_local_nov(b, tt[0] * v[i, 0] + tt[1] * v[i, 1] + tt[2] * v[i, 2],
                                          bt[0] * v[i, 0] + bt[1] * v[i, 1] + bt[2] * v[i, 2], nov), 1e-4)
        r = rough[i]
        t = lut_index[m]
        dfg1 = table_bilinear(tables, t, nov, r, 0)
        dfg2 = table_bilinear(tables, t, nov, r, 1)
        if sampled and not math.isnan(dfg_sampled[i, 0]):  # an anisotropic lobe's own (pbrkit)
            dfg1 = dfg_sampled[i, 0]
            dfg2 = dfg_sampled[i, 1]
        if engine == _ENGINE_KHRONOS and ibl_khronos_extensions(b):  # the Sample Viewer's extensions
            for c in range(3):
                out[i, c] = sample_viewer_extensions_ibl(mf, m, base[i, c], metal[i], r, nov, dfg2 - dfg1, dfg1,
                                                         prefiltered[i, c], irradiance[i, c], coat_prefiltered[i, c],
                                                         sheen_prefiltered[i, c], charlie[i], c, base[i, 0],
                                                         base[i, 1], base[i, 2],
                                                         transmitted[i, c] if ibl_transmission(b) > 0.0 else 0.0,
                                                         coat_nov) * occlusion[i]
                ec_out[i, c] = 1.0
            continue
        if engine == _ENGINE_KHRONOS or engine == _ENGINE_THREE or engine == _ENGINE_BABYLON:
            for c in range(3):
                out[i, c] = _engine_ibl(engine, base[i, c], metal[i], r, nov, dfg2 - dfg1, dfg1, prefiltered[i, c],
                                        irradiance[i, c]) * occlusion[i]
                ec_out[i, c] = 1.0
            continue
        diffuse_on = ibl_has_diffuse(b)
        diffuse_weight = ibl_diffuse_weight(b, nov, exact_diffuse, diffuse_table) * _INV_PI
        constant_f = fresnel_constant(b)
        f0s = split_sum_f0(b)
        f90 = split_sum_f90(b)
        extras = ibl_has_extras(b)
        base_scale = ibl_base_scale(b, nov, coat_nov)
        transmits = ibl_transmission(b)
        spec_add = (0.0, 0.0, 0.0)
        diff_add = (0.0, 0.0, 0.0)
        if extras:  # the model's other lobes (Disney's clear coat and sheen)
            c1 = 0.0
            c2 = 0.0
            if coat_roughness[i] >= 0.0:
                c1 = table_bilinear(tables, t, coat_nov, coat_roughness[i], 0)
                c2 = table_bilinear(tables, t, coat_nov, coat_roughness[i], 1)
            spec_add, diff_add = ibl_extras(b, nov, coat_nov, c1, c2, sheen_table,
                                            (irradiance[i, 0], irradiance[i, 1], irradiance[i, 2]),
                                            (coat_prefiltered[i, 0], coat_prefiltered[i, 1], coat_prefiltered[i, 2]),
                                            (sheen_prefiltered[i, 0], sheen_prefiltered[i, 1], sheen_prefiltered[i, 2]),
                                            dfg1, dfg2, (prefiltered[i, 0], prefiltered[i, 1], prefiltered[i, 2]))
        for c in range(3):
            f0 = f0s[c]
            if constant_f:
                albedo = f0 * dfg2
            else:
                albedo = dfg1 * f90 + f0 * (dfg2 - dfg1)
            ec = 1.0
            if energy_compensation:
                ec = filament_energy_compensation(f0, max(dfg2, 1e-6))
            ec_out[i, c] = ec
            spec = prefiltered[i, c] * albedo * ec
            diff = 0.0
            if diffuse_on:
                w = filament_diffuse_weight(albedo) if engine == _ENGINE_FILAMENT else diffuse_weight
                diff = b.diffuse_color[c] * w * irradiance[i, c]
                if transmits > 0.0:  # KHR_materials_transmission: the light through it, weighted alike
                    diff += transmits * b.base[c] * w * math.pi * transmitted[i, c]
            if extras:  # the model's base under its other lobes (glTF's sheen albedo scaling; 1 for Disney)
                spec = spec * base_scale + spec_add[c]
                diff = diff * base_scale + diff_add[c]
            out[i, c] = (spec + diff) * occlusion[i]


@row_kernel(3)
def _area_specular_kernel(start, stop, mi, mf, mat, n, rough, metal, base, spec, fresnel, split, out):
    """The area lights' specular term in the form of a prefiltered radiance, for
    :func:`_ibl_kernel` to multiply by the split-sum albedo: with Schlick's F = f0 +
    (1 - f0) Fc, the lights' LTC integrals of the f lobe (``spec``) and of the f Fc
    lobe (``fresnel``) weighted by f0 norm and (1 - f0) fresnel (``split``, the LTC
    table's), divided by their sum (:func:`pbrkit.ltc.shader.ltc_fresnel_rect`; f0
    per channel from :func:`pbrkit.brdf.dispatch.split_sum_f0`); a constant F (``fresnel = "none"``)
    keeps the f lobe."""
    for i in range(start, stop):
        b, _, _ = hit_bxdf(mi, mf, mat[i], rough[i], metal[i], base[i, 0], base[i, 1], base[i, 2], n[i, 0], n[i, 1],
                           n[i, 2], NO_TANGENT)
        constant_f = fresnel_constant(b)
        f0s = split_sum_f0(b)
        for c in range(3):
            out[i, c] = spec[i, c]
            if constant_f:
                continue
            f0 = f0s[c]
            a = f0 * split[i, 0]
            d = (1.0 - f0) * split[i, 1]
            if a + d > 0.0:
                out[i, c] = (a * spec[i, c] + d * fresnel[i, c]) / (a + d)


def render_realtime(scene, geometry=None, env=None, bake=None, diffuse="sh", energy_compensation=False,
                    shadows=True, bake_size=256, bake_options=None, diffuse_weight="fstar", engine="pbrkit",
                    primary=None):
    """Real-time shading of ``scene`` (module docstring).  ``diffuse``: ``sh`` (the
    bake's 9 SH coefficients) or ``cube`` (its irradiance cube); ``diffuse_weight``:
    ``fstar`` (what engines do) or ``exact`` (:func:`pbrkit.brdf.shading.gltf.ibl_diffuse_weight`).
    ``engine`` (:data:`ENGINES`) evaluates the IBL as that engine's shaders do with
    its ``pbrkit bake --target`` files: ``filament``: its chain (prefiltered at r_m =
    1 - sqrt(1 - m/(M - 1)), read from ``filament/ibl.ktx`` for a bake folder) at
    lod = (M - 1) r (2 - r), looked up in the dominant direction
    (:func:`specular_dominant_direction`), SH diffuse weighted by 1 - E, Filament's
    energy compensation; ``khronos``: the generic chain at lod = r (M - 1), the
    irradiance cube, :func:`_engine_ibl`'s Sample Viewer terms; ``three``: the same
    chain as Filament's (``three/specular.ktx2``), roughness at least 0.045, the
    same lookup direction, pi x the last level as irradiance, :func:`_engine_ibl`'s
    three.js terms, its roughness from screen-space derivatives of the normal before
    normal mapping (:func:`three_roughness`; three.js's own 16 x 16 DFG table is not reproduced:
    pbrkit's converged one is used); ``babylon``: its chain (alpha_m = 2^(m/0.8) /
    N, ``babylon/specular.dds`` for a bake folder) at lod = 0.8 log2(N (r^2 +
    0.0005)), SH, :func:`_engine_ibl`'s Babylon.js terms.  The engine modes shade
    metallic-roughness materials (base colour, metallic, roughness) as the engine
    does, whatever the material's model.  ``primary``: the camera rays' hits when the
    caller has cast them already (:func:`pbrkit.rendering.primary._primary`; styles).
    Returns a :class:`RenderResult`;
    ``stats['timings']`` has the stages in seconds."""
    from ..ibl.cubemap import CubeSampler
    from ..ibl.prefilter import level_of_roughness
    from ..ibl.sh import irradiance_from_sh

    spec = render_engine(engine)
    # the chain it samples, when not the generic one (three.js r187 uses Filament's level curve)
    curve = None if spec is None else spec.extra_chain
    if curve is not None:
        bake_options = dict(bake_options or {}, chains=(curve,))
    if spec is not None:
        if spec.diffuse in ("sh", "cube"):  # Babylon's spherical polynomial, the Sample Viewer's Lambertian cube
            diffuse = spec.diffuse
        if spec.energy_compensation is not None:  # Filament's, or the engines' own multiple scattering
            energy_compensation = spec.energy_compensation

    if diffuse not in ("sh", "cube"):
        raise ValueError(f"unknown diffuse source {diffuse!r}; use 'sh' or 'cube'")
    if diffuse_weight not in DIFFUSE_WEIGHTS:
        raise ValueError(f"unknown diffuse weight {diffuse_weight!r}; use one of {', '.join(DIFFUSE_WEIGHTS)}")
    timings = {}
    t0 = time.perf_counter()
    geometry = geometry or Geometry(scene)
    env = env or EnvironmentLight(scene.environment)
    t1 = time.perf_counter()
    timings["load"] = t1 - t0
    if bake is None:
        bake = env.bake(size=bake_size, **(bake_options or {}))
    t2 = time.perf_counter()
    timings["bake"] = t2 - t1
    prim = _primary(scene, geometry) if primary is None else primary
    t3 = time.perf_counter()
    timings["primary_rays"] = t3 - t2
    mat_i, mat_f = material_tables(geometry.materials)
    # a row of the tables per hit whose KHR_materials extension textures change its parameters
    mat_i, mat_f, hit_material, origin = per_hit_tables(mat_i, mat_f, prim.surface)
    s = replace(prim.surface, material=hit_material, extension_values=None)
    count = prim.rows.size
    v = -prim.dirs[prim.rows]
    radiance = np.zeros((prim.dirs.shape[0], 3))
    radiance[~prim.hit] = _background(prim, env)
    if count:
        # lookup tables per material
        tables, lut_index, names = [], np.zeros(len(geometry.materials), dtype=np.int64), []
        for mi, m in enumerate(geometry.materials):
            # the Sample Viewer reads its lut_ggx (the bake's height-correlated table) for every material
            table, name = (np.asarray(bake.lut), "height-correlated") if engine == "khronos" else \
                _lut_for(m.spec, bake.lut)
            if name not in names:
                names.append(name)
                tables.append(np.asarray(table, dtype=np.float64)[..., :2])
            lut_index[mi] = names.index(name)
        if origin is not None:  # the per-hit rows take their scene material's table
            lut_index = lut_index[origin]
        tables = np.ascontiguousarray(np.stack(tables))
        mat = np.ascontiguousarray(s.material)
        n_rows = np.ascontiguousarray(s.n)
        v_rows = np.ascontiguousarray(v)
        base_rows = np.ascontiguousarray(s.base_color)
        refl = np.empty((count, 3))
        coat_roughness = np.empty(count)
        sheen_roughness = np.empty(count)
        for_materials(_reflection_kernel, mat_i)(mat_i, mat_f, mat, n_rows, v_rows, s.roughness, s.metallic,
                                                 base_rows, np.ascontiguousarray(surface_tangents(s)), refl,
                                                 coat_roughness, sheen_roughness)
        chain = _engine_chain(bake, env, engine) if curve is not None else bake.specular
        levels = len(chain)
        key = (id(bake), engine)
        sampler = env.samplers.get(key)
        if sampler is None or sampler[0] is not bake:
            sampler = (bake, CubeSampler([np.asarray(x) for x in chain]))
            env.samplers[key] = sampler
        sampler = sampler[1]
        rough_rows = s.roughness
        if engine == "three":  # its roughness floor and screen-space term, then r^4 towards the normal
            # geometryRoughness: the derivatives of three's nonPerturbedNormal, the normal before normal mapping
            rough_rows = three_roughness(scene.camera, prim.rows, s.n if s.n_unmapped is None else s.n_unmapped,
                                         s.roughness)
        if spec is None:
            lod = np.asarray(level_of_roughness(s.roughness, levels), dtype=np.float64)
        else:  # the engine's level curve
            lod = np.asarray(spec.lod(rough_rows, levels, int(np.asarray(chain[0]).shape[1])), dtype=np.float64)
            if spec.dominant_direction:
                refl = specular_dominant_direction(s.n, refl, rough_rows)
        prefiltered = sampler(env.to_env_frame(refl), lod) * env.intensity
        coat_prefiltered = np.zeros((count, 3))
        coated = np.flatnonzero(coat_roughness >= 0.0)
        coat_n = coat_normals(mat_f, s.material, n_rows)  # n_rows itself where no coat has a normal of its own
        if coated.size:  # a clear coat: a second lookup at its own roughness, about its own (unbent) normal
            cn = coat_n[coated]
            nov = np.sum(cn * v[coated], axis=1, keepdims=True)
            coat_dir = 2.0 * nov * cn - v[coated]
            coat_prefiltered[coated] = sampler(env.to_env_frame(coat_dir),
                                               level_of_roughness(coat_roughness[coated], levels)) * env.intensity
        # the sheen's lookups: only the extended forms' extras read them (a scene without one passes
        # a single zero row instead of a per-pixel array)
        extended = bool(np.isin(mat_i[:, 0], _EXTENDED).any())
        sheen_prefiltered = (_sheen_lookups(bake, env, sampler, s.n, v, sheen_roughness, levels) if extended
                             else np.zeros((1, 3)))
        charlie = _charlie_rows(bake, n_rows, v_rows, sheen_roughness, engine) if extended else np.zeros(1)
        if spec is not None and spec.diffuse == "last-level":  # three: getIBLIrradiance, pi x the r = 1 level
            irradiance = math.pi * sampler(env.to_env_frame(s.n), np.full(count, levels - 1.0)) * env.intensity
        elif diffuse == "sh":
            irradiance = irradiance_from_sh(np.asarray(bake.sh), env.to_env_frame(s.n)) * env.intensity
        else:
            irradiance = CubeSampler(np.asarray(bake.irradiance))(env.to_env_frame(s.n)) * env.intensity
        t4 = time.perf_counter()
        timings["ibl_lookups"] = t4 - t3
        out = np.empty((count, 3))
        ec = np.empty((count, 3))
        transmitted = transmission_lookups(mat_i, mat_f, s, v, scene.camera.position, sampler, env.to_env_frame,
                                           levels, engine, camera_forward=scene.camera.basis()[2])
        if transmitted.shape[0] > 1:
            transmitted *= env.intensity
        dfg_sampled = np.zeros((1, 2))
        anisotropic = np.flatnonzero(mat_f[s.material, _ANISOTROPY_STRENGTH] > 0.0) if engine == "pbrkit" and \
            extended else np.zeros(0, dtype=np.int64)
        if anisotropic.size:  # KHR_materials_anisotropy: filtered importance sampling of the lobe itself
            lobe, d1, d2 = anisotropic_ibl(mat_i, mat_f, anisotropic, s, v_rows, surface_tangents(s), sampler,
                                           env.to_env_frame, levels, env.intensity)
            prefiltered[anisotropic] = lobe
            dfg_sampled = np.full((count, 2), np.nan)
            dfg_sampled[anisotropic, 0] = d1
            dfg_sampled[anisotropic, 1] = d2
        ibl_kernel = for_materials(_ibl_kernel, mat_i)
        ibl_kernel(mat_i, mat_f, mat, lut_index, tables, n_rows, v_rows, rough_rows, s.metallic, base_rows,
                   s.occlusion, np.ascontiguousarray(prefiltered, dtype=np.float64),
                   np.ascontiguousarray(irradiance, dtype=np.float64), coat_prefiltered, coat_roughness,
                   sheen_prefiltered, charlie, transmitted, dfg_sampled, bool(anisotropic.size),
                   sheen_albedo_table(), fresnel_mix_albedo_table(), diffuse_weight == "exact",
                   bool(energy_compensation), ENGINES.index(engine), out, ec)
        t5 = time.perf_counter()
        timings["ibl_shading"] = t5 - t4
        if len(geometry.area_lights):  # LTC: the same composition, with the lights' integrals for the bake's
            lt = area_light_ltc(geometry.area_lights, s.p, n_rows, v_rows, s.roughness, coat_roughness)
            spec = np.empty((count, 3))
            for_materials(_area_specular_kernel, mat_i)(mat_i, mat_f, mat, n_rows, s.roughness, s.metallic,
                                                        base_rows, lt.specular, lt.fresnel, lt.split, spec)
            irr, coat = lt.irradiance, lt.coat
            tilted = np.flatnonzero((coat_roughness >= 0.0) & np.any(coat_n != n_rows, axis=1))
            if tilted.size:  # a coat with its own normal: its lobe's LTC in the coat's frame
                coat[tilted] = area_light_ltc(geometry.area_lights, s.p[tilted], coat_n[tilted], v_rows[tilted],
                                              coat_roughness[tilted]).specular
            area = np.empty((count, 3))
            ibl_kernel(mat_i, mat_f, mat, lut_index, tables, n_rows, v_rows, s.roughness, s.metallic, base_rows,
                       np.ones(count), spec, irr, coat, coat_roughness, np.zeros((count if extended else 1, 3)),
                       np.zeros(count if extended else 1), np.zeros((1, 3)), np.zeros((1, 2)), False,
                       sheen_albedo_table(),
                       fresnel_mix_albedo_table(),
                       diffuse_weight == "exact", bool(energy_compensation), 0, area, np.empty((count, 3)))
            out += area
            t6 = time.perf_counter()
            timings["area_lights"] = t6 - t5
            t5 = t6
        out += punctual_radiance(geometry, s, v, mat_i, mat_f, ec if energy_compensation else None, shadows)
        # the emission, beneath the coat of a KHR_materials_clearcoat material (its README's
        # f0 0.04; the Sample Viewer's from the material's IOR under engine khronos)
        coat_f0 = COAT_F0 if engine != "khronos" else f0_from_ior(mat_f[s.material, COLUMNS.ior])
        out += emission_seen(mat_i, mat_f, s.material,
                             np.einsum("ij,ij->i", coat_n, v_rows), s.emissive, coat_f0)
        radiance[prim.rows] = out
        timings["punctual"] = time.perf_counter() - t5
    image, mask = _resolve(scene, radiance, prim.hit)
    timings["total"] = time.perf_counter() - t0
    stats = {"mode": "realtime", "timings": timings, "bake_levels": len(bake.specular),
             "bake_size": int(np.asarray(bake.specular[0]).shape[1]), "diffuse": diffuse,
             "energy_compensation": bool(energy_compensation), "shadows": bool(shadows),
             "diffuse_weight": diffuse_weight, "engine": engine,
             "pixels": int(scene.camera.width * scene.camera.height)}
    return RenderResult(image, mask, None, stats)


