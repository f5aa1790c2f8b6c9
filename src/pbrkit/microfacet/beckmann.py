"""The Beckmann microfacet distribution as one unit: its D (isotropic and
anisotropic), its exact Smith Lambda and G1, the sampling of its distribution
of normals (Walter et al. 2007) and of its distribution of visible normals
(Heitz & d'Eon 2014), each with its pdf.

Arguments are cosines and sines in the shading frame (``noh = n.h``,
``toh = t.h``, ``boh = b.h``, ``nov = n.v``, ``tov``, ``bov``); the samplers
and their pdfs take directions in the local frame (normal +z, tangent +x).
``alpha`` is the Beckmann width (the rms slope / sqrt 2 convention of Walter
et al. 2007), *not* perceptual roughness: the public models map perceptual
roughness r to alpha = r^2 (:func:`pbrkit.microfacet.roughness.alpha_from_roughness`),
following Burley 2012 and Karis 2013; no remap is applied here.

Every term is a :func:`pbrkit.core.jit.dual_use` function (NumPy on arrays,
compiled for scalars inside Numba kernels); each warp returns components and
has a NumPy wrapper ``sample_*(u, ...)``.  For u anywhere in [0, 1]^2
(including the edges) and any view, no warp returns NaN or Inf for alpha > 0
up to 1e20, and no pdf does for alpha from
:data:`pbrkit.microfacet.roughness.ALPHA_MIN` up.

The models do not sample Beckmann lobes with the visible-normal sampler here
(they use the GGX proposal of the same alpha, :mod:`pbrkit.brdf.bxdf`); it is
a capability of the unit, tested against its pdf.
"""

from __future__ import annotations

import math

import numpy as np
from numba import types
from numba.extending import overload

from ..core.jit import dual_use, select
from ..sampling.warps import (
    _TINY,
    ONE_MINUS_EPSILON,
    _alpha,
    _direction_from_cos2,
    _square,
    _stack,
    _vector3,
)
from .smith import COS_MIN, _tan2, erf, g1_smith, visible_normal_pdf

__all__ = [
    "d_beckmann",
    "d_beckmann_anisotropic",
    "lambda_beckmann",
    "lambda_beckmann_anisotropic",
    "g1_beckmann",
    "warp_beckmann_ndf",
    "warp_beckmann_vndf",
    "warp_beckmann_vndf_anisotropic",
    "pdf_beckmann_ndf",
    "pdf_beckmann_vndf",
    "pdf_beckmann_vndf_anisotropic",
    "sample_beckmann_ndf",
    "sample_beckmann_vndf",
    "sample_beckmann_vndf_anisotropic",
]

_INV_SQRT_PI = 1.0 / math.sqrt(math.pi)


# ------------------------------------------------------------------ D


@dual_use
def d_beckmann(noh, alpha):
    """Beckmann distribution.

    Beckmann & Spizzichino 1963; Walter et al. 2007, eq. 25:
    D = exp(-tan^2 theta_h / alpha^2) / (pi alpha^2 cos^4 theta_h).
    """
    c = np.minimum(np.maximum(noh, 1e-8), 1.0)
    c2 = c * c
    a2 = alpha * alpha
    value = np.exp((c2 - 1.0) / (a2 * c2)) / (np.pi * a2 * c2 * c2)
    return select(noh > 0.0, value, 0.0)


@dual_use
def d_beckmann_anisotropic(noh, toh, boh, alpha_t, alpha_b):
    """Anisotropic Beckmann.

    Heitz 2014, eq. 84 (after Ward 1992):
    D = exp(-((t.h / a_t)^2 + (b.h / a_b)^2) / (n.h)^2) / (pi a_t a_b (n.h)^4).
    """
    c = np.minimum(np.maximum(noh, 1e-8), 1.0)
    c2 = c * c
    x = toh / alpha_t
    y = boh / alpha_b
    value = np.exp(-(x * x + y * y) / c2) / (np.pi * alpha_t * alpha_b * c2 * c2)
    return select(noh > 0.0, value, 0.0)


# ------------------------------------------------------------------ Lambda, G1


@dual_use
def _lambda_beckmann_of_a(a):
    # Heitz 2014, eq. 83: Lambda(a) = (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi)).
    return 0.5 * (erf(a) - 1.0) + np.exp(-a * a) / (2.0 * a * np.sqrt(np.pi))


@dual_use
def lambda_beckmann(nov, alpha):
    """Smith Lambda for Beckmann, exact form with erf (Heitz 2014, eq. 83), a = 1 / (alpha tan theta)."""
    tan_theta = np.sqrt(_tan2(nov))
    a = 1.0 / np.maximum(alpha * tan_theta, 1e-300)
    return select(a > 30.0, 0.0, _lambda_beckmann_of_a(np.minimum(a, 30.0)))


@dual_use
def lambda_beckmann_anisotropic(nov, tov, bov, alpha_t, alpha_b):
    """Anisotropic Beckmann Lambda (Heitz 2014, eqs. 83 and 86)."""
    c = np.minimum(np.maximum(nov, COS_MIN), 1.0)
    x = tov * alpha_t
    y = bov * alpha_b
    a = c / np.maximum(np.sqrt(x * x + y * y), 1e-300)
    return select(a > 30.0, 0.0, _lambda_beckmann_of_a(np.minimum(a, 30.0)))


@dual_use
def g1_beckmann(nov, alpha):
    """Exact Smith G1 for isotropic Beckmann; 0 for n.v <= 0."""
    return select(nov > 0.0, g1_smith(lambda_beckmann(nov, alpha)), 0.0)


# ------------------------------------------------------------------ the complementary error function


def _erfc(x):
    """Complementary error function 1 - erf(x), without its cancellation: SciPy's
    ``scipy.special.erfc`` on arrays from Python (imported on first use), ``math.erfc``
    on scalars inside Numba kernels (the overload below), as :func:`pbrkit.microfacet.smith.erf`."""
    from scipy.special import erfc as _scipy_erfc

    return _scipy_erfc(x)


@overload(_erfc)
def _erfc_numba(x):
    if isinstance(x, types.Float):
        return lambda x: math.erfc(x)
    return None


# ------------------------------------------------------------------ sampling


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


#: Newton steps of the visible-slope inversion, each over every sample: from the
#: starting bounds the cdf is met to 1e-13 of u for u <= 1/2 and to 1e-16 absolute
#: above after 8, at every view measured (against 40-digit inversions).
_VNDF_STEPS = 8
#: u is kept in [_U_LOW, 1 - _U_HIGH]: the slopes' cut-off tails hold a probability
#: of 1e-250 below (|slope| < 24) and 1e-14 at the top, where the visible slopes end
#: at cot theta with a density that vanishes there.
_U_LOW = 1e-250
_U_HIGH = 1e-14
#: cot theta beyond which erfc(cot) < 1e-295 and exp(-cot^2) / sqrt(pi) < 1e-293.
_COT_MAX = 26.0


@dual_use
def _visible_slope_x(u, cos_theta, sin_theta):
    """The slope x~ along the view's azimuth of a visible normal of the alpha = 1
    Beckmann surface, by inversion of its cdf at u, for a view at polar angle
    theta in [0, pi/2] given by (cos theta, sin theta).

    Heitz & d'Eon 2014 (the x~ marginal that pbrt-v3's BeckmannSample11 also
    inverts): the visible slopes have the density proportional to
    (cos theta - x~ sin theta) exp(-x~^2 - y~^2) for x~ <= cot theta, so x~ has
    the mass N(x) = cos theta erfc(-x) + sin theta exp(-x^2) / sqrt(pi) below x
    and R(x) = Z - N(x) = cos theta (erfc(x) - erfc(cot theta)) +
    sin theta exp(-x^2) expm1(x^2 - cot^2 theta) / sqrt(pi) above it, with
    Z = N(cot theta) = 2 cos theta (1 + Lambda) (each written with sin theta as a
    factor, so that it holds from normal incidence to the horizon, and without
    the cancellation of 1 - erf).  Both are log-concave (the density is), so
    Newton's method on log N(x) = log(u Z) from a point left of the root rises
    to it monotonically, and on log R(x) = log((1 - u) Z) from a point right of
    it falls to it; the first is used for u <= 1/2, the second above, each
    started from a closed-form bound: N(x) <= N(0) exp(-x^2) for x <= 0, and
    R(x) <= sin theta d^2 / sqrt(pi) (d = cot theta - x) or
    R(x) <= cos theta exp(-x^2) for x >= 0.  (pbrt-v3 iterates in erf(x~)
    instead, with a bisection fallback; in float64 the forms here keep the
    relative precision of u in the lower tail.)
    """
    cot = np.minimum(cos_theta / np.maximum(sin_theta, _TINY), _COT_MAX)
    erfc_cot = _erfc(cot)
    z = cos_theta * (2.0 - erfc_cot) + sin_theta * np.exp(-cot * cot) * _INV_SQRT_PI
    upper = u > 0.5
    q = select(upper, np.maximum(1.0 - u, _U_HIGH), np.maximum(u, _U_LOW)) * z
    # starting points: left of the root for the lower form, right of it for the upper one
    x_lower = -np.sqrt(np.maximum(np.log((cos_theta + sin_theta * _INV_SQRT_PI) / q), 0.0))
    exact_cot = cos_theta < _COT_MAX * sin_theta  # cot theta not clamped: R <= sin d^2 / sqrt(pi) holds
    x_a = select(exact_cot, cot - np.sqrt(q / (_INV_SQRT_PI * np.maximum(sin_theta, _TINY))), np.inf)
    x_b = np.sqrt(np.maximum(np.log(np.maximum(cos_theta, _TINY) / q), 0.0))
    x = select(upper, np.minimum(np.minimum(x_a, x_b), cot), x_lower)
    side = select(upper, -1.0, 1.0)
    log_q = np.log(q)
    for _ in range(_VNDF_STEPS):  # a fixed number of steps, each over every sample
        e = np.exp(-x * x) * _INV_SQRT_PI
        density = 2.0 * (cos_theta - x * sin_theta) * e  # dN/dx = -dR/dx
        tail = _erfc(np.abs(x))  # erfc(-x) and erfc(x) from the one that is small
        positive = x >= 0.0
        below = cos_theta * select(positive, 2.0 - tail, tail) + sin_theta * e
        above = cos_theta * (select(positive, tail, 2.0 - tail) - erfc_cot) + sin_theta * e * np.expm1(
            (x - cot) * (x + cot))
        mass = np.maximum(select(upper, above, below), 1e-300)
        x = np.minimum(x - side * (np.log(mass) - log_q) * mass / np.maximum(density, 1e-290), cot)
    return x


@dual_use
def warp_beckmann_vndf_anisotropic(u1, u2, wox, woy, woz, alpha_x, alpha_y):
    """Half vector h distributed as the Beckmann distribution of visible normals D_wo(h).

    Heitz & d'Eon 2014, "Importance Sampling Microfacet-Based BSDFs using the
    Distribution of Visible Normals", EGSR 2014: stretch the view to
    the alpha = 1 configuration, V = normalize(alpha_x wo_x, alpha_y wo_y, wo_z);
    sample the slopes (x~, y~) of the visible normals of the alpha = 1 surface
    in the frame of V's azimuth: x~ from its marginal by inverting its cdf at u1
    (:func:`_visible_slope_x`), and y~, independent of x~ because the Beckmann
    slope density exp(-x~^2 - y~^2) / pi separates, from the Gaussian
    exp(-y~^2) / sqrt(pi) at u2 (the same inversion at normal incidence);
    rotate them to V's azimuth, unstretch by (alpha_x, alpha_y) and return the
    normal h = normalize(-x~, -y~, 1) of those slopes.  ``wo`` (the view,
    surface to eye) should be unit length with wo.z > 0; a view below the
    surface is mirrored to -wo first, as in :func:`pbrkit.microfacet.ggx.warp_ggx_vndf`,
    and a grazing view (wo.z = 0) samples the limit.  The tails of u are cut
    at probabilities of 1e-250 and 1e-14 (module constants), so u on the edges
    of [0, 1]^2 gives finite normals.  pdf: :func:`pdf_beckmann_vndf_anisotropic`.
    """
    sign = select(woz < 0.0, -1.0, 1.0)
    vx = alpha_x * wox * sign
    vy = alpha_y * woy * sign
    vz = woz * sign
    inv_v = 1.0 / np.sqrt(np.maximum(vx * vx + vy * vy + vz * vz, _TINY))
    vx = vx * inv_v
    vy = vy * inv_v
    vz = vz * inv_v
    sin2 = vx * vx + vy * vy
    tilted = sin2 > 0.0
    sin_theta = np.sqrt(sin2)
    inv_sin = 1.0 / np.sqrt(select(tilted, sin2, 1.0))
    cos_phi = select(tilted, vx * inv_sin, 1.0)
    sin_phi = select(tilted, vy * inv_sin, 0.0)
    cos_theta = select(tilted, vz, 1.0)  # the zero vector is taken as the normal
    sx = _visible_slope_x(u1, cos_theta, sin_theta)
    # y~ is Gaussian (the marginal at normal incidence), its tails taken from min(u2, 1 - u2)
    sy = _visible_slope_x(np.minimum(u2, 1.0 - u2), 1.0, 0.0)
    sy = select(u2 > 0.5, -sy, sy)
    mx = alpha_x * (cos_phi * sx - sin_phi * sy)
    my = alpha_y * (sin_phi * sx + cos_phi * sy)
    inv_h = 1.0 / np.sqrt(mx * mx + my * my + 1.0)
    return -mx * inv_h, -my * inv_h, inv_h


@dual_use
def warp_beckmann_vndf(u1, u2, wox, woy, woz, alpha):
    """Isotropic Beckmann visible-normal sampling: :func:`warp_beckmann_vndf_anisotropic`
    with alpha_x = alpha_y = alpha (Heitz & d'Eon 2014).  pdf: :func:`pdf_beckmann_vndf`."""
    return warp_beckmann_vndf_anisotropic(u1, u2, wox, woy, woz, alpha, alpha)


# ------------------------------------------------------------------ pdfs (solid angle of h)


@dual_use
def pdf_beckmann_ndf(noh, alpha):
    """pdf of :func:`warp_beckmann_ndf`: D_Beckmann(h) (n.h) (Walter et al. 2007, eqs. 24-25,
    :func:`d_beckmann`)."""
    return d_beckmann(noh, alpha) * np.maximum(noh, 0.0)


@dual_use
def pdf_beckmann_vndf_anisotropic(wox, woy, woz, hx, hy, hz, alpha_x, alpha_y):
    """pdf of :func:`warp_beckmann_vndf_anisotropic` w.r.t. the solid angle of h.

    The distribution of visible normals (Heitz & d'Eon 2014; Heitz 2014,
    eq. 16): D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z with the exact Smith
    G1 = 1 / (1 + Lambda(wo)) of :func:`lambda_beckmann_anisotropic` and D of
    :func:`d_beckmann_anisotropic`.  A view with wo.z < 0 is mirrored to -wo,
    matching the sampler; wo.z is clamped at 1e-8 (the clamp Lambda uses), so a
    grazing view gives the finite limit.
    """
    sign = select(woz < 0.0, -1.0, 1.0)
    vx = wox * sign
    vy = woy * sign
    vz = woz * sign
    voh = vx * hx + vy * hy + vz * hz
    return visible_normal_pdf(lambda_beckmann_anisotropic(vz, vx, vy, alpha_x, alpha_y), voh,
                              d_beckmann_anisotropic(hz, hx, hy, alpha_x, alpha_y), vz)


@dual_use
def pdf_beckmann_vndf(nov, noh, voh, alpha):
    """pdf of :func:`warp_beckmann_vndf`: D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z
    (Heitz & d'Eon 2014; Heitz 2014, eq. 16) with the exact isotropic Smith G1 (Lambda of
    :func:`lambda_beckmann`, Heitz 2014 eq. 83) and :func:`d_beckmann`.
    Arguments are n.wo, n.h and wo.h; a view below the surface (n.wo < 0) is
    mirrored, matching the sampler."""
    flip = nov < 0.0
    c = np.abs(nov)
    vh = select(flip, -voh, voh)
    return visible_normal_pdf(lambda_beckmann(c, alpha), vh, d_beckmann(noh, alpha), c)


# ------------------------------------------------------------------ NumPy wrappers


def sample_beckmann_ndf(u, alpha):
    """Beckmann half vectors with pdf D (n.h) (:func:`warp_beckmann_ndf`)."""
    u1, u2 = _square(u)
    return _stack(*warp_beckmann_ndf(u1, u2, _alpha(alpha)))


def sample_beckmann_vndf(u, wo, alpha):
    """Beckmann visible normals for the local view ``wo`` (..., 3) (:func:`warp_beckmann_vndf`,
    Heitz & d'Eon 2014)."""
    u1, u2 = _square(u)
    return _stack(*warp_beckmann_vndf(u1, u2, *_vector3(wo, "wo"), _alpha(alpha)))


def sample_beckmann_vndf_anisotropic(u, wo, alpha_x, alpha_y):
    """Anisotropic Beckmann visible normals for the local view ``wo``
    (:func:`warp_beckmann_vndf_anisotropic`)."""
    u1, u2 = _square(u)
    return _stack(*warp_beckmann_vndf_anisotropic(u1, u2, *_vector3(wo, "wo"), _alpha(alpha_x, "alpha_x"),
                                                  _alpha(alpha_y, "alpha_y")))
