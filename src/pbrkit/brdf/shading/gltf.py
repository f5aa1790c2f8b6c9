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

``KHR_materials_transmission`` and ``KHR_materials_volume`` (their READMEs,
"Transmission BTDF", "Properties"): ``transmission`` takes that fraction of the
diffuse base (the setup scales the diffuse colour by 1 - transmission) and sends it
through the surface by a specular BTDF, thin-walled (``thickness`` 0) or refracting into
an absorbing medium (``thickness`` > 0, ``attenuation_color``, ``attenuation_distance``):
the BSDF with both sides, its sampling and pdf are :mod:`pbrkit.brdf.transmission`'s,
which the ground truth calls for such a material; the composition here is its
reflection.  The extra slots 7-9 hold the transmission factor, the ior and the
thickness.

A material that uses no extension (every extension parameter at its default)
compiles as :data:`CORE`, the composition above without the sheen
(:attr:`pbrkit.brdf.shading.model.Model.core`): its code, and so its speed, is
the core model's; :data:`MODEL`, with the extensions, runs for the others.
"""

from __future__ import annotations

import math


from ...core.filtering import linear_1d
from ...core.jit import dual_use
from ..bxdf import BxDF, metallic_workflow
from ..diffuse import kd_ibl, lambert
from ...microfacet.roughness import alpha_from_roughness
from ..fresnel import f0_from_ior, f0_metallic, f_iridescence, f_schlick
from ..lobes import Lobe, lobe_width, quadrature_albedo
from ..lobes.clearcoat import CLEARCOAT as CLEARCOAT_LOBE
from ..lobes.clearcoat import CLEARCOAT_ALPHA_SLOT, CLEARCOAT_SLOT, clearcoat_weight, coat_nov
from ..lobes.diffuse import LAMBERT
from ..lobes.microfacet import microfacet
from ..lobes.sheen import (SHEEN, SHEEN_COLOR_SLOT, SHEEN_ROUGHNESS_SLOT, sheen_albedo_lookup,
                           sheen_albedo_scaling)
from ..operators import add, fresnel_coat, fresnel_mix, layer, mix, weighted
from ..parameters import BASE_COLOR, METALLIC, ROUGHNESS, Parameter
from ...microfacet.smith import g2_height_correlated, g2_separable, visibility
from ..terms import GGX, SCHLICK, SCHLICK_SPECULAR, SEPARABLE, Masking
from .model import Model, RealTime

__all__ = ["MODEL", "CORE", "GLTF_IOR", "GLTF_DIELECTRIC_F0", "gltf_fresnel_mix_weight", "SPECIFICATION",
           "COMPOSITION", "SHEEN_COLOR", "SHEEN_ROUGHNESS", "CLEARCOAT", "CLEARCOAT_ROUGHNESS", "SPECULAR",
           "SPECULAR_COLOR", "IOR", "IRIDESCENCE", "IRIDESCENCE_IOR", "IRIDESCENCE_THICKNESS_MINIMUM",
           "IRIDESCENCE_THICKNESS_MAXIMUM", "TRANSMISSION", "ANISOTROPY_STRENGTH", "ANISOTROPY_ROTATION", "DISPERSION", "THICKNESS", "ATTENUATION_DISTANCE", "ATTENUATION_COLOR",
           "SPECULAR_SLOT", "IRIDESCENCE_SLOT", "TRANSMISSION_SLOT", "THICKNESS_SLOT", "SPECULAR_DV", "khr_fresnel",
           "SPECULAR_COMPOSITION", "SHEEN_COMPOSITION",
           "EXTENDED_COMPOSITION", "ibl_diffuse_weight", "ibl_specular_diffuse_weight",
           "ibl_coat_roughness", "ibl_sheen_roughness", "ibl_extensions_extras", "ibl_extensions_base_scale",
           "ibl_transmission"]

#: The glTF 2.0 dielectric's IOR (Appendix B.3.4) and its normal reflectance
#: ((1.5 - 1) / (1.5 + 1))^2 = 0.04.
GLTF_IOR = 1.5
_INV_PI = 1.0 / math.pi
GLTF_DIELECTRIC_F0 = f0_from_ior(GLTF_IOR)

#: KHR_materials_sheen's factors (its README, "Properties"; default 0: no sheen).
SHEEN_COLOR = Parameter("sheen_color", (0.0, 0.0, 0.0), 0.0, 1.0, "linear Rec.709",
                        "sheen colour, KHR_materials_sheen sheenColorFactor", channels=3)
SHEEN_ROUGHNESS = Parameter("sheen_roughness", 0.0, 0.0, 1.0, "",
                            "Charlie sheen roughness (alpha = r^2), KHR_materials_sheen sheenRoughnessFactor")
#: KHR_materials_clearcoat's factors (its README, "Properties"; default 0: no coat).
CLEARCOAT = Parameter("clearcoat", 0.0, 0.0, 1.0, "", "clear coat weight, KHR_materials_clearcoat clearcoatFactor")
CLEARCOAT_ROUGHNESS = Parameter("clearcoat_roughness", 0.0, 0.0, 1.0, "",
                                "clear coat roughness (alpha = r^2), KHR_materials_clearcoat "
                                "clearcoatRoughnessFactor")
#: KHR_materials_specular's factors (its README, "Properties"; defaults 1: the core's F).
SPECULAR = Parameter("specular", 1.0, 0.0, 1.0, "", "dielectric specular weight (F90 too), "
                     "KHR_materials_specular specularFactor")
SPECULAR_COLOR = Parameter("specular_color", (1.0, 1.0, 1.0), 0.0, math.inf, "linear Rec.709",
                           "dielectric F0 colour (f0 = min(f0(ior) colour, 1) specular), KHR_materials_specular "
                           "specularColorFactor", channels=3)
#: KHR_materials_ior's ior (its README; 1.5 the core's, 0 or at least 1).
IOR = Parameter("ior", GLTF_IOR, 1.0, math.inf, "", "dielectric index of refraction (f0 = ((ior - 1) / (ior + "
                "1))^2; 0: f0 = 1), KHR_materials_ior ior", also=(0.0,))
#: KHR_materials_iridescence's factors (its README, "Properties"; iridescenceFactor 0: no
#: film; the thickness is iridescenceThicknessMaximum where no thickness texture applies).
IRIDESCENCE = Parameter("iridescence", 0.0, 0.0, 1.0, "", "thin-film weight, KHR_materials_iridescence "
                        "iridescenceFactor")
IRIDESCENCE_IOR = Parameter("iridescence_ior", 1.3, 1.0, math.inf, "", "thin film's index of refraction, "
                            "KHR_materials_iridescence iridescenceIor")
IRIDESCENCE_THICKNESS_MINIMUM = Parameter("iridescence_thickness_minimum", 100.0, 0.0, math.inf, "nm",
                                          "film thickness at thickness-texture 0 (unused without the texture), "
                                          "KHR_materials_iridescence iridescenceThicknessMinimum")
IRIDESCENCE_THICKNESS_MAXIMUM = Parameter("iridescence_thickness_maximum", 400.0, 0.0, math.inf, "nm",
                                          "film thickness (at thickness-texture 1, and without the texture), "
                                          "KHR_materials_iridescence iridescenceThicknessMaximum")
#: KHR_materials_transmission's factor (its README, "Properties"; default 0: opaque).
TRANSMISSION = Parameter("transmission", 0.0, 0.0, 1.0, "", "fraction of the light that penetrates the surface "
                         "(is not specularly reflected) that is transmitted rather than diffused, "
                         "KHR_materials_transmission transmissionFactor")
#: KHR_materials_volume's factors (its README, "Properties"; thickness 0: thin-walled).
THICKNESS = Parameter("thickness", 0.0, 0.0, math.inf, "scene units", "0: thin-walled; > 0: the closed mesh bounds "
                      "a refracting, absorbing medium (the ground truth traces the real path length), "
                      "KHR_materials_volume thicknessFactor")
ATTENUATION_DISTANCE = Parameter("attenuation_distance", 0.0, 0.0, math.inf, "scene units",
                                 "distance at which white light inside the medium turns attenuation_color "
                                 "(sigma_a = -ln(attenuation_color) / attenuation_distance); 0 stands for glTF's "
                                 "+Infinity (no absorption), which JSON cannot write, KHR_materials_volume "
                                 "attenuationDistance")
ATTENUATION_COLOR = Parameter("attenuation_color", (1.0, 1.0, 1.0), 0.0, 1.0, "linear Rec.709",
                              "colour white light turns into after attenuation_distance in the medium, "
                              "KHR_materials_volume attenuationColor", channels=3)
#: KHR_materials_anisotropy's factors (its README, "Properties"; strength 0: isotropic).
ANISOTROPY_STRENGTH = Parameter("anisotropy_strength", 0.0, 0.0, 1.0, "",
                                "roughness added along the anisotropy direction (alpha_t = mix(alpha, 1, "
                                "strength^2), alpha_b = alpha), KHR_materials_anisotropy anisotropyStrength")
ANISOTROPY_ROTATION = Parameter("anisotropy_rotation", 0.0, -math.pi, math.pi, "radians",
                                "anisotropy direction, counter-clockwise from the tangent towards the bitangent, "
                                "KHR_materials_anisotropy anisotropyRotation (glTF files' any angle, wrapped)")
#: KHR_materials_dispersion's factor (its README; 0: none): 20 / V_d, V_d the Abbe number.
DISPERSION = Parameter("dispersion", 0.0, 0.0, math.inf, "", "20 / Abbe number of the volume's dielectric: each "
                       "colour channel refracts with its own IOR (Cauchy's n(lambda) through ior at 587.6 nm), "
                       "KHR_materials_dispersion dispersion")
#: The BxDF ``extra`` slots of the specular factor (sheen: 0-3, clear coat: 4-5), of the
#: transmission factor and the volume's thickness (:mod:`pbrkit.brdf.transmission`), and of
#: the thin film: its weight, IOR and thickness (nm).  The dielectric's IOR rides in the
#: BxDF's ``eta`` (every channel), unused by the model's Schlick Fresnel.
SPECULAR_SLOT = 6
TRANSMISSION_SLOT = 7
IRIDESCENCE_SLOT, IRIDESCENCE_IOR_SLOT, IRIDESCENCE_THICKNESS_SLOT = 8, 9, 10
THICKNESS_SLOT = 11


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
    # the metallic workflow with KHR_materials_ior and KHR_materials_specular's dielectric
    # F0 and F90 (the specular README, "Implementation" and "Interaction with other
    # extensions": dielectric_f0 = min(((ior - 1) / (ior + 1))^2 specularColor, 1) specular,
    # dielectric_f90 = specular), mixed with the metal's (base colour, 1) by metallic;
    # dielectric_f0 holds max3 of the dielectric F0 (the diffuse weight's); the sheen's colour
    # and roughness, the coat's weight and alpha, the specular factor, the transmission factor,
    # the thin film, the volume's thickness and the coat's world-space normal (0: the shading
    # normal; pbrkit.brdf.lobes.clearcoat.coat_in_frame turns it local) in the extra slots
    # (pbrkit.brdf.lobes.sheen, pbrkit.brdf.lobes.clearcoat, SPECULAR_SLOT, ...); the
    # dielectric's F0 colour as the BxDF's specular colour and its IOR as its eta;
    # KHR_materials_transmission's mix(diffuse_brdf, specular_btdf, transmission) takes
    # 1 - transmission of the diffuse (its README, "Transmission BTDF"; the BTDF itself is
    # pbrkit.brdf.transmission's)
    z3 = (0.0, 0.0, 0.0)
    alpha = alpha_from_roughness(roughness)
    transmission = params[q, columns.transmission]
    kd = (1.0 - metallic) * (1.0 - transmission)
    s = params[q, columns.specular]
    ior = params[q, columns.ior]
    f0_ior = f0_from_ior(ior)
    sc = columns.specular_color
    d0 = min(f0_ior * params[q, sc], 1.0) * s
    d1 = min(f0_ior * params[q, sc + 1], 1.0) * s
    d2 = min(f0_ior * params[q, sc + 2], 1.0) * s
    f0 = (f0_metallic(b0, metallic, d0), f0_metallic(b1, metallic, d1), f0_metallic(b2, metallic, d2))
    f90 = s + (1.0 - s) * metallic
    h = columns.sheen_color
    extra = (params[q, h], params[q, h + 1], params[q, h + 2], params[q, columns.sheen_roughness],
             params[q, columns.clearcoat], alpha_from_roughness(params[q, columns.clearcoat_roughness]), s,
             transmission, params[q, columns.iridescence], params[q, columns.iridescence_ior],
             params[q, columns.iridescence_thickness_maximum], params[q, columns.thickness],
             params[q, columns.coat_normal], params[q, columns.coat_normal + 1], params[q, columns.coat_normal + 2])
    # KHR_materials_anisotropy (its README, "Anisotropy"): alpha_t = mix(alpha, 1, strength^2)
    # along the direction turned anisotropyRotation from the tangent, alpha_b = alpha across it
    strength = params[q, columns.anisotropy_strength]
    alpha_t = alpha + (1.0 - alpha) * (strength * strength)
    return BxDF(codes[row, 0], codes[row, 1], codes[row, 2], codes[row, 3], codes[row, 4], roughness, alpha,
                alpha_t, alpha, strength > 0.0, params[q, columns.anisotropy_rotation], metallic, (b0, b1, b2),
                (b0 * kd, b1 * kd, b2 * kd), f0, f90, (ior, ior, ior), z3, max(d0, max(d1, d2)), (d0, d1, d2), extra)


_SPECULAR = microfacet(GGX, SEPARABLE, SCHLICK)
_DV = _SPECULAR.parts.dv
#: specular_brdf(alpha) = D V of B.3.2 (no Fresnel): the transmission's thin-walled BTDF
#: evaluates it at the mirrored light (:mod:`pbrkit.brdf.transmission`).
SPECULAR_DV = _DV


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


@dual_use(inline=True)
def _dielectric_iridescence(b, voh):
    # KHR_materials_iridescence over the dielectric (its README, iridescent_dielectric_layer with
    # KHR_materials_specular): the film's Fresnel over base F0 = specular min(F0(ior) specularColor, 1)
    # (the BxDF's specular colour), at v.h
    d = b.specular_color
    return f_iridescence(voh, b.extra[IRIDESCENCE_IOR_SLOT], b.extra[IRIDESCENCE_THICKNESS_SLOT], d[0], d[1], d[2])


@dual_use(inline=True)
def _specular_mix_weight(b, c):
    # 1 - max3(dielectric_fresnel), dielectric_fresnel = mix(dielectric_f0, specular, (1 - |v.h|)^5)
    # per channel (KHR_materials_specular's README, "Implementation"): its largest channel is
    # the one of the largest f0, b.dielectric_f0; with a thin film (KHR_materials_iridescence,
    # rgb_mix) the largest channel of mix(dielectric_fresnel, iridescent_f, iridescence)
    k = b.extra[IRIDESCENCE_SLOT]
    if k == 0.0:
        return 1.0 - f_schlick(c.voh, b.dielectric_f0, b.extra[SPECULAR_SLOT])
    s = b.extra[SPECULAR_SLOT]
    i0, i1, i2 = _dielectric_iridescence(b, c.voh)
    f0 = f_schlick(c.voh, b.specular_color[0], s)
    f1 = f_schlick(c.voh, b.specular_color[1], s)
    f2 = f_schlick(c.voh, b.specular_color[2], s)
    return 1.0 - max(f0 + (i0 - f0) * k, max(f1 + (i1 - f1) * k, f2 + (i2 - f2) * k))


@dual_use(inline=True)
def khr_fresnel(b, voh):
    """The RGB Fresnel of the extended model's specular lobe: mix(dielectric_fresnel,
    metal_fresnel, metallic), Schlick's with the BxDF's F0 and F90 (KHR_materials_specular,
    KHR_materials_ior), and with a thin film (KHR_materials_iridescence's README,
    iridescent_dielectric_layer and iridescent_conductor_layer) each part mixed towards the
    film's Fresnel (:func:`pbrkit.brdf.fresnel.f_iridescence`, over the dielectric's F0 colour
    and over the base colour) by iridescenceFactor."""
    k = b.extra[IRIDESCENCE_SLOT]
    if k == 0.0:
        return f_schlick(voh, b.f0[0], b.f90), f_schlick(voh, b.f0[1], b.f90), f_schlick(voh, b.f0[2], b.f90)
    s = b.extra[SPECULAR_SLOT]
    m = b.metallic
    d = _dielectric_iridescence(b, voh)
    e = f_iridescence(voh, b.extra[IRIDESCENCE_IOR_SLOT], b.extra[IRIDESCENCE_THICKNESS_SLOT], b.base[0], b.base[1],
                      b.base[2])
    out = [0.0, 0.0, 0.0]
    for c in range(3):
        fd = f_schlick(voh, b.specular_color[c], s)
        fm = f_schlick(voh, b.base[c], 1.0)
        out[c] = (fd + (d[c] - fd) * k) * (1.0 - m) + (fm + (e[c] - fm) * k) * m
    return out[0], out[1], out[2]


_GGX_LAMBDAS = GGX.lambdas


@dual_use(inline=True)
def _v_khr(b, c):
    # B.3.2's separable Smith V of GGX, or for KHR_materials_anisotropy its README's
    # V_GGX_anisotropic: the height-correlated Smith V of the anisotropic GGX
    # (Heitz 2014, eq. 99 with the anisotropic Lambdas, eqs. 80 and 86), without the
    # README's clamp to [0, 1]: V = G2 / (4 n.l n.v) exceeds 1 where n.l n.v < G2 / 4 (2.3 at
    # n.l = n.v = 0.3), which the clamp would cut; the exact V keeps the BRDF reciprocal
    # and its albedo the quadrature's (the Sample Viewer clamps: its highlights beyond about
    # 60 degrees differ)
    lam_l, lam_v = _GGX_LAMBDAS(b, c)
    if b.anisotropic:
        return visibility(g2_height_correlated(lam_l, lam_v), c.nol, c.nov)
    return visibility(g2_separable(lam_l, lam_v), c.nol, c.nov)


#: The extended model's masking: :data:`pbrkit.brdf.terms.SEPARABLE` (the core's), and
#: for an anisotropic material KHR_materials_anisotropy's height-correlated V (:func:`_v_khr`).
KHR_MASKING = Masking("separable", "separable", v=_v_khr)
#: The specular lobe with KHR_materials_specular's F90 (:data:`pbrkit.brdf.terms.SCHLICK_SPECULAR`):
#: its D V, sampling and split-sum pieces, with the Fresnel :func:`khr_fresnel` in its value.
_SPECULAR_F90 = microfacet(GGX, KHR_MASKING, SCHLICK_SPECULAR)
_DV_F90 = _SPECULAR_F90.parts.dv


@dual_use(inline=True)
def _khr_specular_value(b, c, ec, w):
    spec = _DV_F90(b, c)
    f0, f1, f2 = khr_fresnel(b, c.voh)
    return f0 * ((spec * ec[0]) * w), f1 * ((spec * ec[1]) * w), f2 * ((spec * ec[2]) * w)


_SPECULAR_KHR = Lobe("specular", _khr_specular_value, _SPECULAR_F90.technique, "specular", _SPECULAR_F90.estimate,
                     quadrature_albedo(_khr_specular_value, lobe_width), _SPECULAR_F90.parts)
#: The material with KHR_materials_ior and KHR_materials_specular:
#: ``dielectric_fresnel specular_brdf + (1 - max3(dielectric_fresnel)) diffuse_brdf`` mixed
#: with the metal by metallic (the specular README), folded as :data:`COMPOSITION` is.
SPECULAR_COMPOSITION = add(weighted(_specular_mix_weight, LAMBERT), _SPECULAR_KHR)
#: With KHR_materials_sheen: ``sheenColor sheen_brdf + material sheen_albedo_scaling``
#: (the extension's README, "Albedo-scaling technique"), the scaling 1 - max3(sheenColor)
#: E(n.v) of the lobe's tabulated albedo (:func:`pbrkit.brdf.lobes.sheen.sheen_albedo_lookup`).
#: The sheen rides on the diffuse lobe's cosine samples.
SHEEN_COMPOSITION = layer(SHEEN, SPECULAR_COMPOSITION)
#: With KHR_materials_clearcoat on top of the sheen (the sheen README: "clearcoat is layered
#: on top of sheen"): ``mix(material, clearcoat_brdf, clearcoat clearcoat_fresnel(n_c.v))``,
#: n_c the coat's normal (:func:`pbrkit.brdf.lobes.clearcoat.coat_nov`)
#: (:func:`pbrkit.brdf.operators.fresnel_coat` at IOR 1.5, :data:`pbrkit.brdf.lobes.clearcoat.CLEARCOAT`).
EXTENDED_COMPOSITION = fresnel_coat(GLTF_IOR, clearcoat_weight, SHEEN_COMPOSITION, CLEARCOAT_LOBE, coat_nov)


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
def ibl_specular_diffuse_weight(b, nov, exact, table):
    """:func:`ibl_diffuse_weight` with KHR_materials_specular and KHR_materials_ior: 1 -
    F* of Lagarde's roughness-aware Schlick with the dielectric's largest F0
    (``b.dielectric_f0``) and F90 scaled by the specular factor s, f0 + (max(s (1 - r),
    f0) - f0)(1 - n.v)^5; the ``exact`` table only for the core's F (f0 0.04, s = 1),
    the only one it holds."""
    s = b.extra[SPECULAR_SLOT]
    f0 = b.dielectric_f0
    if exact and f0 == GLTF_DIELECTRIC_F0 and s == 1.0:
        return linear_1d(table, nov)
    return 1.0 - f_schlick(nov, f0, max(s * (1.0 - b.roughness), f0))


@dual_use(inline=True)
def ibl_transmission(b):
    """KHR_materials_transmission in real time: the weight (1 - metallic) transmission on
    baseColor x the diffuse's Fresnel weight x the transmitted light
    (:mod:`pbrkit.rendering.transmission_ibl`): the specification's mix(diffuse_brdf,
    specular_btdf, transmission) beneath the dielectric's fresnel_mix, the setup having
    taken 1 - transmission of the diffuse colour."""
    return (1.0 - b.metallic) * b.extra[TRANSMISSION_SLOT]


@dual_use(inline=True)
def _sheen_on(b):
    s = SHEEN_COLOR_SLOT
    return b.extra[s] > 0.0 or b.extra[s + 1] > 0.0 or b.extra[s + 2] > 0.0


@dual_use(inline=True)
def _coat(b, nov):
    # KHR_materials_clearcoat's weight of the coat over the material: clearcoat clearcoat_fresnel(n.v)
    return b.extra[CLEARCOAT_SLOT] * f_schlick(nov, GLTF_DIELECTRIC_F0, 1.0)


@dual_use(inline=True)
def ibl_coat_roughness(b):
    """The perceptual roughness of the clear coat's prefiltered lookup in real time
    (sqrt of its alpha; -1 without a coat, so no lookup)."""
    if b.extra[CLEARCOAT_SLOT] > 0.0:
        return math.sqrt(b.extra[CLEARCOAT_ALPHA_SLOT])
    return -1.0


@dual_use(inline=True)
def ibl_sheen_roughness(b):
    """The roughness of the sheen's prefiltered lookup in real time: the sheen roughness
    (-1 without a sheen, so no lookup).  The lookup is the Charlie-prefiltered chain when
    the bake has one, else the GGX chain at that roughness (:mod:`pbrkit.rendering.realtime`)."""
    if _sheen_on(b):
        return b.extra[SHEEN_ROUGHNESS_SLOT]
    return -1.0


@dual_use(inline=True)
def _iridescence_ibl(b, nov, dfg1, dfg2, irradiance, radiance, scale):
    # the thin film's change to the base's split sum (ibl_extensions_extras), times the base's scale
    k = b.extra[IRIDESCENCE_SLOT]
    if k == 0.0:
        z = (0.0, 0.0, 0.0)
        return z, z
    s = b.extra[SPECULAR_SLOT]
    m = b.metallic
    fd = _dielectric_iridescence(b, nov)
    fm = f_iridescence(nov, b.extra[IRIDESCENCE_IOR_SLOT], b.extra[IRIDESCENCE_THICKNESS_SLOT], b.base[0], b.base[1],
                       b.base[2])
    spec = [0.0, 0.0, 0.0]
    plain = 0.0
    film = 0.0
    for c in range(3):
        a_d = dfg1 * s + b.specular_color[c] * (dfg2 - dfg1)
        a_m = dfg1 + b.base[c] * (dfg2 - dfg1)
        spec[c] = radiance[c] * k * ((fd[c] * dfg2 - a_d) * (1.0 - m) + (fm[c] * dfg2 - a_m) * m) * scale
        f = f_schlick(nov, b.specular_color[c], max(s * (1.0 - b.roughness), b.specular_color[c]))
        plain = max(plain, f)
        film = max(film, f + (fd[c] - f) * k)
    w = (plain - film) * _INV_PI * scale
    return ((spec[0], spec[1], spec[2]), (b.diffuse_color[0] * w * irradiance[0], b.diffuse_color[1] * w * irradiance[1],
                                          b.diffuse_color[2] * w * irradiance[2]))


@dual_use(inline=True)
def ibl_extensions_extras(b, nov, coat_nov, coat_dfg1, coat_dfg2, sheen_table, irradiance, coat_prefiltered,
                          sheen_prefiltered, dfg1, dfg2, radiance):
    """The extensions' image-based lighting, as the Khronos Sample Viewer evaluates
    them: the sheen, sheenColor E_sheen(n.v, sheenRoughness) times the sheen's
    prefiltered radiance; the clear coat, clearcoat clearcoat_fresnel(n.v) times its
    prefiltered radiance times the white lobe's split-sum albedo DFG2 at its roughness;
    the sheen under the coat's 1 - clearcoat clearcoat_fresnel; the thin film
    (KHR_materials_iridescence), the base's split-sum albedo of each part (dielectric,
    metal) mixed towards the film's Fresnel at n.v times DFG2 by iridescenceFactor, and
    the diffuse weight's largest dielectric Fresnel likewise (the Sample Viewer's
    Fresnel at n.v, on pbrkit's split sum).  The coat's Fresnel and DFG2 are at the
    view's cosine to its normal, ``coat_nov`` (:func:`pbrkit.brdf.lobes.clearcoat.coat_local_nov`).
    Returns (specular RGB, diffuse RGB) to add to the base scaled by
    :func:`ibl_extensions_base_scale`."""
    t = _coat(b, coat_nov)
    e = 0.0
    if _sheen_on(b):
        e = sheen_albedo_lookup(nov, b.extra[SHEEN_ROUGHNESS_SLOT]) * (1.0 - t)
    s = SHEEN_COLOR_SLOT
    k = t * coat_dfg2
    fs, fd = _iridescence_ibl(b, nov, dfg1, dfg2, irradiance, radiance, ibl_extensions_base_scale(b, nov, coat_nov))
    return ((b.extra[s] * e * sheen_prefiltered[0] + k * coat_prefiltered[0] + fs[0],
             b.extra[s + 1] * e * sheen_prefiltered[1] + k * coat_prefiltered[1] + fs[1],
             b.extra[s + 2] * e * sheen_prefiltered[2] + k * coat_prefiltered[2] + fs[2]), fd)


@dual_use(inline=True)
def ibl_extensions_base_scale(b, nov, coat_nov):
    """The factor on the base's IBL terms: KHR_materials_sheen's sheen_albedo_scaling 1 -
    max3(sheenColor) E(n.v) (:func:`pbrkit.brdf.lobes.sheen.sheen_albedo_scaling`) times
    KHR_materials_clearcoat's 1 - clearcoat clearcoat_fresnel(n_c.v), ``coat_nov`` the
    view's cosine to the coat's normal; 1.0 without either."""
    scale = 1.0 - _coat(b, coat_nov)
    if _sheen_on(b):
        s = SHEEN_COLOR_SLOT
        scale *= sheen_albedo_scaling(max(b.extra[s], max(b.extra[s + 1], b.extra[s + 2])), nov,
                                      b.extra[SHEEN_ROUGHNESS_SLOT])
    return scale


#: The core model: a material without KHR_materials extensions compiles as this
#: (:attr:`pbrkit.brdf.shading.model.Model.core`), the code it ran before them.
CORE = Model("gltf", "the glTF 2.0 metallic-roughness BRDF (Appendix B)", (BASE_COLOR, METALLIC, ROUGHNESS),
             core_setup, COMPOSITION, ("ggx", "separable", "schlick", "lambert"),
             RealTime(diffuse_weight=ibl_diffuse_weight), variants=(("ggx", "separable", "schlick", "lambert"),))
@dual_use(inline="llvm")
def emission_coat(params, q, columns):
    """KHR_materials_clearcoat's coat over the emission (its README, "Emission"): the
    weight clearcoatFactor of :func:`pbrkit.brdf.lobes.clearcoat.coated_emission`.
    ``q`` may be an array of rows (NumPy from Python)."""
    return params[q, columns.clearcoat]


MODEL = Model("gltf", "the glTF 2.0 metallic-roughness BRDF (Appendix B) with its KHR_materials extensions",
              (BASE_COLOR, METALLIC, ROUGHNESS, SHEEN_COLOR, SHEEN_ROUGHNESS, CLEARCOAT, CLEARCOAT_ROUGHNESS, SPECULAR,
               SPECULAR_COLOR, IOR, IRIDESCENCE, IRIDESCENCE_IOR, IRIDESCENCE_THICKNESS_MINIMUM,
               IRIDESCENCE_THICKNESS_MAXIMUM, TRANSMISSION, THICKNESS, ATTENUATION_DISTANCE, ATTENUATION_COLOR,
               ANISOTROPY_STRENGTH, ANISOTROPY_ROTATION, DISPERSION), setup,
              EXTENDED_COMPOSITION,
              ("ggx", "separable", "schlick", "lambert"),
              RealTime(diffuse_weight=ibl_specular_diffuse_weight, coat_roughness=ibl_coat_roughness,
                       sheen_roughness=ibl_sheen_roughness, extras=ibl_extensions_extras,
                       base_scale=ibl_extensions_base_scale, khronos_extensions=True,
                       transmission=ibl_transmission), core=CORE,
              emission_coat=emission_coat)
