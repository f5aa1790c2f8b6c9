"""Disney's principled BRDF (Burley 2012, "Physically-Based Shading at Disney",
sec. 5 and Appendix B; the BRDF Explorer's ``disney.brdf``):

    f = (1 - metallic) [base (mix(Burley, subsurface, s)) + sheen] + D_s F_s V_s + clearcoat,

the sum of the lobes of :mod:`pbrkit.brdf.lobes.disney` and an anisotropic GGX
specular (alpha = r^2 and Burley's aspect, anisotropy in [0, 1]) with the
separable exact Smith G (the BRDF Explorer's, without the 2012 notes' alpha_g
"hotness" remap) and Schlick's F from C_spec0 = mix(0.08 specular mix(1,
C_tint, specular_tint), base, metallic), 0.08 specular = 0.16 reflectance^2;
C_tint = base / luminance(base), luminance 0.3 R + 0.6 G + 0.1 B.  Sheen: (1 -
l.h)^5 sheen mix(1, C_tint, sheen_tint); clear coat: 0.25 clearcoat
D_GTR1(mix(0.1, 0.001, gloss)) F_Schlick(0.04) V_Smith(0.25).  In real time
(:func:`ibl_extras`) the clear coat is a second prefiltered lookup at its own
roughness, and the sheen its albedo table times the irradiance.
"""

from __future__ import annotations

import math

from ...core.filtering import linear_1d
from ...core.jit import dual_use, select
from ..bxdf import BxDF
from ...microfacet.roughness import alpha_from_roughness, anisotropic_alphas_burley
from ..fresnel import f0_from_reflectance, f0_metallic
from ..lobes.disney import CLEARCOAT, CLEARCOAT_ALPHA, CLEARCOAT_SLOT, DISNEY_DIFFUSE, SHEEN, SHEEN_SLOT
from ..lobes.microfacet import microfacet
from ..operators import add
from ..parameters import ANISOTROPY, BASE_COLOR, METALLIC, REFLECTANCE, ROUGHNESS, Parameter, narrowed
from ..terms import GGX, SCHLICK, SEPARABLE
from .model import Model, RealTime

__all__ = ["MODEL", "SPECULAR", "disney_tint", "disney_clearcoat_alpha", "ibl_extras", "ibl_coat_roughness",
           "EXTRAS"]

_Z3 = (0.0, 0.0, 0.0)
_INV_PI = 1.0 / math.pi


def _unit(name, default, doc):
    return Parameter(name, default, 0.0, 1.0, "", doc)


#: Disney's parameters beyond the metallic-roughness ones (Burley 2012, sec. 5.1).
EXTRAS = (
    _unit("subsurface", 0.0, "mix of Burley's diffuse and his subsurface approximation"),
    _unit("specular_tint", 0.0, "tints the dielectric f0 towards the base colour's hue"),
    _unit("sheen", 0.0, "grazing retro-reflective sheen, (1 - l.h)^5"),
    _unit("sheen_tint", 0.5, "tints the sheen towards the base colour's hue"),
    _unit("clearcoat", 0.0, "a second, GTR1 specular lobe of f0 0.04 (weight 0.25 clearcoat)"),
    _unit("clearcoat_gloss", 1.0, "the clear coat's GTR1 alpha = mix(0.1, 0.001, gloss)"),
)
_ANISOTROPY = narrowed(ANISOTROPY, low=0.0, doc="Burley's aspect: alpha_x = alpha / sqrt(1 - 0.9 a), "
                                               "alpha_y = alpha sqrt(1 - 0.9 a)")


@dual_use
def disney_tint(c, luminance):
    """Disney's hue-only tint C_tint = C / luminance(C) of one channel, 1 for a
    black colour; the luminance is 0.3 R + 0.6 G + 0.1 B (Burley 2012, App. B;
    the BRDF Explorer's ``disney.brdf``)."""
    return select(luminance > 0.0, c / select(luminance > 0.0, luminance, 1.0), 1.0)


@dual_use
def disney_clearcoat_alpha(gloss):
    """The GTR1 width of Disney's clear coat, alpha = mix(0.1, 0.001, clearcoat_gloss)
    (Burley 2012, App. B; not r^2)."""
    return 0.1 + (0.001 - 0.1) * gloss


@dual_use(inline="llvm")
def setup(codes, row, params, q, columns, roughness, metallic, b0, b1, b2):
    alpha = alpha_from_roughness(roughness)
    anisotropy = params[q, columns.anisotropy]
    alpha_x, alpha_y, anisotropic = alpha, alpha, False
    if anisotropy != 0.0:
        alpha_x, alpha_y = anisotropic_alphas_burley(alpha, anisotropy)
        anisotropic = True
    f0d = f0_from_reflectance(params[q, columns.reflectance])
    lum = 0.3 * b0 + 0.6 * b1 + 0.1 * b2
    t0 = disney_tint(b0, lum)
    t1 = disney_tint(b1, lum)
    t2 = disney_tint(b2, lum)
    st = params[q, columns.specular_tint]
    f0 = (f0_metallic(b0, metallic, f0d * (1.0 + (t0 - 1.0) * st)),
          f0_metallic(b1, metallic, f0d * (1.0 + (t1 - 1.0) * st)),
          f0_metallic(b2, metallic, f0d * (1.0 + (t2 - 1.0) * st)))
    kd = 1.0 - metallic
    s = params[q, columns.sheen]
    sht = params[q, columns.sheen_tint]
    extra = (params[q, columns.subsurface], s * (1.0 + (t0 - 1.0) * sht) * kd, s * (1.0 + (t1 - 1.0) * sht) * kd,
             s * (1.0 + (t2 - 1.0) * sht) * kd, 0.25 * params[q, columns.clearcoat],
             disney_clearcoat_alpha(params[q, columns.clearcoat_gloss]), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    return BxDF(codes[row, 0], codes[row, 1], codes[row, 2], codes[row, 3], codes[row, 4], roughness, alpha,
                alpha_x, alpha_y, anisotropic, 0.0, metallic, (b0, b1, b2), (b0 * kd, b1 * kd, b2 * kd), f0, 1.0, _Z3,
                _Z3, f0d, _Z3, extra)


SPECULAR = microfacet(GGX, SEPARABLE, SCHLICK)


@dual_use(inline=True)
def ibl_coat_roughness(b):
    """The perceptual roughness of the clear coat's prefiltered lookup, sqrt of its
    GTR1 alpha (-1 without a clear coat)."""
    if b.extra[CLEARCOAT_SLOT] > 0.0:
        return math.sqrt(b.extra[CLEARCOAT_ALPHA])
    return -1.0


@dual_use(inline=True)
def ibl_extras(b, nov, coat_nov, coat_dfg1, coat_dfg2, sheen_table, irradiance, coat_prefiltered, sheen_prefiltered, dfg1, dfg2,
              radiance):
    """The clear coat and the sheen in real time: the coat's split sum with f0 0.04,
    0.25 clearcoat (DFG1 + 0.04 (DFG2 - DFG1)) at its roughness times its own
    prefiltered lookup, and the sheen colour times the sheen lobe's albedo table
    (:func:`pbrkit.rendering.realtime.sheen_albedo_table`) times E(n) / pi.  Returns
    (specular RGB, diffuse RGB) to add.  The coat has no normal of its own
    (``coat_nov`` is n.v)."""
    coat = 0.0
    if b.extra[CLEARCOAT_SLOT] > 0.0:
        coat = b.extra[CLEARCOAT_SLOT] * (coat_dfg1 + 0.04 * (coat_dfg2 - coat_dfg1))
    sheen = linear_1d(sheen_table, nov) * _INV_PI
    return ((coat * coat_prefiltered[0], coat * coat_prefiltered[1], coat * coat_prefiltered[2]),
            (b.extra[SHEEN_SLOT] * sheen * irradiance[0], b.extra[SHEEN_SLOT + 1] * sheen * irradiance[1],
             b.extra[SHEEN_SLOT + 2] * sheen * irradiance[2]))


MODEL = Model("disney", "Disney's principled BRDF (Burley 2012)",
              (BASE_COLOR, METALLIC, ROUGHNESS, REFLECTANCE, _ANISOTROPY) + EXTRAS, setup,
              add(add(DISNEY_DIFFUSE, SPECULAR), add(SHEEN, CLEARCOAT)), ("ggx", "separable", "schlick", "burley"),
              RealTime(coat_roughness=ibl_coat_roughness, extras=ibl_extras))
