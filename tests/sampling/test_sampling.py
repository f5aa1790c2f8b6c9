"""Tests for pbrkit.sampling: low-discrepancy points and warps with their pdfs (with the
microfacet warps of the GGX, Beckmann and GTR1 units of pbrkit.microfacet).

Samplers are checked with chi-square goodness-of-fit tests (the Mitsuba /
pbrt-v4 method, machinery in ``tests/support/chi2.py``): 10^6 seeded samples per case,
a (theta, phi) histogram with cells at quantiles of the pdf's marginals,
expected counts by Gauss-Legendre integration of the pdf over every cell (the
integral of the pdf over the sphere must be 1), pooling below 5 expected, and
a Sidak-corrected family-wise level of 0.01 over every chi-square case here.
"""

from __future__ import annotations

import math
import zlib
from fractions import Fraction

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

from pbrkit import sampling as s
from pbrkit.brdf.distributions import ALPHA_MIN
from pbrkit.microfacet import beckmann, ggx, gtr

try:  # tests/ as a package or as a plain directory on sys.path
    from . import chi2
except ImportError:
    import chi2

N_SAMPLES = 1_000_000
FAMILY_ALPHA = 0.01
NORMALISATION_TOL = 1e-4  # |integral of pdf - 1|; the quadrature itself is good to ~1e-6
SEED = 20240611

# =========================================================================
# Low-discrepancy points
# =========================================================================


def _radical_inverse_exact(i, base):
    """phi_b(i) as an exact fraction, rounded once to float (the reference)."""
    numerator, denominator = 0, 1
    while i:
        i, digit = divmod(i, base)
        numerator = numerator * base + digit
        denominator *= base
    return min(float(Fraction(numerator, denominator)), 1.0 - 2.0**-53)


def test_radical_inverse_known_values():
    np.testing.assert_array_equal(s.radical_inverse(np.arange(1, 9), 2),
                                  [1 / 2, 1 / 4, 3 / 4, 1 / 8, 5 / 8, 3 / 8, 7 / 8, 1 / 16])
    np.testing.assert_allclose(s.radical_inverse(np.arange(1, 10), 3),
                               [1 / 3, 2 / 3, 1 / 9, 4 / 9, 7 / 9, 2 / 9, 5 / 9, 8 / 9, 1 / 27], rtol=0, atol=1e-16)
    assert s.radical_inverse(0, 5) == 0.0
    assert s.radical_inverse(1234, 10) == pytest.approx(0.4321, abs=1e-16)
    # a base larger than the index: phi_b(i) = i / b
    assert s.radical_inverse(7, 1_000_003) == 7 / 1_000_003


@pytest.mark.parametrize("base", [2, 3, 5, 7, 10, 97, 65537, 2**31 - 1])
def test_radical_inverse_exact_for_64_bit_indices(base):
    rng = np.random.default_rng([SEED, base % 1000])
    index = np.concatenate([rng.integers(0, 2**64, size=300, dtype=np.uint64),
                            np.array([0, 1, base - 1, base, 2**53 + 1, 2**63, 2**64 - 2, 2**64 - 1], dtype=np.uint64)])
    got = s.radical_inverse(index, base)
    want = np.array([_radical_inverse_exact(int(i), base) for i in index])
    ulps = np.abs(got - want) / np.spacing(np.maximum(want, 1e-300))
    if base == 2:
        np.testing.assert_array_equal(got, want)  # bit reversal, rounded once
    else:
        assert ulps.max() <= 2
    assert np.all((got >= 0.0) & (got < 1.0))


def test_radical_inverse_accepts_integer_kinds_and_rejects_bad_input():
    assert s.radical_inverse(2**64 - 1, 2) == 1.0 - 2.0**-53
    with pytest.raises(ValueError, match="2\\*\\*64"):
        s.radical_inverse(2**64, 3)
    np.testing.assert_array_equal(s.radical_inverse(np.arange(5, dtype=np.int32), 3),
                                  s.radical_inverse(np.arange(5, dtype=np.uint64), 3))
    assert s.radical_inverse(np.zeros((2, 0), dtype=np.int64), 3).shape == (2, 0)
    with pytest.raises(ValueError, match="non-negative"):
        s.radical_inverse(-1, 2)
    with pytest.raises(ValueError, match="integer"):
        s.radical_inverse(np.array([0.5]), 2)
    with pytest.raises(ValueError, match="base"):
        s.radical_inverse(3, 1)
    with pytest.raises(ValueError, match="base"):
        s.radical_inverse(3, 2.0)


def test_van_der_corput_halton_hammersley_structure():
    np.testing.assert_array_equal(s.van_der_corput(8), [0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875])
    # the first 2^k van der Corput points are exactly the grid {i / 2^k}
    np.testing.assert_array_equal(np.sort(s.van_der_corput(1024)), np.arange(1024) / 1024)
    np.testing.assert_array_equal(s.primes(10), [2, 3, 5, 7, 11, 13, 17, 19, 23, 29])
    assert s.primes(1000)[-1] == 7919
    h = s.halton(50, 4, skip=7)
    for k, p in enumerate([2, 3, 5, 7]):
        np.testing.assert_array_equal(h[:, k], s.radical_inverse(np.arange(7, 57), p))
    np.testing.assert_array_equal(s.halton(57, 4)[7:], h)
    big = s.halton(30, 120)
    assert big.shape == (30, 120)
    np.testing.assert_array_equal(big[:, 119], s.radical_inverse(np.arange(30), 659))  # the 120th prime
    hm = s.hammersley(4, 3)
    np.testing.assert_allclose(hm, [[0, 0, 0], [0.25, 0.5, 1 / 3], [0.5, 0.25, 2 / 3], [0.75, 0.75, 1 / 9]],
                               rtol=0, atol=1e-16)
    # every 1-D projection of a 3^5-point Hammersley set in base 3 is a stratified grid
    np.testing.assert_allclose(np.sort(s.hammersley(243, 3)[:, 2]), np.arange(243) / 243, atol=1e-15)
    with pytest.raises(ValueError):
        s.halton(10, 0)
    with pytest.raises(ValueError):
        s.hammersley(0)


def _l2_star_brute_force(points):
    """T^2 = integral over y in [0,1]^d of (#{x_i < y} / n - prod y)^2, integrated exactly.

    The point coordinates cut the cube into boxes in which the count is
    constant, so each box contributes (c/n)^2 V - 2 (c/n) prod (b^2 - a^2)/2 +
    prod (b^3 - a^3)/3 exactly.  Independent of Warnock's formula."""
    x = np.asarray(points)
    n, d = x.shape
    cuts = [np.unique(np.concatenate([[0.0, 1.0], x[:, k]])) for k in range(d)]
    lows = np.meshgrid(*[c[:-1] for c in cuts], indexing="ij")
    highs = np.meshgrid(*[c[1:] for c in cuts], indexing="ij")
    lo = np.stack([m.ravel() for m in lows], axis=-1)
    hi = np.stack([m.ravel() for m in highs], axis=-1)
    # x_i is inside the open anchored box [0, y) for every y in the cell iff x_i <= lower corner
    count = np.sum(np.all(x[None, :, :] <= lo[:, None, :], axis=-1), axis=1) / n
    volume = np.prod(hi - lo, axis=1)
    first = np.prod((hi**2 - lo**2) / 2, axis=1)
    second = np.prod((hi**3 - lo**3) / 3, axis=1)
    return float(np.sum(count**2 * volume - 2 * count * first + second))


@pytest.mark.parametrize("n, d", [(1, 1), (9, 1), (12, 2), (16, 2), (7, 3)])
def test_warnock_matches_brute_force_integration(n, d):
    rng = np.random.default_rng([SEED, n, d])
    for points in (rng.random((n, d)), s.hammersley(n, d), s.halton(n, d, skip=1)):
        assert s.l2_star_discrepancy(points) ** 2 == pytest.approx(_l2_star_brute_force(points), rel=1e-11,
                                                                  abs=1e-15)


def test_warnock_one_dimensional_closed_forms():
    # one point: T^2 = 1/3 - x + x^2
    for x in (0.0, 0.3, 0.5, 1.0):
        assert s.l2_star_discrepancy([[x]]) ** 2 == pytest.approx(1 / 3 - x + x * x, abs=1e-15)
    # 1-D: T^2 = 1 / (12 n^2) + (1/n) sum (x_(i) - (2i - 1) / (2n))^2 (Niederreiter 1992, ch. 2)
    rng = np.random.default_rng(SEED)
    for n in (1, 5, 64):
        x = np.sort(rng.random(n))
        centred = (2 * np.arange(1, n + 1) - 1) / (2 * n)
        want = 1 / (12 * n * n) + np.mean((x - centred) ** 2)
        assert s.l2_star_discrepancy(x[:, None]) ** 2 == pytest.approx(want, rel=1e-12)
        assert s.l2_star_discrepancy(centred[:, None]) ** 2 == pytest.approx(1 / (12 * n * n), rel=1e-10)
    with pytest.raises(ValueError, match="unit cube"):
        s.l2_star_discrepancy([[1.5, 0.2]])
    with pytest.raises(ValueError, match="shape"):
        s.l2_star_discrepancy(np.zeros(4))


@pytest.mark.parametrize("d", [2, 3])
def test_low_discrepancy_beats_random_and_decreases(d):
    rng = np.random.default_rng([SEED, d])
    previous = {"hammersley": np.inf, "halton": np.inf}
    for n in (64, 256, 1024, 4096):
        # i.i.d. uniform points: E[T^2] = (2^-d - 3^-d) / n (the integral of V (1 - V) / n over anchored
        # boxes of volume V); 32 random sets per n agree (the relative sd of one set's T^2 is ~0.6)
        expected_random_t2 = (2.0**-d - 3.0**-d) / n
        if n <= 1024:
            random_t2 = [s.l2_star_discrepancy(rng.random((n, d))) ** 2 for _ in range(32)]
            assert np.mean(random_t2) == pytest.approx(expected_random_t2, rel=0.35)
        for name, points in (("hammersley", s.hammersley(n, d)), ("halton", s.halton(n, d, skip=1))):
            t = s.l2_star_discrepancy(points)
            assert t < math.sqrt(expected_random_t2), (name, n, t)
            if n <= 1024:
                assert t**2 < np.median(random_t2), (name, n, t)
            assert t < previous[name], (name, n)
            previous[name] = t
    # the rate: T ~ (log n)^((d-1)/2) / n, far below random's n^-1/2 at n = 4096
    for name, t in previous.items():
        assert t < 0.2 * math.sqrt(expected_random_t2), name


# =========================================================================
# Warps: unit tests
# =========================================================================

ALPHAS = (0.05, 0.3, 1.0)
ANISO_ALPHAS = ((0.05, 0.3), (0.3, 1.0), (1.0, 0.05))
INCIDENT_DEGREES = (0, 45, 80)
VIEW_AZIMUTH = 1.0  # radians, so anisotropic cases are not aligned with the axes


def _view(theta_degrees, phi=VIEW_AZIMUTH):
    t = math.radians(theta_degrees)
    return np.array([math.sin(t) * math.cos(phi), math.sin(t) * math.sin(phi), math.cos(t)])


def test_concentric_disk_known_values():
    u = np.array([[0.5, 0.5], [1.0, 0.5], [0.5, 1.0], [0.0, 0.5], [0.5, 0.0], [1.0, 1.0], [0.75, 0.5]])
    c = math.sqrt(0.5)
    want = [[0, 0], [1, 0], [0, 1], [-1, 0], [0, -1], [c, c], [0.5, 0]]
    np.testing.assert_allclose(s.sample_concentric_disk(u), want, atol=1e-15)
    # concentric squares go to concentric circles: |p| = max(|2u1 - 1|, |2u2 - 1|)
    rng = np.random.default_rng(SEED)
    u = rng.random((1000, 2))
    p = s.sample_concentric_disk(u)
    np.testing.assert_allclose(np.hypot(p[:, 0], p[:, 1]), np.max(np.abs(2 * u - 1), axis=1), rtol=1e-14)


def test_warp_known_values():
    alpha = 0.3
    np.testing.assert_allclose(s.sample_uniform_sphere([0.0, 0.3]), [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(s.sample_uniform_sphere([0.5, 0.25]), [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(s.sample_uniform_hemisphere([0.5, 0.0]), [math.sqrt(0.75), 0, 0.5], atol=1e-15)
    np.testing.assert_allclose(s.sample_cosine_hemisphere([0.5, 0.5]), [0, 0, 1], atol=1e-15)
    # GGX (Walter eq. 35): u1 = 1/2 gives tan theta = alpha; Beckmann (eq. 28): u1 = 1 - 1/e gives tan theta = alpha
    h = ggx.sample_ggx_ndf([0.5, 0.0], alpha)
    assert math.atan2(h[0], h[2]) == pytest.approx(math.atan(alpha), rel=1e-14)
    h = beckmann.sample_beckmann_ndf([1 - math.exp(-1), 0.25], alpha)
    assert math.atan2(h[1], h[2]) == pytest.approx(math.atan(alpha), rel=1e-14)
    # GTR1 (Burley B.2): u1 = 1/2 gives cos^2 theta = (1 - alpha) / (1 - alpha^2) = 1 / (1 + alpha)
    h = gtr.sample_gtr1_ndf([0.5, 0.0], alpha)
    assert h[2] ** 2 == pytest.approx(1 / (1 + alpha), rel=1e-14)
    np.testing.assert_allclose(gtr.sample_gtr1_ndf([0.0, 0.3], alpha), [0, 0, 1], atol=1e-15)
    # GTR1 at alpha = 1 is uniform D: D cos is the cosine lobe, cos^2 = 1 - u1
    assert gtr.sample_gtr1_ndf([0.36, 0.1], 1.0)[2] == pytest.approx(0.8, rel=1e-14)
    # VNDF at normal incidence: the disk centre (u1 = 0) is the normal
    np.testing.assert_allclose(ggx.sample_ggx_vndf([0.0, 0.7], [0, 0, 1], alpha), [0, 0, 1], atol=1e-15)


def test_anisotropic_reduces_to_isotropic():
    rng = np.random.default_rng(SEED)
    u = rng.random((2000, 2))
    for alpha in (ALPHA_MIN, 0.05, 0.3, 1.0, 2.0):
        np.testing.assert_allclose(ggx.sample_ggx_ndf_anisotropic(u, alpha, alpha), ggx.sample_ggx_ndf(u, alpha),
                                   atol=2e-15)
        h = ggx.sample_ggx_ndf(u, alpha)
        # (d_ggx's (n.h)^2 (alpha^2 - 1) + 1 loses ~eps / alpha^2 near the peak, hence the rtol)
        np.testing.assert_allclose(ggx.pdf_ggx_ndf_anisotropic(h[:, 0], h[:, 1], h[:, 2], alpha, alpha),
                                   ggx.pdf_ggx_ndf(h[:, 2], alpha), rtol=1e-8)
        wo = _view(70)
        h = ggx.sample_ggx_vndf(u, wo, alpha)
        voh = h @ wo
        np.testing.assert_allclose(ggx.pdf_ggx_vndf_anisotropic(*wo, h[:, 0], h[:, 1], h[:, 2], alpha, alpha),
                                   ggx.pdf_ggx_vndf(wo[2], h[:, 2], voh, alpha), rtol=1e-8)


_EDGE_U = np.array([0.0, 1e-300, 1e-12, 0.25, 0.5, 1 - 1e-12, 1 - 2.0**-53, 1.0])
_EDGE_U2 = np.stack(np.meshgrid(_EDGE_U, _EDGE_U, indexing="ij"), axis=-1).reshape(-1, 2)
_EDGE_VIEWS = np.array([[0, 0, 1], [1, 0, 0], [0, 1, 1e-300], [0.6, 0.8, 1e-12], [0.3, -0.4, -0.5], [0, 0, -1],
                        [1e-300, 0, 1]], dtype=float)


def _all_warps(u, alpha_x, alpha_y, wo):
    """Every warp with its pdf at the returned direction: (name, directions, pdf values)."""
    out = []
    for name, sampler, pdf in (
            ("uniform_sphere", s.sample_uniform_sphere, lambda w: s.pdf_uniform_sphere(w[..., 2])),
            ("uniform_hemisphere", s.sample_uniform_hemisphere, lambda w: s.pdf_uniform_hemisphere(w[..., 2])),
            ("cosine_hemisphere", s.sample_cosine_hemisphere, lambda w: s.pdf_cosine_hemisphere(w[..., 2]))):
        w = sampler(u)
        out.append((name, w, pdf(w)))
    for name, sampler, pdf in (("ggx_ndf", ggx.sample_ggx_ndf, ggx.pdf_ggx_ndf),
                               ("beckmann_ndf", beckmann.sample_beckmann_ndf, beckmann.pdf_beckmann_ndf),
                               ("gtr1_ndf", gtr.sample_gtr1_ndf, gtr.pdf_gtr1_ndf)):
        h = sampler(u, alpha_x)
        out.append((name, h, pdf(h[..., 2], alpha_x)))
    h = ggx.sample_ggx_ndf_anisotropic(u, alpha_x, alpha_y)
    out.append(("ggx_ndf_anisotropic", h, ggx.pdf_ggx_ndf_anisotropic(h[..., 0], h[..., 1], h[..., 2], alpha_x,
                                                                    alpha_y)))
    h = ggx.sample_ggx_vndf(u, wo, alpha_x)
    voh = np.sum(h * wo, axis=-1)
    pdf_h = ggx.pdf_ggx_vndf(wo[..., 2], h[..., 2], voh, alpha_x)
    out.append(("ggx_vndf", h, pdf_h))
    out.append(("ggx_vndf_light", s.reflect(wo, h), s.pdf_light_from_half(pdf_h, voh)))
    h = ggx.sample_ggx_vndf_anisotropic(u, wo, alpha_x, alpha_y)
    pdf_h = ggx.pdf_ggx_vndf_anisotropic(wo[..., 0], wo[..., 1], wo[..., 2], h[..., 0], h[..., 1], h[..., 2],
                                       alpha_x, alpha_y)
    out.append(("ggx_vndf_anisotropic", h, pdf_h))
    return out


@pytest.mark.parametrize("alpha_x, alpha_y", [(ALPHA_MIN, ALPHA_MIN), (ALPHA_MIN, 1.0), (0.3, 0.05), (1.0, 1.0),
                                              (4.0, 0.5), (1e6, ALPHA_MIN)])
def test_degenerate_inputs_give_finite_unit_vectors(alpha_x, alpha_y):
    u = np.repeat(_EDGE_U2, len(_EDGE_VIEWS), axis=0)
    wo = np.tile(_EDGE_VIEWS / np.linalg.norm(_EDGE_VIEWS, axis=1, keepdims=True), (len(_EDGE_U2), 1))
    with np.errstate(divide="raise", over="raise", invalid="raise"):  # not even in discarded branches
        results = _all_warps(u, alpha_x, alpha_y, wo)
    for name, w, pdf in results:
        assert np.all(np.isfinite(w)), name
        np.testing.assert_allclose(np.linalg.norm(w, axis=-1), 1.0, atol=1e-12, err_msg=name)
        assert np.all(np.isfinite(pdf) & (pdf >= 0.0)), name
        if name.endswith("ndf") or name.endswith("hemisphere") or name.startswith("ggx_ndf"):
            assert np.all(w[..., 2] >= 0.0), name
    p = s.sample_concentric_disk(_EDGE_U2)
    assert np.all(np.isfinite(p)) and np.all(np.hypot(p[:, 0], p[:, 1]) <= 1.0 + 1e-15)


@settings(max_examples=300, deadline=None)
@given(u1=st.floats(0.0, 1.0), u2=st.floats(0.0, 1.0), alpha_x=st.floats(ALPHA_MIN, 2.0),
       alpha_y=st.floats(ALPHA_MIN, 2.0), theta=st.floats(0.0, math.pi / 2), phi=st.floats(0.0, 2 * math.pi))
def test_warps_property(u1, u2, alpha_x, alpha_y, theta, phi):
    wo = np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)])
    for name, w, pdf in _all_warps(np.array([u1, u2]), alpha_x, alpha_y, wo):
        assert np.all(np.isfinite(w)) and abs(np.linalg.norm(w) - 1.0) < 1e-12, name
        assert np.isfinite(pdf) and pdf >= 0.0, name
        if name.startswith("ggx_vndf") and name != "ggx_vndf_light":
            # visible normals: facing the view and above the surface
            assert w @ wo >= -1e-12 and w[2] >= 0.0, name


def test_reflect_and_half_vector_jacobian():
    rng = np.random.default_rng(SEED)
    wo = s.sample_uniform_hemisphere(rng.random((500, 2)))
    h = ggx.sample_ggx_vndf(rng.random((500, 2)), wo, 0.5)
    l = s.reflect(wo, h)
    np.testing.assert_allclose(np.linalg.norm(l, axis=-1), 1.0, atol=1e-14)
    np.testing.assert_allclose(s.reflect(l, h), wo, atol=1e-14)
    voh = np.sum(wo * h, axis=-1)
    ok = voh > 1e-6
    half = (wo + l)[ok]
    np.testing.assert_allclose(half / np.linalg.norm(half, axis=-1, keepdims=True), h[ok], atol=1e-10)
    np.testing.assert_allclose(s.reflect([0.6, 0.0, 0.8], [0, 0, 1]), [-0.6, 0.0, 0.8], atol=1e-15)
    # d omega_h / d omega_l by finite differences: map a small triangle of half vectors to light
    # directions and compare spherical areas (Walter et al. 2007, eq. 14: 1 / (4 v.h))
    eps = 1e-5
    for i in np.flatnonzero(ok)[:50]:
        t1 = np.cross(h[i], [0.0, 0.0, 1.0] if abs(h[i, 2]) < 0.9 else [1.0, 0.0, 0.0])
        t1 /= np.linalg.norm(t1)
        t2 = np.cross(h[i], t1)
        # a small quadrilateral centred on h (central differences), area from its diagonals
        hs = h[i] + eps * np.array([t1, t2, -t1, -t2])
        hs /= np.linalg.norm(hs, axis=-1, keepdims=True)
        ls = s.reflect(np.broadcast_to(wo[i], hs.shape), hs)
        area_h = np.linalg.norm(np.cross(hs[0] - hs[2], hs[1] - hs[3]))
        area_l = np.linalg.norm(np.cross(ls[0] - ls[2], ls[1] - ls[3]))
        assert area_h / area_l == pytest.approx(s.half_to_light_jacobian(voh[i]), rel=1e-6)
    assert s.half_to_light_jacobian(0.25) == 1.0
    assert s.half_to_light_jacobian(0.0) == 0.0 and s.half_to_light_jacobian(-0.5) == 0.0
    assert s.pdf_light_from_half(2.0, 0.5) == 1.0


def test_wrappers_validate_and_broadcast():
    with pytest.raises(ValueError, match="last axis"):
        s.sample_uniform_sphere(np.zeros((4, 3)))
    with pytest.raises(ValueError, match="unit square"):
        s.sample_cosine_hemisphere([0.5, 1.5])
    with pytest.raises(ValueError, match="unit square"):
        ggx.sample_ggx_ndf([np.nan, 0.5], 0.3)
    with pytest.raises(ValueError, match="alpha"):
        ggx.sample_ggx_ndf([0.5, 0.5], 0.0)
    with pytest.raises(ValueError, match="alpha_y"):
        ggx.sample_ggx_vndf_anisotropic([0.5, 0.5], [0, 0, 1], 0.3, -1.0)
    with pytest.raises(ValueError, match="wo"):
        ggx.sample_ggx_vndf([0.5, 0.5], [0, 0, 0], 0.3)
    with pytest.raises(ValueError, match="wo"):
        ggx.sample_ggx_vndf([0.5, 0.5], [0, 1], 0.3)
    u = np.random.default_rng(SEED).random((4, 5, 2))
    assert ggx.sample_ggx_ndf(u, np.full(5, 0.3)).shape == (4, 5, 3)
    assert ggx.sample_ggx_vndf(u, np.array([0.0, 0.0, 1.0]), 0.3).shape == (4, 5, 3)
    assert s.sample_concentric_disk(u).shape == (4, 5, 2)
    assert s.sample_uniform_sphere([0.1, 0.2]).shape == (3,)


# ------------------------------------------------------------ dual use in Numba


@numba.njit(cache=True)
def _put(out, i, k, values):
    for j in range(len(values)):
        out[i, k + j] = values[j]


@numba.njit(cache=True)
def _terms_kernel(u, wo, alpha_x, alpha_y, out):
    for i in range(u.shape[0]):
        u1, u2 = u[i, 0], u[i, 1]
        wx, wy, wz = wo[i, 0], wo[i, 1], wo[i, 2]
        ax, ay = alpha_x[i], alpha_y[i]
        k = 0
        x, y, z = s.warp_uniform_sphere(u1, u2)
        _put(out, i, k, (x, y, z, s.pdf_uniform_sphere(z)))
        k += 4
        x, y, z = s.warp_uniform_hemisphere(u1, u2)
        _put(out, i, k, (x, y, z, s.pdf_uniform_hemisphere(z)))
        k += 4
        x, y = s.warp_concentric_disk(u1, u2)
        _put(out, i, k, (x, y, s.pdf_concentric_disk(x, y)))
        k += 3
        x, y, z = s.warp_cosine_hemisphere(u1, u2)
        _put(out, i, k, (x, y, z, s.pdf_cosine_hemisphere(z)))
        k += 4
        x, y, z = ggx.warp_ggx_ndf(u1, u2, ax)
        _put(out, i, k, (x, y, z, ggx.pdf_ggx_ndf(z, ax)))
        k += 4
        x, y, z = ggx.warp_ggx_ndf_anisotropic(u1, u2, ax, ay)
        _put(out, i, k, (x, y, z, ggx.pdf_ggx_ndf_anisotropic(x, y, z, ax, ay)))
        k += 4
        x, y, z = beckmann.warp_beckmann_ndf(u1, u2, ax)
        _put(out, i, k, (x, y, z, beckmann.pdf_beckmann_ndf(z, ax)))
        k += 4
        x, y, z = gtr.warp_gtr1_ndf(u1, u2, ax)
        _put(out, i, k, (x, y, z, gtr.pdf_gtr1_ndf(z, ax)))
        k += 4
        x, y, z = ggx.warp_ggx_vndf(u1, u2, wx, wy, wz, ax)
        voh = wx * x + wy * y + wz * z
        pdf_h = ggx.pdf_ggx_vndf(wz, z, voh, ax)
        _put(out, i, k, (x, y, z, pdf_h))
        k += 4
        lx, ly, lz = s.reflect_xyz(wx, wy, wz, x, y, z)
        _put(out, i, k, (lx, ly, lz, s.pdf_light_from_half(pdf_h, voh), s.half_to_light_jacobian(voh)))
        k += 5
        x, y, z = ggx.warp_ggx_vndf_anisotropic(u1, u2, wx, wy, wz, ax, ay)
        _put(out, i, k, (x, y, z, ggx.pdf_ggx_vndf_anisotropic(wx, wy, wz, x, y, z, ax, ay)))


def test_terms_compile_in_numba_and_match_numpy():
    rng = np.random.default_rng(SEED)
    n = 256
    u = np.concatenate([rng.random((n, 2)), _EDGE_U2])
    m = len(u)
    wo = s.sample_uniform_sphere(rng.random((m, 2)))
    wo[:4] = [[0, 0, 1], [1, 0, 0], [0, 0, -1], [0.6, 0, -0.8]]
    alpha_x = rng.uniform(ALPHA_MIN, 1.5, m)
    alpha_y = rng.uniform(ALPHA_MIN, 1.5, m)
    got = np.empty((m, 44))
    _terms_kernel(u, wo, alpha_x, alpha_y, got)
    u1, u2 = u[:, 0], u[:, 1]
    wx, wy, wz = wo.T
    parts = []
    x, y, z = s.warp_uniform_sphere(u1, u2)
    parts += [x, y, z, s.pdf_uniform_sphere(z)]
    x, y, z = s.warp_uniform_hemisphere(u1, u2)
    parts += [x, y, z, s.pdf_uniform_hemisphere(z)]
    x, y = s.warp_concentric_disk(u1, u2)
    parts += [x, y, s.pdf_concentric_disk(x, y)]
    x, y, z = s.warp_cosine_hemisphere(u1, u2)
    parts += [x, y, z, s.pdf_cosine_hemisphere(z)]
    x, y, z = ggx.warp_ggx_ndf(u1, u2, alpha_x)
    parts += [x, y, z, ggx.pdf_ggx_ndf(z, alpha_x)]
    x, y, z = ggx.warp_ggx_ndf_anisotropic(u1, u2, alpha_x, alpha_y)
    parts += [x, y, z, ggx.pdf_ggx_ndf_anisotropic(x, y, z, alpha_x, alpha_y)]
    x, y, z = beckmann.warp_beckmann_ndf(u1, u2, alpha_x)
    parts += [x, y, z, beckmann.pdf_beckmann_ndf(z, alpha_x)]
    x, y, z = gtr.warp_gtr1_ndf(u1, u2, alpha_x)
    parts += [x, y, z, gtr.pdf_gtr1_ndf(z, alpha_x)]
    x, y, z = ggx.warp_ggx_vndf(u1, u2, wx, wy, wz, alpha_x)
    voh = wx * x + wy * y + wz * z
    pdf_h = ggx.pdf_ggx_vndf(wz, z, voh, alpha_x)
    parts += [x, y, z, pdf_h]
    lx, ly, lz = s.reflect_xyz(wx, wy, wz, x, y, z)
    parts += [lx, ly, lz, s.pdf_light_from_half(pdf_h, voh), s.half_to_light_jacobian(voh)]
    x, y, z = ggx.warp_ggx_vndf_anisotropic(u1, u2, wx, wy, wz, alpha_x, alpha_y)
    parts += [x, y, z, ggx.pdf_ggx_vndf_anisotropic(wx, wy, wz, x, y, z, alpha_x, alpha_y)]
    want = np.stack(np.broadcast_arrays(*parts), axis=-1)
    assert np.all(np.isfinite(got))
    np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-13)


# =========================================================================
# Chi-square goodness-of-fit
# =========================================================================


def _pdf_of_light_from_vndf(pdf_h_of):
    """Solid-angle pdf of l = reflect(wo, h) given the pdf of h as a function of (h, wo.h)."""

    def pdf(wo, x, y, z):
        hx, hy, hz = wo[0] + x, wo[1] + y, wo[2] + z
        length = np.sqrt(hx * hx + hy * hy + hz * hz)
        length = np.where(length > 0.0, length, 1.0)
        hx, hy, hz = hx / length, hy / length, hz / length
        voh = wo[0] * hx + wo[1] * hy + wo[2] * hz
        return s.pdf_light_from_half(pdf_h_of(hx, hy, hz, voh), voh)

    return pdf


def _sphere_cases():
    """(id, sampler(u) -> directions, pdf(x, y, z), theta edges where the pdf jumps)."""
    horizon = (math.pi / 2,)
    cases = [
        ("uniform_sphere", s.sample_uniform_sphere, lambda x, y, z: s.pdf_uniform_sphere(z), ()),
        ("uniform_hemisphere", s.sample_uniform_hemisphere, lambda x, y, z: s.pdf_uniform_hemisphere(z), horizon),
        ("cosine_hemisphere", s.sample_cosine_hemisphere, lambda x, y, z: s.pdf_cosine_hemisphere(z), horizon),
    ]
    for a in ALPHAS:
        cases += [
            (f"ggx_ndf-a{a}", lambda u, a=a: ggx.sample_ggx_ndf(u, a), lambda x, y, z, a=a: ggx.pdf_ggx_ndf(z, a),
             horizon),
            (f"beckmann_ndf-a{a}", lambda u, a=a: beckmann.sample_beckmann_ndf(u, a),
             lambda x, y, z, a=a: beckmann.pdf_beckmann_ndf(z, a), horizon),
            (f"gtr1_ndf-a{a}", lambda u, a=a: gtr.sample_gtr1_ndf(u, a), lambda x, y, z, a=a: gtr.pdf_gtr1_ndf(z, a),
             horizon),
        ]
    for ax, ay in ANISO_ALPHAS:
        cases.append((f"ggx_ndf_aniso-a{ax},{ay}", lambda u, ax=ax, ay=ay: ggx.sample_ggx_ndf_anisotropic(u, ax, ay),
                      lambda x, y, z, ax=ax, ay=ay: ggx.pdf_ggx_ndf_anisotropic(x, y, z, ax, ay), horizon))
    views = [(deg, _view(deg)) for deg in INCIDENT_DEGREES]
    for (ax, ay), (deg, wo) in [((a, a), v) for a in ALPHAS for v in views] + \
                               [(p, v) for p in ANISO_ALPHAS for v in views] + [((0.3, 0.3), (120, _view(120)))]:
        if ax == ay:
            tag = f"a{ax}-theta{deg}"

            def sample_h(u, wo=wo, a=ax):
                return ggx.sample_ggx_vndf(u, wo, a)

            def pdf_h(hx, hy, hz, voh, wo=wo, a=ax):
                return ggx.pdf_ggx_vndf(wo[2], hz, voh, a)
            kind = "ggx_vndf"
        else:
            tag = f"a{ax},{ay}-theta{deg}"

            def sample_h(u, wo=wo, ax=ax, ay=ay):
                return ggx.sample_ggx_vndf_anisotropic(u, wo, ax, ay)

            def pdf_h(hx, hy, hz, voh, wo=wo, ax=ax, ay=ay):
                return ggx.pdf_ggx_vndf_anisotropic(wo[0], wo[1], wo[2], hx, hy, hz, ax, ay)
            kind = "ggx_vndf_aniso"

        def pdf_h_xyz(x, y, z, wo=wo, pdf_h=pdf_h):
            return pdf_h(x, y, z, wo[0] * x + wo[1] * y + wo[2] * z)

        pdf_l = _pdf_of_light_from_vndf(pdf_h)
        cases.append((f"{kind}-{tag}", sample_h, pdf_h_xyz, horizon))
        if deg <= 90:
            # l = reflect(wo, h) with pdf D_wo(h) / (4 wo.h); h.z >= 0 bounds its support at l.z >= -wo.z
            cases.append((f"{kind}-light-{tag}", lambda u, wo=wo, f=sample_h: s.reflect(wo, f(u)),
                          lambda x, y, z, wo=wo, f=pdf_l: f(wo, x, y, z), (math.acos(-wo[2]),)))
    return cases


SPHERE_CASES = _sphere_cases()
NUM_CHI2_TESTS = len(SPHERE_CASES) + 1  # + the concentric disk
ALPHA_TEST = chi2.sidak_alpha(FAMILY_ALPHA, NUM_CHI2_TESTS)


def _u(case_id, n=N_SAMPLES):
    seed = zlib.crc32(case_id.encode())
    return np.random.default_rng([SEED, seed]).random((n, 2))


def _assert_fits(result, label):
    assert abs(result.total_probability - 1.0) < NORMALISATION_TOL, f"{label}: pdf does not integrate to 1: {result}"
    assert result.p_value > ALPHA_TEST, f"{label}: rejected at level {ALPHA_TEST:.2e}: {result}"


def test_sidak_level():
    assert NUM_CHI2_TESTS >= 50
    assert ALPHA_TEST == pytest.approx(1 - 0.99 ** (1 / NUM_CHI2_TESTS))
    assert 1 - (1 - ALPHA_TEST) ** NUM_CHI2_TESTS == pytest.approx(FAMILY_ALPHA)


@pytest.mark.parametrize("case_id, sampler, pdf, fixed_theta", SPHERE_CASES, ids=[c[0] for c in SPHERE_CASES])
def test_chi2_sphere(case_id, sampler, pdf, fixed_theta):
    directions = sampler(_u(case_id))
    result = chi2.sphere_chi2_test(directions, pdf, fixed_theta=fixed_theta)
    _assert_fits(result, case_id)


def test_chi2_concentric_disk():
    points = s.sample_concentric_disk(_u("concentric_disk"))
    _assert_fits(chi2.disk_chi2_test(points, s.pdf_concentric_disk), "concentric_disk")


# ------------------------------------------------- the test can fail


def test_chi2_rejects_wrong_pdfs():
    """Samples tested against a plausible but wrong pdf must be rejected, so the
    chi-square tests above can fail."""
    wo = _view(45)
    u = _u("wrong pdf")
    wrong = []
    h = ggx.sample_ggx_ndf(u, 0.3)
    wrong.append(("GGX samples vs Beckmann pdf", h, lambda x, y, z: beckmann.pdf_beckmann_ndf(z, 0.3), (math.pi / 2,)))
    wrong.append(("GGX alpha 0.3 vs pdf at alpha 0.33", h, lambda x, y, z: ggx.pdf_ggx_ndf(z, 0.33), (math.pi / 2,)))
    h = ggx.sample_ggx_vndf(u, wo, 0.3)
    wrong.append(("VNDF vs pdf with alpha * 1.1", h,
                  lambda x, y, z: ggx.pdf_ggx_vndf(wo[2], z, wo[0] * x + wo[1] * y + wo[2] * z, 0.33), (math.pi / 2,)))
    wrong.append(("VNDF vs the NDF pdf D cos", h, lambda x, y, z: ggx.pdf_ggx_ndf(z, 0.3), (math.pi / 2,)))
    l = s.reflect(wo, h)
    pdf_l = _pdf_of_light_from_vndf(lambda hx, hy, hz, voh: ggx.pdf_ggx_vndf(wo[2], hz, voh, 0.33))
    wrong.append(("VNDF light vs pdf with alpha * 1.1", l, lambda x, y, z: pdf_l(wo, x, y, z),
                  (math.acos(-wo[2]),)))
    h = ggx.sample_ggx_vndf_anisotropic(u, wo, 0.3, 0.05)
    wrong.append(("anisotropic VNDF vs swapped alphas", h,
                  lambda x, y, z: ggx.pdf_ggx_vndf_anisotropic(*wo, x, y, z, 0.05, 0.3), (math.pi / 2,)))
    for label, w, pdf, fixed in wrong:
        result = chi2.sphere_chi2_test(w, pdf, fixed_theta=fixed)
        assert abs(result.total_probability - 1.0) < NORMALISATION_TOL, label  # a normalised but wrong pdf
        assert result.p_value < ALPHA_TEST, f"{label} was not rejected: {result}"
    # samples outside the support of the pdf fail outright
    w = s.sample_uniform_sphere(u[:10_000])
    assert chi2.sphere_chi2_test(w, lambda x, y, z: s.pdf_uniform_hemisphere(z),
                                 fixed_theta=(math.pi / 2,)).p_value == 0.0
    # a pdf off by a constant factor fails the normalisation check even where the statistic alone is weak
    result = chi2.sphere_chi2_test(s.sample_cosine_hemisphere(u[:10_000]),
                                   lambda x, y, z: 1.002 * s.pdf_cosine_hemisphere(z), fixed_theta=(math.pi / 2,))
    assert abs(result.total_probability - 1.002) < 1e-6
    with pytest.raises(AssertionError, match="integrate to 1"):
        _assert_fits(result, "scaled cosine pdf")


def test_pearson_pooling():
    # cells below 5 expected are pooled into one bin before the statistic is formed
    statistic, dof, p = chi2.pearson_chi2([1, 2, 0, 100, 96, 101], [1.0, 2.0, 2.5, 100.0, 100.0, 95.5])
    assert statistic == pytest.approx((3 - 5.5) ** 2 / 5.5 + 0 + 16 / 100 + 5.5**2 / 95.5)
    assert dof == 3
    assert p == pytest.approx(stats.chi2.sf(statistic, 3))
    # a pool still under 5 takes in the next smallest cell
    statistic, dof, _ = chi2.pearson_chi2([1, 2, 0, 100, 96, 101], [1.0, 2.0, 1.5, 100.0, 100.0, 95.5])
    assert statistic == pytest.approx((104 - 100) ** 2 / 100 + 0 + 16 / 100)
    assert dof == 2
    assert chi2.pearson_chi2([1, 0], [0.0, 10.0])[2] == 0.0
