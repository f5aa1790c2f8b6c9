"""Masking-shadowing functions G and visibility terms V = G2 / (4 n.l n.v).

Smith's model (Smith 1967) with the Lambda functions derived in Heitz 2014,
"Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs",
JCGT 3(2) (cited below as Heitz 2014).  Arguments are cosines with the
normal (``nov = n.v``, ``nol = n.l``), tangent-frame components for
anisotropic forms (``tov = t.v``, ``bov = b.v``), and the distribution's
alpha (not perceptual roughness; see :mod:`pbrkit.brdf.distributions`).

Direction cosines at or below zero give G = 0 (back-facing directions are
masked); cosines are clamped to 1e-8 internally so no NaN or Inf appears.
"""

from __future__ import annotations

import math

import numpy as np
from numba import types
from numba.extending import overload

from ..core.jit import dual_use, select

__all__ = [
    "COS_MIN",
    "erf",
    "lambda_ggx",
    "lambda_ggx_anisotropic",
    "lambda_beckmann",
    "lambda_beckmann_anisotropic",
    "g1_smith",
    "g1_ggx",
    "g1_beckmann",
    "g2_separable",
    "g2_height_correlated",
    "visibility",
    "v_smith_ggx_height_correlated",
    "alpha_g_disney",
    "k_schlick_from_alpha",
    "k_ue4_direct",
    "k_ue4_ibl",
    "g1_schlick_ggx",
    "g2_schlick_ggx",
    "g2_kelemen",
    "v_kelemen",
    "v_neubelt",
]

#: Cosines are clamped to at least this value inside the masking terms.
COS_MIN = 1e-8


def erf(x):
    """Error function: elementwise on arrays from Python (SciPy's ``scipy.special.erf``,
    imported on first use), ``math.erf`` on scalars inside Numba kernels (the
    overload below).  Not a Numba ufunc: building one at import cost every
    command about 0.3 s."""
    from scipy.special import erf as _erf

    return _erf(x)


@overload(erf)
def _erf_numba(x):
    if isinstance(x, types.Float):
        return lambda x: math.erf(x)
    return None


@dual_use
def _tan2(cos_theta):
    c = np.minimum(np.maximum(cos_theta, COS_MIN), 1.0)
    c2 = c * c
    return (1.0 - c2) / c2


@dual_use
def lambda_ggx(nov, alpha):
    """Smith Lambda for GGX: (-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2 (Heitz 2014, eq. 72)."""
    return 0.5 * (np.sqrt(1.0 + alpha * alpha * _tan2(nov)) - 1.0)


@dual_use
def lambda_ggx_anisotropic(nov, tov, bov, alpha_t, alpha_b):
    """Anisotropic GGX Lambda (Heitz 2014, eqs. 80 and 86).

    alpha_0^2 tan^2 theta = ((t.v a_t)^2 + (b.v a_b)^2) / (n.v)^2.
    """
    c = np.minimum(np.maximum(nov, COS_MIN), 1.0)
    x = tov * alpha_t
    y = bov * alpha_b
    return 0.5 * (np.sqrt(1.0 + (x * x + y * y) / (c * c)) - 1.0)


@dual_use
def _lambda_beckmann_of_a(a):
    # Heitz 2014, eq. 83: Lambda(a) = (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi)).
    return 0.5 * (erf(a) - 1.0) + np.exp(-a * a) / (2.0 * a * np.sqrt(np.pi))


@dual_use
def lambda_beckmann(nov, alpha):
    """Smith Lambda for Beckmann, exact form with erf (Heitz 2014, eq. 83), a = 1 / (alpha tan theta)."""
    tan_theta = np.sqrt(_tan2(nov))
    a = 1.0 / np.maximum(alpha * tan_theta, 1e-300)
    return select(a > 30.0, 0.0, _lambda_beckmann_of_a(np.minimum(a, 30.0)))


@dual_use
def lambda_beckmann_anisotropic(nov, tov, bov, alpha_t, alpha_b):
    """Anisotropic Beckmann Lambda (Heitz 2014, eqs. 83 and 86)."""
    c = np.minimum(np.maximum(nov, COS_MIN), 1.0)
    x = tov * alpha_t
    y = bov * alpha_b
    a = c / np.maximum(np.sqrt(x * x + y * y), 1e-300)
    return select(a > 30.0, 0.0, _lambda_beckmann_of_a(np.minimum(a, 30.0)))


@dual_use
def g1_smith(lambda_v):
    """Smith masking G1 = 1 / (1 + Lambda) (Heitz 2014, eq. 43)."""
    return 1.0 / (1.0 + lambda_v)


@dual_use
def g1_ggx(nov, alpha):
    """Exact Smith G1 for isotropic GGX; 0 for n.v <= 0."""
    return select(nov > 0.0, g1_smith(lambda_ggx(nov, alpha)), 0.0)


@dual_use
def g1_beckmann(nov, alpha):
    """Exact Smith G1 for isotropic Beckmann; 0 for n.v <= 0."""
    return select(nov > 0.0, g1_smith(lambda_beckmann(nov, alpha)), 0.0)


@dual_use
def g2_separable(lambda_l, lambda_v):
    """Separable masking-shadowing G2 = G1(l) G1(v) (Heitz 2014, eq. 98)."""
    return g1_smith(lambda_l) * g1_smith(lambda_v)


@dual_use
def g2_height_correlated(lambda_l, lambda_v):
    """Height-correlated masking-shadowing G2 = 1 / (1 + Lambda(l) + Lambda(v)) (Heitz 2014, eq. 99)."""
    return 1.0 / (1.0 + lambda_l + lambda_v)


@dual_use
def visibility(g2, nol, nov):
    """V = G2 / (4 n.l n.v), the form real-time models use (Karis 2013; Filament sec. 4.4.2)."""
    denominator = 4.0 * np.maximum(nol, COS_MIN) * np.maximum(nov, COS_MIN)
    return select((nol > 0.0) & (nov > 0.0), g2 / denominator, 0.0)


@dual_use
def v_smith_ggx_height_correlated(nol, nov, alpha):
    """Height-correlated Smith-GGX visibility in the division-free form.

    Heitz 2014 eq. 99 with eq. 72, rearranged by Lagarde & de Rousiers 2014
    ("Moving Frostbite to PBR", listing 2) and used by Filament (sec. 4.4.2):
    V = 0.5 / (n.l sqrt((n.v)^2 (1 - a^2) + a^2) + n.v sqrt((n.l)^2 (1 - a^2) + a^2)).
    Equal to visibility(g2_height_correlated(...)) but finite at grazing angles.
    """
    a2 = alpha * alpha
    cl = np.minimum(np.maximum(nol, 0.0), 1.0)
    cv = np.minimum(np.maximum(nov, 0.0), 1.0)
    lv = cl * np.sqrt(cv * cv * (1.0 - a2) + a2)
    ll = cv * np.sqrt(cl * cl * (1.0 - a2) + a2)
    return select((nol > 0.0) & (nov > 0.0), 0.5 / np.maximum(lv + ll, 1e-300), 0.0)


@dual_use
def alpha_g_disney(roughness):
    """Disney's "hotness" remap for the masking term only: alpha_g = (0.5 + r / 2)^2.

    Burley 2012, sec. 5.6 (adopted by Karis 2013 for direct lighting).
    """
    return (0.5 + 0.5 * roughness) ** 2


@dual_use
def k_schlick_from_alpha(alpha):
    """Schlick's k that matches Smith GGX: k = alpha / 2 (Karis 2013, eq. 4 and its note)."""
    return 0.5 * alpha


@dual_use
def k_ue4_direct(roughness):
    """UE4 direct-light k = (r + 1)^2 / 8 = alpha_g_disney(r) / 2 (Karis 2013, eq. 4)."""
    return k_schlick_from_alpha(alpha_g_disney(roughness))


@dual_use
def k_ue4_ibl(roughness):
    """UE4 image-based-lighting k = alpha / 2 with alpha = r^2 (Karis 2013, "Specular G")."""
    return k_schlick_from_alpha(roughness * roughness)


@dual_use
def g1_schlick_ggx(nov, k):
    """Schlick-GGX G1 = n.v / (n.v (1 - k) + k) (Schlick 1994; Karis 2013, eq. 4)."""
    c = np.maximum(nov, 0.0)
    denominator = c * (1.0 - k) + k
    return select(nov > 0.0, c / np.maximum(denominator, 1e-300), 0.0)


@dual_use
def g2_schlick_ggx(nol, nov, k):
    """Separable Schlick-GGX G2 = G1(l) G1(v) (Karis 2013, eq. 4)."""
    return g1_schlick_ggx(nol, k) * g1_schlick_ggx(nov, k)


@dual_use
def g2_kelemen(nol, nov, voh):
    """Kelemen & Szirmay-Kalos 2001 ("A Microfacet Based Coupled Specular-Matte BRDF
    Model with Importance Sampling", Eurographics short paper): G2 = n.l n.v / (v.h)^2,
    i.e. V = 1 / (4 (v.h)^2).  Not bounded by 1; cheap."""
    h = np.maximum(voh, COS_MIN)
    return select((nol > 0.0) & (nov > 0.0), np.maximum(nol, 0.0) * np.maximum(nov, 0.0) / (h * h), 0.0)


@dual_use
def v_kelemen(voh):
    """Kelemen visibility V = 1 / (4 (v.h)^2) (Kelemen & Szirmay-Kalos 2001)."""
    h = np.maximum(voh, COS_MIN)
    return 0.25 / (h * h)


@dual_use
def v_neubelt(nol, nov):
    """Cloth visibility V = 1 / (4 (n.l + n.v - n.l n.v)) (Neubelt & Pettineo 2013,
    "Crafting a Next-Gen Material Pipeline for The Order: 1886"; Filament sec. 4.12.2)."""
    cl = np.maximum(nol, 0.0)
    cv = np.maximum(nov, 0.0)
    return select((nol > 0.0) & (nov > 0.0), 0.25 / np.maximum(cl + cv - cl * cv, COS_MIN), 0.0)
