"""Warps** from the unit square u = (u1, u2) in [0, 1]^2 to directions, each
  with the solid-angle pdf of the direction it returns.  Directions are in the
  local shading frame of pbrt-v4 (:mod:`pbrkit.core.vec`): the normal is +z, x is
  the tangent and y the bitangent.

Every warp exists as a :func:`pbrkit.core.jit.dual_use` core ``warp_*(u1, u2, ...)``
that takes scalars or arrays and returns a tuple of components (usable inside
Numba kernels), and as a thin NumPy wrapper ``sample_*(u, ...)`` taking ``u``
of shape (..., 2) and returning (..., 3) unit vectors (``(..., 2)`` for the
disk).  Each ``pdf_*`` is a term too, with the arguments named in its
docstring.

Only the generic warps live here (sphere, hemisphere, concentric disk, cosine,
the mirror reflection and the Jacobian of the half-vector map); the sampling
of each microfacet distribution (GGX, Beckmann, Blinn-Phong, GTR1: NDF and
visible normals) lives with its D and masking in its unit of
:mod:`pbrkit.microfacet`, built on the helpers here.  This module imports
nothing from :mod:`pbrkit.microfacet` or :mod:`pbrkit.brdf`.

Degenerate input is guarded: for u anywhere in [0, 1]^2 (including the edges)
no warp returns NaN or Inf.
"""

from __future__ import annotations

import numpy as np

from ..core import checks
from ..core.jit import dual_use, select

__all__ = [
    "ONE_MINUS_EPSILON",
    "unit_square",
    "warp_uniform_sphere",
    "warp_uniform_hemisphere",
    "warp_concentric_disk",
    "warp_cosine_hemisphere",
    "reflect_xyz",
    "pdf_uniform_sphere",
    "pdf_uniform_hemisphere",
    "pdf_concentric_disk",
    "pdf_cosine_hemisphere",
    "half_to_light_jacobian",
    "pdf_light_from_half",
    "sample_uniform_sphere",
    "sample_uniform_hemisphere",
    "sample_concentric_disk",
    "sample_cosine_hemisphere",
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
    """Unit vector with cos^2 theta = cos2, sin^2 theta = sin2 (cos2 + sin2 = 1) and phi = 2 pi u2
    (the last step of the isotropic NDF warps of :mod:`pbrkit.microfacet`)."""
    cos_theta = np.sqrt(np.maximum(cos2, 0.0))
    sin_theta = np.sqrt(np.maximum(sin2, 0.0))
    phi = _TWO_PI * u2
    return sin_theta * np.cos(phi), sin_theta * np.sin(phi), cos_theta


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


# The argument checks and stacking of every sample_* wrapper, here and in the units of
# pbrkit.microfacet.


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


def reflect(wo, h):
    """l = 2 (wo.h) h - wo over the last axis (:func:`reflect_xyz`), shape (..., 3)."""
    return _stack(*reflect_xyz(*_vector3(wo, "wo"), *_vector3(h, "h")))

