"""Shared test helper: KHR_materials_sheen's formulas transcribed independently of pbrkit
(the specification's GLSL blocks, "Sheen distribution" and "Sheen visibility", with
GLSL's mix), and the directional albedo E_sheen of its white sheen BRDF by a tensor
Gauss-Legendre rule over the light direction."""

from __future__ import annotations

import math

import numpy as np
from quadrature import graded_gauss_legendre


def _mix(x, y, a):
    return x * (1.0 - a) + y * a


def spec_d(noh, sheen_roughness):
    """KHR_materials_sheen "Sheen distribution", as its GLSL block writes it."""
    alpha_g = sheen_roughness * sheen_roughness
    inv_r = 1.0 / alpha_g
    cos2h = noh * noh
    sin2h = 1.0 - cos2h
    return (2.0 + inv_r) * np.power(sin2h, inv_r * 0.5) / (2.0 * np.pi)


def spec_l(x, alpha_g):
    one_minus_alpha_sq = (1.0 - alpha_g) * (1.0 - alpha_g)
    a = _mix(21.5473, 25.3245, one_minus_alpha_sq)
    b = _mix(3.82987, 3.32435, one_minus_alpha_sq)
    c = _mix(0.19823, 0.16801, one_minus_alpha_sq)
    d = _mix(-1.97760, -1.27393, one_minus_alpha_sq)
    e = _mix(-4.32054, -4.85967, one_minus_alpha_sq)
    return a / (1.0 + b * np.power(x, c)) + d * x + e


def spec_lambda(cos_theta, alpha_g):
    return np.where(np.abs(cos_theta) < 0.5, np.exp(spec_l(cos_theta, alpha_g)),
                    np.exp(2.0 * spec_l(0.5, alpha_g) - spec_l(1.0 - cos_theta, alpha_g)))


def spec_visibility(nol, nov, sheen_roughness):
    alpha_g = sheen_roughness * sheen_roughness
    return 1.0 / ((1.0 + spec_lambda(nov, alpha_g) + spec_lambda(nol, alpha_g)) * (4.0 * nov * nol))


def reference_sheen_albedo(mu, r):
    """E_sheen(mu, r) of the spec's white sheen BRDF (spec_d spec_visibility), by a tensor
    Gauss-Legendre rule over the light direction (cos theta_l graded towards the horizon,
    phi on [0, pi] mirrored); independent of the lobe's half-vector quadrature.
    Checked once against scipy.integrate.dblquad (1e-7): 0.18785393 at (0.5, 0.5),
    0.70639074 at (0.05, 0.3), 0.55278622 at (0.2, 0.8)."""
    ct, wt = graded_gauss_legendre(0.0, 1.0, 24, 24, grade=2.0)
    ph, wp = graded_gauss_legendre(0.0, np.pi, 24, 16)
    ct, ph = np.meshgrid(ct, ph, indexing="ij")
    w = np.outer(wt, wp)
    st = np.sqrt(1.0 - ct * ct)
    sv = math.sqrt(1.0 - mu * mu)
    hx, hy, hz = st * np.cos(ph) + sv, st * np.sin(ph), ct + mu
    noh = hz / np.sqrt(hx * hx + hy * hy + hz * hz)
    f = spec_d(noh, r) * spec_visibility(ct, mu, r)
    return 2.0 * float(np.sum(f * ct * w))
