"""One vertex of the ground truth's paths, the estimator of
:mod:`pbrkit.rendering.estimator` at a surface point (:func:`_vertex`, and
:func:`_transmissive_vertex` for materials that transmit), and the environment a
BxDF sample escapes to (:func:`_env_miss`): what the fused kernel
(:mod:`pbrkit.rendering.reference`) and the wavefront loop (:mod:`pbrkit.rendering.wavefront`)
call per path and bounce, with the same random numbers (the lane kernel,
:mod:`pbrkit.rendering.lanes`, schedules the same estimator in SIMD lanes).
"""

from __future__ import annotations

from ..brdf.dispatch import core_substitute, lobe_probabilities
from ..brdf.transmission import transmissive_probabilities
from ..core.jit import dual_use
from ..sampling.random import _uniform
from .area_lights import area_light_sample
from .environment import _env_pdf_texel, _env_sample, _env_texel
from .estimator import (
    STRATEGY_MIS,
    Shading,
    bsdf_sample,
    emission_weight,
    light_sample,
    transmissive_bsdf_sample,
    transmissive_light_sample,
)
from .materials import hit_bxdf

__all__ = []


@dual_use
def _vertex(key, strategy, materials, env, area, m, px, py, pz, gx, gy, gz, nx, ny, nz, vx, vy, vz, rough, metal,
            b0, b1, b2, tangent):
    """The samples of one path vertex (the estimator of :mod:`pbrkit.rendering.estimator`
    with the random numbers of ``key``) at a point of material ``m`` with the textured
    roughness, metallic and base colour, geometric normal g, shading normal n, seen
    from v, and the surface's ``tangent`` (:func:`pbrkit.rendering.materials.hit_bxdf`).  Returns (environment direction (3), its contribution (3, unshadowed,
    MIS-weighted), area-light direction (3), the distance to the light, its
    contribution (3, unshadowed, MIS-weighted), BRDF direction (3), BRDF weight
    f cos / pdf (3), BRDF pdf); the contributions are 0 where a sample gives nothing,
    the BRDF weight and pdf 0 where the path ends.  ``strategy``: an index into
    :data:`pbrkit.rendering.estimator.STRATEGIES`.  The area light is picked uniformly
    among the scene's (probability 1 / A), then sampled by
    :func:`pbrkit.rendering.area_lights.area_light_sample`.  The BRDF, its sampling
    routine and pdf are the material's BxDF (:mod:`pbrkit.brdf.bxdf`).  A light
    sample below the surface (g.l <= 0) or of zero pdf is not evaluated.  A material that
    transmits takes :func:`_transmissive_vertex` instead (the engines choose, only in
    scenes that have one: this function stays the opaque materials' own)."""
    z3 = (0.0, 0.0, 0.0)
    nov = nx * vx + ny * vy + nz * vz
    if nov <= 0.0 or gx * vx + gy * vy + gz * vz <= 0.0:
        return z3, z3, z3, 0.0, z3, z3, z3, 0.0
    b, t, bt = hit_bxdf(materials.codes, materials.params, m, rough, metal, b0, b1, b2, nx, ny, nz, tangent)
    at = Shading((nx, ny, nz), t, bt, (gx, gy, gz), (vx, vy, vz))
    p_spec, p_coat = lobe_probabilities(b, nov)
    # --- environment sample
    light_dir = z3
    light_val = z3
    if strategy == STRATEGY_MIS:
        lx, ly, lz, pdf_e, ei, ej = _env_sample(env.func, env.total, env.alias, env.rows, env.cos, env.sin,
                                                _uniform(key, 0), _uniform(key, 1))
        light_dir = (lx, ly, lz)
        if pdf_e > 0.0 and gx * lx + gy * ly + gz * lz > 0.0:
            radiance = env.radiance
            light_val = light_sample(b, at, p_spec, p_coat, lx, ly, lz, pdf_e, radiance[ei, ej, 0],
                                     radiance[ei, ej, 1], radiance[ei, ej, 2])
    # --- area-light sample
    area_dir = z3
    area_dist = 0.0
    area_val = z3
    n_area = area.codes.shape[0]
    if strategy == STRATEGY_MIS and n_area > 0:
        li = min(int(_uniform(key, 5) * n_area), n_area - 1)
        ax, ay, az, dist, pdf_a, r0, r1, r2 = area_light_sample(area.codes, area.values, area.vertices, li, px, py,
                                                                pz, _uniform(key, 6), _uniform(key, 7))
        if pdf_a > 0.0 and gx * ax + gy * ay + gz * az > 0.0:
            area_dir = (ax, ay, az)
            area_dist = dist
            area_val = light_sample(b, at, p_spec, p_coat, ax, ay, az, pdf_a / n_area, r0, r1, r2)
    # --- BRDF sample
    bsdf_dir, bsdf_w, pdf_b = bsdf_sample(b, at, p_spec, p_coat, _uniform(key, 4), _uniform(key, 2),
                                          _uniform(key, 3))
    return light_dir, light_val, area_dir, area_dist, area_val, bsdf_dir, bsdf_w, pdf_b


@dual_use
def _transmissive_vertex(key, strategy, materials, env, area, m, px, py, pz, gx, gy, gz, nx, ny, nz, vx, vy, vz,
                         rough, metal, b0, b1, b2, tangent):
    """:func:`_vertex` of a material that transmits (the same random numbers): the view
    on either side of the surface (the side of its geometric and shading normals must
    agree), light samples on either side
    (:func:`pbrkit.rendering.estimator.transmissive_light_sample`), the BSDF sample of
    :func:`pbrkit.rendering.estimator.transmissive_bsdf_sample`."""
    z3 = (0.0, 0.0, 0.0)
    nov = nx * vx + ny * vy + nz * vz
    if nov * (gx * vx + gy * vy + gz * vz) <= 0.0:
        return z3, z3, z3, 0.0, z3, z3, z3, 0.0
    b, t, bt = hit_bxdf(materials.codes, materials.params, m, rough, metal, b0, b1, b2, nx, ny, nz, tangent)
    at = Shading((nx, ny, nz), t, bt, (gx, gy, gz), (vx, vy, vz))
    p_t, p_spec, p_coat = transmissive_probabilities(b, nov)
    light_dir = z3
    light_val = z3
    if strategy == STRATEGY_MIS:
        lx, ly, lz, pdf_e, ei, ej = _env_sample(env.func, env.total, env.alias, env.rows, env.cos, env.sin,
                                                _uniform(key, 0), _uniform(key, 1))
        light_dir = (lx, ly, lz)
        if pdf_e > 0.0:
            radiance = env.radiance
            light_val = transmissive_light_sample(b, at, p_t, p_spec, p_coat, lx, ly, lz, pdf_e,
                                                  radiance[ei, ej, 0], radiance[ei, ej, 1], radiance[ei, ej, 2])
    area_dir = z3
    area_dist = 0.0
    area_val = z3
    n_area = area.codes.shape[0]
    if strategy == STRATEGY_MIS and n_area > 0:
        li = min(int(_uniform(key, 5) * n_area), n_area - 1)
        ax, ay, az, dist, pdf_a, r0, r1, r2 = area_light_sample(area.codes, area.values, area.vertices, li, px, py,
                                                                pz, _uniform(key, 6), _uniform(key, 7))
        if pdf_a > 0.0:
            area_dir = (ax, ay, az)
            area_dist = dist
            area_val = transmissive_light_sample(b, at, p_t, p_spec, p_coat, ax, ay, az, pdf_a / n_area, r0, r1, r2)
    bsdf_dir, bsdf_w, pdf_b = transmissive_bsdf_sample(b, at, p_t, p_spec, p_coat, _uniform(key, 4),
                                                       _uniform(key, 2), _uniform(key, 3))
    return light_dir, light_val, area_dir, area_dist, area_val, bsdf_dir, bsdf_w, pdf_b


@dual_use(inline="llvm")
def _transmits(media):
    """The engines' flag that the scene has materials that transmit, as the kernels read
    it: a kernel for the registered models' cores alone calls :func:`_opaque` instead
    (:func:`pbrkit.brdf.dispatch.core_substitute`), whose constant LLVM folds, so that
    it keeps no code of the media."""
    return media


@dual_use(inline="llvm")
def _opaque(media):
    """:func:`_transmits` in a kernel for materials without extensions: never."""
    return False


core_substitute(_transmits, _opaque)
core_substitute(_transmissive_vertex, _vertex)


@dual_use
def _env_miss(strategy, pdf_b, env, dx, dy, dz):
    """Radiance times the MIS weight of a BRDF sample (pdf ``pdf_b``) that reaches the
    environment along d (:func:`pbrkit.rendering.estimator.emission_weight`)."""
    radiance = env.radiance
    i, j = _env_texel(radiance.shape[0], radiance.shape[1], env.cos, env.sin, dx, dy, dz)
    w = emission_weight(strategy, pdf_b, _env_pdf_texel(env.func, env.total, i, j))
    return radiance[i, j, 0] * w, radiance[i, j, 1] * w, radiance[i, j, 2] * w
