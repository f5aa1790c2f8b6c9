"""The generalised Trowbridge-Reitz (GTR) distributions of Burley 2012 as one
unit: the normalisation constant, D for any gamma, GTR1 (Berry's distribution,
gamma = 1, the Disney clear coat) and the sampling of GTR1's distribution of
normals with its pdf.

GTR1 has no closed-form Smith Lambda (Burley 2012 pairs the clear coat with a
fixed GGX masking term, alpha = 0.25), so there is no Lambda, G1 or
visible-normal sampler here; gamma = 2 is GGX (:mod:`pbrkit.microfacet.ggx`).

Arguments: ``noh = n.h``; ``alpha`` is the width of the distribution, *not*
perceptual roughness (the Disney clear coat uses alpha = lerp(0.1, 0.001,
gloss), not r^2; :mod:`pbrkit.microfacet.roughness` holds the other remaps).
Every term is a :func:`pbrkit.core.jit.dual_use` function; the warp returns
components, :func:`sample_gtr1_ndf` is its NumPy wrapper.
"""

from __future__ import annotations

import numpy as np

from ..core.jit import dual_use, select
from ..sampling.warps import _alpha, _direction_from_cos2, _square, _stack

__all__ = [
    "gtr_normalization",
    "d_gtr",
    "d_gtr1",
    "warp_gtr1_ndf",
    "pdf_gtr1_ndf",
    "sample_gtr1_ndf",
]

_INV_PI = 1.0 / np.pi


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
    GTR1 has no closed-form Smith Lambda (module docstring).
    """
    return d_gtr(noh, alpha, 1.0)


@dual_use
def warp_gtr1_ndf(u1, u2, alpha):
    """Half vector h distributed as D_GTR1(h) (n.h) (Berry's distribution, Disney clear coat).

    Burley 2012, "Physically-Based Shading at Disney", Appendix B.2:
    cos^2 theta_h = (1 - alpha^(2 (1 - u1))) / (1 - alpha^2), phi_h = 2 pi u2,
    evaluated with L = ln alpha^2 as cos^2 = expm1((1 - u1) L) / expm1(L) and
    sin^2 = exp((1 - u1) L) expm1(u1 L) / expm1(L); at alpha = 1 (L = 0) the limit
    cos^2 = 1 - u1.  The Disney clear coat uses alpha = lerp(0.1, 0.001, gloss),
    not r^2.  pdf: :func:`pdf_gtr1_ndf`.
    """
    big_l = np.log(alpha * alpha)
    l_ok = np.abs(big_l) > 1e-12
    safe_l = select(l_ok, big_l, 1.0)
    denominator = np.expm1(safe_l)
    cos2 = select(l_ok, np.expm1((1.0 - u1) * safe_l) / denominator, 1.0 - u1)
    sin2 = select(l_ok, np.exp((1.0 - u1) * safe_l) * np.expm1(u1 * safe_l) / denominator, u1)
    return _direction_from_cos2(cos2, sin2, u2)


@dual_use
def pdf_gtr1_ndf(noh, alpha):
    """pdf of :func:`warp_gtr1_ndf`: D_GTR1(h) (n.h) (Burley 2012, Appendix B.2,
    :func:`d_gtr1`)."""
    return d_gtr1(noh, alpha) * np.maximum(noh, 0.0)


def sample_gtr1_ndf(u, alpha):
    """GTR1 (Berry) half vectors with pdf D (n.h) (:func:`warp_gtr1_ndf`)."""
    u1, u2 = _square(u)
    return _stack(*warp_gtr1_ndf(u1, u2, _alpha(alpha)))
