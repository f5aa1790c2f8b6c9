"""The sheen lobe of ``KHR_materials_sheen``: f_sheen = sheenColor D_Charlie V_sheen
(no Fresnel), the specification's "Implementation Notes" (``SheenBRDF = nu_S
D_S``, "Sheen distribution", "Sheen visibility"), with D and V of
:mod:`pbrkit.microfacet.charlie` (Estevez and Kulla 2017, "Production Friendly
Microfacet Sheen BRDF").

Roughness: alpha = sheenRoughness^2 (the specification's ``alpha_g``,
:func:`pbrkit.microfacet.charlie.charlie_alpha`); the sheen roughness is its
own parameter, independent of the material's roughness.

Its parameters travel in the BxDF's ``extra`` slots: the sheen colour at
:data:`SHEEN_COLOR_SLOT` (3 values) and the sheen roughness at
:data:`SHEEN_ROUGHNESS_SLOT` (a model that wires the lobe in fills them).

- Sampling: by cosine-weighted directions, the diffuse lobes' technique, with
  an estimate of its own (luminance(sheenColor) E_sheen(n.v), so that a sheen
  over a metal, whose diffuse estimate is 0, is still sampled); the Charlie NDF
  sampler (:func:`pbrkit.microfacet.charlie.warp_charlie_ndf`) is there for
  the IBL prefiltering, which samples D as the Sample Viewer's does.
- Directional albedo: E_sheen(n.v, sheenRoughness) of the white lobe by a
  converged quadrature over the half vector (:func:`sheen_albedo`), baked into
  a table (:func:`sheen_albedo_table`, baked in ``pbrkit/data/sheen_albedo.npy``; the specification's lookup "with x =
  VdotN and y = sheenRoughness") that the lobe's ``albedo`` reads bilinearly
  (:func:`sheen_albedo_lookup`), times the sheen colour.
- Layering: the specification's albedo scaling, ``sheen_material = sheenColor
  sheen_brdf + material sheen_albedo_scaling`` with ``sheen_albedo_scaling = 1 -
  max3(sheenColor) E(VdotN)`` (its "Albedo-scaling technique", the simplified
  n.v-only form), is :func:`pbrkit.brdf.operators.layer` with :data:`SHEEN` as
  the top (its largest albedo channel is max3(sheenColor) E).

Noted: with the fitted Lambda the white lobe's E exceeds 1 near grazing for
small sheen roughness (1.15 at n.v = 0.01, sheenRoughness = 0.2; the fit is not
the Smith Lambda of D there), so the scaling goes negative there; and E is
steep towards n.v = 0, where the 33-point table is coarse (the lookup is
within 0.02 of E for n.v >= 0.1).  Neither is corrected here: both are the
specification's.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...core.color import rec709_luminance
from ...core.jit import dual_use
from ...core.quadrature import gauss_legendre_01, horizon_limits, horizon_phi_max, split_node
from ...microfacet.charlie import charlie_alpha, d_charlie, g2_charlie, v_charlie
from . import COSINE, Lobe

__all__ = ["SHEEN_COLOR_SLOT", "SHEEN_ROUGHNESS_SLOT", "SHEEN", "sheen_value", "sheen_albedo", "sheen_albedo_table",
           "sheen_albedo_lookup", "sheen_albedo_lookups", "SHEEN_TABLE_SIZE", "SHEEN_TABLE_FILE", "write_sheen_albedo_table",
           "sheen_albedo_scaling"]

#: The BxDF ``extra`` slots of the sheen lobe: its colour (3) and its roughness.
SHEEN_COLOR_SLOT, SHEEN_ROUGHNESS_SLOT = 0, 3
#: Gauss-Legendre nodes of :func:`sheen_albedo`: per theta_h segment, in phi.
SHEEN_ALBEDO_NODES = (48, 32)
#: Size of the E_sheen table (n.v, sheenRoughness), grid points at j / (n - 1).
SHEEN_TABLE_SIZE = (33, 33)
_XT, _WT = gauss_legendre_01(SHEEN_ALBEDO_NODES[0])
_XP, _WP = gauss_legendre_01(SHEEN_ALBEDO_NODES[1])
_MU_MIN = 1e-4


@dual_use
def sheen_albedo_quadrature(mu, sheen_roughness):
    """E_sheen(mu) of the white sheen BRDF D_Charlie V_sheen (scalar; see
    :func:`sheen_albedo`)."""
    alpha = charlie_alpha(sheen_roughness)
    k = 2.0 + 1.0 / alpha
    mu = min(max(mu, _MU_MIN), 1.0)
    sin_v, cos_a, cos_b = horizon_limits(mu)
    s_a = math.sqrt(max(1.0 - cos_a * cos_a, 0.0))
    u_a = s_a ** k
    u_b = (1.0 - cos_b * cos_b) ** (0.5 * k)
    total = 0.0
    for segment in range(2):
        for t in range(_XT.shape[0]):
            if segment == 0:
                # sin theta_h linear on [0, sin theta_a]: du = k s^(k - 1) ds
                sin_h = s_a * _XT[t]
                du = k * sin_h ** (k - 1.0) * s_a * _WT[t]
            else:
                u, du = split_node(1, _XT[t], _WT[t], u_a, u_b)
                sin_h = u ** (1.0 / k)
            cos_h = math.sqrt(max(1.0 - sin_h * sin_h, 0.0))
            if cos_h <= 0.0 or du <= 0.0:
                continue
            phi_max = horizon_phi_max(mu, sin_v, cos_h, sin_h)
            # f cos dl = D V l_z 4 (v.h) dh and dh = du dphi / (2 pi D cos_h): D cancels,
            # V l_z = G2 / (4 mu); the phi range doubled for its mirror half
            scale = du * phi_max / (math.pi * mu * cos_h)
            for q in range(_XP.shape[0]):
                phi = phi_max * _XP[q]
                hx = sin_h * math.cos(phi)
                voh = sin_v * hx + mu * cos_h
                lz = 2.0 * voh * cos_h - mu
                if lz <= 0.0 or voh <= 0.0:
                    continue
                total += g2_charlie(lz, mu, alpha) * voh * scale * _WP[q]
    return total


@dual_use(inline=True, cache=False)
def sheen_albedo(mu, sheen_roughness):
    """E_sheen(mu, sheenRoughness) = integral over the upper hemisphere of
    D_Charlie V_sheen (n.l) dl, the directional albedo of the white sheen BRDF
    (the E of KHR_materials_sheen's "Albedo-scaling technique"), by
    Gauss-Legendre over the half vector in the variable u = sin(theta_h)^(2 +
    1 / alpha), the cumulative distribution of D cos theta_h in theta_h
    (:func:`pbrkit.microfacet.charlie.warp_charlie_ndf`), so that D cancels
    from the integrand (G2 (v.h) / (2 pi mu cos theta_h) du dphi); theta_h split
    at the horizon limits of :mod:`pbrkit.core.quadrature` (theta_a linear in
    sin theta_h, then the cosine substitution up to theta_b), phi up to the
    horizon bound, mirrored.  Converged to about 1e-4 (tests/microfacet/test_charlie.py
    checks it against scipy).  alpha = sheenRoughness^2; mu floored at 1e-4.
    Compiled when called from Python."""
    return sheen_albedo_quadrature(mu, sheen_roughness)


def sheen_albedo_table(size=SHEEN_TABLE_SIZE):
    """The table E_sheen[i, j] at sheenRoughness r_i = i / (n_r - 1) (rows) and
    n.v mu_j = j / (n_mu - 1) (columns), each entry :func:`sheen_albedo`: what the
    specification's lookup reads (x = VdotN, y = sheenRoughness) and what
    :func:`sheen_albedo_lookup` interpolates."""
    n_r, n_mu = size
    table = np.empty((n_r, n_mu))
    for i in range(n_r):
        for j in range(n_mu):
            table[i, j] = sheen_albedo(j / (n_mu - 1), i / (n_r - 1))
    return table


#: The baked table (:func:`sheen_albedo_table`, stored as ``pbrkit/data/sheen_albedo.npy``
#: so that importing the lobe compiles nothing; tests/microfacet/test_charlie.py recomputes it).
SHEEN_TABLE_FILE = Path(__file__).resolve().parents[2] / "data" / "sheen_albedo.npy"
_TABLE = np.load(SHEEN_TABLE_FILE)


def write_sheen_albedo_table(path=SHEEN_TABLE_FILE):
    """Bake :func:`sheen_albedo_table` into ``path`` (.npy)."""
    np.save(path, sheen_albedo_table())


@dual_use
def sheen_albedo_lookup(mu, sheen_roughness):
    """E_sheen(mu, sheenRoughness) read bilinearly from the table of
    :func:`sheen_albedo_table` (both arguments clamped to [0, 1]; scalar)."""
    n_r, n_mu = _TABLE.shape
    x = min(max(mu, 0.0), 1.0) * (n_mu - 1)
    y = min(max(sheen_roughness, 0.0), 1.0) * (n_r - 1)
    j = min(int(x), n_mu - 2)
    i = min(int(y), n_r - 2)
    fx = x - j
    fy = y - i
    top = _TABLE[i, j] * (1.0 - fx) + _TABLE[i, j + 1] * fx
    bottom = _TABLE[i + 1, j] * (1.0 - fx) + _TABLE[i + 1, j + 1] * fx
    return top * (1.0 - fy) + bottom * fy


def sheen_albedo_lookups(mu, sheen_roughness):
    """:func:`sheen_albedo_lookup` of arrays (broadcast), with NumPy: the same bilinear
    reading of the table's grid points."""
    mu, r = np.broadcast_arrays(np.asarray(mu, dtype=np.float64), np.asarray(sheen_roughness, dtype=np.float64))
    n_r, n_mu = _TABLE.shape
    x = np.clip(mu, 0.0, 1.0) * (n_mu - 1)
    y = np.clip(r, 0.0, 1.0) * (n_r - 1)
    j = np.minimum(x.astype(np.int64), n_mu - 2)
    i = np.minimum(y.astype(np.int64), n_r - 2)
    fx = x - j
    fy = y - i
    top = _TABLE[i, j] * (1.0 - fx) + _TABLE[i, j + 1] * fx
    bottom = _TABLE[i + 1, j] * (1.0 - fx) + _TABLE[i + 1, j + 1] * fx
    return top * (1.0 - fy) + bottom * fy


@dual_use(inline=True)
def _black(b):
    return b.extra[SHEEN_COLOR_SLOT] == 0.0 and b.extra[SHEEN_COLOR_SLOT + 1] == 0.0 and \
        b.extra[SHEEN_COLOR_SLOT + 2] == 0.0


@dual_use(inline=True)
def sheen_value(b, c, ec, w):
    """sheenColor D_Charlie(n.h) V_sheen(n.l, n.v) (KHR_materials_sheen), times the
    operators' weight ``w``; alpha = sheenRoughness^2.  A black sheen colour (the
    extension absent) is 0 without evaluating D and V."""
    if _black(b):
        return 0.0, 0.0, 0.0
    alpha = charlie_alpha(b.extra[SHEEN_ROUGHNESS_SLOT])
    k = d_charlie(c.noh, alpha) * v_charlie(c.nol, c.nov, alpha) * w
    return (b.extra[SHEEN_COLOR_SLOT] * k, b.extra[SHEEN_COLOR_SLOT + 1] * k, b.extra[SHEEN_COLOR_SLOT + 2] * k)


@dual_use(inline=True)
def _sheen_lobe_albedo(b, nov):
    # 0 exactly for a black sheen colour, so that layer()'s scaling of the base is 1.0
    if _black(b):
        return 0.0, 0.0, 0.0
    e = sheen_albedo_lookup(nov, b.extra[SHEEN_ROUGHNESS_SLOT])
    return (b.extra[SHEEN_COLOR_SLOT] * e, b.extra[SHEEN_COLOR_SLOT + 1] * e, b.extra[SHEEN_COLOR_SLOT + 2] * e)


@dual_use
def sheen_albedo_scaling(sheen_color_max, nov, sheen_roughness):
    """KHR_materials_sheen's ``sheen_albedo_scaling = 1 - max3(sheenColor)
    E(VdotN)`` (the simplified form, "Albedo-scaling technique") with E from the
    table (:func:`sheen_albedo_lookup`): the factor :func:`pbrkit.brdf.operators.layer`
    gives the base under :data:`SHEEN`, for the real-time paths that scale their
    direct and indirect base terms by it.  Scalar."""
    return 1.0 - sheen_color_max * sheen_albedo_lookup(nov, sheen_roughness)


@dual_use(inline=True)
def _sheen_estimate(b, nov):
    # luminance(sheenColor) E_sheen(n.v): its share of the cosine technique (0 exactly
    # for a black sheen, leaving the mixture's probabilities as they were)
    if _black(b):
        return 0.0
    e = sheen_albedo_lookup(nov, b.extra[SHEEN_ROUGHNESS_SLOT])
    return rec709_luminance(b.extra[SHEEN_COLOR_SLOT], b.extra[SHEEN_COLOR_SLOT + 1],
                            b.extra[SHEEN_COLOR_SLOT + 2]) * e


#: The KHR_materials_sheen lobe: sampled by the cosine technique of the diffuse
#: lobes (its estimate :func:`_sheen_estimate` added to theirs), its albedo the
#: sheen colour times the E_sheen table.
SHEEN = Lobe("khr-sheen", sheen_value, COSINE, "diffuse", _sheen_estimate, _sheen_lobe_albedo)
