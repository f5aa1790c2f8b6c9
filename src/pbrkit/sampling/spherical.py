"""Solid-angle sampling of area-light shapes: directions from a shading point o
toward a rectangle, a triangle, a sphere or a disk, each with its exact pdf
with respect to solid angle, for the Monte Carlo reference renderer.

The shapes are sampled by the solid angle they subtend, so the pdf of every
direction that reaches the shape is the constant 1 / Omega (rectangle:
Urena, Fajardo, King 2013; triangle: Arvo 1995; sphere: the uniform cone of
pbrt-v4), except the disk, sampled uniformly by area (Shirley & Chiu's
concentric map) with the pdf converted to solid angle, d^2 / (A |cos|).

Every sampler is a :func:`pbrkit.core.jit.dual_use` function of plain floats
(callable from Python, and compiled into any Numba kernel that calls it) and
returns the same tuple::

    (dx, dy, dz, distance, pdf)

a unit direction from o, the distance from o along it to the point hit on the
shape (the near side of a sphere), and the solid-angle pdf.  A configuration
that cannot be sampled returns ``(0, 0, 0, 0, 0)``: pdf 0 means "no sample"
(the caller skips the light or falls back to area sampling), never NaN.
That happens for a degenerate shape (zero area or radius), a shading point in
the plane of a rectangle or triangle, inside (or on) a sphere, and for a
rectangle or triangle whose solid angle is below :data:`MIN_SOLID_ANGLE`
(1e-9 sr), where Urena's inversion, which keeps the fraction of Omega below a
sample to about 1e-15 / Omega, would be off by more than ~1e-6; the matching
``*_pdf`` functions return 0 there too, so a multiple-importance weight
computed with them agrees with the sampler.

The vectorised NumPy functions at the end (``sample_spherical_rectangles``,
``sample_spherical_triangles``, ``sample_sphere_cones``, ``sample_disks``,
and the solid angles and pdfs) broadcast arrays of points and ``u`` of shape
(..., 2) and run one parallel Numba kernel over them.

Frames: any right-handed world frame (``docs/CONVENTIONS.md``); nothing here
depends on which axis is up.  No roughness is involved.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import dual_use, row_kernel
from ..core.vec import orthonormal_basis_xyz
from .warps import unit_square, warp_concentric_disk

__all__ = [
    "MIN_SOLID_ANGLE",
    "DISK_COS_MIN",
    "triangle_solid_angle",
    "rectangle_solid_angle",
    "spherical_rectangle_pdf",
    "sample_spherical_rectangle",
    "spherical_triangle_pdf",
    "sample_spherical_triangle",
    "sphere_cone_pdf",
    "sample_sphere_cone",
    "disk_solid_angle_pdf",
    "area_solid_angle_pdf",
    "sample_disk_area",
    "triangle_solid_angles",
    "rectangle_solid_angles",
    "sample_spherical_rectangles",
    "spherical_rectangle_pdfs",
    "sample_spherical_triangles",
    "spherical_triangle_pdfs",
    "sample_sphere_cones",
    "sphere_cone_pdfs",
    "sample_disks",
    "disk_solid_angle_pdfs",
]

_PI = math.pi
_TWO_PI = 2.0 * math.pi

#: Rectangles and triangles subtending less than this (steradians) are not
#: sampled by solid angle (pdf 0; the caller samples them by area or skips them):
#: Urena's inversion works with angles near pi and keeps the fraction of Omega
#: below a sample to ~1e-15 / Omega.  A square of side 1 at distance 1000
#: subtends 1e-6 sr, at distance 30000 about 1e-9 sr.
MIN_SOLID_ANGLE = 1e-9
#: A disk sample whose |cos| (disk normal vs the direction) is at most this gets pdf 0.
DISK_COS_MIN = 1e-12


# =========================================================================
# Small scalar helpers
# =========================================================================


@dual_use
def _clamp(x, lo, hi):
    return min(max(x, lo), hi)


@dual_use
def _length(x, y, z):
    return math.sqrt(x * x + y * y + z * z)


@dual_use
def _no_sample():
    return 0.0, 0.0, 0.0, 0.0, 0.0


@dual_use
def _direction_and_distance(px, py, pz, pdf):
    """(p / |p|, |p|, pdf), or no sample when p is zero or not finite."""
    dist = _length(px, py, pz)
    if not (dist > 0.0 and dist < math.inf):
        return _no_sample()
    inv = 1.0 / dist
    return px * inv, py * inv, pz * inv, dist, pdf


@dual_use
def _triangle_solid_angle_unit(ax, ay, az, bx, by, bz, cx, cy, cz):
    """Van Oosterom & Strackee's solid angle with the three vertices pre-scaled to
    a maximum component of 1 (no overflow); the triple product is taken with the
    edge vectors, a . ((b - a) x (c - a)), exact for a tiny triangle's area."""
    la = _length(ax, ay, az)
    lb = _length(bx, by, bz)
    lc = _length(cx, cy, cz)
    if la == 0.0 or lb == 0.0 or lc == 0.0:
        return 0.0
    e1x = bx - ax
    e1y = by - ay
    e1z = bz - az
    e2x = cx - ax
    e2y = cy - ay
    e2z = cz - az
    triple = ax * (e1y * e2z - e1z * e2y) + ay * (e1z * e2x - e1x * e2z) + az * (e1x * e2y - e1y * e2x)
    if triple == 0.0:
        return 0.0  # seen edge-on (or no area): not the formula's 2 pi inside the triangle
    ab = ax * bx + ay * by + az * bz
    ac = ax * cx + ay * cy + az * cz
    bc = bx * cx + by * cy + bz * cz
    denominator = la * lb * lc + ab * lc + ac * lb + bc * la
    return 2.0 * math.atan2(abs(triple), denominator)


@dual_use
def _max_abs9(ax, ay, az, bx, by, bz, cx, cy, cz):
    return max(abs(ax), abs(ay), abs(az), abs(bx), abs(by), abs(bz), abs(cx), abs(cy), abs(cz))


# =========================================================================
# Solid angles
# =========================================================================


@dual_use
def triangle_solid_angle(ax, ay, az, bx, by, bz, cx, cy, cz):
    """Solid angle (sr, >= 0) of the triangle with vertices a, b, c given relative to
    the shading point (any non-zero lengths).

    Van Oosterom & Strackee, "The Solid Angle of a Plane Triangle", IEEE Trans.
    Biomedical Engineering BME-30(2), 1983, pp. 125-126, the closed form
    tan(Omega / 2) = |a . (b x c)| / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|),
    evaluated as Omega = 2 atan2(|a . (b x c)|, denominator), which is right on
    both sides of Omega = pi (a negative denominator).  The vertices are first
    scaled to a largest component of 1 and the triple product is written
    a . ((b - a) x (c - a)).  A point exactly in the triangle's plane sees it
    edge-on and gets 0 (the formula would give 2 pi inside the triangle, the
    limit from either side), as do a zero vertex, a triangle without area and
    non-finite input.
    """
    m = _max_abs9(ax, ay, az, bx, by, bz, cx, cy, cz)
    if not (m > 0.0 and m < math.inf):
        return 0.0
    s = 1.0 / m
    return _triangle_solid_angle_unit(ax * s, ay * s, az * s, bx * s, by * s, bz * s, cx * s, cy * s, cz * s)


@dual_use
def _rectangle_frame(ox, oy, oz, sx, sy, sz, exx, exy, exz, eyx, eyy, eyz):
    """The rectangle in its local frame: (ok, x0, y0, x1, y1, z0, x-hat (3 floats),
    y-hat (3), d (3)) with x-hat = ex / |ex|, y-hat = ey / |ey|,
    z-hat = normalize(x-hat x y-hat), d = s - o, (x0, y0, z0) the components of d
    and x1 = x0 + |ex|, y1 = y0 + |ey| (Urena et al. 2013, the local reference system R)."""
    exl = _length(exx, exy, exz)
    eyl = _length(eyx, eyy, eyz)
    dx = sx - ox
    dy = sy - oy
    dz = sz - oz
    ok = exl > 0.0 and eyl > 0.0 and exl < math.inf and eyl < math.inf
    if not ok:
        exl = 1.0
        eyl = 1.0
    xhx = exx / exl
    xhy = exy / exl
    xhz = exz / exl
    yhx = eyx / eyl
    yhy = eyy / eyl
    yhz = eyz / eyl
    zhx = xhy * yhz - xhz * yhy
    zhy = xhz * yhx - xhx * yhz
    zhz = xhx * yhy - xhy * yhx
    zl = _length(zhx, zhy, zhz)
    if not (zl > 0.0):
        ok = False
        zl = 1.0
    x0 = dx * xhx + dy * xhy + dz * xhz
    y0 = dx * yhx + dy * yhy + dz * yhz
    z0 = (dx * zhx + dy * zhy + dz * zhz) / zl
    ok = ok and (abs(x0) + abs(y0) + abs(z0)) < math.inf
    return ok, x0, y0, x0 + exl, y0 + eyl, z0, xhx, xhy, xhz, yhx, yhy, yhz, dx, dy, dz


@dual_use
def _rectangle_angles(x0, y0, x1, y1, h):
    """(g0, g1, k) of the spherical rectangle [x0, x1] x [y0, y1] at height h (Urena
    et al. 2013, SphQuadInit): the interior angles at v10 and v11, and
    k = 2 pi - g2 - g3 with the angles g2, g3 at v01, v00.  The interior angle at a
    corner (x, y) is the angle between the planes through o and its two edges,
    atan2(h |v|, +-x y) in closed form (|v| = sqrt(x^2 + y^2 + h^2)), which keeps full
    precision near 0 and pi; k is summed as (pi - g2) + (pi - g3), each an atan2."""
    h2 = h * h
    g0 = math.atan2(h * math.sqrt(x1 * x1 + y0 * y0 + h2), x1 * y0)
    g1 = math.atan2(h * math.sqrt(x1 * x1 + y1 * y1 + h2), -x1 * y1)
    k = (math.atan2(h * math.sqrt(x0 * x0 + y1 * y1 + h2), -x0 * y1)
         + math.atan2(h * math.sqrt(x0 * x0 + y0 * y0 + h2), x0 * y0))
    return g0, g1, k


@dual_use
def _local_rectangle_solid_angle(x0, y0, x1, y1, h):
    """Solid angle of [x0, x1] x [y0, y1] in the plane at distance h from the origin.

    Above 1 sr: Urena et al.'s S = g0 + g1 + g2 + g3 - 2 pi (:func:`_rectangle_angles`),
    good to ~1e-15 absolute.  Below, where S cancels: the two triangles (v00, v10, v11)
    and (v00, v11, v01) by Van Oosterom & Strackee (1983), whose triple products
    are exactly h (x1 - x0)(y1 - y0) (full relative precision for tiny rectangles;
    the triangles alone would lose it for a point close above their shared diagonal)."""
    m = max(abs(x0), abs(y0), abs(x1), abs(y1), h)
    if not (m > 0.0 and m < math.inf) or h == 0.0:
        return 0.0
    s = 1.0 / m
    x0 = x0 * s
    x1 = x1 * s
    y0 = y0 * s
    y1 = y1 * s
    h = h * s
    g0, g1, k = _rectangle_angles(x0, y0, x1, y1, h)
    s_area = g0 + g1 - k
    if s_area > 1.0:
        return s_area
    triple = h * (x1 - x0) * (y1 - y0)
    h2 = h * h
    l00 = math.sqrt(x0 * x0 + y0 * y0 + h2)
    l10 = math.sqrt(x1 * x1 + y0 * y0 + h2)
    l11 = math.sqrt(x1 * x1 + y1 * y1 + h2)
    l01 = math.sqrt(x0 * x0 + y1 * y1 + h2)
    d00_10 = x0 * x1 + y0 * y0 + h2
    d00_11 = x0 * x1 + y0 * y1 + h2
    d10_11 = x1 * x1 + y0 * y1 + h2
    d00_01 = x0 * x0 + y0 * y1 + h2
    d11_01 = x1 * x0 + y1 * y1 + h2
    den1 = l00 * l10 * l11 + d00_10 * l11 + d00_11 * l10 + d10_11 * l00
    den2 = l00 * l11 * l01 + d00_11 * l01 + d00_01 * l11 + d11_01 * l00
    return 2.0 * (math.atan2(triple, den1) + math.atan2(triple, den2))


@dual_use
def rectangle_solid_angle(ox, oy, oz, sx, sy, sz, exx, exy, exz, eyx, eyy, eyz):
    """Solid angle (sr, >= 0) of the rectangle with corner s and orthogonal edges
    ex, ey (the corners are s, s + ex, s + ex + ey, s + ey) seen from o.

    The spherical rectangle of Urena, Fajardo, King, "An Area-Preserving
    Parametrization for Spherical Rectangles", Computer Graphics Forum 32(4)
    (EGSR 2013), pp. 59-66: in the local frame (x along ex, y along ey) the
    rectangle is [x0, x1] x [y0, y1] at height z0.  Its area is the paper's
    S = sum of the interior angles - 2 pi when that exceeds 1 sr, else the sum of
    the two triangles' Van Oosterom & Strackee (1983) solid angles, which keeps
    full relative precision for a tiny, distant or grazing rectangle, where the
    angle sum cancels.  0 for o in the rectangle's plane, a zero edge or non-finite input.
    """
    ok, x0, y0, x1, y1, z0, _, _, _, _, _, _, _, _, _ = _rectangle_frame(
        ox, oy, oz, sx, sy, sz, exx, exy, exz, eyx, eyy, eyz)
    if not ok:
        return 0.0
    return _local_rectangle_solid_angle(x0, y0, x1, y1, abs(z0))


# =========================================================================
# Rectangle (Urena, Fajardo, King 2013)
# =========================================================================


@dual_use
def spherical_rectangle_pdf(ox, oy, oz, sx, sy, sz, exx, exy, exz, eyx, eyy, eyz):
    """Solid-angle pdf of :func:`sample_spherical_rectangle` for any direction from o
    that hits the rectangle: 1 / Omega (:func:`rectangle_solid_angle`;
    Urena et al. 2013), or 0 where the sampler returns no sample
    (Omega < :data:`MIN_SOLID_ANGLE`, o in the plane, degenerate rectangle).
    The caller checks that the direction hits the rectangle."""
    omega = rectangle_solid_angle(ox, oy, oz, sx, sy, sz, exx, exy, exz, eyx, eyy, eyz)
    if not (omega >= MIN_SOLID_ANGLE):
        return 0.0
    return 1.0 / omega


@dual_use
def _one_plus_minus(y, r, dd2):
    """(1 + y / r, 1 - y / r) for r = sqrt(dd2 + y^2) without cancellation: the
    small one of the pair is written dd2 / (r (r + |y|))."""
    small = dd2 / (r * (r + abs(y)))
    if y >= 0.0:
        return 1.0 + y / r, small
    return small, 1.0 - y / r


@dual_use
def sample_spherical_rectangle(ox, oy, oz, sx, sy, sz, exx, exy, exz, eyx, eyy, eyz, u1, u2):
    """Direction toward the rectangle (corner s, orthogonal edges ex, ey) seen from o,
    uniform in solid angle; returns (dx, dy, dz, distance, pdf = 1 / Omega).

    Urena, Fajardo, King, "An Area-Preserving Parametrization for Spherical
    Rectangles", Computer Graphics Forum 32(4) (EGSR 2013), pp. 59-66, with
    its code listing (SphQuadInit, SphQuadSample).  Local reference system: x along ex, y along ey, with z chosen so
    that the rectangle lies at z0 < 0 (z is flipped when o is on the other side
    of the plane, so both sides work).  The interior angles g_i at the corners
    are atan2(|z0| |v|, -/+ x y) (the angle between the edge normals n_i of
    the paper, in closed form), k = 2 pi - g2 - g3 and S = g0 + g1 - k.
    First u1 picks the sub-rectangle [x0, xu] of area u1 S, with
    au = u1 S + k, fu = (cos(au) b0 - b1) / sin(au), cu = sign(fu) / sqrt(fu^2 + b0^2),
    xu = -cu z0 / sqrt(1 - cu^2).  Written here without a division by sin(au) and
    without the cancellations of 1 - cu^2 and of cos(au) b0 - b1 (which decide
    everything when o is close to the plane): with b0 = cos(beta0), b1 = cos(beta1),
    xu = -|z0| sin(au) / sqrt(R), R = (cos(au + beta0) - cos(beta1)) (cos(au - beta0) -
    cos(beta1)) = fu^2 sin^2(au) - (1 - b0^2) sin^2(au), each factor a product of two
    sines; fu has the sign of -sin(au) on the whole range, so xu = 0 at au = pi.
    Then along the segment x = xu, y is uniform in h = y / sqrt(d^2 + y^2)
    (d^2 = xu^2 + z0^2) between h0 and h1, yv = h d / sqrt(1 - h^2); 1 - h and
    1 + h are interpolated separately, each computed without cancellation, so a
    grazing configuration keeps its precision.  xu and yv are clamped to the
    rectangle, and the point is s + (xu - x0) x-hat + (yv - y0) y-hat.

    The pdf is 1 / Omega with Omega from :func:`rectangle_solid_angle` (accurate to
    rounding also where S cancels).  The map itself is exact up to the rounding
    of au, so the fraction of Omega below a sample is off by at most ~1e-15 / Omega
    (measured against 40-digit arithmetic in the tests).  No sample (pdf 0, all zeros) for
    o in the plane, a zero edge or Omega < :data:`MIN_SOLID_ANGLE`.  ex and ey
    must be orthogonal (a parallelogram is not a spherical rectangle).
    """
    ok, x0, y0, x1, y1, z0, xhx, xhy, xhz, yhx, yhy, yhz, dx, dy, dz = _rectangle_frame(
        ox, oy, oz, sx, sy, sz, exx, exy, exz, eyx, eyy, eyz)
    if not ok:
        return _no_sample()
    h = abs(z0)  # the paper's z0 is -h
    omega = _local_rectangle_solid_angle(x0, y0, x1, y1, h)
    if not (omega >= MIN_SOLID_ANGLE):
        return _no_sample()
    # work at unit scale (products of coordinates neither overflow nor underflow)
    m = max(abs(x0), abs(y0), abs(x1), abs(y1), h)
    inv_m = 1.0 / m
    x0 *= inv_m
    y0 *= inv_m
    x1 *= inv_m
    y1 *= inv_m
    h *= inv_m
    h2 = h * h
    g0, g1, k = _rectangle_angles(x0, y0, x1, y1, h)
    s_area = g0 + g1 - k
    au = _clamp(u1, 0.0, 1.0) * s_area + k
    # b0 = n0.z = cos(beta0) and b1 = n2.z = cos(beta1), sin(beta) = h / |(0, h, y)|
    beta0 = math.atan2(h, -y0)
    beta1 = math.atan2(h, y1)
    # fu^2 + b0^2 - 1 = R / sin^2(au) with R = num^2 - (1 - b0^2) sin^2(au), num = cos(au) b0 - b1:
    # R = (cos(au + beta0) - cos(beta1)) (cos(au - beta0) - cos(beta1)), a product of sines.
    # num < 0 on the whole range (num = 0 would need |cu| >= 1), so sign(xu) = -sign(sin(au)):
    # xu = 0 at au = pi, where the two new interior angles are right angles.
    radicand = 4.0 * (math.sin(0.5 * (au + beta0 + beta1)) * math.sin(0.5 * (au + beta0 - beta1))
                      * math.sin(0.5 * (au - beta0 + beta1)) * math.sin(0.5 * (au - beta0 - beta1)))
    if radicand > 0.0:
        xu = -h * math.sin(au) / math.sqrt(radicand)
    else:
        xu = x1 if au > _PI else x0
    xu = _clamp(xu, x0, x1)
    # the second step: y uniform in h = y / sqrt(d^2 + y^2) at x = xu
    dd2 = xu * xu + h2
    dd = math.sqrt(dd2)
    r0 = math.sqrt(dd2 + y0 * y0)
    r1 = math.sqrt(dd2 + y1 * y1)
    p0, q0 = _one_plus_minus(y0, r0, dd2)
    p1, q1 = _one_plus_minus(y1, r1, dd2)
    v = _clamp(u2, 0.0, 1.0)
    p = (1.0 - v) * p0 + v * p1  # 1 + hv
    q = (1.0 - v) * q0 + v * q1  # 1 - hv
    hv = 0.5 * (p - q)
    pq = p * q
    if pq > 0.0:
        yv = hv * dd / math.sqrt(pq)
    else:
        yv = y1 if hv > 0.0 else y0
    yv = _clamp(yv, y0, y1)
    fx = (xu - x0) * m
    fy = (yv - y0) * m
    return _direction_and_distance(dx + fx * xhx + fy * yhx, dy + fx * xhy + fy * yhy, dz + fx * xhz + fy * yhz,
                                   1.0 / omega)


# =========================================================================
# Triangle (Arvo 1995)
# =========================================================================


@dual_use
def spherical_triangle_pdf(ax, ay, az, bx, by, bz, cx, cy, cz):
    """Solid-angle pdf of :func:`sample_spherical_triangle` for any direction that
    hits the triangle (vertices relative to the shading point): 1 / Omega
    (:func:`triangle_solid_angle`; Arvo 1995), or 0 where the sampler returns
    no sample (Omega < :data:`MIN_SOLID_ANGLE`, the point in the plane, a
    degenerate triangle).  The caller checks that the direction hits it."""
    omega = triangle_solid_angle(ax, ay, az, bx, by, bz, cx, cy, cz)
    if not (omega >= MIN_SOLID_ANGLE):
        return 0.0
    return 1.0 / omega


@dual_use
def sample_spherical_triangle(ax, ay, az, bx, by, bz, cx, cy, cz, u1, u2):
    """Direction toward the triangle with vertices a, b, c (relative to the shading
    point, any non-zero lengths), uniform in solid angle; returns
    (dx, dy, dz, distance, pdf = 1 / Omega).

    Arvo, "Stratified Sampling of Spherical Triangles",
    Proc. SIGGRAPH 95, pp. 437-438 (the sampling algorithm): with unit vertices A, B,
    C, u1 chooses the point C' on the arc AC such that the sub-triangle A B C'
    has area u1 Omega, and u2 chooses the point on the arc B C' with
    1 - cos theta = u2 (1 - B.C') (theta measured from B), which together are an
    area-preserving map of the unit square onto the spherical triangle.
    pbrt-v4 sec. 6.5.4 (SampleSphericalTriangle) discusses the numerically
    careful evaluation; here the arc length b' = |A C'| is solved in closed form
    from Van Oosterom & Strackee's (1983) tangent formula for the sub-triangle,
    tan(b' / 2) = sin(h) (1 + A.B) / (cos(h) |A.(B x T)| - sin(h) B.T),
    h = u1 Omega / 2, T the unit tangent at A toward C (so C' = cos b' A + sin b' T),
    which is Arvo's C' without the cancellations of his q = cos b' for small
    triangles (1 + A.B is taken as |A + B|^2 / 2, exact also when o lies close
    above the edge AB and A, B are nearly antipodal), and 1 - B.C' is taken as
    |C' - B|^2 / 2.  b' is clamped to the
    arc AC, so every direction hits the triangle.  The distance is the
    ray-plane distance to the triangle's plane.

    No sample (pdf 0, all zeros) for a point in the triangle's plane, a
    degenerate triangle or Omega < :data:`MIN_SOLID_ANGLE`.
    """
    m = _max_abs9(ax, ay, az, bx, by, bz, cx, cy, cz)
    if not (m > 0.0 and m < math.inf):
        return _no_sample()
    s = 1.0 / m
    ax *= s
    ay *= s
    az *= s
    bx *= s
    by *= s
    bz *= s
    cx *= s
    cy *= s
    cz *= s
    omega = _triangle_solid_angle_unit(ax, ay, az, bx, by, bz, cx, cy, cz)
    if not (omega >= MIN_SOLID_ANGLE):
        return _no_sample()
    la = _length(ax, ay, az)
    lb = _length(bx, by, bz)
    # unit A and B
    uax = ax / la
    uay = ay / la
    uaz = az / la
    ubx = bx / lb
    uby = by / lb
    ubz = bz / lb
    # T: the unit tangent at A toward C, from the edge c - a (orthogonal part to A)
    ex = cx - ax
    ey = cy - ay
    ez = cz - az
    proj = ex * uax + ey * uay + ez * uaz
    tx = ex - proj * uax
    ty = ey - proj * uay
    tz = ez - proj * uaz
    lt = _length(tx, ty, tz)
    if not (lt > 0.0):
        return _no_sample()
    tx /= lt
    ty /= lt
    tz /= lt
    # the arc AC: tan(b / 2) = |C - A| / |C + A| (unit vectors)
    lc = _length(cx, cy, cz)
    ucx = cx / lc
    ucy = cy / lc
    ucz = cz / lc
    w_max_num = _length(ucx - uax, ucy - uay, ucz - uaz)
    w_max_den = _length(ucx + uax, ucy + uay, ucz + uaz)
    # the sub-triangle A B C' of area u1 Omega
    # 1 + A.B = |A + B|^2 / 2, exact also for a nearly antipodal pair (o close above edge AB)
    one_plus_ab = 0.5 * ((uax + ubx) ** 2 + (uay + uby) ** 2 + (uaz + ubz) ** 2)
    # |A . (B x T)|
    bxt_x = uby * tz - ubz * ty
    bxt_y = ubz * tx - ubx * tz
    bxt_z = ubx * ty - uby * tx
    p_abs = abs(uax * bxt_x + uay * bxt_y + uaz * bxt_z)
    b_dot_t = ubx * tx + uby * ty + ubz * tz
    half = 0.5 * _clamp(u1, 0.0, 1.0) * omega
    sin_h = math.sin(half)
    cos_h = math.cos(half)
    w_num = sin_h * one_plus_ab
    w_den = cos_h * p_abs - sin_h * b_dot_t
    # w = w_num / w_den, clamped to the arc's w_max = w_max_num / w_max_den
    if w_den > 0.0 and w_num * w_max_den < w_max_num * w_den:
        w = w_num / w_den
        w2 = w * w
        cos_b = (1.0 - w2) / (1.0 + w2)
        sin_b = 2.0 * w / (1.0 + w2)
        cpx = cos_b * uax + sin_b * tx
        cpy = cos_b * uay + sin_b * ty
        cpz = cos_b * uaz + sin_b * tz
    else:
        cpx = ucx
        cpy = ucy
        cpz = ucz
    # the point on the arc B -> C' with 1 - cos theta = u2 (1 - B.C')
    dbx = cpx - ubx
    dby = cpy - uby
    dbz = cpz - ubz
    one_minus_bc = 0.5 * (dbx * dbx + dby * dby + dbz * dbz)
    eps = _clamp(u2, 0.0, 1.0) * one_minus_bc
    cos_t = 1.0 - eps
    sin_t = math.sqrt(max(eps * (2.0 - eps), 0.0))
    # unit normal to B toward C' in their plane: (C' - B) minus its component along B
    along = dbx * ubx + dby * uby + dbz * ubz
    nx = dbx - along * ubx
    ny = dby - along * uby
    nz = dbz - along * ubz
    ln = _length(nx, ny, nz)
    if ln > 0.0:
        nx /= ln
        ny /= ln
        nz /= ln
    else:
        sin_t = 0.0
        cos_t = 1.0
    wx = cos_t * ubx + sin_t * nx
    wy = cos_t * uby + sin_t * ny
    wz = cos_t * ubz + sin_t * nz
    lw = _length(wx, wy, wz)
    wx /= lw
    wy /= lw
    wz /= lw
    # distance to the triangle's plane along w
    e1x = bx - ax
    e1y = by - ay
    e1z = bz - az
    gx = e1y * ez - e1z * ey
    gy = e1z * ex - e1x * ez
    gz = e1x * ey - e1y * ex
    along_n = wx * gx + wy * gy + wz * gz
    offset = ax * gx + ay * gy + az * gz
    if along_n == 0.0 or (along_n > 0.0) != (offset > 0.0):
        return _no_sample()
    dist = offset / along_n * m
    return wx, wy, wz, dist, 1.0 / omega


# =========================================================================
# Sphere (the subtended cone, pbrt-v4)
# =========================================================================


@dual_use
def _sphere_cone(cx, cy, cz, radius):
    """(ok, |c|, cos theta_max, 1 - cos theta_max) of the cone a sphere subtends,
    each without cancellation: cos^2 theta_max = (|c| - r)(|c| + r) / |c|^2 and
    1 - cos theta_max = sin^2 theta_max / (1 + cos theta_max)."""
    dc = _length(cx, cy, cz)
    r = abs(radius)
    if not (r > 0.0 and dc > r and dc < math.inf):
        return False, 1.0, 1.0, 0.0
    sin_max = r / dc
    cos_max = math.sqrt(max((dc - r) * (dc + r), 0.0)) / dc
    one_minus = sin_max * sin_max / (1.0 + cos_max)
    if not (one_minus > 0.0):
        return False, 1.0, 1.0, 0.0
    return True, dc, cos_max, one_minus


@dual_use
def sphere_cone_pdf(cx, cy, cz, radius):
    """Solid-angle pdf of :func:`sample_sphere_cone` for any direction inside the cone
    the sphere (centre c relative to the shading point, radius r) subtends:
    1 / (2 pi (1 - cos theta_max)), sin theta_max = r / |c| (pbrt-v4 sec. 6.2,
    "Sampling": Sphere::PDF).  0 for a shading point inside or on the sphere,
    r <= 0, or non-finite input.  The caller checks that the direction hits it."""
    ok, _, _, one_minus = _sphere_cone(cx, cy, cz, radius)
    if not ok:
        return 0.0
    return 1.0 / (_TWO_PI * one_minus)


@dual_use
def sample_sphere_cone(cx, cy, cz, radius, u1, u2):
    """Direction toward a sphere (centre c relative to the shading point, radius r),
    uniform over the cone it subtends; returns (dx, dy, dz, distance, pdf).

    Pharr, Jakob, Humphreys, "Physically Based Rendering", 4th ed. (pbrt-v4),
    sec. 6.2 (Spheres), "Sampling" (Sphere::Sample with a reference point
    outside the sphere): sin^2 theta_max = r^2 / |c|^2, cos theta =
    1 - u1 (1 - cos theta_max), phi = 2 pi u2 about the axis c / |c| (frame of
    Duff et al. 2017), pdf = 1 / (2 pi (1 - cos theta_max)) (the uniform cone,
    pbrt-v4 appendix A.5, SampleUniformCone).  pbrt switches to a Taylor
    expansion of sin^2 theta for cones under 1.5 degrees; here the same
    accuracy comes from never subtracting nearly equal numbers:
    1 - cos theta_max = sin^2 theta_max / (1 + cos theta_max), and with
    e = u1 (1 - cos theta_max), sin^2 theta = e (2 - e).  The distance to the
    near intersection, |c| cos theta - sqrt(r^2 - |c|^2 sin^2 theta), is
    evaluated as (|c|^2 - r^2) / (|c| (cos theta + s)) with
    s^2 = (1 - u1)(1 - cos theta_max)(cos theta + cos theta_max), free of
    cancellation for any size and distance.

    No sample (pdf 0, all zeros) when the point is inside or on the sphere
    (pbrt-v4 then samples by area), for r <= 0 or non-finite input.
    """
    ok, dc, cos_max, one_minus = _sphere_cone(cx, cy, cz, radius)
    if not ok:
        return _no_sample()
    v = _clamp(u1, 0.0, 1.0)
    eps = v * one_minus
    cos_t = 1.0 - eps
    sin_t = math.sqrt(max(eps * (2.0 - eps), 0.0))
    phi = _TWO_PI * u2
    wx = cx / dc
    wy = cy / dc
    wz = cz / dc
    t_vec, b_vec = orthonormal_basis_xyz(wx, wy, wz)
    sc = sin_t * math.cos(phi)
    ss = sin_t * math.sin(phi)
    dx = sc * t_vec[0] + ss * b_vec[0] + cos_t * wx
    dy = sc * t_vec[1] + ss * b_vec[1] + cos_t * wy
    dz = sc * t_vec[2] + ss * b_vec[2] + cos_t * wz
    ld = _length(dx, dy, dz)
    dx /= ld
    dy /= ld
    dz /= ld
    r = abs(radius)
    s = math.sqrt(max((1.0 - v) * one_minus * (cos_t + cos_max), 0.0))
    dist = (dc - r) * (dc + r) / (dc * (cos_t + s))
    return dx, dy, dz, dist, 1.0 / (_TWO_PI * one_minus)


# =========================================================================
# Disk (area sampling by the concentric map)
# =========================================================================


@dual_use
def area_solid_angle_pdf(distance, abs_cos, area):
    """Solid-angle pdf of a point drawn uniformly by area on a planar shape of area A,
    seen at ``distance`` with |cos| = |n . w| between its normal and the direction:
    the area density 1 / A times the Jacobian d^2 / |cos| of area to solid angle,
    d omega = |cos| dA / d^2 (pbrt-v4 sec. 4.2.3, eq. (4.9)).  0 for |cos| <=
    :data:`DISK_COS_MIN`, A <= 0 or non-finite input."""
    c = abs(abs_cos)
    if not (c > DISK_COS_MIN and area > 0.0 and area < math.inf and distance < math.inf):
        return 0.0
    pdf = distance * distance / (area * c)
    if not (pdf < math.inf):
        return 0.0
    return pdf


@dual_use
def disk_solid_angle_pdf(distance, abs_cos, radius):
    """Solid-angle pdf of :func:`sample_disk_area` for a direction that hits the disk
    at ``distance`` with |cos| = |n . w| between the disk normal and the
    direction: :func:`area_solid_angle_pdf` with A = pi r^2.  0 for |cos| <=
    :data:`DISK_COS_MIN`, r <= 0 or non-finite input."""
    return area_solid_angle_pdf(distance, abs_cos, _PI * radius * radius)


@dual_use
def sample_disk_area(ox, oy, oz, cx, cy, cz, nx, ny, nz, radius, u1, u2):
    """A point uniform by area on the disk (centre c, normal n, radius r) and the
    direction to it from o; returns (dx, dy, dz, distance, pdf) with the
    solid-angle pdf d^2 / (pi r^2 |n . w|) (:func:`disk_solid_angle_pdf`).

    The point is c + r (x t + y b) with (x, y) from Shirley & Chiu's concentric
    map (:func:`pbrkit.sampling.warps.warp_concentric_disk`; Shirley & Chiu 1997,
    "A Low Distortion Map Between Disk and Square", JGT 2(3)) and (t, b) the
    tangent frame of n (Duff et al. 2017); pbrt-v4 sec. 6.4 (Disks),
    "Sampling" (Disk::Sample, converted to solid angle as in Shape::Sample by
    a reference point).  n need not be unit length.  No sample (pdf 0, all
    zeros) for r <= 0, a zero normal, o on the disk, or |cos| at most
    :data:`DISK_COS_MIN` (o in the disk's plane).
    """
    ln = _length(nx, ny, nz)
    r = abs(radius)
    if not (ln > 0.0 and ln < math.inf and r > 0.0 and r < math.inf):
        return _no_sample()
    nx /= ln
    ny /= ln
    nz /= ln
    t_vec, b_vec = orthonormal_basis_xyz(nx, ny, nz)
    x, y = warp_concentric_disk(_clamp(u1, 0.0, 1.0), _clamp(u2, 0.0, 1.0))
    x = float(x) * r
    y = float(y) * r
    px = cx - ox + x * t_vec[0] + y * b_vec[0]
    py = cy - oy + x * t_vec[1] + y * b_vec[1]
    pz = cz - oz + x * t_vec[2] + y * b_vec[2]
    dist = _length(px, py, pz)
    if not (dist > 0.0 and dist < math.inf):
        return _no_sample()
    dx = px / dist
    dy = py / dist
    dz = pz / dist
    pdf = disk_solid_angle_pdf(dist, dx * nx + dy * ny + dz * nz, r)
    if pdf == 0.0:
        return _no_sample()
    return dx, dy, dz, dist, pdf


# =========================================================================
# Kernels and the NumPy API
# =========================================================================


@row_kernel(0)
def _rectangle_kernel(start, stop, o, s, ex, ey, u, out_dir, out_dist, out_pdf):
    for i in range(start, stop):
        dx, dy, dz, dist, pdf = sample_spherical_rectangle(
            o[i, 0], o[i, 1], o[i, 2], s[i, 0], s[i, 1], s[i, 2], ex[i, 0], ex[i, 1], ex[i, 2],
            ey[i, 0], ey[i, 1], ey[i, 2], u[i, 0], u[i, 1])
        out_dir[i, 0] = dx
        out_dir[i, 1] = dy
        out_dir[i, 2] = dz
        out_dist[i] = dist
        out_pdf[i] = pdf


@row_kernel(0)
def _rectangle_measure_kernel(start, stop, o, s, ex, ey, pdf, out):
    for i in range(start, stop):
        args = (o[i, 0], o[i, 1], o[i, 2], s[i, 0], s[i, 1], s[i, 2], ex[i, 0], ex[i, 1], ex[i, 2],
                ey[i, 0], ey[i, 1], ey[i, 2])
        if pdf:
            out[i] = spherical_rectangle_pdf(*args)
        else:
            out[i] = rectangle_solid_angle(*args)


@row_kernel(0)
def _triangle_kernel(start, stop, o, a, b, c, u, out_dir, out_dist, out_pdf):
    for i in range(start, stop):
        dx, dy, dz, dist, pdf = sample_spherical_triangle(
            a[i, 0] - o[i, 0], a[i, 1] - o[i, 1], a[i, 2] - o[i, 2], b[i, 0] - o[i, 0], b[i, 1] - o[i, 1],
            b[i, 2] - o[i, 2], c[i, 0] - o[i, 0], c[i, 1] - o[i, 1], c[i, 2] - o[i, 2], u[i, 0], u[i, 1])
        out_dir[i, 0] = dx
        out_dir[i, 1] = dy
        out_dir[i, 2] = dz
        out_dist[i] = dist
        out_pdf[i] = pdf


@row_kernel(0)
def _triangle_measure_kernel(start, stop, o, a, b, c, pdf, out):
    for i in range(start, stop):
        args = (a[i, 0] - o[i, 0], a[i, 1] - o[i, 1], a[i, 2] - o[i, 2], b[i, 0] - o[i, 0], b[i, 1] - o[i, 1],
                b[i, 2] - o[i, 2], c[i, 0] - o[i, 0], c[i, 1] - o[i, 1], c[i, 2] - o[i, 2])
        if pdf:
            out[i] = spherical_triangle_pdf(*args)
        else:
            out[i] = triangle_solid_angle(*args)


@row_kernel(0)
def _sphere_kernel(start, stop, o, c, radius, u, out_dir, out_dist, out_pdf):
    for i in range(start, stop):
        dx, dy, dz, dist, pdf = sample_sphere_cone(c[i, 0] - o[i, 0], c[i, 1] - o[i, 1], c[i, 2] - o[i, 2],
                                                   radius[i], u[i, 0], u[i, 1])
        out_dir[i, 0] = dx
        out_dir[i, 1] = dy
        out_dir[i, 2] = dz
        out_dist[i] = dist
        out_pdf[i] = pdf


@row_kernel(0)
def _sphere_pdf_kernel(start, stop, o, c, radius, out):
    for i in range(start, stop):
        out[i] = sphere_cone_pdf(c[i, 0] - o[i, 0], c[i, 1] - o[i, 1], c[i, 2] - o[i, 2], radius[i])


@row_kernel(0)
def _disk_kernel(start, stop, o, c, n, radius, u, out_dir, out_dist, out_pdf):
    for i in range(start, stop):
        dx, dy, dz, dist, pdf = sample_disk_area(o[i, 0], o[i, 1], o[i, 2], c[i, 0], c[i, 1], c[i, 2],
                                                 n[i, 0], n[i, 1], n[i, 2], radius[i], u[i, 0], u[i, 1])
        out_dir[i, 0] = dx
        out_dir[i, 1] = dy
        out_dir[i, 2] = dz
        out_dist[i] = dist
        out_pdf[i] = pdf


def _points(value, name):
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 0 or a.shape[-1] != 3:
        raise ValueError(f"{name} must have 3 components in its last axis; got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite")
    return a


def _radius(value):
    r = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(r) & (r >= 0.0)):
        raise ValueError("radius must be finite and non-negative")
    return r


def _broadcast(vectors, scalars=()):
    """Broadcast (..., k) arrays and (...) scalars to one leading shape; returns the
    shape and C-contiguous flattened copies ((N, k) and (N,))."""
    shapes = [v.shape[:-1] for v in vectors] + [np.shape(s) for s in scalars]
    shape = np.broadcast_shapes(*shapes)
    flat_vectors = [np.ascontiguousarray(np.broadcast_to(v, shape + v.shape[-1:]).reshape(-1, v.shape[-1]))
                    for v in vectors]
    flat_scalars = [np.ascontiguousarray(np.broadcast_to(s, shape).reshape(-1)) for s in scalars]
    return shape, flat_vectors, flat_scalars


def _outputs(n):
    return np.empty((n, 3)), np.empty(n), np.empty(n)


def _reshape(shape, directions, distances, pdf):
    return directions.reshape(shape + (3,)), distances.reshape(shape), pdf.reshape(shape)


def _check_orthogonal(ex, ey):
    dot = np.sum(ex * ey, axis=-1)
    scale = np.linalg.norm(ex, axis=-1) * np.linalg.norm(ey, axis=-1)
    if np.any(np.abs(dot) > 1e-9 * scale):
        raise ValueError("ex and ey must be orthogonal (the rectangle's edges)")


def triangle_solid_angles(o, v0, v1, v2):
    """Solid angles (...) of triangles (v0, v1, v2) seen from points o, all (..., 3)
    broadcast together (:func:`triangle_solid_angle`, Van Oosterom & Strackee 1983)."""
    shape, (o, a, b, c), _ = _broadcast([_points(o, "o"), _points(v0, "v0"), _points(v1, "v1"), _points(v2, "v2")])
    out = np.empty(o.shape[0])
    _triangle_measure_kernel(o, a, b, c, False, out)
    return out.reshape(shape)


def spherical_triangle_pdfs(o, v0, v1, v2):
    """Solid-angle pdfs (...) of :func:`sample_spherical_triangles` (1 / Omega, or 0
    where it gives no sample; :func:`spherical_triangle_pdf`)."""
    shape, (o, a, b, c), _ = _broadcast([_points(o, "o"), _points(v0, "v0"), _points(v1, "v1"), _points(v2, "v2")])
    out = np.empty(o.shape[0])
    _triangle_measure_kernel(o, a, b, c, True, out)
    return out.reshape(shape)


def sample_spherical_triangles(o, v0, v1, v2, u):
    """Directions from o toward triangles (v0, v1, v2) uniform in solid angle
    (:func:`sample_spherical_triangle`, Arvo 1995).  o, v0, v1, v2 (..., 3) and
    u (..., 2) broadcast; returns (directions (..., 3), distances (...), pdf (...)),
    all zero where no sample is possible."""
    shape, (o, a, b, c, u), _ = _broadcast([_points(o, "o"), _points(v0, "v0"), _points(v1, "v1"),
                                            _points(v2, "v2"), unit_square(u)])
    out = _outputs(o.shape[0])
    _triangle_kernel(o, a, b, c, u, *out)
    return _reshape(shape, *out)


def rectangle_solid_angles(o, corner, ex, ey):
    """Solid angles (...) of rectangles (corner, orthogonal edges ex, ey) seen from o
    (:func:`rectangle_solid_angle`)."""
    ex = _points(ex, "ex")
    ey = _points(ey, "ey")
    _check_orthogonal(ex, ey)
    shape, (o, s, ex, ey), _ = _broadcast([_points(o, "o"), _points(corner, "corner"), ex, ey])
    out = np.empty(o.shape[0])
    _rectangle_measure_kernel(o, s, ex, ey, False, out)
    return out.reshape(shape)


def spherical_rectangle_pdfs(o, corner, ex, ey):
    """Solid-angle pdfs (...) of :func:`sample_spherical_rectangles` (1 / Omega, or 0
    where it gives no sample; :func:`spherical_rectangle_pdf`)."""
    ex = _points(ex, "ex")
    ey = _points(ey, "ey")
    _check_orthogonal(ex, ey)
    shape, (o, s, ex, ey), _ = _broadcast([_points(o, "o"), _points(corner, "corner"), ex, ey])
    out = np.empty(o.shape[0])
    _rectangle_measure_kernel(o, s, ex, ey, True, out)
    return out.reshape(shape)


def sample_spherical_rectangles(o, corner, ex, ey, u):
    """Directions from o toward rectangles (corner, orthogonal edges ex, ey) uniform
    in solid angle (:func:`sample_spherical_rectangle`, Urena et al. 2013).
    o, corner, ex, ey (..., 3) and u (..., 2) broadcast; returns
    (directions (..., 3), distances (...), pdf (...)), all zero where no sample
    is possible."""
    ex = _points(ex, "ex")
    ey = _points(ey, "ey")
    _check_orthogonal(ex, ey)
    shape, (o, s, ex, ey, u), _ = _broadcast([_points(o, "o"), _points(corner, "corner"), ex, ey, unit_square(u)])
    out = _outputs(o.shape[0])
    _rectangle_kernel(o, s, ex, ey, u, *out)
    return _reshape(shape, *out)


def sphere_cone_pdfs(o, center, radius):
    """Solid-angle pdfs (...) of :func:`sample_sphere_cones` (:func:`sphere_cone_pdf`):
    1 / (2 pi (1 - cos theta_max)), 0 for points inside a sphere."""
    shape, (o, c), (r,) = _broadcast([_points(o, "o"), _points(center, "center")], [_radius(radius)])
    out = np.empty(o.shape[0])
    _sphere_pdf_kernel(o, c, r, out)
    return out.reshape(shape)


def sample_sphere_cones(o, center, radius, u):
    """Directions from o uniform in the cones subtended by spheres (centre, radius)
    (:func:`sample_sphere_cone`, pbrt-v4 sec. 6.2).  o, center (..., 3), radius (...)
    and u (..., 2) broadcast; returns (directions (..., 3), distances to the near
    hit (...), pdf (...)), all zero for points inside a sphere."""
    shape, (o, c, u), (r,) = _broadcast([_points(o, "o"), _points(center, "center"), unit_square(u)],
                                        [_radius(radius)])
    out = _outputs(o.shape[0])
    _sphere_kernel(o, c, r, u, *out)
    return _reshape(shape, *out)


def sample_disks(o, center, normal, radius, u):
    """Points uniform by area on disks (centre, normal, radius) and the directions
    to them from o (:func:`sample_disk_area`).  o, center, normal (..., 3),
    radius (...) and u (..., 2) broadcast; returns (directions (..., 3),
    distances (...), solid-angle pdf (...)), all zero where no sample is possible."""
    shape, (o, c, n, u), (r,) = _broadcast([_points(o, "o"), _points(center, "center"), _points(normal, "normal"),
                                            unit_square(u)], [_radius(radius)])
    out = _outputs(o.shape[0])
    _disk_kernel(o, c, n, r, u, *out)
    return _reshape(shape, *out)


def disk_solid_angle_pdfs(o, center, normal, radius, directions):
    """Solid-angle pdf (...) of :func:`sample_disks` for given unit ``directions``
    from o: the ray o + t w (t > 0) is intersected with the disk's plane, and
    the pdf is d^2 / (pi r^2 |n . w|) where the hit lies within the radius,
    else 0 (:func:`disk_solid_angle_pdf`).  NumPy only (no kernel)."""
    o = _points(o, "o")
    c = _points(center, "center")
    n = _points(normal, "normal")
    w = _points(directions, "directions")
    r = _radius(radius)
    n_len = np.linalg.norm(n, axis=-1, keepdims=True)
    if np.any(n_len == 0.0):
        raise ValueError("normal must not be the zero vector")
    n = n / n_len
    w = w / np.linalg.norm(w, axis=-1, keepdims=True)
    cos = np.sum(n * w, axis=-1)
    offset = np.sum(n * (c - o), axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(cos != 0.0, offset / np.where(cos != 0.0, cos, 1.0), -1.0)
    hit = o + t[..., None] * w
    inside = (t > 0.0) & (np.sum((hit - c) ** 2, axis=-1) <= r * r)
    area = np.pi * r * r
    abs_cos = np.abs(cos)
    with np.errstate(divide="ignore", invalid="ignore"):
        pdf = np.where(inside & (abs_cos > DISK_COS_MIN) & (area > 0.0),
                       t * t / np.where(area > 0.0, area, 1.0) / np.where(abs_cos > 0.0, abs_cos, 1.0), 0.0)
    return pdf
