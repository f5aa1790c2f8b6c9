"""Reference microfacet terms for the tests, written from the papers.

Nothing here imports ``pbrkit``: the formulas below are transcribed from the
cited sources, and the integrals use the rules of ``tests/support/quadrature.py``
(which do not import pbrkit either), so albedos computed here are an
independent check of the package's terms, tables and reports.

Local frame: n = +z (as in ``quadrature.py``); v = (sin theta_v, 0, cos theta_v).
Roughness follows the project's convention (README "Conventions"): perceptual
roughness r, alpha = max(r^2, 1e-3).

:func:`albedo_terms` integrates, for one (n.v, r), every lobe the
approximations report compares (Karis' split-sum A and B, GGX with the Fresnel
and masking variants, URP's mobile term) on ONE set of light directions, so
that a 32 x 32 grid costs one node construction per cell.

The second half holds full-model transcriptions of pbrkit's shading models,
each written from its published source (glTF 2.0 Appendix B, Karis 2013, the
Filament documentation, Unity URP's ``BRDF.hlsl``, Burley 2012 and the BRDF
Explorer's ``disney.brdf``, a Cook-Torrance with every D / G / F / diffuse
choice, EON of Portsmouth, Kutz & Hill 2025, glTF under KHR_materials_sheen's
Charlie sheen and albedo scaling): vectorised NumPy functions of
light and view directions l, v (N, 3) in the local frame (normal +z, tangent +x,
bitangent +y) and per-element material values, returning the BRDF value f
(N, 3) -- not f cos -- and 0 unless n.l > 0 and n.v > 0.
``tests/brdf/test_model_values.py`` checks pbrkit's NumPy API against them.
"""

from __future__ import annotations

import numpy as np
from quadrature import albedo_nodes, view_direction

__all__ = [
    "ALPHA_MIN",
    "CT_DIFFUSES",
    "CT_DISTRIBUTIONS",
    "CT_FRESNELS",
    "CT_MASKINGS",
    "Geometry",
    "GOLD_ETA_K",
    "RULE",
    "albedo_maps",
    "albedo_terms",
    "alpha_of",
    "burley_diffuse",
    "charlie_albedo",
    "charlie_d",
    "charlie_lambda",
    "charlie_v",
    "comparison_values",
    "cook_torrance_brdf",
    "d_beckmann_anisotropic",
    "d_blinn_phong",
    "d_ggx",
    "d_ggx_anisotropic",
    "d_gtr1",
    "disney_brdf",
    "disney_subsurface",
    "env_brdf_approx_karis",
    "eon_diffuse",
    "filament_brdf",
    "fresnel_conductor",
    "fresnel_dielectric",
    "fresnel_schlick",
    "fresnel_schlick_f90",
    "fresnel_schlick_pow4",
    "fresnel_ue4_sg",
    "g1_schlick",
    "ggx_albedo",
    "gltf_brdf",
    "gltf_sheen_brdf",
    "lambda_beckmann_anisotropic",
    "lambda_ggx",
    "lambda_ggx_anisotropic",
    "sheen_albedo_bilinear",
    "texel_grid",
    "ue4_brdf",
    "urp_mobile_brdf",
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


# ---------------------------------------------------------------- full models
#
# Each model below is a function of l, v (N, 3) in the local frame (normal +z,
# tangent +x, bitangent +y; unit length) and per-element material values (base
# colour (N, 3), scalars (N,)), returning f (N, 3), zero unless n.l > 0 and n.v > 0.
# Roughness: alpha = max(r^2, ALPHA_MIN) (README "Conventions"), anisotropic alphas
# as each model documents them.


class Geometry:
    """l, v, the half vector h = (l + v) / |l + v| and their cosines in the local frame:
    n.l, n.v, n.h = h_z, v.h (= l.h), l.v, sin^2 theta_h = h_x^2 + h_y^2 (from the
    components, without cancellation), and ``above``: n.l > 0 and n.v > 0."""

    def __init__(self, l, v):
        self.l = l = np.asarray(l, dtype=float)
        self.v = v = np.asarray(v, dtype=float)
        h = l + v
        length = np.linalg.norm(h, axis=-1, keepdims=True)
        self.h = h = np.where(length > 0.0, h / np.where(length > 0.0, length, 1.0), (0.0, 0.0, 1.0))
        self.nol, self.nov, self.noh = l[..., 2], v[..., 2], h[..., 2]
        self.voh = np.sum(v * h, axis=-1)
        self.lov = np.sum(l * v, axis=-1)
        self.sin2h = h[..., 0] ** 2 + h[..., 1] ** 2
        self.above = (self.nol > 0.0) & (self.nov > 0.0)

    def only_above(self, f):
        """f (N, 3) where l and v are above the surface, else 0."""
        return np.where(self.above[..., None], f, 0.0)


def _alpha(r):
    return np.maximum(np.asarray(r, dtype=float) ** 2, ALPHA_MIN)


def _rgb(x):
    """A per-element scalar as a column against RGB."""
    return np.asarray(x, dtype=float)[..., None]


def _inputs(l, v, roughness, base, metallic, anisotropy):
    """The inputs of an anisotropic model as arrays: the geometry, the perceptual
    roughness r, alpha = r^2 (clamped), the base colour, metallic as a column against
    RGB and the anisotropy broadcast against alpha."""
    r = np.asarray(roughness, dtype=float)
    alpha = _alpha(r)
    return (Geometry(l, v), r, alpha, np.asarray(base, dtype=float), _rgb(metallic),
            np.asarray(anisotropy, dtype=float) + np.zeros_like(alpha))


def _mix(a, b, t):
    """GLSL's mix(a, b, t) = a (1 - t) + b t."""
    return a * (1.0 - t) + b * t


def _smith_ggx_visibility_separable(nol, nov, alpha):
    """The separable Smith-GGX visibility of glTF 2.0 Appendix B.3.2,
    V = 1 / ((|N.L| + sqrt(alpha^2 + (1 - alpha^2)(N.L)^2)) (|N.V| + sqrt(alpha^2 + (1 - alpha^2)(N.V)^2)))
    (= G1(l) G1(v) / (4 |N.L| |N.V|), G1 = 2 |N.X| / (|N.X| + sqrt(alpha^2 + (1 - alpha^2)(N.X)^2)))."""
    a2 = alpha * alpha
    return 1.0 / ((np.abs(nol) + np.sqrt(a2 + (1.0 - a2) * nol * nol))
                  * (np.abs(nov) + np.sqrt(a2 + (1.0 - a2) * nov * nov)))


def gltf_brdf(l, v, base, metallic, roughness):
    """The glTF 2.0 metallic-roughness BRDF as the specification's Appendix B writes it
    (B.2.2, B.3.1 - B.3.5), mixed literally (not folded into one f0):

        material = mix(dielectric_brdf, metal_brdf, metallic)
        metal_brdf = conductor_fresnel(f0 = baseColor, specular_brdf(alpha))
                   = specular_brdf(alpha) (baseColor + (1 - baseColor)(1 - |V.H|)^5)
        dielectric_brdf = fresnel_mix(ior = 1.5, diffuse_brdf(baseColor), specular_brdf(alpha))
                   = mix(baseColor / pi, specular_brdf(alpha), f0 + (1 - f0)(1 - |V.H|)^5),
                     f0 = ((1 - ior) / (1 + ior))^2 = 0.04
        specular_brdf(alpha) = V D, D = alpha^2 / (pi ((N.H)^2 (alpha^2 - 1) + 1)^2) (:func:`d_ggx`),
        V the separable Smith-GGX visibility (B.3.2), alpha = roughness^2."""
    g = Geometry(l, v)
    alpha = _alpha(roughness)
    with np.errstate(all="ignore"):
        spec = (d_ggx(g.noh, g.sin2h, alpha) * _smith_ggx_visibility_separable(g.nol, g.nov, alpha))[..., None]
        fc = ((1.0 - np.abs(g.voh)) ** 5)[..., None]
        base = np.asarray(base, dtype=float)
        metal = spec * (base + (1.0 - base) * fc)
        ior = 1.5
        f0 = ((1.0 - ior) / (1.0 + ior)) ** 2
        dielectric = _mix(base / np.pi, spec, f0 + (1.0 - f0) * fc)
        f = _mix(dielectric, metal, _rgb(metallic))
    return g.only_above(f)


def ue4_brdf(l, v, base, metallic, roughness, reflectance):
    """Unreal Engine 4 (Karis 2013, "Real Shading in Unreal Engine 4"):

        f = c_diff / pi + D F G / (4 n.l n.v),

    D GGX of alpha = r^2 (eq. 2), G = G1(l) G1(v) Schlick's with the direct-light
    k = (r + 1)^2 / 8 (eq. 4, r the perceptual roughness), F the spherical-Gaussian
    Schlick F0 + (1 - F0) 2^((-5.55473 v.h - 6.98316) v.h) (eq. 5); metallic workflow
    c_diff = base (1 - metallic), F0 = lerp(0.08 specular, base, metallic) with UE4's
    Specular s expressed as the project's reflectance, 0.08 s = 0.16 reflectance^2."""
    g = Geometry(l, v)
    r = np.asarray(roughness, dtype=float)
    alpha = _alpha(r)
    k = (r + 1.0) ** 2 / 8.0
    base = np.asarray(base, dtype=float)
    with np.errstate(all="ignore"):
        f0 = _mix(_rgb(0.16 * np.asarray(reflectance) ** 2), base, _rgb(metallic))
        dg = d_ggx(g.noh, g.sin2h, alpha) * g1_schlick(g.nol, k) * g1_schlick(g.nov, k) / (4.0 * g.nol * g.nov)
        f = base * (1.0 - _rgb(metallic)) / np.pi + fresnel_ue4_sg(g.voh[..., None], f0) * dg[..., None]
    return g.only_above(f)


def filament_brdf(l, v, base, metallic, roughness, reflectance, anisotropy, diffuse="lambert",
                  burley_roughness="alpha"):
    """Filament's standard model (Filament documentation, "Physically Based Rendering in
    Filament", sec. 4), f = diffuseColor f_d + D V F:

    - sec. 4.8.3 (remapping): alpha = perceptualRoughness^2, diffuseColor = (1 - metallic)
      baseColor, f0 = 0.16 reflectance^2 (1 - metallic) + baseColor metallic;
    - sec. 4.4.1, ``D_GGX``: D = (alpha / (1 - (n.h)^2 + (n.h alpha)^2))^2 / pi (1 - (n.h)^2
      written as h_x^2 + h_y^2);
    - sec. 4.4.2, ``V_SmithGGXCorrelated``: V = 0.5 / (n.l sqrt((n.v)^2 (1 - alpha^2) + alpha^2)
      + n.v sqrt((n.l)^2 (1 - alpha^2) + alpha^2));
    - sec. 4.4.3, ``F_Schlick(l.h, f0, f90)`` = f0 + (f90 - f0)(1 - l.h)^5 with Filament's
      f90 = saturate(dot(f0, vec3(50 * 0.33))) (its shading code's ``fresnel``, the
      specular occlusion of f0 below 2 %);
    - sec. 4.5, f_d: Lambert 1 / pi, or ``Fd_Burley`` (1 / pi) F_Schlick(n.l, 1, f90)
      F_Schlick(n.v, 1, f90), f90 = 0.5 + 2 alpha (l.h)^2 -- the documentation's alpha,
      "roughness, remapped from perceptualRoughness" (its table of symbols; the shading
      code passes ``pixel.roughness``).  ``burley_roughness="perceptual"`` uses the
      perceptual roughness instead (Burley 2012's own parameter); ``diffuse="none"``: 0;
    - sec. 4.10.1 (anisotropic model, Kulla & Conty 2017's parameterisation):
      a_t = max(alpha (1 + anisotropy), 0.001), a_b = max(alpha (1 - anisotropy), 0.001),
      ``D_GGX_Anisotropic``: a2 = a_t a_b, w = (a_b t.h, a_t b.h, a2 n.h),
      D = a2 (a2 / w.w)^2 / pi; ``V_SmithGGXCorrelated_Anisotropic``:
      V = 0.5 / (n.l |(a_t t.v, a_b b.v, n.v)| + n.v |(a_t t.l, a_b b.l, n.l)|);
      used where anisotropy != 0."""
    g, r, alpha, base, m, aniso = _inputs(l, v, roughness, base, metallic, anisotropy)
    with np.errstate(all="ignore"):
        f0 = 0.16 * _rgb(reflectance) ** 2 * (1.0 - m) + base * m
        f90 = np.clip(np.sum(f0 * (50.0 * 0.33), axis=-1), 0.0, 1.0)
        # isotropic
        k = alpha / (g.sin2h + (g.noh * alpha) ** 2)
        d_iso = np.where(g.noh > 0.0, k * k / np.pi, 0.0)
        a2 = alpha * alpha
        v_iso = 0.5 / (g.nol * np.sqrt(g.nov ** 2 * (1.0 - a2) + a2) + g.nov * np.sqrt(g.nol ** 2 * (1.0 - a2) + a2))
        # anisotropic
        at = np.maximum(alpha * (1.0 + aniso), 0.001)
        ab = np.maximum(alpha * (1.0 - aniso), 0.001)
        aa = at * ab
        w = np.stack([ab * g.h[..., 0], at * g.h[..., 1], aa * g.noh], axis=-1)
        w2 = aa / np.sum(w * w, axis=-1)
        d_aniso = np.where(g.noh > 0.0, aa * w2 * w2 / np.pi, 0.0)
        lam_v = g.nol * np.linalg.norm(np.stack([at * g.v[..., 0], ab * g.v[..., 1], g.nov], axis=-1), axis=-1)
        lam_l = g.nov * np.linalg.norm(np.stack([at * g.l[..., 0], ab * g.l[..., 1], g.nol], axis=-1), axis=-1)
        v_aniso = 0.5 / (lam_v + lam_l)
        dv = np.where(aniso != 0.0, d_aniso * v_aniso, d_iso * v_iso)
        specular = fresnel_schlick_f90(g.voh[..., None], f0, f90[..., None]) * dv[..., None]
        if diffuse == "lambert":
            fd = np.full_like(alpha, 1.0 / np.pi)
        elif diffuse == "burley":
            fd = burley_diffuse(g.nol, g.nov, g.voh, alpha if burley_roughness == "alpha" else r)
        elif diffuse == "none":
            fd = np.zeros_like(alpha)
        else:
            raise ValueError(diffuse)
        f = (1.0 - m) * base * fd[..., None] + specular
    return g.only_above(f)


def urp_mobile_brdf(l, v, base, metallic, roughness):
    """Unity URP's BRDF (URP ``BRDF.hlsl``: ``InitializeBRDFData``, ``DirectBRDFSpecular``;
    after Zioma 2015, "Optimizing PBR for Mobile"), as pbrkit's urp_mobile module
    describes it: diffuse = base (1 - 0.04)(1 - metallic) (``OneMinusReflectivityMetallic``),
    specular colour lerp(0.04, base, metallic) (``kDielectricSpec``), the specular term
    alpha^2 / (d^2 max(0.1, (l.h)^2) (4 alpha + 2)), d = (n.h)^2 (alpha^2 - 1) + 1
    (:func:`urp_specular_term`), alpha = r^2 (``PerceptualRoughnessToRoughness``), and
    the BRDF (diffuse + specular term) / pi (Unity's lights carry pi).  Left out, as the
    module leaves them out: URP's fp16 guards (d's + 1.00001 instead of + 1, alpha
    clamped at HALF_MIN_SQRT rather than ALPHA_MIN's 1e-3, the mobile clamp to 100)."""
    g = Geometry(l, v)
    alpha = _alpha(roughness)
    base = np.asarray(base, dtype=float)
    m = _rgb(metallic)
    with np.errstate(all="ignore"):
        diffuse = base * (1.0 - 0.04) * (1.0 - m)
        specular = _mix(0.04, base, m)
        term = urp_specular_term(g.noh, g.sin2h, g.voh, alpha) * np.pi  # URP's term, before / pi
        f = (diffuse + specular * term[..., None]) / np.pi
    return g.only_above(f)


def disney_brdf(l, v, base, metallic, roughness, reflectance, anisotropy, subsurface, specular_tint, sheen,
                sheen_tint, clearcoat, clearcoat_gloss):
    """Disney's principled BRDF, the BRDF Explorer's ``disney.brdf`` (Burley 2012,
    "Physically-Based Shading at Disney", sec. 5 and App. B):

        f = ((1 / pi) mix(Fd, ss, subsurface) Cdlin + Fsheen)(1 - metallic) + Gs Fs Ds
            + 0.25 clearcoat Gr Fr Dr,

    Cdlum = 0.3 R + 0.6 G + 0.1 B, Ctint = Cdlin / Cdlum (1 if Cdlum = 0),
    Cspec0 = mix(0.08 specular mix(1, Ctint, specularTint), Cdlin, metallic) with
    0.08 specular = 0.16 reflectance^2 (the project's reflectance),
    Csheen = mix(1, Ctint, sheenTint); FL, FV, FH = (1 - n.l)^5, (1 - n.v)^5, (1 - l.h)^5;
    Fd: Burley's diffuse (:func:`burley_diffuse` times pi), ss: the subsurface term
    (:func:`disney_subsurface` times pi), both of the perceptual roughness;
    Ds = ``GTR2_aniso`` (anisotropic GGX, :func:`d_ggx_anisotropic`) with
    aspect = sqrt(1 - 0.9 anisotropic), a_x = alpha / aspect, a_y = alpha aspect
    (App. B.2; alpha = max(r^2, ALPHA_MIN) and each clamped at 0.001 -- the BRDF
    Explorer clamps r^2 / aspect and r^2 aspect at 0.001, which differs only where
    r^2 < 0.001), Fs = mix(Cspec0, 1, FH),
    Gs = ``smithG_GGX_aniso``(l) ``smithG_GGX_aniso``(v), smithG_GGX_aniso =
    1 / (n.x + sqrt((x.X a_x)^2 + (x.Y a_y)^2 + (n.x)^2)) (the separable Smith
    visibility, G1 / (2 n.x) each); clear coat Dr = GTR1 (:func:`d_gtr1`) of
    alpha = mix(0.1, 0.001, clearcoatGloss), Fr = mix(0.04, 1, FH),
    Gr = smithG_GGX(n.l, 0.25) smithG_GGX(n.v, 0.25), smithG_GGX(c, a) =
    1 / (c + sqrt(a^2 + c^2 - a^2 c^2))."""
    g = Geometry(l, v)
    r = np.asarray(roughness, dtype=float)
    alpha = _alpha(r)
    cd = np.asarray(base, dtype=float)
    m = _rgb(metallic)
    with np.errstate(all="ignore"):
        lum = 0.3 * cd[..., 0] + 0.6 * cd[..., 1] + 0.1 * cd[..., 2]
        tint = np.where(lum[..., None] > 0.0, cd / np.where(lum > 0.0, lum, 1.0)[..., None], 1.0)
        cspec0 = _mix(0.16 * _rgb(reflectance) ** 2 * _mix(1.0, tint, _rgb(specular_tint)), cd, m)
        csheen = _mix(1.0, tint, _rgb(sheen_tint))
        fh = ((1.0 - g.voh) ** 5)[..., None]
        fd = burley_diffuse(g.nol, g.nov, g.voh, r) * np.pi
        ss = disney_subsurface(g.nol, g.nov, g.voh, r) * np.pi
        diffuse = (1.0 / np.pi) * _mix(fd, ss, np.asarray(subsurface, dtype=float))[..., None] * cd
        fsheen = fh * _rgb(sheen) * csheen
        aspect = np.sqrt(1.0 - 0.9 * np.asarray(anisotropy, dtype=float))
        ax = np.maximum(alpha / aspect, 0.001)
        ay = np.maximum(alpha * aspect, 0.001)
        ds = d_ggx_anisotropic(g.h[..., 0], g.h[..., 1], g.noh, ax, ay)
        fs = _mix(cspec0, 1.0, fh)

        def smith_aniso(w):
            return 1.0 / (w[..., 2] + np.sqrt((w[..., 0] * ax) ** 2 + (w[..., 1] * ay) ** 2 + w[..., 2] ** 2))

        gs = smith_aniso(g.l) * smith_aniso(g.v)

        def smith(c, a):
            return 1.0 / (c + np.sqrt(a * a + c * c - a * a * c * c))

        alpha_c = _mix(0.1, 0.001, np.asarray(clearcoat_gloss, dtype=float))
        dr = d_gtr1(g.noh, g.sin2h, alpha_c)
        fr = _mix(0.04, 1.0, fh[..., 0])
        gr = smith(g.nol, 0.25) * smith(g.nov, 0.25)
        f = ((diffuse + fsheen) * (1.0 - m) + (gs * ds)[..., None] * fs
             + (0.25 * np.asarray(clearcoat, dtype=float) * gr * fr * dr)[..., None])
    return g.only_above(f)


#: cook_torrance's term names, as the transcription below spells them.
CT_DISTRIBUTIONS = ("ggx", "beckmann", "blinn-phong")
CT_MASKINGS = ("height-correlated", "separable", "schlick-ggx", "schlick-ggx-ue4", "kelemen", "implicit")
CT_FRESNELS = ("schlick", "schlick-pow4", "ue4-sg", "exact-conductor", "exact-dielectric", "none")
CT_DIFFUSES = ("lambert", "burley", "none", "eon")


def cook_torrance_brdf(l, v, base, metallic, roughness, reflectance, anisotropy, distribution, masking, fresnel,
                       diffuse, eta=None, k=None, specular_color=None):
    """A Cook & Torrance 1982 microfacet BRDF, f = k_d rho_d f_diffuse + D G F / (4 n.l n.v)
    (Walter et al. 2007, eq. 20), every term chosen by name:

    - ``distribution`` (alpha = max(r^2, ALPHA_MIN); anisotropic where anisotropy != 0 with
      Kulla & Conty 2017's a_x = max(alpha (1 + a), ALPHA_MIN), a_y = max(alpha (1 - a),
      ALPHA_MIN), tangent +x): ``ggx`` (:func:`d_ggx_anisotropic`), ``beckmann``
      (:func:`d_beckmann_anisotropic`), ``blinn-phong`` (:func:`d_blinn_phong`, exponent
      2 / alpha^2 - 2; isotropic: the anisotropy is ignored);
    - ``masking``: Smith's G with the distribution's own Lambda (Blinn-Phong: Beckmann's of
      the same alpha, Walter et al. 2007 sec. 5.2), ``height-correlated``
      G = 1 / (1 + Lambda(l) + Lambda(v)) (Heitz 2014, eq. 99) or ``separable``
      G = 1 / ((1 + Lambda(l))(1 + Lambda(v))) (Heitz 2014, eq. 98); ``schlick-ggx``
      G1 = n.x / (n.x (1 - k) + k) with k = alpha / 2 and ``schlick-ggx-ue4`` with
      k = (r + 1)^2 / 8 (Karis 2013, eq. 4; the isotropic alpha); ``kelemen``
      (:func:`v_kelemen`); ``implicit`` G = (n.l)(n.v) (V = 1/4);
    - ``fresnel`` of v.h: ``schlick`` (Schlick 1994, eq. 15), ``schlick-pow4`` (the fourth
      power), ``ue4-sg`` (Karis 2013, eq. 5), each with the metallic-workflow
      f0 = lerp(0.16 reflectance^2, base, metallic); ``exact-conductor`` of the complex IOR
      eta + i k (:func:`fresnel_conductor`); ``exact-dielectric`` (:func:`fresnel_dielectric`)
      of the IOR n = (1 + sqrt(f0)) / (1 - sqrt(f0)) of f0 = 0.16 reflectance^2 (the
      inverse of f0 = ((n - 1) / (n + 1))^2; metallic ignored); ``none``: F = the constant
      ``specular_color``;
    - ``diffuse``, times base (1 - metallic): ``lambert`` 1 / pi, ``burley``
      (:func:`burley_diffuse` of the perceptual roughness), ``eon`` (:func:`eon_diffuse`,
      the perceptual roughness), ``none``."""
    g, r, alpha, base, m, aniso = _inputs(l, v, roughness, base, metallic, anisotropy)
    if distribution == "blinn-phong":
        aniso = np.zeros_like(alpha)
    ax = np.where(aniso != 0.0, np.maximum(alpha * (1.0 + aniso), ALPHA_MIN), alpha)
    ay = np.where(aniso != 0.0, np.maximum(alpha * (1.0 - aniso), ALPHA_MIN), alpha)
    with np.errstate(all="ignore"):
        if distribution == "ggx":
            d = d_ggx_anisotropic(g.h[..., 0], g.h[..., 1], g.noh, ax, ay)
            lam_l = lambda_ggx_anisotropic(g.l[..., 0], g.l[..., 1], g.nol, ax, ay)
            lam_v = lambda_ggx_anisotropic(g.v[..., 0], g.v[..., 1], g.nov, ax, ay)
        elif distribution in ("beckmann", "blinn-phong"):
            if distribution == "beckmann":
                d = d_beckmann_anisotropic(g.h[..., 0], g.h[..., 1], g.noh, ax, ay)
            else:
                d = d_blinn_phong(g.noh, alpha)
            lam_l = lambda_beckmann_anisotropic(g.l[..., 0], g.l[..., 1], g.nol, ax, ay)
            lam_v = lambda_beckmann_anisotropic(g.v[..., 0], g.v[..., 1], g.nov, ax, ay)
        else:
            raise ValueError(distribution)
        four = 4.0 * g.nol * g.nov
        if masking == "height-correlated":
            vis = 1.0 / (1.0 + lam_l + lam_v) / four
        elif masking == "separable":
            vis = 1.0 / ((1.0 + lam_l) * (1.0 + lam_v)) / four
        elif masking in ("schlick-ggx", "schlick-ggx-ue4"):
            kk = alpha / 2.0 if masking == "schlick-ggx" else (r + 1.0) ** 2 / 8.0
            vis = g1_schlick(g.nol, kk) * g1_schlick(g.nov, kk) / four
        elif masking == "kelemen":
            vis = v_kelemen(g.lov)
        elif masking == "implicit":
            vis = np.full_like(alpha, 0.25)
        else:
            raise ValueError(masking)
        c = g.voh[..., None]
        f0 = _mix(_rgb(0.16 * np.asarray(reflectance, dtype=float) ** 2), base, m)
        if fresnel == "schlick":
            f = fresnel_schlick(c, f0)
        elif fresnel == "schlick-pow4":
            f = fresnel_schlick_pow4(c, f0)
        elif fresnel == "ue4-sg":
            f = fresnel_ue4_sg(c, f0)
        elif fresnel == "exact-conductor":
            f = fresnel_conductor(c, np.asarray(eta, dtype=float), np.asarray(k, dtype=float))
        elif fresnel == "exact-dielectric":
            root = np.sqrt(0.16 * _rgb(reflectance) ** 2)
            f = fresnel_dielectric(c, (1.0 + root) / (1.0 - root)) + np.zeros_like(base)
        elif fresnel == "none":
            f = np.asarray(specular_color, dtype=float) + np.zeros_like(base)
        else:
            raise ValueError(fresnel)
        rho = base * (1.0 - m)
        if diffuse == "lambert":
            fd = rho / np.pi
        elif diffuse == "burley":
            fd = rho * burley_diffuse(g.nol, g.nov, g.voh, r)[..., None]
        elif diffuse == "eon":
            fd = eon_diffuse(g.l, g.v, rho, r)
        elif diffuse == "none":
            fd = np.zeros_like(base)
        else:
            raise ValueError(diffuse)
        out = fd + f * (d * vis)[..., None]
    return g.only_above(out)


# ------------------------------------------------------------- KHR_materials_sheen

#: The Charlie alpha's floor (the spec's alpha_g = sheenRoughness^2 is 0 at sheenRoughness 0,
#: where 1 / alpha_g is infinite; pbrkit and this transcription floor it at 1e-12).
SHEEN_ALPHA_MIN = 1e-12


def _sheen_alpha(sheen_roughness):
    return np.maximum(np.asarray(sheen_roughness, dtype=float) ** 2, SHEEN_ALPHA_MIN)


def charlie_d(cos_h, sin2_h, alpha_g):
    """KHR_materials_sheen, "Sheen distribution" (Estevez and Kulla 2017, eq. 2):
    D(m) = (2 + 1 / alpha_g) sin(theta)^(1 / alpha_g) / (2 pi), sin^2 from the half
    vector's components; 0 below the horizon."""
    inv_r = 1.0 / alpha_g
    return np.where(cos_h >= 0.0, (2.0 + inv_r) * np.power(sin2_h, 0.5 * inv_r) / (2.0 * np.pi), 0.0)


def _sheen_l(x, alpha_g):
    # KHR_materials_sheen "Sheen visibility": l(x, alpha_g), the coefficients mixed by
    # (1 - alpha_g)^2 between their alpha_g = 1 and alpha_g = 0 fits (Estevez and Kulla 2017, Table 1)
    t = (1.0 - alpha_g) * (1.0 - alpha_g)
    a = _mix(21.5473, 25.3245, t)
    b = _mix(3.82987, 3.32435, t)
    c = _mix(0.19823, 0.16801, t)
    d = _mix(-1.97760, -1.27393, t)
    e = _mix(-4.32054, -4.85967, t)
    return a / (1.0 + b * np.power(np.maximum(x, 0.0), c)) + d * x + e


def charlie_lambda(cos_theta, alpha_g):
    """KHR_materials_sheen "Sheen visibility": lambda_sheen(cos_theta, alpha_g) =
    exp(l(cos_theta)) below 0.5, exp(2 l(0.5) - l(1 - cos_theta)) above."""
    return np.where(np.abs(cos_theta) < 0.5, np.exp(_sheen_l(np.abs(cos_theta), alpha_g)),
                    np.exp(2.0 * _sheen_l(0.5, alpha_g) - _sheen_l(1.0 - np.abs(cos_theta), alpha_g)))


def charlie_v(nol, nov, alpha_g):
    """KHR_materials_sheen "Sheen visibility": V = 1 / ((1 + lambda(n.v) + lambda(n.l)) 4 n.l n.v)."""
    return 1.0 / ((1.0 + charlie_lambda(nov, alpha_g) + charlie_lambda(nol, alpha_g)) * (4.0 * nol * nov))


def charlie_albedo(mu, sheen_roughness, n_u=512, n_phi=128):
    """E_sheen(mu) = integral of D V (n.l) over the hemisphere of l, the white sheen's
    directional albedo (KHR_materials_sheen, "Albedo-scaling technique").  Written here:
    with k = 2 + 1 / alpha_g, D sin(theta_h) cos(theta_h) d theta_h = du / (2 pi) for
    u = sin(theta_h)^k, and dl = 4 (v.h) dh, so E = (1 / (2 pi)) integral over u in [0, 1],
    phi in [0, 2 pi) of V (n.l) 4 (v.h) / cos(theta_h) du dphi (D cancels); Gauss-Legendre
    in u and phi (phi on [0, pi], doubled: v in the xz plane).  mu floored at 1e-4."""
    mu = max(float(mu), 1e-4)
    alpha_g = float(_sheen_alpha(sheen_roughness))
    k = 2.0 + 1.0 / alpha_g
    xu, wu = np.polynomial.legendre.leggauss(n_u)
    xp, wp = np.polynomial.legendre.leggauss(n_phi)
    u = 0.5 * (xu + 1.0)
    phi = 0.5 * np.pi * (xp + 1.0)
    sin_h = u[:, None] ** (1.0 / k)
    cos_h = np.sqrt(np.maximum(1.0 - sin_h * sin_h, 0.0))
    sv = np.sqrt(1.0 - mu * mu)
    voh = sv * sin_h * np.cos(phi)[None, :] + mu * cos_h
    lz = 2.0 * voh * cos_h - mu
    ok = (lz > 0.0) & (voh > 0.0) & (cos_h > 0.0)
    with np.errstate(all="ignore"):
        g = np.where(ok, charlie_v(lz, mu, alpha_g) * lz * 4.0 * voh / cos_h, 0.0)
    weights = (0.5 * wu)[:, None] * (0.5 * np.pi * wp)[None, :]
    return 2.0 * float(np.sum(g * weights)) / (2.0 * np.pi)


def sheen_albedo_bilinear(table, mu, sheen_roughness):
    """The spec's lookup of E "with x = VdotN and y = sheenRoughness" in ``table`` (rows:
    sheenRoughness i / (n_r - 1), columns: n.v j / (n_mu - 1)), bilinear, clamped."""
    table = np.asarray(table, dtype=float)
    n_r, n_mu = table.shape
    x = np.clip(mu, 0.0, 1.0) * (n_mu - 1)
    y = np.clip(sheen_roughness, 0.0, 1.0) * (n_r - 1)
    j = np.minimum(x.astype(int), n_mu - 2)
    i = np.minimum(y.astype(int), n_r - 2)
    fx, fy = x - j, y - i
    top = table[i, j] * (1.0 - fx) + table[i, j + 1] * fx
    bottom = table[i + 1, j] * (1.0 - fx) + table[i + 1, j + 1] * fx
    return top * (1.0 - fy) + bottom * fy


def gltf_sheen_brdf(l, v, base, metallic, roughness, sheen_color, sheen_roughness, e_table):
    """glTF 2.0 (:func:`gltf_brdf`) under KHR_materials_sheen's layering (its README,
    "Sheen" and "Albedo-scaling technique"):

        sheen_material = sheenColor sheen_brdf + material sheen_albedo_scaling,
        sheen_brdf = D_Charlie V_sheen (:func:`charlie_d`, :func:`charlie_v`), no Fresnel,
        sheen_albedo_scaling = 1 - max3(sheenColor) E(VdotN),

    E read bilinearly from ``e_table`` (:func:`sheen_albedo_bilinear`; e.g. a table of
    :func:`charlie_albedo`)."""
    g = Geometry(l, v)
    material = gltf_brdf(l, v, base, metallic, roughness)
    color = np.asarray(sheen_color, dtype=float)
    alpha_g = _sheen_alpha(sheen_roughness)
    with np.errstate(all="ignore"):
        sheen_brdf = charlie_d(g.noh, g.sin2h, alpha_g) * charlie_v(g.nol, g.nov, alpha_g)
        e = sheen_albedo_bilinear(e_table, g.nov, sheen_roughness)
        scaling = 1.0 - np.max(color, axis=-1) * e
        f = color * sheen_brdf[..., None] + material * scaling[..., None]
    return g.only_above(f)


def gltf_khr_brdf(l, v, base, metallic, roughness, sheen_color, sheen_roughness, clearcoat, clearcoat_roughness,
                  specular, specular_color, ior, e_table, iridescence=0.0, iridescence_ior=1.3,
                  iridescence_thickness=400.0, iridescent_fresnel=None, clearcoat_normal=None):
    """glTF 2.0 with KHR_materials_ior, KHR_materials_specular, KHR_materials_sheen and
    KHR_materials_clearcoat, written from the extensions' READMEs:

        dielectric_f0 = min(((ior - 1) / (ior + 1))^2 specularColor, 1) specular  (specular, ior)
        dielectric_f90 = specular
        dielectric_fresnel = mix(dielectric_f0, dielectric_f90, (1 - |V.H|)^5)
        dielectric_brdf = dielectric_fresnel specular_brdf + (1 - max3(dielectric_fresnel)) diffuse_brdf
        metal_brdf = specular_brdf (baseColor + (1 - baseColor)(1 - |V.H|)^5)
        material = mix(dielectric_brdf, metal_brdf, metallic)
        sheen_material = sheenColor sheen_brdf + material (1 - max3(sheenColor) E(VdotN))   (sheen)
        coated = mix(sheen_material, clearcoat_brdf, clearcoat (0.04 + 0.96 (1 - |V.N|)^5))  (clearcoat)
        clearcoat_brdf = D(clearcoatRoughness^2) G / (4 |V.N| |L.N|)

    the metal and the dielectric mixed literally (not folded into one F0).  With
    KHR_materials_iridescence (its README, iridescent_dielectric_layer with
    KHR_materials_specular and iridescent_conductor_layer):

        dielectric_brdf = rgb_mix(diffuse_brdf, specular_brdf, mix(specular fr, iridescent_f, iridescence))
        iridescent_f = iridescent_fresnel(1, iridescenceIor, specular min(F0(ior) specularColor, 1), thickness)
        metal_brdf = mix(conductor_fresnel(baseColor, specular_brdf),
                         specular_brdf iridescent_fresnel(1, iridescenceIor, baseColor, thickness), iridescence)
        rgb_mix(base, specular, a) = (1 - max3(a)) base + a specular

    ``iridescent_fresnel(cos, film_ior, thickness, f0 (..., 3))`` -> (..., 3) is given
    (the thin film's Fresnel is checked against an Airy summation in test_thin_film.py;
    here the layering around it is transcribed).  ``clearcoat_normal`` (N, 3), unit, in the
    local frame: KHR_materials_clearcoat's clearcoatNormal ("Roughness and normal are taken
    from clearcoatNormal and clearcoatRoughness"; fresnel_coat's ``normal`` "affects the
    top layer, but not the base"): the coat's D, G and |V.Nc| about it, 0 unless L.Nc > 0
    and V.Nc > 0 (None: the shading normal)."""
    g = Geometry(l, v)
    alpha = _alpha(roughness)
    base = np.asarray(base, dtype=float)
    with np.errstate(all="ignore"):
        spec = (d_ggx(g.noh, g.sin2h, alpha) * _smith_ggx_visibility_separable(g.nol, g.nov, alpha))[..., None]
        fc = ((1.0 - np.abs(g.voh)) ** 5)[..., None]
        s = _rgb(specular)
        f0_ior = ((np.asarray(ior, dtype=float) - 1.0) / (np.asarray(ior, dtype=float) + 1.0)) ** 2
        d_f0 = np.minimum(_rgb(f0_ior) * np.asarray(specular_color, dtype=float), 1.0) * s
        d_fresnel = d_f0 + (s - d_f0) * fc
        m_fresnel = base + (1.0 - base) * fc
        k = _rgb(iridescence)
        if np.any(k > 0.0):
            voh = np.abs(g.voh)
            d_fresnel = d_fresnel + (iridescent_fresnel(voh, iridescence_ior, iridescence_thickness, d_f0)
                                     - d_fresnel) * k
            m_fresnel = m_fresnel + (iridescent_fresnel(voh, iridescence_ior, iridescence_thickness, base)
                                     - m_fresnel) * k
        dielectric = d_fresnel * spec + (1.0 - np.max(d_fresnel, axis=-1, keepdims=True)) * base / np.pi
        metal = spec * m_fresnel
        material = _mix(dielectric, metal, _rgb(metallic))
        color = np.asarray(sheen_color, dtype=float)
        alpha_g = _sheen_alpha(sheen_roughness)
        sheen_brdf = charlie_d(g.noh, g.sin2h, alpha_g) * charlie_v(g.nol, g.nov, alpha_g)
        black = np.all(color == 0.0, axis=-1)
        sheen_brdf = np.where(black, 0.0, sheen_brdf)
        e = sheen_albedo_bilinear(e_table, g.nov, sheen_roughness)
        sheen_material = color * sheen_brdf[..., None] + material * (1.0 - np.max(color, axis=-1) * e)[..., None]
        alpha_c = _alpha(clearcoat_roughness)
        if clearcoat_normal is None:
            coat = d_ggx(g.noh, g.sin2h, alpha_c) * _smith_ggx_visibility_separable(g.nol, g.nov, alpha_c)
            coat_weight = np.asarray(clearcoat, dtype=float) * (0.04 + 0.96 * (1.0 - np.abs(g.nov)) ** 5)
        else:
            nc = np.asarray(clearcoat_normal, dtype=float)
            h = np.asarray(l, dtype=float) + np.asarray(v, dtype=float)
            h = h / np.linalg.norm(h, axis=-1, keepdims=True)
            nol_c = np.sum(np.asarray(l) * nc, axis=-1)
            nov_c = np.sum(np.asarray(v) * nc, axis=-1)
            noh_c = np.sum(h * nc, axis=-1)
            coat = d_ggx(noh_c, 1.0 - noh_c * noh_c, alpha_c) * _smith_ggx_visibility_separable(nol_c, nov_c,
                                                                                                    alpha_c)
            coat = np.where((nol_c > 0.0) & (nov_c > 0.0), coat, 0.0)
            coat_weight = np.asarray(clearcoat, dtype=float) * (0.04 + 0.96 * (1.0 - np.abs(nov_c)) ** 5)
        f = _mix(sheen_material, coat[..., None], _rgb(coat_weight))
    return g.only_above(f)


# ------------------------------------------- KHR_materials_transmission / _volume


def _schlick_f(c, f0, f90):
    return f0 + (f90 - f0) * (1.0 - c) ** 5


def _f_tr(cos_vh, eta, f0, f90):
    """The volume README, "Implementation": F_TR^+ entering a denser medium (eta =
    eta_o / eta_i >= 1), F_TR^- at cos theta_o leaving it, 1 under total internal
    reflection."""
    c = np.abs(cos_vh)
    if eta >= 1.0:
        return _schlick_f(c, f0, f90)
    sin2_o = (1.0 / eta) ** 2 * (1.0 - c * c)
    cos_o = np.sqrt(np.maximum(1.0 - sin2_o, 0.0))
    return np.where(sin2_o >= 1.0, 1.0, _schlick_f(cos_o, f0, f90))


def _ggx_d_full(h, alpha):
    # D_T of the transmission README: alpha^2 chi+(n.h) / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)
    c = h[..., 2]
    return np.where(c > 0.0, alpha ** 2 / (np.pi * (c * c * (alpha ** 2 - 1.0) + 1.0) ** 2), 0.0)


def _v_separable_abs(nol, nov, alpha):
    # the README's nu_T without its chi+ factors: 1 / ((|n.l| + sqrt(a2 + (1 - a2)(n.l)^2)) (|n.v| + ...))
    a2 = alpha ** 2
    nol = np.abs(nol)
    nov = np.abs(nov)
    return 1.0 / ((nol + np.sqrt(a2 + (1.0 - a2) * nol * nol)) * (nov + np.sqrt(a2 + (1.0 - a2) * nov * nov)))


def _lambda_ggx_w(w, alpha):
    # Smith's Lambda of GGX for a direction w (|w_z| the cosine): (-1 + sqrt(1 + alpha^2 tan^2)) / 2
    c2 = w[..., 2] ** 2
    t2 = np.maximum(1.0 - c2, 0.0) / np.maximum(c2, 1e-300)
    return 0.5 * (-1.0 + np.sqrt(1.0 + alpha * alpha * t2))


def gltf_transmission_bsdf(l, v, base, metallic, roughness, transmission, ior=1.5, thickness=0.0, specular=1.0,
                           specular_color=(1.0, 1.0, 1.0)):
    """glTF 2.0 with KHR_materials_transmission (and KHR_materials_volume's thickness),
    written from the READMEs, for l and v (N, 3) in the local frame on either side:

        dielectric_brdf = fresnel_mix(ior, base = mix(diffuse_brdf(baseColor),
                                                      specular_btdf(r^2) baseColor, transmission),
                                      layer = specular_brdf(r^2))     (transmission, "Transmission BTDF")
        material = mix(dielectric_brdf, metal_brdf, metallic)

    with KHR_materials_specular's dielectric F0 and F90 (as gltf_khr_brdf).  Reflection
    (l on v's side) is the core glTF material with the diffuse weighted by 1 -
    transmission.  Transmission:

    - thin-walled (thickness 0): the transmission README's "Implementation Notes",
      specular_btdf = nu_T D_T with H_T = normalize(V - 2 (N.L) N + L) and the
      separable nu_T (both sides alike: the frame turned to v), its chi+ factors those
      of the specular lobe it is ("exactly the same as the specular lobe except sampled
      along the line of sight through the surface", "Refraction"): of L mirrored
      through the surface, L' = L - 2 (N.L) N, whose half vector with V H_T is (the
      notes' chi+(H_T.L / N.L) with the unmirrored L would cut the lobe where H_T.L > 0;
      the Khronos Sample Viewer's getPunctualRadianceTransmission has no such cut);
    - volume: the volume README's "Implementation", H_TR = -normalize(eta_i V + eta_o L),
      MicrofacetBTDF = |H.L| |H.V| / (|N.L| |N.V|) eta_o^2 G D / (eta_i (H.V) + eta_o (H.L))^2,
      with eta_i V's side and eta_o L's side (ior outside, 1 inside), times
      (eta_i / eta_o)^2: the README's normalisation (its V "the incident side") is the
      adjoint one; a path tracer of radiance from the camera uses Walter et al. 2007's
      eq. 21 with its outgoing direction o = V, whose numerator is eta_V^2 (the two
      differ by that factor; they agree through any closed surface).  G is the
      height-correlated Smith G2 = 1 / (1 + Lambda(V) + Lambda(L)) (Heitz 2014 eq. 99;
      the README's non-normative notes write the separable form), with the chi+
      factors of microfacets seen from behind;

    each times (1 - F_TR(V.H)) (1 - metallic) transmission baseColor, F_TR the volume
    README's three cases.  Seen from inside a volume (v_z < 0): F_TR D V + (1 - F_TR)
    (1 - transmission)(1 - metallic) baseColor / pi on the inside, the transmission
    with eta = 1 / ior."""
    l = np.array(l, dtype=float)
    v = np.array(v, dtype=float)
    base = np.asarray(base, dtype=float)
    alpha = max(float(roughness) ** 2, ALPHA_MIN)
    thin = thickness <= 0.0
    inside = (not thin) & (v[..., 2] < 0.0)
    flip = np.where(v[..., 2] < 0.0, -1.0, 1.0)
    l[..., 2] *= flip
    v[..., 2] *= flip
    s = float(specular)
    f0_ior = ((max(ior, 1.0) - 1.0) / (max(ior, 1.0) + 1.0)) ** 2
    d_f0 = np.minimum(f0_ior * np.asarray(specular_color, dtype=float), 1.0) * s
    f0_max = float(np.max(d_f0))
    out = np.zeros(l.shape[:-1] + (3,))
    above = l[..., 2] > 0.0
    below = l[..., 2] < 0.0
    with np.errstate(all="ignore"):
        # reflection from outside: the core material, the diffuse weighted by 1 - transmission
        g = Geometry(l, v)
        spec = (d_ggx(g.noh, g.sin2h, alpha) * _smith_ggx_visibility_separable(g.nol, g.nov, alpha))[..., None]
        fc = ((1.0 - np.abs(g.voh)) ** 5)[..., None]
        d_fresnel = d_f0 + (s - d_f0) * fc
        dielectric = d_fresnel * spec + (1.0 - np.max(d_fresnel, axis=-1, keepdims=True)) * (
            1.0 - transmission) * base / np.pi
        metal = spec * (base + (1.0 - base) * fc)
        outside_r = _mix(dielectric, metal, _rgb(metallic))
        # reflection from inside a volume
        f_in = _f_tr(g.voh, 1.0 / ior, f0_max, s)[..., None]
        inside_r = f_in * spec + (1.0 - f_in) * (1.0 - transmission) * (1.0 - metallic) * base / np.pi
        reflection = np.where(inside[..., None], inside_r, outside_r)
        if thin:
            mirrored = l * np.array([1.0, 1.0, -1.0])
            h = v - 2.0 * l[..., 2:3] * np.array([0.0, 0.0, 1.0]) + l
            h /= np.linalg.norm(h, axis=-1, keepdims=True)
            hl = np.sum(h * mirrored, axis=-1)
            hv = np.sum(h * v, axis=-1)
            chi = (hl / mirrored[..., 2] > 0.0) & (hv / v[..., 2] > 0.0)
            btdf = np.where(chi, _v_separable_abs(l[..., 2], v[..., 2], alpha) * _ggx_d_full(h, alpha), 0.0)
            f_t = _f_tr(hv, ior, f0_max, s)
        else:
            eta_i = np.where(inside, ior, 1.0)
            eta_o = np.where(inside, 1.0, ior)
            h = -(eta_i[..., None] * v + eta_o[..., None] * l)
            h /= np.linalg.norm(h, axis=-1, keepdims=True)
            h = np.where(h[..., 2:3] < 0.0, -h, h)  # the microfacet normal on the outside of the frame
            hl = np.sum(h * l, axis=-1)
            hv = np.sum(h * v, axis=-1)
            chi = (hl * l[..., 2] > 0.0) & (hv * v[..., 2] > 0.0)
            g2 = 1.0 / (1.0 + _lambda_ggx_w(v, alpha) + _lambda_ggx_w(l, alpha))
            readme = (np.abs(hl) * np.abs(hv) / (np.abs(l[..., 2]) * np.abs(v[..., 2])) * eta_o ** 2 * g2
                      * _ggx_d_full(h, alpha) / (eta_i * hv + eta_o * hl) ** 2)
            btdf = np.where(chi, readme * (eta_i / eta_o) ** 2, 0.0)
            f_t = _f_tr(hv, eta_o / eta_i, f0_max, s) if np.ndim(eta_o) == 0 else np.where(
                inside, _f_tr(hv, 1.0 / ior, f0_max, s), _f_tr(hv, ior, f0_max, s))
        trans = ((1.0 - f_t) * btdf * (1.0 - metallic) * transmission)[..., None] * base
    out = np.where(above[..., None], reflection, out)
    out = np.where(below[..., None], trans, out)
    return np.nan_to_num(out)


def gltf_anisotropy_brdf(l, v, n, t, w, base, metallic, roughness, strength, rotation):
    """glTF 2.0 with KHR_materials_anisotropy, written from the extension's README
    ("Anisotropy", "Implementation") in world space: the tangent ``t`` (made
    orthogonal to the normal ``n``) with handedness ``w`` spans TBN (B = w n x T, the
    glTF specification's "Meshes"),

        anisotropicT = normalize(TBN (cos(rotation), sin(rotation), 0))
        anisotropicB = normalize(cross(n, anisotropicT))
        at = mix(alphaRoughness, 1, strength^2),  ab = alphaRoughness
        D = a2 w2^2 / pi,  a2 = at ab,  f = (ab T.h, at B.h, a2 N.h),  w2 = a2 / (f . f)
        V = 0.5 / (N.L |(at T.v, ab B.v, N.v)| + N.v |(at T.l, ab B.l, N.l)|)

    (the README's D_GGX_anisotropic and V_GGX_anisotropic, without its clamp of V),
    times Schlick's F of f0 = mix(0.04, baseColor, metallic) at |V.H|, over the
    diffuse (1 - metallic)(1 - F_0.04(V.H)) baseColor / pi of Appendix B."""
    l, v, n, t = (np.asarray(x, dtype=float) for x in (l, v, n, t))
    dot = lambda a, b: np.sum(a * b, axis=-1)  # noqa: E731
    t = t - dot(t, n)[..., None] * n
    t = t / np.linalg.norm(t, axis=-1, keepdims=True)
    b_tbn = np.asarray(w, dtype=float)[..., None] * np.cross(n, t)
    rotation = np.asarray(rotation, dtype=float)[..., None]
    at_dir = np.cos(rotation) * t + np.sin(rotation) * b_tbn
    at_dir = at_dir / np.linalg.norm(at_dir, axis=-1, keepdims=True)
    ab_dir = np.cross(n, at_dir)
    ab_dir = ab_dir / np.linalg.norm(ab_dir, axis=-1, keepdims=True)
    alpha = _alpha(roughness)
    s = np.asarray(strength, dtype=float)
    at = _mix(alpha, 1.0, s * s)
    ab = alpha
    h = l + v
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    nol, nov, noh, voh = dot(n, l), dot(n, v), dot(n, h), dot(v, h)
    with np.errstate(all="ignore"):
        a2 = at * ab
        f = np.stack([ab * dot(at_dir, h), at * dot(ab_dir, h), a2 * noh], axis=-1)
        w2 = a2 / np.sum(f * f, axis=-1)
        d = a2 * w2 * w2 / np.pi
        ggx_v = nol * np.linalg.norm(np.stack([at * dot(at_dir, v), ab * dot(ab_dir, v), nov], axis=-1), axis=-1)
        ggx_l = nov * np.linalg.norm(np.stack([at * dot(at_dir, l), ab * dot(ab_dir, l), nol], axis=-1), axis=-1)
        vis = 0.5 / (ggx_v + ggx_l)
    base = np.asarray(base, dtype=float)
    m = _rgb(metallic)
    fc = ((1.0 - np.abs(voh)) ** 5)[..., None]
    f0 = _mix(0.04, base, m)
    spec = (d * vis)[..., None] * (f0 + (1.0 - f0) * fc)
    diffuse = (1.0 - m) * (1.0 - (0.04 + 0.96 * fc)) * base / np.pi
    out = spec + diffuse
    return np.where(((nol > 0.0) & (nov > 0.0))[..., None], out, 0.0)
