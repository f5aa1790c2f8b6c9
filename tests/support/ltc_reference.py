"""Brute-force references for the LTC tests (functions, not tests).

:func:`polygon_quadrature` integrates any function of the direction over a
spherical polygon by a fine midpoint grid and a point-in-polygon test, with
nothing in common with the closed forms it checks (no edge formula, no
clipping): the polygon, which must lie in an open hemisphere around ``axis``,
is mapped by the gnomonic (central) projection onto the tangent plane at
``axis``, where its great-circle edges become straight lines; every grid point
of the polygon's bounding box gets its winding number (Sunday's crossing
rule, counter-clockwise positive in the plane coordinates (u, v) along
(e2, e1), a left-handed pair with the outward ``axis``, so counter-clockwise
as seen from the origin looking out along ``axis``); the direction of a
plane point (u, v) is w = (v e1 + u e2 + axis) / r with
r = sqrt(1 + u^2 + v^2) and its solid angle du dv / r^3.  So the result is
the sum over grid cells of winding x integrand x solid angle: a polygon
counter-clockwise as seen from the shading point counts +1, the sign
convention of :mod:`pbrkit.ltc.polygon`.

:func:`rect_lobe_quadrature` integrates a microfacet lobe written here from its
terms, f = D G2 / (4 n.l n.v) with D, Lambda and G2 passed in (pbrkit.brdf's
term functions: ``d_beckmann``, ``lambda_beckmann``, ``g2_separable``, ...),
over a rectangle by a composite tensor Gauss-Legendre rule in the rectangle's
own parameters with the area-to-solid-angle Jacobian |cos theta'| / d^2: no
clipping, no adaptivity, nothing in common with :mod:`pbrkit.ltc.reference`'s
cubature (fan, triangles, error estimate) or its lobe (``specular_lobe``).
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["polygon_quadrature", "tangent_basis", "upper_hemisphere_form_factor", "rect_lobe_quadrature",
           "facing_rect"]


@numba.njit(cache=True)
def _winding_numbers(pu, pv, us, vs, out):
    k = pu.shape[0]
    for i in range(us.shape[0]):
        u = us[i]
        for j in range(vs.shape[0]):
            v = vs[j]
            wn = 0
            for e in range(k):
                u0 = pu[e]
                v0 = pv[e]
                u1 = pu[(e + 1) % k]
                v1 = pv[(e + 1) % k]
                left = (u1 - u0) * (v - v0) - (u - u0) * (v1 - v0)
                if v0 <= v:
                    if v1 > v and left > 0.0:
                        wn += 1
                elif v1 <= v and left < 0.0:
                    wn -= 1
            out[i, j] = wn


def tangent_basis(axis):
    """A right-handed orthonormal (e1, e2, axis), e1 x e2 = axis."""
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    helper = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(helper, a)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(a, e1)
    return e1, e2, a


def polygon_quadrature(vertices, integrand, points=2_000_000, axis=None, chunk=256):
    """The winding-number-weighted integral of ``integrand(x, y, z)`` (vectorised,
    unit directions) over the spherical polygon ``vertices`` (K, 3), by a
    midpoint grid of about ``points`` cells over its gnomonic bounding box.
    ``axis`` (default: the normalised sum of the unit vertices) must see
    every vertex at less than ~84 degrees."""
    p = np.asarray(vertices, dtype=np.float64)
    p = p / np.linalg.norm(p, axis=-1, keepdims=True)
    if axis is None:
        axis = p.sum(axis=0)
    e1, e2, a = tangent_basis(axis)
    height = p @ a
    if np.any(height < 0.1):
        raise ValueError("polygon too wide for the gnomonic projection around this axis")
    pu = (p @ e2) / height  # (u, v) along (e2, e1): counter-clockwise seen from the origin is positive
    pv = (p @ e1) / height
    lo_u, hi_u, lo_v, hi_v = pu.min(), pu.max(), pv.min(), pv.max()
    h = np.sqrt((hi_u - lo_u) * (hi_v - lo_v) / points)
    nu = max(int(np.ceil((hi_u - lo_u) / h)), 1)
    nv = max(int(np.ceil((hi_v - lo_v) / h)), 1)
    du = (hi_u - lo_u) / nu
    dv = (hi_v - lo_v) / nv
    us = lo_u + (np.arange(nu) + 0.5) * du
    vs = lo_v + (np.arange(nv) + 0.5) * dv
    total = 0.0
    for start in range(0, nu, chunk):
        uc = us[start:start + chunk]
        wn = np.empty((uc.size, nv), dtype=np.int64)
        _winding_numbers(pu, pv, uc, vs, wn)
        i, j = np.nonzero(wn)
        if i.size == 0:
            continue
        u = uc[i]
        v = vs[j]
        r = np.sqrt(1.0 + u * u + v * v)
        w = (u[:, None] * e2 + v[:, None] * e1 + a) / r[:, None]
        f = np.asarray(integrand(w[:, 0], w[:, 1], w[:, 2]), dtype=np.float64)
        total += float(np.sum(wn[i, j] * f / r**3))
    return total * du * dv


def upper_hemisphere_form_factor(vertices, **kwargs):
    """Brute-force integral of max(0, z) / pi over the polygon (:func:`polygon_quadrature`)."""
    return polygon_quadrature(vertices, lambda x, y, z: np.maximum(z, 0.0) / np.pi, **kwargs)


def rect_lobe_quadrature(nov, alpha, corners, d, lam, g2, panels=64, order=8):
    """(integral of f (n.l) dl, integral of f (1 - v.h)^5 (n.l) dl) over the
    rectangle ``corners`` (4, 3) (c0 + s (c1 - c0) + t (c3 - c0), s, t in [0, 1];
    it must lie wholly above the horizon), f = d(n.h, alpha) g2(lam(n.l, alpha),
    lam(n.v, alpha)) / (4 n.l n.v) for the view v = (sqrt(1 - nov^2), 0, nov),
    by ``panels`` x ``panels`` Gauss-Legendre panels of ``order`` x ``order``
    nodes."""
    c = np.asarray(corners, dtype=np.float64)
    x, w = np.polynomial.legendre.leggauss(order)
    edges = np.linspace(0.0, 1.0, panels + 1)
    h = np.diff(edges)
    s = (edges[:-1, None] + 0.5 * h[:, None] * (x[None, :] + 1.0)).reshape(-1)
    ws = (0.5 * h[:, None] * w[None, :]).reshape(-1)
    e1, e3 = c[1] - c[0], c[3] - c[0]
    normal = np.cross(e1, e3)
    area = np.linalg.norm(normal)
    normal /= area
    v = np.array([np.sqrt(1.0 - nov * nov), 0.0, nov])
    out = np.zeros(2)
    for i in range(0, s.size, 64):
        p = c[0] + s[i:i + 64, None, None] * e1 + s[None, :, None] * e3
        dist = np.linalg.norm(p, axis=-1)
        l = p / dist[..., None]
        nol = l[..., 2]
        if np.any(nol <= 0.0):
            raise ValueError("the rectangle must lie above the horizon")
        hv = l + v
        hv /= np.linalg.norm(hv, axis=-1, keepdims=True)
        f = d(hv[..., 2], alpha) * g2(lam(nol, alpha), lam(nov, alpha)) / (4.0 * nol * nov)
        g = f * nol * np.abs(l @ normal) / dist ** 2 * area * ws[i:i + 64, None] * ws[None, :]
        fc = (1.0 - hv @ v) ** 5
        out += (g.sum(), (g * fc).sum())
    return out


def facing_rect(centre, half_width, half_height):
    """A rectangle (4, 3) facing the origin (three.js's winding,
    :func:`pbrkit.ltc.lights.rect_corners`; flipped if needed)."""
    from pbrkit.ltc.lights import rect_corners

    c = rect_corners(centre, half_width, half_height)
    if np.dot(np.cross(c[1] - c[0], c[3] - c[0]), -c[0]) < 0.0:
        c = rect_corners(centre, -np.asarray(half_width, dtype=float), half_height)
    return c
