"""The clear coat lobe of ``KHR_materials_clearcoat`` (the extension's README,
"Clearcoat BRDF"): the specular term of glTF 2.0's Appendix B at the coat's own
roughness,

    clearcoat_brdf = D(alpha_c) G(alpha_c) / (4 |N.V| |N.L|) = D V,

D GGX (B.3.2), V the separable Smith-GGX visibility (B.3.2), without a Fresnel
factor: the coat's Fresnel, clearcoat_fresnel = 0.04 + 0.96 (1 - |V.N|)^5, is the
weight of the layering operator :func:`pbrkit.brdf.operators.fresnel_coat`, which
mixes the coat over the material beneath.

Roughness: alpha_c = clearcoatRoughness^2, floored at ALPHA_MIN
(:func:`pbrkit.microfacet.roughness.alpha_from_roughness`).  Its parameters travel
in the BxDF's ``extra`` slots: the coat's weight (clearcoatFactor) at
:data:`CLEARCOAT_SLOT` and alpha_c at :data:`CLEARCOAT_ALPHA_SLOT` (the glTF
model's extended setup fills them).  The coat shares the material's shading
normal (a ``clearcoatNormalTexture`` is not applied).

- Sampling: GGX visible normals of alpha_c (:func:`pbrkit.brdf.lobes.ggx_normals`),
  role "coat"; the estimate is 1 (the white lobe's albedo is at most 1), scaled by
  the operator's clearcoat * clearcoat_fresnel(n.v).
- Directional albedo: the half-vector quadrature of its value at alpha_c
  (:func:`pbrkit.brdf.lobes.quadrature_albedo`).
"""

from __future__ import annotations

from ...core.jit import dual_use
from ..fresnel import f_schlick
from ...microfacet.ggx import d_ggx, lambda_ggx
from ...microfacet.smith import g2_separable, visibility
from . import Lobe, ggx_normals, quadrature_albedo

__all__ = ["CLEARCOAT_SLOT", "CLEARCOAT_ALPHA_SLOT", "CLEARCOAT", "clearcoat_value", "clearcoat_weight",
           "coated_emission"]

#: The BxDF ``extra`` slots of the coat: its weight (clearcoatFactor) and alpha_c.
CLEARCOAT_SLOT, CLEARCOAT_ALPHA_SLOT = 4, 5


@dual_use(inline=True)
def _alpha(b):
    return b.extra[CLEARCOAT_ALPHA_SLOT]


@dual_use(inline=True)
def clearcoat_weight(b):
    """The coat's weight, KHR_materials_clearcoat's clearcoatFactor (0: no coat)."""
    return b.extra[CLEARCOAT_SLOT]


@dual_use(inline="llvm")
def coated_emission(weight, f0, nov):
    """The factor on the emission beneath a coat of weight ``weight`` seen at n.v:
    1 - weight clearcoat_fresnel, clearcoat_fresnel = f0 + (1 - f0)(1 - |n.v|)^5
    (KHR_materials_clearcoat README, "Emission": the coat lies over the emission,
    coated_emission = emission (1 - clearcoat clearcoat_fresnel); its Fresnel is the
    layering's, :func:`pbrkit.brdf.operators.fresnel_coat`, f0 0.04 for the coat's
    IOR 1.5; the Khronos Sample Viewer takes f0 from the material's IOR).  n is the
    coat's normal, here the shading normal.  Works on arrays from Python."""
    return 1.0 - weight * f_schlick(abs(nov), f0, 1.0)


@dual_use(inline=True)
def clearcoat_value(b, c, ec, w):
    """D_GGX(n.h; alpha_c) V_separable(n.l, n.v; alpha_c) (white, no Fresnel), times
    the operators' weight ``w``; 0 without evaluating D and V when the weight ``w``
    is 0 (no coat)."""
    if w == 0.0:
        return 0.0, 0.0, 0.0
    a = _alpha(b)
    k = d_ggx(c.noh, a) * visibility(g2_separable(lambda_ggx(c.nol, a), lambda_ggx(c.nov, a)), c.nol, c.nov) * w
    return k, k, k


@dual_use(inline=True)
def _estimate(b, nov):
    return 1.0


#: KHR_materials_clearcoat's coat lobe (module docstring).
CLEARCOAT = Lobe("clearcoat", clearcoat_value, ggx_normals(_alpha), "coat", _estimate,
                 quadrature_albedo(clearcoat_value, _alpha))
