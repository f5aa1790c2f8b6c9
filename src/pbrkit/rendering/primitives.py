"""Analytic primitives: spheres and infinite planes, intersected in compiled kernels.

- Spheres and infinite planes are intersected analytically in compiled
  kernels (spheres through a bounding-volume hierarchy stored with skip
  pointers, so traversal needs no stack), with the numerically careful
  ray/sphere solution of Haines, Günther and Akenine-Möller, "Precision
  Improvements for Ray/Sphere Intersection", Ray Tracing Gems (2019), ch. 7.
  The surface data of a sphere hit (unit normal, point snapped onto the
  sphere) are computed once, by :func:`sphere_normal_and_point`, for the
  NumPy shading path and the compiled kernels alike.
"""

from __future__ import annotations

import math

import numpy as np

from ..brdf.shading.registry import COLUMNS
from ..core.jit import dual_use, row_kernel

__all__ = [
    "KIND_NONE",
    "KIND_SPHERE",
    "KIND_PLANE",
    "analytic_surface",
    "KIND_TRIANGLE",
    "build_sphere_bvh",
    "sphere_normal_and_point",
]

KIND_NONE, KIND_SPHERE, KIND_PLANE, KIND_TRIANGLE = 0, 1, 2, 3
_INF = np.inf
_DOUBLE_SIDED = COLUMNS.double_sided


# ============================================================ analytic primitives


def build_sphere_bvh(centers, radii, leaf_size=2):
    """Bounding-volume hierarchy over spheres, flattened in depth-first order with
    skip pointers (the "threaded" layout: a hit on node i continues at i + 1, a
    miss or a finished leaf at ``skip[i]``).  Median split on the longest axis
    of the centres' bounds.  Returns ``(box_min (K, 3), box_max (K, 3), skip (K,),
    first (K,), count (K,), order (S,))``; a leaf holds spheres
    ``order[first:first + count]`` (count 0 for inner nodes)."""
    centers = np.asarray(centers, dtype=float).reshape(-1, 3)
    radii = np.asarray(radii, dtype=float).reshape(-1)
    lo_all = centers - radii[:, None]
    hi_all = centers + radii[:, None]
    nodes = []  # [lo, hi, skip, first, count]
    order = []

    def build(index):
        node = len(nodes)
        nodes.append([lo_all[index].min(axis=0), hi_all[index].max(axis=0), 0, 0, 0])
        if index.size <= leaf_size:
            nodes[node][3] = len(order)
            nodes[node][4] = index.size
            order.extend(index.tolist())
        else:
            c = centers[index]
            axis = int(np.argmax(c.max(axis=0) - c.min(axis=0)))
            sorted_index = index[np.argsort(c[:, axis], kind="stable")]
            half = sorted_index.size // 2
            build(sorted_index[:half])
            build(sorted_index[half:])
        nodes[node][2] = len(nodes)

    if centers.shape[0]:
        # iterative depth would be log2(S); recursion is fine for any realistic count
        build(np.arange(centers.shape[0]))
    k = len(nodes)
    box_min = np.array([n[0] for n in nodes]).reshape(k, 3)
    box_max = np.array([n[1] for n in nodes]).reshape(k, 3)
    skip = np.array([n[2] for n in nodes], dtype=np.int64)
    first = np.array([n[3] for n in nodes], dtype=np.int64)
    count = np.array([n[4] for n in nodes], dtype=np.int64)
    return box_min, box_max, skip, first, count, np.array(order, dtype=np.int64)


@dual_use(inline=True)
def _ray_sphere(ox, oy, oz, dx, dy, dz, cx, cy, cz, r, tmin):
    """Smallest t > tmin of the unit-direction ray o + t d on the sphere, or inf
    (Haines et al. 2019, Ray Tracing Gems ch. 7: the discriminant as
    r^2 - |f - (f.d) d|^2 with f = o - c, and the root pair q, c / q)."""
    fx = ox - cx
    fy = oy - cy
    fz = oz - cz
    b = fx * dx + fy * dy + fz * dz
    px = fx - b * dx
    py = fy - b * dy
    pz = fz - b * dz
    disc = r * r - (px * px + py * py + pz * pz)
    if disc < 0.0:
        return _INF
    c = fx * fx + fy * fy + fz * fz - r * r
    q = -b - math.copysign(math.sqrt(disc), b)
    if q == 0.0:
        return _INF
    t0 = c / q
    t1 = q
    if t0 > t1:
        t0, t1 = t1, t0
    if t0 > tmin:
        return t0
    if t1 > tmin:
        return t1
    return _INF


@dual_use(inline=True)
def _ray_plane(ox, oy, oz, dx, dy, dz, qx, qy, qz, nx, ny, nz):
    """Parameter t of the ray o + t d on the plane through q with unit normal n:
    t = ((q - o).n) / (d.n), inf for a ray parallel to it."""
    den = dx * nx + dy * ny + dz * nz
    t = ((qx - ox) * nx + (qy - oy) * ny + (qz - oz) * nz) / (den if den != 0.0 else 1.0)
    return t if den != 0.0 else _INF


@dual_use
def sphere_normal_and_point(cx, cy, cz, r, px, py, pz):
    """The unit outward normal n = (p - c) / |p - c| of the sphere (centre c,
    radius r) at a hit point p, and p snapped onto the sphere, c + r n.
    Returns (nx, ny, nz, sx, sy, sz): scalars inside kernels, arrays from
    NumPy.  p = o + t d with t from :func:`_ray_sphere` (Haines et al. 2019,
    Ray Tracing Gems ch. 7) carries the rounding error of t, which grows with
    the distance; the snapped point lies on the sphere to the precision of c
    and r, so rays leaving it start from the surface."""
    nx = px - cx
    ny = py - cy
    nz = pz - cz
    length = np.sqrt(nx * nx + ny * ny + nz * nz)
    nx = nx / length
    ny = ny / length
    nz = nz / length
    return nx, ny, nz, cx + r * nx, cy + r * ny, cz + r * nz


@dual_use
def _slab(o, i, lo, hi, t0, t1):
    """The ray parameter interval [t0, t1] narrowed to the slab lo <= o + t d <= hi
    of one axis (i = 1 / d)."""
    a = (lo - o) * i
    b = (hi - o) * i
    if a > b:
        a, b = b, a
    return max(t0, a), min(t1, b)


@dual_use
def _ray_box(ox, oy, oz, ix, iy, iz, lo, hi, node, tmax):
    """Slab test (Kay & Kajiya 1986): does the ray (inverse direction i) enter the box before tmax?"""
    t0, t1 = _slab(ox, ix, lo[node, 0], hi[node, 0], 0.0, tmax)
    t0, t1 = _slab(oy, iy, lo[node, 1], hi[node, 1], t0, t1)
    t0, t1 = _slab(oz, iz, lo[node, 2], hi[node, 2], t0, t1)
    return t0 <= t1


@dual_use
def _inv(d):
    if d == 0.0:
        return 1e300
    return 1.0 / d


@dual_use
def trace_analytic(ox, oy, oz, dx, dy, dz, tmin, tmax, any_hit, spheres, bvh_lo, bvh_hi, bvh_skip, bvh_first,
                   bvh_count, bvh_order, planes):
    """Closest (or, with ``any_hit``, any) analytic hit with tmin < t < tmax.
    ``spheres`` (S, 4) rows (cx, cy, cz, r); ``planes`` (P, 6) rows (point, unit normal).
    Returns (t, kind, index) with t = inf, kind = KIND_NONE when nothing is hit."""
    best = tmax
    kind = 0
    index = -1
    for p in range(planes.shape[0]):
        t = _ray_plane(ox, oy, oz, dx, dy, dz, planes[p, 0], planes[p, 1], planes[p, 2], planes[p, 3], planes[p, 4],
                       planes[p, 5])
        if tmin < t < best:
            best = t
            kind = 2
            index = p
            if any_hit:
                return best, kind, index
    n_nodes = bvh_skip.shape[0]
    if n_nodes:
        ix = _inv(dx)
        iy = _inv(dy)
        iz = _inv(dz)
        node = 0
        while node < n_nodes:
            if _ray_box(ox, oy, oz, ix, iy, iz, bvh_lo, bvh_hi, node, best):
                cnt = bvh_count[node]
                if cnt > 0:
                    for q in range(bvh_first[node], bvh_first[node] + cnt):
                        s = bvh_order[q]
                        t = _ray_sphere(ox, oy, oz, dx, dy, dz, spheres[s, 0], spheres[s, 1], spheres[s, 2],
                                        spheres[s, 3], tmin)
                        if t < best:
                            best = t
                            kind = 1
                            index = s
                            if any_hit:
                                return best, kind, index
                    node = bvh_skip[node]
                else:
                    node += 1
            else:
                node = bvh_skip[node]
    if kind == 0:
        return _INF, 0, -1
    return best, kind, index


@row_kernel(0)
def _trace_batch(start, stop, origins, dirs, tmin, tmax, any_hit, spheres, lo, hi, skip, first, count, order, planes,
                 out_t, out_kind, out_index):
    for i in range(start, stop):
        t, k, idx = trace_analytic(origins[i, 0], origins[i, 1], origins[i, 2], dirs[i, 0], dirs[i, 1], dirs[i, 2],
                                   tmin, tmax[i], any_hit, spheres, lo, hi, skip, first, count, order, planes)
        out_t[i] = t
        out_kind[i] = k
        out_index[i] = idx


@dual_use
def analytic_surface(kind, index, spheres, planes, sphere_mat, plane_mat, mf, ox, oy, oz, dx, dy, dz, t):
    """Position, normal (facing the ray for double-sided materials: parameter rows ``mf``
    of :func:`pbrkit.rendering.materials.material_tables`) and material of the hit at
    distance t along the ray o + t d on primitive ``index`` of ``kind``."""
    px = ox + t * dx
    py = oy + t * dy
    pz = oz + t * dz
    if kind == KIND_SPHERE:
        nx, ny, nz, px, py, pz = sphere_normal_and_point(spheres[index, 0], spheres[index, 1], spheres[index, 2],
                                                         spheres[index, 3], px, py, pz)
        m = sphere_mat[index]
    else:
        nx = planes[index, 3]
        ny = planes[index, 4]
        nz = planes[index, 5]
        m = plane_mat[index]
    if mf[m, _DOUBLE_SIDED] > 0.0 and nx * dx + ny * dy + nz * dz > 0.0:
        nx, ny, nz = -nx, -ny, -nz
    return px, py, pz, nx, ny, nz, m
