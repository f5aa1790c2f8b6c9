"""The GGX / Trowbridge-Reitz microfacet distribution as one unit: its D
(isotropic and anisotropic), its Smith Lambda and G1, the division-free
height-correlated visibility, and its two samplers (the distribution of
normals, Walter et al. 2007, and of visible normals, Heitz 2018) with their
pdfs (the arrangement of pbrt-v4's TrowbridgeReitzDistribution, Pharr, Jakob
and Humphreys 2023, sec. 9.6).

Arguments are cosines and sines in the shading frame: ``noh = n.h``,
``toh = t.h``, ``boh = b.h`` for the tangent ``t`` and bitangent ``b``,
``nov = n.v`` (``tov``, ``bov``) for a direction v; the samplers and their
pdfs take directions in the local frame of pbrt-v4 (:mod:`pbrkit.core.vec`:
the normal is +z, x the tangent, y the bitangent).  ``alpha`` is the width of
the distribution, *not* perceptual roughness: the public models map perceptual
roughness r to alpha = r^2 (:func:`pbrkit.microfacet.roughness.alpha_from_roughness`),
following Burley 2012 and Karis 2013; no remap is applied here.

Every term is a :func:`pbrkit.core.jit.dual_use` function (NumPy on arrays,
compiled for scalars inside Numba kernels); each warp ``warp_*(u1, u2, ...)``
returns a tuple of components and has a NumPy wrapper ``sample_*(u, ...)``
taking ``u`` of shape (..., 2) and returning (..., 3) unit vectors.
Degenerate input is guarded: for u anywhere in [0, 1]^2 (including the edges)
and any view direction, no warp returns NaN or Inf for alpha > 0 up to 1e20,
and no pdf does for alpha from :data:`pbrkit.microfacet.roughness.ALPHA_MIN`
up (D itself overflows at the peak for alpha below ~1e-8).
"""

from __future__ import annotations

import numpy as np

from ..core.jit import dual_use, select
from ..sampling.warps import _TINY, _TWO_PI, _alpha, _direction_from_cos2, _square, _stack, _vector3
from .smith import COS_MIN, _tan2, g1_smith, visible_normal_pdf

__all__ = [
    "d_ggx",
    "d_ggx_anisotropic",
    "lambda_ggx",
    "lambda_ggx_anisotropic",
    "g1_ggx",
    "v_smith_ggx_height_correlated",
    "warp_ggx_ndf",
    "warp_ggx_ndf_anisotropic",
    "warp_ggx_vndf",
    "warp_ggx_vndf_anisotropic",
    "pdf_ggx_ndf",
    "pdf_ggx_ndf_anisotropic",
    "pdf_ggx_vndf",
    "pdf_ggx_vndf_anisotropic",
    "sample_ggx_ndf",
    "sample_ggx_ndf_anisotropic",
    "sample_ggx_vndf",
    "sample_ggx_vndf_anisotropic",
]


# ------------------------------------------------------------------ D


@dual_use
def d_ggx(noh, alpha):
    """GGX / Trowbridge-Reitz distribution.

    Trowbridge & Reitz 1975; Walter et al. 2007, eq. 33:
    D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2), zero for n.h <= 0.
    """
    a2 = alpha * alpha
    c = np.minimum(noh, 1.0)
    # (n.h)^2 (alpha^2 - 1) + 1 written as alpha^2 c^2 + (1 - c)(1 + c): no cancellation
    # near the peak for small alpha.
    d = a2 * c * c + (1.0 - c) * (1.0 + c)
    return select(noh > 0.0, a2 / (np.pi * d * d), 0.0)


@dual_use
def d_ggx_anisotropic(noh, toh, boh, alpha_t, alpha_b):
    """Anisotropic GGX.

    Burley 2012, Appendix B.2, eq. 13; Heitz 2014 ("Understanding the
    Masking-Shadowing Function in Microfacet-Based BRDFs", JCGT 3(2)), eq. 85:
    D = 1 / (pi a_t a_b ((t.h / a_t)^2 + (b.h / a_b)^2 + (n.h)^2)^2).
    """
    x = toh / alpha_t
    y = boh / alpha_b
    d = x * x + y * y + noh * noh
    return select(noh > 0.0, 1.0 / (np.pi * alpha_t * alpha_b * d * d), 0.0)


# ------------------------------------------------------------------ Lambda, G1, V


@dual_use
def lambda_ggx(nov, alpha):
    """Smith Lambda for GGX: (-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2 (Heitz 2014, eq. 72)."""
    return 0.5 * (np.sqrt(1.0 + alpha * alpha * _tan2(nov)) - 1.0)


@dual_use
def lambda_ggx_anisotropic(nov, tov, bov, alpha_t, alpha_b):
    """Anisotropic GGX Lambda (Heitz 2014, eqs. 80 and 86).

    alpha_0^2 tan^2 theta = ((t.v a_t)^2 + (b.v a_b)^2) / (n.v)^2.
    """
    c = np.minimum(np.maximum(nov, COS_MIN), 1.0)
    x = tov * alpha_t
    y = bov * alpha_b
    return 0.5 * (np.sqrt(1.0 + (x * x + y * y) / (c * c)) - 1.0)


@dual_use
def g1_ggx(nov, alpha):
    """Exact Smith G1 for isotropic GGX; 0 for n.v <= 0."""
    return select(nov > 0.0, g1_smith(lambda_ggx(nov, alpha)), 0.0)


@dual_use
def v_smith_ggx_height_correlated(nol, nov, alpha):
    """Height-correlated Smith-GGX visibility in the division-free form.

    Heitz 2014 eq. 99 with eq. 72, rearranged by Lagarde & de Rousiers 2014
    ("Moving Frostbite to PBR", listing 2) and used by Filament (sec. 4.4.2):
    V = 0.5 / (n.l sqrt((n.v)^2 (1 - a^2) + a^2) + n.v sqrt((n.l)^2 (1 - a^2) + a^2)).
    Equal to visibility(g2_height_correlated(...)) but finite at grazing angles.
    """
    a2 = alpha * alpha
    cl = np.minimum(np.maximum(nol, 0.0), 1.0)
    cv = np.minimum(np.maximum(nov, 0.0), 1.0)
    lv = cl * np.sqrt(cv * cv * (1.0 - a2) + a2)
    ll = cv * np.sqrt(cl * cl * (1.0 - a2) + a2)
    return select((nol > 0.0) & (nov > 0.0), 0.5 / np.maximum(lv + ll, 1e-300), 0.0)


# ------------------------------------------------------------------ sampling


@dual_use
def warp_ggx_ndf(u1, u2, alpha):
    """Half vector h distributed as D_GGX(h) (n.h) (isotropic GGX NDF sampling).

    Walter, Marschner, Li, Torrance 2007, "Microfacet Models for Refraction
    through Rough Surfaces", eqs. 35-36: theta_h = arctan(alpha sqrt(u1) / sqrt(1 - u1)),
    phi_h = 2 pi u2; written as cos^2 theta_h = (1 - u1) / (1 + (alpha^2 - 1) u1)
    and sin^2 theta_h = alpha^2 u1 / (1 + (alpha^2 - 1) u1), finite for u1 in [0, 1]
    (the denominator is summed as (1 - u1) + alpha^2 u1, free of cancellation).
    alpha is the GGX width (alpha = r^2 in the public models).  pdf: :func:`pdf_ggx_ndf`.
    """
    a2 = alpha * alpha
    denominator = np.maximum((1.0 - u1) + a2 * u1, _TINY)
    return _direction_from_cos2((1.0 - u1) / denominator, a2 * u1 / denominator, u2)


@dual_use
def warp_ggx_ndf_anisotropic(u1, u2, alpha_x, alpha_y):
    """Half vector h distributed as D_GGX,aniso(h) (n.h), alpha_x along the tangent x.

    Heitz 2014 ("Understanding the Masking-Shadowing Function in Microfacet-Based
    BRDFs", JCGT 3(2)), sec. 5: the anisotropic distribution is the alpha = 1
    distribution with its slopes stretched by (alpha_x, alpha_y).  GGX with
    alpha = 1 has D cos = cos / pi, so h' is drawn with sin^2 theta' = u1,
    phi' = 2 pi u2 (Walter et al. 2007, eqs. 35-36 at alpha = 1) and
    h = normalize(alpha_x h'_x, alpha_y h'_y, h'_z).  Equals :func:`warp_ggx_ndf`
    for alpha_x = alpha_y, and the same distribution as pbrt-v3's
    phi = atan(alpha_y / alpha_x tan(2 pi u2)) construction.
    pdf: :func:`pdf_ggx_ndf_anisotropic`.
    """
    sx, sy, sz = _direction_from_cos2(1.0 - u1, u1, u2)
    x = alpha_x * sx
    y = alpha_y * sy
    inv_length = 1.0 / np.sqrt(np.maximum(x * x + y * y + sz * sz, _TINY))
    return x * inv_length, y * inv_length, sz * inv_length


@dual_use
def warp_ggx_vndf_anisotropic(u1, u2, wox, woy, woz, alpha_x, alpha_y):
    """Half vector h distributed as the GGX distribution of visible normals D_wo(h).

    Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4):
    stretch the view to the alpha = 1 configuration,
    V_h = normalize(alpha_x wo_x, alpha_y wo_y, wo_z); build the frame
    (T1, T2, V_h) with T1 = normalize(-V_h.y, V_h.x, 0) (or +x when V_h = +z);
    sample the projected hemisphere as a disk point (t1, t2) = sqrt(u1)(cos, sin)(2 pi u2)
    whose t2 is warped over the visible half-disk with s = (1 + V_h.z) / 2,
    t2 <- (1 - s) sqrt(1 - t1^2) + s t2; lift to N_h = t1 T1 + t2 T2 +
    sqrt(1 - t1^2 - t2^2) V_h and unstretch, h = normalize(alpha_x N_h.x,
    alpha_y N_h.y, max(0, N_h.z)).  ``wo`` (the view, surface to eye) should
    be unit length with wo.z > 0; a view below the surface is mirrored to
    -wo first, as pbrt-v4 does.  pdf: :func:`pdf_ggx_vndf_anisotropic`.
    """
    sign = select(woz < 0.0, -1.0, 1.0)
    vx = alpha_x * wox * sign
    vy = alpha_y * woy * sign
    vz = woz * sign
    inv_v = 1.0 / np.sqrt(np.maximum(vx * vx + vy * vy + vz * vz, _TINY))
    vx = vx * inv_v
    vy = vy * inv_v
    vz = vz * inv_v
    lensq = vx * vx + vy * vy
    tilted = lensq > 0.0
    inv_len = 1.0 / np.sqrt(select(tilted, lensq, 1.0))
    t1x = select(tilted, -vy * inv_len, 1.0)
    t1y = select(tilted, vx * inv_len, 0.0)
    # T2 = V_h x T1 (T1 has no z component)
    t2x = -vz * t1y
    t2y = vz * t1x
    t2z = vx * t1y - vy * t1x
    r = np.sqrt(np.maximum(u1, 0.0))
    phi = _TWO_PI * u2
    p1 = r * np.cos(phi)
    p2 = r * np.sin(phi)
    s = 0.5 * (1.0 + vz)
    p2 = (1.0 - s) * np.sqrt(np.maximum(1.0 - p1 * p1, 0.0)) + s * p2
    p3 = np.sqrt(np.maximum(1.0 - p1 * p1 - p2 * p2, 0.0))
    nx = p1 * t1x + p2 * t2x + p3 * vx
    ny = p1 * t1y + p2 * t2y + p3 * vy
    nz = p2 * t2z + p3 * vz
    hx = alpha_x * nx
    hy = alpha_y * ny
    hz = np.maximum(nz, 0.0)
    inv_h = 1.0 / np.sqrt(np.maximum(hx * hx + hy * hy + hz * hz, _TINY))
    return hx * inv_h, hy * inv_h, hz * inv_h


@dual_use
def warp_ggx_vndf(u1, u2, wox, woy, woz, alpha):
    """Isotropic GGX visible-normal sampling: :func:`warp_ggx_vndf_anisotropic` with
    alpha_x = alpha_y = alpha (Heitz 2018).  pdf: :func:`pdf_ggx_vndf`."""
    return warp_ggx_vndf_anisotropic(u1, u2, wox, woy, woz, alpha, alpha)


# ------------------------------------------------------------------ pdfs (solid angle of h)


@dual_use
def pdf_ggx_ndf(noh, alpha):
    """pdf of :func:`warp_ggx_ndf` w.r.t. the solid angle of h: D_GGX(h) (n.h)
    (Walter et al. 2007, eq. 24 with the D of eq. 33, :func:`d_ggx`)."""
    return d_ggx(noh, alpha) * np.maximum(noh, 0.0)


@dual_use
def pdf_ggx_ndf_anisotropic(hx, hy, hz, alpha_x, alpha_y):
    """pdf of :func:`warp_ggx_ndf_anisotropic`: D_GGX,aniso(h) (n.h) for h = (hx, hy, hz)
    in the local frame (:func:`d_ggx_anisotropic`, Heitz 2014 eq. 85)."""
    return d_ggx_anisotropic(hz, hx, hy, alpha_x, alpha_y) * np.maximum(hz, 0.0)


@dual_use
def pdf_ggx_vndf_anisotropic(wox, woy, woz, hx, hy, hz, alpha_x, alpha_y):
    """pdf of :func:`warp_ggx_vndf_anisotropic` w.r.t. the solid angle of h.

    The distribution of visible normals (Heitz & d'Eon 2014, "Importance
    Sampling Microfacet-Based BSDFs using the Distribution of Visible Normals",
    EGSR 2014; Heitz 2018, eq. 3): D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z with the
    exact Smith G1 = 1 / (1 + Lambda(wo)) of :func:`lambda_ggx_anisotropic` and
    D of :func:`d_ggx_anisotropic`.  A view with wo.z < 0 is
    mirrored to -wo, matching the sampler.  wo.z is clamped at 1e-8 (the clamp
    Lambda uses), so a grazing view gives the finite limit.
    """
    sign = select(woz < 0.0, -1.0, 1.0)
    vx = wox * sign
    vy = woy * sign
    vz = woz * sign
    voh = vx * hx + vy * hy + vz * hz
    return visible_normal_pdf(lambda_ggx_anisotropic(vz, vx, vy, alpha_x, alpha_y), voh,
                              d_ggx_anisotropic(hz, hx, hy, alpha_x, alpha_y), vz)


@dual_use
def pdf_ggx_vndf(nov, noh, voh, alpha):
    """pdf of :func:`warp_ggx_vndf`: D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z
    (Heitz 2018, eq. 3) with the exact isotropic Smith G1 (Lambda of
    :func:`lambda_ggx`, Heitz 2014 eq. 72) and :func:`d_ggx`.  Arguments are
    n.wo, n.h and wo.h; a view below the surface (n.wo < 0) is mirrored,
    matching the sampler."""
    flip = nov < 0.0
    c = np.abs(nov)
    vh = select(flip, -voh, voh)
    return visible_normal_pdf(lambda_ggx(c, alpha), vh, d_ggx(noh, alpha), c)


# ------------------------------------------------------------------ NumPy wrappers


def sample_ggx_ndf(u, alpha):
    """GGX half vectors with pdf D (n.h) (:func:`warp_ggx_ndf`); alpha broadcasts against u[..., 0]."""
    u1, u2 = _square(u)
    return _stack(*warp_ggx_ndf(u1, u2, _alpha(alpha)))


def sample_ggx_ndf_anisotropic(u, alpha_x, alpha_y):
    """Anisotropic GGX half vectors with pdf D (n.h) (:func:`warp_ggx_ndf_anisotropic`)."""
    u1, u2 = _square(u)
    return _stack(*warp_ggx_ndf_anisotropic(u1, u2, _alpha(alpha_x, "alpha_x"), _alpha(alpha_y, "alpha_y")))


def sample_ggx_vndf(u, wo, alpha):
    """GGX visible normals for the local view ``wo`` (..., 3) (:func:`warp_ggx_vndf`, Heitz 2018)."""
    u1, u2 = _square(u)
    return _stack(*warp_ggx_vndf(u1, u2, *_vector3(wo, "wo"), _alpha(alpha)))


def sample_ggx_vndf_anisotropic(u, wo, alpha_x, alpha_y):
    """Anisotropic GGX visible normals for the local view ``wo`` (:func:`warp_ggx_vndf_anisotropic`)."""
    u1, u2 = _square(u)
    return _stack(*warp_ggx_vndf_anisotropic(u1, u2, *_vector3(wo, "wo"), _alpha(alpha_x, "alpha_x"),
                                             _alpha(alpha_y, "alpha_y")))
