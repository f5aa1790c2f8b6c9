"""Unity URP's mobile BRDF (URP ``BRDF.hlsl``; after Renaldas Zioma, "Optimizing
PBR for Mobile", SIGGRAPH 2015): diffuse base (0.96 (1 - metallic)) / pi and the
"minimalist Cook-Torrance" term times the specular colour lerp(0.04, base,
metallic) (``kDielectricSpec``), alpha = r^2 (``PerceptualRoughnessToRoughness``).
Unity's punctual lights carry a factor pi, so the BRDF value is the term
divided by pi.  The dielectric f0 is URP's fixed 0.04.
"""

from __future__ import annotations

import math

import numpy as np

from ...core.jit import dual_use, select
from ..bxdf import metallic_workflow
from ...microfacet.roughness import alpha_from_roughness
from ..lobes.diffuse import LAMBERT
from ..lobes.microfacet import microfacet
from ..operators import add
from ..parameters import BASE_COLOR, METALLIC, ROUGHNESS
from ..terms import CONSTANT_F0, GGX, HEIGHT_CORRELATED
from .model import Model

__all__ = ["MODEL", "URP_DIELECTRIC_F0", "urp_specular", "urp_diffuse_weight", "SPECULAR"]

#: URP's dielectric specular colour ``kDielectricSpec.rgb`` (URP ``BRDF.hlsl``).
URP_DIELECTRIC_F0 = 0.04
_INV_PI = 1.0 / math.pi


@dual_use
def urp_diffuse_weight(metallic):
    """URP's diffuse weight ``OneMinusReflectivityMetallic``: (1 - 0.04)(1 - metallic)
    = 0.96 (1 - metallic) (URP ``BRDF.hlsl``, ``kDielectricSpec.a = 1 - 0.04``)."""
    return (1.0 - URP_DIELECTRIC_F0) * (1.0 - metallic)


@dual_use
def urp_specular(noh, loh, alpha):
    """Unity URP's "minimalist Cook-Torrance" specular term (URP ``BRDF.hlsl``,
    ``DirectBRDFSpecular``; after Renaldas Zioma, "Optimizing PBR for Mobile",
    SIGGRAPH 2015): alpha^2 / (d^2 max(0.1, (l.h)^2) (4 alpha + 2)) with
    d = (n.h)^2 (alpha^2 - 1) + 1.  Unity's lights carry a factor pi, so the
    BRDF value is this term divided by pi."""
    a2 = alpha * alpha
    c = np.minimum(np.maximum(noh, 0.0), 1.0)
    d = a2 * c * c + (1.0 - c) * (1.0 + c)  # = c^2 (alpha^2 - 1) + 1 without cancellation
    return select(noh > 0.0, a2 / (d * d * np.maximum(0.1, loh * loh) * (4.0 * alpha + 2.0)), 0.0)


@dual_use(inline=True)
def _urp_dv(b, c):
    return urp_specular(c.noh, c.voh, b.alpha) * _INV_PI


@dual_use(inline="llvm")
def setup(codes, row, params, q, columns, roughness, metallic, b0, b1, b2):
    return metallic_workflow(codes, row, roughness, alpha_from_roughness(roughness), metallic, b0, b1, b2,
                             URP_DIELECTRIC_F0, urp_diffuse_weight(metallic))


#: URP's term / pi with F the specular colour (D and V name the GGX and its
#: height-correlated Smith masking it approximates: the explorer's terms, the table).
SPECULAR = microfacet(GGX, HEIGHT_CORRELATED, CONSTANT_F0, dv=_urp_dv)

MODEL = Model("urp_mobile", "Unity URP's mobile BRDF (Zioma 2015)", (BASE_COLOR, METALLIC, ROUGHNESS), setup,
              add(LAMBERT, SPECULAR), ("ggx", "height-correlated", "schlick", "lambert"))
