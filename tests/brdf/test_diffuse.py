"""Tests of pbrkit.brdf.diffuse: Lambert and Burley (Disney) diffuse against closed
forms and quadrature (``tests/support/quadrature.py``).

Burley's albedo at normal view (v = n) has a closed form: there l.h =
cos(theta_l / 2), so F_D90 = 0.5 + 2 r cos^2(theta_l / 2) = 0.5 + r (1 + mu_l)
and the albedo is 2 integral_0^1 mu (1 + (F_D90 - 1)(1 - mu)^5) d mu, with
Beta integrals B(2, 6) = 1/42 and B(3, 6) = 1/168: 1 - 1/42 at r = 0 and
1 + 1/28 at r = 1 (derived in the test docstrings).
"""

from __future__ import annotations

import numpy as np
import pytest
from quadrature import hemisphere_rule, view_direction

from pbrkit.brdf import diffuse


def _albedo(factor_of_l, n_mu=96, n_phi=64):
    d, w = hemisphere_rule(n_mu, n_phi)
    return float(np.sum(w * factor_of_l(d) * d[:, 2]))


def test_lambert_white_furnace():
    assert _albedo(lambda l: diffuse.lambert(l[:, 2])) == pytest.approx(1.0, abs=1e-12)
    assert diffuse.lambert(0.3) == pytest.approx(1.0 / np.pi, rel=1e-15)
    assert diffuse.lambert(0.0) == 0.0 and diffuse.lambert(-0.2) == 0.0


def _burley_of(v, roughness):
    def factor(l):
        h = l + v
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        return diffuse.burley(l[:, 2], v[2], np.sum(l * h, axis=-1), roughness)

    return factor


def test_burley_known_values():
    """l = v = n: both Schlick factors are 1, f = 1 / pi for every roughness;
    r = 0, grazing light and normal view: f = F_D90 / pi = 0.5 / pi;
    both grazing: F_D90^2 / pi."""
    for r in (0.0, 0.5, 1.0):
        assert diffuse.burley(1.0, 1.0, 1.0, r) == pytest.approx(1.0 / np.pi, rel=1e-15)
    assert diffuse.burley(0.0, 1.0, np.sqrt(0.5), 0.0) == pytest.approx(0.5 / np.pi, rel=1e-15)
    # l.h = cos theta_d; F_D90 = 0.5 + 2 r cos^2 theta_d.
    r, loh = 0.8, 0.6
    fd90 = 0.5 + 2.0 * r * loh * loh
    assert diffuse.burley(0.0, 0.0, loh, r) == pytest.approx(fd90 * fd90 / np.pi, rel=1e-14)
    nol, nov = 0.3, 0.7
    expected = (1 + (fd90 - 1) * (1 - nol) ** 5) * (1 + (fd90 - 1) * (1 - nov) ** 5) / np.pi
    assert diffuse.burley(nol, nov, loh, r) == pytest.approx(expected, rel=1e-14)


def test_burley_albedo_closed_forms_at_normal_view():
    """r = 0: F_D90 = 0.5, albedo = 2 int mu (1 - (1 - mu)^5 / 2) = 1 - B(2, 6) = 1 - 1/42.
    r = 1: F_D90 - 1 = 0.5 + mu, albedo = 1 + 2 (B(2, 6) / 2 + B(3, 6)) = 1 + 1/28."""
    v = view_direction(1.0)
    assert _albedo(_burley_of(v, 0.0)) == pytest.approx(1.0 - 1.0 / 42.0, abs=1e-12)
    assert _albedo(_burley_of(v, 1.0)) == pytest.approx(1.0 + 1.0 / 28.0, abs=1e-12)


def test_burley_is_reciprocal_and_bounded():
    rng = np.random.default_rng(7)
    nol, nov, loh = rng.uniform(0.0, 1.0, size=(3, 1000))
    r = rng.uniform(0.0, 1.0, 1000)
    np.testing.assert_allclose(diffuse.burley(nol, nov, loh, r), diffuse.burley(nov, nol, loh, r), rtol=1e-14)
    f = diffuse.burley(nol, nov, loh, r)
    fd90 = 0.5 + 2.0 * r * loh * loh
    # Each Schlick factor lies between 1 and F_D90.
    lo = np.minimum(1.0, fd90) ** 2 / np.pi
    hi = np.maximum(1.0, fd90) ** 2 / np.pi
    assert np.all(f >= lo * (1 - 1e-14)) and np.all(f <= hi * (1 + 1e-14))
