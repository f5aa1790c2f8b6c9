"""Tests for pbrkit.ltc.distribution: the LTC distribution of Heitz et al. 2016
(evaluation, sampling, polygon integrals) and the parameterisation and
``ltc_1`` storage of the published fit.

References: quadrature over the sphere (the Gauss-Legendre cells of
``tests/support/chi2.py``) for the normalisation, chi-square tests of the sampler
(``tests/support/chi2.py``, as ``tests/sampling/test_sampling.py`` tests every warp), the brute-force
polygon quadrature of ``tests/support/ltc_reference.py`` for polygon integrals, and
pbrkit's GGX NDF pdf D(h) (n.h), which is exactly the LTC of
M = diag(alpha_x, alpha_y, 1).
"""

from __future__ import annotations

import math
import zlib

import numba
import numpy as np
import pytest

from pbrkit import ltc
from pbrkit.microfacet.ggx import pdf_ggx_ndf, pdf_ggx_ndf_anisotropic
from pbrkit.sampling import pdf_cosine_hemisphere, warp_cosine_hemisphere

try:  # tests/ as a package or as a plain directory on sys.path
    from . import chi2
    from . import ltc_reference as ref
except ImportError:
    import chi2
    import ltc_reference as ref

SEED = 20250212
N_SAMPLES = 200_000
FAMILY_ALPHA = 0.01
NORMALISATION_TOL = 1e-9  # |integral of D - 1|; the cell quadrature gives ~3e-16 for these lobes
BRUTE_FORCE_POINTS = 600_000  # good to ~2e-6 absolute, 2e-5 relative here


def _rotation(axis, angle):
    axis = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def _cases():
    """(id, M): the identity, fit-like isotropic matrices (Heitz's a, b, c, d
    form), anisotropic GGX, a general 3 x 3 and a reflecting one (det < 0)."""
    general = _rotation([0.3, -0.5, 0.8], 0.9) @ np.array([[0.4, 0.1, 0.2], [0.0, 0.7, -0.1], [0.05, 0.0, 1.0]])
    return [
        ("identity", np.eye(3)),
        ("narrow", ltc.ltc_matrix(0.08, 0.0, 0.08, 0.0)),
        ("fit-like", ltc.ltc_matrix(0.45, -0.3, 0.5, 0.25)),
        ("grazing", ltc.ltc_matrix(0.6, 0.4, 0.35, -0.8)),
        ("ggx-anisotropic", np.diag([0.15, 0.6, 1.0])),
        ("general", general),
        ("reflecting", np.diag([-1.0, 1.0, 1.0]) @ ltc.ltc_matrix(0.3, 0.2, 0.4, -0.4)),
    ]


CASES = _cases()
ALPHA_TEST = chi2.sidak_alpha(FAMILY_ALPHA, len(CASES))


def _support_frame(m_inv):
    """Rows (t1, t2, n) of a rotation taking the great circle bounding the support
    of D, {w : (M^-1 w)_z = 0} with normal n = (M^-1)^T z, to the equator, so that
    D's kink lies on cell edges of the (theta, phi) grids."""
    e1, e2, n = ref.tangent_basis(m_inv[2])
    return np.stack([e1, e2, n])


def _pdf_in_frame(m_inv, frame):
    def pdf(x, y, z):
        w = np.stack(np.broadcast_arrays(x, y, z), axis=-1) @ frame  # back to the local frame
        return ltc.ltc_pdf(m_inv, w)
    return pdf


# =========================================================================
# Normalisation and special cases
# =========================================================================


@pytest.mark.parametrize("case_id, m", CASES, ids=[c[0] for c in CASES])
def test_integral_over_the_sphere_is_one(case_id, m):
    m_inv = np.linalg.inv(m)
    frame = _support_frame(m_inv)
    pdf = _pdf_in_frame(m_inv, frame)

    def density(t, p):
        st = np.sin(t)
        return pdf(st * np.cos(p), st * np.sin(p), np.cos(t)) * st

    edges_t, edges_p = chi2.quantile_edges(density, (0.0, np.pi), (0.0, 2 * np.pi), (16, 24), (np.pi / 2,))
    total = chi2.cell_integrals(density, edges_t, edges_p).sum()
    assert abs(total - 1.0) < NORMALISATION_TOL, (case_id, total)
    # no mass beyond the support's great circle
    lower = edges_t >= np.pi / 2
    cells = chi2.cell_integrals(density, edges_t[lower], edges_p)
    assert np.all(cells == 0.0)


def test_scaled_matrix_is_not_normalised_quadrature_can_fail():
    """The same quadrature sees a Jacobian off by a constant (|det M^-1|^1.01)."""
    m_inv = np.linalg.inv(dict(CASES)["fit-like"])
    det = abs(np.linalg.det(m_inv))

    def density(t, p):
        st = np.sin(t)
        w = np.stack(np.broadcast_arrays(st * np.cos(p), st * np.sin(p), np.cos(t)), axis=-1)
        return ltc.ltc_evaluate(m_inv, w) * det**0.01 * st

    edges_t, edges_p = chi2.quantile_edges(density, (0.0, np.pi), (0.0, 2 * np.pi), (16, 24), (np.pi / 2,))
    total = chi2.cell_integrals(density, edges_t, edges_p).sum()
    assert abs(total - 1.0) > 100 * NORMALISATION_TOL


def test_identity_is_the_clamped_cosine():
    rng = np.random.default_rng(SEED)
    w = rng.normal(size=(1000, 3))
    w /= np.linalg.norm(w, axis=-1, keepdims=True)
    np.testing.assert_allclose(ltc.ltc_evaluate(np.eye(3), w), pdf_cosine_hemisphere(w[:, 2]), rtol=1e-14,
                               atol=1e-300)
    u = rng.random((1000, 2))
    np.testing.assert_allclose(ltc.ltc_sample(np.eye(3), u[:, 0], u[:, 1]),
                               np.stack(warp_cosine_hemisphere(u[:, 0], u[:, 1]), axis=-1), atol=1e-15)
    polygons = rng.normal(size=(500, 4, 3)) + [0.0, 0.0, 0.5]
    np.testing.assert_allclose(ltc.ltc_polygon_integral(np.eye(3), polygons),
                               ltc.polygon_clamped_cosine_integral(polygons), rtol=1e-14, atol=1e-17)


@pytest.mark.parametrize("alpha_x, alpha_y", [(0.05, 0.05), (0.3, 0.3), (1.0, 1.0), (0.1, 0.7)])
def test_stretched_cosine_is_the_ggx_normal_distribution(alpha_x, alpha_y):
    """M = diag(alpha_x, alpha_y, 1) turns the clamped cosine into the GGX
    distribution of normals weighted by the cosine, D(h) (n.h) (Heitz et al. 2016,
    the slope-space stretch of Heitz 2014): an independent closed form."""
    rng = np.random.default_rng([SEED, int(alpha_x * 100), int(alpha_y * 100)])
    w = rng.normal(size=(2000, 3))
    w /= np.linalg.norm(w, axis=-1, keepdims=True)
    m_inv = np.diag([1 / alpha_x, 1 / alpha_y, 1.0])
    got = ltc.ltc_evaluate(m_inv, w)
    if alpha_x == alpha_y:
        np.testing.assert_allclose(got, pdf_ggx_ndf(w[:, 2], alpha_x), rtol=1e-10, atol=1e-300)
    np.testing.assert_allclose(got, pdf_ggx_ndf_anisotropic(w[:, 0], w[:, 1], w[:, 2], alpha_x, alpha_y),
                               rtol=1e-10, atol=1e-300)


def test_scale_invariance_and_reflections():
    rng = np.random.default_rng(SEED + 1)
    m = dict(CASES)["grazing"]
    m_inv = np.linalg.inv(m)
    w = rng.normal(size=(500, 3))
    polygons = rng.normal(size=(200, 4, 3)) + [0.0, 0.0, 0.8]
    d = ltc.ltc_evaluate(m_inv, w)
    integral = ltc.ltc_polygon_integral(m_inv, polygons)
    for k in (1e-3, 0.7, 5.0, 1e3):
        np.testing.assert_allclose(ltc.ltc_evaluate(k * m_inv, w), d, rtol=1e-12, atol=1e-300)
        np.testing.assert_allclose(ltc.ltc_polygon_integral(k * m_inv, polygons), integral, rtol=1e-12,
                                   atol=1e-16)
    # the direction's length does not matter
    np.testing.assert_allclose(ltc.ltc_evaluate(m_inv, 3.7 * w), d, rtol=1e-13, atol=1e-300)
    # a negative factor sends the lobe to its antipode
    np.testing.assert_allclose(ltc.ltc_evaluate(-m_inv, -w), d, rtol=1e-13, atol=1e-300)
    # a mirror s = diag(1, -1, 1) composed into M^-1 evaluates the mirrored lobe, and its polygon
    # integral is that of the mirrored polygon with the winding reversed
    s = np.diag([1.0, -1.0, 1.0])
    np.testing.assert_allclose(ltc.ltc_evaluate(m_inv @ s, w @ s), d, rtol=1e-13, atol=1e-300)
    np.testing.assert_allclose(ltc.ltc_polygon_integral(m_inv @ s, polygons @ s), -integral, rtol=1e-12,
                               atol=1e-16)
    # and an isotropic (a, b, c, d) lobe is itself symmetric under y -> -y (module docstring)
    np.testing.assert_allclose(ltc.ltc_evaluate(m_inv, w @ s), d, rtol=1e-13, atol=1e-300)


# =========================================================================
# Sampling: chi-square
# =========================================================================


@pytest.mark.parametrize("case_id, m", CASES, ids=[c[0] for c in CASES])
def test_chi2_sampler(case_id, m):
    rng = np.random.default_rng([SEED, zlib.crc32(case_id.encode())])
    u = rng.random((N_SAMPLES, 2))
    w = ltc.ltc_sample(m, u[:, 0], u[:, 1])
    np.testing.assert_allclose(np.linalg.norm(w, axis=-1), 1.0, atol=1e-14)
    m_inv = np.linalg.inv(m)
    frame = _support_frame(m_inv)
    result = chi2.sphere_chi2_test(w @ frame.T, _pdf_in_frame(m_inv, frame), fixed_theta=(np.pi / 2,))
    assert abs(result.total_probability - 1.0) < 1e-4, f"{case_id}: {result}"
    assert result.p_value > ALPHA_TEST, f"{case_id}: rejected at level {ALPHA_TEST:.2e}: {result}"


def test_chi2_rejects_wrong_pdfs():
    """Samples of one LTC tested against a plausible but different one are rejected."""
    rng = np.random.default_rng([SEED, 99])
    u = rng.random((N_SAMPLES, 2))
    m = dict(CASES)["fit-like"]
    w = ltc.ltc_sample(m, u[:, 0], u[:, 1])
    wrong = [
        ("a * 1.05", ltc.ltc_matrix(0.45 * 1.05, -0.3, 0.5, 0.25)),
        ("b + 0.03", ltc.ltc_matrix(0.45, -0.27, 0.5, 0.25)),
        ("M transposed", m.T),
        ("d mirrored", ltc.ltc_matrix(0.45, -0.3, 0.5, -0.25)),
    ]
    for label, other in wrong:
        m_inv = np.linalg.inv(other)
        frame = _support_frame(np.linalg.inv(m))
        result = chi2.sphere_chi2_test(w @ frame.T, _pdf_in_frame(m_inv, frame), fixed_theta=(np.pi / 2,))
        assert result.p_value < ALPHA_TEST, f"{label} was not rejected: {result}"


# =========================================================================
# Polygon integrals against brute-force quadrature of ltc_evaluate
# =========================================================================


def _test_polygons():
    rng = np.random.default_rng(SEED + 2)
    polygons = []
    # rectangles facing the origin around random directions of the upper hemisphere and through the horizon
    for centre in ([0.2, 0.1, 1.0], [0.8, 0.0, 0.6], [-0.5, 0.6, 0.2], [0.9, -0.3, -0.05], [0.0, 1.0, 0.1]):
        e1, e2, a = ref.tangent_basis(centre)
        hx, hy = rng.uniform(0.2, 0.8, 2)
        polygons.append(np.array([a - hx * e1 - hy * e2, a + hx * e1 - hy * e2, a + hx * e1 + hy * e2,
                                  a - hx * e1 + hy * e2]))
    # a triangle around the pole and one straddling the horizon, reversed (padded to 4 vertices by
    # repeating one: a zero-length edge adds nothing)
    polygons.append(np.array([[0.3, -0.2, 1.0], [0.1, 0.4, 1.0], [-0.4, -0.1, 1.0], [-0.4, -0.1, 1.0]]))
    polygons.append(np.array([[0.9, 0.5, 0.4], [1.0, -0.4, -0.3], [0.6, 0.1, 0.9], [0.6, 0.1, 0.9]])[::-1])
    return polygons


POLYGONS = _test_polygons()


@pytest.mark.parametrize("case_id", ["narrow", "fit-like", "grazing", "general", "reflecting"])
def test_polygon_integral_matches_quadrature(case_id):
    m_inv = np.linalg.inv(dict(CASES)[case_id])
    got = ltc.ltc_polygon_integral(m_inv, np.stack(POLYGONS))
    for p, value in zip(POLYGONS, got):
        want = ref.polygon_quadrature(p, lambda x, y, z: ltc.ltc_evaluate(m_inv, np.stack([x, y, z], axis=-1)),
                                      points=BRUTE_FORCE_POINTS)
        assert value == pytest.approx(want, abs=1e-5, rel=1e-4), (case_id, p)
        assert ltc.ltc_polygon_integral_single(m_inv, p) == pytest.approx(value, rel=1e-13, abs=1e-16)
    assert np.max(np.abs(got)) > 0.05  # the lobe meets the polygons


# =========================================================================
# Parameterisation and storage
# =========================================================================


def test_matrix_inverse_and_storage_round_trip():
    rng = np.random.default_rng(SEED + 3)
    n = 500
    a = rng.uniform(0.01, 1.5, n)
    b = rng.uniform(-1.0, 1.0, n)
    c = rng.uniform(0.01, 1.5, n)
    d = rng.uniform(-1.0, 1.0, n)
    keep = a - b * d > 0.05
    a, b, c, d = a[keep], b[keep], c[keep], d[keep]
    m = ltc.ltc_matrix(a, b, c, d)
    m_inv = ltc.ltc_inverse_matrix(a, b, c, d)
    np.testing.assert_allclose(m_inv, np.linalg.inv(m), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(m[0], [[a[0], 0, b[0]], [0, c[0], 0], [d[0], 0, 1]])
    texel = ltc.ltc_texel(a, b, c, d)
    # the texel is (m00, m20, m02, m22) of M^-1 / (M^-1)_11, with (row, column) indices
    np.testing.assert_allclose(texel, ltc.texel_from_inverse(np.linalg.inv(m)), rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(texel[:, 0], m_inv[:, 0, 0] / m_inv[:, 1, 1], rtol=1e-13)
    np.testing.assert_allclose(texel[:, 1], m_inv[:, 2, 0] / m_inv[:, 1, 1], rtol=1e-13)
    np.testing.assert_allclose(texel[:, 2], m_inv[:, 0, 2] / m_inv[:, 1, 1], rtol=1e-13)
    np.testing.assert_allclose(texel[:, 3], m_inv[:, 2, 2] / m_inv[:, 1, 1], rtol=1e-13)
    # as a shader reads it: GLSL mat3(vec3(x, 0, y), vec3(0, 1, 0), vec3(z, 0, w)) takes columns
    x, y, z, w = texel.T
    zero, one = np.zeros_like(x), np.ones_like(x)
    glsl = np.stack([np.stack([x, zero, y], -1), np.stack([zero, one, zero], -1), np.stack([z, zero, w], -1)],
                    axis=-1)
    np.testing.assert_array_equal(ltc.inverse_from_texel(texel), glsl)
    # the stored matrix is M^-1 scaled by c
    np.testing.assert_allclose(ltc.inverse_from_texel(texel), m_inv * c[:, None, None], rtol=1e-12, atol=1e-12)
    # and back to the parameters
    back = ltc.params_from_texel(texel)
    for got, want in zip(back, (a, b, c, d)):
        np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-12)
    # the stored matrix is the same lobe: same values, samples and polygon integrals
    dirs = rng.normal(size=(texel.shape[0], 3))
    np.testing.assert_allclose(ltc.ltc_evaluate(ltc.inverse_from_texel(texel), dirs), ltc.ltc_evaluate(m_inv, dirs),
                               rtol=1e-11, atol=1e-300)
    polygons = rng.normal(size=(texel.shape[0], 4, 3)) + [0.0, 0.0, 1.0]
    np.testing.assert_allclose(ltc.ltc_polygon_integral(ltc.inverse_from_texel(texel), polygons),
                               ltc.ltc_polygon_integral(m_inv, polygons), rtol=1e-10, atol=1e-14)
    # the storage of a texel whose m11 is negative would flip the lobe, and is detectable
    flipped = ltc.texel_from_inverse(np.linalg.inv(ltc.ltc_matrix(0.5, 0.1, -0.5, 0.2)))
    assert flipped[0] < 0.0
    # the identity's texel
    np.testing.assert_allclose(ltc.ltc_texel(1.0, 0.0, 1.0, 0.0), [1.0, 0.0, 0.0, 1.0])


def test_sampler_and_pdf_agree_pointwise():
    """ltc_sample's direction, mapped back by M^-1, is the cosine sample it came
    from, and the pdf at it is the cosine pdf times the Jacobian |det M^-1| / |M^-1 w|^3."""
    rng = np.random.default_rng(SEED + 4)
    u = rng.random((1000, 2))
    for _, m in CASES:
        m_inv = np.linalg.inv(m)
        w = ltc.ltc_sample(m, u[:, 0], u[:, 1])
        wo = np.stack(warp_cosine_hemisphere(u[:, 0], u[:, 1]), axis=-1)
        back = w @ m_inv.T
        length = np.linalg.norm(back, axis=-1)
        np.testing.assert_allclose(back / length[:, None], wo, atol=1e-12)
        jacobian = abs(np.linalg.det(m_inv)) / length**3
        np.testing.assert_allclose(ltc.ltc_pdf(m_inv, w), wo[:, 2] / np.pi * jacobian, rtol=1e-10, atol=1e-300)


# =========================================================================
# Numba and input checks
# =========================================================================


@numba.njit  # not cached: Numba's cache would not see edits to pbrkit.ltc
def _kernel(m, m_inv, u, polygons, out):
    for i in range(u.shape[0]):
        x, y, z = ltc.warp_ltc(m[0, 0], m[0, 1], m[0, 2], m[1, 0], m[1, 1], m[1, 2], m[2, 0], m[2, 1], m[2, 2],
                               u[i, 0], u[i, 1])
        out[i, 0] = x
        out[i, 1] = y
        out[i, 2] = z
        out[i, 3] = ltc.ltc_evaluate_xyz(m_inv[0, 0], m_inv[0, 1], m_inv[0, 2], m_inv[1, 0], m_inv[1, 1],
                                         m_inv[1, 2], m_inv[2, 0], m_inv[2, 1], m_inv[2, 2], x, y, z)
        out[i, 4] = ltc.ltc_polygon_integral_single(m_inv, polygons[i])


def test_dual_use_in_numba_kernels():
    rng = np.random.default_rng(SEED + 5)
    m = dict(CASES)["reflecting"]
    m_inv = np.linalg.inv(m)
    u = rng.random((64, 2))
    polygons = rng.normal(size=(64, 4, 3)) + [0.0, 0.0, 1.0]
    out = np.empty((64, 5))
    _kernel(m, m_inv, u, polygons, out)
    w = ltc.ltc_sample(m, u[:, 0], u[:, 1])
    np.testing.assert_allclose(out[:, :3], w, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(out[:, 3], ltc.ltc_evaluate(m_inv, w), rtol=1e-12)
    np.testing.assert_allclose(out[:, 4], ltc.ltc_polygon_integral(m_inv, polygons), rtol=1e-12, atol=1e-15)


def test_bad_input():
    with pytest.raises(ValueError, match="shape"):
        ltc.ltc_evaluate(np.eye(2), [0, 0, 1])
    with pytest.raises(ValueError, match="invertible"):
        ltc.ltc_evaluate(np.zeros((3, 3)), [0, 0, 1])
    with pytest.raises(ValueError, match="finite"):
        ltc.ltc_evaluate(np.full((3, 3), np.nan), [0, 0, 1])
    with pytest.raises(ValueError, match="non-zero"):
        ltc.ltc_evaluate(np.eye(3), [0, 0, 0])
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        ltc.ltc_sample(np.eye(3), 1.5, 0.5)
    with pytest.raises(ValueError, match="singular"):
        ltc.ltc_inverse_matrix(1.0, 1.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="singular"):
        ltc.ltc_texel(1.0, 0.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="shape"):
        ltc.inverse_from_texel([1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="m11"):
        ltc.texel_from_inverse(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="zero vector"):
        ltc.ltc_polygon_integral(np.eye(3), [[0, 0, 1], [0, 0, 0], [1, 0, 1]])
    assert ltc.ltc_sample(np.eye(3), np.zeros((2, 5)), 0.5).shape == (2, 5, 3)
    assert ltc.ltc_polygon_integral(np.stack([np.eye(3)] * 3), np.ones((3, 4, 3)) + np.eye(4, 3)).shape == (3,)
