"""Shading models composed from the terms of :mod:`distributions`, :mod:`masking`,
:mod:`fresnel` and :mod:`diffuse`.

Every model is a function ``model(l, v, n, material, ...)`` of unit directions
in the last axis of arrays (l toward the light, v toward the eye, n the
normal; any broadcastable leading shapes) and a :class:`pbrkit.Material`
whose fields broadcast against those leading shapes.  It returns the BRDF
value f (RGB, shape (..., 3)) -- *not* f cos -- and 0 where l or v is below
the surface.  Perceptual roughness r maps to alpha = r^2 (clamped at
``ALPHA_MIN``) in every model; other remaps are stated per model.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from ..core.jit import dual_use, parallel_kernel, select
from ..core.vec import dot, half_vector, shading_frame
from .diffuse import burley, burley_subsurface, lambert
from .distributions import (
    alpha_from_roughness,
    anisotropic_alphas,
    anisotropic_alphas_burley,
    d_beckmann,
    d_beckmann_anisotropic,
    d_blinn_phong,
    d_ggx,
    d_ggx_anisotropic,
    d_gtr1,
    phong_exponent_from_beckmann_alpha,
)
from .fresnel import (
    f0_metallic,
    f90_filament,
    f_conductor,
    f_schlick,
    f_schlick_pow4,
    f_schlick_ue4_sg,
)
from .masking import (
    g2_height_correlated,
    g2_kelemen,
    g2_schlick_ggx,
    g2_separable,
    k_schlick_from_alpha,
    k_ue4_direct,
    lambda_beckmann,
    lambda_beckmann_anisotropic,
    lambda_ggx,
    lambda_ggx_anisotropic,
    v_smith_ggx_height_correlated,
    visibility,
)
from .material import Material

__all__ = [
    "Cosines",
    "frame_cosines",
    "combine_lobes",
    "ue4",
    "ue4_specular",
    "filament",
    "filament_specular",
    "urp_mobile",
    "urp_specular",
    "cook_torrance",
    "disney",
    "MODELS",
    "DISTRIBUTIONS",
    "MASKINGS",
    "FRESNELS",
    "DIFFUSES",
]


class Cosines(NamedTuple):
    """Cosines of the shading frame; tangent-frame components are None without a tangent."""

    nol: np.ndarray
    nov: np.ndarray
    noh: np.ndarray
    voh: np.ndarray
    tol: np.ndarray | None = None
    bol: np.ndarray | None = None
    tov: np.ndarray | None = None
    bov: np.ndarray | None = None
    toh: np.ndarray | None = None
    boh: np.ndarray | None = None


def frame_cosines(l, v, n, t=None, tangent_frame=False):
    """Dot products n.l, n.v, n.h, v.h (= l.h), and with ``tangent_frame`` the
    tangent-frame components (t from ``t`` or :func:`pbrkit.vec.orthonormal_basis`)."""
    l = np.asarray(l, dtype=float)
    v = np.asarray(v, dtype=float)
    n = np.asarray(n, dtype=float)
    h = half_vector(l, v)
    cos = dict(nol=dot(n, l), nov=dot(n, v), noh=dot(n, h), voh=np.maximum(dot(v, h), 0.0))
    if tangent_frame:
        t, b, n = shading_frame(n, t)
        cos.update(tol=dot(t, l), bol=dot(b, l), tov=dot(t, v), bov=dot(b, v), toh=dot(t, h), boh=dot(b, h))
    return Cosines(**cos)


@dual_use
def combine_lobes(nol, nov, diffuse_color, diffuse_factor, specular, fresnel):
    """f = diffuse_color * diffuse_factor + specular * F, zero below the horizon.

    The metallic-workflow sum of Karis 2013 / Filament sec. 4.4 / glTF 2.0
    Appendix B, with diffuse_color = base_color (1 - metallic) and ``specular``
    the Fresnel-free microfacet lobe D V.
    """
    return select((nol > 0.0) & (nov > 0.0), diffuse_color * diffuse_factor + specular * fresnel, 0.0)


def _channel(x):
    """Append an axis so per-pixel scalars broadcast against RGB."""
    return np.asarray(x, dtype=float)[..., None]


# --------------------------------------------------------------------------- UE4


@dual_use
def ue4_specular(nol, nov, noh, roughness):
    """UE4 specular lobe without Fresnel (Karis 2013, "Real Shading in Unreal Engine 4"):
    D_GGX(alpha = r^2) times V = G2 / (4 n.l n.v) with separable Schlick-GGX
    G1 and the direct-light remap k = (r + 1)^2 / 8."""
    alpha = alpha_from_roughness(roughness)
    g2 = g2_schlick_ggx(nol, nov, k_ue4_direct(roughness))
    return d_ggx(noh, alpha) * visibility(g2, nol, nov)


@dual_use
def _ue4_channel(nol, nov, voh, specular, base_color, metallic, dielectric_f0):
    f0 = f0_metallic(base_color, metallic, dielectric_f0)
    return combine_lobes(nol, nov, base_color * (1.0 - metallic), lambert(nol), specular,
                         f_schlick_ue4_sg(voh, f0))


@parallel_kernel
def _ue4_kernel(l, v, n, base_color, metallic, roughness, dielectric_f0, out):
    for i in numba.prange(l.shape[0]):
        hx = l[i, 0] + v[i, 0]
        hy = l[i, 1] + v[i, 1]
        hz = l[i, 2] + v[i, 2]
        hl = np.sqrt(hx * hx + hy * hy + hz * hz)
        if hl > 1e-12:
            hx /= hl
            hy /= hl
            hz /= hl
        else:
            hx, hy, hz = n[i, 0], n[i, 1], n[i, 2]
        nol = n[i, 0] * l[i, 0] + n[i, 1] * l[i, 1] + n[i, 2] * l[i, 2]
        nov = n[i, 0] * v[i, 0] + n[i, 1] * v[i, 1] + n[i, 2] * v[i, 2]
        noh = n[i, 0] * hx + n[i, 1] * hy + n[i, 2] * hz
        voh = max(v[i, 0] * hx + v[i, 1] * hy + v[i, 2] * hz, 0.0)
        specular = ue4_specular(nol, nov, noh, roughness[i])
        for c in range(3):
            out[i, c] = _ue4_channel(nol, nov, voh, specular, base_color[i, c], metallic[i], dielectric_f0[i])


def _flat(x, shape, channels=None):
    # Always a writable C-contiguous float64 array, so the kernel is compiled for one
    # signature only (broadcast views are read-only, which Numba types separately).
    full = shape + ((channels,) if channels else ())
    flat = np.broadcast_to(np.asarray(x, dtype=np.float64), full).reshape((-1,) + full[len(shape):])
    return np.require(flat, dtype=np.float64, requirements=["C", "W"])


def ue4(l, v, n, material: Material, backend: str = "numba"):
    """UE4 shading model (Karis 2013): Lambert diffuse + GGX + Schlick-GGX with
    k = (r + 1)^2 / 8 + the spherical-Gaussian Schlick Fresnel, metallic
    workflow with dielectric f0 = 0.16 reflectance^2 (0.08 specular in UE4 terms).

    ``backend="numba"`` evaluates with a parallel compiled kernel (the fast
    path); ``backend="numpy"`` composes the same terms with NumPy.
    """
    if backend == "numpy":
        c = frame_cosines(l, v, n)
        specular = ue4_specular(c.nol, c.nov, c.noh, material.roughness)
        return _ue4_channel(_channel(c.nol), _channel(c.nov), _channel(c.voh), _channel(specular),
                            material.base_color, _channel(material.metallic), _channel(material.dielectric_f0))
    if backend != "numba":
        raise ValueError(f"unknown backend {backend!r}; use 'numba' or 'numpy'")
    l, v, n = (np.asarray(x, dtype=np.float64) for x in (l, v, n))
    shape = np.broadcast_shapes(l.shape[:-1], v.shape[:-1], n.shape[:-1], material.base_color.shape[:-1],
                                np.shape(material.metallic), np.shape(material.roughness),
                                np.shape(material.reflectance))
    out = np.empty((int(np.prod(shape)), 3))
    _ue4_kernel(_flat(l, shape, 3), _flat(v, shape, 3), _flat(n, shape, 3), _flat(material.base_color, shape, 3),
                _flat(material.metallic, shape), _flat(material.roughness, shape),
                _flat(material.dielectric_f0, shape), out)
    return out.reshape(shape + (3,))


# ---------------------------------------------------------------------- Filament


@dual_use
def filament_specular(nol, nov, noh, alpha):
    """Filament's isotropic specular lobe without Fresnel (Filament documentation,
    sec. 4.4): D_GGX times the height-correlated Smith-GGX visibility."""
    return d_ggx(noh, alpha) * v_smith_ggx_height_correlated(nol, nov, alpha)


@dual_use
def _filament_specular_anisotropic(c_nol, c_nov, c_noh, tol, bol, tov, bov, toh, boh, alpha_t, alpha_b):
    # Filament sec. 4.9.1: anisotropic GGX with the anisotropic height-correlated Smith term.
    g2 = g2_height_correlated(lambda_ggx_anisotropic(c_nol, tol, bol, alpha_t, alpha_b),
                              lambda_ggx_anisotropic(c_nov, tov, bov, alpha_t, alpha_b))
    return d_ggx_anisotropic(c_noh, toh, boh, alpha_t, alpha_b) * visibility(g2, c_nol, c_nov)


def filament(l, v, n, material: Material, diffuse: str = "lambert", t=None):
    """Filament's standard model (Filament documentation, sec. 4): Lambert or
    Burley diffuse, GGX (anisotropic when ``material.anisotropy`` != 0, with the
    tangent ``t`` or a built frame), height-correlated Smith-GGX visibility and
    Schlick Fresnel with f0 = 0.16 reflectance^2 (1 - metallic) + base metallic
    and f90 = saturate(50 * 0.33 * sum(f0)) (Filament's specular occlusion)."""
    anisotropic = bool(np.any(material.anisotropy != 0.0))
    c = frame_cosines(l, v, n, t=t, tangent_frame=anisotropic)
    alpha = material.alpha
    if anisotropic:
        at, ab = anisotropic_alphas(alpha, material.anisotropy)
        specular = _filament_specular_anisotropic(c.nol, c.nov, c.noh, c.tol, c.bol, c.tov, c.bov, c.toh, c.boh,
                                                  at, ab)
    else:
        specular = filament_specular(c.nol, c.nov, c.noh, alpha)
    f0 = f0_metallic(material.base_color, _channel(material.metallic), _channel(material.dielectric_f0))
    fresnel = f_schlick(_channel(c.voh), f0, _channel(f90_filament(np.sum(f0, axis=-1))))
    diffuse_factor = _diffuse_factor(diffuse, c, material.roughness)
    return combine_lobes(_channel(c.nol), _channel(c.nov), material.base_color * (1.0 - _channel(material.metallic)),
                         _channel(diffuse_factor), _channel(specular), fresnel)


def _diffuse_factor(name, c, roughness):
    if name == "lambert":
        return lambert(c.nol)
    if name == "burley":
        return burley(c.nol, c.nov, c.voh, roughness)
    if name == "none":
        return np.zeros_like(c.nol)
    raise ValueError(f"unknown diffuse {name!r}; choose one of {', '.join(DIFFUSES)}")


# -------------------------------------------------------------------- Unity URP


@dual_use
def urp_specular(noh, loh, alpha):
    """Unity URP's "minimalist Cook-Torrance" specular term (URP ``BRDF.hlsl``,
    ``DirectBRDFSpecular``; after Renaldas Zioma, "Optimizing PBR for Mobile",
    SIGGRAPH 2015): alpha^2 / (d^2 max(0.1, (l.h)^2) (4 alpha + 2)) with
    d = (n.h)^2 (alpha^2 - 1) + 1.  Unity's lights carry a factor pi, so the
    BRDF value is this term divided by pi (see :func:`urp_mobile`)."""
    a2 = alpha * alpha
    c = np.minimum(np.maximum(noh, 0.0), 1.0)
    d = a2 * c * c + (1.0 - c) * (1.0 + c)  # = c^2 (alpha^2 - 1) + 1 without cancellation
    return select(noh > 0.0, a2 / (d * d * np.maximum(0.1, loh * loh) * (4.0 * alpha + 2.0)), 0.0)


def urp_mobile(l, v, n, material: Material):
    """Unity URP mobile BRDF: diffuse = base (0.96 (1 - metallic)), specular colour
    lerp(0.04, base, metallic) (URP ``kDielectricSpec``), specular term
    :func:`urp_specular`, alpha = r^2 (URP ``PerceptualRoughnessToRoughness``).

    Unity's punctual lights are pi times brighter than radiometric ones, so the
    returned BRDF is (diffuse + specular_color * term) / pi.  The dielectric f0
    is URP's fixed 0.04 (``material.reflectance`` is not used).
    """
    c = frame_cosines(l, v, n)
    metallic = _channel(material.metallic)
    specular_color = f0_metallic(material.base_color, metallic, 0.04)
    diffuse_color = material.base_color * (0.96 * (1.0 - metallic))
    term_ = urp_specular(c.noh, c.voh, material.alpha) / np.pi
    return combine_lobes(_channel(c.nol), _channel(c.nov), diffuse_color, 1.0 / np.pi, _channel(term_),
                         specular_color)


# ------------------------------------------------------------ generic Cook-Torrance

DISTRIBUTIONS = ("ggx", "beckmann", "blinn-phong")
MASKINGS = ("height-correlated", "separable", "schlick-ggx", "schlick-ggx-ue4", "kelemen", "implicit")
FRESNELS = ("schlick", "schlick-pow4", "ue4-sg", "exact-conductor", "exact-dielectric", "none")
DIFFUSES = ("lambert", "burley", "none")


def _check_choice(kind, name, choices):
    if name not in choices:
        raise ValueError(f"unknown {kind} {name!r}; choose one of {', '.join(choices)}")


def cook_torrance(l, v, n, material: Material, distribution="ggx", masking="height-correlated",
                  fresnel="schlick", diffuse="lambert", t=None):
    """Cook & Torrance 1982 microfacet BRDF f = D G F / (4 n.l n.v) (+ diffuse),
    with each term chosen by name:

    - ``distribution``: ``ggx``, ``beckmann`` (both anisotropic when
      ``material.anisotropy`` != 0), ``blinn-phong`` (exponent
      2 / alpha^2 - 2 from the Beckmann alpha, Walter et al. 2007 eq. 30).
    - ``masking``: exact Smith ``height-correlated`` or ``separable`` for the
      chosen D (Blinn-Phong uses Beckmann's Lambda); ``schlick-ggx`` (k =
      alpha / 2), ``schlick-ggx-ue4`` (k = (r + 1)^2 / 8), ``kelemen``, or
      ``implicit`` (G = n.l n.v).
    - ``fresnel``: ``schlick``, ``schlick-pow4``, ``ue4-sg`` (f0 from the
      metallic workflow), ``exact-conductor`` (material.eta, material.k),
      ``exact-dielectric`` (IOR from f0 = 0.16 reflectance^2, metallic ignored),
      or ``none`` (F = 1).
    - ``diffuse``: ``lambert``, ``burley`` or ``none``, weighted by
      base_color (1 - metallic).
    """
    _check_choice("distribution", distribution, DISTRIBUTIONS)
    _check_choice("masking", masking, MASKINGS)
    _check_choice("fresnel", fresnel, FRESNELS)
    _check_choice("diffuse", diffuse, DIFFUSES)
    anisotropic = bool(np.any(material.anisotropy != 0.0)) and distribution != "blinn-phong"
    c = frame_cosines(l, v, n, t=t, tangent_frame=anisotropic)
    alpha = material.alpha

    if anisotropic:
        at, ab = anisotropic_alphas(alpha, material.anisotropy)
        if distribution == "ggx":
            d = d_ggx_anisotropic(c.noh, c.toh, c.boh, at, ab)
            lam = lambda_ggx_anisotropic
        else:
            d = d_beckmann_anisotropic(c.noh, c.toh, c.boh, at, ab)
            lam = lambda_beckmann_anisotropic
        lambda_l = lam(c.nol, c.tol, c.bol, at, ab)
        lambda_v = lam(c.nov, c.tov, c.bov, at, ab)
    else:
        if distribution == "ggx":
            d = d_ggx(c.noh, alpha)
            lam = lambda_ggx
        elif distribution == "beckmann":
            d = d_beckmann(c.noh, alpha)
            lam = lambda_beckmann
        else:
            d = d_blinn_phong(c.noh, phong_exponent_from_beckmann_alpha(alpha))
            lam = lambda_beckmann
        lambda_l = lam(c.nol, alpha)
        lambda_v = lam(c.nov, alpha)

    if masking == "height-correlated":
        g2 = g2_height_correlated(lambda_l, lambda_v)
    elif masking == "separable":
        g2 = g2_separable(lambda_l, lambda_v)
    elif masking == "schlick-ggx":
        g2 = g2_schlick_ggx(c.nol, c.nov, k_schlick_from_alpha(alpha))
    elif masking == "schlick-ggx-ue4":
        g2 = g2_schlick_ggx(c.nol, c.nov, k_ue4_direct(material.roughness))
    elif masking == "kelemen":
        g2 = g2_kelemen(c.nol, c.nov, c.voh)
    else:
        g2 = np.maximum(c.nol, 0.0) * np.maximum(c.nov, 0.0)
    specular = d * visibility(g2, c.nol, c.nov)

    metallic = _channel(material.metallic)
    f0 = f0_metallic(material.base_color, metallic, _channel(material.dielectric_f0))
    voh = _channel(c.voh)
    if fresnel == "schlick":
        fr = f_schlick(voh, f0)
    elif fresnel == "schlick-pow4":
        fr = f_schlick_pow4(voh, f0)
    elif fresnel == "ue4-sg":
        fr = f_schlick_ue4_sg(voh, f0)
    elif fresnel == "exact-conductor":
        if material.eta is None:
            raise ValueError("fresnel='exact-conductor' needs material.eta and material.k")
        fr = f_conductor(voh, material.eta, material.k)
    elif fresnel == "exact-dielectric":
        root = np.sqrt(_channel(material.dielectric_f0))
        fr = f_conductor(voh, (1.0 + root) / np.maximum(1.0 - root, 1e-6), 0.0) + 0.0 * f0
    else:
        fr = np.ones_like(f0) * np.ones_like(voh)

    diffuse_factor = _diffuse_factor(diffuse, c, material.roughness)
    return combine_lobes(_channel(c.nol), _channel(c.nov), material.base_color * (1.0 - metallic),
                         _channel(diffuse_factor), _channel(specular), fr)


# ------------------------------------------------------------- Disney principled


def disney(l, v, n, material: Material, t=None):
    """Disney's principled BRDF (Burley 2012, "Physically-Based Shading at Disney",
    sec. 5 and Appendix B; the BRDF Explorer's ``disney.brdf``).

    f = (1 - metallic) [base (mix(Burley, subsurface, s)) + sheen] + D_s F_s V_s + clearcoat:

    - diffuse: :func:`pbrkit.diffuse.burley` mixed with
      :func:`pbrkit.diffuse.burley_subsurface` by ``material.subsurface``;
    - sheen: (1 - l.h)^5 sheen mix(1, C_tint, sheen_tint), with
      C_tint = base / luminance(base) (luminance 0.3 R + 0.6 G + 0.1 B);
    - specular: anisotropic GGX with alpha = r^2 and Burley's aspect
      (:func:`pbrkit.distributions.anisotropic_alphas_burley`, anisotropy in
      [0, 1]), separable exact Smith G (the BRDF Explorer's version, without the
      2012 notes' alpha_g "hotness" remap), Schlick Fresnel from
      C_spec0 = mix(0.08 specular mix(1, C_tint, specular_tint), base, metallic)
      where 0.08 specular = 0.16 reflectance^2 (``material.dielectric_f0``);
    - clear coat: 0.25 clearcoat D_GTR1(alpha = mix(0.1, 0.001, gloss)) times
      Schlick F with f0 = 0.04 times separable Smith V with alpha = 0.25.
    """
    anisotropy = np.asarray(material.anisotropy)
    if np.any(anisotropy < 0.0):
        raise ValueError("disney: Material.anisotropy must be in [0, 1] (Burley's aspect parameterisation)")
    anisotropic = bool(np.any(anisotropy != 0.0))
    c = frame_cosines(l, v, n, t=t, tangent_frame=anisotropic)
    alpha = material.alpha
    if anisotropic:
        ax, ay = anisotropic_alphas_burley(alpha, anisotropy)
        d = d_ggx_anisotropic(c.noh, c.toh, c.boh, ax, ay)
        lambda_l = lambda_ggx_anisotropic(c.nol, c.tol, c.bol, ax, ay)
        lambda_v = lambda_ggx_anisotropic(c.nov, c.tov, c.bov, ax, ay)
    else:
        d = d_ggx(c.noh, alpha)
        lambda_l = lambda_ggx(c.nol, alpha)
        lambda_v = lambda_ggx(c.nov, alpha)
    specular = d * visibility(g2_separable(lambda_l, lambda_v), c.nol, c.nov)

    base = material.base_color
    luminance = np.sum(base * np.array([0.3, 0.6, 0.1]), axis=-1, keepdims=True)
    tint = np.where(luminance > 0.0, base / np.where(luminance > 0.0, luminance, 1.0), 1.0)
    metallic = _channel(material.metallic)
    spec_tint = _channel(material.specular_tint)
    f0 = f0_metallic(base, metallic, _channel(material.dielectric_f0) * (1.0 + (tint - 1.0) * spec_tint))
    loh = _channel(c.voh)
    roughness = material.roughness
    subsurface = material.subsurface
    diffuse_factor = (burley(c.nol, c.nov, c.voh, roughness) * (1.0 - subsurface)
                      + burley_subsurface(c.nol, c.nov, c.voh, roughness) * subsurface)
    lobes = combine_lobes(_channel(c.nol), _channel(c.nov), base * (1.0 - metallic), _channel(diffuse_factor),
                          _channel(specular), f_schlick(loh, f0))
    sheen_color = _channel(material.sheen) * (1.0 + (tint - 1.0) * _channel(material.sheen_tint))
    sheen = f_schlick(loh, 0.0, 1.0) * sheen_color * (1.0 - metallic)
    coat_alpha = 0.1 + (0.001 - 0.1) * material.clearcoat_gloss
    coat_v = visibility(g2_separable(lambda_ggx(c.nol, 0.25), lambda_ggx(c.nov, 0.25)), c.nol, c.nov)
    coat = _channel(0.25 * material.clearcoat * d_gtr1(c.noh, coat_alpha) * coat_v) * f_schlick(loh, 0.04)
    valid = _channel((c.nol > 0.0) & (c.nov > 0.0))
    return lobes + np.where(valid, sheen + coat, 0.0)


MODELS = {
    "ue4": ue4,
    "filament": filament,
    "urp_mobile": urp_mobile,
    "cook_torrance": cook_torrance,
    "disney": disney,
}
