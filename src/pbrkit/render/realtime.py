"""Real-time rendering (:func:`render_realtime`) is what an engine does with a bake
(:mod:`pbrkit.bake`): punctual lights evaluated with the model (with exact
shadow rays, as an ideal shadow map), plus split-sum image-based lighting
(Karis 2013, "Real Shading in Unreal Engine 4", "Image based lighting"):

- specular: the prefiltered chain sampled trilinearly (seam-aware,
  :class:`pbrkit.cubemap.CubeSampler`) in the mirror direction
  R = 2 (n.v) n - v at the fractional level ``level_of_roughness(r, M)``,
  times the DFG table (:mod:`pbrkit.tables`, texel centres, bilinear, clamp)
  as lerp(DFG1, DFG2, F0) = DFG1 + F0 (DFG2 - DFG1) (Filament sec. 5.3.4.3;
  f90 = 1).  The table's visibility matches the material's masking
  (height-correlated: the bake's table; separable; Schlick-GGX with
  k = alpha / 2 for UE4, whose IBL uses that remap); F0 is the model's (the
  metallic workflow's lerp, the exact conductor's F(1) for
  ``exact-conductor``, the constant colour S for ``fresnel = "none"``, where
  the albedo is S DFG2).  Optional energy compensation multiplies the
  specular lobes by 1 + F0 (1 / DFG2 - 1) (Filament sec. 4.7.2,
  :func:`pbrkit.tables.filament_energy_compensation`).
- diffuse: base_color / pi * E(n) * k_d with k_d = (1 - F*)(1 - metallic)
  (:func:`pbrkit.diffuse.kd_ibl`; seed 000) and E from the bake's SH
  (:func:`pbrkit.sh.irradiance_from_sh`) or its irradiance cube.
- the glTF occlusion texture scales both IBL terms; emission is added.

Known approximations of the real-time path (what ``compare`` measures):
the split sum itself (n = v = r in the prefilter, the lobe's shape), the
(1 - F*) factor on the diffuse, Lambert in place of Burley and GGX in place
of Beckmann / Blinn-Phong for the IBL, and the SH truncation.
"""

from __future__ import annotations

import time
from functools import lru_cache

import numba
import numpy as np

from ..albedo.tables import table_bilinear
from ..brdf.diffuse import kd_ibl
from ..brdf.fresnel import f_conductor
from ..core.jit import parallel_kernel
from .environment import EnvironmentLight
from .geometry import Geometry
from .primary import RenderResult, _primary, _resolve
from .punctual import _punctual
from .shading import (
    _INV_PI,
    _MF_ETA,
    _MF_F0D,
    _MF_K,
    _MF_SPEC,
    _MI_DIFF,
    _MI_FRES,
    _MI_MODEL,
    _f0_channel,
    material_tables,
)

__all__ = [
    "render_realtime",
]

# ================================================================ real time


@lru_cache(maxsize=8)
def _extra_lut(visibility, size):
    from ..albedo.tables import lookup_table

    return lookup_table("dfg", size, visibility)[0]


def _lut_for(spec, bake_lut):
    """The DFG table matching a material's masking (module docstring), and its name."""
    if spec.model == "ue4" or spec.masking in ("schlick-ggx", "schlick-ggx-ue4"):
        return _extra_lut("schlick-ggx", bake_lut.shape[0]), "schlick-ggx"
    if spec.masking == "separable":
        return _extra_lut("separable", bake_lut.shape[0]), "separable"
    return np.asarray(bake_lut), "height-correlated"


@parallel_kernel
def _ibl_kernel(mi, mf, mat, lut_index, tables, n, v, rough, metal, base, occlusion, prefiltered, irradiance,
                energy_compensation, out, ec_out):
    """Split-sum IBL per pixel (module docstring); writes the radiance and the
    energy-compensation factor (for the punctual lights)."""
    for i in numba.prange(n.shape[0]):
        m = mat[i]
        nov = max(n[i, 0] * v[i, 0] + n[i, 1] * v[i, 1] + n[i, 2] * v[i, 2], 1e-4)
        r = rough[i]
        t = lut_index[m]
        dfg1 = table_bilinear(tables, t, nov, r, 0)
        dfg2 = table_bilinear(tables, t, nov, r, 1)
        model = mi[m, _MI_MODEL]
        fres = mi[m, _MI_FRES]
        diffuse_on = model == 2 or model == 3 or mi[m, _MI_DIFF] != 2
        for c in range(3):
            b = base[i, c]
            if model == 0 and fres == 3:
                f0 = min(f_conductor(1.0, mf[m, _MF_ETA + c], mf[m, _MF_K + c]), 1.0)
            elif model == 0 and fres == 4:
                f0 = mf[m, _MF_F0D]
            elif model == 0 and fres == 5:
                f0 = mf[m, _MF_SPEC + c]
            else:
                f0 = _f0_channel(mi, mf, m, b, metal[i])
            if model == 0 and fres == 5:
                albedo = f0 * dfg2
            else:
                albedo = dfg1 + f0 * (dfg2 - dfg1)
            ec = 1.0
            if energy_compensation:
                ec = 1.0 + f0 * (1.0 / max(dfg2, 1e-6) - 1.0)
            ec_out[i, c] = ec
            spec = prefiltered[i, c] * albedo * ec
            diff = 0.0
            if diffuse_on:
                metal_part = metal[i] if not (model == 0 and fres == 4) else 0.0
                kd = kd_ibl(nov, f0, r, metal_part)
                if model == 3:
                    kd *= 0.96
                diff = b * kd * irradiance[i, c] * _INV_PI
            out[i, c] = (spec + diff) * occlusion[i]


def render_realtime(scene, geometry=None, env=None, bake=None, diffuse="sh", energy_compensation=False,
                    shadows=True, bake_size=256, bake_options=None):
    """Real-time shading of ``scene`` (module docstring).  ``diffuse``: ``sh`` (the
    bake's 9 SH coefficients) or ``cube`` (its irradiance cube).  Returns a
    :class:`RenderResult`; ``stats['timings']`` has the stages in seconds."""
    from ..ibl.cubemap import CubeSampler
    from ..ibl.prefilter import level_of_roughness
    from ..ibl.sh import irradiance_from_sh

    if diffuse not in ("sh", "cube"):
        raise ValueError(f"unknown diffuse source {diffuse!r}; use 'sh' or 'cube'")
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
    prim = _primary(scene, geometry)
    t3 = time.perf_counter()
    timings["primary_rays"] = t3 - t2
    s = prim.surface
    mat_i, mat_f = material_tables(geometry.materials)
    count = prim.rows.size
    v = -prim.dirs[prim.rows]
    radiance = np.zeros((prim.dirs.shape[0], 3))
    radiance[~prim.hit] = env.background(prim.dirs[~prim.hit])
    if count:
        # lookup tables per material
        tables, lut_index, names = [], np.zeros(len(geometry.materials), dtype=np.int64), []
        for mi, m in enumerate(geometry.materials):
            table, name = _lut_for(m.spec, bake.lut)
            if name not in names:
                names.append(name)
                tables.append(np.asarray(table, dtype=np.float64)[..., :2])
            lut_index[mi] = names.index(name)
        tables = np.ascontiguousarray(np.stack(tables))
        nov = np.sum(s.n * v, axis=1, keepdims=True)
        refl = 2.0 * nov * s.n - v
        levels = len(bake.specular)
        sampler = env.samplers.get(id(bake))
        if sampler is None or sampler[0] is not bake:
            sampler = (bake, CubeSampler([np.asarray(x) for x in bake.specular]))
            env.samplers[id(bake)] = sampler
        sampler = sampler[1]
        lod = np.asarray(level_of_roughness(s.roughness, levels), dtype=np.float64)
        prefiltered = sampler(env.to_env_frame(refl), lod) * env.intensity
        if diffuse == "sh":
            irradiance = irradiance_from_sh(np.asarray(bake.sh), env.to_env_frame(s.n)) * env.intensity
        else:
            irradiance = CubeSampler(np.asarray(bake.irradiance))(env.to_env_frame(s.n)) * env.intensity
        t4 = time.perf_counter()
        timings["ibl_lookups"] = t4 - t3
        out = np.empty((count, 3))
        ec = np.empty((count, 3))
        _ibl_kernel(mat_i, mat_f, np.ascontiguousarray(s.material), lut_index, tables, np.ascontiguousarray(s.n),
                    np.ascontiguousarray(v), s.roughness, s.metallic, np.ascontiguousarray(s.base_color),
                    s.occlusion, np.ascontiguousarray(prefiltered, dtype=np.float64),
                    np.ascontiguousarray(irradiance, dtype=np.float64), bool(energy_compensation), out, ec)
        t5 = time.perf_counter()
        timings["ibl_shading"] = t5 - t4
        out += _punctual(geometry, s, v, mat_i, mat_f, ec if energy_compensation else None, shadows)
        out += s.emissive
        radiance[prim.rows] = out
        timings["punctual"] = time.perf_counter() - t5
    image, mask = _resolve(scene, radiance, prim.hit)
    timings["total"] = time.perf_counter() - t0
    stats = {"mode": "realtime", "timings": timings, "bake_levels": len(bake.specular),
             "bake_size": int(np.asarray(bake.specular[0]).shape[1]), "diffuse": diffuse,
             "energy_compensation": bool(energy_compensation), "shadows": bool(shadows),
             "pixels": int(scene.camera.width * scene.camera.height)}
    return RenderResult(image, mask, None, stats)


