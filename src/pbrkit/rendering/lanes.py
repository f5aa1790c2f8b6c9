"""The lane engine of the ground truth: direct lighting (``bounces`` = 0) of scenes of
spheres and planes and their area lights, the estimator of
:mod:`pbrkit.rendering.estimator` scheduled in SIMD lanes.  The samples of one primary
hit go through stages, each a loop over up to :data:`_LANES` samples in
structure-of-arrays buffers on the stack that LLVM vectorises: random numbers,
environment and area-light samples, the BxDF at them and its own samples
(:func:`_material_lanes`, specialised per material by :func:`_lanes_for_variant`),
the environment the BxDF samples see, shadow and BxDF rays (:func:`_trace_lanes`, or
the BVH for larger scenes), the area lights' shadows and the emission the BxDF
samples meet (ray by ray: those loops stay scalar), then the pixel's sums in sample
order (:mod:`pbrkit.rendering.film`).  It draws the same random numbers as the fused
and wavefront engines (:func:`pbrkit.rendering.vertex._vertex`), so it gives their
numbers (tested), and the same bytes for any thread count.
"""

from __future__ import annotations

import numpy as np

from ..brdf.bxdf import CODE_COLUMNS, NO_TANGENT
from ..brdf.dispatch import emission_coat, lobe_probabilities, sample_wi, specialised
from ..brdf.lobes.clearcoat import coated_emission
from ..brdf.shading.registry import COLUMNS, VARIANTS
from ..core.codegen import generate
from ..core.jit import lane_stage, run_in_threads, stack_array, threaded_kernel
from ..sampling.random import _sample_key, _stream_key, _uniform
from .area_lights import area_light_hit, area_light_sample
from .environment import _alias_choice, _alias_column, _env_texel, _texel_of, _texel_pdf, _texel_point
from .estimator import (
    STRATEGY_MIS,
    Shading,
    area_emission,
    area_shadow_t,
    bsdf_weight,
    emission_weight,
    light_sample,
    view_in_frame,
)
from .film import shifted_add, store_pixel
from .materials import COAT_F0, for_materials, hit_bxdf
from .primitives import KIND_NONE, KIND_PLANE, KIND_SPHERE, _ray_plane, _ray_sphere, analytic_surface, trace_analytic

__all__ = ["material_variants", "direct_lighting"]

#: The materials the direct-lighting kernel specialises, as code rows (model,
#: distribution, masking, Fresnel, diffuse): the registry's variants
#: (:data:`pbrkit.brdf.shading.registry.VARIANTS`, declared by the models).  The BxDF
#: of such a material is rebuilt with these codes as constants
#: (:func:`pbrkit.brdf.dispatch.specialised`), so that LLVM drops every other branch
#: of the dispatch and vectorises the lane loops.  Other materials run the same loops
#: unspecialised.
_VARIANTS = tuple(codes for codes, _ in VARIANTS)
#: Lanes (samples of one primary hit) per pass through the stages.
_LANES = 256
#: Scenes with at most this many spheres and planes test every ray against each of
#: them in vectorised loops; larger ones traverse the sphere BVH ray by ray.
_BULK_PRIMITIVES = 16
#: Rows of the lane buffers of :func:`_direct_kernel` (``stack_array(rows, columns)``
#: there, one array per stage's output): no loop reads the array it writes, and LLVM,
#: which knows separate allocations apart, vectorises every stage without run-time
#: overlap checks.
_U_LOBE, _U_1, _U_2, _U_K, _U_DV = range(5)                  # random numbers; alias draw
_L_DIR, _L_PDF, _L_RAD, _L_LE = 0, 3, 4, 7                   # light samples (environment, then area); BxDF's env.
_M_LVAL, _M_LOCAL = 0, 3                                     # BxDF at them; local BxDF directions
_S_DIR, _S_W, _S_PDF = 0, 3, 6                               # BxDF samples
_T_T, _T_KIND, _T_INDEX = range(3)                           # ray hits
_X_ADIST, _X_AEM, _X_END = 0, 1, 4                           # area lights: shadow length; emission met; path ended
#: Pixels per parallel work item.
_BLOCK = 8
#: Columns of the packed parameter row the kernels read.
_ANISOTROPY = COLUMNS.anisotropy
_EMISSIVE = COLUMNS.emissive


def material_variants(codes, params):
    """The specialisation (index into :data:`_VARIANTS`, or -1) of each material row of
    :func:`pbrkit.rendering.materials.material_tables`' ``(codes, params)``: isotropic
    materials whose code row is one of the variants."""
    out = np.full(codes.shape[0], -1, dtype=np.int64)
    for m in range(codes.shape[0]):
        if params[m, _ANISOTROPY] == 0.0 and tuple(codes[m, :CODE_COLUMNS]) in _VARIANTS:
            out[m] = _VARIANTS.index(tuple(codes[m, :CODE_COLUMNS]))
    return out


@lane_stage
def _material_lanes(b, at, p_spec, p_coat, strategy, count, n_eval, ub, lb, mb, sb):
    """The BxDF's part of the samples in a set of lane buffers (:func:`_direct_kernel`) at
    the shading point ``at`` (:class:`pbrkit.rendering.estimator.Shading`): the
    MIS-weighted value of each of the ``n_eval`` light samples (``mb[_M_LVAL]``: the
    environment's, then the area lights'; :func:`pbrkit.rendering.estimator.light_sample`),
    then a direction sampled from the BxDF with its weight f cos / pdf and pdf
    (``sb[_S_DIR]``, ``sb[_S_W]``, ``sb[_S_PDF]``;
    :func:`pbrkit.rendering.estimator.bsdf_weight` of the local direction that
    :func:`pbrkit.brdf.bxdf.sample_wi` draws).  The kernel calls it with a BxDF
    specialised by :func:`pbrkit.brdf.dispatch.specialised` or with any BxDF (:func:`_lanes_for_variant`)."""
    if strategy == STRATEGY_MIS:
        for i in range(n_eval):
            v0, v1, v2 = light_sample(b, at, p_spec, p_coat, lb[_L_DIR, i], lb[_L_DIR + 1, i], lb[_L_DIR + 2, i],
                                      lb[_L_PDF, i], lb[_L_RAD, i], lb[_L_RAD + 1, i], lb[_L_RAD + 2, i])
            mb[_M_LVAL, i] = v0
            mb[_M_LVAL + 1, i] = v1
            mb[_M_LVAL + 2, i] = v2
    # the BxDF samples: estimator.bsdf_sample in its two steps, the local directions
    # (sample_wi) in loops of their own, so that with one lobe its choice is a constant and
    # the other lobes' warps are not computed as well, then bsdf_weight in one loop (one
    # copy of the BxDF's evaluation per specialisation, not one per lobe choice)
    wox, woy, nov = view_in_frame(at)
    if p_coat <= 0.0 and p_spec >= 1.0:
        for i in range(count):
            llx, lly, llz = sample_wi(b, wox, woy, nov, 0.0, ub[_U_1, i], ub[_U_2, i], 1.0, -0.0)
            mb[_M_LOCAL, i] = llx
            mb[_M_LOCAL + 1, i] = lly
            mb[_M_LOCAL + 2, i] = llz
    elif p_coat <= 0.0 and p_spec <= 0.0:
        for i in range(count):
            llx, lly, llz = sample_wi(b, wox, woy, nov, 0.5, ub[_U_1, i], ub[_U_2, i], 0.0, -0.0)
            mb[_M_LOCAL, i] = llx
            mb[_M_LOCAL + 1, i] = lly
            mb[_M_LOCAL + 2, i] = llz
    else:
        for i in range(count):
            llx, lly, llz = sample_wi(b, wox, woy, nov, ub[_U_LOBE, i], ub[_U_1, i], ub[_U_2, i], p_spec, p_coat)
            mb[_M_LOCAL, i] = llx
            mb[_M_LOCAL + 1, i] = lly
            mb[_M_LOCAL + 2, i] = llz
    for i in range(count):
        d, w, pdf_b = bsdf_weight(b, at, p_spec, p_coat, mb[_M_LOCAL, i], mb[_M_LOCAL + 1, i], mb[_M_LOCAL + 2, i])
        sb[_S_DIR, i] = d[0]
        sb[_S_DIR + 1, i] = d[1]
        sb[_S_DIR + 2, i] = d[2]
        sb[_S_W, i] = w[0]
        sb[_S_W + 1, i] = w[1]
        sb[_S_W + 2, i] = w[2]
        sb[_S_PDF, i] = pdf_b


@lane_stage
def _hit_lanes(ox, oy, oz, dirs, row, count, spheres, planes, q, src, dst):
    """One step of :func:`_trace_lanes`: the hits ``src`` of the rays from o along
    ``dirs[row:row + 3]`` updated with primitive q (planes first, then spheres: the
    tests of :func:`pbrkit.rendering.primitives.trace_analytic` in its order, without
    the BVH) into ``dst``."""
    n_planes = planes.shape[0]
    if q < n_planes:
        qx, qy, qz, px, py, pz = planes[q, 0], planes[q, 1], planes[q, 2], planes[q, 3], planes[q, 4], planes[q, 5]
        for i in range(count):
            t = _ray_plane(ox, oy, oz, dirs[row, i], dirs[row + 1, i], dirs[row + 2, i], qx, qy, qz, px, py, pz)
            best = src[_T_T, i]
            closer = 0.0 < t < best
            dst[_T_T, i] = t if closer else best
            dst[_T_KIND, i] = KIND_PLANE if closer else src[_T_KIND, i]
            dst[_T_INDEX, i] = q if closer else src[_T_INDEX, i]
    else:
        s = q - n_planes
        cx = spheres[s, 0]
        cy = spheres[s, 1]
        cz = spheres[s, 2]
        r = spheres[s, 3]
        for i in range(count):
            t = _ray_sphere(ox, oy, oz, dirs[row, i], dirs[row + 1, i], dirs[row + 2, i], cx, cy, cz, r, 0.0)
            best = src[_T_T, i]
            closer = t < best
            dst[_T_T, i] = t if closer else best
            dst[_T_KIND, i] = KIND_SPHERE if closer else src[_T_KIND, i]
            dst[_T_INDEX, i] = s if closer else src[_T_INDEX, i]


@lane_stage
def _trace_lanes(ox, oy, oz, dirs, row, count, spheres, planes, ha, hb):
    """Closest hits, t in (0, inf), of the rays from o along ``dirs[row:row + 3]`` against
    every plane and sphere, in ``ha``: rows t (inf: none), kind, index (:func:`_hit_lanes`,
    alternating between the hit buffers ``ha`` and ``hb``)."""
    for i in range(count):
        ha[_T_T, i] = np.inf
        ha[_T_KIND, i] = KIND_NONE
        ha[_T_INDEX, i] = -1.0
    n = planes.shape[0] + spheres.shape[0]
    for q in range(0, n - 1, 2):
        _hit_lanes(ox, oy, oz, dirs, row, count, spheres, planes, q, ha, hb)
        _hit_lanes(ox, oy, oz, dirs, row, count, spheres, planes, q + 1, hb, ha)
    if n % 2:
        _hit_lanes(ox, oy, oz, dirs, row, count, spheres, planes, n - 1, ha, hb)
        for i in range(count):
            ha[_T_T, i] = hb[_T_T, i]
            ha[_T_KIND, i] = hb[_T_KIND, i]
            ha[_T_INDEX, i] = hb[_T_INDEX, i]


def direct_lighting(seed, spp, k2, strategy, occlusion, base_value, hits, materials, env, shapes, area, film):
    """Direct lighting of an analytic scene into ``film`` (:class:`pbrkit.rendering.film.Film`)
    by :func:`_direct_kernel` on a pool of threads: ``base_value`` (rays, 3) the
    deterministic part of each ray, ``hits`` the primary hits
    (:class:`pbrkit.rendering.records.Points`, rows with material -1 missed), the
    scene as :mod:`pbrkit.rendering.records`' records."""
    n_pixels = film.sum.shape[0]
    emissive = bool(np.any(materials.params[:, _EMISSIVE:_EMISSIVE + 3] != 0.0))
    run_in_threads(for_materials(_direct_kernel, materials.codes), (n_pixels + _BLOCK - 1) // _BLOCK, np.uint64(seed), spp, k2, strategy,
                   bool(occlusion), emissive, base_value, hits, materials,
                   material_variants(materials.codes, materials.params), env, shapes, area, film)


@threaded_kernel
def _direct_kernel(start, stop, seed, spp, k2, strategy, occlusion, emissive, base_value, hits, materials, variant,
                   env, shapes, area, film):
    """Direct lighting (bounces = 0) of an analytic scene and its area lights (module
    docstring): rays are (pixel, sub-pixel) pairs, sample j of a pixel uses sub-pixel
    j mod k2.  A primary ray that misses, or sees the surface from behind, contributes
    its ``base_value`` to every sample at once.  Sums as the fused kernel's (shifted
    data, :mod:`pbrkit.rendering.film`).  It runs the pixels of blocks ``start`` to
    ``stop`` (:data:`_BLOCK` pixels each), handed out to threads by
    :func:`pbrkit.core.jit.run_in_threads`.  ``emissive``: whether any material emits
    (then the BxDF rays look for the surfaces they hit); ``variant``: each material's
    specialisation (:func:`material_variants`).

    Lane buffers are on the stack (:func:`pbrkit.core.jit.stack_array`): LLVM knows
    them apart from the tables, so the loops that gather from tables and store into
    them are vectorised.  The arrays are read out of the records here, once; no
    function called in a loop over lanes takes an array (reference counting would add
    calls that keep LLVM from vectorising the loop).  The kernel is one function,
    not a loop calling a stage: LLVM then optimises its code once, where a stage
    would be optimised in its own compilation and again inlined into the kernel."""
    ub = stack_array(5, 256)
    lb = stack_array(10, 512)  # environment samples, then area-light samples
    mb = stack_array(6, 512)
    sb = stack_array(7, 256)
    ha = stack_array(3, 256)
    hb = stack_array(3, 256)
    shadow = stack_array(2, 256)  # environment samples; area-light samples
    xb = stack_array(5, 256)  # area lights: shadow ray length; emission seen by BxDF samples; path ended on a light
    # one reference per array (attribute reads; unpacking a record as a tuple would count two)
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
    radiance = env.radiance
    func = env.func
    total = env.total
    alias = env.alias
    row_cos = env.rows
    c = env.cos
    s = env.sin
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
    acodes = area.codes
    avalues = area.values
    averts = area.vertices
    n_pixels = film.sum.shape[0]
    height = radiance.shape[0]
    width = radiance.shape[1]
    n_texels = alias.shape[0]
    bulk = spheres.shape[0] + planes.shape[0] <= _BULK_PRIMITIVES
    n_area = acodes.shape[0]
    for pix in range(start * _BLOCK, min(n_pixels, stop * _BLOCK)):
        stream = _stream_key(seed, pix, 0)
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        q0 = 0.0
        q1 = 0.0
        q2 = 0.0
        k0 = 0.0
        k1 = 0.0
        k2_ = 0.0
        for sub in range(min(k2, spp)):
            row = pix * k2 + sub
            n_sub = (spp - sub + k2 - 1) // k2
            m = mat[row]
            px, py, pz = p[row, 0], p[row, 1], p[row, 2]
            gx, gy, gz = ng[row, 0], ng[row, 1], ng[row, 2]
            nx, ny, nz = n[row, 0], n[row, 1], n[row, 2]
            vx, vy, vz = v[row, 0], v[row, 1], v[row, 2]
            nov = nx * vx + ny * vy + nz * vz
            if m < 0 or nov <= 0.0 or gx * vx + gy * vy + gz * vz <= 0.0:  # the same value every sample
                if sub == 0:
                    k0, k1, k2_ = base_value[row, 0], base_value[row, 1], base_value[row, 2]
                s0, q0 = shifted_add(k0, s0, q0, base_value[row, 0], n_sub)
                s1, q1 = shifted_add(k1, s1, q1, base_value[row, 1], n_sub)
                s2, q2 = shifted_add(k2_, s2, q2, base_value[row, 2], n_sub)
                continue
            b, t, bt = hit_bxdf(mi, mf, m, rough[row], metal[row], base[row, 0], base[row, 1], base[row, 2], nx, ny, nz,
                                NO_TANGENT)
            at = Shading((nx, ny, nz), t, bt, (gx, gy, gz), (vx, vy, vz))
            p_spec, p_coat = lobe_probabilities(b, nov)
            ox = px + eps * gx
            oy = py + eps * gy
            oz = pz + eps * gz
            for c0 in range(0, n_sub, _LANES):
                lanes = min(_LANES, n_sub - c0)
                # --- random numbers and environment samples (the alias table's draws in a
                # loop of their own, so that its random loads overlap: _env_sample in two parts)
                for i in range(lanes):
                    key = _sample_key(stream, sub + k2 * (c0 + i))
                    ub[_U_LOBE, i] = _uniform(key, 4)
                    ub[_U_1, i] = _uniform(key, 2)
                    ub[_U_2, i] = _uniform(key, 3)
                if strategy == STRATEGY_MIS:
                    for i in range(lanes):
                        key = _sample_key(stream, sub + k2 * (c0 + i))
                        k, f = _alias_column(n_texels, _uniform(key, 0))
                        k, dv = _alias_choice(k, f, alias[k, 0], alias[k, 1])
                        ub[_U_K, i] = k
                        ub[_U_DV, i] = dv
                    for i in range(lanes):
                        key = _sample_key(stream, sub + k2 * (c0 + i))
                        ei, ej = _texel_of(np.int64(ub[_U_K, i]), width)
                        lx, ly, lz = _texel_point(row_cos[ei], row_cos[ei + 1], width, ej, ub[_U_DV, i], _uniform(key, 1),
                                                  c, s)
                        lb[_L_DIR, i] = lx
                        lb[_L_DIR + 1, i] = ly
                        lb[_L_DIR + 2, i] = lz
                        lb[_L_PDF, i] = _texel_pdf(func[ei, ej], total)
                        lb[_L_RAD, i] = radiance[ei, ej, 0]
                        lb[_L_RAD + 1, i] = radiance[ei, ej, 1]
                        lb[_L_RAD + 2, i] = radiance[ei, ej, 2]
                # --- area-light samples (as _vertex: a light picked uniformly, then a point on it),
                # after the environment's in the same buffers, so the BxDF evaluates both in one loop
                n_eval = lanes
                if strategy == STRATEGY_MIS and n_area > 0:
                    n_eval = 2 * lanes
                    for i in range(lanes):
                        key = _sample_key(stream, sub + k2 * (c0 + i))
                        li = min(np.int64(_uniform(key, 5) * n_area), n_area - 1)
                        ax, ay, az, dist, pdf_a, r0, r1, r2 = area_light_sample(acodes, avalues, averts, li, px, py, pz,
                                                                                _uniform(key, 6), _uniform(key, 7))
                        j = lanes + i
                        lb[_L_DIR, j] = ax
                        lb[_L_DIR + 1, j] = ay
                        lb[_L_DIR + 2, j] = az
                        lb[_L_PDF, j] = pdf_a / n_area if pdf_a > 0.0 and gx * ax + gy * ay + gz * az > 0.0 else 0.0
                        lb[_L_RAD, j] = r0
                        lb[_L_RAD + 1, j] = r1
                        lb[_L_RAD + 2, j] = r2
                        xb[_X_ADIST, i] = area_shadow_t(dist)
                # --- the BxDF (specialised for the materials of _VARIANTS)
                _lanes_for_variant(variant[m], b, at, p_spec, p_coat, strategy, lanes, n_eval, ub, lb, mb, sb)
                # --- the environment the BxDF samples see
                for i in range(lanes):  # vertex._env_miss, with the loads in the loop
                    ei, ej = _env_texel(height, width, c, s, sb[_S_DIR, i], sb[_S_DIR + 1, i], sb[_S_DIR + 2, i])
                    w = emission_weight(strategy, sb[_S_PDF, i], _texel_pdf(func[ei, ej], total))
                    lb[_L_LE, i] = radiance[ei, ej, 0] * w
                    lb[_L_LE + 1, i] = radiance[ei, ej, 1] * w
                    lb[_L_LE + 2, i] = radiance[ei, ej, 2] * w
                # --- shadow rays and BxDF rays
                if occlusion and bulk:
                    if strategy == STRATEGY_MIS:
                        _trace_lanes(ox, oy, oz, lb, _L_DIR, lanes, spheres, planes, ha, hb)
                        for i in range(lanes):
                            shadow[0, i] = ha[_T_T, i]
                    _trace_lanes(ox, oy, oz, sb, _S_DIR, lanes, spheres, planes, ha, hb)
                # --- rays that the bulk tests did not trace: ray by ray through the BVH (shadow
                # rays only where the sample brings light, BxDF rays where the environment or an
                # emissive surface does), into the same buffers
                if occlusion and not bulk:
                    for i in range(lanes):
                        shadow[0, i] = np.inf
                        ha[_T_T, i] = np.inf
                        ha[_T_KIND, i] = KIND_NONE
                        ha[_T_INDEX, i] = -1.0
                        if strategy == STRATEGY_MIS and (mb[_M_LVAL, i] > 0.0 or mb[_M_LVAL + 1, i] > 0.0
                                                         or mb[_M_LVAL + 2, i] > 0.0):
                            if trace_analytic(ox, oy, oz, lb[_L_DIR, i], lb[_L_DIR + 1, i], lb[_L_DIR + 2, i], 0.0,
                                              np.inf, True, spheres, lo, hi, skip, first, count, order,
                                              planes)[1] != KIND_NONE:
                                shadow[0, i] = 0.0
                        closest = emissive or n_area > 0  # what the ray hits first matters
                        if sb[_S_PDF, i] > 0.0 and (closest or lb[_L_LE, i] > 0.0 or lb[_L_LE + 1, i] > 0.0
                                                    or lb[_L_LE + 2, i] > 0.0):
                            th, hk, hi_ = trace_analytic(ox, oy, oz, sb[_S_DIR, i], sb[_S_DIR + 1, i],
                                                         sb[_S_DIR + 2, i], 0.0, np.inf, not closest, spheres, lo, hi,
                                                         skip, first, count, order, planes)
                            ha[_T_T, i] = th
                            ha[_T_KIND, i] = hk
                            ha[_T_INDEX, i] = hi_
                # --- area lights (as the fused kernel): they hide the environment samples and
                # each other from the shadow rays; a BxDF sample that meets one before any surface
                # sees its emission, MIS-weighted, and (with occlusion) ends there
                if n_area > 0:
                    for i in range(lanes):
                        j = lanes + i
                        shadow[1, i] = np.inf
                        if strategy == STRATEGY_MIS and occlusion:
                            if (shadow[0, i] == np.inf and (mb[_M_LVAL, i] > 0.0 or mb[_M_LVAL + 1, i] > 0.0
                                                            or mb[_M_LVAL + 2, i] > 0.0)
                                    and area_light_hit(acodes, avalues, averts, ox, oy, oz, lb[_L_DIR, i],
                                                       lb[_L_DIR + 1, i], lb[_L_DIR + 2, i], np.inf)[1] >= 0):
                                shadow[0, i] = 0.0
                            if mb[_M_LVAL, j] > 0.0 or mb[_M_LVAL + 1, j] > 0.0 or mb[_M_LVAL + 2, j] > 0.0:
                                tmax = xb[_X_ADIST, i]
                                if (trace_analytic(ox, oy, oz, lb[_L_DIR, j], lb[_L_DIR + 1, j], lb[_L_DIR + 2, j], 0.0,
                                                   tmax, True, spheres, lo, hi, skip, first, count, order,
                                                   planes)[1] != KIND_NONE
                                        or area_light_hit(acodes, avalues, averts, ox, oy, oz, lb[_L_DIR, j],
                                                          lb[_L_DIR + 1, j], lb[_L_DIR + 2, j], tmax)[1] >= 0):
                                    shadow[1, i] = 0.0
                        xb[_X_AEM, i] = 0.0
                        xb[_X_AEM + 1, i] = 0.0
                        xb[_X_AEM + 2, i] = 0.0
                        xb[_X_END, i] = 0.0
                        if sb[_S_PDF, i] > 0.0 and (sb[_S_W, i] > 0.0 or sb[_S_W + 1, i] > 0.0 or sb[_S_W + 2, i] > 0.0):
                            th = ha[_T_T, i] if occlusion else np.inf
                            at_, ai, a0, a1, a2 = area_light_hit(acodes, avalues, averts, ox, oy, oz, sb[_S_DIR, i],
                                                                 sb[_S_DIR + 1, i], sb[_S_DIR + 2, i], th)
                            if ai >= 0:
                                le = area_emission(strategy, sb[_S_PDF, i], area, ai, px, py, pz, sb[_S_DIR, i],
                                                   sb[_S_DIR + 1, i], sb[_S_DIR + 2, i], at_, a0, a1, a2)
                                xb[_X_AEM, i] = sb[_S_W, i] * le[0]
                                xb[_X_AEM + 1, i] = sb[_S_W + 1, i] * le[1]
                                xb[_X_AEM + 2, i] = sb[_S_W + 2, i] * le[2]
                                xb[_X_END, i] = 1.0 if occlusion else 0.0
                # --- each sample's value: base + the environment sample if unshadowed + the
                # area-light sample if unshadowed + the area light a BxDF sample meets + the BxDF
                # sample's environment if it escapes, or the emission of what it hits (in the
                # fused kernel's order); into the rows of the spent local directions
                base0 = base_value[row, 0]
                base1 = base_value[row, 1]
                base2 = base_value[row, 2]
                if n_area == 0:  # two loops, so that this one keeps no branch on the area lights
                    for i in range(lanes):
                        l0 = mb[_M_LVAL, i]
                        l1 = mb[_M_LVAL + 1, i]
                        l2 = mb[_M_LVAL + 2, i]
                        lit = (strategy == STRATEGY_MIS and (l0 > 0.0 or l1 > 0.0 or l2 > 0.0)
                               and not (occlusion and shadow[0, i] < np.inf))
                        w0 = sb[_S_W, i]
                        w1 = sb[_S_W + 1, i]
                        w2 = sb[_S_W + 2, i]
                        sampled = sb[_S_PDF, i] > 0.0 and (w0 > 0.0 or w1 > 0.0 or w2 > 0.0)
                        escaped = not occlusion or ha[_T_KIND, i] == KIND_NONE
                        mb[_M_LOCAL, i] = (base0 + (l0 if lit else 0.0)) + ((w0 * lb[_L_LE, i] if escaped else 0.0)
                                                                            if sampled else 0.0)
                        mb[_M_LOCAL + 1, i] = (base1 + (l1 if lit else 0.0)) + (
                            (w1 * lb[_L_LE + 1, i] if escaped else 0.0) if sampled else 0.0)
                        mb[_M_LOCAL + 2, i] = (base2 + (l2 if lit else 0.0)) + (
                            (w2 * lb[_L_LE + 2, i] if escaped else 0.0) if sampled else 0.0)
                else:
                    for i in range(lanes):
                        l0 = mb[_M_LVAL, i]
                        l1 = mb[_M_LVAL + 1, i]
                        l2 = mb[_M_LVAL + 2, i]
                        lit = (strategy == STRATEGY_MIS and (l0 > 0.0 or l1 > 0.0 or l2 > 0.0)
                               and not (occlusion and shadow[0, i] < np.inf))
                        j = lanes + i
                        a0 = mb[_M_LVAL, j]
                        a1 = mb[_M_LVAL + 1, j]
                        a2 = mb[_M_LVAL + 2, j]
                        area_lit = (strategy == STRATEGY_MIS and (a0 > 0.0 or a1 > 0.0 or a2 > 0.0)
                                    and not (occlusion and shadow[1, i] < np.inf))
                        w0 = sb[_S_W, i]
                        w1 = sb[_S_W + 1, i]
                        w2 = sb[_S_W + 2, i]
                        sampled = sb[_S_PDF, i] > 0.0 and (w0 > 0.0 or w1 > 0.0 or w2 > 0.0)
                        escaped = (not occlusion or ha[_T_KIND, i] == KIND_NONE) and xb[_X_END, i] == 0.0
                        x0 = ((base0 + (l0 if lit else 0.0)) + (a0 if area_lit else 0.0)) + xb[_X_AEM, i]
                        x1 = ((base1 + (l1 if lit else 0.0)) + (a1 if area_lit else 0.0)) + xb[_X_AEM + 1, i]
                        x2 = ((base2 + (l2 if lit else 0.0)) + (a2 if area_lit else 0.0)) + xb[_X_AEM + 2, i]
                        mb[_M_LOCAL, i] = x0 + ((w0 * lb[_L_LE, i] if escaped else 0.0) if sampled else 0.0)
                        mb[_M_LOCAL + 1, i] = x1 + ((w1 * lb[_L_LE + 1, i] if escaped else 0.0) if sampled else 0.0)
                        mb[_M_LOCAL + 2, i] = x2 + ((w2 * lb[_L_LE + 2, i] if escaped else 0.0) if sampled else 0.0)
                if emissive:  # emission of the surfaces the BxDF samples hit
                    for i in range(lanes):
                        if (sb[_S_PDF, i] > 0.0 and (sb[_S_W, i] > 0.0 or sb[_S_W + 1, i] > 0.0 or sb[_S_W + 2, i] > 0.0)
                                and occlusion and ha[_T_KIND, i] != KIND_NONE and (n_area == 0 or xb[_X_END, i] == 0.0)):
                            hi_ = np.int64(ha[_T_INDEX, i])
                            hk_ = np.int64(ha[_T_KIND, i])
                            hm = sphere_mat[hi_] if hk_ == KIND_SPHERE else plane_mat[hi_]
                            ec = 1.0
                            wc = emission_coat(mi, hm, mf, hm)
                            if wc > 0.0:  # a coat over the emission (KHR_materials_clearcoat), at the hit's normal
                                hn = analytic_surface(hk_, hi_, spheres, planes, sphere_mat, plane_mat, mf, ox, oy, oz,
                                                       sb[_S_DIR, i], sb[_S_DIR + 1, i], sb[_S_DIR + 2, i],
                                                       ha[_T_T, i])
                                ec = coated_emission(wc, COAT_F0, hn[3] * sb[_S_DIR, i] + hn[4] * sb[_S_DIR + 1, i]
                                                     + hn[5] * sb[_S_DIR + 2, i])
                            mb[_M_LOCAL, i] += sb[_S_W, i] * mf[hm, _EMISSIVE] * ec
                            mb[_M_LOCAL + 1, i] += sb[_S_W + 1, i] * mf[hm, _EMISSIVE + 1] * ec
                            mb[_M_LOCAL + 2, i] += sb[_S_W + 2, i] * mf[hm, _EMISSIVE + 2] * ec
                # --- the pixel's sums, in sample order (the shift: its first sample)
                if sub == 0 and c0 == 0:
                    k0 = mb[_M_LOCAL, 0]
                    k1 = mb[_M_LOCAL + 1, 0]
                    k2_ = mb[_M_LOCAL + 2, 0]
                for i in range(lanes):
                    s0, q0 = shifted_add(k0, s0, q0, mb[_M_LOCAL, i], 1)
                    s1, q1 = shifted_add(k1, s1, q1, mb[_M_LOCAL + 1, i], 1)
                    s2, q2 = shifted_add(k2_, s2, q2, mb[_M_LOCAL + 2, i], 1)
        store_pixel(film, pix, k0, k1, k2_, s0, s1, s2, q0, q1, q2)


def _variant_source():
    """The source of :func:`_lanes_for_variant`, generated from the registry's variants."""
    lines = ["def _lanes_for_variant(vr, b, at, p_spec, p_coat, strategy, count, n_eval, ub, lb, mb, sb):"]
    for i, (codes, coat) in enumerate(VARIANTS):
        lines += [f"    {'if' if i == 0 else 'elif'} vr == {i}:",
                  f"        _material_lanes(specialised(b, {codes!r}), at, p_spec, "
                  + ("p_coat" if coat else "-0.0") + ", strategy, count, n_eval, ub, lb, mb, sb)"]
    lines += ["    else:", "        _material_lanes(b, at, p_spec, p_coat, strategy, count, n_eval, ub, lb, mb, sb)"]
    return "\n".join(lines) + "\n"


#: :func:`_material_lanes` for a material of specialisation ``vr`` (:func:`material_variants`):
#: one copy per variant of the registry, with the BxDF rebuilt from its constant code row
#: (:func:`pbrkit.brdf.dispatch.specialised`) and p_coat = -0.0 for a model without a coat
#: (0, as a constant that also folds p_spec + p_coat to p_spec), and one copy for any BxDF
#: (vr = -1).  Generated from the registry; inlined into the kernel's stage (Numba IR),
#: so that every copy is optimised there, beside the lane buffers it works on.
_lanes_for_variant = generate(_variant_source(), "_lanes_for_variant",
                              {"_material_lanes": _material_lanes, "specialised": specialised})
