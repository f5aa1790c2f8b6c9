"""Microfacet normal distribution functions D(h).

Every D here is normalised so that the projected area of the microfacets is
the macro-surface area: integral over the hemisphere of D(h) (n.h) dh = 1
(Walter, Marschner, Li, Torrance 2007, eq. 4).  Arguments are cosines and
sines in the shading frame: ``noh = n.h``, ``toh = t.h``, ``boh = b.h`` for the
tangent ``t`` and bitangent ``b``.  ``alpha`` is the width parameter of the
distribution, *not* perceptual roughness: the public models map perceptual
roughness r to alpha = r^2 (:func:`alpha_from_roughness`), following Burley
2012 and Karis 2013.

All functions are :func:`pbrkit.core.jit.dual_use` functions: NumPy on arrays of any
broadcastable shape, and compiled for scalars inside Numba kernels.
"""

from __future__ import annotations

import numpy as np

from ..core.jit import dual_use, select

__all__ = [
    "ALPHA_MIN",
    "alpha_from_roughness",
    "anisotropic_alphas",
    "anisotropic_alphas_burley",
    "d_ggx",
    "d_ggx_anisotropic",
    "d_beckmann",
    "d_beckmann_anisotropic",
    "d_gtr",
    "d_gtr1",
    "gtr_normalization",
    "d_blinn_phong",
    "phong_exponent_from_beckmann_alpha",
    "beckmann_alpha_from_phong_exponent",
]

#: Smallest alpha the public API uses.  Keeps D finite in float64 at r = 0
#: (peak D(n) = 1 / (pi alpha^2) ~ 3.2e5) so a smooth surface is mirror-like
#: without NaN.  (Filament clamps perceptual roughness at 0.045 for fp16
#: shaders; pbrkit computes in float64 and can afford a sharper lobe.)
ALPHA_MIN = 1e-3

_INV_PI = 1.0 / np.pi


@dual_use
def alpha_from_roughness(roughness):
    """alpha = r^2 for perceptual roughness r, clamped below at :data:`ALPHA_MIN`.

    The perceptual remap of Burley 2012 ("Physically-Based Shading at Disney",
    SIGGRAPH course notes, sec. 5.4) adopted by Karis 2013 and glTF 2.0.
    """
    return np.maximum(roughness * roughness, ALPHA_MIN)


@dual_use
def anisotropic_alphas(alpha, anisotropy):
    """(alpha_t, alpha_b) from alpha and anisotropy in [-1, 1].

    Kulla & Conty, "Revisiting Physically Based Shading at Imageworks",
    SIGGRAPH 2017 course notes, sec. 2.2 (also Filament's parameterisation):
    alpha_t = alpha (1 + a), alpha_b = alpha (1 - a), clamped at ALPHA_MIN.
    """
    at = np.maximum(alpha * (1.0 + anisotropy), ALPHA_MIN)
    ab = np.maximum(alpha * (1.0 - anisotropy), ALPHA_MIN)
    return at, ab


@dual_use
def anisotropic_alphas_burley(alpha, anisotropy):
    """(alpha_x, alpha_y) from alpha and anisotropy in [0, 1].

    Burley 2012, Appendix B.2: aspect = sqrt(1 - 0.9 a),
    alpha_x = alpha / aspect, alpha_y = alpha * aspect.
    """
    aspect = np.sqrt(1.0 - 0.9 * anisotropy)
    return np.maximum(alpha / aspect, ALPHA_MIN), np.maximum(alpha * aspect, ALPHA_MIN)


@dual_use
def d_ggx(noh, alpha):
    """GGX / Trowbridge-Reitz distribution.

    Trowbridge & Reitz 1975; Walter et al. 2007, eq. 33:
    D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2), zero for n.h <= 0.
    """
    a2 = alpha * alpha
    c = np.minimum(noh, 1.0)
    # (n.h)^2 (alpha^2 - 1) + 1 written as alpha^2 c^2 + (1 - c)(1 + c): no cancellation
    # near the peak for small alpha.
    d = a2 * c * c + (1.0 - c) * (1.0 + c)
    return select(noh > 0.0, a2 / (np.pi * d * d), 0.0)


@dual_use
def d_ggx_anisotropic(noh, toh, boh, alpha_t, alpha_b):
    """Anisotropic GGX.

    Burley 2012, Appendix B.2, eq. 13; Heitz 2014 ("Understanding the
    Masking-Shadowing Function in Microfacet-Based BRDFs", JCGT 3(2)), eq. 85:
    D = 1 / (pi a_t a_b ((t.h / a_t)^2 + (b.h / a_b)^2 + (n.h)^2)^2).
    """
    x = toh / alpha_t
    y = boh / alpha_b
    d = x * x + y * y + noh * noh
    return select(noh > 0.0, 1.0 / (np.pi * alpha_t * alpha_b * d * d), 0.0)


@dual_use
def d_beckmann(noh, alpha):
    """Beckmann distribution.

    Beckmann & Spizzichino 1963; Walter et al. 2007, eq. 25:
    D = exp(-tan^2 theta_h / alpha^2) / (pi alpha^2 cos^4 theta_h).
    """
    c = np.minimum(np.maximum(noh, 1e-8), 1.0)
    c2 = c * c
    a2 = alpha * alpha
    value = np.exp((c2 - 1.0) / (a2 * c2)) / (np.pi * a2 * c2 * c2)
    return select(noh > 0.0, value, 0.0)


@dual_use
def d_beckmann_anisotropic(noh, toh, boh, alpha_t, alpha_b):
    """Anisotropic Beckmann.

    Heitz 2014, eq. 84 (after Ward 1992):
    D = exp(-((t.h / a_t)^2 + (b.h / a_b)^2) / (n.h)^2) / (pi a_t a_b (n.h)^4).
    """
    c = np.minimum(np.maximum(noh, 1e-8), 1.0)
    c2 = c * c
    x = toh / alpha_t
    y = boh / alpha_b
    value = np.exp(-(x * x + y * y) / c2) / (np.pi * alpha_t * alpha_b * c2 * c2)
    return select(noh > 0.0, value, 0.0)


@dual_use
def gtr_normalization(alpha, gamma):
    """The constant c of the GTR distribution D = c / (alpha^2 cos^2 + sin^2)^gamma.

    Burley 2012, Appendix B.1 (eqs. 4-5):
    c = (gamma - 1)(alpha^2 - 1) / (pi (1 - (alpha^2)^(1 - gamma))) for gamma != 1
    and c = (alpha^2 - 1) / (pi ln alpha^2) for gamma = 1.  Both are written as
    (x / L)(y / expm1(y)) / pi with x = alpha^2 - 1, L = ln alpha^2 and
    y = (1 - gamma) L, whose removable singularities (alpha = 1, gamma = 1)
    are taken as their limits; so c(alpha = 1) = 1 / pi for every gamma.
    """
    a2 = alpha * alpha
    x = a2 - 1.0
    big_l = np.log(a2)
    l_ok = np.abs(big_l) > 1e-12
    x_over_l = select(l_ok, x / select(l_ok, big_l, 1.0), 1.0)
    y = (1.0 - gamma) * big_l
    y_ok = np.abs(y) > 1e-12
    y_over_expm1 = select(y_ok, y / select(y_ok, np.expm1(y), 1.0), 1.0)
    return x_over_l * y_over_expm1 * _INV_PI


@dual_use
def d_gtr(noh, alpha, gamma):
    """Generalised Trowbridge-Reitz (GTR) distribution.

    Burley 2012, Appendix B.1: D = c / (alpha^2 cos^2 theta_h + sin^2 theta_h)^gamma
    with c from :func:`gtr_normalization`.  gamma = 2 is GGX; gamma = 1 is
    Berry's distribution, used by the Disney clear coat (GTR1).
    """
    c = np.minimum(noh, 1.0)
    base = alpha * alpha * c * c + (1.0 - c) * (1.0 + c)
    return select(noh > 0.0, gtr_normalization(alpha, gamma) / base**gamma, 0.0)


@dual_use
def d_gtr1(noh, alpha):
    """GTR with gamma = 1 (Berry 1923), the Disney clear-coat lobe.

    Burley 2012, Appendix B.1: D = (alpha^2 - 1) / (pi ln(alpha^2) (alpha^2 cos^2 + sin^2)).
    The Disney clear coat uses alpha = lerp(0.1, 0.001, gloss), not r^2.
    """
    return d_gtr(noh, alpha, 1.0)


@dual_use
def d_blinn_phong(noh, exponent):
    """Normalised Blinn-Phong distribution.

    Blinn 1977; normalised as in Walter et al. 2007 (eq. 30) and Karis 2013
    ("Specular BRDF Reference"): D = (e + 2) / (2 pi) (n.h)^e.
    Relate e to a Beckmann alpha with :func:`phong_exponent_from_beckmann_alpha`.
    """
    c = np.minimum(np.maximum(noh, 0.0), 1.0)
    return select(noh > 0.0, (exponent + 2.0) / (2.0 * np.pi) * c**exponent, 0.0)


@dual_use
def phong_exponent_from_beckmann_alpha(alpha):
    """e = 2 / alpha^2 - 2 (Walter et al. 2007, eq. 30; Karis 2013 blog post)."""
    return 2.0 / (alpha * alpha) - 2.0


@dual_use
def beckmann_alpha_from_phong_exponent(exponent):
    """alpha = sqrt(2 / (e + 2)), the inverse of :func:`phong_exponent_from_beckmann_alpha`."""
    return np.sqrt(2.0 / (exponent + 2.0))
