"""Deterministic numerical integration over the hemisphere, for the tests only.

These rules are written from the geometry alone and share no code with
``pbrkit`` (they do not import it), so integrals computed with them are an
independent check of the package's formulas.

Local frame: the normal is +z, the tangent +x, the bitangent +y; a direction
with polar angle theta and azimuth phi is
(sin theta cos phi, sin theta sin phi, cos theta).

Two rules:

* :func:`hemisphere_rule` -- Gauss-Legendre in mu = cos theta on [0, 1] times
  Gauss-Legendre in phi on [0, 2 pi].  For broad integrands (Lambert, cosine
  powers).

* :func:`half_vector_rule` -- for microfacet lobes concentrated around the
  normal with width alpha (possibly anisotropic, alpha_t along +x and alpha_b
  along +y).  The azimuth is stretched as in GGX sampling,
  phi = atan2(alpha_b sin psi, alpha_t cos psi), so that the lobe has the same
  width alpha_phi = sqrt(alpha_t^2 cos^2 psi + alpha_b^2 sin^2 psi) in every
  column; along a column the polar angle is
  theta = atan(alpha_phi e^lam), the logarithm of tan theta / alpha_phi.  The
  variable lam turns every lobe shape met here (GGX, Beckmann, GTR, Blinn-Phong,
  and the power-law tails of a broad integrand seen through a narrow lobe's
  nodes) into a bell of width ~1 in lam, whatever alpha is, so composite
  Gauss-Legendre panels of width ~1 resolve lobes from alpha = 1e-3 to 1 with
  the same nodes.  (This is the log form of the change of variable
  tan^2 theta = alpha^2 u / (1 - u) that samples GGX.)  The measure is
  d omega = sin theta d theta d phi = sin^2 theta cos theta d lam d phi, and
  d phi / d psi = alpha_t alpha_b / (alpha_t^2 cos^2 psi + alpha_b^2 sin^2 psi).
  An optional upper limit theta_max(phi) per column cuts the domain exactly at
  a curve where the integrand has a kink (v.h = 0, or the reflected direction
  reaching the horizon), so that Gauss-Legendre keeps its fast convergence.
  Across columns, psi is integrated with composite Gauss-Legendre panels graded
  geometrically toward the azimuths where such a cut swings fastest and toward
  the peaks of d phi / d psi.  Measured accuracy (tests/brdf/test_distributions.py
  checks it on integrals known in closed form): ~1e-7 for normalised lobes,
  <= 1e-5 for broad integrands through strongly anisotropic nodes, and < 1e-4 for
  the directional albedos of the models (against rules ~5x denser).

:func:`directional_albedo` integrates f(l, v) (n.l) over the light directions
of the upper hemisphere through the half vector: l = 2 (v.h) h - v and
dl = 4 (v.h) dh (Walter et al. 2007, eq. 14), restricted exactly to the
half vectors whose l is above the horizon.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "gauss_legendre",
    "graded_gauss_legendre",
    "hemisphere_rule",
    "half_vector_rule",
    "theta_max_visible",
    "theta_max_reflected",
    "albedo_nodes",
    "directional_albedo",
    "view_direction",
]

_HALF_PI = 0.5 * np.pi


def gauss_legendre(a, b, n):
    """Nodes and weights of the n-point Gauss-Legendre rule on [a, b]."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (b - a) * x + 0.5 * (b + a), 0.5 * (b - a) * w


def graded_gauss_legendre(a, b, n, panels, grade=1.0):
    """Composite Gauss-Legendre nodes on [a, b], panel edges graded towards a by t^grade."""
    x, w = np.polynomial.legendre.leggauss(n)
    edges = a + (b - a) * np.linspace(0.0, 1.0, panels + 1) ** grade
    lo, hi = edges[:-1, None], edges[1:, None]
    return (0.5 * (hi - lo) * (x + 1.0) + lo).ravel(), (0.5 * (hi - lo) * w).ravel()


def _direction(cos_theta, sin_theta, phi):
    return np.stack([sin_theta * np.cos(phi), sin_theta * np.sin(phi), cos_theta], axis=-1)


def hemisphere_rule(n_mu=64, n_phi=64):
    """Directions (N, 3) and weights (N,) with sum w g(w) ~ integral over the upper hemisphere of g d omega.

    Gauss-Legendre in mu = cos theta (d omega = d mu d phi) and in phi.
    """
    mu, w_mu = gauss_legendre(0.0, 1.0, n_mu)
    phi, w_phi = gauss_legendre(0.0, 2.0 * np.pi, n_phi)
    mu, phi = np.meshgrid(mu, phi, indexing="ij")
    weights = np.outer(w_mu, w_phi)
    directions = _direction(mu, np.sqrt(1.0 - mu * mu), phi)
    return directions.reshape(-1, 3), weights.reshape(-1)


def _graded_panels(a, b, levels, ratio):
    """Panel edges on [a, b], geometrically refined toward both ends.

    Edges at a + (b - a) s with s = 0, 0.5 ratio^levels, ..., 0.5 ratio, 0.5 and
    symmetrically up to 1.
    """
    s = 0.5 * ratio ** np.arange(levels, 0, -1)
    s = np.concatenate([[0.0], s, [0.5], 1.0 - s[::-1], [1.0]])
    return a + (b - a) * s


def _psi_of_phi(phi, at, ab):
    """Inverse of phi = atan2(ab sin psi, at cos psi)."""
    return np.arctan2(at * np.sin(phi), ab * np.cos(phi))


def _psi_rule(at, ab, phi_split, n_nodes, levels, ratio):
    """Composite Gauss-Legendre nodes and weights in psi over one turn.

    The turn is cut at the azimuths phi_split and phi_split + pi and, for an
    anisotropic stretch, where d phi / d psi peaks (psi = 0, pi when
    alpha_t < alpha_b, psi = +-pi/2 otherwise; the peak is alpha_max / alpha_min
    high and alpha_min / alpha_max wide), and each arc is refined toward its ends.
    """
    breaks = [_psi_of_phi(phi_split, at, ab), _psi_of_phi(phi_split + np.pi, at, ab)]
    if at < ab:
        breaks += [0.0, np.pi]
    elif at > ab:
        breaks += [0.5 * np.pi, -0.5 * np.pi]
    breaks = np.sort(np.mod(np.asarray(breaks), 2.0 * np.pi))
    keep = np.concatenate([[True], np.diff(breaks) > 1e-9])
    breaks = breaks[keep]
    if len(breaks) > 1 and breaks[-1] - breaks[0] > 2.0 * np.pi - 1e-9:
        breaks = breaks[:-1]
    ends = np.concatenate([breaks, [breaks[0] + 2.0 * np.pi]])
    x, wx = np.polynomial.legendre.leggauss(n_nodes)
    psi_parts, w_parts = [], []
    for a, b in zip(ends[:-1], ends[1:]):
        edges = _graded_panels(a, b, levels, ratio)
        lo, hi = edges[:-1, None], edges[1:, None]
        psi_parts.append((0.5 * (hi - lo) * (x + 1.0) + lo).ravel())
        w_parts.append((0.5 * (hi - lo) * wx).ravel())
    return np.concatenate(psi_parts), np.concatenate(w_parts)


def half_vector_rule(alpha_t, alpha_b=None, theta_max=None, phi_split=0.5 * np.pi, n_psi_nodes=8,
                     psi_levels=6, psi_ratio=0.25, n_panels=28, n_nodes=6, q_min=1e-4, tan_limit=1e7):
    """Directions (N, 3) and weights (N,) for lobes of width alpha around +z (see the module docstring).

    ``theta_max``: None (the whole hemisphere) or a function of the azimuth
    phi (array) giving the upper limit of theta in each column, in (0, pi / 2].
    The column runs over q = tan theta / alpha_phi from q_min to
    min(tan theta_max, tan_limit) / alpha_phi; the parts left out (theta < alpha q_min,
    and the band of 1 / tan_limit = 1e-7 rad at the horizon, solid angle ~6e-7)
    are negligible for the bounded integrands of the tests.
    Along each column: ``n_panels`` equal panels in lam = ln q of ``n_nodes``
    Gauss-Legendre nodes.  Across columns: the turn of psi is cut at the
    azimuths ``phi_split`` and ``phi_split + pi`` (where the cuts of
    :func:`theta_max_visible` and :func:`theta_max_reflected` for a view direction
    at azimuth phi_split - pi/2 change fastest) and, when anisotropic, at the
    peaks of d phi / d psi; each arc is split into panels graded toward its
    ends (``psi_levels`` levels of ratio ``psi_ratio``) of ``n_psi_nodes``
    Gauss-Legendre nodes.
    """
    if alpha_b is None:
        alpha_b = alpha_t
    at, ab = float(alpha_t), float(alpha_b)
    psi, w_psi = _psi_rule(at, ab, phi_split, n_psi_nodes, psi_levels, psi_ratio)
    cp, sp = np.cos(psi), np.sin(psi)
    rho2 = at * at * cp * cp + ab * ab * sp * sp
    alpha_phi = np.sqrt(rho2)
    phi = np.arctan2(ab * sp, at * cp)
    w_phi = w_psi * (at * ab / rho2)

    lam_lo = np.full_like(psi, np.log(q_min))
    if theta_max is None:
        lam_hi = np.log(tan_limit / alpha_phi)
    else:
        tmax = np.asarray(theta_max(phi), dtype=float)
        if np.any(tmax <= 0.0) or np.any(tmax > _HALF_PI):
            raise ValueError("theta_max must lie in (0, pi/2]")
        tan_max = np.where(tmax >= _HALF_PI, np.inf, np.tan(np.minimum(tmax, _HALF_PI)))
        lam_hi = np.log(np.minimum(tan_max, tan_limit) / alpha_phi)
        lam_lo = np.minimum(lam_lo, lam_hi - 1.0)

    x, wx = np.polynomial.legendre.leggauss(n_nodes)
    k = np.arange(n_panels)
    width = (lam_hi - lam_lo) / n_panels  # per column
    # lam[column, panel, node]
    lam = lam_lo[:, None, None] + width[:, None, None] * (k[None, :, None] + 0.5 * (x[None, None, :] + 1.0))
    w_lam = 0.5 * width[:, None, None] * wx[None, None, :] * np.ones_like(lam)

    tan_theta = alpha_phi[:, None, None] * np.exp(lam)
    cos_theta = 1.0 / np.sqrt(1.0 + tan_theta * tan_theta)
    sin_theta = tan_theta * cos_theta
    # d omega = sin theta d theta d phi, d theta / d lam = sin theta cos theta.
    weights = w_lam * (sin_theta * sin_theta * cos_theta) * w_phi[:, None, None]
    directions = _direction(cos_theta, sin_theta, np.broadcast_to(phi[:, None, None], lam.shape))
    return directions.reshape(-1, 3), weights.reshape(-1)


def view_direction(cos_theta, phi=0.0):
    """Unit local direction with n.v = cos_theta and azimuth phi."""
    s = np.sqrt(max(0.0, 1.0 - cos_theta * cos_theta))
    return np.array([s * np.cos(phi), s * np.sin(phi), cos_theta])


def _v_angles(v):
    v = np.asarray(v, dtype=float)
    return float(v[2]), float(np.hypot(v[0], v[1])), float(np.arctan2(v[1], v[0]))


def theta_max_visible(v):
    """theta_max(phi) of the half vectors h with v.h > 0.

    v.h = sin theta_v sin theta cos(phi - phi_v) + cos theta_v cos theta, which is
    positive for all theta < pi/2 when cos(phi - phi_v) >= 0 and otherwise for
    tan theta < cos theta_v / (sin theta_v |cos(phi - phi_v)|).
    """
    cv, sv, phi_v = _v_angles(v)

    def bound(phi):
        c = np.cos(phi - phi_v)
        limit = np.arctan2(cv, sv * np.maximum(-c, 0.0))
        return np.where(c >= 0.0, _HALF_PI, np.minimum(limit, _HALF_PI))

    return bound


def theta_max_reflected(v):
    """theta_max(phi) of the half vectors h whose mirror direction l = 2 (v.h) h - v has n.l > 0.

    n.l = 2 (v.h)(n.h) - n.v = cos theta_v cos 2 theta + sin theta_v cos(phi - phi_v) sin 2 theta,
    = R cos(2 theta - delta) with delta = atan2(sin theta_v cos(phi - phi_v), cos theta_v),
    positive exactly for theta < (delta + pi/2) / 2.  (On that set v.h > n.v / (2 n.h) > 0.)
    """
    cv, sv, phi_v = _v_angles(v)

    def bound(phi):
        delta = np.arctan2(sv * np.cos(phi - phi_v), cv)
        return np.minimum(0.5 * (delta + _HALF_PI), _HALF_PI)

    return bound


def albedo_nodes(v, alpha_t, alpha_b=None, **rule_options):
    """Light directions l (N, 3) and weights (N,) with
    sum weight f(l) ~ integral over the upper hemisphere of f(l) (n.l) dl for the view v.

    Built from :func:`half_vector_rule` (lobe width (alpha_t, alpha_b), exact
    cut of :func:`theta_max_reflected`): l = 2 (v.h) h - v, dl = 4 (v.h) dh.
    """
    v = np.asarray(v, dtype=float)
    phi_v = float(np.arctan2(v[1], v[0]))
    h, w = half_vector_rule(alpha_t, alpha_b, theta_max=theta_max_reflected(v), phi_split=phi_v + 0.5 * np.pi,
                            **rule_options)
    voh = h @ v
    l = 2.0 * voh[:, None] * h - v
    l /= np.linalg.norm(l, axis=-1, keepdims=True)
    return l, w * 4.0 * voh * np.maximum(l[:, 2], 0.0)


def directional_albedo(brdf, v, alpha_t, alpha_b=None, **rule_options):
    """integral over l in the upper hemisphere of brdf(l, v) (n.l) dl, through the half vector.

    ``brdf(l, v)`` takes local directions of shape (N, 3) and (3,) and returns
    (N,) or (N, C); see :func:`albedo_nodes`.
    """
    v = np.asarray(v, dtype=float)
    l, weight = albedo_nodes(v, alpha_t, alpha_b, **rule_options)
    f = np.asarray(brdf(l, v), dtype=float)
    if f.ndim == 1:
        return float(np.sum(weight * f))
    return np.tensordot(weight, f, axes=(0, 0))
