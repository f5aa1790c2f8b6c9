"""The Beckmann microfacet distribution as one unit: its D (isotropic and
anisotropic), its exact Smith Lambda and G1, and the sampling of its
distribution of normals (Walter et al. 2007) with its pdf.

Arguments are cosines and sines in the shading frame (``noh = n.h``,
``toh = t.h``, ``boh = b.h``, ``nov = n.v``, ``tov``, ``bov``); the samplers
and their pdfs take directions in the local frame (normal +z, tangent +x).
``alpha`` is the Beckmann width (the rms slope / sqrt 2 convention of Walter
et al. 2007), *not* perceptual roughness: the public models map perceptual
roughness r to alpha = r^2 (:func:`pbrkit.microfacet.roughness.alpha_from_roughness`),
following Burley 2012 and Karis 2013; no remap is applied here.

Every term is a :func:`pbrkit.core.jit.dual_use` function (NumPy on arrays,
compiled for scalars inside Numba kernels); each warp returns components and
has a NumPy wrapper ``sample_*(u, ...)``.  For u anywhere in [0, 1]^2
(including the edges) and any view, no warp returns NaN or Inf for alpha > 0
up to 1e20, and no pdf does for alpha from
:data:`pbrkit.microfacet.roughness.ALPHA_MIN` up.
"""

from __future__ import annotations

import numpy as np

from ..core.jit import dual_use, select
from ..sampling.warps import ONE_MINUS_EPSILON, _alpha, _direction_from_cos2, _square, _stack
from .smith import COS_MIN, _tan2, erf, g1_smith

__all__ = [
    "d_beckmann",
    "d_beckmann_anisotropic",
    "lambda_beckmann",
    "lambda_beckmann_anisotropic",
    "g1_beckmann",
    "warp_beckmann_ndf",
    "pdf_beckmann_ndf",
    "sample_beckmann_ndf",
]


# ------------------------------------------------------------------ D


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


# ------------------------------------------------------------------ Lambda, G1


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
def g1_beckmann(nov, alpha):
    """Exact Smith G1 for isotropic Beckmann; 0 for n.v <= 0."""
    return select(nov > 0.0, g1_smith(lambda_beckmann(nov, alpha)), 0.0)


# ------------------------------------------------------------------ sampling


@dual_use
def warp_beckmann_ndf(u1, u2, alpha):
    """Half vector h distributed as D_Beckmann(h) (n.h).

    Walter et al. 2007, eqs. 28-29: theta_h = arctan sqrt(-alpha^2 ln(1 - u1)),
    phi_h = 2 pi u2 (u1 is clamped to 1 - 2^-53 so u1 = 1 stays finite).
    alpha is the Beckmann width (rms slope / sqrt 2 convention of Walter).
    pdf: :func:`pdf_beckmann_ndf`.
    """
    u = np.minimum(u1, ONE_MINUS_EPSILON)
    tan2 = -alpha * alpha * np.log1p(-u)
    inv = 1.0 / (1.0 + tan2)
    return _direction_from_cos2(inv, tan2 * inv, u2)


# ------------------------------------------------------------------ pdfs (solid angle of h)


@dual_use
def pdf_beckmann_ndf(noh, alpha):
    """pdf of :func:`warp_beckmann_ndf`: D_Beckmann(h) (n.h) (Walter et al. 2007, eqs. 24-25,
    :func:`d_beckmann`)."""
    return d_beckmann(noh, alpha) * np.maximum(noh, 0.0)


# ------------------------------------------------------------------ NumPy wrappers


def sample_beckmann_ndf(u, alpha):
    """Beckmann half vectors with pdf D (n.h) (:func:`warp_beckmann_ndf`)."""
    u1, u2 = _square(u)
    return _stack(*warp_beckmann_ndf(u1, u2, _alpha(alpha)))
