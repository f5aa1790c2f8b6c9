"""Unreal Engine 4's shading model (Karis 2013, "Real Shading in Unreal Engine 4"):
Lambert diffuse plus the GGX lobe (alpha = r^2) with the separable Schlick-GGX
masking of the direct-light remap k = (r + 1)^2 / 8 and the spherical-Gaussian
Schlick Fresnel, in the metallic workflow with dielectric f0 = 0.16 reflectance^2
(UE4's ``Specular`` s is f0 = 0.08 s: :meth:`pbrkit.Material.from_ue4`).  Its
image-based lighting uses k = alpha / 2 (the split-sum table of Schlick-GGX).
"""

from __future__ import annotations

from ...core.jit import dual_use
from ..bxdf import metallic_workflow
from ...microfacet.roughness import alpha_from_roughness
from ..fresnel import f0_from_reflectance
from ..lobes.diffuse import LAMBERT
from ..lobes.microfacet import microfacet
from ..operators import add
from ..parameters import BASE_COLOR, METALLIC, REFLECTANCE, ROUGHNESS
from ..terms import GGX, SCHLICK_GGX_UE4, UE4_SG
from .model import Model

__all__ = ["MODEL", "SPECULAR", "ue4_specular"]

@dual_use(inline="llvm")
def setup(codes, row, params, q, columns, roughness, metallic, b0, b1, b2):
    return metallic_workflow(codes, row, roughness, alpha_from_roughness(roughness), metallic, b0, b1, b2,
                             f0_from_reflectance(params[q, columns.reflectance]), 1.0 - metallic)


#: D_GGX(alpha = r^2) V_SchlickGGX(k = (r + 1)^2 / 8) F_SG.
SPECULAR = microfacet(GGX, SCHLICK_GGX_UE4, UE4_SG)
#: UE4's specular lobe without Fresnel, D V (Karis 2013), for a BxDF of UE4.
ue4_specular = SPECULAR.parts.dv

MODEL = Model("ue4", "Unreal Engine 4 (Karis 2013)", (BASE_COLOR, METALLIC, ROUGHNESS, REFLECTANCE), setup,
              add(LAMBERT, SPECULAR), ("ggx", "schlick-ggx-ue4", "ue4-sg", "lambert"))
