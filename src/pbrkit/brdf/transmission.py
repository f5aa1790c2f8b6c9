"""The glTF material's BSDF with ``KHR_materials_transmission`` and ``KHR_materials_volume``
for the ground truth: reflection on the side of the view and transmission to the other
side, with its sampling routine and pdf (:mod:`pbrkit.rendering.estimator` calls them for a
material whose ``transmission`` is above 0 (:func:`transmissive_material`); every
other material, and the core model,
keeps the reflection-only code of :mod:`pbrkit.brdf.dispatch`).

The BSDF (the transmission README, "Transmission BTDF")::

    dielectric_brdf = fresnel_mix(ior, base = mix(diffuse_brdf(baseColor),
                                                  specular_btdf(alpha = roughness^2) baseColor,
                                                  transmission),
                                  layer = specular_brdf(alpha = roughness^2))

mixed with the metal by metallic (so a metal transmits nothing: "Transparent Metals")
and under the sheen and clear coat layers as the rest of the base.  Reflection (the
view v and the light l on one side) is the extended model's composition
(:data:`pbrkit.brdf.shading.gltf.EXTENDED_COMPOSITION`), whose diffuse colour the
setup scales by 1 - transmission.  Transmission (l on the other side) is

    f_T = (1 - metallic) transmission baseColor (1 - F_TR(v.h)) specular_btdf(v, l) S(n.v),

S the sheen's albedo scaling times the coat's 1 - clearcoat F(n.v)
(:func:`pbrkit.brdf.shading.gltf.ibl_extensions_base_scale`; 1 seen from inside a
volume, where the layers are not).  alpha = roughness^2 (glTF 2.0 Appendix B.2.2,
:func:`pbrkit.microfacet.roughness.alpha_from_roughness`, floored at 1e-3).

``specular_btdf``:

- thin-walled (``thickness`` 0, the transmission README, "Refraction" and
  "Transmission BTDF"): "two surfaces back-to-back": no refraction on average; the
  lobe "is exactly the same as the specular lobe except sampled along the line of
  sight through the surface": D V of the glTF specular lobe at the mirror image
  l' = (l_x, l_y, -l_z) of l through the surface, i.e. with the README's
  H_T = normalize(v - 2 (n.l) n + l) (its "Implementation Notes": G_T D_T / (4 |n.l|
  |n.v|)).  Light passes straight through, blurred by the roughness; sampled by the
  GGX visible normals of v (Heitz 2018), reflected, then mirrored.
- volume (``thickness`` > 0, the volume README, "Refraction" and "Implementation"):
  the rough dielectric BTDF of Walter et al. 2007 (eq. 21, in radiance form: light
  entering the denser medium is compressed by 1 / eta^2), exactly
  :func:`pbrkit.microfacet.dielectric.f_dielectric_ggx` without its own Fresnel
  (divided by 1 - F_exact(v.h)): D G |l.h| |v.h| / (|n.l| |n.v| (l.h + v.h / eta)^2)
  / eta^2, h the generalised half vector (Walter 2007 eq. 16; the README's
  H_TR = -normalize(eta_i v + eta_o l)), G the height-correlated Smith G2 of that
  module (the README's non-normative notes use the separable form).  eta is the
  relative index across the surface from v's side: ior from outside, 1 / ior from
  inside.  A smooth interface (alpha at the floor) is a Dirac delta (sample-only,
  weight (1 - F_TR) / eta^2).  The ray is refracted; the medium inside absorbs
  (Beer-Lambert, :func:`sigma_a`), which the renderer applies along the real path.

Fresnel: F_TR of the volume README, "Implementation", with the glTF dielectric's
f0 (KHR_materials_ior, KHR_materials_specular: ``b.dielectric_f0``) and F90 the
specular factor: entering a denser medium (eta >= 1, and always for thin walls)
F = f0 + (F90 - f0)(1 - |v.h|)^5; leaving it, cos theta_o = sqrt(1 - (1 - (v.h)^2) /
eta^2) on the less dense side, F = f0 + (F90 - f0)(1 - cos theta_o)^5, and F = 1
under total internal reflection (F90 unscaled, "Interaction with other
extensions").  From outside this is the composition's Schlick F exactly, so
reflection and transmission share one F and a smooth interface sends F one way and
1 - F the other.  Seen from inside a volume the reflection is F_TR D V +
(1 - F_TR) diffuse (the layers are outside).

Sampling: a mixture of the transmission technique (probability p_t) and the
composition's own (reflection only; :func:`pbrkit.brdf.dispatch.sample_wi` with
its specular/coat/diffuse split), p_t proportional to an estimate of the
transmitted albedo (1 - metallic) transmission luminance(baseColor) (1 - F_TR(n.v))
against the reflected (metallic + (1 - metallic) F_TR) and diffuse ones, clamped to
[0.05, 0.95] (1 where nothing reflects); the pdf is the mixture's.

Local frame: normal +z, the caller's (outward for a volume: the side the view is
on decides entering or leaving); wo the view, wi the light, either side.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.color import rec709_luminance
from ..core.jit import dual_use
from ..microfacet.dielectric import (
    SPECULAR,
    TRANSMISSION,
    f_dielectric_ggx,
    fresnel_dielectric,
    half_vector_dielectric,
    pdf_dielectric_ggx,
    warp_dielectric_ggx,
)
from ..microfacet.ggx import pdf_ggx_vndf, warp_ggx_vndf
from ..sampling.warps import pdf_light_from_half, reflect_xyz
from .bxdf import local_cosines
from .lobes.clearcoat import coat_local_nov
from .dispatch import bxdf_f, bxdf_pdf, lobe_probabilities, sample_wi
from .fresnel import f_schlick
from .shading.gltf import (
    SPECULAR_DV,
    SPECULAR_SLOT,
    THICKNESS_SLOT,
    TRANSMISSION_SLOT,
    ibl_extensions_base_scale,
)
from .shading.registry import COLUMNS

__all__ = ["DELTA_PDF", "P_MIN", "FRAUNHOFER_NM", "dispersion_iors", "sample_viewer_dispersion_iors",
           "transmissive_material", "volume_material",
           "sigma_a", "absorption", "interface", "fresnel_tr", "transmissive_f", "transmissive_probabilities",
           "transmissive_pdf", "transmissive_sample"]

#: The "pdf" a sample of a Dirac delta (a smooth interface) reports: so large that the
#: power heuristic gives it weight 1 against any light-sampling pdf (no light sample can
#: land on a delta), and finite, so that the weight is not inf / inf.
DELTA_PDF = 1e100
#: The least (and 1 - the largest) probability of the transmission technique.
P_MIN = 0.05
_TRANSMISSION = COLUMNS.transmission
_THICKNESS = COLUMNS.thickness
_ATT_DISTANCE = COLUMNS.attenuation_distance
_ATT_COLOR = COLUMNS.attenuation_color


#: The wavelengths (nm) of Fraunhofer's C, d and F lines, at which the Abbe number is
#: defined (V_d = (n_d - 1) / (n_F - n_C)): each RGB channel's in the ground truth of
#: KHR_materials_dispersion (:func:`dispersion_iors`).
FRAUNHOFER_NM = (656.3, 587.6, 486.1)


def dispersion_iors(ior, dispersion):
    """The IOR of each colour channel (..., 3) of a KHR_materials_dispersion volume
    (its README, "Overview"): Cauchy's n(lambda) = A + B / lambda^2 through n_d = ``ior``
    at 587.6 nm with Abbe number V_d = 20 / ``dispersion``,
    n(lambda) = max(n_d + (n_d - 1) / V_d (523655 / lambda^2 - 1.5168), 1),
    at the Fraunhofer line of each channel (:data:`FRAUNHOFER_NM`: R at C, G at d, B at F,
    the lines V_d is defined by): pbrkit's RGB reading of a spectral effect.
    ``dispersion`` 0: ``ior`` in every channel."""
    ior = np.asarray(ior, dtype=np.float64)[..., None]
    d = np.asarray(dispersion, dtype=np.float64)[..., None]
    lam = np.asarray(FRAUNHOFER_NM)
    return np.where(d > 0.0, np.maximum(ior + (ior - 1.0) * d / 20.0 * (523655.0 / (lam * lam) - 1.5168), 1.0),
                    ior + 0.0 * lam)


def sample_viewer_dispersion_iors(ior, dispersion):
    """KHR_materials_dispersion's real-time approximation (its README, "Implementation",
    and the Sample Viewer's ``getIBLVolumeRefraction``): green at ``ior``, red and blue
    half the F - C spread (n_d - 1) / V_d below and above, halfSpread = (ior - 1) 0.025
    dispersion; (..., 3)."""
    ior = np.asarray(ior, dtype=np.float64)[..., None]
    half = (ior - 1.0) * 0.025 * np.asarray(dispersion, dtype=np.float64)[..., None]
    return ior + half * np.array([-1.0, 0.0, 1.0])


@dual_use(inline=True)
def transmissive_material(codes, params, m):
    """Whether material row ``m`` of the kernels' tables transmits: its ``transmission``
    column is above 0, which only glTF's extended model declares (every other model's
    row holds the default 0 there; no model code is compared, the models being reached
    through the dispatch)."""
    return params[m, _TRANSMISSION] > 0.0


@dual_use(inline=True)
def volume_material(codes, params, m):
    """Whether material row ``m`` bounds a medium (transmits, thickness > 0)."""
    return transmissive_material(codes, params, m) and params[m, _THICKNESS] > 0.0


@dual_use(inline=True)
def _sigma(color, distance):
    # -ln(c) / d: inf for c = 0 (everything absorbed), 0 for c = 1 or d = 0 (pbrkit's +inf)
    if color >= 1.0 or distance <= 0.0:
        return 0.0
    if color <= 0.0:
        return math.inf
    return -math.log(color) / distance


@dual_use(inline=True)
def sigma_a(params, m):
    """The absorption coefficient (RGB) of material ``m``'s medium: sigma_a =
    -ln(attenuationColor) / attenuationDistance (the volume README, "Attenuation"; 0 for
    the defaults, colour 1 or distance +inf, which the ``attenuation_distance`` parameter
    writes 0)."""
    d = params[m, _ATT_DISTANCE]
    return (_sigma(params[m, _ATT_COLOR], d), _sigma(params[m, _ATT_COLOR + 1], d),
            _sigma(params[m, _ATT_COLOR + 2], d))


@dual_use(inline=True)
def _beer(sigma, t):
    # exp(-sigma t) (Beer-Lambert), 1 without absorption (also for t = inf)
    if sigma <= 0.0:
        return 1.0
    return math.exp(-sigma * t)


@dual_use(inline=True)
def absorption(params, m, t):
    """Transmittance exp(-sigma_a t) (RGB) of a path of length ``t`` inside material
    ``m``'s medium: T(x) = attenuationColor^(x / attenuationDistance) (the volume README,
    "Attenuation")."""
    s = sigma_a(params, m)
    return _beer(s[0], t), _beer(s[1], t), _beer(s[2], t)


@dual_use(inline=True)
def interface(b, woz):
    """(sign, front, thin, eta) at a view of local z ``woz``: ``sign`` turns the frame so
    that the view is above (+1 or -1); ``front``: the view is outside (always for a thin
    wall); eta: the relative index across the surface from the view's side (ior from
    outside, 1 / ior from inside; an ior below 1, KHR_materials_ior's 0, is taken as 1)."""
    ior = b.eta[0]
    if ior < 1.0:
        ior = 1.0
    thin = b.extra[THICKNESS_SLOT] <= 0.0
    sign = 1.0 if woz >= 0.0 else -1.0
    front = thin or woz >= 0.0
    eta = ior if front else 1.0 / ior
    return sign, front, thin, eta


@dual_use(inline=True)
def fresnel_tr(b, cos_vh, eta):
    """F_TR of the volume README, "Implementation" (module docstring): Schlick's F with
    the dielectric's f0 and F90 = the specular factor at |v.h| entering a denser medium,
    at the transmitted side's cos theta_o leaving it, 1 under total internal reflection."""
    f0 = b.dielectric_f0
    s = b.extra[SPECULAR_SLOT]
    c = abs(cos_vh)
    if eta >= 1.0:
        return f_schlick(c, f0, s)
    sin2 = (1.0 - c * c) / (eta * eta)
    if sin2 >= 1.0:
        return 1.0
    return f_schlick(math.sqrt(1.0 - sin2), f0, s)


@dual_use(inline=True)
def _tint(b, k):
    # (1 - metallic) transmission baseColor k ("Tinting", "Transparent Metals")
    w = (1.0 - b.metallic) * b.extra[TRANSMISSION_SLOT] * k
    return b.base[0] * w, b.base[1] * w, b.base[2] * w


@dual_use(inline=True)
def _value(b, front, thin, eta, wox, woy, woz, wix, wiy, wiz):
    # f in the turned frame (woz > 0)
    if wiz > 0.0:
        c = local_cosines(wox, woy, woz, wix, wiy, wiz)
        if front:
            return bxdf_f(b, c, 1.0, 1.0, 1.0)
        f = fresnel_tr(b, c.voh, eta)
        dv = SPECULAR_DV(b, c) * f
        k = (1.0 - f) / math.pi
        d = b.diffuse_color
        return dv + d[0] * k, dv + d[1] * k, dv + d[2] * k
    if wiz < 0.0:
        scale = ibl_extensions_base_scale(b, woz, coat_local_nov(b, wox, woy, woz)) if front else 1.0
        if thin:
            c = local_cosines(wox, woy, woz, wix, wiy, -wiz)
            k = SPECULAR_DV(b, c) * (1.0 - fresnel_tr(b, c.voh, eta))
        else:
            hx, hy, hz, etap, ok = half_vector_dielectric(wox, woy, woz, wix, wiy, wiz, eta)
            woh = wox * hx + woy * hy + woz * hz
            fe = fresnel_dielectric(woh, eta)
            btdf = f_dielectric_ggx(wox, woy, woz, wix, wiy, wiz, eta, b.alpha, b.alpha, True) / max(1.0 - fe, 1e-300)
            k = btdf * (1.0 - fresnel_tr(b, woh, eta))
        return _tint(b, k * scale)
    return 0.0, 0.0, 0.0


@dual_use(inline=True)
def transmissive_f(b, wox, woy, woz, wix, wiy, wiz):
    """The BSDF f(wo, wi) (RGB, not f cos; radiance form) in the local frame (module
    docstring), wo and wi on either side."""
    sign, front, thin, eta = interface(b, woz)
    return _value(b, front, thin, eta, wox, woy, woz * sign, wix, wiy, wiz * sign)


@dual_use(inline=True)
def transmissive_probabilities(b, woz):
    """(p_t, p_spec, p_coat): the probability of the transmission technique, and the
    specular and coat shares the composition's sampler gets of the rest (module
    docstring)."""
    sign, front, thin, eta = interface(b, woz)
    nov = abs(woz)
    p_spec0, p_coat = lobe_probabilities(b, nov)
    f = fresnel_tr(b, nov, eta)
    m = b.metallic
    t = b.extra[TRANSMISSION_SLOT]
    lum = rec709_luminance(b.base[0], b.base[1], b.base[2])
    e_s = m + (1.0 - m) * f
    e_d = (1.0 - m) * (1.0 - t) * (1.0 - f) * lum
    e_t = (1.0 - m) * t * (1.0 - f) * lum
    q = 1.0
    if e_d > 0.0:
        q = min(max(e_s / (e_s + e_d), 0.1), 0.9)
    p_t = 0.0
    if (1.0 - m) * t > 0.0:
        if e_s + e_d <= 0.0:  # nothing reflects (KHR_materials_specular's specular 0 and transmission 1)
            p_t = 1.0
        else:
            p_t = min(max(e_t / max(e_s + e_d + e_t, 1e-300), P_MIN), 1.0 - P_MIN)
    return p_t, (1.0 - p_coat) * q, p_coat


@dual_use(inline=True)
def _pdf_t(b, thin, eta, wox, woy, woz, wix, wiy, wiz):
    # the transmission technique's density at wi (wiz < 0 < woz)
    if thin:
        c = local_cosines(wox, woy, woz, wix, wiy, -wiz)
        return pdf_light_from_half(pdf_ggx_vndf(c.nov, c.noh, c.voh, b.alpha), c.voh)
    hx, hy, hz, etap, ok = half_vector_dielectric(wox, woy, woz, wix, wiy, wiz, eta)
    fe = fresnel_dielectric(wox * hx + woy * hy + woz * hz, eta)
    # the sampler refracts whenever it can (uc = 1): the branch probability 1 - F drops out
    return pdf_dielectric_ggx(wox, woy, woz, wix, wiy, wiz, eta, b.alpha, b.alpha) / max(1.0 - fe, 1e-300)


@dual_use(inline=True)
def _pdf(b, thin, eta, wox, woy, woz, wix, wiy, wiz, p_t, p_spec, p_coat):
    if wiz > 0.0:
        return (1.0 - p_t) * bxdf_pdf(b, local_cosines(wox, woy, woz, wix, wiy, wiz), p_spec, p_coat)
    if wiz < 0.0 and p_t > 0.0:
        return p_t * _pdf_t(b, thin, eta, wox, woy, woz, wix, wiy, wiz)
    return 0.0


@dual_use(inline=True)
def transmissive_pdf(b, wox, woy, woz, wix, wiy, wiz, p_t, p_spec, p_coat):
    """The mixture's solid-angle density of wi (either side) for the view wo, with the
    probabilities of :func:`transmissive_probabilities` (a smooth interface's delta has
    none: 0 there)."""
    sign, front, thin, eta = interface(b, woz)
    return _pdf(b, thin, eta, wox, woy, woz * sign, wix, wiy, wiz * sign, p_t, p_spec, p_coat)


@dual_use(inline=True)
def transmissive_sample(b, wox, woy, woz, u_lobe, u1, u2, p_t, p_spec, p_coat):
    """A direction from the mixture (module docstring) for the view wo (local, either
    side): (wix, wiy, wiz, weight f |cos| / pdf (RGB), pdf), the pdf :data:`DELTA_PDF`
    for a smooth interface's refraction; a zero weight and pdf for a failed sample."""
    sign, front, thin, eta = interface(b, woz)
    vz = woz * sign
    delta = False
    ok = True
    if u_lobe < p_t:
        if thin:
            hx, hy, hz = warp_ggx_vndf(u1, u2, wox, woy, vz, b.alpha)
            lx, ly, lz = reflect_xyz(wox, woy, vz, hx, hy, hz)
            lz = -lz
            ok = lz < 0.0  # a reflection below the horizon is a failed sample
        else:
            lx, ly, lz, f_, pdf_, flag = warp_dielectric_ggx(u1, u2, 1.0, wox, woy, vz, eta, b.alpha, b.alpha, True)
            ok = (flag & TRANSMISSION) != 0
            delta = (flag & SPECULAR) != 0
    else:
        lx, ly, lz = sample_wi(b, wox, woy, vz, (u_lobe - p_t) / (1.0 - p_t), u1, u2, p_spec, p_coat)
        ok = lz > 0.0  # the composition's reflection: below the horizon it failed
    norm = math.sqrt(lx * lx + ly * ly + lz * lz)
    ok = ok and norm > 0.0
    if ok:
        lx /= norm
        ly /= norm
        lz /= norm
    if ok and delta:
        # the smooth interface's refraction: f |cos| = (1 - F_TR(n.v)) tint S / eta^2 over its probability p_t
        scale = ibl_extensions_base_scale(b, vz, coat_local_nov(b, wox, woy, vz)) if front else 1.0
        w = _tint(b, (1.0 - fresnel_tr(b, vz, eta)) * scale / (eta * eta * p_t))
        return lx, ly, lz * sign, w, DELTA_PDF
    f = _value(b, front, thin, eta, wox, woy, vz, lx, ly, lz)
    pdf = _pdf(b, thin, eta, wox, woy, vz, lx, ly, lz, p_t, p_spec, p_coat)
    if ok and pdf > 0.0 and lz != 0.0:
        k = abs(lz) / pdf
        return lx, ly, lz * sign, (f[0] * k, f[1] * k, f[2] * k), pdf
    return 0.0, 0.0, 0.0, (0.0, 0.0, 0.0), 0.0
