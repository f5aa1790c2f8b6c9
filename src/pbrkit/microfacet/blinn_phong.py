"""The normalised Blinn-Phong microfacet distribution as one unit: its D, the
exponent <-> Beckmann alpha relation, its masking "via its Beckmann
equivalent", and the exact sampling of its distribution of normals with its pdf.

Blinn-Phong has no closed-form Smith Lambda of its own; Walter et al. 2007
(sec. 5.2, eq. 30) pair it with the Beckmann distribution whose alpha
matches the exponent e, alpha = sqrt(2 / (e + 2)), and use that distribution's
Lambda (:func:`lambda_blinn_phong`).  That is an approximation of the Smith
masking of the Blinn-Phong D itself (close for large e; tests/brdf/test_masking.py
measures how far the weak white furnace is from 1).

Arguments: ``noh = n.h``, ``nov = n.v`` and the exponent e, *not* perceptual
roughness or alpha: a model with perceptual roughness r takes alpha = r^2
(:func:`pbrkit.microfacet.roughness.alpha_from_roughness`, Burley 2012, Karis
2013) and e = 2 / alpha^2 - 2 (:func:`phong_exponent_from_beckmann_alpha`).
Every term is a :func:`pbrkit.core.jit.dual_use` function; the warp returns
components and :func:`sample_blinn_phong_ndf` is its NumPy wrapper.
"""

from __future__ import annotations

import numpy as np

from ..core.jit import dual_use, select
from ..sampling.warps import _TINY, _TWO_PI, _square, _stack
from .beckmann import lambda_beckmann

__all__ = [
    "d_blinn_phong",
    "phong_exponent_from_beckmann_alpha",
    "beckmann_alpha_from_phong_exponent",
    "lambda_blinn_phong",
    "warp_blinn_phong_ndf",
    "pdf_blinn_phong_ndf",
    "sample_blinn_phong_ndf",
]


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


@dual_use
def lambda_blinn_phong(nov, exponent):
    """Smith Lambda of Blinn-Phong via its Beckmann equivalent: Beckmann's exact Lambda
    (:func:`pbrkit.microfacet.beckmann.lambda_beckmann`, Heitz 2014 eq. 83) at
    alpha = sqrt(2 / (e + 2)) (Walter et al. 2007, sec. 5.2 and eq. 30); an
    approximation of the Blinn-Phong D's own Smith Lambda (module docstring).
    G1 = :func:`pbrkit.microfacet.smith.g1_smith` of it."""
    return lambda_beckmann(nov, beckmann_alpha_from_phong_exponent(exponent))


@dual_use
def warp_blinn_phong_ndf(u1, u2, exponent):
    """Half vector h distributed as D_Blinn-Phong(h) (n.h), exactly.

    D cos = (e + 2) / (2 pi) cos^(e + 1) theta_h has the cdf cos^(e + 2) theta_h
    in cos theta_h, so cos theta_h = u1^(1 / (e + 2)) and phi_h = 2 pi u2 (the
    sampling of Walter et al. 2007's normalised Phong distribution, sec. 5.2).
    Written as cos theta_h = exp(t) and 1 - cos theta_h = -expm1(t) with
    t = ln(u1) / (e + 2), so sin theta_h keeps its precision for large e
    (u1 = 0 is taken as 1e-300).  Any e > -2.  pdf: :func:`pdf_blinn_phong_ndf`.
    """
    t = np.log(np.maximum(u1, _TINY)) / np.maximum(exponent + 2.0, _TINY)
    cos_theta = np.exp(t)
    sin_theta = np.sqrt(np.maximum(-np.expm1(t) * (1.0 + cos_theta), 0.0))
    phi = _TWO_PI * u2
    return sin_theta * np.cos(phi), sin_theta * np.sin(phi), cos_theta


@dual_use
def pdf_blinn_phong_ndf(noh, exponent):
    """pdf of :func:`warp_blinn_phong_ndf` w.r.t. the solid angle of h: D(h) (n.h)
    with D of :func:`d_blinn_phong` (Walter et al. 2007, eq. 24)."""
    return d_blinn_phong(noh, exponent) * np.maximum(noh, 0.0)


def _exponent(exponent):
    e = np.asarray(exponent, dtype=np.float64)
    if not np.all(np.isfinite(e) & (e > -2.0)):
        raise ValueError("exponent must be finite and greater than -2")
    return e


def sample_blinn_phong_ndf(u, exponent):
    """Blinn-Phong half vectors with pdf D (n.h) (:func:`warp_blinn_phong_ndf`);
    ``exponent`` broadcasts against u[..., 0]."""
    u1, u2 = _square(u)
    return _stack(*warp_blinn_phong_ndf(u1, u2, _exponent(exponent)))
