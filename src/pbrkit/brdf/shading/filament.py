"""Filament's standard model (Filament documentation, sec. 4): Lambert or Burley
diffuse (or none), the GGX lobe (anisotropic when the material is: Kulla & Conty's
alpha_t = alpha (1 + a), alpha_b = alpha (1 - a), a in [-1, 1]) with the
height-correlated Smith-GGX visibility (Lagarde & de Rousiers' division-free
form when isotropic) and Schlick's Fresnel with f0 = 0.16 reflectance^2 (1 -
metallic) + base metallic and f90 = saturate(50 * 0.33 * sum(f0)) (Filament's
specular occlusion); alpha = r^2.
"""

from __future__ import annotations

from ...core.jit import dual_use
from ..bxdf import NO_EXTRA, BxDF
from ...microfacet.roughness import alpha_from_roughness, anisotropic_alphas
from ..fresnel import f0_from_reflectance, f0_metallic, f90_filament
from ..lobes.diffuse import diffuse_choice
from ..lobes.microfacet import microfacet
from ..operators import add
from ..parameters import ANISOTROPY, BASE_COLOR, METALLIC, REFLECTANCE, ROUGHNESS, Choice
from ..terms import GGX, HEIGHT_CORRELATED_DIVISION_FREE, SCHLICK_F90
from .model import Model

__all__ = ["MODEL", "DIFFUSE", "SPECULAR", "filament_specular"]

_Z3 = (0.0, 0.0, 0.0)
#: Filament's diffuse lobes.
DIFFUSE = Choice("diffuse", ("lambert", "burley", "none"), "lambert", "the diffuse lobe")


@dual_use(inline="llvm")
def setup(codes, row, params, q, columns, roughness, metallic, b0, b1, b2):
    alpha = alpha_from_roughness(roughness)
    anisotropy = params[q, columns.anisotropy]
    alpha_x, alpha_y, anisotropic = alpha, alpha, False
    if anisotropy != 0.0:
        alpha_x, alpha_y = anisotropic_alphas(alpha, anisotropy)
        anisotropic = True
    f0d = f0_from_reflectance(params[q, columns.reflectance])
    f0 = (f0_metallic(b0, metallic, f0d), f0_metallic(b1, metallic, f0d), f0_metallic(b2, metallic, f0d))
    kd = 1.0 - metallic
    return BxDF(codes[row, 0], codes[row, 1], codes[row, 2], codes[row, 3], codes[row, 4], roughness, alpha,
                alpha_x, alpha_y, anisotropic, 0.0, metallic, (b0, b1, b2), (b0 * kd, b1 * kd, b2 * kd), f0,
                f90_filament(f0[0] + f0[1] + f0[2]), _Z3, _Z3, f0d, _Z3, NO_EXTRA)


SPECULAR = microfacet(GGX, HEIGHT_CORRELATED_DIVISION_FREE, SCHLICK_F90)
#: Filament's specular lobe without Fresnel, D V (sec. 4.4), for a BxDF of Filament.
filament_specular = SPECULAR.parts.dv

MODEL = Model("filament", "Filament's standard model (Filament documentation, sec. 4)",
              (BASE_COLOR, METALLIC, ROUGHNESS, REFLECTANCE, ANISOTROPY, DIFFUSE), setup,
              add(diffuse_choice(DIFFUSE.choices), SPECULAR), ("ggx", "height-correlated", "schlick", None),
              variants=(("ggx", "height-correlated", "schlick", "lambert"),))
