"""Masking-shadowing functions G and visibility terms V = G2 / (4 n.l n.v).

The exact Smith terms live with their distributions in :mod:`pbrkit.microfacet`
and are re-exported here under their old names (this module only imports them):

- ``COS_MIN``, ``erf``, ``g1_smith``, ``g2_separable``, ``g2_height_correlated``,
  ``visibility``: :mod:`pbrkit.microfacet.smith` (Smith 1967; Heitz 2014,
  "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs",
  JCGT 3(2));
- ``lambda_ggx``, ``lambda_ggx_anisotropic``, ``g1_ggx``,
  ``v_smith_ggx_height_correlated``: :mod:`pbrkit.microfacet.ggx`;
- ``lambda_beckmann``, ``lambda_beckmann_anisotropic``, ``g1_beckmann``:
  :mod:`pbrkit.microfacet.beckmann`;
- ``alpha_g_disney``: :mod:`pbrkit.microfacet.roughness`.

Written here are the approximations that are not Smith's exact masking of a
distribution: Schlick-GGX with its k remaps (Schlick 1994; Karis 2013),
Kelemen & Szirmay-Kalos 2001, and Neubelt & Pettineo 2013's cloth visibility.
Arguments are cosines with the normal (``nov = n.v``, ``nol = n.l``), ``voh = v.h``,
Schlick's k, or perceptual roughness r where a remap says so (``k_ue4_direct``,
``k_ue4_ibl``); the distributions' alpha is not perceptual roughness (see
:mod:`pbrkit.microfacet.roughness`).

Direction cosines at or below zero give G = 0 (back-facing directions are
masked); cosines are clamped to 1e-8 internally so no NaN or Inf appears.
"""

from __future__ import annotations

import numpy as np

from ..core.jit import dual_use, select
from ..microfacet.beckmann import g1_beckmann, lambda_beckmann, lambda_beckmann_anisotropic
from ..microfacet.ggx import g1_ggx, lambda_ggx, lambda_ggx_anisotropic, v_smith_ggx_height_correlated
from ..microfacet.roughness import alpha_g_disney
from ..microfacet.smith import COS_MIN, erf, g1_smith, g2_height_correlated, g2_separable, visibility

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
