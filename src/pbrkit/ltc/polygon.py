"""The integral of the clamped cosine over a spherical polygon, in closed form.

D_o(w) = max(0, w_z) / pi is the normalised clamped cosine of the local
shading frame (``docs/CONVENTIONS.md``: normal +z, directions point away from
the surface).  Its integral over a spherical polygon P is the polygon's form
factor (Lambert 1760), and by Stokes' theorem it is a sum over the edges
(Arvo 1995, "Applications of Irradiance Tensors to the Simulation of
Non-Lambertian Phenomena", SIGGRAPH 1995: the irradiance vector of a polygon;
Heitz, Dupuy, Hill, Neubelt 2016, "Real-Time Polygonal-Light Shading with
Linearly Transformed Cosines", ACM TOG 35(4), eq. 11):

    E(P) = 1 / (2 pi) sum_i theta_i  n_i . z,
    theta_i = angle between p_i and p_{i+1},  n_i = (p_{i+1} x p_i) / |p_{i+1} x p_i|,

valid for a polygon on or above the horizon; a polygon reaching below it is
first clipped to the upper hemisphere z >= 0, exactly (Sutherland-Hodgman
against the plane z = 0, as Heitz et al.'s shader ``ClipQuadToHorizon`` does), which adds at most
one vertex to a convex polygon.

Polygons.  ``vertices`` (..., K, 3) holds the K vertices of each polygon as
points relative to the shading point (any non-zero length: only their
directions matter) in the local frame.  Edge k joins vertex k to vertex
k + 1 (mod K) along the *minor* great-circle arc, which is the projection of
the straight segment between the two points: a planar polygon of an emitter
(seen from a point off its plane) gives exactly the spherical polygon it
subtends.  The interior is the region the edges bound inside an open
hemisphere containing all the vertices (any planar polygon not through the
shading point qualifies); a self-intersecting polygon counts each region with
its winding number.  Polygons with fewer vertices can share a batch by
repeating their last vertex: a zero-length edge contributes 0.

Sign convention: the result is **positive when the vertices run
counter-clockwise as seen from the shading point** (the origin, looking at the
polygon), i.e. when the right-hand normal (p1 - p0) x (p2 - p0) of a planar
polygon points toward the shading point: the polygon shows it its front face
in the OpenGL / glTF sense, and a one-sided emitter lighting the shading point
(``docs/CONVENTIONS.md``: it emits on the side its normal points to; three.js
orders a rectangle's corners counter-clockwise seen from that side) gives
E > 0.  Reversing the order negates E; a one-sided emitter takes max(0, E),
a two-sided one |E|.  This is Heitz et al.'s eq. 11 with n_i = p_{i+1} x p_i
normalised, i.e. eq. 11 as printed (p_i x p_{i+1}) summed over the *reversed*
vertex order: the printed form is positive for a polygon counter-clockwise
seen from outside the sphere, which their shader code (and three.js, whose
frame (T1, -N x T1, N) is the mirror image of pbrkit's right-handed
(T1, N x T1, N)) arranges by ordering or handedness.  The edge terms
:func:`edge_integral` and :func:`edge_vector_form_factor` keep the printed
orientation (a -> b gives theta (a x b) / |a x b|), so the polygon sums call
them with each edge's end points swapped.

Robustness: each edge's angle is ``atan2(|a x b|, a . b)`` (never the acos of
a dot product, which loses all precision for nearly parallel edges), and
``theta (a x b)_z / |a x b|`` tends to 0 smoothly as the edge shrinks.  The
horizon crossing of an edge is the positive combination |a_z| b + |b_z| a
whose z is exactly 0 in floating point, so edges lying on, touching or
crossing the horizon need no tolerance.  Vertices are rescaled before they
are normalised, so any finite non-zero coordinates work.  The only undefined
edge joins two antipodal vertices (no unique great circle); it contributes 0.

No roughness remap is involved: these are geometric integrals.

Every per-polygon routine is a :func:`pbrkit.core.jit.dual_use` function
taking one polygon (K, 3) (and a 3 x 3 matrix), so Numba kernels elsewhere
(the fitter) compile it in; the NumPy functions run a parallel kernel over the
leading dimensions.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import dual_use, row_kernel, select

__all__ = [
    "edge_integral",
    "edge_vector_form_factor",
    "polygon_form_factor",
    "transformed_polygon_form_factor",
    "clip_polygon_to_horizon",
    "polygon_clamped_cosine_integral",
    "polygon_vector_form_factor",
    "clip_to_horizon",
    "clipped_vertex_capacity",
    "transformed_polygon_integrals",
]

_INV_TWO_PI = 0.5 / math.pi
_IDENTITY = np.eye(3)


# =========================================================================
# Edge terms (dual-use scalars)
# =========================================================================


@dual_use
def edge_integral(ax, ay, az, bx, by, bz):
    """The z component of Arvo's edge vector for the arc a -> b:
    theta (a x b)_z / |a x b| with theta the angle between a and b.

    Heitz et al. 2016, eq. 11 (one term, without the 1 / (2 pi)); their shader's
    ``IntegrateEdge``; Arvo 1995 (Theta_i Gamma_i . n).  a and b need
    not be unit length.  theta = atan2(|a x b|, a . b), accurate for nearly
    parallel edges; a zero-length edge (or an antipodal pair, where the arc
    is undefined) gives 0.  No roughness remap is involved.
    """
    cx = ay * bz - az * by
    cy = az * bx - ax * bz
    cz = ax * by - ay * bx
    s = np.sqrt(cx * cx + cy * cy + cz * cz)
    d = ax * bx + ay * by + az * bz
    theta = np.arctan2(s, d)
    ok = s > 0.0
    return select(ok, theta * cz / select(ok, s, 1.0), 0.0)


@dual_use
def edge_vector_form_factor(ax, ay, az, bx, by, bz):
    """Arvo's edge vector theta (a x b) / |a x b| for the arc a -> b, as (x, y, z).

    Arvo 1995: the irradiance vector of a polygon is
    1 / (2 pi) sum_i Theta_i Gamma_i; three.js calls this term
    ``LTC_EdgeVectorFormFactor``.  Its z component is :func:`edge_integral`.
    Same robustness as :func:`edge_integral`; 0 for a degenerate edge.  No
    roughness remap is involved.
    """
    cx = ay * bz - az * by
    cy = az * bx - ax * bz
    cz = ax * by - ay * bx
    s = np.sqrt(cx * cx + cy * cy + cz * cz)
    d = ax * bx + ay * by + az * bz
    theta = np.arctan2(s, d)
    ok = s > 0.0
    scale = select(ok, theta / select(ok, s, 1.0), 0.0)
    return scale * cx, scale * cy, scale * cz


# =========================================================================
# One polygon (dual-use: a (K, 3) array from Python or inside a kernel)
# =========================================================================


@dual_use
def _unit_vertex(m, vertices, k):
    """Vertex k of ``vertices`` transformed by the 3 x 3 ``m`` and normalised
    (rescaled by its largest component first, so no square overflows); a
    zero vector stays zero."""
    px = vertices[k, 0]
    py = vertices[k, 1]
    pz = vertices[k, 2]
    x = m[0, 0] * px + m[0, 1] * py + m[0, 2] * pz
    y = m[1, 0] * px + m[1, 1] * py + m[1, 2] * pz
    z = m[2, 0] * px + m[2, 1] * py + m[2, 2] * pz
    big = max(abs(x), abs(y), abs(z))
    if big > 0.0:
        x /= big
        y /= big
        z /= big
        inv = 1.0 / math.sqrt(x * x + y * y + z * z)
        x *= inv
        y *= inv
        z *= inv
    return x, y, z


@dual_use
def _horizon_crossing(px, py, pz, cx, cy, cz):
    """The unit direction where the arc p -> c crosses z = 0 (p_z and c_z of
    opposite signs, one possibly 0): |p_z| c + |c_z| p, a positive combination
    (so on the minor arc) whose z is exactly 0; (0, 0, 0) if it vanishes
    (antipodal p and c)."""
    wp = abs(cz)
    wc = abs(pz)
    big = max(wp, wc)  # scaled so the larger weight is 1: no underflow for z ~ 1e-300
    if big > 0.0:
        wp /= big
        wc /= big
    x = wc * cx + wp * px
    y = wc * cy + wp * py
    length = math.sqrt(x * x + y * y)
    if length > 0.0:
        return x / length, y / length, 0.0
    return 0.0, 0.0, 0.0


@dual_use
def transformed_polygon_form_factor(m, vertices):
    """The signed integral of max(0, w_z) / pi over the spherical polygon with
    vertices m @ p_k (``m`` 3 x 3, ``vertices`` (K, 3)), clipped to z >= 0.

    Heitz et al. 2016, eq. 11 with their horizon clipping (``ClipQuadToHorizon``); Arvo
    1995.  The clipping is Sutherland-Hodgman against z >= 0 streamed
    through the edge sum, so no clipped polygon is stored: each emitted
    vertex closes an edge with the previous one.  Sign and polygon
    conventions: module docstring (positive for a polygon counter-clockwise
    seen from the shading point).  The linear map is applied to the
    vertices only; the caller accounts for its determinant's sign if it
    wants the orientation of the untransformed polygon
    (:func:`pbrkit.ltc.distribution.ltc_polygon_integral_single` does).  No
    roughness remap is involved.
    """
    n = vertices.shape[0]
    total = 0.0
    if n == 0:
        return total
    have_first = False
    fx = fy = fz = 0.0
    lx = ly = lz = 0.0
    px, py, pz = _unit_vertex(m, vertices, n - 1)
    for k in range(n):
        cx, cy, cz = _unit_vertex(m, vertices, k)
        p_in = pz >= 0.0
        c_in = cz >= 0.0
        for emit in range(2):
            if emit == 0:
                if p_in == c_in:
                    continue
                ex, ey, ez = _horizon_crossing(px, py, pz, cx, cy, cz)
            else:
                if not c_in:
                    continue
                ex, ey, ez = cx, cy, cz
            if have_first:
                total += edge_integral(ex, ey, ez, lx, ly, lz)  # reversed: module docstring
            else:
                fx, fy, fz = ex, ey, ez
                have_first = True
            lx, ly, lz = ex, ey, ez
        px, py, pz = cx, cy, cz
    if have_first:
        total += edge_integral(fx, fy, fz, lx, ly, lz)
    return total * _INV_TWO_PI


@dual_use
def polygon_form_factor(vertices):
    """The signed integral of max(0, w_z) / pi over one spherical polygon
    (K, 3), clipped to the upper hemisphere: the form factor (Heitz et al.
    2016, eq. 11; Arvo 1995; conventions in the module docstring).  No
    roughness remap is involved."""
    return transformed_polygon_form_factor(_IDENTITY, vertices)


@dual_use
def clip_polygon_to_horizon(m, vertices, out):
    """Sutherland-Hodgman clip of the polygon m @ p_k (``vertices`` (K, 3)) to
    z >= 0, written as unit vectors into ``out`` (at least
    :func:`clipped_vertex_capacity` (K) rows); returns the vertex count.

    The same clipping as :func:`transformed_polygon_form_factor` (Heitz et al.
    2016, ``ClipQuadToHorizon``), materialised: a vertex on or above the horizon is kept,
    an edge crossing it adds its crossing point (z exactly 0).  A convex
    polygon gets at most K + 1 vertices, any polygon at most K + K // 2.  No
    roughness remap is involved."""
    n = vertices.shape[0]
    count = 0
    if n == 0:
        return count
    px, py, pz = _unit_vertex(m, vertices, n - 1)
    for k in range(n):
        cx, cy, cz = _unit_vertex(m, vertices, k)
        p_in = pz >= 0.0
        c_in = cz >= 0.0
        if p_in != c_in:
            ex, ey, ez = _horizon_crossing(px, py, pz, cx, cy, cz)
            out[count, 0] = ex
            out[count, 1] = ey
            out[count, 2] = ez
            count += 1
        if c_in:
            out[count, 0] = cx
            out[count, 1] = cy
            out[count, 2] = cz
            count += 1
        px, py, pz = cx, cy, cz
    return count


# =========================================================================
# Kernels and the NumPy API
# =========================================================================


@row_kernel(1)
def _form_factor_kernel(start, stop, m, vertices, out):
    stride = 0 if m.shape[0] == 1 else 1  # one matrix for all polygons, or one each
    for i in range(start, stop):
        out[i] = transformed_polygon_form_factor(m[i * stride], vertices[i])


@row_kernel(0)
def _clip_kernel(start, stop, vertices, out, counts):
    for i in range(start, stop):
        c = clip_polygon_to_horizon(_IDENTITY, vertices[i], out[i])
        counts[i] = c
        # pad with the last vertex (zero-length edges add nothing), or zeros when empty
        for r in range(c, out.shape[1]):
            for a in range(3):
                out[i, r, a] = out[i, c - 1, a] if c > 0 else 0.0


@row_kernel(0)
def _vector_form_factor_kernel(start, stop, vertices, out):
    for i in range(start, stop):
        n = vertices.shape[1]
        sx = sy = sz = 0.0
        if n > 0:
            px, py, pz = _unit_vertex(_IDENTITY, vertices[i], n - 1)
            for k in range(n):
                cx, cy, cz = _unit_vertex(_IDENTITY, vertices[i], k)
                ex, ey, ez = edge_vector_form_factor(cx, cy, cz, px, py, pz)  # reversed: module docstring
                sx += ex
                sy += ey
                sz += ez
                px, py, pz = cx, cy, cz
        out[i, 0] = sx * _INV_TWO_PI
        out[i, 1] = sy * _INV_TWO_PI
        out[i, 2] = sz * _INV_TWO_PI


def _polygons(vertices, name="vertices"):
    """``vertices`` as float64 (..., K, 3), finite, no zero vertex."""
    v = np.asarray(vertices, dtype=np.float64)
    if v.ndim < 2 or v.shape[-1] != 3:
        raise ValueError(f"{name} must have shape (..., K, 3); got {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{name} must be finite")
    if np.any(np.all(v == 0.0, axis=-1)):
        raise ValueError(f"{name} must not contain a zero vector (a vertex at the shading point)")
    return v


def clipped_vertex_capacity(k):
    """The most vertices Sutherland-Hodgman clipping to z >= 0 can give a K-gon:
    K + K // 2 (each run of vertices above the horizon gains two crossings;
    a convex polygon gets at most K + 1)."""
    return int(k) + int(k) // 2


def _flat(v):
    return np.ascontiguousarray(v.reshape((-1,) + v.shape[-2:]))


def transformed_polygon_integrals(m, vertices):
    """Batched :func:`transformed_polygon_form_factor`: ``m`` (..., 3, 3) and
    ``vertices`` (..., K, 3) broadcast over their leading dimensions.  Internal
    helper of :func:`polygon_clamped_cosine_integral` and
    :func:`pbrkit.ltc.distribution.ltc_polygon_integral`."""
    v = _polygons(vertices)
    m = np.asarray(m, dtype=np.float64)
    if m.ndim < 2 or m.shape[-2:] != (3, 3):
        raise ValueError(f"the matrices must have shape (..., 3, 3); got {m.shape}")
    if not np.all(np.isfinite(m)):
        raise ValueError("the matrices must be finite")
    shape = np.broadcast_shapes(m.shape[:-2], v.shape[:-2])
    size = int(np.prod(shape, dtype=np.int64))
    out = np.empty(size)
    if size == 0:
        return out.reshape(shape)
    v = _flat(np.broadcast_to(v, shape + v.shape[-2:]))
    if m.size == 9:  # one matrix for every polygon: not copied per polygon
        m = np.ascontiguousarray(m.reshape(1, 3, 3))
    else:
        m = _flat(np.broadcast_to(m, shape + (3, 3)))
    _form_factor_kernel(m, v, out)
    return out.reshape(shape)


def polygon_clamped_cosine_integral(vertices):
    """The integral of D_o(w) = max(0, w_z) / pi over each spherical polygon
    (the form factor), ``vertices`` (..., K, 3) -> (...).

    Closed form of Lambert / Arvo (Arvo 1995; Heitz et al. 2016, eq. 11)
    after exact clipping to the upper hemisphere (:func:`polygon_form_factor`
    on every polygon, in a parallel Numba kernel).  Signed: positive when the
    vertices run counter-clockwise as seen from the shading point (the
    polygon's right-hand normal points at it); take ``abs`` for a two-sided
    emitter or ``max(0, .)`` for a one-sided one (module docstring).  Vertices need not
    be unit length; any K (a polygon with K < 3 gives 0).  Raises ValueError
    for a non-finite or zero vertex.  No roughness remap is involved.
    """
    v = _polygons(vertices)
    return transformed_polygon_integrals(_IDENTITY, v)


def clip_to_horizon(vertices):
    """The polygons ``vertices`` (..., K, 3) clipped to the upper hemisphere
    z >= 0: ``(clipped, count)`` with ``clipped`` (..., K + K // 2, 3) unit
    vectors and ``count`` (...) the number of vertices of each clipped polygon.

    Sutherland-Hodgman against the plane z = 0 (Heitz et al. 2016, ``ClipQuadToHorizon``;
    :func:`clip_polygon_to_horizon`); vertices on the horizon count as above
    it, crossing points have z = 0 exactly.  Rows past ``count`` repeat the
    last vertex (all zeros when nothing is left), so the padded polygon has
    the same integral.  No roughness remap is involved.
    """
    v = _polygons(vertices)
    shape = v.shape[:-2]
    k = v.shape[-2]
    capacity = clipped_vertex_capacity(k)
    flat = _flat(v)
    out = np.zeros((flat.shape[0], capacity, 3))
    counts = np.zeros(flat.shape[0], dtype=np.int64)
    if flat.shape[0] and capacity:
        _clip_kernel(flat, out, counts)
    return out.reshape(shape + (capacity, 3)), counts.reshape(shape)


def polygon_vector_form_factor(vertices):
    """Arvo's irradiance vector of each polygon, *not* clipped:
    F = 1 / (2 pi) sum_i theta_i (p_{i+1} x p_i) / |p_{i+1} x p_i|, (..., K, 3) -> (..., 3).

    Arvo 1995; Heitz's and three.js's "vector form factor" (Hill &
    Heitz 2016, the sphere approximation of horizon clipping, uses its length
    and direction).  F . n is the signed integral of (n . w) / pi over the
    polygon for any unit n (unclamped), so F_z equals
    :func:`polygon_clamped_cosine_integral` for a polygon above the horizon,
    and F points toward a polygon that faces the shading point.
    Same sign convention and robustness as the module docstring.  No
    roughness remap is involved.
    """
    v = _polygons(vertices)
    shape = v.shape[:-2]
    flat = _flat(v)
    out = np.empty((flat.shape[0], 3))
    if flat.shape[0]:
        _vector_form_factor_kernel(flat, out)
    return out.reshape(shape + (3,))
