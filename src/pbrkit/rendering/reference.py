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
  samples on both sides (:mod:`pbrkit.rendering.estimator`), rays leaving from the side
  they go to, and inside a volume (a closed surface of thickness > 0, its normals
  outward) the Beer-Lambert transmittance of the real path length, internal
  reflections included.  Scenes with such materials run direct lighting in the fused
  kernel rather than the lanes; punctual lights shine through them from either side
  (:func:`pbrkit.rendering.punctual.punctual_at`: a light behind a thin wall; a light
  beyond a volume reaches its inside only by refraction, which shadow rays do not
  connect).
  ``KHR_materials_dispersion`` volumes refract each colour channel with its own IOR
  (:func:`pbrkit.brdf.transmission.dispersion_iors`): the scene is sampled once per
  channel, every dispersive material at that channel's IOR (its reflection and
  refraction alike, the material at that wavelength), and each pass gives its
  channel, so a path never mixes wavelengths (three times the work);
- visibility is traced, so the glTF occlusion texture (a real-time stand-in
  for it) is not applied; ``occlusion=False`` instead lets every surface see
  the whole environment unblocked by the other objects, as real-time IBL
  assumes, to isolate the shading approximations in a comparison.  Punctual
  lights cast shadows either way (exact shadow rays, as the real-time path's
  ideal shadow map), so both modes light a point the same way.
- the estimator is written once, as scalar functions
  (:mod:`pbrkit.rendering.estimator`, which derives it), and so are the pixel's sums
  (:mod:`pbrkit.rendering.film`); three engines schedule them.  Scenes of spheres
  and planes run in one fused kernel per pixel (all samples, ray casting
  included): direct lighting (``bounces`` = 0) in SIMD lanes
  (:mod:`pbrkit.rendering.lanes`), paths with bounces sample by sample
  (:func:`_fused_kernel`, one :func:`pbrkit.rendering.vertex._vertex` per bounce);
  scenes with triangle meshes run as a wavefront loop over the samples
  (:mod:`pbrkit.rendering.wavefront`, the same vertex on every path of a bounce at
  once), casting with Embree.  All
  give the same numbers for the same scene (tested), and the same bytes for any
  thread count.  The kernels take the scene as a few records of arrays
  (:mod:`pbrkit.rendering.records`).
"""
from __future__ import annotations

import time

import numpy as np

from ..brdf.dispatch import emission_coat
from ..brdf.lobes.clearcoat import coated_emission
from ..brdf.transmission import absorption, transmissive_material, volume_material
from ..brdf.shading.registry import COLUMNS
from ..core import checks
from ..brdf.bxdf import NO_TANGENT
from ..brdf.transmission import dispersion_iors
from ..core.jit import run_in_threads, threaded_kernel
from ..sampling.random import _path_key
from .area_lights import area_light_hit
from .environment import EnvironmentLight
from .estimator import STRATEGIES, area_emission, area_shadow_t, ray_origin
from .film import Film, film_estimate, new_film, shifted_add, store_pixel
from .geometry import Geometry
from .lanes import direct_lighting
from .materials import COAT_F0, for_materials, hit_bxdf, material_tables
from .primary import RenderResult, _primary
from .primitives import KIND_NONE, KIND_SPHERE, analytic_surface, trace_analytic
from .punctual import NO_TANGENTS, punctual_at
from .records import Materials, Points, analytic_shapes, area_arrays, environment_arrays, punctual_lights
from .vertex import _env_miss, _transmissive_vertex, _transmits, _vertex
from .wavefront import _base_values, _wavefront

__all__ = [
    "render_reference",
]

#: Columns of the packed parameter row the kernels read.
_EMISSIVE = COLUMNS.emissive
_ROUGHNESS = COLUMNS.roughness
_METALLIC = COLUMNS.metallic
_BASE_COLOR = COLUMNS.base_color
_TRANSMISSION = COLUMNS.transmission
_THICKNESS = COLUMNS.thickness
_IOR = COLUMNS.ior
_DISPERSION = COLUMNS.dispersion


@threaded_kernel
def _fused_kernel(start, stop, seed, spp, k2, bounces, strategy, occlusion, media, base_value, hits, materials, env,
                  shapes, lights, area, film):
    """Every sample of every pixel of an analytic scene (spheres, planes) in one pass:
    rows are the (pixel, sub-pixel) rays; sample j of a pixel uses sub-pixel j mod k2.
    ``base_value`` (rays, 3) is the deterministic part of each ray (background, or
    emission + punctual light at the primary hit); ``hits`` the primary hits
    (:class:`pbrkit.rendering.records.Points`; rows with material < 0 missed).  Each
    bounce is one :func:`_vertex`, whose samples it traces: shadow rays for the light
    samples, then the BRDF sample's ray, which meets an area light, the environment
    or the next surface.  Per pixel it accumulates the shifted sums of ``film``
    (:mod:`pbrkit.rendering.film`).  It runs pixels ``start`` to ``stop``, handed out to
    threads by :func:`pbrkit.core.jit.run_in_threads`.  ``media``: the scene has
    materials that transmit; then each ray leaves from the side of the surface it goes
    to (:func:`pbrkit.rendering.estimator.ray_origin`), and the path keeps the medium it is
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
                            me, b0, b1, b2, NO_TANGENT)
                    else:
                        ldir, lval, adir, adist, aval, bdir, bw, pdf_b = _vertex(
                            key, strategy, materials, env, area, m, px, py, pz, gx, gy, gz, nx, ny, nz, vx, vy, vz, r,
                            me, b0, b1, b2, NO_TANGENT)
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
                        bh, th_, bth = hit_bxdf(mi, mf, m, r, me, b0, b1, b2, nx, ny, nz, NO_TANGENT)
                        pr = punctual_at(mi, mf, m, bh, th_, bth, px, py, pz, gx, gy, gz, nx, ny, nz, vx, vy, vz, 1.0,
                                         1.0, 1.0, codes, values, eps, True, spheres, lo, hi, skip, first, count,
                                         order, planes)
                        x0 += t0 * pr[0]
                        x1 += t1 * pr[1]
                        x2 += t2 * pr[2]
            if j == 0:
                h0, h1, h2 = x0, x1, x2
            s0, q0 = shifted_add(h0, s0, q0, x0, 1)
            s1, q1 = shifted_add(h1, s1, q1, x1, 1)
            s2, q2 = shifted_add(h2, s2, q2, x2, 1)
        store_pixel(film, pix, h0, h1, h2, s0, s1, s2, q0, q1, q2)


def _primary_points(prim, v):
    """The primary hits as :class:`pbrkit.rendering.records.Points`, one row per ray (rows
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
    tangent = NO_TANGENTS  # analytic shapes: no tangent (the fused and lane kernels read none)
    if s.tangent is not None:
        tangent = np.zeros((rays, 4))
        tangent[:, 3] = 1.0
        tangent[prim.rows] = s.tangent
    return Points(p, ng, n, vv, mat, rough, metal, base, tangent)


def _sample(scene, geometry, env, prim, v, materials, spp, bounces, seed, code, occlusion, engine):
    """Every sample of the scene with ``materials`` (:class:`pbrkit.rendering.records.Materials`)
    by the engine ``engine`` chooses (:func:`render_reference`): (:class:`Film`, the
    engine's description)."""
    cam = scene.camera
    k2 = cam.supersample ** 2
    n_pixels = cam.width * cam.height
    base_value = _base_values(prim, geometry, env, materials)
    # materials that transmit: the lane engine (direct lighting) does not handle them
    media = bool(np.any(materials.params[:, _TRANSMISSION] > 0.0))
    if geometry.has_meshes or engine == "wavefront":
        film = _wavefront(geometry, env, prim, base_value, k2, n_pixels, spp, bounces, seed, code, bool(occlusion),
                          materials, scene)
        return film, "wavefront" + (" (Embree)" if geometry.has_meshes else "")
    hits = _primary_points(prim, v)
    film = new_film(n_pixels)
    envs = environment_arrays(env)
    shapes = analytic_shapes(geometry)
    area = area_arrays(geometry)
    if bounces == 0 and not media:
        direct_lighting(seed, spp, k2, code, occlusion, base_value, hits, materials, envs, shapes, area, film)
        return film, "fused (analytic primitives; direct lighting in SIMD lanes)"
    run_in_threads(for_materials(_fused_kernel, materials.codes), n_pixels, np.uint64(seed), spp, k2, bounces,
                   code, bool(occlusion), media, base_value, hits, materials, envs, shapes, punctual_lights(geometry),
                   area, film)
    return film, "fused (analytic primitives)"


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
    t2 = time.perf_counter()
    code = STRATEGIES.index(strategy)
    if engine == "fused" and geometry.has_meshes:
        raise ValueError("the fused engine handles spheres and planes only; this scene has triangle meshes")
    dispersive = np.flatnonzero((materials.params[:, _DISPERSION] > 0.0) & (materials.params[:, _TRANSMISSION] > 0.0)
                                & (materials.params[:, _THICKNESS] > 0.0))
    if dispersive.size == 0:
        film, engine_name = _sample(scene, geometry, env, prim, v, materials, spp, bounces, seed, code, occlusion,
                                    engine)
    else:  # KHR_materials_dispersion: each channel's paths with its own IOR (module docstring)
        iors = dispersion_iors(materials.params[dispersive, _IOR], materials.params[dispersive, _DISPERSION])
        parts = []
        for c in range(3):
            params = materials.params.copy()
            params[dispersive, _IOR] = iors[:, c]
            channel, engine_name = _sample(scene, geometry, env, prim, v, Materials(materials.codes, params), spp,
                                           bounces, seed, code, occlusion, engine)
            parts.append(channel)
        film = Film(*(np.stack([parts[c][k][:, c] for c in range(3)], axis=-1) for k in range(3)))
        engine_name += ", a pass per colour channel (dispersion)"
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
