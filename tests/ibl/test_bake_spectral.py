"""Building blocks of the bake: level <-> roughness mapping, the GGX lobe
normalisation and its Funk-Hecke coefficients, the spherical-harmonic
transform (pbrkit.ibl.spectral), highlight splitting and the irradiance kernel.

Independent references: SciPy quadrature and its real spherical harmonics,
the clamped-cosine coefficients of Ramamoorthi & Hanrahan 2001 (eq. 9),
pbrkit.ibl.sh (tested on its own) for degree <= 2, and brute-force sums written
out here with the GGX formula typed from Walter et al. 2007, eq. 33.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate
from scipy.special import eval_legendre, sph_harm_y

from pbrkit.ibl import prefilter as pf
from pbrkit.ibl import spectral as sp
from pbrkit.ibl.equirect import (
    equirect_directions,
    equirect_integral,
    equirect_solid_angles,
)
from pbrkit.ibl.irradiance import cosine_zonal_coefficients, irradiance_reference
from pbrkit.ibl.sh import eval_sh, project_equirect


def ggx(noh, alpha):
    a2 = alpha * alpha
    return a2 / (np.pi * (noh * noh * (a2 - 1.0) + 1.0) ** 2)


# ------------------------------------------------------------ level mapping


@pytest.mark.parametrize("levels", [2, 5, 9])
def test_roughness_of_level_is_linear_and_inverted(levels):
    m = np.arange(levels)
    r = pf.roughness_of_level(m, levels)
    assert r[0] == 0.0 and r[-1] == 1.0
    assert np.allclose(np.diff(r), 1.0 / (levels - 1))
    assert np.allclose(pf.level_of_roughness(r, levels), m, atol=1e-12)
    frac = np.linspace(0, levels - 1, 37)
    assert np.allclose(pf.level_of_roughness(pf.roughness_of_level(frac, levels), levels), frac)
    assert pf.level_of_roughness(1.7, levels) == levels - 1  # clamped


@pytest.mark.parametrize("bad", [(0, 1), (5, 5), (-1, 5), (np.nan, 3)])
def test_level_mapping_rejects_bad_input(bad):
    with pytest.raises(ValueError):
        pf.roughness_of_level(*bad)


# ----------------------------------------------------------------- GGX lobe


@pytest.mark.parametrize("alpha", [1e-3, 0.04, 0.0625, 0.3, 0.7, 0.99994, 0.99998, 1.0])
def test_lobe_normalization_matches_quadrature(alpha):
    # integral over the hemisphere n.l > 0 of D(h) (n.l), n.h = cos(theta / 2)
    def f(theta):
        return ggx(np.cos(theta / 2), alpha) * np.cos(theta) * np.sin(theta) * 2 * np.pi

    pts = [alpha, 2 * alpha, 4 * alpha] if alpha < 0.3 else None
    ref, _ = integrate.quad(f, 0, np.pi / 2, points=pts, limit=400, epsabs=0, epsrel=1e-12)
    assert pf.ggx_lobe_normalization(alpha) == pytest.approx(ref, rel=1e-9)


def test_lobe_normalization_limits():
    assert pf.ggx_lobe_normalization(1e-6) == pytest.approx(4.0, rel=1e-9)
    assert pf.ggx_lobe_normalization(1.0) == 1.0
    z = pf.ggx_lobe_normalization(np.array([0.5, 1.0]))  # arrays: both branches at once, finite
    assert np.all(np.isfinite(z)) and z[1] == 1.0


@pytest.mark.parametrize("alpha", [0.0625, 0.5])
def test_ggx_zonal_coefficients_match_scipy(alpha):
    lam, total = pf.ggx_zonal_coefficients(alpha, 40)
    assert total == pytest.approx(pf.ggx_lobe_normalization(alpha), rel=1e-10)
    assert lam[0] == pytest.approx(1.0, abs=1e-14)
    for l in (1, 7, 20, 40):
        ref, _ = integrate.quad(lambda t: ggx(np.cos(t / 2), alpha) * np.cos(t) * eval_legendre(l, np.cos(t))
                                * np.sin(t) * 2 * np.pi, 0, np.pi / 2, points=[alpha, 2 * alpha], limit=500,
                                epsabs=1e-13)
        assert lam[l] == pytest.approx(ref / total, abs=2e-10)


def test_band_limit_grows_as_the_lobe_narrows():
    assert pf.band_limit(0.0625, 512) < pf.band_limit(0.04, 512) < pf.band_limit(0.0156, 2048)
    lmax = pf.band_limit(0.0625, 512)
    lam, _ = pf.ggx_zonal_coefficients(0.0625, lmax + 40)
    assert np.all(np.abs(lam[lmax:]) < pf.BAND_LIMIT_TOLERANCE)
    assert pf.band_limit(1.0, 48) == 48  # kink-limited tail: the cap


# ------------------------------------------------------------------ spectral


def test_cosine_kernel_coefficients_are_ramamoorthi_hanrahan():
    lam = cosine_zonal_coefficients(12)
    ref = np.zeros(13)
    ref[1] = 2 / 3
    for l in range(0, 13, 2):  # R&H 2001 eq. 9, divided by pi
        ref[l] = 2 * (-1) ** (l // 2 - 1) / ((l + 2) * (l - 1)) * math.factorial(l) / (
            2 ** l * math.factorial(l // 2) ** 2)
    assert np.allclose(lam, ref, atol=1e-13)


def test_analysis_matches_scipy_projection():
    h = 48
    rng = np.random.default_rng(3)
    img = rng.random((h, 2 * h, 2))
    coeffs = sp.analyse_equirect(img, 6)
    # projection of the piecewise-constant image with SciPy's harmonics (no Condon-Shortley phase): exact
    # cell integrals in phi, 12-point Gauss in theta per row band
    x, w = np.polynomial.legendre.leggauss(12)
    dphi = 2 * np.pi / (2 * h)
    phi = dphi * (np.arange(2 * h) + 0.5) - np.pi
    for l, m in [(0, 0), (1, 1), (3, 2), (6, 6), (5, 0), (6, 1)]:
        total = np.zeros(2, complex)
        for i in range(h):
            half = 0.5 * np.pi / h
            theta = np.pi * (i + 0.5) / h + half * x
            band = half * np.sum(w * np.sin(theta) * (sph_harm_y(l, m, theta, 0.0).real * (-1) ** m))
            col = dphi * np.sinc(m * dphi / 2 / np.pi) * np.exp(-1j * m * phi)
            total += band * (col[:, None] * img[i]).sum(axis=0)
        # the bake's 2-point rule: relative error ~ (l pi / H)^4 / 4320
        assert np.abs(coeffs[l, m] - total).max() < 1e-6 * np.abs(coeffs[0, 0]).max(), (l, m)


def test_synthesis_of_degree_two_matches_pbrkit_sh():
    h = 64
    d = equirect_directions(h)
    img = 1.0 + d[..., :1] * 0.3 + (d[..., 1:2] ** 2) * 0.5 + d[..., 0:1] * d[..., 2:3]
    coeffs = sp.analyse_equirect(img, 2)
    grid = sp.synthesise_equirect(coeffs, h)
    ref = eval_sh(project_equirect(img), d)
    assert np.abs(grid - ref).max() < 2e-3 * np.abs(ref).max()


def test_piecewise_constant_analysis_converges_at_second_order():
    # The cell means of a band-limited function have the function's coefficients up to O((l / H)^2):
    # halving the cell size must cut the error about four-fold.
    lmax = 10
    rng = np.random.default_rng(7)
    c = rng.normal(size=(lmax + 1, lmax + 1, 1)) + 1j * rng.normal(size=(lmax + 1, lmax + 1, 1))
    c[np.triu_indices(lmax + 1, 1)] = 0.0
    c[:, 0] = c[:, 0].real
    fine = sp.synthesise_equirect(c, 1024)
    means = [sp.halve_equirect(sp.halve_equirect(sp.halve_equirect(fine)))]
    means.insert(0, sp.halve_equirect(means[0]))
    errors = [np.abs(sp.analyse_equirect(img, lmax) - c).max() for img in means]
    assert errors[1] < 0.02 * np.abs(c).max()
    assert 3.0 < errors[0] / errors[1] < 5.0


def test_halve_keeps_the_integral():
    img = np.random.default_rng(0).random((40, 80, 3)).astype(np.float32)
    half = sp.halve_equirect(img, band=6)
    assert half.shape == (20, 40, 3)
    assert np.allclose(equirect_integral(half, exact=True), equirect_integral(img, exact=True), rtol=1e-12)


def test_cubic_sampling_is_accurate_across_the_poles():
    h = 64
    d0 = equirect_directions(h)
    f = lambda d: 1.0 + 0.5 * d[..., 1] + 0.3 * d[..., 0] * d[..., 2] - 0.2 * d[..., 2]  # noqa: E731
    grid = f(d0)[..., None]
    rng = np.random.default_rng(5)
    d = rng.normal(size=(2000, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    near_pole = np.array([[0.01, 0.9999, 0.005], [-0.003, -0.99999, 0.002]])
    d = np.concatenate([d, near_pole / np.linalg.norm(near_pole, axis=1, keepdims=True)])
    got = sp.sample_equirect(grid, d)[:, 0]
    assert np.abs(got - f(d)).max() < 2e-3


# ---------------------------------------------------------------- highlights


def test_highlight_split_conserves_energy():
    h = 32
    img = np.full((h, 2 * h, 3), 0.5, np.float32)
    img[10, 20] = [300.0, 200.0, 100.0]
    img[11, 20] = [50.0, 50.0, 50.0]
    img[30, 3] = [20.0, 20.0, 20.0]
    hl = pf.equirect_highlights(img, max_count=2)
    assert hl.threshold == 20.0  # the third brightest pixel, above 16 x the mean
    bounded = np.minimum(img, hl.threshold)
    omega = equirect_solid_angles(h, exact=True)
    total = (img.astype(np.float64) * omega[..., None]).sum(axis=(0, 1))
    split = (bounded.astype(np.float64) * omega[..., None]).sum(axis=(0, 1)) + hl.energies.sum(axis=0)
    assert np.allclose(split, total, rtol=1e-6)
    assert hl.count == 2
    assert np.allclose(hl.directions, equirect_directions(h)[[10, 11], [20, 20]])
    halved = sp.halve_equirect(img, clip=hl.threshold)  # clamped band by band: the same bounded integral
    assert np.allclose(equirect_integral(halved, exact=True), equirect_integral(bounded, exact=True), rtol=1e-12)
    d, e, size = pf.merge_highlights(hl, 2)
    assert e.shape == (1, 3) and np.allclose(e.sum(0), hl.energies.sum(0))
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0)
    assert pf.equirect_highlights(np.ones((h, 2 * h, 3))).count == 0
    cube = np.ones((6, 8, 8, 3))
    cube[2, 3, 4] = 1000.0
    hc = pf.cube_highlights(cube)
    from pbrkit.ibl.cubemap import cube_texel_solid_angles

    omega = cube_texel_solid_angles(8)
    mean = (np.sum(omega) + 999 * omega[2, 3, 4]) / (4 * np.pi)
    assert hc.count == 1 and hc.threshold == pytest.approx(pf.HIGHLIGHT_RATIO * mean, rel=1e-12)
    assert np.allclose(hc.energies, (1000 - hc.threshold) * omega[2, 3, 4])


@pytest.mark.parametrize("lobe", [pf.LOBE_COSINE, pf.LOBE_GGX])
@pytest.mark.parametrize("normalise", [False, True])
def test_point_lobe_sum_is_the_written_out_sum(lobe, normalise):
    rng = np.random.default_rng(6)
    n = rng.normal(size=(40, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    l = rng.normal(size=(70, 3))
    l /= np.linalg.norm(l, axis=1, keepdims=True)
    values, weights, start = rng.random((70, 2)), rng.random(70), rng.random((40, 2))
    alpha, scale = 0.3, 1.7
    nol = n @ l.T
    k = np.maximum(nol, 0.0) if lobe == pf.LOBE_COSINE else np.where(
        nol > 0, ggx(np.sqrt(0.5 + 0.5 * np.maximum(nol, -1.0)), alpha) * nol, 0.0)
    w = k * scale * weights[None, :]
    out = np.zeros((40, 2)) if normalise else start.copy()
    pf.point_lobe_sum(out, n, l, values, lobe, alpha, scale, weights, normalise)
    expected = w @ values / w.sum(axis=1, keepdims=True) if normalise else start + w @ values
    assert np.allclose(out, expected, rtol=1e-13)


def test_irradiance_reference_of_constant_cube_is_pi():
    from pbrkit.ibl.cubemap import cube_texel_directions

    cube = np.ones((6, 16, 16, 3))
    e = irradiance_reference(cube, cube_texel_directions(4).reshape(-1, 3))
    assert np.allclose(e, np.pi, rtol=3e-3)  # midpoint rule with the horizon kink
