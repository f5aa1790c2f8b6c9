"""The half-vector domain shared by the white furnace and the lookup tables
(pbrkit.core.quadrature).

Independent references: the GGX NDF's cumulative distribution in theta_h by
SciPy quadrature of D(h) (n.h) over the cap (Walter et al. 2007, eq. 33
typed here), the mirror reflection l = 2 (v.h) h - v written out here (its
height above the horizon at the bounds), and exact integrals of monomials
and of s e^-s.
"""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest
from scipy import integrate

from pbrkit.core.quadrature import (
    gauss_legendre_01,
    ggx_cos_of_s,
    ggx_s_of_cos,
    horizon_limits,
    horizon_phi_max,
    split_node,
)


def _ggx(theta_h, alpha):
    """D = alpha^2 / (pi (alpha^2 cos^2 + sin^2)^2) (Walter et al. 2007, eq. 33, without cancellation)."""
    a2 = alpha * alpha
    return a2 / (np.pi * (a2 * np.cos(theta_h) ** 2 + np.sin(theta_h) ** 2) ** 2)


def _reflected_height(mu, theta_h, phi):
    """n.l of l = 2 (v.h) h - v with v = (sin theta_v, 0, mu), h at (theta_h, phi)."""
    sv = math.sqrt(1.0 - mu * mu)
    h = np.array([math.sin(theta_h) * math.cos(phi), math.sin(theta_h) * math.sin(phi), math.cos(theta_h)])
    v = np.array([sv, 0.0, mu])
    return 2.0 * (v @ h) * h[2] - mu


@pytest.mark.parametrize("n", [1, 3, 8, 24])
def test_gauss_legendre_01_integrates_polynomials_exactly(n):
    x, w = gauss_legendre_01(n)
    assert np.all((x > 0) & (x < 1))
    for k in range(2 * n):
        assert np.dot(w, x ** k) == pytest.approx(1.0 / (k + 1), rel=1e-13)


@pytest.mark.parametrize("alpha", [1e-3, 0.05, 0.3, 1.0])
def test_node_variable_is_minus_log_of_one_minus_the_ggx_cdf(alpha):
    def density(t):  # of theta_h: D(h) (n.h) sin theta_h 2 pi
        return 2 * np.pi * _ggx(t, alpha) * np.cos(t) * np.sin(t)

    for theta in (0.1 * alpha, alpha, 0.7, 1.2, 1.5):
        u, _ = integrate.quad(density, 0.0, theta, points=[min(alpha, theta)], epsabs=0, epsrel=1e-13, limit=200)
        if u < 0.5:
            expected = -math.log1p(-u)
        else:  # 1 - u from the tail, without cancellation
            tail, _ = integrate.quad(density, theta, 0.5 * math.pi, epsabs=0, epsrel=1e-13, limit=200)
            expected = -math.log(tail)
        # 1 - cos^2 theta carries the rounding of cos theta: relative error ~ 1e-16 / sin^2 theta
        rel = max(1e-10, 4e-16 / math.sin(theta) ** 2)
        assert ggx_s_of_cos(math.cos(theta), alpha) == pytest.approx(expected, rel=rel)


@pytest.mark.parametrize("alpha", [1e-3, 0.05, 0.3, 1.0])
def test_node_variable_round_trip(alpha):
    c = np.linspace(1e-3, 1.0, 400)
    s = ggx_s_of_cos(c, alpha)
    cos_h, sin_h, x = ggx_cos_of_s(s, alpha)
    assert np.allclose(cos_h, c, rtol=1e-12, atol=0)
    assert np.allclose(sin_h, np.sqrt(1 - c * c), rtol=1e-10, atol=1e-15)
    assert np.allclose(x, (1 - c * c) / (c * c) / alpha ** 2, rtol=1e-11)
    assert np.all(np.diff(s) < 0)  # s grows towards the horizon


@pytest.mark.parametrize("mu", [0.02, 0.3, 0.8, 0.999])
def test_horizon_bounds_put_the_reflection_on_the_horizon(mu):
    sin_v, cos_a, cos_b = horizon_limits(mu)
    assert sin_v == pytest.approx(math.sqrt(1 - mu * mu), rel=1e-14)
    theta_a, theta_b = math.acos(cos_a), math.acos(cos_b)
    assert _reflected_height(mu, theta_a, math.pi) == pytest.approx(0.0, abs=1e-14)  # worst azimuth
    assert _reflected_height(mu, theta_b, 0.0) == pytest.approx(0.0, abs=1e-14)  # best azimuth
    for theta_h in np.linspace(theta_a, theta_b, 9)[1:-1]:
        pm = horizon_phi_max(mu, sin_v, math.cos(theta_h), math.sin(theta_h))
        assert 0.0 < pm < math.pi
        assert _reflected_height(mu, theta_h, pm) == pytest.approx(0.0, abs=1e-13)
        assert _reflected_height(mu, theta_h, 0.99 * pm) > 0.0
        assert _reflected_height(mu, theta_h, min(math.pi, 1.01 * pm)) < 0.0
    assert horizon_phi_max(mu, sin_v, math.cos(0.9 * theta_a), math.sin(0.9 * theta_a)) == math.pi
    beyond = 0.5 * (theta_b + math.pi / 2)
    assert horizon_phi_max(mu, sin_v, math.cos(beyond), math.sin(beyond)) == 0.0
    # normal incidence (sin theta_v = 0): every azimuth or none
    assert horizon_phi_max(1.0, 0.0, math.cos(0.3), math.sin(0.3)) == math.pi
    assert horizon_phi_max(1.0, 0.0, math.cos(1.0), math.sin(1.0)) == 0.0


def test_split_nodes_integrate_over_both_segments():
    x, w = gauss_legendre_01(16)
    total = 0.0
    for segment in (0, 1):
        s, ds = split_node(segment, x, w, 2.0, 5.0)
        assert np.all((s >= 2.0 * segment) & (s <= 2.0 + 3.0 * segment))
        total += np.sum(s * np.exp(-s) * ds)
    assert total == pytest.approx(1.0 - 6.0 * math.exp(-5.0), rel=1e-12)


@numba.njit
def _compiled(mu, alpha, c, s, out):
    for k in range(mu.shape[0]):
        sin_v, cos_a, cos_b = horizon_limits(mu[k])
        cos_h, sin_h, x = ggx_cos_of_s(s[k], alpha[k])
        node, weight = split_node(k % 2, 0.3, 0.2, 1.5, 4.0)
        values = (sin_v, cos_a, cos_b, ggx_s_of_cos(c[k], alpha[k]), cos_h, sin_h, x,
                  horizon_phi_max(mu[k], sin_v, cos_h, sin_h), node, weight)
        for j in range(10):
            out[k, j] = values[j]


def test_compiled_and_numpy_agree():
    rng = np.random.default_rng(2)
    n = 300
    mu, alpha, c, s = rng.uniform(0.01, 1, n), rng.uniform(1e-3, 1, n), rng.uniform(0.01, 1, n), rng.uniform(0, 12, n)
    out = np.zeros((n, 10), dtype=np.float64)
    _compiled(mu, alpha, c, s, out)
    sin_v, cos_a, cos_b = horizon_limits(mu)
    cos_h, sin_h, x = ggx_cos_of_s(s, alpha)
    nodes = [split_node(k % 2, 0.3, 0.2, 1.5, 4.0) for k in range(n)]
    ref = np.stack([sin_v, cos_a, cos_b, ggx_s_of_cos(c, alpha), cos_h, sin_h, x,
                    horizon_phi_max(mu, sin_v, cos_h, sin_h), [a for a, _ in nodes], [b for _, b in nodes]], axis=1)
    assert np.allclose(out, ref, rtol=1e-13, atol=1e-15)
