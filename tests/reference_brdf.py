"""Reference microfacet terms for the tests, written from the papers.

Nothing here imports ``pbrkit``: the formulas below are transcribed from the
cited sources, and the integrals use the rules of ``tests/quadrature.py``
(which do not import pbrkit either), so albedos computed here are an
independent check of the package's terms, tables and reports.

Local frame: n = +z (as in ``quadrature.py``); v = (sin theta_v, 0, cos theta_v).
Roughness follows the project's convention (README "Conventions"): perceptual
roughness r, alpha = max(r^2, 1e-3).

:func:`albedo_terms` integrates, for one (n.v, r), every lobe the
approximations report compares (Karis' split-sum A and B, GGX with the Fresnel
and masking variants, URP's mobile term) on ONE set of light directions, so
that a 32 x 32 grid costs one node construction per cell.
"""

from __future__ import annotations

import numpy as np
from quadrature import albedo_nodes, view_direction

__all__ = [
    "ALPHA_MIN",
    "GOLD_ETA_K",
    "RULE",
    "albedo_maps",
    "albedo_terms",
    "alpha_of",
    "burley_diffuse",
    "comparison_values",
    "d_beckmann_anisotropic",
    "d_blinn_phong",
    "d_ggx",
    "d_ggx_anisotropic",
    "d_gtr1",
    "disney_subsurface",
    "env_brdf_approx_karis",
    "eon_diffuse",
    "fresnel_conductor",
    "fresnel_dielectric",
    "fresnel_schlick",
    "fresnel_schlick_f90",
    "fresnel_schlick_pow4",
    "fresnel_ue4_sg",
    "g1_schlick",
    "ggx_albedo",
    "lambda_beckmann_anisotropic",
    "lambda_ggx",
    "lambda_ggx_anisotropic",
    "texel_grid",
    "urp_specular_term",
    "v_kelemen",
]

#: alpha = max(r^2, ALPHA_MIN) (README "Conventions").
ALPHA_MIN = 1e-3

#: Gold's complex IOR (eta, k) at the linear-sRGB primaries: Mitsuba's spectral
#: data (after Palik) integrated to RGB -- the values the report's "gold" uses.
GOLD_ETA_K = ((0.143119, 0.374957, 1.44248), (3.98316, 2.38572, 1.60322))


#: The rule options of ``quadrature.albedo_nodes`` used for the report's grids:
#: 40 panels of 5 nodes along each column (the lobe's log-slope variable) and
#: 5-node psi panels, 5 levels of grading (24 000 nodes per (n.v, r)).
#: Measured on the 32 x 32 texel grid: every albedo here within 1.4e-6 of a rule
#: ~10x denser (n_psi_nodes=12, psi_levels=9, n_panels=80, n_nodes=8; rows
#: r = 0.5/32, 1.5/32, 2.5/32, 4.5/32, ..., 31.5/32, every n.v), except URP's, whose
#: max(0.1, (l.h)^2) kink lies on no cut: within 1.7e-4 of a rule ~20x denser
#: (n_psi_nodes=16, psi_levels=10, n_panels=120, n_nodes=10; every cell; worst at
#: grazing n.v, r ~ 0.5).
RULE = {"n_psi_nodes": 5, "psi_levels": 5, "n_panels": 40, "n_nodes": 5}


def texel_grid(n):
    """Texel centres (i + 0.5) / n (CONVENTIONS: table columns / rows)."""
    return (np.arange(n) + 0.5) / n


def alpha_of(r):
    return max(float(r) ** 2, ALPHA_MIN)


# ---------------------------------------------------------------- microfacet terms


def d_ggx(cos_h, sin2_h, alpha):
    """GGX / Trowbridge-Reitz D = alpha^2 / (pi (cos^2 theta_h (alpha^2 - 1) + 1)^2)
    (Walter et al. 2007, eq. 33), with the denominator written as
    alpha^2 cos^2 + sin^2 from the direction's own components."""
    a2 = alpha * alpha
    t = a2 * cos_h * cos_h + sin2_h
    return np.where(cos_h > 0.0, a2 / (np.pi * t * t), 0.0)


def lambda_ggx(cos_t, alpha):
    """Smith Lambda of GGX, (-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2 (Heitz 2014, eq. 72)."""
    c2 = cos_t * cos_t
    tan2 = (1.0 - c2) / c2
    return 0.5 * (np.sqrt(1.0 + alpha * alpha * tan2) - 1.0)


def g1_schlick(cos_t, k):
    """Schlick's G1 = cos / (cos (1 - k) + k) (Schlick 1994; Karis 2013, eq. 4)."""
    return cos_t / (cos_t * (1.0 - k) + k)


def d_ggx_anisotropic(hx, hy, hz, alpha_x, alpha_y):
    """Anisotropic GGX of a unit half vector h in the local frame (tangent x, normal z),
    D = 1 / (pi a_x a_y ((h_x / a_x)^2 + (h_y / a_y)^2 + h_z^2)^2) (Burley 2012, App. B.2,
    eq. 13; Heitz 2014, eq. 85); zero for h_z <= 0.  With a_x = a_y = alpha it is
    Walter et al.'s eq. 33 (:func:`d_ggx`)."""
    s = (hx / alpha_x) ** 2 + (hy / alpha_y) ** 2 + hz * hz
    return np.where(hz > 0.0, 1.0 / (np.pi * alpha_x * alpha_y * s * s), 0.0)


def lambda_ggx_anisotropic(wx, wy, wz, alpha_x, alpha_y):
    """Smith Lambda of anisotropic GGX for a unit direction w (local frame),
    (-1 + sqrt(1 + alpha_o^2 tan^2 theta)) / 2 with alpha_o^2 tan^2 theta =
    (alpha_x^2 w_x^2 + alpha_y^2 w_y^2) / w_z^2 (Heitz 2014, eqs. 72 and 86)."""
    t = ((alpha_x * wx) ** 2 + (alpha_y * wy) ** 2) / (wz * wz)
    return 0.5 * (np.sqrt(1.0 + t) - 1.0)


def d_beckmann_anisotropic(hx, hy, hz, alpha_x, alpha_y):
    """Beckmann D = exp(-((h_x / a_x)^2 + (h_y / a_y)^2) / h_z^2) / (pi a_x a_y h_z^4)
    (Heitz 2014, eq. 84); with a_x = a_y = alpha it is Walter et al. 2007's eq. 25,
    exp(-tan^2 theta_h / alpha^2) / (pi alpha^2 cos^4 theta_h).  Zero for h_z <= 0."""
    z = np.where(hz > 0.0, hz, 1.0)
    e = ((hx / alpha_x) ** 2 + (hy / alpha_y) ** 2) / (z * z)
    return np.where(hz > 0.0, np.exp(-e) / (np.pi * alpha_x * alpha_y * z ** 4), 0.0)


def lambda_beckmann_anisotropic(wx, wy, wz, alpha_x, alpha_y):
    """Smith Lambda of Beckmann, Lambda = (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi)),
    a = 1 / (alpha_o tan theta) = w_z / sqrt(alpha_x^2 w_x^2 + alpha_y^2 w_y^2)
    (Heitz 2014, eqs. 83 and 86; Walter et al. 2007, eq. 27 gives G1 = 1 / (1 + Lambda));
    0 at normal incidence (a infinite).  erf from SciPy."""
    from scipy.special import erf

    root = np.sqrt((alpha_x * wx) ** 2 + (alpha_y * wy) ** 2)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        a = wz / root
        lam = 0.5 * (erf(a) - 1.0) + np.exp(-a * a) / (2.0 * a * np.sqrt(np.pi))
    return np.where(root > 0.0, lam, 0.0)


def d_blinn_phong(cos_h, alpha):
    """Normalised Blinn-Phong D = (e + 2) / (2 pi) cos^e theta_h with the exponent of the
    Beckmann width, e = 2 / alpha^2 - 2 (Blinn 1977; Walter et al. 2007, eq. 30);
    zero for cos theta_h <= 0."""
    e = 2.0 / (alpha * alpha) - 2.0
    c = np.clip(cos_h, 0.0, 1.0)
    return np.where(cos_h > 0.0, (e + 2.0) / (2.0 * np.pi) * c ** e, 0.0)


def d_gtr1(cos_h, sin2_h, alpha):
    """GTR with gamma = 1 (Berry 1923), D = (alpha^2 - 1) / (pi ln(alpha^2) (alpha^2 cos^2 theta_h
    + sin^2 theta_h)) (Burley 2012, App. B.1, eq. 4; the BRDF Explorer's ``GTR1``, whose
    t = 1 + (alpha^2 - 1) cos^2 is written here from the components); zero for cos <= 0."""
    a2 = alpha * alpha
    return np.where(cos_h > 0.0, (a2 - 1.0) / (np.pi * np.log(a2) * (a2 * cos_h * cos_h + sin2_h)), 0.0)


def v_kelemen(lov):
    """Kelemen & Szirmay-Kalos 2001 ("A Microfacet Based Coupled Specular-Matte BRDF Model
    with Importance Sampling"): G / ((n.l)(n.v)) ~ 2 / (1 + l.v), so the visibility
    V = G / (4 n.l n.v) = 1 / (2 (1 + l.v)) (= 1 / (4 (l.h)^2))."""
    return 0.5 / (1.0 + lov)


# ---------------------------------------------------------------- Fresnel


def fresnel_schlick(c, f0):
    """Schlick 1994, eq. 15: F = f0 + (1 - f0)(1 - c)^5."""
    m = 1.0 - c
    m2 = m * m
    return f0 + (1.0 - f0) * (m2 * m2 * m)


def fresnel_schlick_f90(c, f0, f90):
    """Schlick's F with a grazing value f90, F = f0 + (f90 - f0)(1 - c)^5 (Filament
    documentation sec. 4.4.3, ``F_Schlick(u, f0, f90)``; Schlick 1994 with f90 = 1)."""
    m = 1.0 - c
    m2 = m * m
    return f0 + (f90 - f0) * (m2 * m2 * m)


def fresnel_schlick_pow4(c, f0):
    """The fourth-power variant (Unity URP's Pow4(1 - c))."""
    m2 = (1.0 - c) * (1.0 - c)
    return f0 + (1.0 - f0) * (m2 * m2)


def fresnel_ue4_sg(c, f0):
    """UE4's spherical-Gaussian Schlick, F = f0 + (1 - f0) 2^((-5.55473 c - 6.98316) c)
    (Karis 2013, eq. 5)."""
    return f0 + (1.0 - f0) * np.exp2((-5.55473 * c - 6.98316) * c)


def fresnel_dielectric(c, eta):
    """Unpolarised Fresnel reflectance of a dielectric (Walter et al. 2007, eq. 22;
    Cook & Torrance 1982): g = sqrt(eta^2 - 1 + c^2),
    F = (g - c)^2 / (2 (g + c)^2) (1 + ((c (g + c) - 1) / (c (g - c) + 1))^2)."""
    g = np.sqrt(eta * eta - 1.0 + c * c)
    a = (g - c) / (g + c)
    b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
    return 0.5 * a * a * (1.0 + b * b)


def fresnel_conductor(c, eta, k):
    """Unpolarised Fresnel reflectance of a conductor eta + i k in real arithmetic
    (S. Lagarde, "Memo on Fresnel equations", 2013, after Born & Wolf 14.2):
    a^2 + b^2 = sqrt((eta^2 - k^2 - sin^2)^2 + 4 eta^2 k^2), a = sqrt((a^2 + b^2 + eta^2 - k^2 - sin^2) / 2),
    R_s = (a^2 + b^2 + cos^2 - 2 a cos) / (a^2 + b^2 + cos^2 + 2 a cos),
    R_p = R_s (cos^2 (a^2 + b^2) + sin^4 - 2 a cos sin^2) / (cos^2 (a^2 + b^2) + sin^4 + 2 a cos sin^2)."""
    c2 = c * c
    s2 = 1.0 - c2
    t0 = eta * eta - k * k - s2
    a2b2 = np.sqrt(t0 * t0 + 4.0 * eta * eta * k * k)
    a = np.sqrt(0.5 * (a2b2 + t0))
    rs = (a2b2 + c2 - 2.0 * a * c) / (a2b2 + c2 + 2.0 * a * c)
    t1 = a2b2 * c2 + s2 * s2
    t2 = 2.0 * a * c * s2
    return 0.5 * (rs + rs * (t1 - t2) / (t1 + t2))


# ---------------------------------------------------------------- real-time shortcuts


def env_brdf_approx_karis(nov, r):
    """Karis 2014, "Physically Based Shading on Mobile" (``EnvBRDFApprox``):
    c0 = (-1, -0.0275, -0.572, 0.022), c1 = (1, 0.0425, 1.04, -0.04), q = r c0 + c1,
    a004 = min(q.x^2, exp2(-9.28 n.v)) q.x + q.y, (A, B) = (-1.04, 1.04) a004 + q.zw."""
    qx, qy, qz, qw = (-r + 1.0, -0.0275 * r + 0.0425, -0.572 * r + 1.04, 0.022 * r - 0.04)
    a004 = np.minimum(qx * qx, 2.0 ** (-9.28 * nov)) * qx + qy
    return -1.04 * a004 + qz, 1.04 * a004 + qw


def urp_specular_term(cos_h, sin2_h, loh, alpha):
    """Unity URP ``DirectBRDFSpecular`` (Zioma 2015, "Optimizing PBR for Mobile"):
    alpha^2 / (d^2 max(0.1, (l.h)^2) (4 alpha + 2)), d = (n.h)^2 (alpha^2 - 1) + 1;
    Unity's lights carry pi, so the BRDF is this / pi (times the specular colour)."""
    a2 = alpha * alpha
    d = a2 * cos_h * cos_h + sin2_h
    return a2 / (d * d * np.maximum(0.1, loh * loh) * (4.0 * alpha + 2.0)) / np.pi


# ---------------------------------------------------------------- albedos


def _lobe_nodes(mu, r, rule, clamp=True):
    """alpha, v, and the light directions l (N, 3), weights (N,) (n.l included) and
    half vectors h (N, 3) of the nodes that reflect v above the horizon.  ``clamp``:
    alpha = max(r^2, ALPHA_MIN) as shading does, else r^2 as the lookup tables do."""
    alpha = alpha_of(r) if clamp else float(r) ** 2
    v = view_direction(mu)
    l, w = albedo_nodes(v, alpha, **(rule or {}))
    keep = w > 0.0
    l, w = l[keep], w[keep]
    h = l + v
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    return alpha, v, l, w, h


def ggx_albedo(mu, r, f0=(), rule=None):
    """(E, S) for GGX with height-correlated Smith G2 (Heitz 2014, eqs. 72 and 99) at
    n.v = mu, roughness r: E the white-furnace albedo (F = 1) and S[c] the albedo with
    Schlick's Fresnel of normal reflectance f0[c]."""
    alpha, v, l, w, h = _lobe_nodes(mu, r, rule)
    nol = l[:, 2]
    g2 = 1.0 / (1.0 + lambda_ggx(nol, alpha) + lambda_ggx(mu, alpha))
    fcos = w * d_ggx(h[:, 2], h[:, 0] ** 2 + h[:, 1] ** 2, alpha) * g2 / (4.0 * nol * mu)
    voh = np.clip(h[:, 0] * v[0] + h[:, 1] * v[1] + h[:, 2] * v[2], 0.0, 1.0)
    f0 = np.atleast_1d(np.asarray(f0, dtype=float))
    return float(np.sum(fcos)), np.sum(fresnel_schlick(voh[None, :], f0[:, None]) * fcos, axis=-1)


def split_sum_terms(mu, r, rule=None):
    """(A, B) of Karis' split sum (Schlick-GGX k = alpha / 2) at alpha = r^2 unclamped,
    the roughness the lookup tables integrate (their row 0 lies below ALPHA_MIN)."""
    alpha, v, l, w, h = _lobe_nodes(mu, r, rule, clamp=False)
    nol = l[:, 2]
    voh = np.clip(h @ v, 0.0, 1.0)
    k = 0.5 * alpha
    g = g1_schlick(nol, k) * g1_schlick(mu, k)
    weight = w * d_ggx(h[:, 2], h[:, 0] ** 2 + h[:, 1] ** 2, alpha) * g / (4.0 * nol * mu)
    fc = fresnel_schlick(voh, 0.0)
    return float(np.sum(weight * (1.0 - fc))), float(np.sum(weight * fc))


def albedo_terms(mu, r, rule=None):
    """Directional albedos (integral of f (n.l) dl) at n.v = mu, roughness r.

    Returns a dict of floats (or RGB arrays for gold):

    - ``A``, ``B``: split-sum scale and bias with Schlick-GGX k = alpha / 2
      (Karis 2013), i.e. integral of D G (1 - Fc) / (4 n.v) and of D G Fc / (4 n.v),
      Fc = (1 - v.h)^5, at the tables' unclamped alpha = r^2 (:func:`split_sum_terms`);
    - ``hc_*``: GGX with height-correlated Smith G2 = 1 / (1 + Lambda_l + Lambda_v)
      (Heitz 2014, eq. 99) and Fresnel ``schlick004`` / ``pow4_004`` / ``sg004``
      (f0 = 0.04), ``dielectric`` (exact, IOR 1.5), ``schlick1`` (f0 = 1),
      ``gold_schlick`` / ``gold_exact`` (RGB; Schlick with f0 = exact F at normal incidence);
    - ``sep_smith``, ``sep_schlick_ibl``, ``sep_schlick_ue4``: F = 1 with separable
      G1 G1 of exact Smith, Schlick k = alpha / 2, Schlick k = (r + 1)^2 / 8;
    - ``urp``: URP's term with specular colour 1 (scale by f0 for other colours).
    """
    alpha, v, l, w, h = _lobe_nodes(mu, r, rule)
    nol = l[:, 2]
    cos_h = h[:, 2]
    sin2_h = h[:, 0] ** 2 + h[:, 1] ** 2
    voh = np.clip(h[:, 0] * v[0] + h[:, 1] * v[1] + h[:, 2] * v[2], 0.0, 1.0)
    d = d_ggx(cos_h, sin2_h, alpha)
    # w already carries n.l: f (n.l) = D G2 / (4 n.l n.v) (n.l) -> weight D G2 / (4 n.l n.v).
    base = w * d / (4.0 * nol * mu)
    lam_l, lam_v = lambda_ggx(nol, alpha), lambda_ggx(mu, alpha)
    g_hc = 1.0 / (1.0 + lam_l + lam_v)
    g_sep = 1.0 / ((1.0 + lam_l) * (1.0 + lam_v))
    k_ibl = 0.5 * alpha
    k_ue4 = (r + 1.0) ** 2 / 8.0
    g_ibl = g1_schlick(nol, k_ibl) * g1_schlick(mu, k_ibl)
    g_ue4 = g1_schlick(nol, k_ue4) * g1_schlick(mu, k_ue4)
    fc = fresnel_schlick(voh, 0.0)  # (1 - v.h)^5
    hc = base * g_hc
    a_table, b_table = split_sum_terms(mu, r, rule) if float(r) ** 2 < ALPHA_MIN else (
        float(np.sum(base * g_ibl * (1.0 - fc))), float(np.sum(base * g_ibl * fc)))
    out = {
        "A": a_table,
        "B": b_table,
        "hc_schlick1": float(np.sum(hc)),
        "hc_schlick004": float(np.sum(hc * fresnel_schlick(voh, 0.04))),
        "hc_pow4_004": float(np.sum(hc * fresnel_schlick_pow4(voh, 0.04))),
        "hc_sg004": float(np.sum(hc * fresnel_ue4_sg(voh, 0.04))),
        "hc_dielectric": float(np.sum(hc * fresnel_dielectric(voh, 1.5))),
        "sep_smith": float(np.sum(base * g_sep)),
        "sep_schlick_ibl": float(np.sum(base * g_ibl)),
        "sep_schlick_ue4": float(np.sum(base * g_ue4)),
        "urp": float(np.sum(w * urp_specular_term(cos_h, sin2_h, voh, alpha))),
    }
    eta, k = (np.asarray(x)[:, None] for x in GOLD_ETA_K)  # (3, 1): channels first is faster
    f0_gold = np.minimum(fresnel_conductor(1.0, eta, k), 1.0)
    # (sums rather than BLAS products: no thread start-up per cell)
    out["gold_schlick"] = np.sum(fresnel_schlick(voh, f0_gold) * hc, axis=-1)
    out["gold_exact"] = np.sum(fresnel_conductor(voh, eta, k) * hc, axis=-1)
    return out


def comparison_values(t, mu, r):
    """The report's comparisons (``pbrkit approximations``) at one cell, from
    :func:`albedo_terms` ``t``: approximation minus reference, as documented in
    README's "pbrkit approximations" section."""
    a, b = env_brdf_approx_karis(mu, r)
    gold = t["gold_schlick"] - t["gold_exact"]
    return {
        "karis-env-brdf-a": a - t["A"],
        "karis-env-brdf-b": b - t["B"],
        "ue4-sg-vs-schlick": t["hc_sg004"] - t["hc_schlick004"],
        "pow4-vs-pow5": t["hc_pow4_004"] - t["hc_schlick004"],
        "schlick-vs-exact-dielectric": t["hc_schlick004"] - t["hc_dielectric"],
        # the channel with the largest |error|, signed
        "schlick-vs-exact-gold": float(gold[np.argmax(np.abs(gold))]),
        "schlick-ggx-ibl-vs-smith": t["sep_schlick_ibl"] - t["sep_smith"],
        "schlick-ggx-ue4-vs-smith": t["sep_schlick_ue4"] - t["sep_smith"],
        "urp-vs-ggx-f1": t["urp"] - t["hc_schlick1"],
        "urp-vs-ggx-f004": 0.04 * t["urp"] - t["hc_schlick004"],
    }


def albedo_maps(n, rule=None):
    """``{comparison: (n, n) array}`` indexed [j (roughness), i (n.v)] on the texel
    grid of size n, like the report (:func:`comparison_values` at every cell)."""
    axis = texel_grid(n)
    maps = {}
    for j in range(n):
        for i in range(n):
            values = comparison_values(albedo_terms(axis[i], axis[j], rule), axis[i], axis[j])
            for name, value in values.items():
                maps.setdefault(name, np.empty((n, n)))[j, i] = value
    return maps


# ---------------------------------------------------------------- diffuse lobes


def burley_diffuse(nol, nov, loh, r):
    """Burley's diffuse factor (times the base colour), Burley 2012, sec. 5.3, eq. 3 and
    the BRDF Explorer's ``disney.brdf`` (``Fd``): (1 / pi) (1 + (F_D90 - 1)(1 - n.l)^5)
    (1 + (F_D90 - 1)(1 - n.v)^5), F_D90 = 0.5 + 2 r cos^2 theta_d, cos theta_d = l.h,
    r the roughness the caller passes (Burley: the perceptual roughness)."""
    fd90 = 0.5 + 2.0 * r * loh * loh
    fl = (1.0 - nol) ** 5
    fv = (1.0 - nov) ** 5
    return (1.0 + (fd90 - 1.0) * fl) * (1.0 + (fd90 - 1.0) * fv) / np.pi


def disney_subsurface(nol, nov, loh, r):
    """Disney's subsurface approximation (times the base colour), the BRDF Explorer's
    ``disney.brdf`` (Burley 2012, sec. 5.3, after Hanrahan & Krueger 1993):
    F_ss90 = r (l.h)^2, F_ss = mix(1, F_ss90, (1 - n.l)^5) mix(1, F_ss90, (1 - n.v)^5),
    ss = 1.25 (F_ss (1 / (n.l + n.v) - 0.5) + 0.5); the factor is ss / pi."""
    fss90 = r * loh * loh
    fl = (1.0 - nol) ** 5
    fv = (1.0 - nov) ** 5
    fss = (1.0 + (fss90 - 1.0) * fl) * (1.0 + (fss90 - 1.0) * fv)
    return 1.25 * (fss * (1.0 / (nol + nov) - 0.5) + 0.5) / np.pi


def eon_diffuse(l, v, rho, r):
    """EON, the energy-preserving Oren-Nayar diffuse (Portsmouth, Kutz & Hill 2025,
    "EON: A practical energy-preserving rough diffuse BRDF", JCGT 14(1); OpenPBR 1.1's
    diffuse), written from the paper: Fujii's lobe (FON)

        f_FON = (rho / pi) A (1 + r s / t),  s = l.v - (n.l)(n.v),  t = max(n.l, n.v) if s > 0 else 1,
        A = 1 / (1 + c1 r),  c1 = 1/2 - 2 / (3 pi),

    plus the multiple-scattering lobe that restores the energy FON loses,

        f_ms = (rho_ms / pi) (1 - E_F(n.l)) (1 - E_F(n.v)) / (1 - E_avg),
        rho_ms = rho^2 E_avg / (1 - rho (1 - E_avg)),  E_avg = A (1 + c2 r),  c2 = 2/3 - 28 / (15 pi),

    with FON's albedo in closed form, E_F(mu) = A + (r A / pi) G(mu),
    G(mu) = S (acos mu - S mu) + (2/3)((S / mu)(1 - S^3) - S), S = sqrt(1 - mu^2).
    At r = 0 FON is Lambert and loses nothing: no multiple-scattering lobe.

    l, v: directions (..., 3) (normal +z, broadcastable); rho: the diffuse colour
    (..., 3); r: the perceptual roughness (...).  Returns f (..., 3) for n.l, n.v > 0
    (no horizon test here)."""
    l = np.asarray(l, dtype=float)
    v = np.asarray(v, dtype=float)
    rho = np.asarray(rho, dtype=float)
    r = np.asarray(r, dtype=float)
    c1 = 0.5 - 2.0 / (3.0 * np.pi)
    c2 = 2.0 / 3.0 - 28.0 / (15.0 * np.pi)
    a = 1.0 / (1.0 + c1 * r)

    def e_f(mu):
        s = np.sqrt(1.0 - mu * mu)
        g = s * (np.arccos(mu) - s * mu) + 2.0 / 3.0 * ((s / mu) * (1.0 - s ** 3) - s)
        return a + r * a / np.pi * g

    nol, nov = l[..., 2], v[..., 2]
    s = np.sum(l * v, axis=-1) - nol * nov
    s_over_t = np.where(s > 0.0, s / np.maximum(nol, nov), s)
    single = a * (1.0 + r * s_over_t) / np.pi
    e_avg = a * (1.0 + c2 * r)
    lost = 1.0 - e_avg
    with np.errstate(divide="ignore", invalid="ignore"):
        shape = np.where(lost > 0.0, (1.0 - e_f(nol)) * (1.0 - e_f(nov)) / lost, 0.0)
    e_avg = e_avg[..., None]
    rho_ms = rho * rho * e_avg / (1.0 - rho * (1.0 - e_avg))
    return rho * single[..., None] + rho_ms / np.pi * shape[..., None]
