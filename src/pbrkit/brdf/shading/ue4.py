"""Unreal Engine 4's shading model (Karis 2013, "Real Shading in Unreal Engine 4"):
Lambert diffuse plus the GGX lobe (alpha = r^2) with the separable Schlick-GGX
masking of the direct-light remap k = (r + 1)^2 / 8 and the spherical-Gaussian
Schlick Fresnel, in the metallic workflow with dielectric f0 = 0.16 reflectance^2
(UE4's ``Specular`` s is f0 = 0.08 s: :meth:`pbrkit.Material.from_ue4`).  Its
image-based lighting uses k = alpha / 2 (the split-sum table of Schlick-GGX).
"""

from __future__ import annotations

from ...core.jit import dual_use
from ..bxdf import NO_EXTRA, BxDF
from ...microfacet.roughness import alpha_from_roughness
from ..fresnel import f0_from_reflectance, f0_metallic
from ..lobes.diffuse import LAMBERT
from ..lobes.microfacet import microfacet
from ..operators import add
from ..parameters import BASE_COLOR, METALLIC, REFLECTANCE, ROUGHNESS
from ..terms import GGX, SCHLICK_GGX_UE4, UE4_SG
from .model import Model

__all__ = ["MODEL", "SPECULAR", "ue4_specular"]

_Z3 = (0.0, 0.0, 0.0)


@dual_use(inline=True)
def setup(codes, row, params, q, columns, roughness, metallic, b0, b1, b2):
    alpha = alpha_from_roughness(roughness)
    f0d = f0_from_reflectance(params[q, columns.reflectance])
    f0 = (f0_metallic(b0, metallic, f0d), f0_metallic(b1, metallic, f0d), f0_metallic(b2, metallic, f0d))
    kd = 1.0 - metallic
    return BxDF(codes[row, 0], codes[row, 1], codes[row, 2], codes[row, 3], codes[row, 4], roughness, alpha,
                alpha, alpha, False, metallic, (b0, b1, b2), (b0 * kd, b1 * kd, b2 * kd), f0, 1.0, _Z3, _Z3, f0d,
                _Z3, NO_EXTRA)


#: D_GGX(alpha = r^2) V_SchlickGGX(k = (r + 1)^2 / 8) F_SG.
SPECULAR = microfacet(GGX, SCHLICK_GGX_UE4, UE4_SG)
#: UE4's specular lobe without Fresnel, D V (Karis 2013), for a BxDF of UE4.
ue4_specular = SPECULAR.parts.dv

MODEL = Model("ue4", "Unreal Engine 4 (Karis 2013)", (BASE_COLOR, METALLIC, ROUGHNESS, REFLECTANCE), setup,
              add(LAMBERT, SPECULAR), ("ggx", "schlick-ggx-ue4", "ue4-sg", "lambert"))
