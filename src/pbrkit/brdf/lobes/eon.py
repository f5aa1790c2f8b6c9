"""The energy-preserving Oren-Nayar diffuse lobe, EON (Portsmouth, Kutz and Hill
2025, "EON: A practical energy-preserving rough diffuse BRDF", JCGT 14(1); the
diffuse lobe of OpenPBR Surface 1.1).

Fujii's improved Oren-Nayar model (FON) in the form of EON's eqs.:

    f_ss = (rho / pi) A (1 + r s / t),   s = l.v - (n.l)(n.v),
    s / t = s / max(n.l, n.v) where s > 0, else s,   A = 1 / (1 + c1 r),

with c1 = 1/2 - 2 / (3 pi), and its directional albedo in closed form

    E_F(mu) = A + (r A / pi) G(mu),
    G(mu) = S (acos mu - S mu) + (2/3) ((S / mu)(1 - S^3) - S),   S = sqrt(1 - mu^2),

its cosine-weighted mean E_avg = A (1 + c2 r), c2 = 2/3 - 28 / (15 pi); EON adds
the multiple-scattering lobe that restores the energy FON loses,

    f_ms = (rho_ms / pi) (1 - E_F(n.l)) (1 - E_F(n.v)) / (1 - E_avg),
    rho_ms = rho^2 E_avg / (1 - rho (1 - E_avg)),

so that its directional albedo is rho E_F(mu) + rho_ms (1 - E_F(mu)), 1 for
rho = 1 at every mu (a white furnace), and r = 0 is Lambert.  Roughness: r is
the material's perceptual roughness (as Burley's diffuse uses it); rho is the
diffuse colour.  Sampled by cosine-weighted directions (EON's own clipped-LTC
sampling is left out), with the albedo estimate of the other diffuse lobes.
"""

from __future__ import annotations

import math

from ...core.jit import dual_use
from . import COSINE, Lobe, diffuse_estimate

__all__ = ["EON", "eon_fujii_albedo", "eon_value", "eon_albedo"]

_INV_PI = 1.0 / math.pi
_C1 = 0.5 - 2.0 / (3.0 * math.pi)
_C2 = 2.0 / 3.0 - 28.0 / (15.0 * math.pi)


@dual_use
def eon_fujii_albedo(mu, r):
    """E_F(mu): the directional albedo of Fujii's Oren-Nayar lobe for rho = 1, in
    closed form (EON, Portsmouth et al. 2025, the FON albedo; mu = n.v > 0, r in [0, 1])."""
    a = 1.0 / (1.0 + _C1 * r)
    m = min(max(mu, 1e-7), 1.0)
    s = math.sqrt(max(1.0 - m * m, 0.0))
    g = s * (math.acos(m) - s * m) + (2.0 / 3.0) * ((s / m) * (1.0 - s * s * s) - s)
    return a + (r * a * _INV_PI) * g


@dual_use
def _eon_channel(rho, r, ef_l, ef_v, e_avg):
    # rho_ms / pi (1 - E_F(l)) (1 - E_F(v)) / (1 - E_avg); at r = 0 FON is Lambert and loses
    # nothing (1 - E_avg = 0): no multiple-scattering lobe
    lost = 1.0 - e_avg
    if lost <= 1e-15:
        return 0.0
    rho_ms = rho * rho * e_avg / (1.0 - rho * lost)
    return rho_ms * _INV_PI * max(1.0 - ef_l, 0.0) * max(1.0 - ef_v, 0.0) / lost


@dual_use(inline=True)
def eon_value(b, c, ec, w):
    """The EON lobe's value (module docstring) for the BxDF's diffuse colour and
    perceptual roughness, times the operators' weight ``w``."""
    r = b.roughness
    nol = c.nol
    nov = c.nov
    if nol <= 0.0 or nov <= 0.0:
        return 0.0, 0.0, 0.0
    # l.v = 2 (v.h)^2 - 1, with h the half vector
    s = (2.0 * c.voh * c.voh - 1.0) - nol * nov
    s_over_t = s / max(nol, nov) if s > 0.0 else s
    a = 1.0 / (1.0 + _C1 * r)
    single = _INV_PI * a * (1.0 + r * s_over_t)
    ef_l = eon_fujii_albedo(nol, r)
    ef_v = eon_fujii_albedo(nov, r)
    e_avg = a * (1.0 + _C2 * r)
    rho = b.diffuse_color
    return ((rho[0] * single + _eon_channel(rho[0], r, ef_l, ef_v, e_avg)) * w,
            (rho[1] * single + _eon_channel(rho[1], r, ef_l, ef_v, e_avg)) * w,
            (rho[2] * single + _eon_channel(rho[2], r, ef_l, ef_v, e_avg)) * w)


@dual_use
def _eon_albedo_channel(rho, ef, e_avg):
    return rho * ef + rho * rho * e_avg / (1.0 - rho * (1.0 - e_avg)) * (1.0 - ef)


@dual_use(inline=True)
def eon_albedo(b, nov):
    """EON's directional albedo rho E_F(mu) + rho_ms (1 - E_F(mu)) (exact, closed form)."""
    r = b.roughness
    ef = eon_fujii_albedo(nov, r)
    e_avg = (1.0 / (1.0 + _C1 * r)) * (1.0 + _C2 * r)
    rho = b.diffuse_color
    return (_eon_albedo_channel(rho[0], ef, e_avg), _eon_albedo_channel(rho[1], ef, e_avg),
            _eon_albedo_channel(rho[2], ef, e_avg))


#: EON, sampled by cosine-weighted directions.
EON = Lobe("eon", eon_value, COSINE, "diffuse", diffuse_estimate, eon_albedo)
