"""Punctual lights at surface points: unshadowed radiance per light and, in
analytic scenes, shadow rays inside the kernel.
"""

from __future__ import annotations

import numpy as np

from ..brdf.bxdf import NO_TANGENT
from ..brdf.dispatch import bxdf_f, core_substitute
from ..brdf.transmission import transmissive_f, transmissive_material
from ..core.jit import dual_use, row_kernel
from .lights import light_arrays, light_incidence
from .materials import for_materials, hit_bxdf, hit_cosines
from .primitives import KIND_NONE, trace_analytic

__all__ = ["punctual_at", "punctual_radiance", "surface_tangents", "tangent_of", "NO_TANGENTS"]


#: The tangent rows of points that have none: one row of NO_TANGENT, which the kernels
#: read for every point (:func:`tangent_of`).
NO_TANGENTS = np.array([NO_TANGENT])


def surface_tangents(surface):
    """The tangents of a :class:`pbrkit.rendering.geometry.Surface` for the kernels: its
    (N, 4) rows, or :data:`NO_TANGENTS` where it has none (:func:`tangent_of`)."""
    return NO_TANGENTS if surface.tangent is None else surface.tangent


@dual_use(inline=True)
def tangent_of(tan, i):
    """Row ``i`` of the tangents ``tan`` (N, 4) as a tuple, or its one row when it has one
    (:data:`NO_TANGENTS`, or a single point's own)."""
    j = min(i, tan.shape[0] - 1)
    return tan[j, 0], tan[j, 1], tan[j, 2], tan[j, 3]

# ============================================================ punctual lights


@dual_use(inline=True)
def _opaque_light(mi, mf, m, b, t, bt, nx, ny, nz, vx, vy, vz, lx, ly, lz, gl, ec0, ec1, ec2):
    """(f(v, l) RGB, n.l) of BxDF ``b`` (frame (n, t, bt)) for a light along l; f 0 for a
    light below the geometric normal (``gl`` = g.l <= 0)."""
    if gl <= 0.0:
        return (0.0, 0.0, 0.0), 0.0
    c = hit_cosines(b, nx, ny, nz, t, bt, vx, vy, vz, lx, ly, lz)
    return bxdf_f(b, c, ec0, ec1, ec2), c.nol


@dual_use(inline=True)
def _light_through(mi, mf, m, b, t, bt, nx, ny, nz, vx, vy, vz, lx, ly, lz, gl, ec0, ec1, ec2):
    """:func:`_opaque_light`, and for a material that transmits (KHR_materials_transmission)
    the BSDF on either side, (f(v, l), |n.l|) (:func:`pbrkit.brdf.transmission.transmissive_f`):
    a light behind a thin wall shines through it.  (A light beyond a volume's other side is
    met only by shadow rays the volume blocks: it reaches the inside by refraction, as
    caustics, which next-event estimation does not connect.)"""
    if not transmissive_material(mi, mf, m):
        return _opaque_light(mi, mf, m, b, t, bt, nx, ny, nz, vx, vy, vz, lx, ly, lz, gl, ec0, ec1, ec2)
    nol = nx * lx + ny * ly + nz * lz
    if nol * gl <= 0.0:  # the shading and geometric normals disagree about the light's side
        return (0.0, 0.0, 0.0), 0.0
    wox = vx * t[0] + vy * t[1] + vz * t[2]
    woy = vx * bt[0] + vy * bt[1] + vz * bt[2]
    woz = vx * nx + vy * ny + vz * nz
    wix = lx * t[0] + ly * t[1] + lz * t[2]
    wiy = lx * bt[0] + ly * bt[1] + lz * bt[2]
    return transmissive_f(b, wox, woy, woz, wix, wiy, nol), abs(nol)


@dual_use(inline="llvm")
def _may_transmit(mi, mf, m):
    """Whether material ``m`` transmits (a light on either side may reach it); in kernels
    for the registered models' cores alone never (:func:`pbrkit.brdf.dispatch.core_substitute`)."""
    return transmissive_material(mi, mf, m)


@dual_use(inline="llvm")
def _opaque_only(mi, mf, m):
    return False


core_substitute(_light_through, _opaque_light)
core_substitute(_may_transmit, _opaque_only)


@row_kernel(3)
def _punctual_kernel(start, stop, mi, mf, mat, p, ng, n, v, rough, metal, base, tan, ec, codes, values, li, out_dir,
                     out_dist, out_value):
    """Unshadowed radiance from light li at each point, its direction and distance."""
    ct = codes[li, 0]
    cf = codes[li, 1]
    lv = values[li]
    for i in range(start, stop):
        lx, ly, lz, dist, factor = light_incidence(ct, cf, lv, p[i, 0], p[i, 1], p[i, 2])
        out_dir[i, 0] = lx
        out_dir[i, 1] = ly
        out_dir[i, 2] = lz
        out_dist[i] = dist
        out_value[i, 0] = 0.0
        out_value[i, 1] = 0.0
        out_value[i, 2] = 0.0
        gl = ng[i, 0] * lx + ng[i, 1] * ly + ng[i, 2] * lz
        if factor <= 0.0 or (gl <= 0.0 and not _may_transmit(mi, mf, mat[i])):
            continue
        b, t, bt = hit_bxdf(mi, mf, mat[i], rough[i], metal[i], base[i, 0], base[i, 1], base[i, 2], n[i, 0], n[i, 1],
                            n[i, 2], tangent_of(tan, i))
        f, nol = _light_through(mi, mf, mat[i], b, t, bt, n[i, 0], n[i, 1], n[i, 2], v[i, 0], v[i, 1], v[i, 2], lx,
                                ly, lz, gl, ec[i, 0], ec[i, 1], ec[i, 2])
        e = factor * max(nol, 0.0)
        out_value[i, 0] = f[0] * lv[0] * e
        out_value[i, 1] = f[1] * lv[1] * e
        out_value[i, 2] = f[2] * lv[2] * e


@row_kernel(3)
def _punctual_analytic_batch(start, stop, mi, mf, mat, p, ng, n, v, rough, metal, base, ec, codes, values, eps, shadows, spheres,
                             lo, hi, skip, first, count, order, planes, out):
    for i in range(start, stop):
        b, t, bt = hit_bxdf(mi, mf, mat[i], rough[i], metal[i], base[i, 0], base[i, 1], base[i, 2], n[i, 0], n[i, 1],
                            n[i, 2], NO_TANGENT)
        r = punctual_at(mi, mf, mat[i], b, t, bt, p[i, 0], p[i, 1], p[i, 2], ng[i, 0], ng[i, 1], ng[i, 2], n[i, 0],
                        n[i, 1], n[i, 2], v[i, 0], v[i, 1], v[i, 2], ec[i, 0], ec[i, 1], ec[i, 2], codes, values, eps,
                        shadows, spheres, lo, hi, skip, first, count, order, planes)
        out[i, 0] = r[0]
        out[i, 1] = r[1]
        out[i, 2] = r[2]


def punctual_radiance(geometry, surface, v, mat_i, mat_f, ec=None, shadows=True):
    """Radiance (N, 3) from the scene's punctual lights at the surface points, seen along v."""
    count = surface.p.shape[0]
    total = np.zeros((count, 3))
    if not geometry.lights or count == 0:
        return total
    codes, values = light_arrays(geometry.lights)
    ec = np.ones((count, 3)) if ec is None else np.ascontiguousarray(ec)
    if not geometry.has_meshes:  # analytic scene: shadow rays inside the kernel
        for_materials(_punctual_analytic_batch, mat_i)(mat_i, mat_f, np.ascontiguousarray(surface.material),
                                 *(np.ascontiguousarray(x) for x in (surface.p, surface.ng, surface.n, v,
                                                                     surface.roughness, surface.metallic,
                                                                     surface.base_color)),
                                 ec, codes, values, 1e-7 * geometry.scale, bool(shadows), geometry.spheres,
                                 *geometry.bvh, geometry.planes, total)
        return total
    args = [np.ascontiguousarray(x) for x in (surface.p, surface.ng, surface.n, v, surface.roughness,
                                              surface.metallic, surface.base_color, surface_tangents(surface))]
    direction = np.empty((count, 3))
    dist = np.empty(count)
    value = np.empty((count, 3))
    kernel = for_materials(_punctual_kernel, mat_i)
    for li in range(len(geometry.lights)):
        kernel(mat_i, mat_f, np.ascontiguousarray(surface.material), *args, ec, codes, values, li,
                         direction, dist, value)
        lit = np.flatnonzero(np.any(value > 0.0, axis=1))
        if shadows and lit.size:
            origins = geometry.offset_origins(surface.p[lit], surface.ng[lit], direction[lit])
            blocked = geometry.occluded(origins, direction[lit], dist[lit] * (1.0 - 1e-6))
            value[lit[blocked]] = 0.0
        total += value
    return total



@dual_use
def punctual_at(mi, mf, m, b, t, bt, px, py, pz, gx, gy, gz, nx, ny, nz, vx, vy, vz, ec0, ec1, ec2, codes, values,
                eps, shadows, spheres, lo, hi, skip, first, count, order, planes):
    """Radiance from every punctual light at an analytic-scene point of material ``m``
    (geometric normal g, shading normal n, BxDF ``b`` with frame (n, t, bt)), with shadow
    rays (from the light's side of the surface) when ``shadows``; through a material that
    transmits from either side (:func:`_light_through`)."""
    r0 = r1 = r2 = 0.0
    may_transmit = _may_transmit(mi, mf, m)
    for li in range(codes.shape[0]):
        lx, ly, lz, dist, factor = light_incidence(codes[li, 0], codes[li, 1], values[li], px, py, pz)
        gl = gx * lx + gy * ly + gz * lz
        if factor <= 0.0 or (gl <= 0.0 and not may_transmit):
            continue
        f, nol = _light_through(mi, mf, m, b, t, bt, nx, ny, nz, vx, vy, vz, lx, ly, lz, gl, ec0, ec1, ec2)
        if f[0] <= 0.0 and f[1] <= 0.0 and f[2] <= 0.0:
            continue
        if shadows:
            side = eps if gl > 0.0 else -eps
            _, k, _ = trace_analytic(px + side * gx, py + side * gy, pz + side * gz, lx, ly, lz, 0.0,
                                     dist * (1.0 - 1e-6), True, spheres, lo, hi, skip, first, count, order, planes)
            if k != KIND_NONE:
                continue
        e = factor * nol
        r0 += f[0] * values[li, 0] * e
        r1 += f[1] * values[li, 1] * e
        r2 += f[2] * values[li, 2] * e
    return r0, r1, r2

