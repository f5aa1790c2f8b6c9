"""Tests of pbrkit.brdf.masking: Smith Lambda functions against their definition and
the weak white furnace, the visibility forms, and the Schlick approximations.

Independent references:

* The weak white furnace (Heitz 2014, "Understanding the Masking-Shadowing
  Function in Microfacet-Based BRDFs", JCGT 3(2), sec. 4.2 / eq. 18): the
  projected area of the visible microfacets is the projected area of the
  macro-surface, integral of G1(v, h) max(0, v.h) D(h) dh = n.v, which holds
  exactly for the Smith G1 = 1 / (1 + Lambda) of the matching D.  Dividing by
  n.v, it says that the distribution of visible normals
  D_v(h) = G1(v) max(0, v.h) D(h) / (n.v) (Heitz 2014, eq. 16) is normalised.
  Integrated with ``tests/support/quadrature.py``, cut exactly at v.h = 0.
* Smith's Lambda from its definition (Heitz 2014, sec. 5.3, after Smith 1967):
  Lambda(v) = (1 / mu) integral over q > mu of (q - mu) P2(q) dq with
  mu = cot theta_v and P2 the density of the microfacet slope projected on v's
  azimuth, evaluated here with SciPy's adaptive quadrature from the slope
  densities P22 written out in the test.
"""

from __future__ import annotations

import numpy as np
import pytest
from quadrature import half_vector_rule, theta_max_visible, view_direction
from scipy import integrate, special

from pbrkit.brdf import distributions as dist
from pbrkit.brdf import masking as m

FURNACE_TOL = 1e-5  # the issue asks for 1e-3; the quadrature gives ~1e-7 here
ANGLES = (0.0, 45.0, 80.0)


def _visible_rule(v, alpha_t, alpha_b=None):
    phi_v = float(np.arctan2(v[1], v[0]))
    return half_vector_rule(alpha_t, alpha_b, theta_max=theta_max_visible(v), phi_split=phi_v + 0.5 * np.pi)


def _view(theta_deg, phi=0.7):
    return view_direction(np.cos(np.radians(theta_deg)), phi)


# ------------------------------------------------------- VNDF / weak white furnace


@pytest.mark.parametrize("theta", ANGLES)
@pytest.mark.parametrize("alpha", [0.01, 0.05, 0.3, 1.0])
def test_ggx_vndf_is_normalised(alpha, theta):
    v = _view(theta)
    h, w = _visible_rule(v, alpha)
    g1 = m.g1_ggx(v[2], alpha)
    integral = np.sum(w * g1 * np.maximum(h @ v, 0.0) * dist.d_ggx(h[:, 2], alpha)) / v[2]
    assert abs(integral - 1.0) < FURNACE_TOL


@pytest.mark.parametrize("theta", ANGLES)
@pytest.mark.parametrize("alpha_t, alpha_b", [(0.05, 0.3), (0.3, 0.05), (1.0, 0.1), (0.02, 0.6)])
def test_anisotropic_ggx_vndf_is_normalised(alpha_t, alpha_b, theta):
    v = _view(theta)
    h, w = _visible_rule(v, alpha_t, alpha_b)
    lam = m.lambda_ggx_anisotropic(v[2], v[0], v[1], alpha_t, alpha_b)
    d = dist.d_ggx_anisotropic(h[:, 2], h[:, 0], h[:, 1], alpha_t, alpha_b)
    integral = np.sum(w * m.g1_smith(lam) * np.maximum(h @ v, 0.0) * d) / v[2]
    assert abs(integral - 1.0) < FURNACE_TOL


@pytest.mark.parametrize("theta", (0.0, 30.0, 60.0, 80.0, 89.0))
@pytest.mark.parametrize("alpha", [0.01, 0.1, 0.5, 1.0])
def test_weak_white_furnace_isotropic(alpha, theta):
    v = _view(theta)
    h, w = _visible_rule(v, alpha)
    voh = np.maximum(h @ v, 0.0)
    for d, g1 in ((dist.d_ggx(h[:, 2], alpha), m.g1_ggx(v[2], alpha)),
                  (dist.d_beckmann(h[:, 2], alpha), m.g1_beckmann(v[2], alpha))):
        assert abs(np.sum(w * g1 * voh * d) - v[2]) < FURNACE_TOL * v[2]


@pytest.mark.parametrize("theta", (0.0, 45.0, 80.0, 89.0))
@pytest.mark.parametrize("alpha_t, alpha_b", [(0.05, 0.4), (0.5, 0.1), (1.0, 0.3)])
def test_weak_white_furnace_anisotropic(alpha_t, alpha_b, theta):
    v = _view(theta)
    h, w = _visible_rule(v, alpha_t, alpha_b)
    voh = np.maximum(h @ v, 0.0)
    cases = ((dist.d_ggx_anisotropic, m.lambda_ggx_anisotropic),
             (dist.d_beckmann_anisotropic, m.lambda_beckmann_anisotropic))
    for d_fn, lambda_fn in cases:
        d = d_fn(h[:, 2], h[:, 0], h[:, 1], alpha_t, alpha_b)
        g1 = m.g1_smith(lambda_fn(v[2], v[0], v[1], alpha_t, alpha_b))
        assert abs(np.sum(w * g1 * voh * d) - v[2]) < FURNACE_TOL * v[2]


def test_blinn_phong_with_beckmann_lambda_is_an_approximation():
    """Walter et al. 2007 (sec. 5.2) use Beckmann's G1 for Blinn-Phong with
    alpha = sqrt(2 / (e + 2)), as ``cook_torrance(distribution="blinn-phong")``
    does.  That Lambda is not Smith's for the Blinn-Phong D, so the weak furnace
    holds only approximately: measured relative errors (quadrature), printed,
    are ~5e-4 at alpha = 0.05 but reach 0.75 at alpha = 1 and 89 degrees.
    Asserted: within 3e-3 for alpha <= 0.1 and every angle up to 89 degrees, and
    a clear violation (> 0.1) at alpha = 1, 45 degrees, so the documented
    limitation stays visible."""
    errors = {}
    for alpha in (0.05, 0.1, 0.3, 1.0):
        e = 2.0 / alpha**2 - 2.0
        for theta in (0.0, 45.0, 80.0, 89.0):
            v = _view(theta)
            h, w = _visible_rule(v, alpha)
            value = np.sum(w * m.g1_beckmann(v[2], alpha) * np.maximum(h @ v, 0.0) * dist.d_blinn_phong(h[:, 2], e))
            errors[alpha, theta] = value / v[2] - 1.0
    print("Blinn-Phong + Beckmann Lambda weak-furnace relative error:",
          {k: round(float(x), 5) for k, x in errors.items()})
    assert max(abs(x) for (alpha, _), x in errors.items() if alpha <= 0.1) < 3e-3
    assert errors[1.0, 45.0] > 0.1


# ------------------------------------------------------- Lambda from its definition


def _lambda_from_definition(p22, theta, phi):
    """(1 / mu) integral_{q > mu} (q - mu) P2(q) dq, P2(q) = integral P22 along the
    slope axis perpendicular to azimuth phi (Heitz 2014, sec. 5.3), by SciPy quad."""
    mu = 1.0 / np.tan(theta)
    c, s = np.cos(phi), np.sin(phi)

    def p2(q):
        return integrate.quad(lambda p: p22(q * c - p * s, q * s + p * c), -np.inf, np.inf,
                              epsabs=1e-13, epsrel=1e-11, limit=200)[0]

    value = integrate.quad(lambda q: (q - mu) * p2(q), mu, np.inf, epsabs=1e-13, epsrel=1e-10, limit=200)[0]
    return value / mu


def _p22_ggx(ax, ay):
    return lambda x, y: 1.0 / (np.pi * ax * ay * (1.0 + (x / ax) ** 2 + (y / ay) ** 2) ** 2)


def _p22_beckmann(ax, ay):
    return lambda x, y: np.exp(-(x / ax) ** 2 - (y / ay) ** 2) / (np.pi * ax * ay)


@pytest.mark.parametrize("alpha, theta_deg", [(0.1, 30.0), (0.1, 85.0), (0.5, 60.0), (1.0, 20.0), (1.0, 80.0)])
def test_isotropic_lambdas_match_their_definition(alpha, theta_deg):
    theta = np.radians(theta_deg)
    nov = np.cos(theta)
    ggx = _lambda_from_definition(_p22_ggx(alpha, alpha), theta, 0.0)
    beckmann = _lambda_from_definition(_p22_beckmann(alpha, alpha), theta, 0.0)
    assert m.lambda_ggx(nov, alpha) == pytest.approx(ggx, rel=1e-7, abs=1e-12)
    assert m.lambda_beckmann(nov, alpha) == pytest.approx(beckmann, rel=1e-7, abs=1e-12)


@pytest.mark.parametrize("alpha_t, alpha_b, theta_deg, phi",
                         [(0.1, 0.6, 60.0, 0.3), (0.8, 0.2, 70.0, 1.2), (0.4, 0.05, 85.0, 2.5)])
def test_anisotropic_lambdas_match_their_definition(alpha_t, alpha_b, theta_deg, phi):
    """Also fixes the orientation: alpha_t belongs to the tangent (x) axis."""
    theta = np.radians(theta_deg)
    v = view_direction(np.cos(theta), phi)
    ggx = _lambda_from_definition(_p22_ggx(alpha_t, alpha_b), theta, phi)
    beckmann = _lambda_from_definition(_p22_beckmann(alpha_t, alpha_b), theta, phi)
    assert m.lambda_ggx_anisotropic(v[2], v[0], v[1], alpha_t, alpha_b) == pytest.approx(ggx, rel=1e-7, abs=1e-12)
    assert m.lambda_beckmann_anisotropic(v[2], v[0], v[1], alpha_t, alpha_b) == pytest.approx(
        beckmann, rel=1e-7, abs=1e-12)


def test_anisotropic_lambdas_reduce_to_isotropic():
    rng = np.random.default_rng(3)
    theta = rng.uniform(0.0, 1.55, 200)
    phi = rng.uniform(0.0, 2.0 * np.pi, 200)
    v = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1)
    for alpha in (0.01, 0.3, 1.0):
        np.testing.assert_allclose(m.lambda_ggx_anisotropic(v[:, 2], v[:, 0], v[:, 1], alpha, alpha),
                                   m.lambda_ggx(v[:, 2], alpha), rtol=1e-9, atol=1e-15)
        np.testing.assert_allclose(m.lambda_beckmann_anisotropic(v[:, 2], v[:, 0], v[:, 1], alpha, alpha),
                                   m.lambda_beckmann(v[:, 2], alpha), rtol=1e-9, atol=1e-15)


# ------------------------------------------------------- closed-form anchors


def test_ggx_alpha_1_closed_forms():
    """At alpha = 1 GGX is uniform and Lambda = (1 / mu - 1) / 2 (Heitz 2014, eq. 72),
    so G1 = 2 mu / (1 + mu), the height-correlated G2 = 2 mu_l mu_v / (mu_l + mu_v)
    and V = G2 / (4 mu_l mu_v) = 1 / (2 (mu_l + mu_v))."""
    mu = np.linspace(0.01, 1.0, 100)
    np.testing.assert_allclose(m.lambda_ggx(mu, 1.0), 0.5 * (1.0 / mu - 1.0), rtol=1e-12)
    np.testing.assert_allclose(m.g1_ggx(mu, 1.0), 2.0 * mu / (1.0 + mu), rtol=1e-12)
    mu_l, mu_v = np.meshgrid(mu, mu[::7])
    np.testing.assert_allclose(m.v_smith_ggx_height_correlated(mu_l, mu_v, 1.0), 0.5 / (mu_l + mu_v), rtol=1e-12)


def test_beckmann_lambda_closed_form():
    """Heitz 2014, eq. 83 with a = 1 / (alpha tan theta), checked with SciPy's erf;
    and against Walter et al. 2007's independent rational fit of the Beckmann G1
    (eq. 27), whose measured max deviation from the exact G1 is 3.1e-3."""
    theta = np.linspace(0.01, 1.56, 200)
    for alpha in (0.05, 0.3, 1.0):
        a = 1.0 / (alpha * np.tan(theta))
        expected = 0.5 * (special.erf(a) - 1.0) + np.exp(-a * a) / (2.0 * a * np.sqrt(np.pi))
        np.testing.assert_allclose(m.lambda_beckmann(np.cos(theta), alpha), expected, rtol=1e-9, atol=1e-13)
        walter = np.where(a < 1.6, (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a), 1.0)
        assert np.max(np.abs(m.g1_beckmann(np.cos(theta), alpha) - walter)) < 5e-3


def test_erf_matches_scipy():
    x = np.linspace(-6.0, 6.0, 1001)
    np.testing.assert_allclose(m.erf(x), special.erf(x), rtol=1e-14, atol=1e-16)


def test_g1_limits_and_range():
    mu = np.concatenate([[0.0, 1e-12, 1e-6], np.linspace(0.001, 1.0, 400)])
    for alpha in (1e-3, 0.01, 0.2, 1.0):
        for g1 in (m.g1_ggx, m.g1_beckmann):
            g = g1(mu, alpha)
            assert np.all(np.isfinite(g)) and np.all(g >= 0.0) and np.all(g <= 1.0)
            assert g1(1.0, alpha) == 1.0  # tan theta = 0: nothing masks at normal incidence
            assert g[0] == 0.0
            assert np.all(np.diff(g[3:]) >= -1e-15)  # more masking toward grazing
            assert g1(-0.3, alpha) == 0.0
    # Small alpha: a mirror masks nothing except at grazing incidence.
    assert m.g1_ggx(0.5, 1e-3) > 1.0 - 1e-5
    assert m.g1_beckmann(0.5, 1e-3) == 1.0


def test_g2_forms():
    rng = np.random.default_rng(4)
    lam_l, lam_v = rng.exponential(size=(2, 500))
    hc = m.g2_height_correlated(lam_l, lam_v)
    sep = m.g2_separable(lam_l, lam_v)
    assert np.all(hc >= sep - 1e-15)  # 1 + a + b <= (1 + a)(1 + b)
    assert np.all(hc <= np.minimum(m.g1_smith(lam_l), m.g1_smith(lam_v)) + 1e-15)
    np.testing.assert_allclose(m.g2_height_correlated(0.0, lam_v), m.g1_smith(lam_v), rtol=1e-15)
    np.testing.assert_allclose(m.g2_separable(0.0, lam_v), m.g1_smith(lam_v), rtol=1e-15)
    np.testing.assert_allclose(sep, 1.0 / ((1.0 + lam_l) * (1.0 + lam_v)), rtol=1e-14)


def test_v_smith_ggx_height_correlated_equals_visibility_of_g2():
    rng = np.random.default_rng(5)
    nol, nov = rng.uniform(1e-4, 1.0, size=(2, 2000))
    for alpha in (1e-3, 0.05, 0.3, 0.7, 1.0):
        g2 = m.g2_height_correlated(m.lambda_ggx(nol, alpha), m.lambda_ggx(nov, alpha))
        np.testing.assert_allclose(m.v_smith_ggx_height_correlated(nol, nov, alpha),
                                   m.visibility(g2, nol, nov), rtol=1e-10)
    assert m.v_smith_ggx_height_correlated(0.0, 0.5, 0.3) == 0.0
    assert m.v_smith_ggx_height_correlated(0.5, -0.1, 0.3) == 0.0
    assert np.isfinite(m.v_smith_ggx_height_correlated(1e-9, 1e-9, 1e-3))


def test_visibility_definition():
    assert m.visibility(0.8, 0.5, 0.25) == pytest.approx(0.8 / (4 * 0.5 * 0.25), rel=1e-15)
    assert m.visibility(0.8, 0.0, 0.25) == 0.0
    assert m.visibility(0.8, 0.5, -0.25) == 0.0


# ------------------------------------------------------- Schlick-GGX and remaps


def test_roughness_remaps_for_k():
    r = np.linspace(0.0, 1.0, 101)
    np.testing.assert_allclose(m.k_ue4_direct(r), (r + 1.0) ** 2 / 8.0, rtol=1e-14)
    np.testing.assert_allclose(m.k_ue4_ibl(r), r * r / 2.0, rtol=1e-14, atol=0)
    np.testing.assert_allclose(m.alpha_g_disney(r), (0.5 + 0.5 * r) ** 2, rtol=1e-14)
    np.testing.assert_allclose(m.k_schlick_from_alpha(r), r / 2.0, rtol=1e-15)


def test_schlick_ggx_against_smith():
    """Schlick-GGX with k = alpha / 2 (Karis 2013) against the exact Smith G1.

    Measured (printed) max |error| over mu in (0, 1]: 0.163 (alpha -> 0, near
    grazing), 0.140 (alpha = 0.1), 0.100 (0.3), 0.066 (0.5), 0.024 (0.8) and 0 at
    alpha = 1, where both are 2 mu / (1 + mu) exactly.  Schlick-GGX never exceeds
    Smith (error <= 0).  Asserted: those bounds with a small margin, and the
    error under 0.075 for mu >= 0.5."""
    mu = np.linspace(1e-6, 1.0, 20001)
    worst = {}
    for alpha in (1e-3, 0.01, 0.1, 0.3, 0.5, 0.8, 1.0):
        err = m.g1_schlick_ggx(mu, m.k_schlick_from_alpha(alpha)) - m.g1_ggx(mu, alpha)
        worst[alpha] = float(np.max(np.abs(err)))
        assert np.all(err <= 1e-14)
        assert np.max(np.abs(err[mu >= 0.5])) < 0.075
    print("max |Schlick-GGX(k = alpha/2) - Smith G1| per alpha:", {a: round(e, 4) for a, e in worst.items()})
    assert max(worst.values()) < 0.165
    assert worst[1.0] < 1e-14
    assert worst[0.5] < 0.07


def test_schlick_ggx_forms():
    mu = np.linspace(0.0, 1.0, 101)
    np.testing.assert_allclose(m.g1_schlick_ggx(mu[1:], 0.0), 1.0, rtol=1e-15)
    assert m.g1_schlick_ggx(1.0, 0.37) == pytest.approx(1.0, rel=1e-15)
    assert m.g1_schlick_ggx(0.0, 0.37) == 0.0
    assert m.g1_schlick_ggx(-0.2, 0.37) == 0.0
    np.testing.assert_allclose(m.g1_schlick_ggx(mu, 0.25), np.where(mu > 0, mu / (0.75 * mu + 0.25), 0.0))
    np.testing.assert_allclose(m.g2_schlick_ggx(mu, mu[::-1], 0.25),
                               m.g1_schlick_ggx(mu, 0.25) * m.g1_schlick_ggx(mu[::-1], 0.25), rtol=1e-15)


def test_kelemen_and_neubelt():
    """Kelemen & Szirmay-Kalos 2001: G2 / (4 n.l n.v) = 1 / (4 (v.h)^2);
    Neubelt & Pettineo 2013: V = 1 / (4 (n.l + n.v - n.l n.v))."""
    rng = np.random.default_rng(6)
    nol, nov, voh = rng.uniform(0.01, 1.0, size=(3, 500))
    np.testing.assert_allclose(m.visibility(m.g2_kelemen(nol, nov, voh), nol, nov), m.v_kelemen(voh), rtol=1e-12)
    np.testing.assert_allclose(m.v_kelemen(voh), 0.25 / voh**2, rtol=1e-15)
    np.testing.assert_allclose(m.v_neubelt(nol, nov), 0.25 / (nol + nov - nol * nov), rtol=1e-15)
    assert m.v_neubelt(1.0, 1.0) == 0.25
    assert m.g2_kelemen(0.0, 0.5, 0.5) == 0.0
    assert m.v_neubelt(0.0, 0.5) == 0.0
