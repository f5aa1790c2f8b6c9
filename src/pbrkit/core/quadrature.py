"""Quadrature rules and the half-vector domain of the white furnace and the
lookup tables, written once for the NumPy furnace
(:func:`pbrkit.albedo.furnace.half_vector_domain`) and the compiled table
kernel (:mod:`pbrkit.albedo.tables`).

The directional albedo integral over the light direction l is taken over the
half vector h (l = 2 (v.h) h - v, dl = 4 (v.h) dh) in polar coordinates
(theta_h, phi) about the normal n = +z, with v = (sin theta_v, 0, cos theta_v),
mu = cos theta_v.

- Node variable in theta_h: s = log(1 + tan^2 theta_h / alpha^2) = -log(1 - u)
  for u = tan^2 theta_h / (alpha^2 + tan^2 theta_h), the cumulative
  distribution of the GGX NDF in theta_h (Walter et al. 2007, "Microfacet
  Models for Refraction through Rough Surfaces", eq. 35: tan^2 theta_h =
  alpha^2 u / (1 - u)).  Nodes uniform in s cover the lobe's core and its
  heavy tail alike (:func:`ggx_s_of_cos`, :func:`ggx_cos_of_s`).
- Horizon: l is above the horizon (n.l = 2 (v.h) cos theta_h - mu > 0) for
  every phi while 2 theta_h + theta_v < pi / 2, i.e. up to
  theta_a = (pi / 2 - theta_v) / 2; beyond, only for
  cos phi > mu (1 - 2 cos^2 theta_h) / (2 cos theta_h sin theta_v sin theta_h),
  up to theta_b = (pi / 2 + theta_v) / 2 where no phi remains
  (:func:`horizon_limits`, :func:`horizon_phi_max`).
- The theta_h range is integrated in two segments split at theta_a; the
  second uses the cosine substitution x -> (1 - cos(pi x)) / 2, which removes
  the square-root behaviour of phi_max at both ends (:func:`split_node`).

Every function but :func:`gauss_legendre_01` is
:func:`pbrkit.core.jit.dual_use`: NumPy on arrays from Python, compiled for
scalars into Numba kernels.
"""

from __future__ import annotations

import numpy as np

from .jit import dual_use, select

__all__ = [
    "gauss_legendre_01",
    "ggx_s_of_cos",
    "ggx_cos_of_s",
    "horizon_limits",
    "horizon_phi_max",
    "split_node",
]


def gauss_legendre_01(n):
    """Gauss-Legendre nodes and weights (n,) on [0, 1]: the n-point rule on
    [-1, 1] (Golub & Welsch 1969, via ``numpy.polynomial.legendre.leggauss``)
    mapped by x -> (x + 1) / 2, weights halved; exact for polynomials of
    degree 2n - 1."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


@dual_use
def ggx_s_of_cos(cos_theta, alpha):
    """Node variable s = log(1 + tan^2 theta_h / alpha^2) = -log(1 - u) of
    cos theta_h, u the GGX NDF's cumulative distribution in theta_h (Walter
    et al. 2007, eq. 35; module doc).  cos^2 theta_h is floored at 1e-300."""
    c2 = cos_theta * cos_theta
    return np.log1p((1.0 - c2) / np.maximum(c2, 1e-300) / (alpha * alpha))


@dual_use
def ggx_cos_of_s(s, alpha):
    """The inverse of :func:`ggx_s_of_cos`: (cos theta_h, sin theta_h, x) with
    x = e^s - 1 = tan^2 theta_h / alpha^2, cos theta_h = 1 / sqrt(1 + alpha^2 x)
    (Walter et al. 2007, eq. 35).  du / ds = 1 - u = 1 / (1 + x)."""
    x = np.expm1(s)
    cos_h = 1.0 / np.sqrt(1.0 + alpha * alpha * x)
    sin_h = np.sqrt(np.maximum(0.0, 1.0 - cos_h * cos_h))
    return cos_h, sin_h, x


@dual_use
def horizon_limits(mu):
    """(sin theta_v, cos theta_a, cos theta_b) for mu = cos theta_v (at most
    1): the half vectors with theta_h < theta_a = (pi / 2 - theta_v) / 2
    reflect v above the horizon for every azimuth, none beyond
    theta_b = (pi / 2 + theta_v) / 2 does (module doc)."""
    theta_v = np.arccos(mu)
    return np.sin(theta_v), np.cos(0.25 * np.pi - 0.5 * theta_v), np.cos(0.25 * np.pi + 0.5 * theta_v)


@dual_use
def horizon_phi_max(mu, sin_v, cos_h, sin_h):
    """phi_max(theta_h) = acos(mu (1 - 2 cos^2 theta_h) / (2 cos theta_h
    sin theta_v sin theta_h)) clamped to [0, pi]: the half vectors at
    azimuth |phi| < phi_max reflect v (mu = cos theta_v) above the horizon
    (module doc).  Where the denominator vanishes the bound is -1 (phi_max =
    pi) if 2 cos^2 theta_h > 1, else 1 (phi_max = 0)."""
    one_minus = 1.0 - 2.0 * cos_h * cos_h
    denominator = 2.0 * cos_h * sin_v * sin_h
    positive = denominator > 0.0
    bound = select(positive, mu * one_minus / select(positive, denominator, 1.0),
                   select(one_minus < 0.0, -1.0, 1.0))
    return np.arccos(np.minimum(np.maximum(bound, -1.0), 1.0))


@dual_use
def split_node(segment, x, weight, mid, end):
    """Node and weight on segment 0 ([0, mid], linear: mid x, mid w) or
    segment 1 ([mid, end], cosine substitution:
    mid + (end - mid) (1 - cos(pi x)) / 2, weight (end - mid) (pi / 2)
    sin(pi x) w) of a rule (x, w) on [0, 1] (module doc)."""
    if segment == 0:
        return mid * x, mid * weight
    return (mid + (end - mid) * 0.5 * (1.0 - np.cos(np.pi * x)),
            (end - mid) * 0.5 * np.pi * np.sin(np.pi * x) * weight)
