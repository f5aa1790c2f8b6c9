"""The glTF 2.0 metallic-roughness BRDF exactly as the glTF 2.0 specification's
Appendix B defines it:

    material = mix(fresnel_mix(ior = 1.5, diffuse_brdf(base_color), specular_brdf(r^2)),
                   conductor_fresnel(base_color, specular_brdf(r^2)), metallic)

(:data:`SPECIFICATION`, written with :mod:`pbrkit.brdf.operators`).  Schlick's
F is linear in f0, so the metal and the dielectric share one specular lobe with
f0 = mix(0.04, base_color, metallic), and the model computes the equal
:data:`COMPOSITION`

    f = (1 - metallic)(1 - F_0.04(v.h)) base_color / pi + D V F_f0(v.h),

D GGX, V the separable Smith-GGX visibility G1(l) G1(v) / (4 n.l n.v) (B.3.2),
alpha = r^2 (B.2.2), the dielectric f0 0.04 of IOR 1.5.  In real time the
diffuse weight 1 - F(v.h) becomes Lagarde's 1 - F*(n.v, 0.04, r) or its exact
albedo (:func:`ibl_diffuse_weight`).

``KHR_materials_sheen`` (the extension's README, "Sheen" and "Albedo-scaling
technique") layers a Charlie sheen over that material:

    sheen_material = sheenColor sheen_brdf + material sheen_albedo_scaling,
    sheen_albedo_scaling = 1 - max3(sheenColor) E_sheen(n.v, sheenRoughness),

:func:`pbrkit.brdf.operators.layer` with :data:`pbrkit.brdf.lobes.sheen.SHEEN` on
top (its albedo sheenColor E, whose largest channel is max3(sheenColor) E).
With ``sheen_color`` 0 (the default) the lobe's value is 0 and the scaling 1
exactly, so the material's values are bitwise the core model's.  In real time
the sheen's IBL is the Khronos Sample Viewer's simplification, sheenColor E
times the prefiltered radiance at the sheen roughness (here the GGX chain; the
Charlie-prefiltered chain is a later step), over the base's IBL scaled by the
same albedo scaling (:func:`ibl_sheen_extras`, :func:`ibl_sheen_base_scale`).

A material that uses no extension (every extension parameter at its default)
compiles as :data:`CORE`, the composition above without the sheen
(:attr:`pbrkit.brdf.shading.model.Model.core`): its code, and so its speed, is
the core model's; :data:`MODEL`, with the extensions, runs for the others.
"""

from __future__ import annotations

from ...core.filtering import linear_1d
from ...core.jit import dual_use
from ..bxdf import BxDF, metallic_workflow
from ..diffuse import kd_ibl, lambert
from ...microfacet.roughness import alpha_from_roughness
from ..fresnel import f0_from_ior, f0_metallic, f_schlick
from ..lobes import Lobe
from ..lobes.diffuse import LAMBERT
from ..lobes.microfacet import microfacet
from ..lobes.sheen import (SHEEN, SHEEN_COLOR_SLOT, SHEEN_ROUGHNESS_SLOT, sheen_albedo_lookup,
                           sheen_albedo_scaling)
from ..operators import add, fresnel_mix, layer, mix, weighted
from ..parameters import BASE_COLOR, METALLIC, ROUGHNESS, Parameter
from ..terms import GGX, SCHLICK, SEPARABLE
from .model import Model, RealTime

__all__ = ["MODEL", "CORE", "GLTF_IOR", "GLTF_DIELECTRIC_F0", "gltf_fresnel_mix_weight", "SPECIFICATION", "COMPOSITION",
           "SHEEN_COLOR", "SHEEN_ROUGHNESS", "SHEEN_COMPOSITION", "ibl_diffuse_weight", "ibl_sheen_roughness",
           "ibl_sheen_extras", "ibl_sheen_base_scale"]

#: The glTF 2.0 dielectric's IOR (Appendix B.3.4) and its normal reflectance
#: ((1.5 - 1) / (1.5 + 1))^2 = 0.04.
GLTF_IOR = 1.5
GLTF_DIELECTRIC_F0 = f0_from_ior(GLTF_IOR)

#: KHR_materials_sheen's factors (its README, "Properties"; default 0: no sheen).
SHEEN_COLOR = Parameter("sheen_color", (0.0, 0.0, 0.0), 0.0, 1.0, "linear Rec.709",
                        "sheen colour, KHR_materials_sheen sheenColorFactor", channels=3)
SHEEN_ROUGHNESS = Parameter("sheen_roughness", 0.0, 0.0, 1.0, "",
                            "Charlie sheen roughness (alpha = r^2), KHR_materials_sheen sheenRoughnessFactor")


@dual_use
def gltf_fresnel_mix_weight(voh):
    """The weight 1 - F(v.h) that the glTF 2.0 metallic-roughness BRDF gives its
    diffuse base under the specular layer: ``fresnel_mix(ior = 1.5, base, layer)
    = mix(base, layer, F)`` with F = f0 + (1 - f0)(1 - |v.h|)^5, f0 = 0.04 (glTF 2.0
    specification, Appendix B.3.4 and B.3.5)."""
    return 1.0 - f_schlick(voh, GLTF_DIELECTRIC_F0, 1.0)


@dual_use(inline=True)
def _fresnel_mix_weight(b, c):
    return gltf_fresnel_mix_weight(c.voh)


@dual_use(inline="llvm")
def core_setup(codes, row, params, q, columns, roughness, metallic, b0, b1, b2):
    # pbrkit.brdf.bxdf.metallic_workflow at the glTF dielectric's f0
    return metallic_workflow(codes, row, roughness, alpha_from_roughness(roughness), metallic, b0, b1, b2,
                             GLTF_DIELECTRIC_F0, 1.0 - metallic)


@dual_use(inline="llvm")
def setup(codes, row, params, q, columns, roughness, metallic, b0, b1, b2):
    # pbrkit.brdf.bxdf.metallic_workflow with the sheen's colour and roughness in the
    # extra slots of pbrkit.brdf.lobes.sheen (SHEEN_COLOR_SLOT = 0, SHEEN_ROUGHNESS_SLOT = 3)
    z3 = (0.0, 0.0, 0.0)
    alpha = alpha_from_roughness(roughness)
    kd = 1.0 - metallic
    f0 = (f0_metallic(b0, metallic, GLTF_DIELECTRIC_F0), f0_metallic(b1, metallic, GLTF_DIELECTRIC_F0),
          f0_metallic(b2, metallic, GLTF_DIELECTRIC_F0))
    s = columns.sheen_color
    extra = (params[q, s], params[q, s + 1], params[q, s + 2], params[q, columns.sheen_roughness], 0.0, 0.0, 0.0,
             0.0)
    return BxDF(codes[row, 0], codes[row, 1], codes[row, 2], codes[row, 3], codes[row, 4], roughness, alpha, alpha,
                alpha, False, metallic, (b0, b1, b2), (b0 * kd, b1 * kd, b2 * kd), f0, 1.0, z3, z3,
                GLTF_DIELECTRIC_F0, z3, extra)


_SPECULAR = microfacet(GGX, SEPARABLE, SCHLICK)
_DV = _SPECULAR.parts.dv


@dual_use(inline=True)
def _diffuse_brdf(b, c, ec, w):
    # diffuse_brdf(base_color) = base_color / pi (B.3.3)
    k = lambert(c.nol) * w
    return b.base[0] * k, b.base[1] * k, b.base[2] * k


@dual_use(inline=True)
def _specular_brdf(b, c, ec, w):
    # specular_brdf(alpha) = D V, without Fresnel (B.3.2)
    k = _DV(b, c) * w
    return k, k, k


@dual_use(inline=True)
def _conductor_fresnel(b, c, ec, w):
    # conductor_fresnel(f0 = base_color, specular_brdf) = specular_brdf F_Schlick(base_color) (B.3.4)
    k = _DV(b, c) * w
    return (f_schlick(c.voh, b.base[0], 1.0) * k, f_schlick(c.voh, b.base[1], 1.0) * k,
            f_schlick(c.voh, b.base[2], 1.0) * k)


@dual_use(inline=True)
def _metallic(b):
    return b.metallic


#: Appendix B as written: the dielectric (a Fresnel mix of the diffuse and specular
#: BRDFs at IOR 1.5) and the metal mixed by metallic.  Its value is the model's
#: (tested); the model evaluates the folded :data:`COMPOSITION`.
SPECIFICATION = mix(fresnel_mix(GLTF_IOR, Lobe("diffuse_brdf", _diffuse_brdf, None, None, None, None),
                                Lobe("specular_brdf", _specular_brdf, None, None, None, None)),
                    Lobe("conductor_fresnel", _conductor_fresnel, None, None, None, None), _metallic)
#: What the model evaluates: the specification with the metallic mix folded into f0
#: (Schlick's F is linear in f0) and the dielectric's Fresnel kept on its diffuse.
COMPOSITION = add(weighted(_fresnel_mix_weight, LAMBERT), _SPECULAR)
#: With KHR_materials_sheen: ``sheenColor sheen_brdf + material sheen_albedo_scaling``
#: (the extension's README, "Albedo-scaling technique"), the scaling 1 - max3(sheenColor)
#: E(n.v) of the lobe's tabulated albedo (:func:`pbrkit.brdf.lobes.sheen.sheen_albedo_lookup`).
#: The sheen rides on the diffuse lobe's cosine samples.
SHEEN_COMPOSITION = layer(SHEEN, COMPOSITION)


@dual_use(inline=True)
def ibl_diffuse_weight(b, nov, exact, table):
    """The real-time weight of the diffuse lobe's IBL (weighted by 1 - F(v.h) in the
    BRDF): Lagarde's 1 - F*(n.v, 0.04, r) (:func:`pbrkit.brdf.diffuse.kd_ibl` with
    metallic 0: the diffuse colour already carries 1 - metallic), or with ``exact``
    the exact albedo of that weight, ``table`` (linear between texel centres)."""
    if exact:
        return linear_1d(table, nov)
    return kd_ibl(nov, GLTF_DIELECTRIC_F0, b.roughness, 0.0)


@dual_use(inline=True)
def _sheen_on(b):
    s = SHEEN_COLOR_SLOT
    return b.extra[s] > 0.0 or b.extra[s + 1] > 0.0 or b.extra[s + 2] > 0.0


@dual_use(inline=True)
def ibl_sheen_roughness(b):
    """The roughness of the sheen's prefiltered lookup in real time: the sheen roughness
    (-1 without a sheen, so no second lookup).  The lookup is the GGX-prefiltered chain
    at that roughness, standing in for the Charlie-prefiltered chain the Khronos Sample
    Viewer samples (a later step)."""
    if _sheen_on(b):
        return b.extra[SHEEN_ROUGHNESS_SLOT]
    return -1.0


@dual_use(inline=True)
def ibl_sheen_extras(b, nov, coat_dfg1, coat_dfg2, sheen_table, irradiance, coat_prefiltered):
    """The sheen's image-based lighting, the Sample Viewer's simplification of
    KHR_materials_sheen: sheenColor E_sheen(n.v, sheenRoughness) times the
    prefiltered radiance at the sheen roughness (:func:`ibl_sheen_roughness`).
    Returns (specular RGB, diffuse RGB) to add to the scaled base."""
    if not _sheen_on(b):
        z = (0.0, 0.0, 0.0)
        return z, z
    e = sheen_albedo_lookup(nov, b.extra[SHEEN_ROUGHNESS_SLOT])
    s = SHEEN_COLOR_SLOT
    return ((b.extra[s] * e * coat_prefiltered[0], b.extra[s + 1] * e * coat_prefiltered[1],
             b.extra[s + 2] * e * coat_prefiltered[2]), (0.0, 0.0, 0.0))


@dual_use(inline=True)
def ibl_sheen_base_scale(b, nov):
    """KHR_materials_sheen's sheen_albedo_scaling 1 - max3(sheenColor) E(n.v) on the base's
    IBL terms (:func:`pbrkit.brdf.lobes.sheen.sheen_albedo_scaling`); 1.0 without a sheen."""
    if not _sheen_on(b):
        return 1.0
    s = SHEEN_COLOR_SLOT
    return sheen_albedo_scaling(max(b.extra[s], max(b.extra[s + 1], b.extra[s + 2])), nov,
                                b.extra[SHEEN_ROUGHNESS_SLOT])


#: The core model: a material without KHR_materials extensions compiles as this
#: (:attr:`pbrkit.brdf.shading.model.Model.core`), the code it ran before them.
CORE = Model("gltf", "the glTF 2.0 metallic-roughness BRDF (Appendix B)", (BASE_COLOR, METALLIC, ROUGHNESS),
             core_setup, COMPOSITION, ("ggx", "separable", "schlick", "lambert"),
             RealTime(diffuse_weight=ibl_diffuse_weight), variants=(("ggx", "separable", "schlick", "lambert"),))
MODEL = Model("gltf", "the glTF 2.0 metallic-roughness BRDF (Appendix B) with KHR_materials_sheen",
              (BASE_COLOR, METALLIC, ROUGHNESS, SHEEN_COLOR, SHEEN_ROUGHNESS), setup, SHEEN_COMPOSITION,
              ("ggx", "separable", "schlick", "lambert"),
              RealTime(diffuse_weight=ibl_diffuse_weight, coat_roughness=ibl_sheen_roughness,
                       extras=ibl_sheen_extras, base_scale=ibl_sheen_base_scale), core=CORE)
