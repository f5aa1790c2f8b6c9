"""Split-sum / DFG lookup tables, Karis' analytic approximation and Kulla-Conty
energy compensation.

Layout (``CONVENTIONS.md``): an array (N, N, C) float32 indexed [j, i, c] with
column i at n.v = (i + 0.5) / N and row j at perceptual roughness
r = (j + 0.5) / N (texel centres; row 0 = smooth).  GGX lobes use
alpha = r^2 exactly, with no clamp: row 0 (r = 0.5 / N, alpha = 0.25 / N^2,
below the shading clamp ALPHA_MIN = 1e-3 for N > 16) is the integral of the
roughness it states.  The clamp belongs to shading (a renderer clamps alpha
before it evaluates D; its table lookup at r < 0.5 / N reads row 0 by
clamp-to-edge); clamping in the table moved row 0 by up to 4e-2 at grazing
n.v.  (:func:`table_alpha`.)

The integrals are computed by deterministic quadrature over the half vector
(the method of :mod:`pbrkit.albedo.furnace`, compiled, with the node map, horizon
bounds and segments of :mod:`pbrkit.core.quadrature`): h is parameterised by
the lobe's own cumulative distribution in theta_h and by the azimuth,
restricted analytically to the half vectors that reflect v above the
horizon, so that D cancels against the parameterisation's density and the
integrand is smooth.
Gauss-Legendre rules converge to well below the 1e-3 tolerance (see the
tests); more theta nodes are used in the grazing columns where the integrand
varies fastest.
"""

from __future__ import annotations

import math

import numpy as np

from ..brdf.bxdf import Cosines, lobe_bxdf
from ..brdf.fresnel import f_conductor, f_schlick
from ..brdf.masking import (
    v_neubelt,
)
from ..brdf.terms import GGX, HEIGHT_CORRELATED_DIVISION_FREE, SCHLICK_GGX, SEPARABLE
from ..core import checks
from ..core.filtering import CLAMP_TO_EDGE, texel_pair
from ..core.jit import dual_use, kernel, row_kernel
from ..core.quadrature import (
    gauss_legendre_01,
    ggx_cos_of_s,
    ggx_s_of_cos,
    horizon_limits,
    horizon_phi_max,
    split_node,
)
from ..microfacet.charlie import v_charlie
from .table_spec import DEFAULT_NODES, TableSpec, default_visibility

__all__ = [
    "VISIBILITIES",
    "TableSpec",
    "texel_centres",
    "table_alpha",
    "specular_integrals",
    "sheen_albedo",
    "integrate_lookup_table",
    "sample_table",
    "table_bilinear",
    "env_brdf_approx",
    "average_albedo",
    "kulla_conty_tables",
    "f_avg_schlick",
    "f_avg_numeric",
    "f_avg_conductor",
    "kulla_conty_ms",
    "kulla_conty_color",
    "filament_energy_compensation",
]

#: Visibility terms for the specular tables, by name -> kernel code.
VISIBILITIES = {"schlick-ggx": 0, "separable": 1, "height-correlated": 2}
_NEUBELT = 3
_SHEEN_CHARLIE = 4
_LOBE_GGX = 0
_LOBE_CHARLIE = 1


def texel_centres(n):
    """(i + 0.5) / n for i in 0..n-1 (texel centres, CONVENTIONS.md)."""
    return (np.arange(n) + 0.5) / n


_V_SCHLICK_GGX = SCHLICK_GGX.v
_V_SEPARABLE = SEPARABLE.for_distribution(GGX)
_V_HEIGHT_CORRELATED = HEIGHT_CORRELATED_DIVISION_FREE.v


@dual_use
def _lobe_visibility(code, nol, nov, alpha):
    """Visibility V = G2 / (4 n.l n.v) of the table's lobe, by code: the masking terms
    the models' lobes use (:mod:`pbrkit.brdf.terms`) for Schlick-GGX with k = alpha / 2
    (cook_torrance ``schlick-ggx``, UE4's IBL), separable exact Smith-GGX
    (cook_torrance ``separable``, glTF, Disney) and height-correlated Smith-GGX
    (Filament's division-free form), or the cloth lobe's Neubelt visibility, or
    KHR_materials_sheen's sheen visibility (:func:`pbrkit.microfacet.charlie.v_charlie`)."""
    if code == _NEUBELT:
        return v_neubelt(nol, nov)
    if code == _SHEEN_CHARLIE:
        return v_charlie(nol, nov, alpha)
    b = lobe_bxdf(alpha)
    c = Cosines(nol, nov, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    if code == 0:
        return _V_SCHLICK_GGX(b, c)
    if code == 1:
        return _V_SEPARABLE(b, c)
    return _V_HEIGHT_CORRELATED(b, c)


@row_kernel(lambda mu, alpha, *rest: alpha.shape[0] * mu.shape[0])
def _integrate_lobe(start, stop, mu, alpha, lobe, vis_code, x_theta, w_theta, x_phi, w_phi, out):
    """out[j, i] = (integral of V (1 - Fc) (n.l) ..., integral of V Fc ...) with Fc = (1 - v.h)^5.

    Quadrature in (w, phi) over the half-vector domain of
    :mod:`pbrkit.core.quadrature` (split at theta_a, horizon bound phi_max):
    for GGX w = s = -log(1 - u), u the NDF's CDF in theta_h
    (:func:`~pbrkit.core.quadrature.ggx_s_of_cos`), for Charlie the fraction
    of the lobe's CDF within the admissible range; phi in
    [0, phi_max(theta_h)], mirrored.
    """
    n_mu = mu.shape[0]
    for index in range(start, stop):  # index = j n_mu + i over the (roughness, n.v) grid
        j = index // n_mu
        i = index % n_mu
        m = mu[i]
        a = alpha[j]
        sin_v, cos_a, cos_b = horizon_limits(min(m, 1.0))
        if lobe == _LOBE_GGX:
            # GGX: nodes uniform in s = -log(1 - u), u the NDF's CDF in theta_h; this spreads
            # them over the lobe's core (u < 0.9) and its tail toward the horizon alike.
            w_a = ggx_s_of_cos(cos_a, a)
            w_b = ggx_s_of_cos(cos_b, a)
            u_b = 1.0
            k = 0.0  # (Charlie only)
            s_b = 0.0
        else:
            # Charlie: CDF in s = sin theta_h is s^k with k = 2 + 1 / alpha (Estevez & Kulla 2017).
            k = 2.0 + 1.0 / a
            s_b = math.sqrt(max(0.0, 1.0 - cos_b * cos_b))
            s_a = math.sqrt(max(0.0, 1.0 - cos_a * cos_a))
            u_b = math.exp(k * math.log(max(s_b, 1e-300)))
            w_a = math.exp(k * (math.log(max(s_a, 1e-300)) - math.log(max(s_b, 1e-300))))
            w_b = 1.0
        acc_a = 0.0
        acc_b = 0.0
        for segment in range(2):
            for t in range(x_theta.shape[0]):
                w, dw = split_node(segment, x_theta[t], w_theta[t], w_a, w_b)
                if lobe == _LOBE_GGX:
                    cos_h, sin_h, x = ggx_cos_of_s(w, a)
                    dw /= 1.0 + x  # du = (1 - u) ds
                else:
                    sin_h = s_b * math.exp(math.log(max(w, 1e-300)) / k)
                    cos_h = math.sqrt(max(0.0, 1.0 - sin_h * sin_h))
                if cos_h <= 0.0:
                    continue
                phi_max = horizon_phi_max(m, sin_v, cos_h, sin_h)
                # D dh = u_b dw dphi / (2 pi cos_h) and dphi = phi_max w_phi, doubled for
                # the mirrored half of the phi range.
                scale = u_b * dw * phi_max / (math.pi * cos_h)
                for p in range(x_phi.shape[0]):
                    c = math.cos(phi_max * x_phi[p])
                    voh = sin_v * sin_h * c + m * cos_h
                    nol = 2.0 * voh * cos_h - m
                    if nol <= 0.0 or voh <= 0.0:
                        continue
                    g = _lobe_visibility(vis_code, nol, m, a) * nol * 4.0 * voh * scale * w_phi[p]
                    fc = f_schlick(voh, 0.0, 1.0)
                    acc_a += g * (1.0 - fc)
                    acc_b += g * fc
        out[j, i, 0] = acc_a
        out[j, i, 1] = acc_b


#: The Gauss-Legendre rule on [0, 1] by its former name here (:func:`pbrkit.core.quadrature.gauss_legendre_01`).
_gauss_legendre_01 = gauss_legendre_01

#: Default quadrature: theta nodes per segment (and in the grazing columns), phi nodes.


def _run(mu, alpha, lobe, vis_code, nodes=DEFAULT_NODES):
    n_theta, n_theta_grazing, n_phi = nodes
    x_t, w_t = gauss_legendre_01(n_theta)
    x_g, w_g = gauss_legendre_01(n_theta_grazing)
    x_p, w_p = gauss_legendre_01(n_phi)
    out = np.zeros((alpha.size, mu.size, 2))
    mu = np.ascontiguousarray(mu, dtype=np.float64)
    alpha = np.ascontiguousarray(alpha, dtype=np.float64)
    grazing = mu < 0.0625
    if np.any(~grazing):
        sub = np.zeros((alpha.size, int((~grazing).sum()), 2))
        _integrate_lobe(mu[~grazing], alpha, lobe, vis_code, x_t, w_t, x_p, w_p, sub)
        out[:, ~grazing] = sub
    if np.any(grazing):
        sub = np.zeros((alpha.size, int(grazing.sum()), 2))
        _integrate_lobe(mu[grazing], alpha, lobe, vis_code, x_g, w_g, x_p, w_p, sub)
        out[:, grazing] = sub
    return out


def table_alpha(roughness):
    """alpha = r^2 of the tables' rows, unclamped (module docstring); r = 0 (only
    reachable through the functions' own arguments, never a texel centre) is
    lifted to 1e-12 so the half-vector map stays finite."""
    return np.maximum(np.square(np.asarray(roughness, dtype=float)), 1e-12)


def specular_integrals(mu, roughness, visibility="height-correlated", nodes=DEFAULT_NODES):
    """(A, B) = (integral of f (1 - Fc) (n.l) dl, integral of f Fc (n.l) dl) for the
    Fresnel-free GGX lobe f = D V and Fc = (1 - v.h)^5, so that the specular
    directional albedo with Schlick Fresnel is F0 A + B (Karis 2013, "Real
    Shading in Unreal Engine 4", sec. "Image based lighting": environment BRDF).

    ``visibility``: ``schlick-ggx`` (k = alpha / 2, Karis' IBL remap),
    ``separable`` (exact Smith G1 G1) or ``height-correlated`` (Heitz 2014).
    ``mu`` and ``roughness`` (perceptual) are 1-D; returns (len(roughness), len(mu), 2).
    """
    if visibility not in VISIBILITIES:
        raise ValueError(f"unknown visibility {visibility!r}; choose one of {', '.join(VISIBILITIES)}")
    mu, roughness = _check_axes(mu, roughness)
    return _run(mu, table_alpha(roughness), _LOBE_GGX, VISIBILITIES[visibility], nodes)


def sheen_albedo(mu, roughness, nodes=DEFAULT_NODES, visibility="neubelt"):
    """Directional albedo of the cloth sheen lobe: integral of D_Charlie V_Neubelt (n.l) dl.

    Charlie distribution D = (2 + 1 / alpha) sin^(1 / alpha) theta_h / (2 pi)
    (Estevez & Kulla 2017, "Production Friendly Microfacet Sheen BRDF", eq. 2)
    with alpha = r^2 (Filament sec. 4.12.2), Neubelt visibility
    :func:`pbrkit.brdf.masking.v_neubelt`, F = 1; the third channel Filament and
    the Khronos IBL sampler bake.  Integrated in h over the Charlie CDF
    s^(2 + 1 / alpha), s = sin theta_h, so D cancels exactly.
    ``visibility="sheen"`` takes KHR_materials_sheen's visibility instead
    (:func:`pbrkit.microfacet.charlie.v_charlie`, Estevez & Kulla's fitted Lambda,
    alpha = r^2): the E_sheen of the specification's albedo scaling.
    Returns (len(roughness), len(mu)).
    """
    if visibility not in ("neubelt", "sheen"):
        raise ValueError(f"unknown sheen visibility {visibility!r}; use 'neubelt' or 'sheen'")
    mu, roughness = _check_axes(mu, roughness)
    code = _NEUBELT if visibility == "neubelt" else _SHEEN_CHARLIE
    out = _run(mu, table_alpha(roughness), _LOBE_CHARLIE, code, nodes)
    return out.sum(axis=-1)


def _check_axes(mu, roughness):
    mu = np.atleast_1d(np.asarray(mu, dtype=float))
    roughness = np.atleast_1d(np.asarray(roughness, dtype=float))
    if mu.ndim != 1 or roughness.ndim != 1:
        raise ValueError("mu and roughness must be 1-D")
    if np.any(~np.isfinite(mu)) or np.any((mu <= 0.0) | (mu > 1.0)):
        raise ValueError("n.v values must be in (0, 1]")
    if np.any(~np.isfinite(roughness)) or np.any((roughness < 0.0) | (roughness > 1.0)):
        raise ValueError("roughness values must be in [0, 1]")
    return mu, roughness


def integrate_lookup_table(kind="dfg", size=128, visibility=None, cloth=False, nodes=DEFAULT_NODES):
    """The (size, size, C) float32 table of ``kind`` ``splitsum`` or ``dfg`` and its :class:`TableSpec`,
    integrated now (:func:`pbrkit.albedo.lut.lookup_table` memoises it).

    Defaults: ``splitsum`` uses Karis' IBL visibility (Schlick-GGX, k = alpha / 2)
    as UE4 does; ``dfg`` uses height-correlated Smith as Filament does.
    ``cloth`` appends the sheen albedo channel (:func:`sheen_albedo`).
    """
    if kind not in ("splitsum", "dfg"):
        raise ValueError(f"unknown table kind {kind!r}; use 'splitsum' or 'dfg'")
    size = checks.integer(size, "table size", 2, 4096)
    visibility = visibility or default_visibility(kind)
    axis = texel_centres(size)
    ab = specular_integrals(axis, axis, visibility, nodes)
    if kind == "splitsum":
        channels = [ab[..., 0], ab[..., 1]]
    else:
        channels = [ab[..., 1], ab[..., 0] + ab[..., 1]]
    if cloth:
        channels.append(sheen_albedo(axis, axis, nodes))
    table = np.stack(channels, axis=-1).astype(np.float32)
    return table, TableSpec(kind, int(size), visibility, bool(cloth), tuple(nodes))


def splitsum_of_dfg(dfg):
    """Karis' (A, B) (specular albedo F0 A + B) of a ``dfg`` table (DFG1, DFG2)
    (specular albedo F0 DFG2 + (1 - F0) DFG1 = F0 (DFG2 - DFG1) + DFG1) of the same
    lobe: A = DFG2 - DFG1, B = DFG1 (:func:`lookup_table`), in float64 then float32.
    Extra channels (sheen) are kept."""
    t = np.asarray(dfg, dtype=np.float64)
    if t.ndim != 3 or t.shape[2] < 2:
        raise ValueError(f"a DFG table has shape (N, N, 2 or 3), got {t.shape}")
    out = t.copy()
    out[..., 0] = t[..., 1] - t[..., 0]
    out[..., 1] = t[..., 0]
    return out.astype(np.float32)


@dual_use
def table_bilinear(tables, t, nov, roughness, c):
    """Channel ``c`` of table ``t`` of a stack (T, rows, columns, C) sampled as a
    GPU samples a texture: bilinear between texel centres (column i at
    n.v = (i + 0.5) / columns, row j at r = (j + 0.5) / rows, CONVENTIONS.md)
    with clamp to edge; a single row or column is constant along its axis.
    A scalar helper compiled into Numba kernels (``pbrkit.rendering``) and into
    :func:`sample_table`'s kernel; arguments must be finite.  Texel selection
    and weights: :func:`pbrkit.core.filtering.texel_pair` (OpenGL 4.6
    sec. 8.14.2)."""
    x0, x1, ax = texel_pair(nov * tables.shape[2] - 0.5, tables.shape[2], CLAMP_TO_EDGE)
    y0, y1, ay = texel_pair(roughness * tables.shape[1] - 0.5, tables.shape[1], CLAMP_TO_EDGE)
    return ((tables[t, y0, x0, c] * (1.0 - ax) + tables[t, y0, x1, c] * ax) * (1.0 - ay)
            + (tables[t, y1, x0, c] * (1.0 - ax) + tables[t, y1, x1, c] * ax) * ay)


@kernel
def _sample_table_kernel(tables, nov, roughness, out):
    for k in range(nov.shape[0]):
        for c in range(out.shape[1]):
            out[k, c] = table_bilinear(tables, 0, nov[k], roughness[k], c)


def sample_table(table, nov, roughness):
    """Bilinear lookup of a table (rows, columns, C) (or (rows, columns)) at
    (n.v, r) with texel centres and clamp-to-edge, as a GPU samples it
    (:func:`table_bilinear`); ``nov`` and ``roughness`` broadcast.  Returns
    (..., C) (or (...) for a 2-D table) float64."""
    table = np.asarray(table)
    if table.ndim not in (2, 3) or table.shape[0] < 1 or table.shape[1] < 1:
        raise ValueError(f"table must have shape (rows, columns) or (rows, columns, C), got {table.shape}")
    channelless = table.ndim == 2
    stack = np.ascontiguousarray(table.reshape((1,) + table.shape[:2] + (-1,)), dtype=np.float64)
    x, y = np.broadcast_arrays(np.asarray(nov, dtype=np.float64), np.asarray(roughness, dtype=np.float64))
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise ValueError("table lookup coordinates (n.v, roughness) must be finite")
    out = np.empty((x.size, stack.shape[3]))
    _sample_table_kernel(stack, np.ascontiguousarray(x.reshape(-1)), np.ascontiguousarray(y.reshape(-1)), out)
    out = out.reshape(x.shape + (stack.shape[3],))
    return out[..., 0] if channelless else out


@dual_use
def env_brdf_approx(nov, roughness):
    """Karis' analytic fit of the environment BRDF (A, B) for mobile.

    B. Karis, "Physically Based Shading on Mobile", Unreal Engine blog, 2014
    (``EnvBRDFApprox``, after Lazarov 2013): with c0 = (-1, -0.0275, -0.572,
    0.022), c1 = (1, 0.0425, 1.04, -0.04), q = r c0 + c1,
    a004 = min(q_x^2, 2^(-9.28 n.v)) q_x + q_y and
    (A, B) = (-1.04, 1.04) a004 + (q_z, q_w).  r is perceptual roughness.
    Returns (A, B).
    """
    qx = -1.0 * roughness + 1.0
    qy = -0.0275 * roughness + 0.0425
    qz = -0.572 * roughness + 1.04
    qw = 0.022 * roughness - 0.04
    a004 = np.minimum(qx * qx, np.exp2(-9.28 * nov)) * qx + qy
    return -1.04 * a004 + qz, 1.04 * a004 + qw


# ------------------------------------------------------------ energy compensation


def average_albedo(roughness, visibility="height-correlated", n_mu=64, nodes=DEFAULT_NODES):
    """E_avg(r) = 2 integral_0^1 E(mu) mu dmu for the F = 1 GGX lobe (Kulla & Conty 2017, eq. 6),
    by Gauss-Legendre in mu over the same quadrature of E."""
    x, w = gauss_legendre_01(n_mu)
    ab = specular_integrals(x, roughness, visibility, nodes)
    e = ab[..., 0] + ab[..., 1]
    return 2.0 * np.sum(e * x * w, axis=-1)


def kulla_conty_tables(size=32, visibility="height-correlated", nodes=DEFAULT_NODES):
    """Kulla & Conty's tables for a size x size texel grid: E(mu, r) of shape
    (size, size) indexed [j (roughness), i (mu)] like the lookup tables, and
    E_avg(r) of shape (size,) (Kulla & Conty 2017, eqs. 4 and 6; seed 002)."""
    axis = texel_centres(size)
    ab = specular_integrals(axis, axis, visibility, nodes)
    return (ab[..., 0] + ab[..., 1]).astype(np.float32), average_albedo(axis, visibility, nodes=nodes)


def f_avg_schlick(f0):
    """Hemispherical average of Schlick's Fresnel, F_avg = 2 integral F(mu) mu dmu
    = (20 f0 + 1) / 21 (Kulla & Conty 2017, sec. 3.3; closed form)."""
    f0 = np.asarray(f0, dtype=float)
    return (20.0 * f0 + 1.0) / 21.0


def f_avg_numeric(fresnel, n_mu=64):
    """F_avg = 2 integral_0^1 F(mu) mu dmu of any ``fresnel(mu)`` by Gauss-Legendre."""
    x, w = gauss_legendre_01(n_mu)
    values = np.asarray(fresnel(x.reshape((-1,) + (1,) * 1)))
    return 2.0 * np.tensordot(w * x, values, axes=(0, 0))


def f_avg_conductor(eta, k, n_mu=64):
    """F_avg of the exact conductor Fresnel with complex IOR (eta, k) per channel (numeric)."""
    eta = np.atleast_1d(np.asarray(eta, dtype=float))
    k = np.atleast_1d(np.asarray(k, dtype=float))
    return f_avg_numeric(lambda mu: f_conductor(mu, eta, k), n_mu)


@dual_use
def kulla_conty_ms(e_o, e_i, e_avg):
    """Kulla-Conty multiple-scattering lobe for F = 1:
    f_ms = (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg))
    (Kulla & Conty 2017, "Revisiting Physically Based Shading at Imageworks", eq. 5)."""
    return (1.0 - e_o) * (1.0 - e_i) / (np.pi * np.maximum(1.0 - e_avg, 1e-12))


@dual_use
def kulla_conty_color(f_avg, e_avg):
    """Colour factor of the multiple-scattering lobe, F_avg E_avg / (1 - F_avg (1 - E_avg))
    (Kulla & Conty 2017, sec. 3.3; Jakob et al. 2014 geometric series)."""
    return f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg))


@dual_use
def filament_energy_compensation(f0, dfg2):
    """Filament's multiple-scattering scale of the specular lobe, 1 + F0 (1 / DFG2 - 1)
    (Filament documentation, sec. 4.7.2, after Fdez-Agüera 2019)."""
    return 1.0 + f0 * (1.0 / dfg2 - 1.0)
