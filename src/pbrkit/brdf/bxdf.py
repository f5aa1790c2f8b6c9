"""Every shading model composed once, as a BxDF with its value, sampling
routine and pdf side by side (the structure of pbrt-v4's BxDFs, Pharr, Jakob
and Humphreys 2023, ch. 9).

A material is packed for compiled code as a row of integer codes
(:data:`CODE_COLUMNS`: model, distribution, masking, Fresnel, diffuse, each an
index into the name tuples below) and a row of float parameters
(:data:`PARAM_COLUMNS`, named ``P_*``).  :func:`make_bxdf` turns the two rows
and the (possibly textured) base colour, metallic and roughness at a shading
point into a :class:`BxDF`: the model's derived quantities (alpha and the
anisotropic alphas, f0, f90, the diffuse colour, Disney's sheen and clear
coat).  Then, with the directions given as their cosines in the shading
frame (:class:`Cosines`, :func:`cosines`; normal n, tangent t, bitangent b):

- :func:`bxdf_f` is the BRDF value f (RGB; not f cos);
- :func:`sample_wi` draws a light direction in the local frame (normal +z,
  tangent +x) from the lobe mixture of :func:`lobe_probabilities`;
- :func:`bxdf_pdf` is the solid-angle pdf of that mixture.

All of them are :func:`pbrkit.core.jit.dual_use` functions compiled into the
kernels of the NumPy API (:mod:`pbrkit.brdf.models`), the furnace
(:mod:`pbrkit.albedo.furnace`, through the API), the lookup tables
(:func:`specular_visibility`) and both render modes (:mod:`pbrkit.render`).
Perceptual roughness r maps to alpha = max(r^2, ALPHA_MIN) in every model;
UE4's direct-light masking also uses k = (r + 1)^2 / 8, and the anisotropic
alphas are Kulla & Conty's (cook_torrance, filament: anisotropy in [-1, 1])
or Burley's (disney: anisotropy in [0, 1]).

Sampling: the specular lobe by GGX visible normals (Heitz 2018; anisotropic
when the material is; Beckmann and Blinn-Phong lobes use the GGX proposal of
the same alpha, which keeps the estimator unbiased), the diffuse (and sheen)
lobes by cosine-weighted directions, Disney's clear coat by the GTR1
distribution of normals (Burley 2012, App. B.2); a direction reflected below
the horizon is a failed sample (the pdf then integrates to less than 1 over
the upper hemisphere, by exactly the probability of failing).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..core.color import rec709_luminance
from ..core.jit import dual_use, select
from ..core.vec import orthonormal_basis_xyz
from ..microfacet.beckmann import d_beckmann, d_beckmann_anisotropic, lambda_beckmann, lambda_beckmann_anisotropic
from ..microfacet.blinn_phong import d_blinn_phong, phong_exponent_from_beckmann_alpha
from ..microfacet.ggx import (
    d_ggx,
    d_ggx_anisotropic,
    lambda_ggx,
    lambda_ggx_anisotropic,
    pdf_ggx_vndf,
    pdf_ggx_vndf_anisotropic,
    v_smith_ggx_height_correlated,
    warp_ggx_vndf,
    warp_ggx_vndf_anisotropic,
)
from ..microfacet.gtr import d_gtr1, pdf_gtr1_ndf, warp_gtr1_ndf
from ..microfacet.roughness import alpha_from_roughness, anisotropic_alphas, anisotropic_alphas_burley
from ..microfacet.smith import g2_height_correlated, g2_separable, visibility
from ..sampling.warps import pdf_cosine_hemisphere, pdf_light_from_half, reflect_xyz, warp_cosine_hemisphere
from .diffuse import burley, burley_subsurface, lambert
from .fresnel import (
    f0_from_ior,
    f0_metallic,
    f90_filament,
    f_conductor,
    f_schlick,
    f_schlick_pow4,
    f_schlick_ue4_sg,
    ior_from_f0,
)
from .masking import g2_kelemen, g2_schlick_ggx, k_schlick_from_alpha, k_ue4_direct

__all__ = [
    "MODELS", "DISTRIBUTIONS", "MASKINGS", "FRESNELS", "DIFFUSES", "MODEL_TERMS",
    "MODEL_COOK_TORRANCE", "MODEL_FILAMENT", "MODEL_UE4", "MODEL_URP_MOBILE", "MODEL_DISNEY", "MODEL_GLTF",
    "DIST_GGX", "DIST_BECKMANN", "DIST_BLINN_PHONG",
    "MASK_HEIGHT_CORRELATED", "MASK_SEPARABLE", "MASK_SCHLICK_GGX", "MASK_SCHLICK_GGX_UE4", "MASK_KELEMEN",
    "MASK_IMPLICIT",
    "FRES_SCHLICK", "FRES_SCHLICK_POW4", "FRES_UE4_SG", "FRES_EXACT_CONDUCTOR", "FRES_EXACT_DIELECTRIC", "FRES_NONE",
    "DIFF_LAMBERT", "DIFF_BURLEY", "DIFF_NONE",
    "C_MODEL", "C_DISTRIBUTION", "C_MASKING", "C_FRESNEL", "C_DIFFUSE", "CODE_COLUMNS",
    "P_DIELECTRIC_F0", "P_ETA", "P_K", "P_SPECULAR_COLOR", "P_BASE_COLOR", "P_METALLIC", "P_ROUGHNESS",
    "P_EMISSIVE", "P_DOUBLE_SIDED", "P_ANISOTROPY", "P_SUBSURFACE", "P_SPECULAR_TINT", "P_SHEEN", "P_SHEEN_TINT",
    "P_CLEARCOAT", "P_CLEARCOAT_GLOSS", "PARAM_COLUMNS",
    "URP_DIELECTRIC_F0", "GLTF_DIELECTRIC_F0", "gltf_fresnel_mix_weight", "urp_diffuse_weight", "disney_tint", "lobe_alphas", "disney_clearcoat_alpha",
    "combine_lobes", "ue4_specular", "filament_specular", "urp_specular",
    "BxDF", "Cosines", "cosines", "isotropic_cosines", "local_cosines", "make_bxdf", "lobe_bxdf", "specular_visibility", "specular_lobe",
    "bxdf_fresnel", "bxdf_f", "lobe_probabilities", "sample_wi", "bxdf_pdf", "tangent_frame",
]

# ------------------------------------------------------------------ choices

#: Shading models, by name (the scene files' ``model`` key).
MODELS = ("cook_torrance", "filament", "ue4", "urp_mobile", "disney", "gltf")
#: cook_torrance's choices of D, G (or V), F and diffuse lobe.
DISTRIBUTIONS = ("ggx", "beckmann", "blinn-phong")
MASKINGS = ("height-correlated", "separable", "schlick-ggx", "schlick-ggx-ue4", "kelemen", "implicit")
FRESNELS = ("schlick", "schlick-pow4", "ue4-sg", "exact-conductor", "exact-dielectric", "none")
DIFFUSES = ("lambert", "burley", "none")

#: The (distribution, masking, fresnel, diffuse) each fixed model implies; None: the material chooses.
MODEL_TERMS = {
    "ue4": ("ggx", "schlick-ggx-ue4", "ue4-sg", "lambert"),
    "filament": ("ggx", "height-correlated", "schlick", None),
    "urp_mobile": ("ggx", "height-correlated", "schlick", "lambert"),
    "disney": ("ggx", "separable", "schlick", "burley"),
    "gltf": ("ggx", "separable", "schlick", "lambert"),
}

MODEL_COOK_TORRANCE = MODELS.index("cook_torrance")
MODEL_FILAMENT = MODELS.index("filament")
MODEL_UE4 = MODELS.index("ue4")
MODEL_URP_MOBILE = MODELS.index("urp_mobile")
MODEL_DISNEY = MODELS.index("disney")
MODEL_GLTF = MODELS.index("gltf")
DIST_GGX = DISTRIBUTIONS.index("ggx")
DIST_BECKMANN = DISTRIBUTIONS.index("beckmann")
DIST_BLINN_PHONG = DISTRIBUTIONS.index("blinn-phong")
MASK_HEIGHT_CORRELATED = MASKINGS.index("height-correlated")
MASK_SEPARABLE = MASKINGS.index("separable")
MASK_SCHLICK_GGX = MASKINGS.index("schlick-ggx")
MASK_SCHLICK_GGX_UE4 = MASKINGS.index("schlick-ggx-ue4")
MASK_KELEMEN = MASKINGS.index("kelemen")
MASK_IMPLICIT = MASKINGS.index("implicit")
FRES_SCHLICK = FRESNELS.index("schlick")
FRES_SCHLICK_POW4 = FRESNELS.index("schlick-pow4")
FRES_UE4_SG = FRESNELS.index("ue4-sg")
FRES_EXACT_CONDUCTOR = FRESNELS.index("exact-conductor")
FRES_EXACT_DIELECTRIC = FRESNELS.index("exact-dielectric")
FRES_NONE = FRESNELS.index("none")
DIFF_LAMBERT = DIFFUSES.index("lambert")
DIFF_BURLEY = DIFFUSES.index("burley")
DIFF_NONE = DIFFUSES.index("none")

#: Columns of a material's integer code row.
C_MODEL, C_DISTRIBUTION, C_MASKING, C_FRESNEL, C_DIFFUSE = range(5)
CODE_COLUMNS = 5
#: Columns of a material's float parameter row (RGB quantities take three).
P_DIELECTRIC_F0 = 0      # 0.16 reflectance^2
P_ETA = 1                # complex IOR (exact conductor), 3
P_K = 4                  # 3
P_SPECULAR_COLOR = 7     # the constant F of fresnel "none", 3
P_BASE_COLOR = 10        # 3
P_METALLIC = 13
P_ROUGHNESS = 14
P_EMISSIVE = 15          # emitted radiance, 3 (renderer only)
P_DOUBLE_SIDED = 18      # 1 or 0 (renderer only)
P_ANISOTROPY = 19
P_SUBSURFACE = 20        # Disney extras from here on
P_SPECULAR_TINT = 21
P_SHEEN = 22
P_SHEEN_TINT = 23
P_CLEARCOAT = 24
P_CLEARCOAT_GLOSS = 25
PARAM_COLUMNS = 26

_INV_PI = 1.0 / math.pi

# ------------------------------------------------------- model-specific terms

#: URP's dielectric specular colour ``kDielectricSpec.rgb`` (URP ``BRDF.hlsl``).
URP_DIELECTRIC_F0 = 0.04
#: The glTF 2.0 dielectric's normal reflectance, from its fixed IOR 1.5 (glTF 2.0
#: specification, Appendix B.3.4, ``fresnel_mix(ior = 1.5, ...)``): ((1.5 - 1) / (1.5 + 1))^2 = 0.04.
GLTF_DIELECTRIC_F0 = f0_from_ior(1.5)


@dual_use
def gltf_fresnel_mix_weight(voh):
    """The weight 1 - F(v.h) that the glTF 2.0 metallic-roughness BRDF gives its
    diffuse base under the specular layer: ``fresnel_mix(ior = 1.5, base, layer)
    = mix(base, layer, F)`` with F = f0 + (1 - f0)(1 - |v.h|)^5, f0 = 0.04
    (glTF 2.0 specification, Appendix B.3.4 and B.3.5).  The whole model is

        material = mix(fresnel_mix(1.5, diffuse_brdf(base_color), specular_brdf(r^2)),
                       conductor_fresnel(base_color, specular_brdf(r^2)), metallic)

    so f = (1 - metallic)(1 - F_0.04(v.h)) base_color / pi + D V F_f0(v.h) with
    f0 = mix(0.04, base_color, metallic) (Schlick's F is linear in f0), D GGX
    and V the separable Smith-GGX visibility of Appendix B.3.2, alpha = r^2."""
    return 1.0 - f_schlick(voh, GLTF_DIELECTRIC_F0, 1.0)


@dual_use
def urp_diffuse_weight(metallic):
    """URP's diffuse weight ``OneMinusReflectivityMetallic``: (1 - 0.04)(1 - metallic)
    = 0.96 (1 - metallic) (URP ``BRDF.hlsl``, ``kDielectricSpec.a = 1 - 0.04``)."""
    return (1.0 - URP_DIELECTRIC_F0) * (1.0 - metallic)


@dual_use
def disney_tint(c, luminance):
    """Disney's hue-only tint C_tint = C / luminance(C) of one channel, 1 for a
    black colour; the luminance is 0.3 R + 0.6 G + 0.1 B (Burley 2012, App. B;
    the BRDF Explorer's ``disney.brdf``)."""
    return select(luminance > 0.0, c / select(luminance > 0.0, luminance, 1.0), 1.0)


@dual_use
def lobe_alphas(model, distribution, alpha, anisotropy):
    """(alpha_x, alpha_y, anisotropic) of a model's specular lobe: Burley's aspect
    for disney (anisotropy in [0, 1], :func:`pbrkit.microfacet.roughness.anisotropic_alphas_burley`),
    Kulla & Conty's stretch for filament and cook_torrance's GGX and Beckmann
    (anisotropy in [-1, 1], :func:`pbrkit.microfacet.roughness.anisotropic_alphas`);
    isotropic otherwise (UE4, URP, Blinn-Phong) or for anisotropy 0."""
    if anisotropy != 0.0:
        if model == MODEL_DISNEY:
            ax, ay = anisotropic_alphas_burley(alpha, anisotropy)
            return ax, ay, True
        if model == MODEL_FILAMENT or (model == MODEL_COOK_TORRANCE and distribution != DIST_BLINN_PHONG):
            ax, ay = anisotropic_alphas(alpha, anisotropy)
            return ax, ay, True
    return alpha, alpha, False


@dual_use
def disney_clearcoat_alpha(gloss):
    """The GTR1 width of Disney's clear coat, alpha = mix(0.1, 0.001, clearcoat_gloss)
    (Burley 2012, App. B; not r^2)."""
    return 0.1 + (0.001 - 0.1) * gloss


@dual_use
def combine_lobes(nol, nov, diffuse_color, diffuse_factor, specular, fresnel):
    """f = diffuse_color * diffuse_factor + specular * F, zero below the horizon.

    The metallic-workflow sum of Karis 2013 / Filament sec. 4.4 / glTF 2.0
    Appendix B, with diffuse_color = base_color (1 - metallic) and ``specular``
    the Fresnel-free microfacet lobe D V.
    """
    return select((nol > 0.0) & (nov > 0.0), diffuse_color * diffuse_factor + specular * fresnel, 0.0)


@dual_use
def ue4_specular(nol, nov, noh, roughness):
    """UE4 specular lobe without Fresnel (Karis 2013, "Real Shading in Unreal Engine 4"):
    D_GGX(alpha = r^2) times V = G2 / (4 n.l n.v) with separable Schlick-GGX
    G1 and the direct-light remap k = (r + 1)^2 / 8."""
    alpha = alpha_from_roughness(roughness)
    g2 = g2_schlick_ggx(nol, nov, k_ue4_direct(roughness))
    return d_ggx(noh, alpha) * visibility(g2, nol, nov)


@dual_use
def filament_specular(nol, nov, noh, alpha):
    """Filament's isotropic specular lobe without Fresnel (Filament documentation,
    sec. 4.4): D_GGX times the height-correlated Smith-GGX visibility."""
    return d_ggx(noh, alpha) * v_smith_ggx_height_correlated(nol, nov, alpha)


@dual_use
def urp_specular(noh, loh, alpha):
    """Unity URP's "minimalist Cook-Torrance" specular term (URP ``BRDF.hlsl``,
    ``DirectBRDFSpecular``; after Renaldas Zioma, "Optimizing PBR for Mobile",
    SIGGRAPH 2015): alpha^2 / (d^2 max(0.1, (l.h)^2) (4 alpha + 2)) with
    d = (n.h)^2 (alpha^2 - 1) + 1.  Unity's lights carry a factor pi, so the
    BRDF value is this term divided by pi (see :func:`specular_lobe`)."""
    a2 = alpha * alpha
    c = np.minimum(np.maximum(noh, 0.0), 1.0)
    d = a2 * c * c + (1.0 - c) * (1.0 + c)  # = c^2 (alpha^2 - 1) + 1 without cancellation
    return select(noh > 0.0, a2 / (d * d * np.maximum(0.1, loh * loh) * (4.0 * alpha + 2.0)), 0.0)


# ------------------------------------------------------------------ the BxDF


class BxDF(NamedTuple):
    """A material at one shading point, ready to evaluate and sample
    (:func:`make_bxdf`).  ``alpha_x``, ``alpha_y`` are along the tangent and
    bitangent (equal to ``alpha`` unless ``anisotropic``); ``f0`` is the
    metallic-workflow normal reflectance of the Schlick-type Fresnel terms and
    ``f90`` their grazing value; ``diffuse_color`` already carries the
    model's metallic weighting; ``sheen`` is Disney's sheen colour times
    (1 - metallic), ``clearcoat`` its 0.25 clearcoat weight."""

    model: int
    distribution: int
    masking: int
    fresnel: int
    diffuse: int
    roughness: float
    alpha: float
    alpha_x: float
    alpha_y: float
    anisotropic: bool
    metallic: float
    base: tuple
    diffuse_color: tuple
    f0: tuple
    f90: float
    eta: tuple
    k: tuple
    dielectric_f0: float
    specular_color: tuple
    subsurface: float
    sheen: tuple
    clearcoat: float
    clearcoat_alpha: float


@dual_use(inline=True)
def make_bxdf(codes, code_row, params, param_row, roughness, metallic, b0, b1, b2):
    """The :class:`BxDF` of a material (row ``code_row`` of the code table
    ``codes``, row ``param_row`` of the parameter table ``params``) with the base
    colour (b0, b1, b2), metallic and perceptual roughness at the shading point
    (textures applied).  Tables and row numbers rather than row views: a view
    per call costs reference counting in the innermost loops."""
    c = code_row
    q = param_row
    model = codes[c, C_MODEL]
    distribution = codes[c, C_DISTRIBUTION]
    alpha = alpha_from_roughness(roughness)
    alpha_x, alpha_y, anisotropic = lobe_alphas(model, distribution, alpha, params[q, P_ANISOTROPY])
    f0d = params[q, P_DIELECTRIC_F0]
    sheen = (0.0, 0.0, 0.0)
    if model == MODEL_URP_MOBILE:
        f0 = (f0_metallic(b0, metallic, URP_DIELECTRIC_F0), f0_metallic(b1, metallic, URP_DIELECTRIC_F0),
              f0_metallic(b2, metallic, URP_DIELECTRIC_F0))
        kd = urp_diffuse_weight(metallic)
    elif model == MODEL_DISNEY:
        lum = 0.3 * b0 + 0.6 * b1 + 0.1 * b2
        t0 = disney_tint(b0, lum)
        t1 = disney_tint(b1, lum)
        t2 = disney_tint(b2, lum)
        st = params[q, P_SPECULAR_TINT]
        f0 = (f0_metallic(b0, metallic, f0d * (1.0 + (t0 - 1.0) * st)),
              f0_metallic(b1, metallic, f0d * (1.0 + (t1 - 1.0) * st)),
              f0_metallic(b2, metallic, f0d * (1.0 + (t2 - 1.0) * st)))
        kd = 1.0 - metallic
        s = params[q, P_SHEEN]
        sht = params[q, P_SHEEN_TINT]
        sheen = (s * (1.0 + (t0 - 1.0) * sht) * kd, s * (1.0 + (t1 - 1.0) * sht) * kd,
                 s * (1.0 + (t2 - 1.0) * sht) * kd)
    else:
        if model == MODEL_GLTF:
            f0d = GLTF_DIELECTRIC_F0
        f0 = (f0_metallic(b0, metallic, f0d), f0_metallic(b1, metallic, f0d), f0_metallic(b2, metallic, f0d))
        kd = 1.0 - metallic
    f90 = f90_filament(f0[0] + f0[1] + f0[2]) if model == MODEL_FILAMENT else 1.0
    clearcoat = 0.0
    clearcoat_alpha = 0.1
    if model == MODEL_DISNEY:
        clearcoat = 0.25 * params[q, P_CLEARCOAT]
        clearcoat_alpha = disney_clearcoat_alpha(params[q, P_CLEARCOAT_GLOSS])
    return BxDF(model, distribution, codes[c, C_MASKING], codes[c, C_FRESNEL], codes[c, C_DIFFUSE], roughness, alpha,
                alpha_x, alpha_y, anisotropic, metallic, (b0, b1, b2), (b0 * kd, b1 * kd, b2 * kd), f0, f90,
                (params[q, P_ETA], params[q, P_ETA + 1], params[q, P_ETA + 2]),
                (params[q, P_K], params[q, P_K + 1], params[q, P_K + 2]), f0d,
                (params[q, P_SPECULAR_COLOR], params[q, P_SPECULAR_COLOR + 1], params[q, P_SPECULAR_COLOR + 2]),
                params[q, P_SUBSURFACE], sheen, clearcoat, clearcoat_alpha)


@dual_use(inline=True)
def lobe_bxdf(model, masking, alpha):
    """A BxDF that holds only an isotropic GGX specular lobe of width alpha with the
    masking of ``model`` (and ``masking`` for cook_torrance): what the lookup
    tables integrate (:mod:`pbrkit.albedo.tables` calls
    :func:`specular_visibility` of it)."""
    z3 = (0.0, 0.0, 0.0)
    return BxDF(model, DIST_GGX, masking, FRES_NONE, DIFF_NONE, math.sqrt(alpha), alpha, alpha, alpha, False, 1.0,
                z3, z3, z3, 1.0, z3, z3, 0.0, z3, 0.0, z3, 0.0, 0.1)


# ---------------------------------------------------------------- the frame


class Cosines(NamedTuple):
    """The light l, the view v and the half vector h = normalize(l + v) in the
    shading frame (n, t, b): n.l, n.v, n.h, v.h (clamped at 0) and the tangent
    components t.l, b.l, t.v, b.v, t.h, b.h (0 when no tangent frame is used)."""

    nol: float
    nov: float
    noh: float
    voh: float
    tol: float
    bol: float
    tov: float
    bov: float
    toh: float
    boh: float


@dual_use
def _half_vector_cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz):
    # h = normalize(l + v) (n where l = -v) and n.l, n.v, n.h, max(v.h, 0).
    hx = lx + vx
    hy = ly + vy
    hz = lz + vz
    hl = math.sqrt(hx * hx + hy * hy + hz * hz)
    if hl > 1e-12:
        hx /= hl
        hy /= hl
        hz /= hl
    else:
        hx, hy, hz = nx, ny, nz
    nol = nx * lx + ny * ly + nz * lz
    nov = nx * vx + ny * vy + nz * vz
    noh = nx * hx + ny * hy + nz * hz
    voh = max(vx * hx + vy * hy + vz * hz, 0.0)
    return hx, hy, hz, nol, nov, noh, voh


@dual_use
def cosines(nx, ny, nz, tx, ty, tz, bx, by, bz, vx, vy, vz, lx, ly, lz):
    """:class:`Cosines` of world directions l and v (unit) in the frame with
    normal n, tangent t and bitangent b (unit, right-handed).  h = normalize(l +
    v); where l = -v, h = n (never NaN)."""
    hx, hy, hz, nol, nov, noh, voh = _half_vector_cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz)
    return Cosines(nol, nov, noh, voh, tx * lx + ty * ly + tz * lz, bx * lx + by * ly + bz * lz,
                   tx * vx + ty * vy + tz * vz, bx * vx + by * vy + bz * vz, tx * hx + ty * hy + tz * hz,
                   bx * hx + by * hy + bz * hz)


@dual_use
def isotropic_cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz):
    """:class:`Cosines` without the tangent components (zero): all an isotropic
    lobe uses."""
    _, _, _, nol, nov, noh, voh = _half_vector_cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz)
    return Cosines(nol, nov, noh, voh, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@dual_use
def local_cosines(wox, woy, woz, wix, wiy, wiz):
    """:class:`Cosines` of directions given in the local frame (normal +z, tangent +x)."""
    return cosines(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, wox, woy, woz, wix, wiy, wiz)


@dual_use
def tangent_frame(nx, ny, nz, anisotropic):
    """Tangent and bitangent of the shading frame at unit normal n.  For
    isotropic materials any frame will do: Duff et al.'s branchless basis
    (:func:`pbrkit.core.vec.orthonormal_basis_xyz`).  Anisotropic materials
    need a frame that varies smoothly over the surface: the tangent follows
    the parallels about +Y, t = normalize(n x Y) (on a sphere the direction of
    increasing longitude phi = atan2(z, x), as a parametric sphere's dp/dphi),
    with Duff's basis where n is within 1e-6 of +-Y."""
    if anisotropic:
        tx = -nz
        tz = nx
        length = math.sqrt(tx * tx + tz * tz)
        if length > 1e-6:
            tx /= length
            tz /= length
            # b = n x t
            return (tx, 0.0, tz), (ny * tz, nz * tx - nx * tz, -ny * tx)
    return orthonormal_basis_xyz(nx, ny, nz)


# -------------------------------------------------------------- the value


@dual_use(inline=True)
def specular_visibility(b, c):
    """The visibility V = G2 / (4 n.l n.v) of the model's specular lobe, and
    Smith's Lambdas where the model uses them: the masking-shadowing choice of
    ``cook_torrance`` (exact Smith height-correlated or separable for the
    chosen D, Schlick-GGX with k = alpha / 2 or UE4's k = (r + 1)^2 / 8,
    Kelemen, or the implicit G = n.l n.v), Filament's division-free
    height-correlated form (Lagarde & de Rousiers 2014), Disney's separable
    Smith, UE4's Schlick-GGX (k = (r + 1)^2 / 8).  Not used by URP, whose term
    has no separate V."""
    nol = c.nol
    nov = c.nov
    model = b.model
    if model == MODEL_FILAMENT and not b.anisotropic:
        return v_smith_ggx_height_correlated(nol, nov, b.alpha)
    if model == MODEL_UE4:
        return visibility(g2_schlick_ggx(nol, nov, k_ue4_direct(b.roughness)), nol, nov)
    mask = b.masking
    if model == MODEL_FILAMENT:
        mask = MASK_HEIGHT_CORRELATED
    elif model == MODEL_DISNEY or model == MODEL_GLTF:
        mask = MASK_SEPARABLE
    if mask == MASK_HEIGHT_CORRELATED or mask == MASK_SEPARABLE:
        if b.anisotropic:
            if b.distribution == DIST_GGX:
                lam_l = lambda_ggx_anisotropic(nol, c.tol, c.bol, b.alpha_x, b.alpha_y)
                lam_v = lambda_ggx_anisotropic(nov, c.tov, c.bov, b.alpha_x, b.alpha_y)
            else:
                lam_l = lambda_beckmann_anisotropic(nol, c.tol, c.bol, b.alpha_x, b.alpha_y)
                lam_v = lambda_beckmann_anisotropic(nov, c.tov, c.bov, b.alpha_x, b.alpha_y)
        elif b.distribution == DIST_GGX:
            lam_l = lambda_ggx(nol, b.alpha)
            lam_v = lambda_ggx(nov, b.alpha)
        else:
            lam_l = lambda_beckmann(nol, b.alpha)
            lam_v = lambda_beckmann(nov, b.alpha)
        if mask == MASK_HEIGHT_CORRELATED:
            g2 = g2_height_correlated(lam_l, lam_v)
        else:
            g2 = g2_separable(lam_l, lam_v)
    elif mask == MASK_SCHLICK_GGX:
        g2 = g2_schlick_ggx(nol, nov, k_schlick_from_alpha(b.alpha))
    elif mask == MASK_SCHLICK_GGX_UE4:
        g2 = g2_schlick_ggx(nol, nov, k_ue4_direct(b.roughness))
    elif mask == MASK_KELEMEN:
        g2 = g2_kelemen(nol, nov, c.voh)
    else:
        g2 = max(nol, 0.0) * max(nov, 0.0)
    return visibility(g2, nol, nov)


@dual_use(inline=True)
def specular_lobe(b, c):
    """The Fresnel-free specular lobe D V of the model (:func:`specular_visibility`;
    D: GGX, Beckmann (both anisotropic when the material is) or Blinn-Phong
    with exponent 2 / alpha^2 - 2 for cook_torrance, GGX for the others; URP's
    term divided by pi)."""
    model = b.model
    if model == MODEL_URP_MOBILE:  # URP's term carries pi (see urp_specular)
        return urp_specular(c.noh, c.voh, b.alpha) * _INV_PI
    if model == MODEL_FILAMENT and not b.anisotropic:
        return filament_specular(c.nol, c.nov, c.noh, b.alpha)
    if model == MODEL_UE4:
        return ue4_specular(c.nol, c.nov, c.noh, b.roughness)
    if b.anisotropic:
        if b.distribution == DIST_BECKMANN:
            d = d_beckmann_anisotropic(c.noh, c.toh, c.boh, b.alpha_x, b.alpha_y)
        else:
            d = d_ggx_anisotropic(c.noh, c.toh, c.boh, b.alpha_x, b.alpha_y)
    elif b.distribution == DIST_BECKMANN and model == MODEL_COOK_TORRANCE:
        d = d_beckmann(c.noh, b.alpha)
    elif b.distribution == DIST_BLINN_PHONG and model == MODEL_COOK_TORRANCE:
        d = d_blinn_phong(c.noh, phong_exponent_from_beckmann_alpha(b.alpha))
    else:
        d = d_ggx(c.noh, b.alpha)
    return d * specular_visibility(b, c)


@dual_use(inline=True)
def _fresnel_channel(b, f0, eta, k, specular, voh):
    # One channel of bxdf_fresnel, from that channel's f0, eta, k and constant colour.
    model = b.model
    if model == MODEL_FILAMENT:
        return f_schlick(voh, f0, b.f90)
    if model == MODEL_UE4:
        return f_schlick_ue4_sg(voh, f0)
    if model == MODEL_URP_MOBILE:
        return f0
    if model == MODEL_DISNEY or model == MODEL_GLTF:
        return f_schlick(voh, f0, 1.0)
    fres = b.fresnel
    if fres == FRES_SCHLICK:
        return f_schlick(voh, f0, 1.0)
    if fres == FRES_SCHLICK_POW4:
        return f_schlick_pow4(voh, f0, 1.0)
    if fres == FRES_UE4_SG:
        return f_schlick_ue4_sg(voh, f0)
    if fres == FRES_EXACT_CONDUCTOR:
        return f_conductor(voh, eta, k)
    if fres == FRES_EXACT_DIELECTRIC:
        return f_conductor(voh, ior_from_f0(b.dielectric_f0), 0.0)
    return specular


@dual_use(inline=True)
def bxdf_fresnel(b, voh):
    """Fresnel reflectance (RGB tuple) at v.h: Schlick with f90 (Filament),
    UE4's spherical-Gaussian Schlick, URP's constant specular colour, or the
    cook_torrance choice (Schlick pow5 or pow4, UE4's, the exact conductor
    with the material's (eta, k), the exact dielectric of IOR from the
    dielectric f0, or the constant specular colour)."""
    return (_fresnel_channel(b, b.f0[0], b.eta[0], b.k[0], b.specular_color[0], voh),
            _fresnel_channel(b, b.f0[1], b.eta[1], b.k[1], b.specular_color[1], voh),
            _fresnel_channel(b, b.f0[2], b.eta[2], b.k[2], b.specular_color[2], voh))


@dual_use(inline=True)
def _diffuse_factor(b, c):
    # The factor multiplying the diffuse colour: Lambert (UE4, URP, or by choice), Burley, none, or
    # Disney's mix of Burley and its subsurface approximation.
    if b.model == MODEL_URP_MOBILE:
        return _INV_PI
    if b.model == MODEL_DISNEY:
        return (burley(c.nol, c.nov, c.voh, b.roughness) * (1.0 - b.subsurface)
                + burley_subsurface(c.nol, c.nov, c.voh, b.roughness) * b.subsurface)
    if b.model == MODEL_GLTF:
        return lambert(c.nol) * gltf_fresnel_mix_weight(c.voh)
    if b.model == MODEL_UE4 or b.diffuse == DIFF_LAMBERT:
        return lambert(c.nol)
    if b.diffuse == DIFF_BURLEY:
        return burley(c.nol, c.nov, c.voh, b.roughness)
    return 0.0


@dual_use
def bxdf_f(b, c, ec0, ec1, ec2):
    """The BRDF value f (RGB tuple; not f cos) of the BxDF for the cosines ``c``;
    (ec0, ec1, ec2) multiply the specular lobe (energy compensation, 1 = off).
    Zero unless n.l > 0 and n.v > 0 (:func:`combine_lobes`).  Disney adds its
    sheen (1 - l.h)^5 sheen_colour (1 - metallic) and its clear coat
    0.25 clearcoat D_GTR1 F_Schlick(0.04) V_Smith(alpha 0.25) (Burley 2012, App. B)."""
    nol = c.nol
    nov = c.nov
    if nol <= 0.0 or nov <= 0.0:
        return 0.0, 0.0, 0.0
    spec = specular_lobe(b, c)
    dfac = _diffuse_factor(b, c)
    voh = c.voh
    f0, f1, f2 = bxdf_fresnel(b, voh)
    r0 = combine_lobes(nol, nov, b.diffuse_color[0], dfac, spec * ec0, f0)
    r1 = combine_lobes(nol, nov, b.diffuse_color[1], dfac, spec * ec1, f1)
    r2 = combine_lobes(nol, nov, b.diffuse_color[2], dfac, spec * ec2, f2)
    if b.model == MODEL_DISNEY:
        fh = f_schlick(voh, 0.0, 1.0)
        coat = 0.0
        if b.clearcoat > 0.0:
            coat_v = visibility(g2_separable(lambda_ggx(nol, 0.25), lambda_ggx(nov, 0.25)), nol, nov)
            coat = b.clearcoat * d_gtr1(c.noh, b.clearcoat_alpha) * coat_v * f_schlick(voh, 0.04, 1.0)
        r0 += fh * b.sheen[0] + coat
        r1 += fh * b.sheen[1] + coat
        r2 += fh * b.sheen[2] + coat
    return r0, r1, r2


# ----------------------------------------------------------------- sampling


@dual_use(inline=True)
def lobe_probabilities(b, nov):
    """Probabilities (p_specular, p_clearcoat) of sampling the specular and clear-coat
    lobes (the diffuse lobe, with Disney's sheen, takes the rest): the specular
    lobe's albedo estimate (Schlick's F at n.v with the model's f0, or the
    constant specular colour) against the diffuse colour's, by Rec.709
    luminance, clamped to [0.1, 0.9] while both lobes are present; Disney's
    clear coat gets its own estimate 0.25 clearcoat F_Schlick(0.04, n.v),
    clamped to [0.1, 0.5]."""
    diffuse_on = b.model != MODEL_COOK_TORRANCE and b.model != MODEL_FILAMENT or b.diffuse != DIFF_NONE
    if b.model == MODEL_COOK_TORRANCE and b.fresnel == FRES_NONE:
        ws = rec709_luminance(b.specular_color[0], b.specular_color[1], b.specular_color[2])
    else:
        ws = rec709_luminance(f_schlick(nov, b.f0[0], 1.0), f_schlick(nov, b.f0[1], 1.0),
                              f_schlick(nov, b.f0[2], 1.0))
    wd = 0.0
    if diffuse_on:
        wd = rec709_luminance(b.base[0], b.base[1], b.base[2]) * (1.0 - b.metallic)
    if wd <= 0.0:
        p_spec = 1.0
    elif ws <= 0.0:
        p_spec = 0.0
    else:
        p_spec = min(max(ws / (ws + wd), 0.1), 0.9)
    p_coat = 0.0
    if b.clearcoat > 0.0:
        wc = b.clearcoat * f_schlick(nov, 0.04, 1.0)
        p_coat = min(max(wc / (ws + wd + wc), 0.1), 0.5)
        p_spec *= 1.0 - p_coat
    return p_spec, p_coat


@dual_use(inline=True)
def sample_wi(b, wox, woy, woz, u_lobe, u1, u2, p_spec, p_coat):
    """A light direction (local frame, normal +z, tangent +x; not normalised
    against rounding) for the view wo: with probability p_spec the mirror
    reflection of wo about a GGX visible normal (Heitz 2018; anisotropic
    alphas when the material is), with p_coat about a GTR1 normal (Burley
    2012, App. B.2), else cosine-weighted (Malley's method).  ``u_lobe``
    picks the lobe, (u1, u2) place the direction."""
    if u_lobe < p_spec:
        if b.anisotropic:
            hx, hy, hz = warp_ggx_vndf_anisotropic(u1, u2, wox, woy, woz, b.alpha_x, b.alpha_y)
        else:
            hx, hy, hz = warp_ggx_vndf(u1, u2, wox, woy, woz, b.alpha)
        return reflect_xyz(wox, woy, woz, hx, hy, hz)
    if u_lobe < p_spec + p_coat:
        hx, hy, hz = warp_gtr1_ndf(u1, u2, b.clearcoat_alpha)
        return reflect_xyz(wox, woy, woz, hx, hy, hz)
    return warp_cosine_hemisphere(u1, u2)


@dual_use(inline=True)
def bxdf_pdf(b, c, p_spec, p_coat):
    """Solid-angle pdf of :func:`sample_wi` for the light direction of ``c``
    (the view's visible-normal pdf D_v(h) / (4 v.h), the GTR1 pdf
    D(h) (n.h) / (4 v.h), and cos / pi, mixed by the lobe probabilities)."""
    pdf = 0.0
    if p_spec > 0.0:
        if b.anisotropic:
            ph = pdf_ggx_vndf_anisotropic(c.tov, c.bov, c.nov, c.toh, c.boh, c.noh, b.alpha_x, b.alpha_y)
        else:
            ph = pdf_ggx_vndf(c.nov, c.noh, c.voh, b.alpha)
        pdf += p_spec * pdf_light_from_half(ph, c.voh)
    if p_coat > 0.0:
        pdf += p_coat * pdf_light_from_half(pdf_gtr1_ndf(c.noh, b.clearcoat_alpha), c.voh)
    if p_spec + p_coat < 1.0:
        pdf += (1.0 - p_spec - p_coat) * pdf_cosine_hemisphere(c.nol)
    return pdf
