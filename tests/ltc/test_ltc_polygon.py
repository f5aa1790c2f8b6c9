"""Tests for pbrkit.ltc.polygon: the closed-form integral of the clamped cosine
max(0, z) / pi over spherical polygons (Arvo 1995; Heitz et al. 2016 eq. 11)
with exact clipping to the upper hemisphere.

References: brute-force quadrature over the polygon (``tests/support/ltc_reference.py``:
a midpoint grid in the gnomonic projection with a winding-number
point-in-polygon test, no edge formula and no clipping), and analytic form
factors (a rectangle parallel to the surface, the whole hemisphere, the
solid angle of a small polygon at the pole).
"""

from __future__ import annotations

import math
import zlib

import numba
import numpy as np
import pytest

from pbrkit.ltc import polygon as lp

try:  # tests/ as a package or as a plain directory on sys.path
    from . import ltc_reference as ref
except ImportError:
    import ltc_reference as ref

SEED = 20250211
BRUTE_FORCE_POINTS = 1_500_000
# the brute-force grid is good to ~3e-6 absolute and 1e-4 relative at this resolution (measured
# over the random polygons here: median relative error 5e-6); a wrong clip or edge term is off by
# 1e-3 or more
BRUTE_FORCE_ATOL = 1e-5
BRUTE_FORCE_RTOL = 2e-4


def _unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _random_direction(rng):
    return _unit(rng.normal(size=3))


def _cap_polygon(rng, k, axis, max_radius=1.2, convex=True):
    """K vertices around ``axis`` at sorted azimuths and angular radii in
    [0.15, max_radius] (equal radii: a convex, cyclic polygon; random radii:
    star-shaped, possibly non-convex; never planar for K > 3 in general)."""
    e1, e2, a = ref.tangent_basis(axis)
    phi = np.sort(rng.uniform(0.0, 2 * np.pi, k))
    radius = np.full(k, rng.uniform(0.15, max_radius)) if convex else rng.uniform(0.15, max_radius, k)
    return (np.cos(radius)[:, None] * a
            + np.sin(radius)[:, None] * (np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2))


def _rectangle(rng, axis):
    """A planar rectangle centred at distance 1 along ``axis``, its plane tilted
    up to ~50 degrees from facing the origin, sides 0.2 .. 2 (points, not unit)."""
    e1, e2, a = ref.tangent_basis(axis)
    tilt = rng.uniform(0.0, 0.9)
    turn = rng.uniform(0.0, 2 * np.pi)
    normal = _unit(np.cos(tilt) * a + np.sin(tilt) * (np.cos(turn) * e1 + np.sin(turn) * e2))
    t1, t2, _ = ref.tangent_basis(normal)
    spin = rng.uniform(0.0, 2 * np.pi)
    t1, t2 = np.cos(spin) * t1 + np.sin(spin) * t2, -np.sin(spin) * t1 + np.cos(spin) * t2
    hx, hy = rng.uniform(0.1, 1.0, 2)
    return np.array([a + sx * hx * t1 + sy * hy * t2 for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))])


def _category(p):
    z = _unit(p)[:, 2]
    if np.all(z > 0.0):
        return "above"
    if np.all(z < 0.0):
        return "below"
    return "crossing"


def _polygons(kind, category, count, seed):
    rng = np.random.default_rng([SEED, seed])
    out = []
    while len(out) < count:
        axis = _random_direction(rng)
        if kind == "triangle":
            p = _cap_polygon(rng, 3, axis, convex=False)
        elif kind == "quad":
            p = _cap_polygon(rng, 4, axis, convex=bool(rng.integers(2)))
        elif kind == "rectangle":
            p = _rectangle(rng, axis)
        else:
            p = _cap_polygon(rng, 6, axis, convex=False)
        if np.any(_unit(p) @ _unit(p.sum(axis=0) if kind != "rectangle" else axis) < 0.2):
            continue
        if _category(p) == category:
            if rng.integers(2):
                p = p[::-1]  # both windings
            out.append(p)
    return out


def _assert_matches_brute_force(polygons, label):
    got = lp.polygon_clamped_cosine_integral(np.stack(polygons))
    errors = []
    for p, value in zip(polygons, got):
        want = ref.upper_hemisphere_form_factor(p, points=BRUTE_FORCE_POINTS)
        errors.append(abs(value - want))
        assert value == pytest.approx(want, abs=BRUTE_FORCE_ATOL, rel=BRUTE_FORCE_RTOL), (label, p)
    return max(errors)


# =========================================================================
# Against brute-force quadrature
# =========================================================================


@pytest.mark.parametrize("kind", ["triangle", "quad", "rectangle", "hexagon"])
@pytest.mark.parametrize("category", ["above", "crossing", "below"])
def test_matches_brute_force_quadrature(kind, category):
    polygons = _polygons(kind, category, 5 if category != "below" else 3, zlib.crc32(f"{kind}-{category}".encode()))
    _assert_matches_brute_force(polygons, f"{kind}-{category}")
    values = lp.polygon_clamped_cosine_integral(np.stack(polygons))
    if category == "below":
        assert np.all(values == 0.0)
    else:
        assert np.all(np.abs(values) > 1e-4)  # the cases are not trivially 0


def test_non_convex_polygons_crossing_the_horizon_several_times():
    # a "W": two prongs dip below the horizon, so the clipped polygon runs along the
    # horizon twice
    w = np.array([[-1.0, 0.6, 0.5], [-0.6, 0.2, -0.4], [-0.2, 0.5, 0.3], [0.2, 0.2, -0.4],
                  [0.6, 0.5, 0.3], [1.0, 0.2, 0.5], [0.0, 1.0, 0.9]])
    w[:, 1] += 1.0  # keep it in the hemisphere around +y
    # a non-planar quad through the horizon and an arrow-head (concave) quad
    non_planar = np.array([[0.5, 0.1, 0.6], [0.8, 0.9, -0.3], [-0.2, 1.0, 0.4], [-0.5, 0.3, -0.5]])
    dart = np.array([[0.0, 1.0, -0.6], [0.9, 1.0, 0.8], [0.0, 1.0, 0.1], [-0.9, 1.0, 0.8]])
    for p in (w, w[::-1], non_planar, dart, dart[::-1]):
        want = ref.upper_hemisphere_form_factor(p, points=BRUTE_FORCE_POINTS, axis=[0.0, 1.0, 0.0])
        assert lp.polygon_clamped_cosine_integral(p) == pytest.approx(want, abs=BRUTE_FORCE_ATOL,
                                                                      rel=BRUTE_FORCE_RTOL)
    clipped, count = lp.clip_to_horizon(w)
    assert count == 9  # 5 vertices above + 4 crossings
    assert np.sum(clipped[:count, 2] == 0.0) == 4


def test_brute_force_reference_can_fail():
    """The reference is sharp enough to see a wrong clip: integrating the
    unclipped clamped cosine (dropping the horizon) or the unclamped cosine
    misses by far more than the tolerance."""
    p = np.array([[1.0, -0.5, -0.4], [1.0, 0.5, -0.4], [1.0, 0.5, 0.6], [1.0, -0.5, 0.6]])  # facing -x
    want = ref.upper_hemisphere_form_factor(p, points=BRUTE_FORCE_POINTS)
    unclamped = ref.polygon_quadrature(p, lambda x, y, z: z / np.pi, points=BRUTE_FORCE_POINTS)
    vector = lp.polygon_vector_form_factor(p)[2]  # unclipped closed form
    assert vector == pytest.approx(unclamped, abs=BRUTE_FORCE_ATOL, rel=BRUTE_FORCE_RTOL)
    assert abs(vector - want) > 100 * BRUTE_FORCE_ATOL
    assert abs(lp.polygon_clamped_cosine_integral(p) - vector) > 100 * BRUTE_FORCE_ATOL


# =========================================================================
# Analytic cases
# =========================================================================


def _corner_form_factor(x, y):
    """Form factor from a differential area to a parallel rectangle [0, x] x [0, y]
    at unit height with one corner straight above it (Howell's catalogue, B-9;
    Hottel): 1 / (2 pi) [X atan(y / X) + Y atan(x / Y)], X = x / sqrt(1 + x^2),
    Y = y / sqrt(1 + y^2), with X, Y as the normalised side lengths."""
    sx = math.sqrt(1.0 + x * x)
    sy = math.sqrt(1.0 + y * y)
    return (x / sx * math.atan(y / sx) + y / sy * math.atan(x / sy)) / (2.0 * math.pi)


def _parallel_rectangle(x0, x1, y0, y1, height):
    """Analytic form factor of [x0, x1] x [y0, y1] at z = height, by superposition
    of corner rectangles (signed areas)."""
    def corner(x, y):
        return math.copysign(1.0, x) * math.copysign(1.0, y) * _corner_form_factor(abs(x) / height,
                                                                                   abs(y) / height)
    return corner(x1, y1) - corner(x0, y1) - corner(x1, y0) + corner(x0, y0)


def test_parallel_rectangles_match_the_analytic_form_factor():
    rng = np.random.default_rng(SEED)
    for _ in range(200):
        x0, x1 = np.sort(rng.uniform(-3, 3, 2))
        y0, y1 = np.sort(rng.uniform(-3, 3, 2))
        height = rng.uniform(0.05, 3.0)
        # counter-clockwise seen from the shading point below (facing it): positive
        p = np.array([[x0, y0, height], [x0, y1, height], [x1, y1, height], [x1, y0, height]])
        want = _parallel_rectangle(x0, x1, y0, y1, height)
        # (the superposition of corner rectangles cancels for thin ones: up to ~3e-10 relative)
        assert lp.polygon_clamped_cosine_integral(p) == pytest.approx(want, rel=1e-9, abs=1e-15)
        assert lp.polygon_clamped_cosine_integral(p[::-1]) == pytest.approx(-want, rel=1e-9, abs=1e-15)


def test_sign_convention_front_facing_is_positive():
    """A rectangle light in three.js's corner order (centre + w - h, centre - w - h,
    centre - w + h, centre + w + h: counter-clockwise seen from its lit side, the
    side cross(c1 - c0, c3 - c0) points to) lighting the shading point gives a
    positive integral; seen from behind, a negative one."""
    rng = np.random.default_rng(SEED + 7)
    for _ in range(50):
        centre = _random_direction(rng) * rng.uniform(0.5, 3.0)
        centre[2] = abs(centre[2]) + 0.2
        w = rng.normal(size=3)
        h = rng.normal(size=3)
        corners = np.array([centre + w - h, centre - w - h, centre - w + h, centre + w + h])
        normal = np.cross(corners[1] - corners[0], corners[3] - corners[0])
        facing = normal @ (-corners[0]) > 0.0  # the shading point is on the lit side
        value = lp.polygon_clamped_cosine_integral(corners)
        if abs(value) > 1e-12:
            assert (value > 0.0) == facing


def test_whole_hemisphere_and_limits():
    for k in (3, 4, 6, 17):
        phi = 0.3 - 2 * np.pi * np.arange(k) / k
        horizon = np.stack([np.cos(phi), np.sin(phi), np.zeros(k)], axis=-1)
        # the horizon itself, counter-clockwise seen from the shading point (clockwise seen from
        # above), bounds the whole upper hemisphere
        assert lp.polygon_clamped_cosine_integral(horizon) == pytest.approx(1.0, abs=1e-15)
        assert lp.polygon_clamped_cosine_integral(horizon[::-1]) == pytest.approx(-1.0, abs=1e-15)
        # the same polygon a hair below the horizon is clipped away entirely
        below = horizon + [0.0, 0.0, -1e-12]
        assert lp.polygon_clamped_cosine_integral(below) == 0.0
    # an enormous square parallel above the point tends to 1 (analytic value: 1 - O(1 / L))
    for half in (1e3, 1e6, 1e9):
        p = np.array([[-half, -half, 1.0], [-half, half, 1.0], [half, half, 1.0], [half, -half, 1.0]])
        want = _parallel_rectangle(-half, half, -half, half, 1.0)
        assert lp.polygon_clamped_cosine_integral(p) == pytest.approx(want, rel=1e-12)
    # a square in a plane through the horizon, rising to the zenith: exactly half the hemisphere's
    # projected disk is covered by the half-space x > 0, form factor 1/2
    half_space = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    assert lp.polygon_clamped_cosine_integral(half_space) == pytest.approx(0.5, abs=1e-15)


@pytest.mark.parametrize("size", [1e-2, 1e-4, 1e-6, 1e-8])
def test_small_quad_at_the_pole(size):
    """A small square of half-side s at unit height: solid angle
    4 asin(s^2 / (1 + s^2)) (the rectangle's exact solid angle) times cos ~ 1,
    so ~ its solid angle / pi.  The acos of a clamped dot product cannot do
    this below s ~ 1e-4 (acos(1 - 1e-16) is 0 or 1.5e-8); atan2 can."""
    p = np.array([[-size, -size, 1.0], [-size, size, 1.0], [size, size, 1.0], [size, -size, 1.0]])
    solid_angle = 4.0 * math.asin(size * size / (1.0 + size * size))
    value = lp.polygon_clamped_cosine_integral(p)
    assert value == pytest.approx(solid_angle / math.pi, rel=max(2 * size * size, 1e-9))
    assert value == pytest.approx(_parallel_rectangle(-size, size, -size, size, 1.0), rel=1e-9)
    # and tilted away from the pole the integral scales with the cosine
    tilt = 0.7
    rot = np.array([[math.cos(tilt), 0, math.sin(tilt)], [0, 1, 0], [-math.sin(tilt), 0, math.cos(tilt)]])
    assert lp.polygon_clamped_cosine_integral(p @ rot.T) == pytest.approx(value * math.cos(tilt), rel=1e-6)


def test_below_the_horizon_is_zero():
    below = np.stack(_polygons("quad", "below", 20, 99))
    assert np.all(lp.polygon_clamped_cosine_integral(below) == 0.0)
    clipped, count = lp.clip_to_horizon(below)
    assert np.all(count == 0) and np.all(clipped == 0.0)
    # touching the horizon at a vertex or along an edge still gives 0
    touch = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, -0.5], [-0.5, 0.0, -0.5]])
    assert lp.polygon_clamped_cosine_integral(touch) == 0.0
    edge = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.3, 0.3, -0.5]])
    assert lp.polygon_clamped_cosine_integral(edge) == 0.0


# =========================================================================
# Orientation, invariances and robustness
# =========================================================================


def test_orientation_and_invariances():
    rng = np.random.default_rng(SEED + 2)
    polygons = np.stack(_polygons("quad", "crossing", 8, 5) + _polygons("quad", "above", 8, 6))
    base = lp.polygon_clamped_cosine_integral(polygons)
    # reversing the order negates; a cyclic shift changes nothing
    np.testing.assert_allclose(lp.polygon_clamped_cosine_integral(polygons[:, ::-1]), -base, rtol=1e-13,
                               atol=1e-16)
    np.testing.assert_allclose(lp.polygon_clamped_cosine_integral(np.roll(polygons, 1, axis=1)), base,
                               rtol=1e-13, atol=1e-16)
    # only the directions of the vertices matter
    scale = rng.uniform(1e-3, 1e3, polygons.shape[:2] + (1,))
    np.testing.assert_allclose(lp.polygon_clamped_cosine_integral(polygons * scale), base, rtol=1e-12,
                               atol=1e-16)
    np.testing.assert_allclose(lp.polygon_clamped_cosine_integral(polygons * 1e300), base, rtol=1e-12,
                               atol=1e-16)
    np.testing.assert_allclose(lp.polygon_clamped_cosine_integral(polygons * 1e-300), base, rtol=1e-12,
                               atol=1e-16)
    # rotations about the normal change nothing; a mirror reverses the winding
    angle = 1.1
    rz = np.array([[math.cos(angle), -math.sin(angle), 0], [math.sin(angle), math.cos(angle), 0], [0, 0, 1]])
    np.testing.assert_allclose(lp.polygon_clamped_cosine_integral(polygons @ rz.T), base, rtol=1e-12,
                               atol=1e-16)
    np.testing.assert_allclose(lp.polygon_clamped_cosine_integral(polygons * [1, -1, 1]), -base, rtol=1e-12,
                               atol=1e-16)
    # repeated vertices (padding a smaller polygon into a batch) add nothing
    padded = np.concatenate([polygons, polygons[:, -1:], polygons[:, -1:]], axis=1)
    np.testing.assert_allclose(lp.polygon_clamped_cosine_integral(padded), base, rtol=1e-13, atol=1e-16)
    padded = np.concatenate([polygons[:, :1], polygons], axis=1)
    np.testing.assert_allclose(lp.polygon_clamped_cosine_integral(padded), base, rtol=1e-13, atol=1e-16)


def test_horizon_crossings_are_continuous():
    """A vertex moving through the horizon (and edges lying on it) changes the
    integral continuously: no tolerance-dependent jump, no NaN."""
    base = np.array([[0.8, -0.5, 0.4], [0.9, 0.6, 0.3], [0.0, 0.0, 1.0]])
    values = []
    zs = np.array([-1e-6, -1e-12, -1e-300, -0.0, 0.0, 1e-300, 1e-12, 1e-6])
    for z in zs:
        p = np.array([[0.9, 0.0, z], *base])
        values.append(lp.polygon_clamped_cosine_integral(p))
    values = np.array(values)
    assert np.all(np.isfinite(values))
    assert np.ptp(values) < 1e-6
    assert np.ptp(values[1:-1]) < 1e-11
    # a triangle with two vertices on the horizon, and one with an edge along it
    p = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # an octant: 1/4 of the projected disk
    assert lp.polygon_clamped_cosine_integral(p) == pytest.approx(0.25, abs=1e-15)
    p = np.array([[0.0, 1.0, -1e-300], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    assert lp.polygon_clamped_cosine_integral(p) == pytest.approx(0.25, abs=1e-15)
    p = np.array([[0.0, 1.0, -1.0], [1.0, 0.0, -1.0], [0.0, 0.0, 1.0]])  # clipped back to the octant
    assert lp.polygon_clamped_cosine_integral(p) == pytest.approx(0.25, abs=1e-15)


def test_nearly_parallel_edges():
    """Slivers and vertices 1e-9 apart: the atan2 edge angle keeps full relative
    precision where acos(dot) would lose it."""
    for eps in (1e-5, 1e-9, 1e-13):
        # a thin triangle in the plane z = 1: base 2 eps at the pole, apex at (0, 1, 1); its form
        # factor is the integral of dA / (pi r^4), r^2 = 1 + x^2 + y^2, which for width
        # 2 eps (1 - y) is 2 eps / pi * integral_0^1 (1 - y) / (1 + y^2)^2 dy = eps / 4, to O(eps^3)
        p = np.array([[eps, 0.0, 1.0], [-eps, 0.0, 1.0], [0.0, 1.0, 1.0]])
        want = eps / 4
        assert lp.polygon_clamped_cosine_integral(p) == pytest.approx(want, rel=1e-6)
    # a triangle with two coincident vertices has no area
    p = np.array([[0.3, 0.2, 1.0], [0.3, 0.2, 1.0], [0.0, 0.5, 1.0]])
    assert lp.polygon_clamped_cosine_integral(p) == 0.0
    assert lp.edge_integral(0.0, 0.0, 1.0, 0.0, 0.0, 1.0) == 0.0
    # the edge term: theta (a x b)_z / |a x b|, for a quarter of the horizon theta = pi / 2
    assert lp.edge_integral(1.0, 0.0, 0.0, 0.0, 1.0, 0.0) == pytest.approx(math.pi / 2, abs=1e-15)
    assert lp.edge_integral(2.0, 0.0, 0.0, 0.0, 0.5, 0.0) == pytest.approx(math.pi / 2, abs=1e-15)
    assert lp.edge_integral(0.0, 1.0, 0.0, 1.0, 0.0, 0.0) == pytest.approx(-math.pi / 2, abs=1e-15)
    # an edge in a vertical plane contributes nothing
    assert lp.edge_integral(1.0, 0.0, 0.0, 0.0, 0.0, 1.0) == 0.0
    t = 1e-9
    assert lp.edge_integral(1.0, 0.0, 0.0, math.cos(t), math.sin(t), 0.0) == pytest.approx(t, rel=1e-14)


# =========================================================================
# Clipping, batches, the vector form factor, Numba
# =========================================================================


def test_clip_to_horizon():
    triangle = np.array([[1.0, 0.0, 1.0], [0.0, 1.0, -1.0], [-1.0, 0.0, 1.0]])  # (clockwise: E < 0)
    clipped, count = lp.clip_to_horizon(triangle)
    assert clipped.shape == (4, 3) and count == 4  # K + 1 for a convex polygon with one vertex below
    np.testing.assert_allclose(clipped, _unit([[1, 0, 1], [1, 1, 0], [-1, 1, 0], [-1, 0, 1]]), atol=1e-15)
    polygons = np.stack(_polygons("rectangle", "crossing", 20, 11) + _polygons("quad", "crossing", 20, 12))
    clipped, count = lp.clip_to_horizon(polygons)
    assert clipped.shape == (40, 6, 3)
    assert np.all(clipped[..., 2] >= 0.0)
    np.testing.assert_allclose(np.linalg.norm(clipped, axis=-1), 1.0, atol=1e-15)
    assert np.all(count[:20] <= 5)  # planar convex quads: at most K + 1
    # the clipped polygons (padded with their last vertex) have the same integral
    np.testing.assert_allclose(lp.polygon_clamped_cosine_integral(clipped),
                               lp.polygon_clamped_cosine_integral(polygons), rtol=1e-13, atol=1e-16)
    # and above the horizon the clamped integral is the unclamped (vector) one
    np.testing.assert_allclose(lp.polygon_vector_form_factor(clipped)[:, 2],
                               lp.polygon_clamped_cosine_integral(polygons), rtol=1e-12, atol=1e-16)
    # capacity K + K // 2 is reached by a quad alternating above and below
    alternating = np.array([[1.0, 0.0, 0.5], [0.5, 0.5, -1.0], [0.0, 1.0, 0.5], [0.2, 0.2, -1.0]])
    clipped, count = lp.clip_to_horizon(alternating)
    assert count == lp.clipped_vertex_capacity(4) == 6


def test_batches_and_shapes():
    polygons = np.stack(_polygons("quad", "crossing", 6, 21)).reshape(2, 3, 4, 3)
    batch = lp.polygon_clamped_cosine_integral(polygons)
    assert batch.shape == (2, 3)
    for i in range(2):
        for j in range(3):
            assert batch[i, j] == lp.polygon_clamped_cosine_integral(polygons[i, j])
            # the dual-use core called from Python on one polygon agrees
            assert lp.polygon_form_factor(polygons[i, j]) == pytest.approx(batch[i, j], rel=1e-14, abs=1e-17)
    assert lp.polygon_clamped_cosine_integral(polygons[0, 0]).shape == ()
    assert lp.polygon_clamped_cosine_integral(np.zeros((0, 4, 3))).shape == (0,)
    assert lp.polygon_vector_form_factor(polygons).shape == (2, 3, 3)
    # fewer than three vertices bound nothing
    for k in (1, 2):
        assert lp.polygon_clamped_cosine_integral(polygons[0, 0, :k]) == 0.0
    # a large batch runs in the kernel, not a Python loop
    rng = np.random.default_rng(SEED + 4)
    many = rng.normal(size=(200_000, 4, 3)) + [0.0, 0.0, 1.0]
    values = lp.polygon_clamped_cosine_integral(many)
    assert values.shape == (200_000,) and np.all(np.isfinite(values)) and np.all(np.abs(values) <= 2.0)


def test_vector_form_factor():
    """F . n is the unclamped cosine integral about any axis n, so for a polygon
    above the plane of n it equals the clamped integral in a frame whose z is n."""
    for p in _polygons("quad", "above", 4, 31) + _polygons("rectangle", "crossing", 4, 32):
        f = lp.polygon_vector_form_factor(p)
        normal = _unit(p.sum(axis=0))
        e1, e2, n = ref.tangent_basis(normal)
        local = p @ np.stack([e1, e2, n]).T  # coordinates in a frame with z = n
        assert np.all(local[:, 2] > 0.0)
        assert f @ n == pytest.approx(lp.polygon_clamped_cosine_integral(local), rel=1e-12, abs=1e-16)
        ex, ey, ez = lp.edge_vector_form_factor(*p[0], *p[1])
        assert ez == pytest.approx(lp.edge_integral(*p[0], *p[1]), rel=1e-14, abs=1e-17)
        assert np.cross(p[0], p[1]) @ [ex, ey, ez] > 0.0


@numba.njit  # not cached: Numba's cache would not see edits to pbrkit.ltc.polygon
def _kernel(polygons, matrices, out):
    for i in range(polygons.shape[0]):
        out[i, 0] = lp.polygon_form_factor(polygons[i])
        out[i, 1] = lp.transformed_polygon_form_factor(matrices[i], polygons[i])
        p = polygons[i]
        out[i, 2] = lp.edge_integral(p[0, 0], p[0, 1], p[0, 2], p[1, 0], p[1, 1], p[1, 2])
        buffer = np.empty((6, 3))
        out[i, 3] = lp.clip_polygon_to_horizon(matrices[i], polygons[i], buffer)


def test_dual_use_in_numba_kernels():
    rng = np.random.default_rng(SEED + 6)
    polygons = np.stack(_polygons("quad", "crossing", 10, 41))
    matrices = rng.normal(size=(10, 3, 3)) + 2 * np.eye(3)
    out = np.empty((10, 4))
    _kernel(polygons, matrices, out)
    np.testing.assert_allclose(out[:, 0], lp.polygon_clamped_cosine_integral(polygons), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(out[:, 1], lp.transformed_polygon_integrals(matrices, polygons), rtol=1e-12,
                               atol=1e-15)
    np.testing.assert_allclose(out[:, 1], lp.polygon_clamped_cosine_integral(np.einsum("nij,nkj->nki", matrices,
                                                                                        polygons)),
                               rtol=1e-12, atol=1e-16)
    np.testing.assert_allclose(out[:, 2], lp.edge_integral(*polygons[:, 0].T, *polygons[:, 1].T), rtol=1e-14)
    _, count = lp.clip_to_horizon(np.einsum("nij,nkj->nki", matrices, polygons))
    np.testing.assert_array_equal(out[:, 3], count)


def test_bad_input():
    with pytest.raises(ValueError, match="shape"):
        lp.polygon_clamped_cosine_integral(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="shape"):
        lp.polygon_clamped_cosine_integral(np.zeros(3))
    with pytest.raises(ValueError, match="finite"):
        lp.polygon_clamped_cosine_integral([[0, 0, 1], [1, 0, np.nan], [0, 1, 1]])
    with pytest.raises(ValueError, match="zero vector"):
        lp.polygon_clamped_cosine_integral([[0, 0, 1], [0, 0, 0], [0, 1, 1]])
    with pytest.raises(ValueError, match="zero vector"):
        lp.clip_to_horizon([[0, 0, 1], [0, 0, 0], [0, 1, 1]])
