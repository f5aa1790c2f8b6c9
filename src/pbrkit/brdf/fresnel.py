"""Fresnel reflectance F.

Arguments: ``cos_theta`` is the cosine between the incident direction and the
(micro-)surface normal (v.h for microfacet BRDFs, n.v for IBL weights).  ``f0``
is the reflectance at normal incidence (scalar or RGB in the last axis) and
``f90`` the reflectance at grazing incidence.  Exact forms take the index of
refraction eta (outside medium / inside medium relative: eta = n_inside /
n_outside) and, for conductors, the extinction coefficient k.

The thin-film iridescence Fresnel of ``KHR_materials_iridescence``
(:func:`f_iridescence`, Belcour and Barla 2017) returns RGB (linear Rec.709)
from the film's IOR and thickness (nm) and the base's f0.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import dual_use, select

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
    "XYZ_TO_REC709",
    "thin_film_sensitivity",
    "f_iridescence",
    "f_iridescence_dielectric",
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


# ------------------------------------------------------------ thin-film iridescence

#: CIE XYZ -> linear Rec.709 (sRGB primaries, D65 white), rows R, G, B: the matrix of
#: KHR_materials_iridescence ("Analytic Spectral Integration", ``XYZ_TO_REC709``,
#: written there column by column as a GLSL mat3).
XYZ_TO_REC709 = ((3.2404542, -1.5371385, -0.4985314),
                 (-0.9692660, 1.8760108, 0.0415560),
                 (0.0556434, -0.2040259, 1.0572252))
_TWO_PI = 2.0 * math.pi


@dual_use
def _sensitivity_lobe(phase, shift, value, position, variance):
    # one Gaussian lobe of the Fourier transform of a colour matching function:
    # value sqrt(2 pi var) cos(pos phase + shift) exp(-var phase^2)
    return value * math.sqrt(_TWO_PI * variance) * np.cos(position * phase + shift) * np.exp(-variance * phase * phase)


@dual_use
def thin_film_sensitivity(opd, shift_x, shift_y, shift_z):
    """The Rec.709 response (r, g, b) to the spectral fringe 2 cos(2 pi OPD / lambda + shift)
    halved, i.e. the Fourier transform of the CIE XYZ colour matching functions at the
    optical path difference ``opd`` (nm) with the phase ``shift`` of each of X, Y, Z,
    by Belcour and Barla's Gaussian fit (Belcour and Barla 2017, "A Practical
    Extension to Microfacet Theory for the Modeling of Varying Iridescence", sec. 4
    "Analytical Spectral Integration"; KHR_materials_iridescence, ``evalSensitivity``:
    the fit's coefficients, X with a second lobe, normalised by 1.0685e-7, then
    :data:`XYZ_TO_REC709`).  Its value at OPD = 0, shift 0 is the Rec.709 colour of
    the equal-energy spectrum of luminance 1, (1.205, 0.948, 0.910).  The
    specification passes the RGB phase of the base as the (X, Y, Z) shifts, channel
    by channel, and so does this function."""
    phase = _TWO_PI * opd * 1.0e-9
    x = (_sensitivity_lobe(phase, shift_x, 5.4856e-13, 1.6810e+06, 4.3278e+09)
         + _sensitivity_lobe(phase, shift_x, 9.7470e-14, 2.2399e+06, 4.5282e+09)) / 1.0685e-7
    y = _sensitivity_lobe(phase, shift_y, 4.4201e-13, 1.7953e+06, 9.3046e+09) / 1.0685e-7
    z = _sensitivity_lobe(phase, shift_z, 5.2481e-13, 2.2084e+06, 6.6121e+09) / 1.0685e-7
    m = XYZ_TO_REC709
    return (m[0][0] * x + m[0][1] * y + m[0][2] * z,
            m[1][0] * x + m[1][1] * y + m[1][2] * z,
            m[2][0] * x + m[2][1] * y + m[2][2] * z)


@dual_use
def _film_channel(r12, t121, cos2, film_ior, base_f0, phi21):
    # the second interface and the compound terms of one channel: (R23, phi23, C0, C1 / 2, C2 / 2)
    # with C_m the amplitude of the m-th fringe, I = C0 + sum_m C_m S_m
    base_ior = ior_from_f0(base_f0 + 0.0001)  # the specification's guard against f0 = 1
    r1 = ((base_ior - film_ior) / (base_ior + film_ior)) ** 2
    r23 = f_schlick(cos2, r1, 1.0)
    phi23 = select(base_ior < film_ior, math.pi, 0.0)
    r123 = np.minimum(np.maximum(r12 * r23, 1e-5), 0.9999)
    root = np.sqrt(r123)
    rs = t121 * t121 * r23 / (1.0 - r123)
    c1 = (rs - t121) * root
    return r12 + rs, c1, c1 * root, phi21 + phi23


@dual_use
def f_iridescence(cos_theta, film_ior, thickness, f0_r, f0_g, f0_b, outside_ior=1.0):
    """The thin-film iridescence Fresnel (r, g, b) of KHR_materials_iridescence
    ("Iridescence Fresnel", ``iridescent_fresnel``): Belcour and Barla 2017's
    Airy summation of a film of index ``film_ior`` (iridescenceIor) and
    ``thickness`` nm between the outside medium (``outside_ior``, 1 for air) and a
    base of normal reflectance f0 (per channel; its IOR (1 + sqrt f0) / (1 - sqrt f0),
    extinction taken as 0 even for metals, as the specification says), with the
    specification's approximations of the paper's model:

    - interfaces by Schlick's Fresnel (no s / p split): R12 = F_Schlick(R0, cos
      theta_1), R0 = ((n_film - n_out) / (n_film + n_out))^2, T121 = 1 - R12,
      R23 = F_Schlick(R1, cos theta_2) with cos theta_2 from Snell's law (total
      internal reflection into the film gives 1);
    - reflection phases 0 or pi (pi where the index drops across the interface),
      phi = phi21 + phi23;
    - the first two fringes of the Airy series in Fourier space, I = C0 + sum_{m=1,2}
      C_m S_m, C0 = R12 + R_s, R_s = T121^2 R23 / (1 - R12 R23), C_m = (R_s - T121)
      sqrt(R12 R23)^m, S_m = 2 :func:`thin_film_sensitivity` (m OPD, m phi), OPD =
      2 n_film d cos theta_2; clamped at 0.

    ``cos_theta`` is v.h (n.v for IBL).  At thickness 0 (no film) it is the base's
    Fresnel of the specification, Schlick's F(f0) (the Sample Viewer fades the film's
    IOR to the outside one over the first 0.03 nm for the same end): the Gaussian
    spectral fit does not reduce to it by itself.
    """
    c1 = np.minimum(np.maximum(cos_theta, 0.0), 1.0)
    r0 = ((film_ior - outside_ior) / (film_ior + outside_ior)) ** 2
    r12 = f_schlick(c1, r0, 1.0)
    t121 = 1.0 - r12
    sin2 = (outside_ior / film_ior) ** 2 * (1.0 - c1 * c1)
    total_reflection = sin2 >= 1.0
    cos2 = np.sqrt(np.maximum(1.0 - sin2, 0.0))
    phi21 = math.pi - select(film_ior < outside_ior, math.pi, 0.0)
    opd = 2.0 * film_ior * thickness * cos2
    c0r, c1r, c2r, pr = _film_channel(r12, t121, cos2, film_ior, f0_r, phi21)
    c0g, c1g, c2g, pg = _film_channel(r12, t121, cos2, film_ior, f0_g, phi21)
    c0b, c1b, c2b, pb = _film_channel(r12, t121, cos2, film_ior, f0_b, phi21)
    s1 = thin_film_sensitivity(opd, pr, pg, pb)
    s2 = thin_film_sensitivity(2.0 * opd, 2.0 * pr, 2.0 * pg, 2.0 * pb)
    film = thickness > 0.0
    r = select(total_reflection, 1.0, np.maximum(c0r + 2.0 * (c1r * s1[0] + c2r * s2[0]), 0.0))
    g = select(total_reflection, 1.0, np.maximum(c0g + 2.0 * (c1g * s1[1] + c2g * s2[1]), 0.0))
    b = select(total_reflection, 1.0, np.maximum(c0b + 2.0 * (c1b * s1[2] + c2b * s2[2]), 0.0))
    return (select(film, r, f_schlick(c1, f0_r, 1.0)), select(film, g, f_schlick(c1, f0_g, 1.0)),
            select(film, b, f_schlick(c1, f0_b, 1.0)))


@dual_use
def f_iridescence_dielectric(cos_theta, film_ior, thickness, base_ior, outside_ior=1.0):
    """:func:`f_iridescence` over a dielectric base of index ``base_ior``: base f0 =
    ((1 - base_ior) / (1 + base_ior))^2 (KHR_materials_iridescence, "Dielectric Base
    Material", ``iridescent_dielectric_layer``)."""
    f0 = f0_from_ior(base_ior)
    return f_iridescence(cos_theta, film_ior, thickness, f0, f0, f0, outside_ior)
