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
model's extended setup fills them).

The coat's normal (the README's ``clearcoatNormal``, "Clearcoat": from
``clearcoatNormalTexture``, and without one the geometry's normal, "no normal mapping is
applied to the clear coat layer, even if normal mapping is applied to the base
material") rides in the slots :data:`COAT_NORMAL_SLOT` .. + 2: (0, 0, 0) where it is the
shading normal; the setup leaves a hit's world-space coat normal there and
:func:`coat_in_frame` (called by :func:`pbrkit.rendering.materials.hit_bxdf`) turns it
into the shading frame's coordinates.  Every coat term then takes its cosines about
that normal (:func:`coat_cosines`): n_c.l, n_c.v, n_c.h (v.h is the same in any frame),
and the lobe is 0 unless n_c.l > 0 and n_c.v > 0.

- Sampling: GGX visible normals of alpha_c (Heitz 2018) about the coat's normal
  (:data:`COAT_NORMALS`: the view turned into a frame about n_c, sampled, reflected
  and turned back; the pdf G1(v) D(h) / (4 n_c.v) from the coat cosines), role
  "coat"; the estimate is 1 (the white lobe's albedo is at most 1), scaled by the
  operator's clearcoat * clearcoat_fresnel(n.v) (at the shading normal's n.v: an
  estimate only sets how often the lobe is sampled).
- Directional albedo: the half-vector quadrature of its value at alpha_c
  (:func:`pbrkit.brdf.lobes.quadrature_albedo`).
"""

from __future__ import annotations

import math

from ...core.jit import dual_use
from ...core.vec import orthonormal_basis_xyz
from ..bxdf import with_extra
from ..fresnel import f_schlick
from ...microfacet.ggx import d_ggx, lambda_ggx, pdf_ggx_vndf, warp_ggx_vndf
from ...microfacet.smith import g2_separable, visibility
from ...sampling.warps import pdf_light_from_half, reflect_xyz
from . import Lobe, Technique, quadrature_albedo

__all__ = ["CLEARCOAT_SLOT", "CLEARCOAT_ALPHA_SLOT", "COAT_NORMAL_SLOT", "CLEARCOAT", "COAT_NORMALS",
           "clearcoat_value", "clearcoat_weight", "coated_emission", "coat_tilted", "coat_cosines", "coat_nov",
           "coat_local_nov", "coat_in_frame"]

#: The BxDF ``extra`` slots of the coat: its weight (clearcoatFactor) and alpha_c.
CLEARCOAT_SLOT, CLEARCOAT_ALPHA_SLOT = 4, 5
#: The first of the three ``extra`` slots of the coat's own normal (module docstring).
COAT_NORMAL_SLOT = 12


@dual_use(inline=True)
def _alpha(b):
    return b.extra[CLEARCOAT_ALPHA_SLOT]


@dual_use(inline=True)
def coat_tilted(b):
    """Whether the coat of ``b`` has a normal of its own (its slots not all 0)."""
    e = b.extra
    s = COAT_NORMAL_SLOT
    return e[s] != 0.0 or e[s + 1] != 0.0 or e[s + 2] != 0.0


@dual_use(inline=True)
def coat_in_frame(b, nx, ny, nz, t, bt):
    """``b`` with its world-space coat normal (the setup's) in the coordinates of the
    shading frame (tangent t, bitangent bt, normal n), normalised; ``b`` itself
    where the coat has no normal of its own."""
    if not coat_tilted(b):
        return b
    e = b.extra
    s = COAT_NORMAL_SLOT
    wx, wy, wz = e[s], e[s + 1], e[s + 2]
    x = t[0] * wx + t[1] * wy + t[2] * wz
    y = bt[0] * wx + bt[1] * wy + bt[2] * wz
    z = nx * wx + ny * wy + nz * wz
    k = 1.0 / math.sqrt(x * x + y * y + z * z)
    return with_extra(b, e[:s] + (x * k, y * k, z * k))


@dual_use(inline=True)
def coat_cosines(b, c):
    """(n_c.l, n_c.v, n_c.h): the cosines of :class:`pbrkit.brdf.bxdf.Cosines` ``c``
    about the coat's normal n_c (its slots, in the shading frame; ``c`` must then carry
    its tangent components, :func:`pbrkit.rendering.materials.hit_cosines`), or ``c``'s own
    where the coat has none."""
    if not coat_tilted(b):
        return c.nol, c.nov, c.noh
    e = b.extra
    s = COAT_NORMAL_SLOT
    x, y, z = e[s], e[s + 1], e[s + 2]
    return (x * c.tol + y * c.bol + z * c.nol, x * c.tov + y * c.bov + z * c.nov,
            x * c.toh + y * c.boh + z * c.noh)


@dual_use(inline=True)
def coat_nov(b, c):
    """|n_c.v|, the view's cosine to the coat's normal (:func:`coat_cosines`): the
    cosine of the coat's Fresnel, clearcoat_fresnel = f0 + (1 - f0)(1 - abs(dot(V,
    normal)))^5 (the README's fresnel_coat); n.v where the coat has no normal of its own."""
    if not coat_tilted(b):
        return c.nov
    e = b.extra
    s = COAT_NORMAL_SLOT
    return abs(e[s] * c.tov + e[s + 1] * c.bov + e[s + 2] * c.nov)


@dual_use(inline=True)
def coat_local_nov(b, wox, woy, woz):
    """n_c.v for the view wo in the shading frame's coordinates (woz = n.v): the real-time
    terms' and the transmission's cosine of the coat's Fresnel (:func:`coat_nov`)."""
    if not coat_tilted(b):
        return woz
    e = b.extra
    s = COAT_NORMAL_SLOT
    return e[s] * wox + e[s + 1] * woy + e[s + 2] * woz


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
    coat's normal.  Works on arrays from Python."""
    return 1.0 - weight * f_schlick(abs(nov), f0, 1.0)


@dual_use(inline=True)
def clearcoat_value(b, c, ec, w):
    """D_GGX(n_c.h; alpha_c) V_separable(n_c.l, n_c.v; alpha_c) (white, no Fresnel),
    times the operators' weight ``w``, about the coat's normal (:func:`coat_cosines`;
    0 unless n_c.l > 0 and n_c.v > 0 where it is not the shading normal); 0 without
    evaluating D and V when the weight ``w`` is 0 (no coat)."""
    if w == 0.0:
        return 0.0, 0.0, 0.0
    a = _alpha(b)
    nol, nov, noh = coat_cosines(b, c)
    if coat_tilted(b) and not (nol > 0.0 and nov > 0.0):
        return 0.0, 0.0, 0.0
    k = d_ggx(noh, a) * visibility(g2_separable(lambda_ggx(nol, a), lambda_ggx(nov, a)), nol, nov) * w
    return k, k, k


@dual_use(inline=True)
def _estimate(b, nov):
    return 1.0


@dual_use
def _sample(b, wox, woy, woz, u1, u2):
    # GGX visible normals of alpha_c about n_c (Heitz 2018), reflected: the view in a frame
    # about n_c (Duff et al. 2017), sampled, and the light turned back
    a = _alpha(b)
    if not coat_tilted(b):
        hx, hy, hz = warp_ggx_vndf(u1, u2, wox, woy, woz, a)
        return reflect_xyz(wox, woy, woz, hx, hy, hz)
    e = b.extra
    s = COAT_NORMAL_SLOT
    x, y, z = e[s], e[s + 1], e[s + 2]
    (tx, ty, tz), (bx, by, bz) = orthonormal_basis_xyz(x, y, z)
    vx = wox * tx + woy * ty + woz * tz
    vy = wox * bx + woy * by + woz * bz
    vz = wox * x + woy * y + woz * z
    if vz <= 0.0:  # the view below the coat: a failed sample
        return 0.0, 0.0, -1.0
    hx, hy, hz = warp_ggx_vndf(u1, u2, vx, vy, vz, a)
    lx, ly, lz = reflect_xyz(vx, vy, vz, hx, hy, hz)
    return lx * tx + ly * bx + lz * x, lx * ty + ly * by + lz * y, lx * tz + ly * bz + lz * z


@dual_use
def _pdf(b, c):
    # the sampler's density of l: G1(v) D(h) / (4 n_c.v) about n_c, wherever l lies (a light
    # below the coat, which the lobe's value gives 0, is still drawn by this technique)
    nol, nov, noh = coat_cosines(b, c)
    if coat_tilted(b) and not (nov > 0.0 and noh > 0.0):
        return 0.0
    return pdf_light_from_half(pdf_ggx_vndf(nov, noh, c.voh, _alpha(b)), c.voh)


#: GGX visible normals of the coat's alpha_c about the coat's normal (module docstring).
COAT_NORMALS = Technique("coat-normals", _sample, _pdf)


#: KHR_materials_clearcoat's coat lobe (module docstring).
CLEARCOAT = Lobe("clearcoat", clearcoat_value, COAT_NORMALS, "coat", _estimate,
                 quadrature_albedo(clearcoat_value, _alpha))
