"""Tests for pbrkit.sampling.spherical: solid-angle sampling of area-light shapes.

* Solid angles against independent references: the integral of cos / d^2 dA
  over the shape by adaptive quadrature (scipy), near the plane and far away,
  and the rectangle against both splits into triangles.
* The parametrizations are area preserving: the fraction of the solid angle
  "below" each sample (the sub-rectangle [x0, xu] for Urena et al., the
  sub-triangle A B C' for Arvo, the fraction along the last arc) equals u, to
  near rounding, also for tiny, distant and grazing shapes.
* Chi-square goodness of fit (``tests/support/chi2.py``, the Mitsuba / pbrt-v4 method)
  of every sampler against the pdf it claims: 1 / Omega inside the shape's
  outline and 0 outside (membership by ray-shape intersection here, in NumPy),
  d^2 / (A |cos|) for the disk, with a Sidak-corrected family-wise level.
* Every sampled direction hits the shape at the returned distance; degenerate
  configurations give pdf 0 and no NaN; the scalar functions compile into
  Numba kernels and agree with the NumPy wrappers.
"""

from __future__ import annotations

import math
import zlib

import numpy as np
import pytest
from scipy import integrate

from pbrkit.sampling import spherical as sp

try:  # tests/ as a package or as a plain directory on sys.path
    from . import chi2
except ImportError:
    import chi2

SEED = 20240917
N_CHI2 = 200_000
FAMILY_ALPHA = 0.01
# The claimed pdfs jump to 0 at the shape's outline, which the cells do not follow, so
# the Gauss-Legendre cell integrals are good to ~2e-4 (not 1e-6 as for smooth pdfs).
NORMALISATION_TOL = 1e-3


def _rng(case_id):
    return np.random.default_rng([SEED, zlib.crc32(case_id.encode())])


def _u(case_id, n):
    return _rng(case_id).random((n, 2))


def _rotation(seed):
    """A fixed random rotation matrix (rows are the rotated axes)."""
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


# =========================================================================
# Independent NumPy references: ray-shape intersection and quadrature
# =========================================================================


def rect_hit(o, s, ex, ey, w, tol=0.0):
    """(hit, t, fx, fy) of rays o + t w against the rectangle s + fx ex + fy ey."""
    n = np.cross(ex, ey)
    dn = np.sum(w * n, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.sum((s - o) * n, axis=-1) / dn
        p = o + t[..., None] * w - s
    fx = np.sum(p * ex, axis=-1) / np.sum(ex * ex, axis=-1)
    fy = np.sum(p * ey, axis=-1) / np.sum(ey * ey, axis=-1)
    hit = (t > 0) & (fx >= -tol) & (fx <= 1 + tol) & (fy >= -tol) & (fy <= 1 + tol)
    return hit, t, fx, fy


def tri_hit(o, a, b, c, w, tol=0.0):
    """(hit, t) of rays o + t w against triangle abc (Moller-Trumbore barycentrics)."""
    e1 = b - a
    e2 = c - a
    p = np.cross(w, e2)
    det = np.sum(e1 * p, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        tv = o - a
        bu = np.sum(tv * p, axis=-1) * inv
        q = np.cross(tv, e1)
        bv = np.sum(w * q, axis=-1) * inv
        t = np.sum(e2 * q, axis=-1) * inv
    hit = (t > 0) & (bu >= -tol) & (bv >= -tol) & (bu + bv <= 1 + tol)
    return hit, t


def sphere_hit(o, c, r, w):
    """(hit, t_near) of rays o + t w (unit w) against the sphere (c, r)."""
    oc = c - o
    b = np.sum(w * oc, axis=-1)
    disc = b * b - (np.sum(oc * oc, axis=-1) - r * r)
    t = b - np.sqrt(np.maximum(disc, 0.0))
    return (disc >= 0) & (b > 0), t


def disk_hit(o, c, n, r, w):
    """(hit, t, |cos|) of rays o + t w (unit w) against the disk (c, unit n, r)."""
    dn = np.sum(w * n, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.sum((c - o) * n, axis=-1) / dn
        p = o + t[..., None] * w - c
    return (t > 0) & (np.sum(p * p, axis=-1) <= r * r), t, np.abs(dn)


def _quad2(f, a, b, lo, hi):
    return integrate.dblquad(f, a, b, lo, hi, epsabs=1e-13, epsrel=1e-11)[0]


def quadrature_triangle_solid_angle(o, a, b, c):
    """Integral of |cos| / d^2 over the triangle, split at the foot of the
    perpendicular from o (if inside) so the peak sits at a corner of each piece."""
    n = np.cross(b - a, c - a)
    n = n / np.linalg.norm(n)
    foot = o - np.dot(o - a, n) * n
    pieces = [(a, b, c)]
    if tri_hit(o, a, b, c, -n if np.dot(o - a, n) > 0 else n)[0]:
        pieces = [(foot, a, b), (foot, b, c), (foot, c, a)]
    total = 0.0
    for p0, p1, p2 in pieces:
        e1 = p1 - p0
        e2 = p2 - p0
        jac = np.linalg.norm(np.cross(e1, e2))
        if jac == 0.0:
            continue

        def f(t, s, p0=p0, e1=e1, e2=e2, jac=jac):
            d = p0 + s * e1 + t * e2 - o
            r2 = d @ d
            return abs(d @ n) / (r2 * math.sqrt(r2)) * jac
        total += _quad2(f, 0.0, 1.0, lambda s: 0.0, lambda s: 1.0 - s)
    return total


def quadrature_rectangle_solid_angle(o, s, ex, ey):
    """Integral of |cos| / d^2 over the rectangle, split at the foot of the perpendicular."""
    n = np.cross(ex, ey)
    n = n / np.linalg.norm(n)
    fx = np.dot(o - s, ex) / np.dot(ex, ex)
    fy = np.dot(o - s, ey) / np.dot(ey, ey)
    xs = [0.0] + ([fx] if 0 < fx < 1 else []) + [1.0]
    ys = [0.0] + ([fy] if 0 < fy < 1 else []) + [1.0]
    jac = np.linalg.norm(ex) * np.linalg.norm(ey)

    def f(v, u):
        d = s + u * ex + v * ey - o
        r2 = d @ d
        return abs(d @ n) / (r2 * math.sqrt(r2)) * jac
    return sum(_quad2(f, x0, x1, lambda u, y0=y0: y0, lambda u, y1=y1: y1)
               for x0, x1 in zip(xs[:-1], xs[1:]) for y0, y1 in zip(ys[:-1], ys[1:]))


# =========================================================================
# Solid angles
# =========================================================================

TRI = (np.array([0.0, 0.0, 0.0]), np.array([1.0, 0.0, 0.0]), np.array([0.3, 0.8, 0.0]))
TRI_POINTS = [
    ("above", [0.4, 0.3, 0.7]),
    ("close-above", [0.4, 0.3, 0.01]),
    ("near-plane-beside", [1.6, 1.1, 1e-3]),
    ("near-plane-above-edge", [0.5, 0.0, 2e-3]),
    ("below-oblique", [-2.0, 1.5, -0.6]),
    ("far", [0.3, -0.4, 60.0]),
    ("far-oblique", [-40.0, 25.0, 20.0]),
]


@pytest.mark.parametrize("name, point", TRI_POINTS, ids=[p[0] for p in TRI_POINTS])
def test_triangle_solid_angle_matches_quadrature(name, point):
    o = np.array(point)
    a, b, c = TRI
    want = quadrature_triangle_solid_angle(o, a, b, c)
    got = sp.triangle_solid_angle(*(a - o), *(b - o), *(c - o))
    assert got == pytest.approx(want, rel=1e-9, abs=1e-15)
    # any vertex order, either orientation, any scale of the relative vertices
    assert sp.triangle_solid_angle(*(c - o), *(b - o), *(a - o)) == pytest.approx(got, rel=1e-13)
    assert sp.triangle_solid_angle(*(b - o) * 1e30, *(c - o) * 1e30, *(a - o) * 1e30) == pytest.approx(got, rel=1e-13)
    assert sp.triangle_solid_angles(o, a, b, c) == pytest.approx(got, rel=1e-13)


RECT = (np.array([-0.5, -0.25, 0.0]), np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.5, 0.0]))
RECT_POINTS = [
    ("above-centre", [0.0, 0.0, 1.0]),
    ("below-centre", [0.1, 0.05, -1.0]),
    ("close-above", [0.2, -0.1, 0.01]),
    ("near-plane-beside", [1.5, 0.3, 1e-3]),
    ("near-plane-above-edge", [0.0, 0.25, -2e-3]),
    ("oblique", [2.5, 1.5, 0.4]),
    ("far", [0.2, -0.1, 80.0]),
    ("far-oblique", [-60.0, 35.0, -30.0]),
]


@pytest.mark.parametrize("name, point", RECT_POINTS, ids=[p[0] for p in RECT_POINTS])
def test_rectangle_solid_angle_matches_quadrature_and_triangles(name, point):
    rot = _rotation(7)
    o = rot @ np.array(point)
    s, ex, ey = (rot @ v for v in RECT)
    want = quadrature_rectangle_solid_angle(o, s, ex, ey)
    got = sp.rectangle_solid_angle(*o, *s, *ex, *ey)
    assert got == pytest.approx(want, rel=1e-9, abs=1e-15)
    # both diagonals split it into two triangles
    v00, v10, v11, v01 = s - o, s + ex - o, s + ex + ey - o, s + ey - o
    split1 = sp.triangle_solid_angle(*v00, *v10, *v01) + sp.triangle_solid_angle(*v10, *v11, *v01)
    split2 = sp.triangle_solid_angle(*v00, *v10, *v11) + sp.triangle_solid_angle(*v00, *v11, *v01)
    assert split1 == pytest.approx(got, rel=1e-9)
    assert split2 == pytest.approx(got, rel=1e-9)
    # the same rectangle from any corner, with either edge first
    assert sp.rectangle_solid_angle(*o, *(s + ex + ey), *(-ey), *(-ex)) == pytest.approx(got, rel=1e-12)
    assert sp.rectangle_solid_angles(o, s, ex, ey) == pytest.approx(got, rel=1e-13)
    # pdf = 1 / Omega
    assert sp.spherical_rectangle_pdf(*o, *s, *ex, *ey) == pytest.approx(1.0 / got, rel=1e-13)


def test_solid_angle_limits():
    a, b, c = TRI
    # a tiny far triangle: Omega -> area cos / d^2
    o = np.array([0.4, 0.3, 1e6])
    assert sp.triangle_solid_angle(*(a - o), *(b - o), *(c - o)) == pytest.approx(0.4 * 1e-12, rel=1e-6)
    # just above the interior: Omega -> 2 pi; in the plane outside: 0
    o = np.array([0.4, 0.3, 1e-9])
    assert sp.triangle_solid_angle(*(a - o), *(b - o), *(c - o)) == pytest.approx(2 * math.pi, rel=1e-8)
    o = np.array([2.0, 0.3, 0.0])
    assert sp.triangle_solid_angle(*(a - o), *(b - o), *(c - o)) == 0.0
    # a square of side 1 seen from above its centre at height h: 4 atan(1 / (4 h sqrt(h^2 + 1/2)))
    for h in (1e-6, 0.5, 3.0, 1e4):
        want = 4.0 * math.atan(0.25 / (h * math.sqrt(h * h + 0.5)))
        got = sp.rectangle_solid_angle(0.5, 0.5, h, 0, 0, 0, 1, 0, 0, 0, 1, 0)
        assert got == pytest.approx(want, rel=1e-12)


# =========================================================================
# The parametrizations are area preserving (u -> exact fractions of Omega)
# =========================================================================


def _h_difference(a, b, d2):
    """a / sqrt(d2 + a^2) - b / sqrt(d2 + b^2) without cancellation."""
    ra = np.sqrt(d2 + a * a)
    rb = np.sqrt(d2 + b * b)
    same = a * b > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        careful = d2 * (a - b) * (a + b) / (ra * rb * (a * rb + b * ra))
    return np.where(same, careful, a / ra - b / rb)


RECT_MAPS = [
    ("above", [0.3, 0.1, 0.8]),
    ("below-oblique", [2.0, -1.0, -0.5]),
    ("close-above", [0.2, 0.1, 1e-4]),
    ("grazing-beside-x", [2.5, 0.3, 1e-6]),
    ("grazing-beside-y", [0.2, -3.0, -1e-6]),
    ("grazing-corner", [-1.5, -3.5, 1e-6]),
    ("far", [0.3, 0.2, 1000.0]),
    ("far-oblique", [-3000.0, 2000.0, -1000.0]),
]


@pytest.mark.parametrize("name, point", RECT_MAPS, ids=[p[0] for p in RECT_MAPS])
def test_rectangle_map_is_area_preserving(name, point):
    """Urena et al. 2013: u1 is the fraction of Omega in [x0, xu] x [y0, y1]
    and u2 the fraction of the column x = xu below yv, whose density in y is
    proportional to d h(y) with h = y / sqrt(xu^2 + z0^2 + y^2)."""
    s, ex, ey = np.zeros(3), np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.5, 0.0])
    o = np.array(point)
    u = _u("rect-map-" + name, 400)
    u[:4] = [[0, 0], [1, 1], [0, 1], [1, 0]]
    w, dist, pdf = sp.sample_spherical_rectangles(o, s, ex, ey, u)
    omega = sp.rectangle_solid_angle(*o, *s, *ex, *ey)
    assert omega > sp.MIN_SOLID_ANGLE and np.all(pdf == 1.0 / omega)
    p = w * dist[:, None] - (s - o)
    fx = np.clip(p[:, 0], 0.0, 1.0)
    yv = np.clip(p[:, 1], 0.0, 0.5)
    u1 = sp.rectangle_solid_angles(o, s, ex * fx[:, None], ey) / omega
    x, y0, y1, h = fx - o[0], -o[1], 0.5 - o[1], abs(o[2])
    d2 = x * x + h * h
    u2 = _h_difference(yv - o[1], y0, d2) / _h_difference(y1, y0, d2)
    tol = 1e-9 + 1e-14 / omega
    assert np.max(np.abs(u1 - u[:, 0])) < tol
    assert np.max(np.abs(u2 - u[:, 1])) < tol


TRI_MAPS = [
    ("above", [0.4, 0.3, 0.7], TRI),
    ("below-oblique", [-2.0, 1.5, -0.6], TRI),
    ("close-above", [0.4, 0.3, 1e-4], TRI),
    ("above-edge", [0.5, 0.0, 1e-3], TRI),
    ("far", [0.3, 0.2, 1000.0], TRI),
    ("thin", [0.3, 0.2, 1.0], (TRI[0], TRI[1], np.array([0.5, 1e-4, 0.0]))),
    ("general", [0.5, 1.0, 1.0], (np.array([0.0, 0.0, 0.0]), np.array([2.0, 0.0, 0.0]), np.array([1.8, 0.15, 0.3]))),
]


@pytest.mark.parametrize("name, point, tri", TRI_MAPS, ids=[p[0] for p in TRI_MAPS])
def test_triangle_map_is_area_preserving(name, point, tri):
    """Arvo 1995: u1 is the fraction of Omega in the sub-triangle A B C' (C' on the
    arc AC where the arc from B through the sample meets it) and u2 = (1 - B.w) /
    (1 - B.C')."""
    o = np.array(point)
    a, b, c = tri
    u = _u("tri-map-" + name, 400)
    u[:, 1] = np.maximum(u[:, 1], 0.05)  # C' is undefined for samples at B (u2 = 0)
    u[:2] = [[0, 1], [1, 1]]
    w, dist, pdf = sp.sample_spherical_triangles(o, a, b, c, u)
    omega = sp.triangle_solid_angle(*(a - o), *(b - o), *(c - o))
    assert omega > sp.MIN_SOLID_ANGLE and np.all(pdf == 1.0 / omega)
    # C': the plane through o, b and the sample meets the segment ac at a + t (c - a)
    m = np.cross(b - o, w)
    t = -np.sum(m * (a - o), axis=-1) / np.sum(m * (c - a), axis=-1)
    cp = a + np.clip(t, 0.0, 1.0)[:, None] * (c - a)
    u1 = sp.triangle_solid_angles(o, a, b, cp) / omega
    bh = (b - o) / np.linalg.norm(b - o)
    cph = (cp - o) / np.linalg.norm(cp - o, axis=-1, keepdims=True)
    u2 = np.sum((w - bh) ** 2, axis=-1) / np.sum((cph - bh) ** 2, axis=-1)
    tol = 1e-9 + 1e-14 / omega
    assert np.max(np.abs(u1 - u[:, 0])) < tol
    assert np.max(np.abs(u2 - u[:, 1])) < max(tol, 1e-8)


def test_maps_are_area_preserving_in_extreme_configurations():
    """The same fractions in 40-digit arithmetic (the float64 references above are
    themselves ill-conditioned here) from the float64 samples: o 1e-8 from the
    plane beside a rectangle or above a triangle's edge (where Arvo's 1 + cos c
    and Urena's cos(au) b0 - b1 and 1 - cu^2 cancel), a rectangle seen from
    its plane's diagonal direction, a triangle 1e4 away.  The samples keep the
    fractions to about 1e-15 / Omega (the rounding of Urena's angles, au ~ pi)."""
    mpmath = pytest.importorskip("mpmath")
    with mpmath.workdps(40):
        _extreme_maps(mpmath.mp)


def _extreme_maps(mp):
    mpf = mp.mpf

    def vec(v):
        return [mpf(float(x)) for x in v]

    def sub(a, b):
        return [x - y for x, y in zip(a, b)]

    def dot(a, b):
        return sum(x * y for x, y in zip(a, b))

    def cross(a, b):
        return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]

    def unit(a):
        n = mp.sqrt(dot(a, a))
        return [x / n for x in a]

    def tri_omega(a, b, c):
        a, b, c = unit(a), unit(b), unit(c)
        return 2 * mp.atan2(abs(dot(a, cross(b, c))), 1 + dot(a, b) + dot(a, c) + dot(b, c))

    def rect_f(x, y, h):
        return mp.atan(x * y / (h * mp.sqrt(x * x + y * y + h * h)))

    def rect_omega(x0, x1, y0, y1, h):
        return rect_f(x1, y1, h) - rect_f(x1, y0, h) - rect_f(x0, y1, h) + rect_f(x0, y0, h)

    n = 40
    u = _u("mp-maps", n)
    u[:, 1] = np.maximum(u[:, 1], 0.05)
    # rectangle [0, 1] x [0, 0.5] in z = 0
    # (the last: 1e-8 above an edge, where the fractions themselves change by 1 / h per unit)
    for point, tol in (([2.5, 0.3, 2e-8], 0.0), ([-1.5, -3.5, -1e-6], 0.0), ([0.5, -100.0, 1e-2], 0.0),
                       ([0.3, 0.2, 1e4], 0.0), ([0.5, 0.0, 1e-8], 1e-7)):
        o = np.array(point)
        w, dist, pdf = sp.sample_spherical_rectangles(o, [0, 0, 0], [1.0, 0, 0], [0, 0.5, 0], u)
        x0, y0, h = -mpf(point[0]), -mpf(point[1]), abs(mpf(point[2]))
        x1, y1 = x0 + 1, y0 + mpf(0.5)
        omega = rect_omega(x0, x1, y0, y1, h)
        assert abs(float(omega) * pdf[0] - 1) < 1e-12
        tol = max(tol, 1e-9 + 1e-15 / float(omega))
        for i in range(n):
            wi = vec(w[i])
            t = h / abs(wi[2])  # exact hit of the float64 direction with the plane
            x, y = t * wi[0], t * wi[1]
            u1 = rect_omega(x0, x, y0, y1, h) / omega
            d2 = x * x + h * h
            hy = [v / mp.sqrt(d2 + v * v) for v in (y0, y, y1)]
            u2 = (hy[1] - hy[0]) / (hy[2] - hy[0])
            assert abs(float(u1) - u[i, 0]) < tol, (point, i)
            assert abs(float(u2) - u[i, 1]) < tol, (point, i)
    # triangle
    a, b, c = TRI
    for point, tol in (([0.5, 0.0, 1e-8], 1e-6), ([0.4, 0.3, 1e-8], 1e-6), ([1.6, 1.1, 1e-8], 1e-8),
                       ([-3e3, 2e3, -1e3], 1e-8)):
        o = np.array(point)
        w, dist, pdf = sp.sample_spherical_triangles(o, a, b, c, u)
        am, bm, cm = (vec(v - o) for v in (a, b, c))
        omega = tri_omega(am, bm, cm)
        assert abs(float(omega) * pdf[0] - 1) < 1e-6
        ah, bh, ch = unit(am), unit(bm), unit(cm)
        for i in range(n):
            p = unit(vec(w[i]))
            cp = unit(cross(cross(ah, ch), cross(bh, p)))
            if dot(cp, [x + y for x, y in zip(ah, ch)]) < 0:
                cp = [-x for x in cp]
            u1 = tri_omega(ah, bh, cp) / omega
            u2 = dot(sub(p, bh), sub(p, bh)) / dot(sub(cp, bh), sub(cp, bh))
            assert abs(float(u1) - u[i, 0]) < tol, (point, i)
            assert abs(float(u2) - u[i, 1]) < tol, (point, i)


# =========================================================================
# Chi-square goodness of fit against the claimed pdf
# =========================================================================


def _frame(axis):
    """Rows (t, b, axis) of an orthonormal frame around ``axis``."""
    z = axis / np.linalg.norm(axis)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t = np.cross(helper, z)
    t /= np.linalg.norm(t)
    return np.stack([t, np.cross(z, t), z])


def _rectangle_case(name, point, rot_seed=None, size=(1.0, 0.5)):
    rot = np.eye(3) if rot_seed is None else _rotation(rot_seed)
    s = rot @ np.array([-0.5 * size[0], -0.5 * size[1], 0.0])
    ex = rot @ np.array([size[0], 0.0, 0.0])
    ey = rot @ np.array([0.0, size[1], 0.0])
    o = rot @ np.array(point)

    def sample(u):
        return sp.sample_spherical_rectangles(o, s, ex, ey, u)

    def hits(w):
        return rect_hit(o, s, ex, ey, w)[0]
    return ("rectangle-" + name, sample, hits, s + 0.5 * (ex + ey) - o, ())


def _triangle_case(name, point, tri=TRI):
    a, b, c = tri
    o = np.array(point)

    def sample(u):
        return sp.sample_spherical_triangles(o, a, b, c, u)

    def hits(w):
        return tri_hit(o, a, b, c, w)[0]
    return ("triangle-" + name, sample, hits, (a + b + c) / 3.0 - o, ())


def _sphere_case(name, center, radius):
    o = np.array([0.1, -0.2, 0.3])
    c = o + np.array(center)

    def sample(u):
        return sp.sample_sphere_cones(o, c, radius, u)

    def hits(w):
        return sphere_hit(o, c, radius, w)[0]
    theta_max = math.asin(radius / np.linalg.norm(c - o))
    return ("sphere-" + name, sample, hits, c - o, (theta_max,))


def _disk_case(name, point, normal=(0.0, 0.0, 1.0), radius=1.0):
    c = np.array([0.2, -0.1, 0.0])
    n = np.array(normal) / np.linalg.norm(normal)
    o = np.array(point)

    def sample(u):
        return sp.sample_disks(o, c, n, radius, u)

    def pdf(w):
        hit, t, cos = disk_hit(o, c, n, radius, w)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(hit, t * t / (math.pi * radius**2 * cos), 0.0)
    return ("disk-" + name, sample, pdf, c - o, ())


GOLD = (np.array([0.0, 0.0, 0.0]), np.array([2.0, 0.0, 0.0]), np.array([1.8, 0.15, 0.3]))
# On the sphere the claimed pdf is an indicator whose outline the (theta, phi) cells
# do not follow; for thin or grazing shapes the cell quadrature then misses slivers,
# so those configurations are tested on the shape itself (PLANE_CHI2_CASES below).
CHI2_CASES = [
    _rectangle_case("close", [0.1, 0.05, 0.3]),
    _rectangle_case("far-small", [0.2, -0.1, 25.0]),
    _rectangle_case("oblique", [2.5, 1.5, 0.4], rot_seed=3),
    _rectangle_case("below", [0.3, -0.2, -0.7], rot_seed=5),
    _triangle_case("close", [0.4, 0.3, 0.2]),
    _triangle_case("far-below", [0.4, 0.3, -30.0]),
    _triangle_case("oblique", [-2.0, 1.5, 0.5]),
    _triangle_case("general-3d", [0.5, 1.0, 1.0], GOLD),
    _sphere_case("close", [0.0, 0.0, 1.5], 1.0),
    _sphere_case("very-close", [0.3, 0.2, 0.95], 0.99),
    _sphere_case("far", [3.0, -4.0, 12.0], 0.2),
    _sphere_case("tiny", [0.0, 60.0, 80.0], 0.05),
    _disk_case("facing", [0.4, 0.1, 1.0]),
    _disk_case("oblique", [2.0, 1.0, 0.5], normal=(0.2, -0.1, 1.0)),
    _disk_case("grazing", [2.0, 0.3, 0.05]),
    _disk_case("behind", [0.3, 0.3, -0.5], normal=(0.3, 0.0, 1.0), radius=0.7),
]


def _plane_rectangle_case(name, point, rot_seed=None, size=(1.0, 0.5)):
    """Samples as hit points (fx, fy) in [0, 1]^2 on the rectangle s + fx ex + fy ey, with
    the claimed solid-angle pdf carried to area: pdf |cos| / d^2 |ex| |ey| (smooth)."""
    case_id, sample, _, _, _ = _rectangle_case(name, point, rot_seed, size)
    rot = np.eye(3) if rot_seed is None else _rotation(rot_seed)
    s = rot @ np.array([-0.5 * size[0], -0.5 * size[1], 0.0])
    ex = rot @ np.array([size[0], 0.0, 0.0])
    ey = rot @ np.array([0.0, size[1], 0.0])
    n = rot @ np.array([0.0, 0.0, 1.0])
    o = rot @ np.array(point)

    def coordinates(w):
        hit, _, fx, fy = rect_hit(o, s, ex, ey, w)
        return np.where(hit, fx, np.nan), fy

    def to_area(fx, fy):
        d = s + fx[..., None] * ex + fy[..., None] * ey - o
        r2 = np.sum(d * d, axis=-1)
        return np.abs(d @ n) / (r2 * np.sqrt(r2)) * size[0] * size[1]
    return "plane-" + case_id, sample, coordinates, to_area


def _plane_triangle_case(name, point, tri=TRI):
    """Samples as (a, b) in [0, 1]^2 with p = A + a (B - A) + a b (C - B) (barycentrics
    (1 - a, a (1 - b), a b)), Jacobian a |(B - A) x (C - B)|."""
    case_id, sample, _, _, _ = _triangle_case(name, point, tri)
    A, B, C = tri
    o = np.array(point)
    cross = np.cross(B - A, C - B)
    n = cross / np.linalg.norm(cross)

    def coordinates(w):
        e1, e2 = B - A, C - A
        p = np.cross(w, e2)
        inv = 1.0 / np.sum(e1 * p, axis=-1)
        tv = o - A
        bu = np.sum(tv * p, axis=-1) * inv
        bv = np.sum(w * np.cross(tv, e1), axis=-1) * inv
        a = bu + bv
        inside = (bu >= 0) & (bv >= 0) & (a <= 1)
        return np.where(inside, a, np.nan), bv / np.where(a > 0, a, 1.0)

    def to_area(a, b):
        d = A + a[..., None] * (B - A) + (a * b)[..., None] * (C - B) - o
        r2 = np.sum(d * d, axis=-1)
        return np.abs(d @ n) / (r2 * np.sqrt(r2)) * a * np.linalg.norm(cross)
    return "plane-" + case_id, sample, coordinates, to_area


PLANE_CHI2_CASES = [
    _plane_rectangle_case("close", [0.1, 0.05, 0.3]),
    _plane_rectangle_case("grazing", [1.5, 0.3, 0.02], rot_seed=4),
    _plane_rectangle_case("grazing-below", [-0.2, -1.5, -0.003], rot_seed=6),
    _plane_rectangle_case("below-long-thin", [-2.0, 0.7, -0.3], size=(4.0, 0.1)),
    _plane_rectangle_case("above-close", [0.3, 0.2, 0.01]),
    _plane_triangle_case("close", [0.4, 0.3, 0.2]),
    _plane_triangle_case("grazing", [0.5, -0.5, -0.01]),
    _plane_triangle_case("grazing-far-corner", [-3.0, -2.0, 0.002]),
    _plane_triangle_case("above-close", [0.4, 0.3, 0.01]),
    _plane_triangle_case("thin", [0.3, 0.2, 0.5], (TRI[0], TRI[1], np.array([0.5, 0.01, 0.0]))),
]
NUM_CHI2_TESTS = len(CHI2_CASES) + len(PLANE_CHI2_CASES)
ALPHA_TEST = chi2.sidak_alpha(FAMILY_ALPHA, NUM_CHI2_TESTS)


def _run_chi2(case_id, sample, density, axis, fixed_theta, n=N_CHI2, constant_pdf=True):
    """Sample, rotate into the frame around ``axis`` and test against ``density(w)``
    (``constant_pdf``: density is a membership test and the claimed pdf is the
    sampler's constant value)."""
    w, dist, pdf = sample(_u(case_id, n))
    assert np.all(pdf > 0) and np.all(np.isfinite(w))
    if constant_pdf:
        assert np.ptp(pdf) <= 1e-12 * pdf[0]
        value = pdf[0]

        def claimed(world):
            return np.where(density(world), value, 0.0)
    else:
        claimed = density
    frame = _frame(axis)

    def local_pdf(x, y, z):
        return claimed(np.stack(np.broadcast_arrays(x, y, z), axis=-1) @ frame)
    return chi2.sphere_chi2_test(w @ frame.T, local_pdf, fixed_theta=fixed_theta)


def test_sidak_level():
    assert NUM_CHI2_TESTS >= 25
    assert 1 - (1 - ALPHA_TEST) ** NUM_CHI2_TESTS == pytest.approx(FAMILY_ALPHA)


@pytest.mark.parametrize("case_id, sample, density, axis, fixed_theta", CHI2_CASES, ids=[c[0] for c in CHI2_CASES])
def test_chi2(case_id, sample, density, axis, fixed_theta):
    result = _run_chi2(case_id, sample, density, axis, fixed_theta, constant_pdf=not case_id.startswith("disk"))
    assert abs(result.total_probability - 1.0) < NORMALISATION_TOL, f"{case_id}: pdf does not integrate to 1: {result}"
    assert result.p_value > ALPHA_TEST, f"{case_id}: rejected at level {ALPHA_TEST:.2e}: {result}"


@pytest.mark.parametrize("case_id, sample, coordinates, to_area", PLANE_CHI2_CASES,
                         ids=[c[0] for c in PLANE_CHI2_CASES])
def test_chi2_on_the_shape(case_id, sample, coordinates, to_area):
    """The hit points in the shape's own coordinates against the claimed pdf carried
    to them (smooth: no outline inside the domain, so the cell integrals are
    accurate to ~1e-6 and the integral of the density checks 1 / Omega too).  A
    direction that misses the shape gets coordinates NaN and fails the test."""
    w, dist, pdf = sample(_u(case_id, N_CHI2))
    assert np.all(pdf > 0) and np.ptp(pdf) <= 1e-12 * pdf[0]
    a, b = coordinates(w)
    value = pdf[0]
    result = chi2.chi2_test_2d(a, b, lambda x, y: value * to_area(x, y), (0.0, 1.0), (0.0, 1.0))
    assert abs(result.total_probability - 1.0) < 1e-5, f"{case_id}: pdf does not integrate to 1: {result}"
    assert result.p_value > ALPHA_TEST, f"{case_id}: rejected at level {ALPHA_TEST:.2e}: {result}"


def test_chi2_rejects_wrong_samplers():
    """The same machinery rejects a near miss: area-uniform points on an oblique
    rectangle tested as uniform in solid angle, a rectangle sampler fed u1^1.05,
    and a sphere cone 1 % too wide."""
    s, ex, ey = np.array([-0.5, -0.25, 0.0]), np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.5, 0.0])
    o = np.array([1.5, 0.8, 0.6])
    omega = sp.rectangle_solid_angle(*o, *s, *ex, *ey)

    def by_area(u):
        p = s + u[:, :1] * ex + u[:, 1:] * ey - o
        d = np.linalg.norm(p, axis=-1)
        return p / d[:, None], d, np.full(len(u), 1.0 / omega)

    def warped(u):
        return sp.sample_spherical_rectangles(o, s, ex, ey, np.stack([u[:, 0] ** 1.05, u[:, 1]], axis=-1))

    def hits(w):
        return rect_hit(o, s, ex, ey, w)[0]
    axis = s + 0.5 * (ex + ey) - o
    for name, sampler in (("by-area", by_area), ("warped", warped)):
        result = _run_chi2("reject-" + name, sampler, hits, axis, ())
        assert result.p_value < 1e-6, f"{name}: {result}"
    c = np.array([0.0, 0.0, 2.0])

    def wide(u):
        return sp.sample_sphere_cones(np.zeros(3), c, 1.01, u)

    def narrow_claim(w):
        return sphere_hit(np.zeros(3), c, 1.0, w)[0]
    result = _run_chi2("reject-wide", lambda u: (*wide(u)[:2], np.full(len(u), sp.sphere_cone_pdf(*c, 1.0))),
                       narrow_claim, c, (math.asin(0.5),))
    assert result.p_value == 0.0


# =========================================================================
# Every sample hits the shape at the returned distance
# =========================================================================


def _random_configs(case_id, n):
    rng = _rng(case_id)
    rots = np.stack([_rotation(int(k)) for k in rng.integers(0, 2**31, n)])
    sizes = 10.0 ** rng.uniform(-2, 1, (n, 2))
    dirs = rng.normal(size=(n, 3))
    dirs /= np.linalg.norm(dirs, axis=-1, keepdims=True)
    dist = 10.0 ** rng.uniform(-2, 2, n)
    return rng, rots, sizes, dirs * dist[:, None]


def test_rectangle_samples_hit_at_their_distance():
    rng, rots, sizes, offsets = _random_configs("rect-hits", 300)
    ex = rots[:, 0] * sizes[:, :1]
    ey = rots[:, 1] * sizes[:, 1:]
    s = rng.normal(size=(300, 3))
    o = s + 0.5 * (ex + ey) + offsets
    u = _u("rect-hits-u", 300 * 64).reshape(300, 64, 2)
    u[:, :4] = [[0, 0], [1, 1], [0, 1], [1, 0]]
    w, dist, pdf = sp.sample_spherical_rectangles(o[:, None], s[:, None], ex[:, None], ey[:, None], u)
    assert w.shape == (300, 64, 3) and dist.shape == pdf.shape == (300, 64)
    ok = pdf > 0
    assert ok.mean() > 0.95
    omega = sp.rectangle_solid_angles(o, s, ex, ey)
    np.testing.assert_array_equal(ok, (omega >= sp.MIN_SOLID_ANGLE)[:, None] & np.ones((1, 64), bool))
    np.testing.assert_allclose(pdf[ok], np.broadcast_to(1.0 / omega[:, None], pdf.shape)[ok], rtol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(w[ok], axis=-1), 1.0, rtol=1e-14)
    hit, t, _, _ = rect_hit(o[:, None], s[:, None], ex[:, None], ey[:, None], w, tol=1e-9)
    assert np.all(hit[ok])
    np.testing.assert_allclose(dist[ok], t[ok], rtol=1e-9)


def test_triangle_samples_hit_at_their_distance():
    rng, rots, sizes, offsets = _random_configs("tri-hits", 300)
    a = rng.normal(size=(300, 3))
    b = a + rots[:, 0] * sizes[:, :1]
    c = a + (rots[:, 0] * rng.uniform(-1, 2, (300, 1)) + rots[:, 1]) * sizes[:, 1:]
    o = (a + b + c) / 3 + offsets
    u = _u("tri-hits-u", 300 * 64).reshape(300, 64, 2)
    u[:, :4] = [[0, 0], [1, 1], [0, 1], [1, 0]]
    w, dist, pdf = sp.sample_spherical_triangles(o[:, None], a[:, None], b[:, None], c[:, None], u)
    ok = pdf > 0
    assert ok.mean() > 0.95
    omega = sp.triangle_solid_angles(o, a, b, c)
    np.testing.assert_array_equal(ok, (omega >= sp.MIN_SOLID_ANGLE)[:, None] & np.ones((1, 64), bool))
    np.testing.assert_allclose(pdf[ok], np.broadcast_to(1.0 / omega[:, None], pdf.shape)[ok], rtol=1e-15)
    np.testing.assert_allclose(sp.spherical_triangle_pdfs(o, a, b, c), np.where(omega >= sp.MIN_SOLID_ANGLE,
                                                                                1.0 / omega, 0.0), rtol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(w[ok], axis=-1), 1.0, rtol=1e-14)
    hit, t = tri_hit(o[:, None], a[:, None], b[:, None], c[:, None], w, tol=1e-9)
    assert np.all(hit[ok])
    np.testing.assert_allclose(dist[ok], t[ok], rtol=1e-9)


def test_sphere_samples_hit_the_near_side_at_their_distance():
    rng = _rng("sphere-hits")
    n = 400
    c = rng.normal(size=(n, 3))
    r = 10.0 ** rng.uniform(-3, 1, n)
    dirs = rng.normal(size=(n, 3))
    dirs /= np.linalg.norm(dirs, axis=-1, keepdims=True)
    o = c + dirs * (r * (1.0 + 10.0 ** rng.uniform(-6, 3, n)))[:, None]
    u = _u("sphere-hits-u", n * 64).reshape(n, 64, 2)
    u[:, :4] = [[0, 0], [1, 1], [0, 1], [1, 0]]
    w, dist, pdf = sp.sample_sphere_cones(o[:, None], c[:, None], r[:, None], u)
    assert np.all(pdf > 0)
    d = np.linalg.norm(c - o, axis=-1)
    omega = 2 * np.pi * (1 - np.sqrt(1 - (r / d) ** 2))
    big = r / d > 1e-3  # elsewhere 1 - cos theta_max cancels in this reference
    np.testing.assert_allclose((1 / pdf[:, 0])[big], omega[big], rtol=1e-9)
    np.testing.assert_allclose(pdf[:, 0], sp.sphere_cone_pdfs(o, c, r), rtol=0)
    p = o[:, None] + w * dist[..., None] - c[:, None]  # the hit point, relative to the centre
    np.testing.assert_allclose(np.linalg.norm(p, axis=-1) / r[:, None], 1.0, atol=1e-9)
    assert np.all(np.sum(p * w, axis=-1) <= 1e-9 * r[:, None])  # near side: the normal faces o
    cos_max = np.sqrt(np.maximum(1 - (r / d) ** 2, 0))
    assert np.all(np.sum(w * ((c - o) / d[:, None])[:, None], axis=-1) >= cos_max[:, None] - 1e-12)


def test_disk_samples_hit_at_their_distance():
    rng = _rng("disk-hits")
    n = 300
    c = rng.normal(size=(n, 3))
    normal = rng.normal(size=(n, 3))
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    r = 10.0 ** rng.uniform(-2, 1, n)
    o = c + rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-1, 1, (n, 1))
    u = _u("disk-hits-u", n * 64).reshape(n, 64, 2)
    w, dist, pdf = sp.sample_disks(o[:, None], c[:, None], normal[:, None], r[:, None], u)
    assert np.all(pdf > 0)
    hit, t, cos = disk_hit(o[:, None], c[:, None], normal[:, None], r[:, None] * (1 + 1e-9), w)
    assert np.all(hit)
    np.testing.assert_allclose(dist, t, rtol=1e-9)
    np.testing.assert_allclose(pdf, dist**2 / (np.pi * r[:, None] ** 2 * cos), rtol=1e-9)
    np.testing.assert_allclose(sp.disk_solid_angle_pdfs(o[:, None], c[:, None], normal[:, None], r[:, None], w),
                               pdf, rtol=1e-9)
    # the points are area-uniform: the concentric map of u (Shirley & Chiu 1997)
    p = o[:, None] + w * dist[..., None] - c[:, None]
    assert np.max(np.abs(np.sum(p * normal[:, None], axis=-1))) < 1e-9 * np.max(np.abs(p))


def test_rectangle_sides_mirror():
    """From o and from its mirror image in the plane the sampler picks the same points
    (the local frame's z flips; Urena et al. 2013)."""
    rot = _rotation(11)
    s, ex, ey = rot @ np.array([-0.5, -0.25, 0.0]), rot @ np.array([1.0, 0, 0]), rot @ np.array([0, 0.5, 0])
    n = rot @ np.array([0, 0, 1.0])
    u = _u("mirror", 1000)
    for point in ([0.3, 0.1, 0.8], [2.0, -1.0, 0.05], [0.1, 0.2, 30.0]):
        o = rot @ np.array(point)
        o_mirror = o - 2 * np.dot(o - s, n) * n
        w1, d1, p1 = sp.sample_spherical_rectangles(o, s, ex, ey, u)
        w2, d2, p2 = sp.sample_spherical_rectangles(o_mirror, s, ex, ey, u)
        np.testing.assert_allclose(o + w1 * d1[:, None], o_mirror + w2 * d2[:, None], atol=1e-12 * np.linalg.norm(o))
        assert p1[0] == pytest.approx(p2[0], rel=1e-12)


# =========================================================================
# Degenerate input, and the scalar functions inside Numba kernels
# =========================================================================


def _zero_sample(result):
    assert all(np.isfinite(v) for v in result)
    assert tuple(float(v) for v in result) == (0.0, 0.0, 0.0, 0.0, 0.0)


@pytest.mark.parametrize("u", [(0.0, 0.0), (0.5, 0.5), (1.0, 1.0), (1.0, 0.0)])
def test_degenerate_configurations_give_pdf_zero(u):
    # rectangle: o in its plane (inside and outside), zero edges, tiny solid angle
    s, ex, ey = (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.5, 0.0)
    for o in ((0.3, 0.2, 0.0), (3.0, 2.0, 0.0), (0.0, 0.0, 0.0), (0.3, 0.2, 1e6)):
        _zero_sample(sp.sample_spherical_rectangle(*o, *s, *ex, *ey, *u))
        assert sp.spherical_rectangle_pdf(*o, *s, *ex, *ey) == 0.0
    _zero_sample(sp.sample_spherical_rectangle(0.3, 0.2, 1.0, *s, 0.0, 0.0, 0.0, *ey, *u))
    _zero_sample(sp.sample_spherical_rectangle(0.3, 0.2, 1.0, *s, *ex, 0.0, 0.0, 0.0, *u))
    assert sp.rectangle_solid_angle(0.3, 0.2, 0.0, *s, *ex, *ey) == 0.0
    # triangle: the point in its plane (inside, outside), collinear vertices, a vertex at o, tiny
    a, b, c = (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.3, 0.8, 0.0)
    for o in ((0.4, 0.3, 0.0), (3.0, 3.0, 0.0), (0.0, 0.0, 0.0), (0.4, 0.3, 1e6)):
        rel = [x - y for v in (a, b, c) for x, y in zip(v, o)]
        _zero_sample(sp.sample_spherical_triangle(*rel, *u))
        assert sp.spherical_triangle_pdf(*rel) == 0.0
    _zero_sample(sp.sample_spherical_triangle(0, 0, -1, 1, 0, -1, 2, 0, -1, *u))  # collinear
    _zero_sample(sp.sample_spherical_triangle(0, 0, -1, 0, 0, -1, 2, 1, -1, *u))  # repeated vertex
    assert sp.triangle_solid_angle(0, 0, -1, 1, 0, -1, 2, 0, -1) == 0.0
    # sphere: o inside, on the surface, zero radius
    for center, radius in (((0.0, 0.0, 0.5), 1.0), ((0.0, 0.0, 1.0), 1.0), ((0.0, 0.0, 2.0), 0.0)):
        _zero_sample(sp.sample_sphere_cone(*center, radius, *u))
        assert sp.sphere_cone_pdf(*center, radius) == 0.0
    # disk: o in its plane, zero radius, zero normal
    _zero_sample(sp.sample_disk_area(3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, *u))
    _zero_sample(sp.sample_disk_area(0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, *u))
    _zero_sample(sp.sample_disk_area(0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, *u))
    assert sp.disk_solid_angle_pdf(1.0, 0.0, 1.0) == 0.0
    # non-finite input
    nan = float("nan")
    _zero_sample(sp.sample_spherical_rectangle(nan, 0.2, 1.0, *s, *ex, *ey, *u))
    _zero_sample(sp.sample_spherical_triangle(nan, 0, -1, 1, 0, -1, 0, 1, -1, *u))
    _zero_sample(sp.sample_sphere_cone(math.inf, 0.0, 2.0, 1.0, *u))


def test_vectorised_degenerate_cases_are_finite():
    u = _u("degenerate-vec", 1000)
    for w, dist, pdf in (
        sp.sample_spherical_rectangles([0.3, 0.2, 0.0], [0, 0, 0], [1.0, 0, 0], [0, 0.5, 0], u),
        sp.sample_spherical_triangles([0.4, 0.3, 0.0], [0, 0, 0], [1.0, 0, 0], [0.3, 0.8, 0], u),
        sp.sample_sphere_cones([0, 0, 0], [0, 0, 0.5], 1.0, u),
        sp.sample_disks([3.0, 0, 0], [0, 0, 0], [0, 0, 1.0], 1.0, u),
    ):
        assert np.all(w == 0) and np.all(dist == 0) and np.all(pdf == 0)
    with pytest.raises(ValueError, match="orthogonal"):
        sp.sample_spherical_rectangles([0, 0, 1.0], [0, 0, 0], [1.0, 0, 0], [0.5, 0.5, 0], u)
    with pytest.raises(ValueError, match="unit square"):
        sp.sample_sphere_cones([0, 0, 0], [0, 0, 2.0], 1.0, u + 1)
    with pytest.raises(ValueError, match="radius"):
        sp.sample_disks([0, 0, 1.0], [0, 0, 0], [0, 0, 1.0], -1.0, u)


def test_tiny_cones_keep_their_precision():
    """sin^2 theta_max = 1e-16: 1 - cos theta_max = 5e-17 exactly (no cancellation),
    and the distances stay |c| - r to rounding."""
    assert 1.0 / sp.sphere_cone_pdf(0.0, 0.0, 1e8, 1.0) == pytest.approx(2 * math.pi * 0.5e-16, rel=1e-12)
    w, dist, pdf = sp.sample_sphere_cones([0, 0, 0], [0, 0, 1e8], 1.0, _u("tiny-cone", 1000))
    assert np.all(w[:, 2] > 0) and np.all(np.hypot(w[:, 0], w[:, 1]) <= 1e-8 * (1 + 1e-12))
    assert np.all((dist >= 1e8 - 1) & (dist <= 1e8))
    hit = w * dist[:, None] - [0, 0, 1e8]
    np.testing.assert_allclose(np.linalg.norm(hit, axis=-1), 1.0, atol=1e-7)
    # a huge sphere just in front of o: theta_max close to 90 degrees, distances ~ |c| - r = 1e-6
    w, dist, pdf = sp.sample_sphere_cones([0, 0, 0], [0, 0, 1.0 + 1e-6], 1.0, [[0.0, 0.0]])
    assert dist[0] == pytest.approx(1e-6, rel=1e-9)


def test_scalar_functions_run_in_python_and_match_the_kernels():
    """The dual-use scalars called from plain Python (floats in, floats out) agree
    with the compiled kernels of the NumPy wrappers, which call the same functions
    inside Numba (to the last few ulps of the math library)."""
    o, s, ex, ey = [0.3, 0.1, 0.8], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.5, 0.0]
    a, b, c = [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.3, 0.8, 0.0]
    rel = [x - y for v in (a, b, c) for x, y in zip(v, o)]
    for u in ((0.0, 0.0), (0.3, 0.7), (1.0, 1.0)):
        pairs = [
            (sp.sample_spherical_rectangle(*o, *s, *ex, *ey, *u), sp.sample_spherical_rectangles(o, s, ex, ey, u)),
            (sp.sample_spherical_triangle(*rel, *u), sp.sample_spherical_triangles(o, a, b, c, u)),
            (sp.sample_sphere_cone(0.0, 1.0, 2.0, 0.5, *u), sp.sample_sphere_cones([0, 0, 0], [0, 1.0, 2.0], 0.5, u)),
            (sp.sample_disk_area(*o, *s, 0.0, 0.0, 1.0, 0.5, *u), sp.sample_disks(o, s, [0, 0, 1.0], 0.5, u)),
        ]
        for scalar, (w, dist, pdf) in pairs:
            assert len(scalar) == 5 and all(isinstance(float(v), float) for v in scalar)
            np.testing.assert_allclose([float(v) for v in scalar], [*w, dist, pdf], rtol=1e-13, atol=1e-15)
    for scalar, vectorised in (
        (sp.rectangle_solid_angle(*o, *s, *ex, *ey), sp.rectangle_solid_angles(o, s, ex, ey)),
        (sp.spherical_rectangle_pdf(*o, *s, *ex, *ey), sp.spherical_rectangle_pdfs(o, s, ex, ey)),
        (sp.triangle_solid_angle(*rel), sp.triangle_solid_angles(o, a, b, c)),
        (sp.spherical_triangle_pdf(*rel), sp.spherical_triangle_pdfs(o, a, b, c)),
        (sp.sphere_cone_pdf(0.0, 1.0, 2.0, 0.5), sp.sphere_cone_pdfs([0, 0, 0], [0, 1.0, 2.0], 0.5)),
    ):
        assert float(scalar) == pytest.approx(float(vectorised), rel=1e-13)
