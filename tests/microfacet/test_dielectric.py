"""The rough dielectric BSDF (pbrkit.microfacet.dielectric), each part against something independent:

* the exact Fresnel reflectance against the Fresnel equations for s and p
  polarisation written out here from Snell's law (and against
  ``pbrkit.brdf.fresnel.f_dielectric`` where both apply), total internal
  reflection included;
* the transmission value against Walter et al. 2007 eq. 21 transcribed here
  (with its own GGX D, Lambda and half vector), and the generalised reciprocity
  of both transport forms;
* the sampler against its pdf over the whole sphere by chi-square (cells of
  ``tests/support/chi2.py``, failed samples as one more cell), from outside and from
  inside, with total internal reflection; the pdf's integral over wi (those
  cells) against the probability of a successful sample integrated over the
  microfacet normal instead (``tests/support/quadrature.py``), which checks the two
  Jacobians;
* the white furnace: the integral of f |cos theta_i| over the sphere (importance
  transport) at or below 1 and equal to the sampler's estimate;
* the smooth limit: reflectance and transmittance tend to the exact Fresnel
  R and 1 - R as alpha -> 0, and at alpha <= SMOOTH_ALPHA the sampler gives the
  delta pair with f and pdf 0;
* the kernels compile in Numba and match NumPy.

A Sidak-corrected family-wise level of 0.01 covers the chi-square cases.
"""

from __future__ import annotations

import math
import zlib

import numba
import numpy as np
import pytest
from quadrature import albedo_nodes, half_vector_rule, theta_max_reflected, theta_max_visible

from pbrkit.brdf.fresnel import f_dielectric
from pbrkit.microfacet import dielectric as dl

try:  # tests/ as a package or as a plain directory on sys.path
    from . import chi2
except ImportError:
    import chi2

SEED = 20261127
N_SAMPLES = 200_000
FAMILY_ALPHA = 0.01


def _u(case_id, n=N_SAMPLES):
    rng = np.random.default_rng([SEED, zlib.crc32(case_id.encode())])
    return rng.random((n, 2)), rng.random(n)


def _direction(theta_degrees, phi=0.7, inside=False):
    t = math.radians(theta_degrees)
    z = math.cos(t)
    return np.array([math.sin(t) * math.cos(phi), math.sin(t) * math.sin(phi), -z if inside else z])


# ----------------------------------------------------------- independent transcriptions


def fresnel_sp(cos_i, n1, n2):
    """Unpolarised reflectance from the Fresnel equations for s and p polarisation
    (Hecht, "Optics", sec. 4.6), light in medium n1 at incidence cos_i >= 0 onto n2."""
    theta_i = np.arccos(np.clip(cos_i, 0.0, 1.0))
    sin_t = n1 / n2 * np.sin(theta_i)
    tir = sin_t >= 1.0
    theta_t = np.arcsin(np.minimum(sin_t, 1.0))
    ci, ct = np.cos(theta_i), np.cos(theta_t)
    rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct)
    rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct)
    return np.where(tir, 1.0, 0.5 * (rs * rs + rp * rp))


def ggx_d(h, ax, ay):
    """Anisotropic GGX D (Heitz 2014 eq. 85), written here from the slopes."""
    sx, sy = h[..., 0] / h[..., 2], h[..., 1] / h[..., 2]
    c4 = h[..., 2] ** 4
    return np.where(h[..., 2] > 0, 1.0 / (np.pi * ax * ay * c4 * (1.0 + (sx / ax) ** 2 + (sy / ay) ** 2) ** 2), 0.0)


def ggx_lambda(w, ax, ay):
    """Anisotropic GGX Lambda (Heitz 2014 eq. 86) of a direction on either side."""
    a2t2 = ((w[..., 0] * ax) ** 2 + (w[..., 1] * ay) ** 2) / w[..., 2] ** 2
    return 0.5 * (np.sqrt(1.0 + a2t2) - 1.0)


def vndf(v, h, ax, ay):
    """D_v(h) = G1(v) max(0, v.h) D(h) / v.z for v.z > 0 (Heitz & d'Eon 2014)."""
    return np.maximum(h @ v, 0.0) * ggx_d(h, ax, ay) / (v[2] * (1.0 + ggx_lambda(v, ax, ay)))


def refract(w, h, eta_from, eta_to):
    """Snell's law in vector form (Hecht sec. 4.4): w (towards the viewer, on the side
    h points to) refracted through h; returns (direction, total internal reflection)."""
    c = h @ w if h.ndim == 1 else np.sum(h * w, axis=-1)
    r = eta_from / eta_to
    k = 1.0 - r * r * (1.0 - c * c)
    t = -r * w + (r * c - np.sqrt(np.maximum(k, 0.0)))[..., None] * h
    return t, k <= 0.0


def walter_eq21(wo, wi, eta, ax, ay):
    """Walter et al. 2007 eq. 21 (light from wi, seen from wo on the other side), with
    h_t = -(eta_i wi + eta_o wo) normalised (eq. 16), height-correlated Smith G."""
    eta_o = np.where(wo[..., 2] > 0, 1.0, eta)
    eta_i = np.where(wi[..., 2] > 0, 1.0, eta)
    h = -(eta_i[..., None] * wi + eta_o[..., None] * wo)
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    h *= np.sign(h[..., 2])[..., None]  # the microfacet facing outside
    wih, woh = np.sum(wi * h, -1), np.sum(wo * h, -1)
    # F at the microfacet for light arriving along -wi from the side of wi
    fr = fresnel_sp(np.abs(wih), eta_i, eta_o)
    g = 1.0 / (1.0 + ggx_lambda(wo, ax, ay) + ggx_lambda(wi, ax, ay))
    value = (np.abs(wih * woh) / np.abs(wi[..., 2] * wo[..., 2]) * eta_o ** 2 * (1.0 - fr) * g * ggx_d(h, ax, ay)
             / (eta_i * wih + eta_o * woh) ** 2)
    front = (wih * wi[..., 2] > 0) & (woh * wo[..., 2] > 0)
    return np.where(front, value, 0.0)


# ------------------------------------------------------------------------ Fresnel


@pytest.mark.parametrize("eta", [1.5, 1.33, 1.0 / 1.5, 2.4])
def test_fresnel_is_the_s_and_p_average(eta):
    c = np.concatenate([np.linspace(-1.0, 1.0, 401), [-1e-9, 1e-9, 0.0]])
    inside = c < 0
    want = np.where(inside, fresnel_sp(-c, eta, 1.0), fresnel_sp(c, 1.0, eta))
    got = dl.fresnel_dielectric(c, eta)
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-12)
    # total internal reflection from the denser side, beyond the critical angle
    n_dense = max(eta, 1.0 / eta)
    critical = math.sqrt(1.0 - 1.0 / n_dense ** 2)
    beyond = np.linspace(0.0, critical * 0.999, 20)
    dense_cos = -beyond if eta > 1 else beyond
    assert np.all(dl.fresnel_dielectric(dense_cos, eta) == 1.0)
    # the brdf module's (complex, cos >= 0) form agrees where it applies
    up = c[c >= 0]
    np.testing.assert_allclose(got[c >= 0], f_dielectric(up, eta), rtol=1e-9, atol=1e-12)
    # Stokes: the same fraction is reflected both ways through the interface
    theta = np.linspace(0.0, 1.5, 30)
    sin_t = np.sin(theta) / eta
    ok = sin_t < 1
    ct = np.sqrt(1 - sin_t[ok] ** 2)
    np.testing.assert_allclose(dl.fresnel_dielectric(np.cos(theta[ok]), eta), dl.fresnel_dielectric(-ct, eta),
                               rtol=1e-10)


def test_fresnel_known_values():
    assert dl.fresnel_dielectric(1.0, 1.5) == pytest.approx(0.04, abs=1e-15)
    assert dl.fresnel_dielectric(-1.0, 1.5) == pytest.approx(0.04, abs=1e-15)
    assert dl.fresnel_dielectric(0.0, 1.5) == 1.0
    assert dl.fresnel_dielectric(0.5, 1.0) == 0.0
    brewster = math.cos(math.atan(1.5))  # rp = 0: F = rs^2 / 2
    cos_t = math.sqrt(1 - (1 - brewster ** 2) / 2.25)
    rs = (brewster - 1.5 * cos_t) / (brewster + 1.5 * cos_t)
    assert dl.fresnel_dielectric(brewster, 1.5) == pytest.approx(0.5 * rs * rs, rel=1e-12)


# ------------------------------------------------------------ values and reciprocity


def _random_pairs(n, seed):
    rng = np.random.default_rng(seed)
    w = rng.normal(size=(2, n, 3))
    w /= np.linalg.norm(w, axis=-1, keepdims=True)
    keep = (np.abs(w[0, :, 2]) > 0.05) & (np.abs(w[1, :, 2]) > 0.05)
    return w[0, keep], w[1, keep]


@pytest.mark.parametrize("eta, ax, ay", [(1.5, 0.3, 0.3), (1.33, 0.1, 0.5), (1.0 / 1.5, 0.6, 0.2)])
def test_transmission_is_walter_eq21_and_reciprocal(eta, ax, ay):
    wo, wi = _random_pairs(4000, SEED)
    args = (eta, ax, ay)
    rad = dl.f_dielectric_ggx(*wo.T, *wi.T, *args, True)
    imp = dl.f_dielectric_ggx(*wo.T, *wi.T, *args, False)
    rad_swapped = dl.f_dielectric_ggx(*wi.T, *wo.T, *args, True)
    imp_swapped = dl.f_dielectric_ggx(*wi.T, *wo.T, *args, False)
    assert np.all(np.isfinite(rad)) and np.all(rad >= 0) and np.all(imp >= 0)
    same = wo[:, 2] * wi[:, 2] > 0
    through = ~same
    assert np.count_nonzero(imp[through] > 0) > 0.1 * np.count_nonzero(through)
    # reflection: the same in both modes and symmetric
    np.testing.assert_array_equal(rad[same], imp[same])
    np.testing.assert_allclose(imp[same], imp_swapped[same], rtol=1e-10, atol=1e-300)
    # transmission: radiance is Walter's eq. 21 (with height-correlated G), importance is eq. 21 * etap^2
    want = walter_eq21(wo[through], wi[through], *args)
    np.testing.assert_allclose(rad[through], want, rtol=1e-9, atol=1e-300)
    eta_o = np.where(wo[:, 2] > 0, 1.0, eta)
    eta_i = np.where(wi[:, 2] > 0, 1.0, eta)
    np.testing.assert_allclose(imp[through], rad[through] * (eta_i / eta_o)[through] ** 2, rtol=1e-12, atol=1e-300)
    # generalised reciprocity (Veach 1997, ch. 5): importance f(wo, wi) / eta_i^2 = f(wi, wo) / eta_o^2,
    # radiance f(wo, wi) / eta_o^2 = f(wi, wo) / eta_i^2
    np.testing.assert_allclose((imp / eta_i ** 2)[through], (imp_swapped / eta_o ** 2)[through], rtol=1e-9,
                               atol=1e-300)
    np.testing.assert_allclose((rad / eta_o ** 2)[through], (rad_swapped / eta_i ** 2)[through], rtol=1e-9,
                               atol=1e-300)


def test_reflection_value_is_d_g_f_over_4_cos_cos():
    wo, wi = _random_pairs(2000, SEED + 1)
    same = wo[:, 2] * wi[:, 2] > 0
    wo, wi = wo[same], wi[same]
    eta, ax, ay = 1.5, 0.25, 0.4
    h = wo + wi
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    h *= np.sign(h[:, 2])[:, None]
    woh = np.sum(wo * h, -1)
    outside = wo[:, 2] > 0
    fr = np.where(outside, fresnel_sp(np.abs(woh), 1.0, eta), fresnel_sp(np.abs(woh), eta, 1.0))
    g = 1.0 / (1.0 + ggx_lambda(wo, ax, ay) + ggx_lambda(wi, ax, ay))
    want = ggx_d(h, ax, ay) * g * fr / (4 * np.abs(wo[:, 2] * wi[:, 2]))
    want = np.where(woh * wo[:, 2] > 0, want, 0.0)
    np.testing.assert_allclose(dl.f_dielectric_ggx(*wo.T, *wi.T, eta, ax, ay), want, rtol=1e-9, atol=1e-300)


# ------------------------------------------------------------------- sampling

#: (id, theta of wo in degrees, inside, eta, alpha_x, alpha_y)
CASES = [
    ("outside-30-a0.3", 30, False, 1.5, 0.3, 0.3),
    ("outside-75-a0.5", 75, False, 1.5, 0.5, 0.5),
    ("outside-45-aniso", 45, False, 1.5, 0.1, 0.4),
    ("inside-20-a0.3", 20, True, 1.5, 0.3, 0.3),  # below the critical angle: TIR on tilted facets
    ("inside-60-a0.3", 60, True, 1.5, 0.3, 0.3),  # beyond the critical angle (41.8 deg): mostly TIR
    ("inside-35-a0.15-aniso", 35, True, 1.5, 0.15, 0.05),
    ("bubble-60-a0.2", 60, False, 1.0 / 1.33, 0.2, 0.2),  # eta < 1 seen from outside: TIR outside
]
ALPHA_TEST = chi2.sidak_alpha(FAMILY_ALPHA, len(CASES))


def _density(fn):
    def density(t, p):
        st = np.sin(t)
        return fn(st * np.cos(p), st * np.sin(p), np.cos(t)) * st

    return density


def _sphere_test(wi, flag, pdf, integrand=None):
    """Chi-square over (theta, phi) cells of the whole sphere plus one cell of failures;
    returns (p, dof, integral of the pdf over the cells, integral of ``integrand``)."""
    n = flag.size
    ok = flag > 0
    theta, phi = chi2.directions_to_spherical(wi[ok])
    density = _density(pdf)
    edges_t, edges_p = chi2.quantile_edges(density, (0.0, np.pi), (0.0, 2.0 * np.pi), (12, 20),
                                           fixed_a=(0.5 * np.pi,))
    probabilities = chi2.cell_integrals(density, edges_t, edges_p)
    integral = float(probabilities.sum())
    observed = np.append(chi2.histogram2d(theta, phi, edges_t, edges_p).ravel(), n - ok.sum())
    expected = np.append(probabilities.ravel(), max(1.0 - integral, 0.0)) * n
    statistic, dof, p = chi2.pearson_chi2(observed, expected)
    other = None if integrand is None else float(chi2.cell_integrals(_density(integrand), edges_t, edges_p).sum())
    return p, dof, integral, other


#: A denser half-vector rule than the default: the integrand has jumps inside the columns
#: (total internal reflection, a refracted direction reaching the horizon).
DENSE_RULE = dict(n_panels=112, n_psi_nodes=32, psi_levels=8)


def _success_probability_over_h(wo, eta, ax, ay):
    """P(a sample succeeds) = int D_v(h) [R 1(reflection above) + (1 - R) 1(refraction through)] dh,
    v = wo turned outside, by the half-vector quadrature (its own D, Lambda, Fresnel, Snell)."""
    inside = wo[2] < 0
    v = wo * np.array([1.0, 1.0, -1.0]) if inside else wo
    n1, n2 = (eta, 1.0) if inside else (1.0, eta)
    h, w = half_vector_rule(ax, ay, theta_max=theta_max_reflected(v), phi_split=math.atan2(v[1], v[0]) + 0.5 * np.pi,
                            **DENSE_RULE)
    reflected = np.sum(w * vndf(v, h, ax, ay) * fresnel_sp(h @ v, n1, n2))
    h, w = half_vector_rule(ax, ay, theta_max=theta_max_visible(v), phi_split=math.atan2(v[1], v[0]) + 0.5 * np.pi,
                            **DENSE_RULE)
    t, tir = refract(np.broadcast_to(v, h.shape), h, n1, n2)
    through = (t[:, 2] < 0) & ~tir
    refracted = np.sum(w * vndf(v, h, ax, ay) * (1.0 - fresnel_sp(h @ v, n1, n2)) * through)
    return reflected + refracted


@pytest.mark.parametrize("case_id, theta, inside, eta, ax, ay", CASES, ids=[c[0] for c in CASES])
def test_sampler_matches_pdf_and_furnace(case_id, theta, inside, eta, ax, ay):
    wo = _direction(theta, inside=inside)
    u, uc = _u(case_id)
    wi, f, pdf, flag = dl.sample_dielectric_ggx(u, uc, wo, eta, ax, ay, radiance=False)
    ok = flag > 0
    assert np.all(np.isfinite(wi)) and np.all(np.abs(np.linalg.norm(wi[ok], axis=-1) - 1) < 1e-12)
    assert set(np.unique(flag)) <= {dl.FAILED, dl.REFLECTION, dl.TRANSMISSION}
    # the sampler's f and pdf are those of the functions at its wi
    np.testing.assert_allclose(f[ok], dl.f_dielectric_ggx(*wo, *wi[ok].T, eta, ax, ay, False), rtol=1e-8)
    np.testing.assert_allclose(pdf[ok], dl.pdf_dielectric_ggx(*wo, *wi[ok].T, eta, ax, ay), rtol=1e-8)
    weight = np.where(ok, f * np.abs(wi[:, 2]) / np.where(ok, pdf, 1.0), 0.0)
    assert weight.max() <= 1.0 + 1e-9  # G2 / G1(wo) <= 1

    p, dof, integral, furnace = _sphere_test(
        wi, flag, lambda x, y, z: dl.pdf_dielectric_ggx(*wo, x, y, z, eta, ax, ay),
        lambda x, y, z: dl.f_dielectric_ggx(*wo, x, y, z, eta, ax, ay, False) * np.abs(z))
    success = _success_probability_over_h(wo, eta, ax, ay)
    estimate, sigma = weight.mean(), weight.std() / math.sqrt(weight.size)
    print(f"{case_id}: chi2 p = {p:.3g} (dof {dof}), int pdf = {integral:.5f}, over h = {success:.5f}, "
          f"sampled = {ok.mean():.5f}, furnace quad = {furnace:.5f}, MC = {estimate:.5f} +- {sigma:.5f}")
    assert p > ALPHA_TEST, f"{case_id}: chi-square rejects the sampler (p = {p:.3g})"
    assert integral <= 1.0 + 1e-4
    # the pdf jumps to 0 along the curve of wi whose h reaches the horizon (D_GGX > 0 there), which the
    # (theta, phi) cells cut across: their integral is good to a few 1e-4 only
    assert integral == pytest.approx(success, abs=1e-3), "the Jacobians of the pdf disagree with the h integral"
    assert ok.mean() == pytest.approx(success, abs=5.0 * math.sqrt(success * (1 - success) / ok.size) + 2e-4)
    assert furnace <= 1.0 + 1e-4
    assert abs(furnace - estimate) < 5.0 * sigma + 2e-4


def test_chi2_rejects_wrong_pdfs():
    """The chi-square cases can fail: the inside sampler against pdfs with the index
    not inverted, a 10% wider alpha, and the refraction Jacobian without its square."""
    wo = _direction(30, inside=True)
    eta, a = 1.5, 0.3
    u, uc = _u("wrong")
    wi, _, _, flag = dl.sample_dielectric_ggx(u, uc, wo, eta, a, a)

    def unsquared(x, y, z):
        pdf = dl.pdf_dielectric_ggx(*wo, x, y, z, eta, a, a)
        hx, hy, hz, etap, _ = dl.half_vector_dielectric(*wo, x, y, z, eta)
        d = (x * hx + y * hy + z * hz) + (wo[0] * hx + wo[1] * hy + wo[2] * hz) / etap
        return np.where(z > 0, pdf * np.abs(d), pdf)

    wrong = {
        "eta not inverted": lambda x, y, z: dl.pdf_dielectric_ggx(*wo, x, y, z, 1.0 / eta, a, a),
        "alpha 0.33": lambda x, y, z: dl.pdf_dielectric_ggx(*wo, x, y, z, eta, 1.1 * a, 1.1 * a),
        "Jacobian unsquared": unsquared,
    }
    for label, pdf in wrong.items():
        p = _sphere_test(wi, flag, pdf)[0]
        assert p < ALPHA_TEST, f"{label} was not rejected (p = {p:.3g})"


# ------------------------------------------------------------------ smooth limit


@pytest.mark.parametrize("theta, inside", [(0, False), (60, False), (30, True), (60, True)])
@pytest.mark.parametrize("alpha", [1e-2, 2e-3])
def test_smooth_limit_tends_to_fresnel(theta, inside, alpha):
    """Directional reflectance (half-vector quadrature of the reflection lobe) and
    transmittance (the same over h, with the refraction Jacobian written here) -> exact R, 1 - R."""
    eta = 1.5
    wo = _direction(theta, phi=0.3, inside=inside)
    v = wo * np.array([1.0, 1.0, -1.0]) if inside else wo
    flip = np.array([1.0, 1.0, -1.0 if inside else 1.0])
    n1, n2 = (eta, 1.0) if inside else (1.0, eta)
    fresnel = float(fresnel_sp(abs(wo[2]), n1, n2))
    l, w = albedo_nodes(v, alpha)
    wi = l * flip
    reflectance = np.sum(w * dl.f_dielectric_ggx(*wo, *wi.T, eta, alpha, alpha, False))
    h, wh = half_vector_rule(alpha, theta_max=theta_max_visible(v), phi_split=0.3 + 0.5 * np.pi)
    t, tir = refract(np.broadcast_to(v, h.shape), h, n1, n2)
    t = t / np.linalg.norm(t, axis=-1, keepdims=True)
    # d omega_h / d omega_t = |t.h| / (t.h + (v.h) n1 / n2)^2 (Walter et al. 2007 eq. 17), written here
    toh = np.sum(t * h, -1)
    jacobian = np.abs(toh) / (toh + (h @ v) * n1 / n2) ** 2
    through = ~tir & (t[:, 2] < 0)
    f = dl.f_dielectric_ggx(*wo, *(t * flip).T, eta, alpha, alpha, False)
    transmittance = np.sum(np.where(through, wh * f * np.abs(t[:, 2]) / np.where(through, jacobian, 1.0), 0.0))
    tol = 2e-3 if alpha > 5e-3 else 2e-4  # measured: 1.0e-3 and 7e-5
    assert reflectance == pytest.approx(fresnel, abs=tol)
    assert transmittance == pytest.approx(1.0 - fresnel, abs=tol)


@pytest.mark.parametrize("alpha", [0.0, 1e-4, dl.SMOOTH_ALPHA])
@pytest.mark.parametrize("theta, inside", [(0, False), (70, False), (30, True), (50, True)])
def test_smooth_interface_is_a_delta_pair(alpha, theta, inside):
    eta = 1.5
    wo = _direction(theta, inside=inside)
    n1, n2 = (eta, 1.0) if inside else (1.0, eta)
    fresnel = float(fresnel_sp(abs(wo[2]), n1, n2))
    u, uc = _u(f"smooth {alpha} {theta} {inside}", 20_000)
    for radiance in (True, False):
        wi, f, pdf, flag = dl.sample_dielectric_ggx(u, uc, wo, eta, alpha, alpha, radiance=radiance)
        assert np.all(flag & dl.SPECULAR)
        refl = (flag & 3) == dl.REFLECTION
        assert refl.mean() == pytest.approx(fresnel, abs=4 * math.sqrt(fresnel * (1 - fresnel) / 20_000) + 1e-12)
        np.testing.assert_allclose(wi[refl], np.broadcast_to(wo * [-1, -1, 1], wi[refl].shape), atol=1e-12)
        np.testing.assert_allclose(pdf[refl], fresnel, rtol=1e-10)
        np.testing.assert_allclose(f[refl] * np.abs(wi[refl, 2]) / pdf[refl], 1.0, rtol=1e-10)
        if fresnel < 1:
            n = np.array([0.0, 0.0, -1.0 if inside else 1.0])
            t, _ = refract(wo, n, n1, n2)
            np.testing.assert_allclose(wi[~refl], np.broadcast_to(t, wi[~refl].shape), atol=1e-12)
            np.testing.assert_allclose(pdf[~refl], 1.0 - fresnel, rtol=1e-10)
            scale = (n1 / n2) ** 2 if radiance else 1.0  # 1 / etap^2, etap = n2 / n1
            np.testing.assert_allclose(f[~refl] * np.abs(wi[~refl, 2]) / pdf[~refl], scale, rtol=1e-10)
        # f and pdf of the delta pair are not functions: 0 everywhere
        assert np.all(dl.f_dielectric_ggx(*wo, *wi.T, eta, alpha, alpha) == 0.0)
        assert np.all(dl.pdf_dielectric_ggx(*wo, *wi.T, eta, alpha, alpha) == 0.0)


def test_degenerate_inputs_stay_finite():
    """Grazing and polar views, the edges of the unit square, index-matched and extreme
    interfaces, huge and tiny alphas: finite samples, f and pdf, nothing below 0."""
    views = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.6, 0.8, 0.0],
                      [math.sqrt(1 - 1e-16), 0.0, 1e-8], [math.sqrt(1 - 1e-16), 0.0, -1e-8]])
    edges = np.array([0.0, 1e-12, 0.5, 1.0 - 1e-12, 1.0])
    u1, u2, uc, k = np.meshgrid(edges, edges, edges, np.arange(len(views)), indexing="ij")
    wo = views[k.ravel()]
    for eta in (1.0, 1.5, 1.0 / 1.5, 1e3):
        for ax, ay in ((1e-3, 1e-3), (1.0001e-3, 1e-3), (0.3, 0.3), (1.0, 1e-3), (1e3, 1e3)):
            with np.errstate(all="ignore"):  # unselected branches (ggx.d_ggx_anisotropic at n.h = 0) may warn
                sample = dl.warp_dielectric_ggx(u1.ravel(), u2.ravel(), np.minimum(uc.ravel(), 1.0 - 1e-16),
                                                *wo.T, eta, ax, ay, True)
                wi = np.stack(sample[:3], axis=-1)
                values = [dl.f_dielectric_ggx(*wo.T, *wi.T, eta, ax, ay),
                          dl.pdf_dielectric_ggx(*wo.T, *wi.T, eta, ax, ay)]
            for part in [*sample[3:5], *values]:
                assert np.all(np.isfinite(part)) and np.all(part >= 0.0), (eta, ax, ay)
            assert np.all(np.isfinite(wi))
            # a direction in the tangent plane scatters nothing
            assert np.all(dl.f_dielectric_ggx(*wo.T, 1.0, 0.0, 0.0, eta, ax, ay) == 0.0)


def test_wrapper_validates():
    wo = _direction(30)
    u, uc = _u("validate", 4)
    for bad in (dict(uc=uc + 1.0), dict(eta=0.0), dict(eta=np.nan), dict(alpha_x=-0.1), dict(alpha_y=np.inf)):
        args = dict(u=u, uc=uc, wo=wo, eta=1.5, alpha_x=0.3, alpha_y=0.3) | bad
        with pytest.raises(ValueError):
            dl.sample_dielectric_ggx(**args)
    with pytest.raises(ValueError):
        dl.sample_dielectric_ggx(u * 2.0, uc, wo, 1.5, 0.3, 0.3)


# ---------------------------------------------------------------------- Numba


@numba.njit(cache=False, error_model="numpy")
def _kernel(u, uc, wo, wi, eta, ax, ay, out):
    for k in range(u.shape[0]):
        s = dl.warp_dielectric_ggx(u[k, 0], u[k, 1], uc[k], wo[k, 0], wo[k, 1], wo[k, 2], eta[k], ax[k], ay[k], True)
        out[k, 0], out[k, 1], out[k, 2], out[k, 3], out[k, 4], out[k, 5] = s[0], s[1], s[2], s[3], s[4], s[5]
        out[k, 6] = dl.f_dielectric_ggx(wo[k, 0], wo[k, 1], wo[k, 2], wi[k, 0], wi[k, 1], wi[k, 2], eta[k], ax[k],
                                        ay[k], False)
        out[k, 7] = dl.pdf_dielectric_ggx(wo[k, 0], wo[k, 1], wo[k, 2], wi[k, 0], wi[k, 1], wi[k, 2], eta[k], ax[k],
                                          ay[k])
        out[k, 8] = dl.fresnel_dielectric(wo[k, 2], eta[k])


@pytest.mark.slow  # compiling the kernel takes ~8 s
def test_kernels_compile_in_numba_and_match_numpy():
    rng = np.random.default_rng(SEED)
    wo, wi = _random_pairs(600, SEED + 2)
    m = len(wo)
    u, uc = rng.random((m, 2)), rng.random(m)
    eta = rng.choice([1.5, 1.0 / 1.33, 2.0], m)
    ax = rng.choice([0.0, 0.05, 0.3, 0.8], m)
    ay = np.where(rng.random(m) < 0.5, ax, rng.uniform(0.01, 1.0, m))
    out = np.empty((m, 9))
    _kernel(u, uc, wo, wi, eta, ax, ay, out)
    parts = list(dl.warp_dielectric_ggx(u[:, 0], u[:, 1], uc, *wo.T, eta, ax, ay, True))
    parts += [dl.f_dielectric_ggx(*wo.T, *wi.T, eta, ax, ay, False), dl.pdf_dielectric_ggx(*wo.T, *wi.T, eta, ax, ay),
              dl.fresnel_dielectric(wo[:, 2], eta)]
    want = np.stack([np.asarray(p, dtype=float) for p in parts], axis=-1)
    assert np.all(np.isfinite(out))
    np.testing.assert_allclose(out, want, rtol=1e-9, atol=1e-12)
