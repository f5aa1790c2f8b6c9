"""The ground truth's estimator pieces (pbrkit.rendering.estimator) and the film's sums
(pbrkit.rendering.film) against independent values: the power heuristic by hand, the
shifted sums against numpy's mean and variance (with a large offset that defeats the
naive sum of squares), and the light and BSDF samples against f, pdf and the MIS
weight assembled from the public NumPy API (pbrkit.brdf.models.evaluate / pdf)."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from pbrkit.brdf import models
from pbrkit.brdf.bxdf import NO_TANGENT
from pbrkit.brdf.dispatch import lobe_probabilities
from pbrkit.rendering.estimator import (
    STRATEGY_BSDF,
    STRATEGY_MIS,
    Shading,
    bsdf_sample,
    emission_weight,
    light_sample,
    power_heuristic,
)
from pbrkit.rendering.film import Film, film_estimate, new_film, shifted_add
from pbrkit.rendering.materials import hit_bxdf, material_tables
from pbrkit.rendering.scene import MaterialSpec
from pbrkit.rendering.textures import SurfaceMaterial


def test_power_heuristic_by_hand():
    assert power_heuristic(1.0, 1.0) == 0.5
    assert power_heuristic(3.0, 4.0) == pytest.approx(9.0 / 25.0, rel=1e-15)
    assert power_heuristic(2.0, 0.0) == 1.0
    assert power_heuristic(0.0, 2.0) == 0.0
    assert power_heuristic(0.0, 0.0) == 0.0  # neither strategy samples it: no weight, no NaN
    rng = np.random.default_rng(1)
    for a, b in rng.gamma(0.5, 2.0, (200, 2)):
        # the two strategies' weights of one direction sum to one (Veach 1997, eq. 9.4)
        assert power_heuristic(a, b) + power_heuristic(b, a) == pytest.approx(1.0, rel=1e-15)
        assert emission_weight(STRATEGY_MIS, a, b) == power_heuristic(a, b)
        assert emission_weight(STRATEGY_BSDF, a, b) == 1.0  # BSDF sampling alone


def _accumulate(x, counts=None):
    """A pixel's film from samples x (N, 3), the shift its first sample."""
    k = x[0].copy()
    s = np.zeros(3)
    q = np.zeros(3)
    for j in range(x.shape[0]):
        for c in range(3):
            s[c], q[c] = shifted_add(k[c], s[c], q[c], x[j, c], 1 if counts is None else counts[j])
    return Film(k[None], s[None], q[None])


def test_shifted_sums_give_numpys_mean_and_variance_despite_a_large_offset():
    """Chan, Golub and LeVeque's shifted data: the mean and standard error of the mean of
    samples 1e9 + noise of 1e-3 are numpy's mean and variance of the noise alone (the
    offset subtracted exactly, Sterbenz) and the exact (rational) variance of the
    samples to an ulp, where the naive E[x^2] - E[x]^2 is lost to cancellation."""
    from fractions import Fraction

    rng = np.random.default_rng(5)
    n = 1000
    offset = 1e9
    x = offset + rng.normal(0.0, 1e-3, (n, 3)) * np.array([1.0, 2.0, 0.5])
    noise = x - offset  # exact: x is within a factor 2 of the offset
    mean, stderr = film_estimate(_accumulate(x), n)
    np.testing.assert_allclose(mean[0], offset + noise.mean(axis=0), rtol=2.5e-16)  # 2 ulp of 1e9
    np.testing.assert_allclose(stderr[0], np.sqrt(np.var(noise, axis=0, ddof=1) / n), rtol=1e-12)
    exact = [Fraction(float(a)) for a in x[:, 1]]
    m = sum(exact) / n
    var = float(sum((a - m) ** 2 for a in exact) / (n - 1))
    assert stderr[0, 1] == pytest.approx(np.sqrt(var / n), rel=4e-16)
    naive = (np.sum(x * x, axis=0) / n - x.mean(axis=0) ** 2) * n / (n - 1)
    assert np.all(np.abs(naive - np.var(noise, axis=0, ddof=1)) > 10 * np.var(noise, axis=0, ddof=1))
    # one sample: no variance, no division by zero
    mean1, stderr1 = film_estimate(_accumulate(x[:1]), 1)
    assert np.array_equal(mean1[0], x[0]) and np.array_equal(stderr1[0], np.zeros(3))


def test_shifted_sums_of_repeated_samples_and_of_arrays():
    """Adding a value with count n (the lane kernel's rays that see no surface) is adding
    it n times; the same function adds whole arrays of pixels (the wavefront engine)."""
    rng = np.random.default_rng(6)
    x = rng.normal(3.0, 1.0, (40, 3))
    counts = rng.integers(1, 5, 40)
    a = film_estimate(_accumulate(x, counts), int(counts.sum()))
    b = film_estimate(_accumulate(np.repeat(x, counts, axis=0)), int(counts.sum()))
    np.testing.assert_allclose(a[0], b[0], rtol=1e-13)
    np.testing.assert_allclose(a[1], b[1], rtol=1e-10)
    pixels = rng.normal(0.0, 1.0, (7, 5, 3))  # 7 samples of 5 pixels
    film = new_film(5)
    film.shift[:] = pixels[0]
    for xs in pixels:
        film.sum[:], film.sumsq[:] = shifted_add(film.shift, film.sum, film.sumsq, xs, 1)
    mean, stderr = film_estimate(film, 7)
    np.testing.assert_allclose(mean, pixels.mean(axis=0), rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(stderr, pixels.std(axis=0, ddof=1) / np.sqrt(7), rtol=1e-12)


_SPECS = [
    (MaterialSpec(name="m", base_color=(0.8, 0.5, 0.3), metallic=0.3, roughness=0.4), "gltf", {}),
    (MaterialSpec(name="m", model="cook_torrance", base_color=(0.3, 0.6, 0.2), metallic=0.5, roughness=0.3,
                  masking="separable", fresnel="none"),
     "cook_torrance", dict(masking="separable", fresnel="none")),
    (MaterialSpec(name="m", model="disney", base_color=(0.7, 0.4, 0.3), roughness=0.45, clearcoat=0.6, sheen=0.3),
     "disney", {}),
]


@numba.njit(error_model="numpy")  # as pbrkit's kernels (pbrkit.core.jit): x / 0 is inf or NaN
def _estimator_samples(codes, params, rough, metal, base, n, v, u, light, pdf_l, radiance):
    """bsdf_sample and light_sample of row 0's material at normal n (= g) seen from v,
    one per row of u (lobe, u1, u2) and of light directions / pdfs / radiances."""
    count = u.shape[0]
    bdir = np.empty((count, 3))
    bw = np.empty((count, 3))
    bpdf = np.empty(count)
    lval = np.empty((count, 3))
    b, t, bt = hit_bxdf(codes, params, 0, rough, metal, base[0], base[1], base[2], n[0], n[1], n[2],
                        NO_TANGENT)
    s = Shading((n[0], n[1], n[2]), t, bt, (n[0], n[1], n[2]), (v[0], v[1], v[2]))
    p_spec, p_coat = lobe_probabilities(b, n[0] * v[0] + n[1] * v[1] + n[2] * v[2])
    for i in range(count):
        d, w, pdf = bsdf_sample(b, s, p_spec, p_coat, u[i, 0], u[i, 1], u[i, 2])
        lv = light_sample(b, s, p_spec, p_coat, light[i, 0], light[i, 1], light[i, 2], pdf_l[i], radiance[i, 0],
                          radiance[i, 1], radiance[i, 2])
        for c in range(3):
            bdir[i, c] = d[c]
            bw[i, c] = w[c]
            lval[i, c] = lv[c]
        bpdf[i] = pdf
    return bdir, bw, bpdf, lval


@pytest.mark.parametrize("spec, model, terms", _SPECS, ids=[m for _, m, _ in _SPECS])
def test_light_and_bsdf_samples_against_the_numpy_api(spec, model, terms):
    """A BSDF sample's weight is f <n.l> / p_B and its pdf p_B, a light sample's value
    w_L f L <n.l> / p_L with w_L = p_L^2 / (p_L^2 + p_B^2), for f and p_B from
    pbrkit.brdf.models.evaluate and .pdf (local frame: n = +z; isotropic materials,
    so the tangent does not matter); samples below the surface give nothing."""
    codes, params = material_tables([SurfaceMaterial(spec)])
    material = spec.material()
    rng = np.random.default_rng(11)
    count = 400
    n = np.array([0.0, 0.0, 1.0])
    v = np.array([0.5, -0.2, 0.8])
    v /= np.linalg.norm(v)
    u = rng.random((count, 3))
    light = rng.normal(size=(count, 3))
    light /= np.linalg.norm(light, axis=1, keepdims=True)  # half of them below the surface
    pdf_l = rng.gamma(1.0, 0.5, count)
    pdf_l[:20] = 0.0  # a light that cannot sample these directions
    radiance = rng.random((count, 3)) * 3.0
    bdir, bw, bpdf, lval = _estimator_samples(codes, params, spec.roughness, spec.metallic,
                                              np.array(spec.base_color, dtype=float), n, v, u, light, pdf_l,
                                              radiance)
    ok = bpdf > 0.0
    assert ok.sum() > count // 2
    np.testing.assert_allclose(np.linalg.norm(bdir[ok], axis=1), 1.0, rtol=1e-14)
    f = models.evaluate(model, bdir[ok], v, n, material, **terms)
    p = models.pdf(model, material, v, bdir[ok], **terms)
    np.testing.assert_allclose(bpdf[ok], p, rtol=1e-12)
    np.testing.assert_allclose(bw[ok], f * bdir[ok, 2:3] / p[:, None], rtol=1e-12)
    assert np.all(bw[~ok] == 0.0) and np.all(bdir[~ok] == n) and np.all(bdir[ok] @ n > 0.0)
    # light samples
    f = models.evaluate(model, light, v, n, material, **terms)
    p_b = models.pdf(model, material, v, light, **terms)
    cos = light[:, 2]
    lit = (pdf_l > 0.0) & (cos > 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        w = pdf_l ** 2 / (pdf_l ** 2 + p_b ** 2)
        expected = np.where(lit[:, None], w[:, None] * f * radiance * cos[:, None] / pdf_l[:, None], 0.0)
    np.testing.assert_allclose(lval, expected, rtol=1e-12, atol=1e-300)
    assert np.all(lval[~lit] == 0.0) and np.count_nonzero(lval[lit]) > 0
