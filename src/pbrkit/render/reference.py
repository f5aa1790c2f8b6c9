"""Monte Carlo ground truth (:func:`render_reference`) integrates the same BRDF times
cos against the full environment and the lights by Monte Carlo, per pixel
(Veach 1997, "Robust Monte Carlo Methods for Light Transport Simulation",
ch. 9):

- environment importance sampling from the piecewise-constant equirect
  radiance: a 2-D distribution over (u, v) proportional to
  luminance(i, j) sin(theta_i), sampled as a marginal over rows and a
  conditional over columns (pbrt-v4, Pharr, Jakob and Humphreys 2023,
  sec. A.5.6 ``PiecewiseConstant2D`` and sec. 12.5.2 image infinite lights),
  with the solid-angle pdf p(u, v) / (2 pi^2 sin theta);
- BRDF sampling: GGX visible normals (Heitz 2018,
  :func:`pbrkit.microfacet.ggx.warp_ggx_vndf`) for the specular lobe and cosine
  sampling for the diffuse one, mixed by an estimate of their albedos;
- multiple importance sampling with the power heuristic (beta = 2; Veach
  1997, sec. 9.2.4), occlusion by shadow rays;
- punctual lights evaluated exactly (with shadow rays) at every vertex;
  emissive surfaces hit by BRDF samples add their emission;
- ``bounces`` = 0 is direct lighting; each further bounce continues the
  path in the sampled BRDF direction (next-event estimation + MIS at every
  vertex).  The per-pixel standard error of the mean is returned with it.
- materials that transmit (``KHR_materials_transmission``, ``KHR_materials_volume``;
  :mod:`pbrkit.brdf.transmission`) continue paths through the surface: light and BSDF
  samples on both sides (:mod:`pbrkit.render.estimator`), rays leaving from the side
  they go to, and inside a volume (a closed surface of thickness > 0, its normals
  outward) the Beer-Lambert transmittance of the real path length, internal
  reflections included.  Scenes with such materials run direct lighting in the fused
  kernel rather than the lanes (punctual lights do not shine through them yet);
- visibility is traced, so the glTF occlusion texture (a real-time stand-in
  for it) is not applied; ``occlusion=False`` instead lets every surface see
  the whole environment unblocked by the other objects, as real-time IBL
  assumes, to isolate the shading approximations in a comparison.  Punctual
  lights cast shadows either way (exact shadow rays, as the real-time path's
  ideal shadow map), so both modes light a point the same way.
- the estimator is written once, as scalar functions
  (:mod:`pbrkit.render.estimator`, which derives it), and so are the pixel's sums
  (:mod:`pbrkit.render.film`); three engines schedule them.  Scenes of spheres
  and planes run in one fused kernel per pixel (all samples, ray casting
  included): direct lighting (``bounces`` = 0) in SIMD lanes
  (:mod:`pbrkit.render.lanes`), paths with bounces sample by sample
  (:func:`_fused_kernel`, one :func:`_vertex` per bounce); scenes with triangle
  meshes run as a wavefront loop over the samples (:func:`_wavefront`, the same
  :func:`_vertex` on every path of a bounce at once), casting with Embree.  All
  give the same numbers for the same scene (tested), and the same bytes for any
  thread count.  The kernels take the scene as a few records of arrays
  (:mod:`pbrkit.render.records`).
"""

from __future__ import annotations

import time
from typing import NamedTuple

import numpy as np

from ..brdf.dispatch import core_substitute, emission_coat, lobe_probabilities
from ..brdf.lobes.clearcoat import coated_emission
from ..brdf.transmission import (
    absorption,
    sigma_a,
    transmissive_material,
    transmissive_probabilities,
    volume_material,
)
from ..brdf.shading.registry import COLUMNS
from ..core import checks
from ..core.jit import dual_use, row_kernel, run_in_threads, threaded_kernel
from ..sampling.random import _path_key, _uniform
from .area_lights import area_light_hit, area_light_sample
from .environment import EnvironmentLight, _env_pdf_texel, _env_sample, _env_texel
from .estimator import (
    STRATEGIES,
    STRATEGY_MIS,
    Shading,
    area_emission,
    area_shadow_t,
    bsdf_sample,
    emission_weight,
    light_sample,
    ray_origin,
    transmissive_bsdf_sample,
    transmissive_light_sample,
)
from .film import Film, film_estimate, new_film, shifted_add, store_pixel
from .geometry import Geometry
from .lanes import direct_lighting
from .materials import COAT_F0, emission_seen, for_materials, hit_bxdf, material_tables
from .primary import RenderResult, _background, _primary
from .primitives import KIND_NONE, KIND_SPHERE, analytic_surface, trace_analytic
from .punctual import punctual_at, punctual_radiance
from .records import Materials, Points, analytic_shapes, area_arrays, environment_arrays, punctual_lights

__all__ = [
    "render_reference",
]

#: Columns of the packed parameter row the kernels read.
_EMISSIVE = COLUMNS.emissive
_ROUGHNESS = COLUMNS.roughness
_METALLIC = COLUMNS.metallic
_BASE_COLOR = COLUMNS.base_color
_TRANSMISSION = COLUMNS.transmission


@dual_use
def _vertex(key, strategy, materials, env, area, m, px, py, pz, gx, gy, gz, nx, ny, nz, vx, vy, vz, rough, metal,
            b0, b1, b2):
    """The samples of one path vertex (the estimator of :mod:`pbrkit.render.estimator`
    with the random numbers of ``key``) at a point of material ``m`` with the textured
    roughness, metallic and base colour, geometric normal g, shading normal n, seen
    from v.  Returns (environment direction (3), its contribution (3, unshadowed,
    MIS-weighted), area-light direction (3), the distance to the light, its
    contribution (3, unshadowed, MIS-weighted), BRDF direction (3), BRDF weight
    f cos / pdf (3), BRDF pdf); the contributions are 0 where a sample gives nothing,
    the BRDF weight and pdf 0 where the path ends.  ``strategy``: an index into
    :data:`pbrkit.render.estimator.STRATEGIES`.  The area light is picked uniformly
    among the scene's (probability 1 / A), then sampled by
    :func:`pbrkit.render.area_lights.area_light_sample`.  The BRDF, its sampling
    routine and pdf are the material's BxDF (:mod:`pbrkit.brdf.bxdf`).  A light
    sample below the surface (g.l <= 0) or of zero pdf is not evaluated.  A material that
    transmits takes :func:`_transmissive_vertex` instead (the engines choose, only in
    scenes that have one: this function stays the opaque materials' own)."""
    z3 = (0.0, 0.0, 0.0)
    nov = nx * vx + ny * vy + nz * vz
    if nov <= 0.0 or gx * vx + gy * vy + gz * vz <= 0.0:
        return z3, z3, z3, 0.0, z3, z3, z3, 0.0
    b, t, bt = hit_bxdf(materials.codes, materials.params, m, rough, metal, b0, b1, b2, nx, ny, nz)
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
                         rough, metal, b0, b1, b2):
    """:func:`_vertex` of a material that transmits (the same random numbers): the view
    on either side of the surface (the side of its geometric and shading normals must
    agree), light samples on either side
    (:func:`pbrkit.render.estimator.transmissive_light_sample`), the BSDF sample of
    :func:`pbrkit.render.estimator.transmissive_bsdf_sample`."""
    z3 = (0.0, 0.0, 0.0)
    nov = nx * vx + ny * vy + nz * vz
    if nov * (gx * vx + gy * vy + gz * vz) <= 0.0:
        return z3, z3, z3, 0.0, z3, z3, z3, 0.0
    b, t, bt = hit_bxdf(materials.codes, materials.params, m, rough, metal, b0, b1, b2, nx, ny, nz)
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
    environment along d (:func:`pbrkit.render.estimator.emission_weight`)."""
    radiance = env.radiance
    i, j = _env_texel(radiance.shape[0], radiance.shape[1], env.cos, env.sin, dx, dy, dz)
    w = emission_weight(strategy, pdf_b, _env_pdf_texel(env.func, env.total, i, j))
    return radiance[i, j, 0] * w, radiance[i, j, 1] * w, radiance[i, j, 2] * w


@threaded_kernel
def _fused_kernel(start, stop, seed, spp, k2, bounces, strategy, occlusion, media, base_value, hits, materials, env,
                  shapes, lights, area, film):
    """Every sample of every pixel of an analytic scene (spheres, planes) in one pass:
    rows are the (pixel, sub-pixel) rays; sample j of a pixel uses sub-pixel j mod k2.
    ``base_value`` (rays, 3) is the deterministic part of each ray (background, or
    emission + punctual light at the primary hit); ``hits`` the primary hits
    (:class:`pbrkit.render.records.Points`; rows with material < 0 missed).  Each
    bounce is one :func:`_vertex`, whose samples it traces: shadow rays for the light
    samples, then the BRDF sample's ray, which meets an area light, the environment
    or the next surface.  Per pixel it accumulates the shifted sums of ``film``
    (:mod:`pbrkit.render.film`).  It runs pixels ``start`` to ``stop``, handed out to
    threads by :func:`pbrkit.core.jit.run_in_threads`.  ``media``: the scene has
    materials that transmit; then each ray leaves from the side of the surface it goes
    to (:func:`pbrkit.render.estimator.ray_origin`), and the path keeps the medium it is
    in (the last volume boundary it crossed inwards, by the sign of its geometric
    normal, until it crosses one outwards) and takes its Beer-Lambert transmittance
    over each segment (:func:`pbrkit.brdf.transmission.absorption`)."""
    media = _transmits(media)
    p = hits.p
    ng = hits.ng
    n = hits.n
    v = hits.v
    mat = hits.material
    rough = hits.roughness
    metal = hits.metallic
    base = hits.base_color
    mi = materials.codes
    mf = materials.params
    spheres = shapes.spheres
    lo = shapes.lo
    hi = shapes.hi
    skip = shapes.skip
    first = shapes.first
    count = shapes.count
    order = shapes.order
    planes = shapes.planes
    sphere_mat = shapes.sphere_material
    plane_mat = shapes.plane_material
    eps = shapes.eps
    codes = lights.codes
    values = lights.values
    acodes = area.codes
    avalues = area.values
    averts = area.vertices
    n_area = acodes.shape[0]
    for pix in range(start, stop):
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        q0 = 0.0
        q1 = 0.0
        q2 = 0.0
        h0 = 0.0  # the shift: the pixel's first sample
        h1 = 0.0
        h2 = 0.0
        for j in range(spp):
            row = pix * k2 + (j % k2)
            x0 = base_value[row, 0]
            x1 = base_value[row, 1]
            x2 = base_value[row, 2]
            m = mat[row]
            if m >= 0:
                px, py, pz = p[row, 0], p[row, 1], p[row, 2]
                gx, gy, gz = ng[row, 0], ng[row, 1], ng[row, 2]
                nx, ny, nz = n[row, 0], n[row, 1], n[row, 2]
                vx, vy, vz = v[row, 0], v[row, 1], v[row, 2]
                r = rough[row]
                me = metal[row]
                b0, b1, b2 = base[row, 0], base[row, 1], base[row, 2]
                t0 = t1 = t2 = 1.0
                medium = -1
                for bounce in range(bounces + 1):
                    key = _path_key(seed, pix, j, bounce)
                    if media and transmissive_material(mi, mf, m):
                        ldir, lval, adir, adist, aval, bdir, bw, pdf_b = _transmissive_vertex(
                            key, strategy, materials, env, area, m, px, py, pz, gx, gy, gz, nx, ny, nz, vx, vy, vz, r,
                            me, b0, b1, b2)
                    else:
                        ldir, lval, adir, adist, aval, bdir, bw, pdf_b = _vertex(
                            key, strategy, materials, env, area, m, px, py, pz, gx, gy, gz, nx, ny, nz, vx, vy, vz, r,
                            me, b0, b1, b2)
                    ox = px + eps * gx
                    oy = py + eps * gy
                    oz = pz + eps * gz
                    lx_, ly_, lz_ = ox, oy, oz
                    if media:  # each ray from the side it goes to
                        lx_, ly_, lz_ = ray_origin(px, py, pz, gx, gy, gz, ldir[0], ldir[1], ldir[2], eps)
                    if lval[0] > 0.0 or lval[1] > 0.0 or lval[2] > 0.0:
                        hk = KIND_NONE
                        if occlusion:  # the objects and the area lights hide the environment
                            hk = trace_analytic(lx_, ly_, lz_, ldir[0], ldir[1], ldir[2], 0.0, np.inf, True, spheres,
                                                lo, hi, skip, first, count, order, planes)[1]
                            if hk == KIND_NONE and n_area:
                                if area_light_hit(acodes, avalues, averts, lx_, ly_, lz_, ldir[0],
                                                  ldir[1], ldir[2], np.inf)[1] >= 0:
                                    hk = KIND_SPHERE
                        if hk == KIND_NONE:
                            x0 += t0 * lval[0]
                            x1 += t1 * lval[1]
                            x2 += t2 * lval[2]
                    if aval[0] > 0.0 or aval[1] > 0.0 or aval[2] > 0.0:
                        hk = KIND_NONE
                        if occlusion:  # shadow ray to the light point: objects and other area lights
                            tmax = area_shadow_t(adist)
                            ax_, ay_, az_ = ox, oy, oz
                            if media:
                                ax_, ay_, az_ = ray_origin(px, py, pz, gx, gy, gz, adir[0], adir[1], adir[2], eps)
                            hk = trace_analytic(ax_, ay_, az_, adir[0], adir[1], adir[2], 0.0, tmax, True, spheres, lo,
                                                hi, skip, first, count, order, planes)[1]
                            if hk == KIND_NONE and area_light_hit(acodes, avalues, averts, ax_, ay_, az_,
                                                                  adir[0], adir[1], adir[2], tmax)[1] >= 0:
                                hk = KIND_SPHERE
                        if hk == KIND_NONE:
                            x0 += t0 * aval[0]
                            x1 += t1 * aval[1]
                            x2 += t2 * aval[2]
                    if pdf_b <= 0.0 or (bw[0] <= 0.0 and bw[1] <= 0.0 and bw[2] <= 0.0):
                        break
                    if media:
                        ox, oy, oz = ray_origin(px, py, pz, gx, gy, gz, bdir[0], bdir[1], bdir[2], eps)
                    th, hk, hi_ = np.inf, KIND_NONE, -1
                    if occlusion:
                        th, hk, hi_ = trace_analytic(ox, oy, oz, bdir[0], bdir[1], bdir[2], 0.0, np.inf, False, spheres,
                                                     lo, hi, skip, first, count, order, planes)
                    t0 *= bw[0]
                    t1 *= bw[1]
                    t2 *= bw[2]
                    if media:  # the medium of this segment, and its transmittance
                        if volume_material(mi, mf, m):
                            medium = m if gx * bdir[0] + gy * bdir[1] + gz * bdir[2] < 0.0 else -1
                        if medium >= 0:
                            ab = absorption(mf, medium, th)
                            t0 *= ab[0]
                            t1 *= ab[1]
                            t2 *= ab[2]
                    if n_area:  # an area light before the next surface (any, without occlusion)
                        at, ai, a0, a1, a2 = area_light_hit(acodes, avalues, averts, ox, oy, oz,
                                                            bdir[0], bdir[1], bdir[2], th)
                        if ai >= 0:
                            le = area_emission(strategy, pdf_b, area, ai, px, py, pz, bdir[0], bdir[1], bdir[2], at,
                                               a0, a1, a2)
                            x0 += t0 * le[0]
                            x1 += t1 * le[1]
                            x2 += t2 * le[2]
                            if occlusion:  # the light is opaque: the path ends on it
                                break
                    if hk == KIND_NONE:
                        le = _env_miss(strategy, pdf_b, env, bdir[0], bdir[1], bdir[2])
                        x0 += t0 * le[0]
                        x1 += t1 * le[1]
                        x2 += t2 * le[2]
                        break
                    px, py, pz, nx, ny, nz, m = analytic_surface(hk, hi_, spheres, planes, sphere_mat, plane_mat, mf,
                                                                  ox, oy, oz, bdir[0], bdir[1], bdir[2], th)
                    ec = 1.0
                    wc = emission_coat(mi, m, mf, m)
                    if wc > 0.0:  # a coat over the emission (KHR_materials_clearcoat)
                        ec = coated_emission(wc, COAT_F0, nx * bdir[0] + ny * bdir[1] + nz * bdir[2])
                    x0 += t0 * mf[m, _EMISSIVE] * ec
                    x1 += t1 * mf[m, _EMISSIVE + 1] * ec
                    x2 += t2 * mf[m, _EMISSIVE + 2] * ec
                    if bounce == bounces:
                        break
                    gx, gy, gz = nx, ny, nz
                    vx, vy, vz = -bdir[0], -bdir[1], -bdir[2]
                    r = mf[m, _ROUGHNESS]
                    me = mf[m, _METALLIC]
                    b0, b1, b2 = mf[m, _BASE_COLOR], mf[m, _BASE_COLOR + 1], mf[m, _BASE_COLOR + 2]
                    if codes.shape[0]:
                        bh, th_, bth = hit_bxdf(mi, mf, m, r, me, b0, b1, b2, nx, ny, nz)
                        pr = punctual_at(bh, th_, bth, px, py, pz, gx, gy, gz, nx, ny, nz, vx, vy, vz, 1.0, 1.0,
                                         1.0, codes, values, eps, True, spheres, lo, hi, skip, first, count, order,
                                         planes)
                        x0 += t0 * pr[0]
                        x1 += t1 * pr[1]
                        x2 += t2 * pr[2]
            if j == 0:
                h0, h1, h2 = x0, x1, x2
            s0, q0 = shifted_add(h0, s0, q0, x0, 1)
            s1, q1 = shifted_add(h1, s1, q1, x1, 1)
            s2, q2 = shifted_add(h2, s2, q2, x2, 1)
        store_pixel(film, pix, h0, h1, h2, s0, s1, s2, q0, q1, q2)


# ------------------------------------------------- wavefront (scenes with meshes)


class VertexSamples(NamedTuple):
    """:func:`_vertex`'s results for a wavefront of path vertices, one row each."""

    light_dir: np.ndarray
    light_val: np.ndarray
    area_dir: np.ndarray
    area_dist: np.ndarray  # how far the shadow ray looks (area_shadow_t)
    area_val: np.ndarray
    bsdf_dir: np.ndarray
    bsdf_w: np.ndarray
    bsdf_pdf: np.ndarray


def _vertex_samples(count):
    """Empty :class:`VertexSamples` for ``count`` vertices."""
    vec = lambda: np.empty((count, 3))  # noqa: E731
    return VertexSamples(vec(), vec(), vec(), np.empty(count), vec(), vec(), vec(), np.empty(count))


@row_kernel(lambda seed, sample, bounce, strategy, media, pixel, *rest: pixel.shape[0])
def _vertex_batch(start, stop, seed, sample, bounce, strategy, media, pixel, points, materials, env, area, out):
    media = _transmits(media)
    p = points.p
    ng = points.ng
    n = points.n
    v = points.v
    mat = points.material
    rough = points.roughness
    metal = points.metallic
    base = points.base_color
    light_dir = out.light_dir
    light_val = out.light_val
    area_dir = out.area_dir
    area_dist = out.area_dist
    area_val = out.area_val
    bsdf_dir = out.bsdf_dir
    bsdf_w = out.bsdf_w
    bsdf_pdf = out.bsdf_pdf
    for i in range(start, stop):
        key = _path_key(seed, pixel[i], sample, bounce)
        if media and transmissive_material(materials.codes, materials.params, mat[i]):
            ldir, lval, adir, adist, aval, bdir, bw, pdf_b = _transmissive_vertex(
                key, strategy, materials, env, area, mat[i], p[i, 0], p[i, 1], p[i, 2], ng[i, 0], ng[i, 1], ng[i, 2],
                n[i, 0], n[i, 1], n[i, 2], v[i, 0], v[i, 1], v[i, 2], rough[i], metal[i], base[i, 0], base[i, 1],
                base[i, 2])
        else:
            ldir, lval, adir, adist, aval, bdir, bw, pdf_b = _vertex(
                key, strategy, materials, env, area, mat[i], p[i, 0], p[i, 1], p[i, 2], ng[i, 0], ng[i, 1], ng[i, 2],
                n[i, 0], n[i, 1], n[i, 2], v[i, 0], v[i, 1], v[i, 2], rough[i], metal[i], base[i, 0], base[i, 1],
                base[i, 2])
        for a in range(3):
            light_dir[i, a] = ldir[a]
            light_val[i, a] = lval[a]
            area_dir[i, a] = adir[a]
            area_val[i, a] = aval[a]
            bsdf_dir[i, a] = bdir[a]
            bsdf_w[i, a] = bw[a]
        area_dist[i] = area_shadow_t(adist)
        bsdf_pdf[i] = pdf_b


@row_kernel(4)
def _area_emission_batch(start, stop, strategy, pdf_b, area, index, p, d, t, radiance, out):
    for i in range(start, stop):
        le = area_emission(strategy, pdf_b[i], area, index[i], p[i, 0], p[i, 1], p[i, 2], d[i, 0], d[i, 1], d[i, 2],
                           t[i], radiance[i, 0], radiance[i, 1], radiance[i, 2])
        out[i, 0] = le[0]
        out[i, 1] = le[1]
        out[i, 2] = le[2]


@row_kernel(2)
def _miss_batch(start, stop, strategy, pdf_b, d, env, out):
    for i in range(start, stop):
        le = _env_miss(strategy, pdf_b[i], env, d[i, 0], d[i, 1], d[i, 2])
        out[i, 0] = le[0]
        out[i, 1] = le[1]
        out[i, 2] = le[2]


def _wavefront(geometry, env, prim, base_value, k2, n_pixels, spp, bounces, seed, strategy, occlusion, materials,
               scene=None):
    """Every sample of a scene with triangle meshes (Embree) as a loop over samples and
    bounces, each step on the whole wavefront of paths at once (:func:`_vertex_batch`,
    then shadow rays, BRDF rays and what they meet); returns the :class:`Film`.  In a
    scene with glTF BLEND surfaces each sample casts its primary rays again, so that
    their coverage (:mod:`pbrkit.render.alpha`) is drawn per sample."""
    envs = environment_arrays(env)
    area = area_arrays(geometry)
    has_area = len(geometry.area_lights) > 0
    # volume boundaries and their media's absorption (the fused kernel's media, per path)
    volume, sigma = _media_tables(materials)
    media = bool(volume.any())
    transmits = bool(np.any(materials.params[:, _TRANSMISSION] > 0.0))
    total_sum = np.zeros((n_pixels, 3))
    total_sq = np.zeros((n_pixels, 3))
    blend = scene is not None and geometry.blends
    ray_pixel = np.arange(prim.dirs.shape[0]) // k2
    ray_sub = np.arange(prim.dirs.shape[0]) % k2
    for j in range(spp):
        sub = j % k2
        if blend:  # this sample's primary rays (ray = pixel * k2 + sub), their coverage drawn anew
            ids = np.arange(sub, prim.dirs.shape[0], k2)
            pj = _primary(scene, geometry, salt=j + 1, rays=ids)
            x = _base_values(pj, geometry, env, materials)
            rows = ids[pj.rows]
            sj = pj.surface
            surf_p, surf_ng, surf_n, surf_mat = sj.p, sj.ng, sj.n, sj.material
            surf_r, surf_m, surf_b = sj.roughness, sj.metallic, sj.base_color
        else:
            x = base_value[sub::k2].copy()  # rays are pixel-major: ray = pixel * k2 + sub
            sel = np.flatnonzero(ray_sub[prim.rows] == sub)
            rows = prim.rows[sel]
            surf_p = prim.surface.p[sel]
            surf_ng = prim.surface.ng[sel]
            surf_n = prim.surface.n[sel]
            surf_mat = prim.surface.material[sel]
            surf_r = prim.surface.roughness[sel]
            surf_m = prim.surface.metallic[sel]
            surf_b = prim.surface.base_color[sel]
        v = -prim.dirs[rows]
        pix = ray_pixel[rows]
        through = np.ones((rows.size, 3))
        medium = np.full(rows.size, -1, dtype=np.int64)
        for bounce in range(bounces + 1):
            count = pix.size
            if count == 0:
                break
            vs = _vertex_samples(count)
            points = Points(*(np.ascontiguousarray(a) for a in (surf_p, surf_ng, surf_n, v, surf_mat, surf_r,
                                                                 surf_m, surf_b)))
            for_materials(_vertex_batch, materials.codes)(seed, j, bounce, strategy, transmits, pix.astype(np.int64),
                                                          points, materials, envs, area, vs)
            ldir, lval, adir, adist, aval, bdir, bw, bpdf = vs
            for direction, value, tmax in ((ldir, lval, None), (adir, aval, adist)):
                lit = np.flatnonzero(np.any(value > 0.0, axis=1))
                if lit.size and occlusion:  # the objects and the area lights cast shadows
                    origins = geometry.offset_origins(surf_p[lit], surf_ng[lit], direction[lit])
                    far = None if tmax is None else tmax[lit]
                    blocked = geometry.occluded(origins, direction[lit], far)
                    if has_area:
                        blocked |= geometry.area_light_hits(origins, direction[lit], far)[1] >= 0
                    lit = lit[~blocked]
                np.add.at(x, pix[lit], through[lit] * value[lit])
            go = np.flatnonzero((bpdf > 0.0) & np.any(bw > 0.0, axis=1))
            if go.size == 0:
                break
            origins = geometry.offset_origins(surf_p[go], surf_ng[go], bdir[go])
            dirs = np.ascontiguousarray(bdir[go])
            through = through[go] * bw[go]
            pix = pix[go]
            hits = geometry.intersect(origins, dirs) if occlusion else None
            if media:  # the medium of this segment (by the side of the boundary it leaves to), its transmittance
                mat_go = surf_mat[go]
                entering = np.sum(surf_ng[go] * dirs, axis=1) < 0.0
                medium = np.where(volume[mat_go], np.where(entering, mat_go, -1), medium[go])
                inside = np.flatnonzero(medium >= 0)
                if inside.size:
                    length = np.full(go.size, np.inf) if hits is None else hits.t
                    s_in = sigma[medium[inside]]
                    with np.errstate(invalid="ignore", over="ignore"):
                        through[inside] *= np.where(s_in > 0.0, np.exp(-s_in * length[inside, None]), 1.0)
            escaped = np.ones(go.size, dtype=bool) if hits is None else ~hits.hit
            if has_area:  # an area light before the next surface (any, without occlusion)
                at, ai, radiance = geometry.area_light_hits(origins, dirs, None if hits is None else hits.t)
                seen = np.flatnonzero(ai >= 0)
                if seen.size:
                    le = np.empty((seen.size, 3))
                    _area_emission_batch(strategy, np.ascontiguousarray(bpdf[go][seen]), area, ai[seen],
                                         np.ascontiguousarray(surf_p[go][seen]), np.ascontiguousarray(dirs[seen]),
                                         at[seen], radiance[seen], le)
                    np.add.at(x, pix[seen], through[seen] * le)
                    if hits is not None:  # the light is opaque: those paths end on it
                        escaped[seen] = False
                        hits.kind[seen] = KIND_NONE
            miss = np.flatnonzero(escaped)
            if miss.size:
                le = np.empty((miss.size, 3))
                _miss_batch(strategy, np.ascontiguousarray(bpdf[go][miss]), np.ascontiguousarray(dirs[miss]), envs,
                            le)
                np.add.at(x, pix[miss], through[miss] * le)
            if hits is None:
                break
            hit = np.flatnonzero(hits.hit)
            if hit.size == 0:
                break
            surface = geometry.surface(hits, origins, dirs, hit)
            seen = emission_seen(materials.codes, materials.params, surface.material,
                                 -np.einsum("ij,ij->i", surface.n, dirs[hit]), surface.emissive)
            np.add.at(x, pix[hit], through[hit] * seen)
            if bounce == bounces:
                break
            through = through[hit]
            pix = pix[hit]
            if media:
                medium = medium[hit]
            v = -dirs[hit]
            if geometry.lights:
                np.add.at(x, pix, through * punctual_radiance(geometry, surface, v, materials.codes,
                                                              materials.params))
            surf_p, surf_ng, surf_n = surface.p, surface.ng, surface.n
            surf_mat, surf_r, surf_m, surf_b = surface.material, surface.roughness, surface.metallic, \
                surface.base_color
        if j == 0:
            shift = x.copy()
        total_sum, total_sq = shifted_add(shift, total_sum, total_sq, x, 1)
    return Film(shift, total_sum, total_sq)


def _media_tables(materials):
    """Per material row: whether it bounds a medium
    (:func:`pbrkit.brdf.transmission.volume_material`) and its absorption coefficient
    sigma_a (M, 3) (:func:`pbrkit.brdf.transmission.sigma_a`)."""
    codes, params = materials
    volume = (params[:, _TRANSMISSION] > 0.0) & (params[:, COLUMNS.thickness] > 0.0)
    sigma = np.zeros((codes.shape[0], 3))
    for m in range(codes.shape[0]):
        sigma[m] = sigma_a(params, m)
    return volume, sigma


def _base_values(prim, geometry, env, materials):
    """The deterministic part of each primary ray (rays, 3): the background where it
    misses, else the emission and the punctual lights at its hit."""
    base_value = np.zeros((prim.dirs.shape[0], 3))
    base_value[~prim.hit] = _background(prim, env)
    if prim.rows.size:
        s = prim.surface
        v = -prim.dirs[prim.rows]
        nov = np.einsum("ij,ij->i", s.n, v)
        base_value[prim.rows] = emission_seen(materials.codes, materials.params, s.material, nov, s.emissive) + \
            punctual_radiance(geometry, s, v, materials.codes, materials.params, None, True)
    return base_value


def _primary_points(prim, v):
    """The primary hits as :class:`pbrkit.render.records.Points`, one row per ray (rows
    of rays that missed: material -1, zeros)."""
    rays = prim.dirs.shape[0]
    s = prim.surface
    mat = np.full(rays, -1, dtype=np.int64)
    p, ng, n, vv, base = (np.zeros((rays, 3)) for _ in range(5))
    rough = np.zeros(rays)
    metal = np.zeros(rays)
    mat[prim.rows] = s.material
    p[prim.rows] = s.p
    ng[prim.rows] = s.ng
    n[prim.rows] = s.n
    vv[prim.rows] = v
    rough[prim.rows] = s.roughness
    metal[prim.rows] = s.metallic
    base[prim.rows] = s.base_color
    return Points(p, ng, n, vv, mat, rough, metal, base)


def render_reference(scene, spp=64, bounces=0, seed=0, geometry=None, env=None, strategy="mis", occlusion=True,
                     engine="auto"):
    """Monte Carlo ground truth of ``scene`` (module docstring) with ``spp`` samples per
    pixel.  ``strategy``: ``mis`` (environment + BRDF sampling, power heuristic) or
    ``brdf`` (BRDF sampling only, for comparison).  ``occlusion=False`` lets every
    surface see the whole environment, unblocked by the other objects (the
    assumption of real-time IBL; bounces must then be 0; punctual lights keep
    their exact shadows, as in the real-time path), so that a comparison
    isolates the shading approximations.  Returns a
    :class:`RenderResult` with the per-pixel standard error of the mean.  ``engine``:
    ``auto`` (the fused kernel for scenes of spheres and planes only, else the
    wavefront loop with Embree), ``fused`` or ``wavefront``; both give the same
    numbers for the same scene."""
    spp = checks.integer(spp, "spp", 1, 1 << 20)
    bounces = checks.integer(bounces, "bounces", 0, 64)
    if strategy not in STRATEGIES:
        raise ValueError(f"unknown strategy {strategy!r}; use 'mis' or 'brdf'")
    if engine not in ("auto", "fused", "wavefront"):
        raise ValueError(f"unknown engine {engine!r}; use 'auto', 'fused' or 'wavefront'")
    if not occlusion and bounces:
        raise ValueError("bounces need occlusion (rays must hit the other objects); use bounces = 0")
    t0 = time.perf_counter()
    geometry = geometry or Geometry(scene)
    env = env or EnvironmentLight(scene.environment)
    env.distribution  # noqa: B018  (computed here: loading, not sampling)
    t1 = time.perf_counter()
    prim = _primary(scene, geometry)
    cam = scene.camera
    k2 = cam.supersample ** 2
    n_pixels = cam.width * cam.height
    materials = Materials(*material_tables(geometry.materials))
    v = -prim.dirs[prim.rows]
    base_value = _base_values(prim, geometry, env, materials)
    t2 = time.perf_counter()
    code = STRATEGIES.index(strategy)
    # materials that transmit: the lane engine (direct lighting) does not handle them
    media = bool(np.any(materials.params[:, _TRANSMISSION] > 0.0))
    if engine == "fused" and geometry.has_meshes:
        raise ValueError("the fused engine handles spheres and planes only; this scene has triangle meshes")
    if geometry.has_meshes or engine == "wavefront":
        film = _wavefront(geometry, env, prim, base_value, k2, n_pixels, spp, bounces, seed, code, bool(occlusion),
                          materials, scene)
        engine_name = "wavefront" + (" (Embree)" if geometry.has_meshes else "")
    else:
        hits = _primary_points(prim, v)
        film = new_film(n_pixels)
        envs = environment_arrays(env)
        shapes = analytic_shapes(geometry)
        area = area_arrays(geometry)
        if bounces == 0 and not media:
            direct_lighting(seed, spp, k2, code, occlusion, base_value, hits, materials, envs, shapes, area, film)
            engine_name = "fused (analytic primitives; direct lighting in SIMD lanes)"
        else:
            run_in_threads(for_materials(_fused_kernel, materials.codes), n_pixels, np.uint64(seed), spp, k2, bounces,
                           code, bool(occlusion), media, base_value, hits, materials, envs, shapes,
                           punctual_lights(geometry), area, film)
            engine_name = "fused (analytic primitives)"
    t3 = time.perf_counter()
    mean, stderr = film_estimate(film, spp)
    image = mean.reshape(cam.height, cam.width, 3)
    stderr = stderr.reshape(cam.height, cam.width, 3)
    mask = prim.hit.reshape(cam.height, cam.width, k2).all(axis=2)
    paths = int(spp * n_pixels)
    surface_paths = int(np.count_nonzero(prim.hit.reshape(n_pixels, k2).any(axis=1))) * spp
    stats = {"mode": "reference", "spp": int(spp), "bounces": int(bounces), "seed": int(seed),
             "strategy": strategy, "occlusion": bool(occlusion), "engine": engine_name, "paths": paths,
             "surface_paths": surface_paths,
             "timings": {"load": t1 - t0, "primary_rays": t2 - t1, "sampling": t3 - t2, "total": t3 - t0},
             "paths_per_second": surface_paths / max(t3 - t2, 1e-9), "pixels": n_pixels}
    return RenderResult(image, mask, stderr, stats)
