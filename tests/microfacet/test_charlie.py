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
import numba
import numpy as np
import pytest
from quadrature import graded_gauss_legendre
from scipy import integrate
from sheen_reference import reference_sheen_albedo, spec_d, spec_lambda, spec_visibility

from pbrkit.microfacet.charlie import (d_charlie, g2_charlie, lambda_charlie, pdf_charlie_ndf, sample_charlie,
                                      v_ashikhmin, v_charlie)

SEED = 20261127
#: sheenRoughness values and their alpha = sheenRoughness^2 (KHR_materials_sheen)
ROUGHNESSES = (0.1, 0.3, 0.5, 0.7, 1.0)


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


# ------------------------------------------------------- the sheen lobe and E_sheen

from pbrkit.brdf.bxdf import EXTRA_SLOTS, BxDF, local_cosines  # noqa: E402
from pbrkit.brdf.lobes.diffuse import LAMBERT  # noqa: E402
from pbrkit.brdf.lobes.sheen import (SHEEN, SHEEN_COLOR_SLOT, SHEEN_ROUGHNESS_SLOT, SHEEN_TABLE_FILE,  # noqa: E402
                                     sheen_albedo, sheen_albedo_lookup, sheen_albedo_scaling, sheen_albedo_table)
from pbrkit.brdf.operators import add, compose, layer  # noqa: E402

SHEEN_COLOR = (0.9, 0.6, 0.3)


def sheen_bxdf(sheen_roughness, sheen_color=SHEEN_COLOR, diffuse=(1.0, 1.0, 1.0)):
    """A BxDF with a white (by default) diffuse colour and the sheen lobe's slots."""
    z3 = (0.0, 0.0, 0.0)
    extra = [0.0] * EXTRA_SLOTS
    extra[SHEEN_COLOR_SLOT:SHEEN_COLOR_SLOT + 3] = sheen_color
    extra[SHEEN_ROUGHNESS_SLOT] = sheen_roughness
    return BxDF(0, 0, 0, 0, 0, 0.5, 0.25, 0.25, 0.25, False, 0.0, 0.0, diffuse, diffuse, z3, 1.0, z3, z3, 0.04, z3,
                tuple(extra))


def test_reference_albedo_against_scipy():
    for (mu, r), expected in (((0.5, 0.5), 0.18785393), ((0.05, 0.3), 0.70639074), ((0.2, 0.8), 0.55278622)):
        assert reference_sheen_albedo(mu, r) == pytest.approx(expected, rel=2e-6)


CASES = [(mu, r) for mu in (0.03, 0.1, 0.3, 0.6, 0.95) for r in (0.15, 0.4, 0.7, 1.0)]


def test_sheen_albedo_against_independent_quadrature():
    """The lobe's half-vector quadrature (D cancelled in the CDF variable) against the
    direct one over the light direction: 1e-5 relative (both converge far beyond)."""
    for mu, r in CASES:
        assert sheen_albedo(mu, r) == pytest.approx(reference_sheen_albedo(mu, r), rel=1e-5, abs=1e-9), (mu, r)


def test_stored_table_is_the_table_function_and_lookup_is_close():
    """The baked pbrkit/data/sheen_albedo.npy is sheen_albedo_table() (bit for bit up to
    rounding), and its bilinear lookup stays within 0.02 of E off the nodes over
    n.v >= 0.1 (E is steep towards grazing: see the module notes)."""
    stored = np.load(SHEEN_TABLE_FILE)
    np.testing.assert_allclose(stored, sheen_albedo_table(), rtol=1e-12, atol=1e-15)
    for mu in np.linspace(0.1, 0.99, 7) + 0.0123:
        for r in np.linspace(0.1, 0.99, 7) + 0.0071:
            mu_, r_ = min(mu, 1.0), min(r, 1.0)
            assert abs(sheen_albedo_lookup(mu_, r_) - sheen_albedo(mu_, r_)) < 0.02, (mu_, r_)


def test_spec_albedo_exceeds_one_at_grazing_for_small_roughness():
    """A property of the specification's fitted Lambda, recorded: E_sheen > 1 near
    grazing for small sheen roughness (the fit is not the Smith Lambda of D there)."""
    assert reference_sheen_albedo(0.01, 0.2) > 1.1
    assert sheen_albedo(0.01, 0.2) == pytest.approx(reference_sheen_albedo(0.01, 0.2), rel=1e-4)


def test_sheen_lobe_value_and_albedo():
    """SHEEN.value = sheenColor D V against the spec transcription; SHEEN.albedo =
    sheenColor E (table); sheen_albedo_scaling = 1 - max3(sheenColor) E."""
    rng = np.random.default_rng(SEED)
    for r in (0.2, 0.6, 1.0):
        b = sheen_bxdf(r)
        for _ in range(20):
            v = rng.normal(size=3)
            l = rng.normal(size=3)
            v[2], l[2] = abs(v[2]), abs(l[2])
            v /= np.linalg.norm(v)
            l /= np.linalg.norm(l)
            c = local_cosines(*v, *l)
            h = (v + l) / np.linalg.norm(v + l)
            expected = np.array(SHEEN_COLOR) * spec_d(h[2], r) * spec_visibility(l[2], v[2], r)
            np.testing.assert_allclose(SHEEN.value(b, c, (1.0, 1.0, 1.0), 0.5), 0.5 * expected, rtol=1e-10)
        e = sheen_albedo_lookup(0.4, r)
        np.testing.assert_allclose(SHEEN.albedo(b, 0.4), np.array(SHEEN_COLOR) * e, rtol=1e-12)
        assert sheen_albedo_scaling(max(SHEEN_COLOR), 0.4, r) == pytest.approx(1.0 - 0.9 * e, rel=1e-12)


def _composed_albedo(value, b, mu):
    """Directional albedo (RGB) of a composed value by the test's light-direction rule
    (a compiled loop over the nodes)."""
    ct, wt = graded_gauss_legendre(0.0, 1.0, 24, 24, grade=2.0)
    ph, wp = graded_gauss_legendre(0.0, np.pi, 24, 16)
    return _albedo_loop(value)(b, math.sqrt(1.0 - mu * mu), mu, ct, wt, ph, wp)


_LOOPS = {}


def _albedo_loop(value):
    if value not in _LOOPS:
        @numba.njit
        def loop(b, sv, mu, ct, wt, ph, wp):
            total = np.zeros(3)
            for i in range(ct.size):
                st = math.sqrt(1.0 - ct[i] * ct[i])
                for j in range(ph.size):
                    c = local_cosines(sv, 0.0, mu, st * math.cos(ph[j]), st * math.sin(ph[j]), ct[i])
                    f = value(b, c, (1.0, 1.0, 1.0))
                    k = 2.0 * ct[i] * wt[i] * wp[j]
                    for a in range(3):
                        total[a] += f[a] * k
            return total

        _LOOPS[value] = loop
    return _LOOPS[value]


@pytest.mark.parametrize("r", (0.3, 0.7))
def test_sheen_layer_over_white_lambert_keeps_the_furnace(r):
    """layer(SHEEN, LAMBERT) is the spec's albedo scaling (f = sheenColor f_sheen +
    (1 - max3(sheenColor) E(n.v)) f_base); over a white Lambert its albedo is
    sheenColor E + 1 - max3(sheenColor) E_table <= 1 + (table error), and 1 in the
    channel of max3; without the scaling (plain add) it exceeds 1 -- the test can fail."""
    composed = compose(layer(SHEEN, LAMBERT))
    b = sheen_bxdf(r)
    for mu in (0.2, 0.5, 0.9):
        e = _composed_albedo(composed.value, b, mu)
        assert np.all(e <= 1.0 + 0.01), (mu, e)
        assert e[0] == pytest.approx(1.0, abs=0.01)
        assert np.all(e > 0.0)
    unscaled = compose(add(SHEEN, LAMBERT))
    assert _composed_albedo(unscaled.value, b, 0.5)[0] > 1.0 + 0.5 * sheen_albedo(0.5, r)
