"""The lobes of Disney's principled BRDF beyond the microfacet specular (Burley
2012, "Physically-Based Shading at Disney", sec. 5 and App. B; the BRDF
Explorer's ``disney.brdf``).  Their parameters travel in the BxDF's ``extra``
slots (:data:`SLOTS`), which the Disney model's setup fills.

- :data:`DISNEY_DIFFUSE`: Burley's diffuse mixed with his subsurface
  approximation, diffuse_color (mix(Burley, subsurface, s)); sampled by cosine.
- :data:`SHEEN`: (1 - l.h)^5 sheen_colour, the colour already carrying
  (1 - metallic); rides on the diffuse lobe's cosine samples (no estimate).
- :data:`CLEARCOAT`: 0.25 clearcoat D_GTR1(alpha_c) V F_Schlick(0.04), V the
  separable Smith-GGX visibility of alpha 0.25, alpha_c = mix(0.1, 0.001, gloss)
  (not r^2); sampled by GTR1 normals, its estimate 0.25 clearcoat F(n.v).
"""

from __future__ import annotations

from ...core.jit import dual_use
from ..diffuse import burley, burley_subsurface
from ..fresnel import f_schlick
from ...microfacet.ggx import lambda_ggx
from ...microfacet.gtr import d_gtr1
from ...microfacet.smith import g2_separable, visibility
from . import COSINE, Lobe, diffuse_estimate, gtr1_normals, quadrature_albedo

__all__ = ["SLOTS", "SUBSURFACE", "SHEEN_SLOT", "CLEARCOAT_SLOT", "CLEARCOAT_ALPHA", "DISNEY_DIFFUSE", "SHEEN",
           "CLEARCOAT", "CLEARCOAT_SPECULAR_ALPHA"]

#: The BxDF ``extra`` slots of Disney's lobes: subsurface, the sheen colour (3), the
#: clear coat weight 0.25 clearcoat and its GTR1 alpha.
SUBSURFACE, SHEEN_SLOT, CLEARCOAT_SLOT, CLEARCOAT_ALPHA = 0, 1, 4, 5
SLOTS = 6
#: The alpha of the clear coat's Smith masking (Burley 2012, App. B: fixed 0.25).
CLEARCOAT_SPECULAR_ALPHA = 0.25


@dual_use(inline=True)
def _disney_diffuse_value(b, c, ec, w):
    s = b.extra[SUBSURFACE]
    k = (burley(c.nol, c.nov, c.voh, b.roughness) * (1.0 - s)
         + burley_subsurface(c.nol, c.nov, c.voh, b.roughness) * s) * w
    return b.diffuse_color[0] * k, b.diffuse_color[1] * k, b.diffuse_color[2] * k


@dual_use(inline=True)
def _sheen_value(b, c, ec, w):
    k = f_schlick(c.voh, 0.0, 1.0) * w
    return b.extra[SHEEN_SLOT] * k, b.extra[SHEEN_SLOT + 1] * k, b.extra[SHEEN_SLOT + 2] * k


@dual_use(inline=True)
def _clearcoat_value(b, c, ec, w):
    weight = b.extra[CLEARCOAT_SLOT]
    coat = 0.0
    if weight > 0.0:
        coat_v = visibility(g2_separable(lambda_ggx(c.nol, CLEARCOAT_SPECULAR_ALPHA),
                                         lambda_ggx(c.nov, CLEARCOAT_SPECULAR_ALPHA)), c.nol, c.nov)
        coat = weight * d_gtr1(c.noh, b.extra[CLEARCOAT_ALPHA]) * coat_v * f_schlick(c.voh, 0.04, 1.0)
    coat *= w
    return coat, coat, coat


@dual_use(inline=True)
def _clearcoat_estimate(b, nov):
    return b.extra[CLEARCOAT_SLOT] * f_schlick(nov, 0.04, 1.0)


@dual_use(inline=True)
def _clearcoat_alpha(b):
    return b.extra[CLEARCOAT_ALPHA]


_GTR1 = gtr1_normals(_clearcoat_alpha)

DISNEY_DIFFUSE = Lobe("disney-diffuse", _disney_diffuse_value, COSINE, "diffuse", diffuse_estimate,
                      quadrature_albedo(_disney_diffuse_value))
SHEEN = Lobe("sheen", _sheen_value, COSINE, None, None, quadrature_albedo(_sheen_value))
CLEARCOAT = Lobe("clearcoat", _clearcoat_value, _GTR1, "coat", _clearcoat_estimate,
                 quadrature_albedo(_clearcoat_value, _clearcoat_alpha))
