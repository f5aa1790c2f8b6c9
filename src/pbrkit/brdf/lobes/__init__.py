"""Lobes: the pieces a shading model is composed of (:mod:`pbrkit.brdf.operators`),
each with its value, its sampling routine and pdf, its albedo estimate and
its directional albedo side by side (the layout of pbrt-v4's BxDFs, Pharr,
Jakob and Humphreys 2023, ch. 9).

A :class:`Lobe` holds compiled functions of a :class:`pbrkit.brdf.bxdf.BxDF`
``b`` (the material at a shading point) and its :class:`~pbrkit.brdf.bxdf.Cosines`
``c`` (local frame: normal +z, tangent +x):

- ``value(b, c, ec, w)``: the lobe's BRDF value f (RGB, not f cos) with the
  factor ``w`` that operators weight it by (1 when it stands alone) and ``ec``
  (RGB) the energy compensation of the specular lobes (1 = off); written
  colour * (factor * w) so that a weighted lobe rounds as the lobe does;
- ``technique``: the :class:`Technique` that samples it (lobes that share one,
  such as Lambert and Disney's sheen under the cosine, share its samples);
- ``role``: how the mixture's sampling treats it (``"specular"``,
  ``"diffuse"``, ``"coat"``; :func:`pbrkit.brdf.operators.compose`);
- ``estimate(b, nov)``: the estimate of its weighted albedo that sets the
  probability of sampling it (None: it adds nothing, riding on another lobe's
  technique);
- ``albedo(b, nov)``: its directional albedo E(n.v) (RGB) -- exact where the
  lobe has a closed form, else a converged quadrature over the half vector
  (:func:`half_vector_albedo`).

The lobes themselves: :mod:`.microfacet` (reflection from a microfacet
distribution with a Fresnel factor), :mod:`.diffuse` (Lambert, Burley, the
choice of cook_torrance), :mod:`.disney` (Disney's diffuse with subsurface,
sheen and clear coat), :mod:`.eon` (OpenPBR's energy-preserving Oren-Nayar),
:mod:`.sheen` (KHR_materials_sheen's Charlie sheen with its albedo table),
:mod:`.clearcoat` (KHR_materials_clearcoat's coat lobe).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ...core.color import rec709_luminance
from ...core.jit import dual_use
from ...core.quadrature import gauss_legendre_01
from ...core.quadrature import ggx_cos_of_s, ggx_s_of_cos, horizon_limits, horizon_phi_max, split_node
from ..bxdf import local_cosines
from ...microfacet.ggx import d_ggx, pdf_ggx_vndf, pdf_ggx_vndf_anisotropic, warp_ggx_vndf, warp_ggx_vndf_anisotropic
from ...microfacet.gtr import pdf_gtr1_ndf, warp_gtr1_ndf
from ...sampling.warps import pdf_cosine_hemisphere, pdf_light_from_half, reflect_xyz, warp_cosine_hemisphere

__all__ = ["Lobe", "Technique", "GGX_VISIBLE_NORMALS", "COSINE", "ggx_normals", "gtr1_normals", "quadrature_albedo",
           "half_vector_albedo", "lobe_width", "broad_width", "ROLES", "diffuse_estimate"]

#: How the mixture samples a lobe: the specular lobe against the diffuse ones, coats
#: on top of both (:func:`pbrkit.brdf.operators.compose`).
ROLES = ("specular", "diffuse", "coat")


@dataclass(frozen=True)
class Technique:
    """A sampling routine and its solid-angle pdf: ``sample(b, wox, woy, woz, u1, u2)``
    a light direction in the local frame (not normalised against rounding; below
    the horizon it is a failed sample), ``pdf(b, c)`` its density at the light of
    ``c``."""

    name: str
    sample: object
    pdf: object


@dataclass(frozen=True, eq=False)
class Lobe:
    """A lobe (module docstring).  ``specular`` lobes also give the pieces the
    lookup tables, the explorer and the real-time split sum read:
    ``parts`` (a :class:`pbrkit.brdf.lobes.microfacet.Microfacet`)."""

    name: str
    value: object
    technique: Technique | None
    role: str | None
    estimate: object | None
    albedo: object
    parts: object = None

    def __post_init__(self):
        if self.role is not None and self.role not in ROLES:
            raise ValueError(f"lobe {self.name!r}: unknown role {self.role!r}; one of {', '.join(ROLES)}")
        if self.role is not None and (self.technique is None or self.estimate is None):
            raise ValueError(f"lobe {self.name!r}: a sampled lobe needs a technique and an estimate")


# ---------------------------------------------------------------- techniques


@dual_use
def _sample_ggx_visible_normals(b, wox, woy, woz, u1, u2):
    # the mirror reflection of wo about a GGX visible normal (Heitz 2018), anisotropic alphas
    # when the lobe is
    if b.anisotropic:
        hx, hy, hz = warp_ggx_vndf_anisotropic(u1, u2, wox, woy, woz, b.alpha_x, b.alpha_y)
    else:
        hx, hy, hz = warp_ggx_vndf(u1, u2, wox, woy, woz, b.alpha)
    return reflect_xyz(wox, woy, woz, hx, hy, hz)


@dual_use
def _pdf_ggx_visible_normals(b, c):
    # D_v(h) / (4 v.h) (Heitz 2018, eq. 17)
    if b.anisotropic:
        ph = pdf_ggx_vndf_anisotropic(c.tov, c.bov, c.nov, c.toh, c.boh, c.noh, b.alpha_x, b.alpha_y)
    else:
        ph = pdf_ggx_vndf(c.nov, c.noh, c.voh, b.alpha)
    return pdf_light_from_half(ph, c.voh)


@dual_use
def _sample_cosine(b, wox, woy, woz, u1, u2):
    return warp_cosine_hemisphere(u1, u2)


@dual_use
def _pdf_cosine(b, c):
    return pdf_cosine_hemisphere(c.nol)


#: GGX visible normals of the BxDF's alphas, reflected (Heitz 2018): the proposal of
#: every microfacet specular lobe (Beckmann and Blinn-Phong ones too, with the GGX
#: of the same alpha, which keeps the estimator unbiased).
GGX_VISIBLE_NORMALS = Technique("ggx-visible-normals", _sample_ggx_visible_normals, _pdf_ggx_visible_normals)
#: Cosine-weighted directions (Malley's method): the diffuse lobes' proposal.
COSINE = Technique("cosine", _sample_cosine, _pdf_cosine)


def ggx_normals(alpha):
    """GGX visible normals (Heitz 2018) of the isotropic width ``alpha(b)`` (a lobe of
    its own roughness, such as glTF's clear coat), reflected: sample and pdf
    D_v(h) / (4 v.h) (Heitz 2018, eq. 17)."""

    @dual_use
    def sample(b, wox, woy, woz, u1, u2):
        hx, hy, hz = warp_ggx_vndf(u1, u2, wox, woy, woz, alpha(b))
        return reflect_xyz(wox, woy, woz, hx, hy, hz)

    @dual_use
    def pdf(b, c):
        return pdf_light_from_half(pdf_ggx_vndf(c.nov, c.noh, c.voh, alpha(b)), c.voh)

    return Technique("ggx-normals", sample, pdf)


def gtr1_normals(alpha):
    """GTR1 normals (Burley 2012, App. B.2) of width ``alpha(b)``, reflected."""

    @dual_use
    def sample(b, wox, woy, woz, u1, u2):
        hx, hy, hz = warp_gtr1_ndf(u1, u2, alpha(b))
        return reflect_xyz(wox, woy, woz, hx, hy, hz)

    @dual_use
    def pdf(b, c):
        return pdf_light_from_half(pdf_gtr1_ndf(c.noh, alpha(b)), c.voh)

    return Technique("gtr1-normals", sample, pdf)


@dual_use(inline=True)
def diffuse_estimate(b, nov):
    """The albedo estimate of a diffuse lobe for sampling: luminance(base) (1 - metallic),
    the non-metallic base colour's Rec.709 luminance."""
    return rec709_luminance(b.base[0], b.base[1], b.base[2]) * (1.0 - b.metallic)


# ----------------------------------------------------------------- albedo

#: Gauss-Legendre nodes of :func:`half_vector_albedo`: per theta_h segment, in phi.
ALBEDO_NODES = (48, 32)
_XT, _WT = gauss_legendre_01(ALBEDO_NODES[0])
_XP, _WP = gauss_legendre_01(ALBEDO_NODES[1])


@dual_use
def half_vector_albedo(value, width, b, nov):
    """E(n.v) = integral of f cos over the upper hemisphere (RGB) of ``value(b, c, ec,
    w)``, by Gauss-Legendre over the half vector in the domain of
    :mod:`pbrkit.core.quadrature` (nodes uniform in s = -log(1 - u), u the GGX NDF's
    CDF of alpha = ``width(b)`` in theta_h; theta_h split at theta_a; phi up to the
    horizon bound phi_max, mirrored: the view lies in the xz plane, so f is even in
    phi for the isotropic lobes and those stretched along the tangent).  With
    dl = 4 (v.h) dh and dh = du dphi / (2 pi D(h) cos theta_h) the integrand is smooth
    and the rule converges like the lookup tables' (better than 1e-5 for microfacet
    lobes of that alpha, and for broad lobes with alpha = 1).  For the tests, the
    explorer and the layer operator; not for the per-sample loops."""
    alpha = width(b)
    mu = min(nov, 1.0)
    sin_v, cos_a, cos_b = horizon_limits(mu)
    s_a = ggx_s_of_cos(cos_a, alpha)
    s_b = ggx_s_of_cos(cos_b, alpha)
    e0 = 0.0
    e1 = 0.0
    e2 = 0.0
    for segment in range(2):
        for t in range(_XT.shape[0]):
            s, ds = split_node(segment, _XT[t], _WT[t], s_a, s_b)
            cos_h, sin_h, x = ggx_cos_of_s(s, alpha)
            if cos_h <= 0.0:
                continue
            du = ds / (1.0 + x)
            phi_max = horizon_phi_max(mu, sin_v, cos_h, sin_h)
            # dh = du dphi / (2 pi D cos_h), the phi range doubled for its mirror half
            scale = du * phi_max / (math.pi * d_ggx(cos_h, alpha) * cos_h)
            for q in range(_XP.shape[0]):
                phi = phi_max * _XP[q]
                hx = sin_h * math.cos(phi)
                hy = sin_h * math.sin(phi)
                voh = sin_v * hx + mu * cos_h
                lx = 2.0 * voh * hx - sin_v
                ly = 2.0 * voh * hy
                lz = 2.0 * voh * cos_h - mu
                if lz <= 0.0 or voh <= 0.0:
                    continue
                c = local_cosines(sin_v, 0.0, mu, lx, ly, lz)
                f = value(b, c, (1.0, 1.0, 1.0), 1.0)
                k = lz * 4.0 * voh * scale * _WP[q]
                e0 += f[0] * k
                e1 += f[1] * k
                e2 += f[2] * k
    return e0, e1, e2


@dual_use(inline=True)
def lobe_width(b):
    """The half-vector width of a microfacet lobe for :func:`half_vector_albedo`: its
    alpha (the geometric mean of the anisotropic ones)."""
    return math.sqrt(b.alpha_x * b.alpha_y)


@dual_use(inline=True)
def broad_width(b):
    """The half-vector width for broad (diffuse) lobes in :func:`half_vector_albedo`: 1."""
    return 1.0


def quadrature_albedo(value, width=broad_width):
    """A lobe's ``albedo(b, nov)`` by :func:`half_vector_albedo` of its ``value``."""

    @dual_use(inline=True, cache=False)
    def albedo(b, nov):
        return half_vector_albedo(value, width, b, nov)

    return albedo
