"""The "Charlie" sheen distribution as one unit: its D, the sheen visibility of
``KHR_materials_sheen`` (Estevez and Kulla's fitted Lambda, and the cheaper
Ashikhmin-Premoze visibility the specification allows), and the sampling of
its distribution of normals with its pdf.

Sources: Estevez and Kulla 2017, "Production Friendly Microfacet Sheen BRDF"
(SIGGRAPH 2017 course "Physically Based Shading", Sony Pictures Imageworks);
the ``KHR_materials_sheen`` specification, section "Implementation Notes"
(subsections "Sheen distribution" and "Sheen visibility"), whose formulas the
Khronos glTF Sample Viewer evaluates (``brdf.glsl``: ``D_Charlie``,
``lambdaSheenNumericHelper``, ``lambdaSheen``, ``V_Sheen``).

Roughness: every term takes the distribution's alpha, alpha = sheenRoughness^2
(the specification's ``alpha_g = sheenRoughness * sheenRoughness``), never the
sheen roughness itself; alpha is floored at 1e-12 (the Sample Viewer floors
sheenRoughness at 1e-6), where D tends to a delta at grazing half vectors.

Charlie has no Smith Lambda in closed form: the specification's visibility is
built on Estevez and Kulla's fit of it, which is also what :func:`g2_charlie`
returns in the height-correlated form 1 / (1 + Lambda(n.v) + Lambda(n.l)).
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import dual_use, select
from ..sampling.warps import _alpha, _direction_from_cos2, _square, _stack

__all__ = [
    "charlie_alpha",
    "d_charlie",
    "lambda_charlie",
    "g2_charlie",
    "v_charlie",
    "v_ashikhmin",
    "warp_charlie_ndf",
    "pdf_charlie_ndf",
    "sample_charlie",
]

_INV_TWO_PI = 0.5 / math.pi
_ALPHA_MIN = 1e-12


@dual_use
def charlie_alpha(sheen_roughness):
    """alpha = sheenRoughness^2, floored at 1e-12 (KHR_materials_sheen, "Sheen
    distribution": ``alpha_g = sheenRoughness * sheenRoughness``)."""
    return np.maximum(sheen_roughness * sheen_roughness, _ALPHA_MIN)


@dual_use
def d_charlie(noh, alpha):
    """The Charlie distribution D(h) = (2 + 1 / alpha) sin(theta_h)^(1 / alpha) / (2 pi).

    Estevez and Kulla 2017, eq. 2 (an exponentiated sine, after Ashikhmin's
    velvet); KHR_materials_sheen "Sheen distribution", which evaluates the sine
    as (1 - (n.h)^2)^(1 / (2 alpha)).  Normalised: the integral of D(h) n.h over
    the hemisphere is 1.  ``alpha`` = sheenRoughness^2 (module docstring);
    0 below the horizon (n.h < 0).
    """
    a = np.maximum(alpha, _ALPHA_MIN)
    c = np.minimum(np.maximum(noh, 0.0), 1.0)
    sin2 = (1.0 - c) * (1.0 + c)
    return select(noh >= 0.0, (2.0 + 1.0 / a) * sin2 ** (0.5 / a) * _INV_TWO_PI, 0.0)


@dual_use
def _lambda_fit(x, alpha):
    # L(x) = a / (1 + b x^c) + d x + e, each coefficient interpolated between its
    # alpha = 0 and alpha = 1 fit by (1 - alpha)^2 (Estevez and Kulla 2017, Table 1;
    # KHR_materials_sheen "Sheen visibility", the function l(x, alpha_g))
    t = (1.0 - alpha) * (1.0 - alpha)
    a = 25.3245 + (21.5473 - 25.3245) * (1.0 - t)
    b = 3.32435 + (3.82987 - 3.32435) * (1.0 - t)
    c = 0.16801 + (0.19823 - 0.16801) * (1.0 - t)
    d = -1.27393 + (-1.97760 + 1.27393) * (1.0 - t)
    e = -4.85967 + (-4.32054 + 4.85967) * (1.0 - t)
    return a / (1.0 + b * np.maximum(x, 0.0) ** c) + d * x + e


@dual_use
def lambda_charlie(cos_theta, alpha):
    """Estevez and Kulla's fitted Smith Lambda of the Charlie distribution:
    exp(L(cos)) for |cos| < 0.5, exp(2 L(0.5) - L(1 - cos)) beyond (the fit is of
    the lower half and mirrored to stay smooth at 0.5), L the five-coefficient
    curve of :func:`_lambda_fit` (Estevez and Kulla 2017, sec. 3 and Table 1;
    KHR_materials_sheen "Sheen visibility", ``lambda_sheen``).  alpha =
    sheenRoughness^2."""
    x = np.abs(cos_theta)
    low = np.exp(_lambda_fit(np.minimum(x, 0.5), alpha))
    high = np.exp(2.0 * _lambda_fit(0.5, alpha) - _lambda_fit(np.maximum(1.0 - x, 0.0), alpha))
    return select(x < 0.5, low, high)


@dual_use
def g2_charlie(nol, nov, alpha):
    """The height-correlated masking-shadowing 1 / (1 + Lambda(n.v) + Lambda(n.l)) of
    the fitted Lambda (:func:`lambda_charlie`; Estevez and Kulla 2017, sec. 3,
    with the "terminator softening" of their sec. 3.1 left out, as the
    specification leaves it out)."""
    return 1.0 / (1.0 + lambda_charlie(nov, alpha) + lambda_charlie(nol, alpha))


@dual_use
def v_charlie(nol, nov, alpha):
    """The sheen visibility nu_s = G2 / (4 n.l n.v) of KHR_materials_sheen ("Sheen
    visibility": ``sheen_visibility``), G2 of :func:`g2_charlie`; 0 unless both
    cosines are positive.  alpha = sheenRoughness^2."""
    ok = (nol > 0.0) & (nov > 0.0)
    denominator = select(ok, 4.0 * nol * nov, 1.0)
    return select(ok, g2_charlie(nol, nov, alpha) / denominator, 0.0)


@dual_use
def v_ashikhmin(nol, nov):
    """The cheaper sheen visibility 1 / (4 (n.l + n.v - n.l n.v)) (Ashikhmin and
    Premoze 2007, "Distribution-based BRDFs"; Neubelt and Pettineo 2013, "Crafting a
    Next-Gen Material Pipeline for The Order: 1886", the cloth BRDF), which
    KHR_materials_sheen ("Sheen visibility") allows on constrained devices -- not
    energy conserving under the albedo scaling, whose table assumes
    :func:`v_charlie`.  0 unless both cosines are positive."""
    l = np.maximum(nol, 0.0)
    v = np.maximum(nov, 0.0)
    s = l + v - l * v
    return select((l > 0.0) & (v > 0.0), 0.25 / np.maximum(s, 1e-300), 0.0)


@dual_use
def warp_charlie_ndf(u1, u2, alpha):
    """A half vector h distributed as D_Charlie(h) (n.h), by inversion.

    The density of theta_h is 2 pi D sin cos = (2 + 1 / alpha) sin^(1 + 1 / alpha)
    cos, whose cumulative distribution is sin(theta_h)^(2 + 1 / alpha) (the
    derivative of sin^k is k sin^(k - 1) cos, k = 2 + 1 / alpha); so
    sin theta_h = u1^(alpha / (2 alpha + 1)), phi_h = 2 pi u2 (derived here from
    Estevez and Kulla 2017, eq. 2; the Sample Viewer's IBL filter samples Charlie
    the same way).  alpha = sheenRoughness^2.  pdf: :func:`pdf_charlie_ndf`.
    """
    a = np.maximum(alpha, _ALPHA_MIN)
    sin2 = u1 ** (2.0 * a / (2.0 * a + 1.0))
    cos2 = np.maximum(1.0 - sin2, 0.0)
    return _direction_from_cos2(cos2, sin2, u2)


@dual_use
def pdf_charlie_ndf(noh, alpha):
    """pdf (solid angle of h) of :func:`warp_charlie_ndf`: D_Charlie(h) (n.h)."""
    return d_charlie(noh, alpha) * np.maximum(noh, 0.0)


def sample_charlie(u, alpha):
    """Charlie half vectors with pdf D (n.h) (:func:`warp_charlie_ndf`); ``u`` (..., 2)."""
    u1, u2 = _square(u)
    return _stack(*warp_charlie_ndf(u1, u2, _alpha(alpha)))
