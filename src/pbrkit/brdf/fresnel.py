"""Fresnel reflectance F.

Arguments: ``cos_theta`` is the cosine between the incident direction and the
(micro-)surface normal (v.h for microfacet BRDFs, n.v for IBL weights).  ``f0``
is the reflectance at normal incidence (scalar or RGB in the last axis) and
``f90`` the reflectance at grazing incidence.  Exact forms take the index of
refraction eta (outside medium / inside medium relative: eta = n_inside /
n_outside) and, for conductors, the extinction coefficient k.
"""

from __future__ import annotations

import numpy as np

from ..core.jit import dual_use

__all__ = [
    "f_schlick",
    "f_schlick_pow4",
    "f_schlick_ue4_sg",
    "f_schlick_roughness",
    "f_dielectric",
    "f_conductor",
    "f0_from_ior",
    "f0_from_reflectance",
    "ior_from_f0",
    "f0_conductor",
    "f0_metallic",
    "f90_filament",
    "CONDUCTORS",
]


@dual_use
def _one_minus_cos(cos_theta):
    return 1.0 - np.minimum(np.maximum(cos_theta, 0.0), 1.0)


@dual_use
def f_schlick(cos_theta, f0, f90=1.0):
    """Schlick's approximation F = f0 + (f90 - f0)(1 - cos)^5.

    Schlick 1994, "An Inexpensive BRDF Model for Physically-based Rendering",
    eq. 15; the f90 generalisation is Filament's (sec. 4.4.3) and Lagarde &
    de Rousiers 2014.
    """
    m = _one_minus_cos(cos_theta)
    m2 = m * m
    return f0 + (f90 - f0) * (m2 * m2 * m)


@dual_use
def f_schlick_pow4(cos_theta, f0, f90=1.0):
    """Schlick with the fourth power, F = f0 + (f90 - f0)(1 - cos)^4.

    The cheaper variant Unity's URP uses for its environment Fresnel term
    (``Pow4(1 - NoV)`` in ``BRDF.hlsl``, ``EnvironmentBRDFSpecular``).
    """
    m = _one_minus_cos(cos_theta)
    m2 = m * m
    return f0 + (f90 - f0) * (m2 * m2)


@dual_use
def f_schlick_ue4_sg(cos_theta, f0):
    """UE4's spherical-Gaussian Schlick: F = f0 + (1 - f0) 2^((-5.55473 c - 6.98316) c).

    Karis 2013, "Real Shading in Unreal Engine 4", SIGGRAPH course notes, eq. 5
    (after Lagarde 2012).
    """
    c = np.minimum(np.maximum(cos_theta, 0.0), 1.0)
    return f0 + (1.0 - f0) * np.exp2((-5.55473 * c - 6.98316) * c)


@dual_use
def f_schlick_roughness(cos_theta, f0, roughness):
    """Roughness-aware Fresnel F* = f0 + (max(1 - r, f0) - f0)(1 - cos)^5.

    Lagarde's IBL weight (S. Lagarde, "Adopting a physically based shading
    model", 2011; seed 000), used for the diffuse weight k_d = (1 - F*)(1 - metallic).
    r is perceptual roughness.
    """
    return f_schlick(cos_theta, f0, np.maximum(1.0 - roughness, f0))


@dual_use
def f_conductor(cos_theta, eta, k):
    """Exact unpolarised Fresnel reflectance for a complex index eta + i k.

    The Fresnel equations with a complex refractive index (Born & Wolf,
    "Principles of Optics", sec. 14.2; pbrt-v4 sec. 9.3.6, ``FrComplex``):
    sin^2 t = sin^2 i / eta^2, r_par = (eta cos i - cos t) / (eta cos i + cos t),
    r_perp = (cos i - eta cos t) / (cos i + eta cos t), F = (|r_par|^2 + |r_perp|^2) / 2.
    With k = 0 this is the dielectric case, total internal reflection included.
    """
    ci = np.minimum(np.maximum(cos_theta, 0.0), 1.0)
    eta_c = eta + 1j * k
    sin2_t = (1.0 - ci * ci) / (eta_c * eta_c)
    ct = np.sqrt(1.0 - sin2_t)
    r_par = (eta_c * ci - ct) / (eta_c * ci + ct)
    r_perp = (ci - eta_c * ct) / (ci + eta_c * ct)
    return 0.5 * (np.abs(r_par) ** 2 + np.abs(r_perp) ** 2)


@dual_use
def f_dielectric(cos_theta, eta):
    """Exact unpolarised Fresnel reflectance of a dielectric interface of relative IOR eta.

    :func:`f_conductor` with k = 0 (Fresnel's equations); returns 1 under total
    internal reflection (eta < 1) and at grazing incidence, and
    ((eta - 1) / (eta + 1))^2 at normal incidence.
    """
    return f_conductor(cos_theta, eta, 0.0)


@dual_use
def f0_from_ior(ior):
    """Normal-incidence reflectance ((n - 1) / (n + 1))^2 (Fresnel at cos = 1, external medium n = 1)."""
    return ((ior - 1.0) / (ior + 1.0)) ** 2


@dual_use
def ior_from_f0(f0):
    """The relative IOR n of a dielectric with normal reflectance f0, the inverse of
    :func:`f0_from_ior`: n = (1 + sqrt(f0)) / (1 - sqrt(f0)), the denominator
    clamped at 1e-6 (f0 -> 1 is an infinitely dense medium)."""
    root = np.sqrt(f0)
    return (1.0 + root) / np.maximum(1.0 - root, 1e-6)


@dual_use
def f0_conductor(eta, k):
    """Normal-incidence reflectance of a conductor of complex IOR eta + i k, clamped
    to [0, 1] to serve as a metallic-workflow base colour:
    min(F(cos = 1), 1) with F of :func:`f_conductor` (Born & Wolf sec. 14.2:
    ((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2))."""
    return np.minimum(f_conductor(1.0, eta, k), 1.0)


@dual_use
def f0_from_reflectance(reflectance):
    """Filament's dielectric f0 = 0.16 reflectance^2 (Filament sec. 4.8.3.2); reflectance 0.5 gives 0.04.

    (UE4's ``Specular`` input is linear instead: f0 = 0.08 specular; the default
    0.5 gives 0.04 in both engines.)
    """
    return 0.16 * reflectance * reflectance


@dual_use
def f0_metallic(base_color, metallic, dielectric_f0=0.04):
    """Metallic workflow f0 = lerp(dielectric_f0, base_color, metallic) (Karis 2013; glTF 2.0 Appendix B)."""
    return dielectric_f0 + (base_color - dielectric_f0) * metallic


@dual_use
def f90_filament(f0_luminance_sum):
    """Filament's specular occlusion of f90: saturate(50 * 0.33 * (f0.r + f0.g + f0.b)).

    Filament shading code (``shading_model_standard``; Schüler 2009): surfaces with
    f0 below 2% cannot reach f90 = 1.  Argument: the sum of f0's RGB channels.
    """
    return np.minimum(np.maximum(50.0 * 0.33 * f0_luminance_sum, 0.0), 1.0)


#: Complex refractive indices (eta, k) at the RGB primaries for common metals,
#: as spectral data integrated to linear sRGB by Mitsuba's renderer data files
#: (after Palik's "Handbook of Optical Constants of Solids").
CONDUCTORS = {
    "gold": ((0.143119, 0.374957, 1.44248), (3.98316, 2.38572, 1.60322)),
    "silver": ((0.155265, 0.116723, 0.138342), (4.82835, 3.12225, 2.14696)),
    "copper": ((0.200438, 0.924033, 1.10221), (3.91295, 2.45285, 2.14219)),
    "aluminium": ((1.65746, 0.880369, 0.521229), (9.22387, 6.26952, 4.83700)),
}
