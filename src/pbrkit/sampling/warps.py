"""Warps** from the unit square u = (u1, u2) in [0, 1]^2 to directions, each
  with the solid-angle pdf of the direction it returns.  Directions are in the
  local shading frame of pbrt-v4 (:mod:`pbrkit.core.vec`): the normal is +z, x is
  the tangent and y the bitangent.

Every warp exists as a :func:`pbrkit.core.jit.dual_use` core ``warp_*(u1, u2, ...)``
that takes scalars or arrays and returns a tuple of components (usable inside
Numba kernels), and as a thin NumPy wrapper ``sample_*(u, ...)`` taking ``u``
of shape (..., 2) and returning (..., 3) unit vectors (``(..., 2)`` for the
disk).  Each ``pdf_*`` is a term too, with the arguments named in its
docstring (cosines, or components for anisotropic lobes).

Roughness: every microfacet warp takes the distribution's alpha, *not*
perceptual roughness; map r to alpha with
:func:`pbrkit.brdf.distributions.alpha_from_roughness` (alpha = r^2) or the model's
own remap.  No remap is applied here.  The pdfs are built from the D and Lambda
terms of :mod:`pbrkit.brdf.distributions` and :mod:`pbrkit.brdf.masking`.

Degenerate input is guarded: for u anywhere in [0, 1]^2 (including the edges)
and any view direction, no warp returns NaN or Inf for alpha > 0 up to 1e20,
and no pdf does for alpha from ``pbrkit.brdf.distributions.ALPHA_MIN`` up (the D
terms themselves overflow at the peak for alpha below ~1e-8).
"""

from __future__ import annotations

import numpy as np

from ..brdf.distributions import d_beckmann, d_ggx, d_ggx_anisotropic, d_gtr1
from ..brdf.masking import COS_MIN, g1_smith, lambda_ggx, lambda_ggx_anisotropic
from ..core import checks
from ..core.jit import dual_use, select

__all__ = [
    "ONE_MINUS_EPSILON",
    "unit_square",
    "warp_uniform_sphere",
    "warp_uniform_hemisphere",
    "warp_concentric_disk",
    "warp_cosine_hemisphere",
    "warp_ggx_ndf",
    "warp_ggx_ndf_anisotropic",
    "warp_ggx_vndf",
    "warp_ggx_vndf_anisotropic",
    "warp_beckmann_ndf",
    "warp_gtr1_ndf",
    "reflect_xyz",
    "pdf_uniform_sphere",
    "pdf_uniform_hemisphere",
    "pdf_concentric_disk",
    "pdf_cosine_hemisphere",
    "pdf_ggx_ndf",
    "pdf_ggx_ndf_anisotropic",
    "pdf_ggx_vndf",
    "pdf_ggx_vndf_anisotropic",
    "pdf_beckmann_ndf",
    "pdf_gtr1_ndf",
    "half_to_light_jacobian",
    "pdf_light_from_half",
    "sample_uniform_sphere",
    "sample_uniform_hemisphere",
    "sample_concentric_disk",
    "sample_cosine_hemisphere",
    "sample_ggx_ndf",
    "sample_ggx_ndf_anisotropic",
    "sample_ggx_vndf",
    "sample_ggx_vndf_anisotropic",
    "sample_beckmann_ndf",
    "sample_gtr1_ndf",
    "reflect",
]

_PI = np.pi
_TWO_PI = 2.0 * np.pi
_INV_PI = 1.0 / np.pi
_INV_TWO_PI = 0.5 / np.pi
_INV_FOUR_PI = 0.25 / np.pi
_PI_OVER_4 = 0.25 * np.pi
_PI_OVER_2 = 0.5 * np.pi
#: The largest float64 below 1 (pbrt's OneMinusEpsilon): radical inverses stay in [0, 1).
ONE_MINUS_EPSILON = 1.0 - 2.0**-53
_TINY = 1e-300


# =========================================================================
# Warp terms (dual-use: NumPy arrays or Numba scalars)
# =========================================================================


@dual_use
def warp_uniform_sphere(u1, u2):
    """Uniform direction on the unit sphere: z = 1 - 2 u1, phi = 2 pi u2.

    Archimedes' hat-box theorem; pbrt-v4 sec. A.5.2 (SampleUniformSphere).
    sin theta is written 2 sqrt(u1 (1 - u1)) = sqrt(1 - z^2) for accuracy at
    the poles.  pdf 1 / (4 pi) (:func:`pdf_uniform_sphere`).
    """
    z = 1.0 - 2.0 * u1
    r = 2.0 * np.sqrt(np.maximum(u1 * (1.0 - u1), 0.0))
    phi = _TWO_PI * u2
    return r * np.cos(phi), r * np.sin(phi), z


@dual_use
def warp_uniform_hemisphere(u1, u2):
    """Uniform direction on the upper (z >= 0) hemisphere: z = u1, phi = 2 pi u2.

    pbrt-v4 sec. A.5.2 (SampleUniformHemisphere).  pdf 1 / (2 pi).
    """
    z = np.minimum(np.maximum(u1, 0.0), 1.0)
    r = np.sqrt(np.maximum((1.0 - z) * (1.0 + z), 0.0))
    phi = _TWO_PI * u2
    return r * np.cos(phi), r * np.sin(phi), z


@dual_use
def warp_concentric_disk(u1, u2):
    """Shirley & Chiu's concentric map from the square to the unit disk, returns (x, y).

    Shirley & Chiu 1997, "A Low Distortion Map Between Disk and Square",
    JGT 2(3): with (a, b) = 2u - 1, concentric squares go to concentric
    circles; r = a, theta = (pi / 4)(b / a) where |a| > |b|, else r = b,
    theta = pi / 2 - (pi / 4)(a / b).  Area-preserving, so the points are
    uniform on the disk (pdf 1 / pi per unit area).  The centre maps to (0, 0).
    """
    a = 2.0 * u1 - 1.0
    b = 2.0 * u2 - 1.0
    use_a = np.abs(a) > np.abs(b)
    r = select(use_a, a, b)
    b_over_a = b / select(use_a, a, 1.0)
    a_over_b = a / select(use_a | (b == 0.0), 1.0, b)
    theta = select(use_a, _PI_OVER_4 * b_over_a, _PI_OVER_2 - _PI_OVER_4 * a_over_b)
    return r * np.cos(theta), r * np.sin(theta)


@dual_use
def warp_cosine_hemisphere(u1, u2):
    """Cosine-weighted direction on the upper hemisphere by Malley's method.

    Malley 1988: a uniform point (x, y) on the unit disk (here the concentric
    map of :func:`warp_concentric_disk`) projected up to the hemisphere,
    z = sqrt(1 - x^2 - y^2), has pdf cos theta / pi.  pbrt-v4 sec. A.5.3
    (SampleCosineHemisphere).
    """
    x, y = warp_concentric_disk(u1, u2)
    z = np.sqrt(np.maximum(1.0 - x * x - y * y, 0.0))
    return x, y, z


@dual_use
def _direction_from_cos2(cos2, sin2, u2):
    """Unit vector with cos^2 theta = cos2, sin^2 theta = sin2 (cos2 + sin2 = 1) and phi = 2 pi u2."""
    cos_theta = np.sqrt(np.maximum(cos2, 0.0))
    sin_theta = np.sqrt(np.maximum(sin2, 0.0))
    phi = _TWO_PI * u2
    return sin_theta * np.cos(phi), sin_theta * np.sin(phi), cos_theta


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


@dual_use
def warp_beckmann_ndf(u1, u2, alpha):
    """Half vector h distributed as D_Beckmann(h) (n.h).

    Walter et al. 2007, eqs. 28-29: theta_h = arctan sqrt(-alpha^2 ln(1 - u1)),
    phi_h = 2 pi u2 (u1 is clamped to 1 - 2^-53 so u1 = 1 stays finite).
    alpha is the Beckmann width (rms slope / sqrt 2 convention of Walter).
    pdf: :func:`pdf_beckmann_ndf`.
    """
    u = np.minimum(u1, ONE_MINUS_EPSILON)
    tan2 = -alpha * alpha * np.log1p(-u)
    inv = 1.0 / (1.0 + tan2)
    return _direction_from_cos2(inv, tan2 * inv, u2)


@dual_use
def warp_gtr1_ndf(u1, u2, alpha):
    """Half vector h distributed as D_GTR1(h) (n.h) (Berry's distribution, Disney clear coat).

    Burley 2012, "Physically-Based Shading at Disney", Appendix B.2:
    cos^2 theta_h = (1 - alpha^(2 (1 - u1))) / (1 - alpha^2), phi_h = 2 pi u2,
    evaluated with L = ln alpha^2 as cos^2 = expm1((1 - u1) L) / expm1(L) and
    sin^2 = exp((1 - u1) L) expm1(u1 L) / expm1(L); at alpha = 1 (L = 0) the limit
    cos^2 = 1 - u1.  The Disney clear coat uses alpha = lerp(0.1, 0.001, gloss),
    not r^2.  pdf: :func:`pdf_gtr1_ndf`.
    """
    big_l = np.log(alpha * alpha)
    l_ok = np.abs(big_l) > 1e-12
    safe_l = select(l_ok, big_l, 1.0)
    denominator = np.expm1(safe_l)
    cos2 = select(l_ok, np.expm1((1.0 - u1) * safe_l) / denominator, 1.0 - u1)
    sin2 = select(l_ok, np.exp((1.0 - u1) * safe_l) * np.expm1(u1 * safe_l) / denominator, u1)
    return _direction_from_cos2(cos2, sin2, u2)


@dual_use
def reflect_xyz(wox, woy, woz, hx, hy, hz):
    """Mirror reflection of wo about h, l = 2 (wo.h) h - wo (Walter et al. 2007, eq. 39);
    returns (x, y, z).  For unit wo and h the result is unit length."""
    two_voh = 2.0 * (wox * hx + woy * hy + woz * hz)
    return two_voh * hx - wox, two_voh * hy - woy, two_voh * hz - woz


# =========================================================================
# pdf terms (solid-angle densities of the sampled direction)
# =========================================================================


@dual_use
def pdf_uniform_sphere(cos_theta):
    """pdf of :func:`warp_uniform_sphere`: 1 / (4 pi) everywhere (``cos_theta`` only sets the shape)."""
    return 0.0 * cos_theta + _INV_FOUR_PI


@dual_use
def pdf_uniform_hemisphere(cos_theta):
    """pdf of :func:`warp_uniform_hemisphere`: 1 / (2 pi) for cos theta >= 0, else 0."""
    return select(cos_theta >= 0.0, _INV_TWO_PI, 0.0)


@dual_use
def pdf_concentric_disk(x, y):
    """pdf of :func:`warp_concentric_disk` per unit area: 1 / pi inside the unit disk, else 0."""
    return select(x * x + y * y <= 1.0, _INV_PI, 0.0)


@dual_use
def pdf_cosine_hemisphere(cos_theta):
    """pdf of :func:`warp_cosine_hemisphere`: max(cos theta, 0) / pi (Malley's method)."""
    return np.maximum(cos_theta, 0.0) * _INV_PI


@dual_use
def pdf_ggx_ndf(noh, alpha):
    """pdf of :func:`warp_ggx_ndf` w.r.t. the solid angle of h: D_GGX(h) (n.h)
    (Walter et al. 2007, eq. 24 with the D of eq. 33, :func:`pbrkit.brdf.distributions.d_ggx`)."""
    return d_ggx(noh, alpha) * np.maximum(noh, 0.0)


@dual_use
def pdf_ggx_ndf_anisotropic(hx, hy, hz, alpha_x, alpha_y):
    """pdf of :func:`warp_ggx_ndf_anisotropic`: D_GGX,aniso(h) (n.h) for h = (hx, hy, hz)
    in the local frame (:func:`pbrkit.brdf.distributions.d_ggx_anisotropic`, Heitz 2014 eq. 85)."""
    return d_ggx_anisotropic(hz, hx, hy, alpha_x, alpha_y) * np.maximum(hz, 0.0)


@dual_use
def pdf_ggx_vndf_anisotropic(wox, woy, woz, hx, hy, hz, alpha_x, alpha_y):
    """pdf of :func:`warp_ggx_vndf_anisotropic` w.r.t. the solid angle of h.

    The distribution of visible normals (Heitz & d'Eon 2014, "Importance
    Sampling Microfacet-Based BSDFs using the Distribution of Visible Normals",
    EGSR 2014; Heitz 2018, eq. 3): D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z with the
    exact Smith G1 = 1 / (1 + Lambda(wo)) of
    :func:`pbrkit.brdf.masking.lambda_ggx_anisotropic` and D of
    :func:`pbrkit.brdf.distributions.d_ggx_anisotropic`.  A view with wo.z < 0 is
    mirrored to -wo, matching the sampler.  wo.z is clamped at 1e-8 (the clamp
    Lambda uses), so a grazing view gives the finite limit.
    """
    sign = select(woz < 0.0, -1.0, 1.0)
    vx = wox * sign
    vy = woy * sign
    vz = woz * sign
    voh = vx * hx + vy * hy + vz * hz
    g1 = g1_smith(lambda_ggx_anisotropic(vz, vx, vy, alpha_x, alpha_y))
    d = d_ggx_anisotropic(hz, hx, hy, alpha_x, alpha_y)
    return g1 * np.maximum(voh, 0.0) * d / np.maximum(vz, COS_MIN)


@dual_use
def pdf_ggx_vndf(nov, noh, voh, alpha):
    """pdf of :func:`warp_ggx_vndf`: D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z
    (Heitz 2018, eq. 3) with the exact isotropic Smith G1 (Lambda of
    :func:`pbrkit.brdf.masking.lambda_ggx`, Heitz 2014 eq. 72) and
    :func:`pbrkit.brdf.distributions.d_ggx`.  Arguments are n.wo, n.h and wo.h; a view
    below the surface (n.wo < 0) is mirrored, matching the sampler."""
    flip = nov < 0.0
    c = np.abs(nov)
    vh = select(flip, -voh, voh)
    g1 = g1_smith(lambda_ggx(c, alpha))
    return g1 * np.maximum(vh, 0.0) * d_ggx(noh, alpha) / np.maximum(c, COS_MIN)


@dual_use
def pdf_beckmann_ndf(noh, alpha):
    """pdf of :func:`warp_beckmann_ndf`: D_Beckmann(h) (n.h) (Walter et al. 2007, eqs. 24-25,
    :func:`pbrkit.brdf.distributions.d_beckmann`)."""
    return d_beckmann(noh, alpha) * np.maximum(noh, 0.0)


@dual_use
def pdf_gtr1_ndf(noh, alpha):
    """pdf of :func:`warp_gtr1_ndf`: D_GTR1(h) (n.h) (Burley 2012, Appendix B.2,
    :func:`pbrkit.brdf.distributions.d_gtr1`)."""
    return d_gtr1(noh, alpha) * np.maximum(noh, 0.0)


@dual_use
def half_to_light_jacobian(voh):
    """|d omega_h / d omega_l| = 1 / (4 v.h) for mirror reflection l = reflect(v, h)
    (Walter et al. 2007, eq. 14; Torrance & Sparrow 1967).  0 for v.h <= 0, where
    h is not the half vector of any reflection of v."""
    return select(voh > 0.0, 0.25 / np.maximum(voh, _TINY), 0.0)


@dual_use
def pdf_light_from_half(pdf_h, voh):
    """Solid-angle pdf of l = reflect(v, h) from the pdf of h: pdf_h / (4 v.h)
    (:func:`half_to_light_jacobian`; Walter et al. 2007, eq. 14).  With the VNDF
    pdf this is G1(v) D(h) / (4 n.v) (Heitz 2018, eq. 17)."""
    return pdf_h * half_to_light_jacobian(voh)


# =========================================================================
# NumPy wrappers
# =========================================================================


def unit_square(u):
    """``u`` as float64 (..., 2) points of the unit square [0, 1]^2, or ValueError."""
    u = np.asarray(u, dtype=np.float64)
    if u.ndim == 0 or u.shape[-1] != 2:
        raise ValueError(f"u must have 2 components (u1, u2) in its last axis; got shape {u.shape}")
    if not np.all((u >= 0.0) & (u <= 1.0)):
        raise ValueError("u must lie in the unit square [0, 1]^2 (and be finite)")
    return u


def _square(u):
    u = unit_square(u)
    return u[..., 0], u[..., 1]


def _alpha(alpha, name="alpha"):
    a = np.asarray(alpha, dtype=np.float64)
    if not np.all(np.isfinite(a) & (a > 0.0)):
        raise ValueError(f"{name} must be positive and finite")
    return a


def _vector3(w, name):
    w, _ = checks.direction_lengths(w, name)
    return w[..., 0], w[..., 1], w[..., 2]


def _stack(*components):
    return np.stack(np.broadcast_arrays(*components), axis=-1)


def sample_uniform_sphere(u):
    """Uniform directions on the sphere, (..., 2) -> (..., 3) (:func:`warp_uniform_sphere`)."""
    return _stack(*warp_uniform_sphere(*_square(u)))


def sample_uniform_hemisphere(u):
    """Uniform directions on the z >= 0 hemisphere (:func:`warp_uniform_hemisphere`)."""
    return _stack(*warp_uniform_hemisphere(*_square(u)))


def sample_concentric_disk(u):
    """Uniform points on the unit disk, (..., 2) -> (..., 2) (:func:`warp_concentric_disk`)."""
    return _stack(*warp_concentric_disk(*_square(u)))


def sample_cosine_hemisphere(u):
    """Cosine-weighted directions on the z >= 0 hemisphere (:func:`warp_cosine_hemisphere`)."""
    return _stack(*warp_cosine_hemisphere(*_square(u)))


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


def sample_beckmann_ndf(u, alpha):
    """Beckmann half vectors with pdf D (n.h) (:func:`warp_beckmann_ndf`)."""
    u1, u2 = _square(u)
    return _stack(*warp_beckmann_ndf(u1, u2, _alpha(alpha)))


def sample_gtr1_ndf(u, alpha):
    """GTR1 (Berry) half vectors with pdf D (n.h) (:func:`warp_gtr1_ndf`)."""
    u1, u2 = _square(u)
    return _stack(*warp_gtr1_ndf(u1, u2, _alpha(alpha)))


def reflect(wo, h):
    """l = 2 (wo.h) h - wo over the last axis (:func:`reflect_xyz`), shape (..., 3)."""
    return _stack(*reflect_xyz(*_vector3(wo, "wo"), *_vector3(h, "h")))

