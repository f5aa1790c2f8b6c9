"""Microfacet normal distribution functions D(h) and the roughness remaps: a
facade over the units of :mod:`pbrkit.microfacet`, where each formula lives.

- ``ALPHA_MIN``, ``alpha_from_roughness``, ``anisotropic_alphas``,
  ``anisotropic_alphas_burley``: :mod:`pbrkit.microfacet.roughness`;
- ``d_ggx``, ``d_ggx_anisotropic``: :mod:`pbrkit.microfacet.ggx`;
- ``d_beckmann``, ``d_beckmann_anisotropic``: :mod:`pbrkit.microfacet.beckmann`;
- ``gtr_normalization``, ``d_gtr``, ``d_gtr1``: :mod:`pbrkit.microfacet.gtr`;
- ``d_blinn_phong``, ``phong_exponent_from_beckmann_alpha``,
  ``beckmann_alpha_from_phong_exponent``: :mod:`pbrkit.microfacet.blinn_phong`.

Every D there is normalised so that the projected area of the microfacets is
the macro-surface area: integral over the hemisphere of D(h) (n.h) dh = 1
(Walter, Marschner, Li, Torrance 2007, eq. 4).  Arguments are cosines and
sines in the shading frame: ``noh = n.h``, ``toh = t.h``, ``boh = b.h`` for the
tangent ``t`` and bitangent ``b``.  ``alpha`` is the width parameter of the
distribution, *not* perceptual roughness: the public models map perceptual
roughness r to alpha = r^2 (:func:`alpha_from_roughness`), following Burley
2012 and Karis 2013.  This module only imports (``pbrkit.distributions`` and
``pbrkit.brdf.distributions`` keep their names).
"""

from __future__ import annotations

from ..microfacet.beckmann import d_beckmann, d_beckmann_anisotropic
from ..microfacet.blinn_phong import (
    beckmann_alpha_from_phong_exponent,
    d_blinn_phong,
    phong_exponent_from_beckmann_alpha,
)
from ..microfacet.ggx import d_ggx, d_ggx_anisotropic
from ..microfacet.gtr import d_gtr, d_gtr1, gtr_normalization
from ..microfacet.roughness import (
    ALPHA_MIN,
    alpha_from_roughness,
    anisotropic_alphas,
    anisotropic_alphas_burley,
)

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
