"""The normalised Blinn-Phong microfacet distribution as one unit: its D and
the exponent <-> Beckmann alpha relation.

Blinn-Phong has no closed-form Smith Lambda of its own; Walter et al. 2007
(sec. 5.2, eq. 30) pair it with the Beckmann distribution whose alpha
matches the exponent e, alpha = sqrt(2 / (e + 2)), and use that distribution's
Lambda (:mod:`pbrkit.microfacet.beckmann`).  That is an approximation of the
Smith masking of the Blinn-Phong D itself (close for large e;
tests/test_masking.py measures how far the weak white furnace is from 1).

Arguments: ``noh = n.h`` and the exponent e, *not* perceptual roughness or
alpha: a model with perceptual roughness r takes alpha = r^2
(:func:`pbrkit.microfacet.roughness.alpha_from_roughness`, Burley 2012, Karis
2013) and e = 2 / alpha^2 - 2 (:func:`phong_exponent_from_beckmann_alpha`).
Every term is a :func:`pbrkit.core.jit.dual_use` function.
"""

from __future__ import annotations

import numpy as np

from ..core.jit import dual_use, select

__all__ = [
    "d_blinn_phong",
    "phong_exponent_from_beckmann_alpha",
    "beckmann_alpha_from_phong_exponent",
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
