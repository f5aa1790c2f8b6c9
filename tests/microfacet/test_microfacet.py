"""Tests of the new pieces of the pbrkit.microfacet units, against independent references.

* Beckmann visible-normal sampling (isotropic and anisotropic, views from
  normal incidence to the horizon): chi-square goodness of fit of 10^6 seeded
  samples against the pdf G1(wo) max(0, wo.h) D(h) / wo.z (machinery in
  ``tests/support/chi2.py``, as tests/sampling/test_sampling.py tests the GGX samplers), the pdf
  integrated over h by the quadrature of ``tests/support/quadrature.py`` (it must be 1),
  and the inversion of the visible-slope cdf checked by SciPy's adaptive
  quadrature of the slope density written out here.
* Blinn-Phong NDF sampling: chi-square against D (n.h).
* Blinn-Phong's Lambda via its Beckmann equivalent: equal to Beckmann's Lambda
  at alpha = sqrt(2 / (e + 2)), and G1 = 1 / (1 + Lambda) equal to Smith's
  integral (Heitz 2014, sec. 5.3) of that Beckmann slope distribution, and close
  to the Smith integral of the Blinn-Phong slope distribution itself for large
  exponents (the approximation Walter et al. 2007 make).

A Sidak-corrected family-wise level of 0.01 covers the chi-square cases here.
"""

from __future__ import annotations

import math
import zlib

import numba
import numpy as np
import pytest
from quadrature import half_vector_rule, theta_max_visible, view_direction
from scipy import integrate, special

from pbrkit.microfacet import beckmann as bk
from pbrkit.microfacet import blinn_phong as bp
from pbrkit.microfacet import ggx
from pbrkit.microfacet.roughness import ALPHA_MIN
from pbrkit.microfacet.smith import g1_smith
from pbrkit.sampling import pdf_light_from_half, reflect

try:  # tests/ as a package or as a plain directory on sys.path
    from . import chi2
except ImportError:
    import chi2

N_SAMPLES = 1_000_000
FAMILY_ALPHA = 0.01
NORMALISATION_TOL = 1e-4  # |integral of pdf - 1| over the chi-square cells
SEED = 20240917

ALPHAS = (0.05, 0.3, 1.0)
ANISO_ALPHAS = ((0.05, 0.3), (0.3, 1.0), (1.0, 0.05))
VIEW_AZIMUTH = 1.0  # radians, so anisotropic cases are not aligned with the axes
EXPONENTS = (0.0, 1.0, 20.0, 798.0)  # Blinn-Phong; 0 is the cosine lobe, 798 Beckmann's alpha 0.05


def _view(theta_degrees, phi=VIEW_AZIMUTH):
    if theta_degrees == 90:  # exactly grazing: wo.z = 0
        return np.array([math.cos(phi), math.sin(phi), 0.0])
    t = math.radians(theta_degrees)
    return np.array([math.sin(t) * math.cos(phi), math.sin(t) * math.sin(phi), math.cos(t)])


def _u(case_id, n=N_SAMPLES):
    return np.random.default_rng([SEED, zlib.crc32(case_id.encode())]).random((n, 2))


# =========================================================================
# Chi-square goodness of fit
# =========================================================================


def _vndf_sampler_and_pdf(wo, ax, ay):
    if ax == ay:
        return (lambda u: bk.sample_beckmann_vndf(u, wo, ax),
                lambda x, y, z: bk.pdf_beckmann_vndf(wo[2], z, wo[0] * x + wo[1] * y + wo[2] * z, ax))
    return (lambda u: bk.sample_beckmann_vndf_anisotropic(u, wo, ax, ay),
            lambda x, y, z: bk.pdf_beckmann_vndf_anisotropic(wo[0], wo[1], wo[2], x, y, z, ax, ay))


#: The azimuths where the visible normals' wo.h = 0 meets the horizon: edges in phi,
#: so that the kink of max(0, wo.h) (a meridian at a grazing view) is not inside a cell.
VISIBLE_EDGES = tuple(np.mod(VIEW_AZIMUTH + np.array([0.5, 1.5]) * math.pi, 2.0 * math.pi))


#: Views of the quick run; the others are marked slow (each case samples 10^6 visible normals).
QUICK_VIEWS = (0, 45, 60, 90)


def _cases():
    """(id, sampler(u) -> directions, pdf(x, y, z), theta edges and phi edges where the pdf
    jumps or has a kink)."""
    horizon = (math.pi / 2,)
    cases = []
    for (ax, ay), deg in [((a, a), d) for a in ALPHAS for d in (0, 45, 80, 89, 90)] + [
            (p, d) for p in ANISO_ALPHAS for d in (0, 60, 89, 90)]:
        wo = _view(deg)
        sampler, pdf = _vndf_sampler_and_pdf(wo, ax, ay)
        kind = "beckmann_vndf" if ax == ay else "beckmann_vndf_aniso"
        cases.append((f"{kind}-a{ax},{ay}-theta{deg}", sampler, pdf, horizon, VISIBLE_EDGES if deg else ()))
    # the light directions l = reflect(wo, h), pdf D_wo(h) / (4 wo.h), support l.z >= -wo.z
    for ax, ay, deg in ((0.3, 0.3, 45), (0.3, 1.0, 70)):
        wo = _view(deg)
        sampler, pdf_h = _vndf_sampler_and_pdf(wo, ax, ay)

        def pdf_l(x, y, z, wo=wo, pdf_h=pdf_h):
            hx, hy, hz = wo[0] + x, wo[1] + y, wo[2] + z
            length = np.sqrt(hx * hx + hy * hy + hz * hz)
            length = np.where(length > 0.0, length, 1.0)
            hx, hy, hz = hx / length, hy / length, hz / length
            return pdf_light_from_half(pdf_h(hx, hy, hz), wo[0] * hx + wo[1] * hy + wo[2] * hz)

        cases.append((f"beckmann_vndf_light-a{ax},{ay}-theta{deg}", lambda u, wo=wo, f=sampler: reflect(wo, f(u)),
                      pdf_l, (math.acos(-wo[2]),), ()))
    for e in EXPONENTS:
        cases.append((f"blinn_phong_ndf-e{e}", lambda u, e=e: bp.sample_blinn_phong_ndf(u, e),
                      lambda x, y, z, e=e: bp.pdf_blinn_phong_ndf(z, e), horizon, ()))
    return cases


CASES = _cases()
ALPHA_TEST = chi2.sidak_alpha(FAMILY_ALPHA, len(CASES))


def _assert_fits(result, label):
    assert abs(result.total_probability - 1.0) < NORMALISATION_TOL, f"{label}: pdf does not integrate to 1: {result}"
    assert result.p_value > ALPHA_TEST, f"{label}: rejected at level {ALPHA_TEST:.2e}: {result}"


def _sphere_chi2(directions, pdf, fixed_theta, fixed_phi):
    """chi2.sphere_chi2_test with fixed edges in phi as well (cells in (theta, phi), density pdf sin theta)."""
    theta, phi = chi2.directions_to_spherical(directions)

    def density(t, p):
        st = np.sin(t)
        return pdf(st * np.cos(p), st * np.sin(p), np.cos(t)) * st

    return chi2.chi2_test_2d(theta, phi, density, (0.0, math.pi), (0.0, 2.0 * math.pi), fixed_a=fixed_theta,
                             fixed_b=fixed_phi)


def _params(cases):
    quick = [f"theta{d}" for d in QUICK_VIEWS]
    return [pytest.param(*case, id=case[0], marks=() if case[0].endswith(tuple(quick)) or "blinn" in case[0]
                         else pytest.mark.slow) for case in cases]


@pytest.mark.parametrize("case_id, sampler, pdf, fixed_theta, fixed_phi", _params(CASES))
def test_chi2(case_id, sampler, pdf, fixed_theta, fixed_phi):
    directions = sampler(_u(case_id))
    _assert_fits(_sphere_chi2(directions, pdf, fixed_theta, fixed_phi), case_id)


def test_chi2_rejects_wrong_pdfs():
    """Plausible but wrong pdfs are rejected, so the cases above can fail: the GGX
    visible normals of the same alpha, a 10% wider alpha, swapped anisotropic
    alphas, the NDF pdf D cos instead of the visible one, and a Blinn-Phong
    exponent 10% off."""
    wo = _view(60)
    u = _u("wrong pdfs")
    h = bk.sample_beckmann_vndf(u, wo, 0.3)
    voh = lambda x, y, z: wo[0] * x + wo[1] * y + wo[2] * z  # noqa: E731
    wrong = [
        ("Beckmann VNDF vs GGX VNDF pdf", h, lambda x, y, z: ggx.pdf_ggx_vndf(wo[2], z, voh(x, y, z), 0.3)),
        ("Beckmann VNDF vs pdf at alpha 0.33", h, lambda x, y, z: bk.pdf_beckmann_vndf(wo[2], z, voh(x, y, z), 0.33)),
        ("Beckmann VNDF vs the NDF pdf D cos", h, lambda x, y, z: bk.pdf_beckmann_ndf(z, 0.3)),
    ]
    h = bk.sample_beckmann_vndf_anisotropic(u, wo, 0.3, 0.05)
    wrong.append(("anisotropic Beckmann VNDF vs swapped alphas", h,
                  lambda x, y, z: bk.pdf_beckmann_vndf_anisotropic(*wo, x, y, z, 0.05, 0.3)))
    h = bp.sample_blinn_phong_ndf(u, 20.0)
    wrong.append(("Blinn-Phong e = 20 vs pdf at e = 22", h, lambda x, y, z: bp.pdf_blinn_phong_ndf(z, 22.0)))
    for label, w, pdf in wrong:
        result = _sphere_chi2(w, pdf, (math.pi / 2,), VISIBLE_EDGES)
        assert abs(result.total_probability - 1.0) < NORMALISATION_TOL, label  # a normalised but wrong pdf
        assert result.p_value < ALPHA_TEST, f"{label} was not rejected: {result}"


# =========================================================================
# The Beckmann distribution of visible normals
# =========================================================================


@pytest.mark.parametrize("theta", (0.0, 45.0, 80.0, 89.0, 89.99))
@pytest.mark.parametrize("alpha_x, alpha_y", [(0.01, 0.01), (0.05, 0.05), (0.3, 0.3), (1.0, 1.0), (0.05, 0.3),
                                              (0.3, 0.05), (1.0, 0.1)])
def test_beckmann_vndf_pdf_integrates_to_one(alpha_x, alpha_y, theta):
    """integral over h of D_wo(h) = 1 (Heitz 2014, eq. 16 with Smith's G1), by the
    half-vector quadrature cut exactly at wo.h = 0."""
    v = view_direction(np.cos(np.radians(theta)), 0.7)
    h, w = half_vector_rule(alpha_x, alpha_y, theta_max=theta_max_visible(v), phi_split=0.7 + 0.5 * np.pi)
    pdf = bk.pdf_beckmann_vndf_anisotropic(v[0], v[1], v[2], h[:, 0], h[:, 1], h[:, 2], alpha_x, alpha_y)
    assert abs(np.sum(w * pdf) - 1.0) < 1e-5
    if alpha_x == alpha_y:
        iso = bk.pdf_beckmann_vndf(v[2], h[:, 2], h @ v, alpha_x)
        np.testing.assert_allclose(iso, pdf, rtol=1e-9, atol=1e-300)


def _slope_cdf_by_quadrature(x, cos_theta, sin_theta):
    """P(x~ <= x) for the visible slopes of the alpha = 1 Beckmann surface: the
    density (cos theta - t sin theta) exp(-t^2) on t <= cot theta, integrated by
    SciPy's adaptive quadrature (not the closed form of the module)."""
    top = cos_theta / sin_theta if sin_theta > 0.0 else np.inf

    def density(t):
        return (cos_theta - t * sin_theta) * math.exp(-t * t)

    def mass(a, b):
        return integrate.quad(density, a, b, epsabs=0.0, epsrel=1e-13, limit=400)[0]

    centre = min(0.0, top)
    total = mass(-np.inf, centre) + (mass(centre, top) if top > centre else 0.0)
    return (mass(-np.inf, min(x, centre)) + (mass(centre, min(x, top)) if x > centre else 0.0)) / total


@pytest.mark.parametrize("theta", (0.0, 20.0, 60.0, 85.0, 89.9, 90.0))
def test_visible_slope_inversion(theta):
    """The inversion of the slope cdf (bk._visible_slope_x): the cdf at the returned
    slope is u, against SciPy's quadrature of the density for a few u, and against
    the closed form N(x) / Z (SciPy's erfc) on a dense grid with the tails:
    to 1e-12 of u for u <= 1/2 and to 1e-15 absolute above."""
    c = 0.0 if theta == 90.0 else math.cos(math.radians(theta))
    s = math.sin(math.radians(theta))
    for u in (1e-9, 0.01, 0.3, 0.5, 0.77, 0.999):
        x = float(bk._visible_slope_x(u, c, s))
        assert _slope_cdf_by_quadrature(x, c, s) == pytest.approx(u, rel=1e-9, abs=1e-13), (u, x)
    u = np.sort(np.concatenate([np.logspace(-250, -1, 500), np.linspace(0.0, 1.0, 20001)[1:-1],
                                1.0 - np.logspace(-14, -1, 200)]))
    x = bk._visible_slope_x(u, c, s)
    assert np.all(np.isfinite(x))
    cot = min(c / s, 26.0) if s > 0.0 else 26.0
    z = c * (1.0 + special.erf(cot)) + s * math.exp(-cot * cot) / math.sqrt(math.pi)
    f = (c * special.erfc(-x) + s * np.exp(-x * x) / math.sqrt(math.pi)) / z
    low = u <= 0.5
    assert np.max(np.abs(f[low] / u[low] - 1.0)) < 1e-12
    assert np.max(np.abs(f[~low] - u[~low])) < 1e-15
    assert np.all(np.diff(x) >= 0.0)  # monotone in u
    assert np.all(x <= cot + 1e-15)  # visible slopes end at cot theta


def test_beckmann_vndf_known_values_and_symmetries():
    # normal incidence, the median of both slopes: the normal itself
    np.testing.assert_array_equal(np.abs(bk.sample_beckmann_vndf([0.5, 0.5], [0.0, 0.0, 1.0], 0.3)), [0, 0, 1])
    rng = np.random.default_rng(SEED)
    u = rng.random((4000, 2))
    for alpha_x, alpha_y in ((0.05, 0.05), (0.3, 1.0), (2.0, 0.02)):
        for deg in (0, 30, 75, 89, 90):
            wo = _view(deg)
            h = bk.sample_beckmann_vndf_anisotropic(u, wo, alpha_x, alpha_y)
            assert np.all(h @ wo >= -1e-12) and np.all(h[:, 2] > 0.0)  # visible, above the surface
            np.testing.assert_allclose(np.linalg.norm(h, axis=-1), 1.0, atol=1e-14)
            if deg < 90:  # a view below the surface is mirrored
                np.testing.assert_array_equal(bk.sample_beckmann_vndf_anisotropic(u, -wo, alpha_x, alpha_y), h)
            if alpha_x == alpha_y:
                np.testing.assert_array_equal(bk.sample_beckmann_vndf(u, wo, alpha_x), h)
    # y~ is symmetric: u2 -> 1 - u2 mirrors the slope across the view's plane (here the xz plane)
    wo = _view(50, 0.0)
    a = bk.sample_beckmann_vndf(u, wo, 0.4)
    b = bk.sample_beckmann_vndf(np.stack([u[:, 0], 1.0 - u[:, 1]], axis=-1), wo, 0.4)
    np.testing.assert_allclose(b * [1, -1, 1], a, atol=1e-12)


_EDGE_U = np.array([0.0, 1e-300, 1e-12, 0.25, 0.5, 1 - 1e-12, 1 - 2.0**-53, 1.0])
_EDGE_U2 = np.stack(np.meshgrid(_EDGE_U, _EDGE_U, indexing="ij"), axis=-1).reshape(-1, 2)
_EDGE_VIEWS = np.array([[0, 0, 1], [1, 0, 0], [0, 1, 1e-300], [0.6, 0.8, 1e-12], [0.3, -0.4, -0.5], [0, 0, -1],
                        [1e-300, 0, 1]], dtype=float)


@pytest.mark.parametrize("alpha_x, alpha_y", [(ALPHA_MIN, ALPHA_MIN), (ALPHA_MIN, 1.0), (0.3, 0.05), (1.0, 1.0),
                                              (4.0, 0.5), (1e6, ALPHA_MIN), (1e20, 1e20)])
def test_degenerate_inputs_give_finite_unit_vectors(alpha_x, alpha_y):
    u = np.repeat(_EDGE_U2, len(_EDGE_VIEWS), axis=0)
    wo = np.tile(_EDGE_VIEWS / np.linalg.norm(_EDGE_VIEWS, axis=1, keepdims=True), (len(_EDGE_U2), 1))
    with np.errstate(divide="raise", over="raise", invalid="raise"):  # not even in discarded branches
        h_iso = bk.sample_beckmann_vndf(u, wo, alpha_x)
        h = bk.sample_beckmann_vndf_anisotropic(u, wo, alpha_x, alpha_y)
        pdfs = [bk.pdf_beckmann_vndf(wo[:, 2], h_iso[:, 2], np.sum(wo * h_iso, axis=-1), alpha_x)]
        if alpha_x < 1e20:  # the pdfs are guarded from ALPHA_MIN up, as GGX's
            pdfs.append(bk.pdf_beckmann_vndf_anisotropic(*wo.T, *h.T, alpha_x, alpha_y))
        for e in (0.0, 1.0, 798.0, 2e6):
            hb = bp.sample_blinn_phong_ndf(u, e)
            assert np.all(np.isfinite(hb)) and np.all(hb[:, 2] >= 0.0)
            np.testing.assert_allclose(np.linalg.norm(hb, axis=-1), 1.0, atol=1e-12)
            pdfs.append(bp.pdf_blinn_phong_ndf(hb[:, 2], e))
    for w in (h_iso, h):
        assert np.all(np.isfinite(w)) and np.all(w[:, 2] >= 0.0)
        np.testing.assert_allclose(np.linalg.norm(w, axis=-1), 1.0, atol=1e-12)
    for p in pdfs:
        assert np.all(np.isfinite(p) & (p >= 0.0))


def test_wrappers_validate():
    with pytest.raises(ValueError, match="unit square"):
        bk.sample_beckmann_vndf([0.5, 1.5], [0, 0, 1], 0.3)
    with pytest.raises(ValueError, match="alpha_y"):
        bk.sample_beckmann_vndf_anisotropic([0.5, 0.5], [0, 0, 1], 0.3, 0.0)
    with pytest.raises(ValueError, match="wo"):
        bk.sample_beckmann_vndf([0.5, 0.5], [0, 0, 0], 0.3)
    with pytest.raises(ValueError, match="exponent"):
        bp.sample_blinn_phong_ndf([0.5, 0.5], -2.0)
    with pytest.raises(ValueError, match="exponent"):
        bp.sample_blinn_phong_ndf([0.5, 0.5], np.inf)
    u = np.random.default_rng(SEED).random((4, 5, 2))
    assert bk.sample_beckmann_vndf(u, [0.0, 0.6, 0.8], np.full(5, 0.3)).shape == (4, 5, 3)
    assert bp.sample_blinn_phong_ndf(u, np.full(5, 10.0)).shape == (4, 5, 3)


# =========================================================================
# Blinn-Phong: exact NDF sampling, Lambda via the Beckmann equivalent
# =========================================================================


def test_blinn_phong_sampling_known_values():
    # cos theta_h = u1^(1 / (e + 2)); e = 0 is the cosine lobe (D cos = cos / pi)
    for e in (0.0, 3.0, 98.0):
        for c in (0.2, 0.9, 0.999):
            h = bp.sample_blinn_phong_ndf([c ** (e + 2.0), 0.25], e)
            assert h[2] == pytest.approx(c, rel=1e-13) and abs(h[0]) < 1e-15 and h[1] > 0.0
    z = np.linspace(0.0, 1.0, 11)
    np.testing.assert_allclose(bp.pdf_blinn_phong_ndf(z, 0.0), z / np.pi, rtol=1e-15)
    # the tiny sin theta of a sharp lobe keeps its precision: 1 - cos = -expm1(ln u1 / (e + 2))
    h = bp.sample_blinn_phong_ndf([0.5, 0.0], 2e6)
    assert h[0] == pytest.approx(math.sqrt(-math.expm1(math.log(0.5) / (2e6 + 2.0)) * 2.0), rel=1e-6)


def test_lambda_blinn_phong_is_beckmanns_at_the_equivalent_alpha():
    nov = np.concatenate([[0.0, 1e-9, 1e-3], np.linspace(0.01, 1.0, 200)])
    for e in (0.0, 1.0, 20.0, 798.0, 2e6):
        alpha = math.sqrt(2.0 / (e + 2.0))  # Walter et al. 2007, eq. 30, written out
        np.testing.assert_array_equal(bp.lambda_blinn_phong(nov, e), bk.lambda_beckmann(nov, alpha))
        assert bp.phong_exponent_from_beckmann_alpha(alpha) == pytest.approx(e, rel=1e-12, abs=1e-12)


def _smith_lambda(p2, theta):
    """Lambda = (1 / mu) integral_{q > mu} (q - mu) P2(q) dq, mu = cot theta (Heitz 2014,
    sec. 5.3, after Smith 1967), with SciPy's adaptive quadrature."""
    mu = 1.0 / math.tan(theta)
    return integrate.quad(lambda q: (q - mu) * p2(q), mu, np.inf, epsabs=1e-14, epsrel=1e-11, limit=400)[0] / mu


def _p2_beckmann(alpha):
    # the slope density exp(-(x^2 + y^2) / alpha^2) / (pi alpha^2) projected on one axis
    return lambda q: math.exp(-q * q / (alpha * alpha)) / (alpha * math.sqrt(math.pi))


def _p2_blinn_phong(e):
    # P22 = D cos^4 = (e + 2) / (2 pi) (1 + x^2 + y^2)^(-(e + 4) / 2), projected on one axis by quadrature
    def p2(q):
        return integrate.quad(lambda p: (e + 2.0) / (2.0 * math.pi) * (1.0 + q * q + p * p) ** (-(e + 4.0) / 2.0),
                              -np.inf, np.inf, epsabs=0.0, epsrel=1e-12, limit=200)[0]
    return p2


@pytest.mark.parametrize("e", (0.0, 8.0, 98.0, 798.0))
def test_g1_blinn_phong_matches_smith_integrals(e):
    """G1 = 1 / (1 + lambda_blinn_phong) is Smith's G1 of the equivalent Beckmann
    surface (to the quadrature's 1e-8), and approximates the Smith G1 of the
    Blinn-Phong slopes themselves, the better the sharper the lobe: largest
    relative differences over 30-88 degrees measured 0.73 at e = 0 (alpha = 1),
    7.3e-2 at e = 8, 5.0e-3 at e = 98 (alpha = 0.14) and 2.8e-4 at e = 798
    (alpha = 0.05), each at 88 degrees."""
    alpha = math.sqrt(2.0 / (e + 2.0))
    p2_bk, p2_bp = _p2_beckmann(alpha), _p2_blinn_phong(e)
    worst = 0.0
    for theta_deg in (30.0, 60.0, 80.0, 88.0):
        theta = math.radians(theta_deg)
        g1 = float(g1_smith(bp.lambda_blinn_phong(math.cos(theta), e)))
        assert g1 == pytest.approx(1.0 / (1.0 + _smith_lambda(p2_bk, theta)), rel=1e-8)
        own = 1.0 / (1.0 + _smith_lambda(p2_bp, theta))
        worst = max(worst, abs(g1 / own - 1.0))
    print(f"e = {e}: largest relative difference from the Blinn-Phong slopes' own Smith G1: {worst:.2e}")
    assert worst < {0.0: 1.0, 8.0: 0.1, 98.0: 1e-2, 798.0: 1e-3}[e]
    if e == 0.0:
        assert worst > 0.3  # an approximation, visibly so for broad lobes


# =========================================================================
# Dual use in Numba
# =========================================================================


@numba.njit(cache=True)
def _terms_kernel(u, wo, alpha_x, alpha_y, exponent, out):
    for i in range(u.shape[0]):
        u1, u2 = u[i, 0], u[i, 1]
        wx, wy, wz = wo[i, 0], wo[i, 1], wo[i, 2]
        ax, ay, e = alpha_x[i], alpha_y[i], exponent[i]
        x, y, z = bk.warp_beckmann_vndf(u1, u2, wx, wy, wz, ax)
        out[i, 0], out[i, 1], out[i, 2] = x, y, z
        out[i, 3] = bk.pdf_beckmann_vndf(wz, z, wx * x + wy * y + wz * z, ax)
        x, y, z = bk.warp_beckmann_vndf_anisotropic(u1, u2, wx, wy, wz, ax, ay)
        out[i, 4], out[i, 5], out[i, 6] = x, y, z
        out[i, 7] = bk.pdf_beckmann_vndf_anisotropic(wx, wy, wz, x, y, z, ax, ay)
        x, y, z = bp.warp_blinn_phong_ndf(u1, u2, e)
        out[i, 8], out[i, 9], out[i, 10] = x, y, z
        out[i, 11] = bp.pdf_blinn_phong_ndf(z, e)
        out[i, 12] = bp.lambda_blinn_phong(abs(wz), e)


def test_terms_compile_in_numba_and_match_numpy():
    rng = np.random.default_rng(SEED)
    u = np.concatenate([rng.random((256, 2)), _EDGE_U2])
    m = len(u)
    edge_views = _EDGE_VIEWS / np.linalg.norm(_EDGE_VIEWS, axis=1, keepdims=True)
    wo = np.tile(edge_views, (m // len(edge_views) + 1, 1))[:m]
    theta, phi = rng.uniform(0.0, 1.5, 256), rng.uniform(0.0, 2.0 * np.pi, 256)
    wo[:256] = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1)
    alpha_x = rng.uniform(ALPHA_MIN, 1.5, m)
    alpha_y = rng.uniform(ALPHA_MIN, 1.5, m)
    exponent = rng.uniform(0.0, 1000.0, m)
    got = np.empty((m, 13))
    _terms_kernel(u, wo, alpha_x, alpha_y, exponent, got)
    u1, u2 = u.T
    wx, wy, wz = wo.T
    parts = []
    x, y, z = bk.warp_beckmann_vndf(u1, u2, wx, wy, wz, alpha_x)
    parts += [x, y, z, bk.pdf_beckmann_vndf(wz, z, wx * x + wy * y + wz * z, alpha_x)]
    x, y, z = bk.warp_beckmann_vndf_anisotropic(u1, u2, wx, wy, wz, alpha_x, alpha_y)
    parts += [x, y, z, bk.pdf_beckmann_vndf_anisotropic(wx, wy, wz, x, y, z, alpha_x, alpha_y)]
    x, y, z = bp.warp_blinn_phong_ndf(u1, u2, exponent)
    parts += [x, y, z, bp.pdf_blinn_phong_ndf(z, exponent), bp.lambda_blinn_phong(np.abs(wz), exponent)]
    want = np.stack(np.broadcast_arrays(*parts), axis=-1)
    assert np.all(np.isfinite(got))
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-12)
