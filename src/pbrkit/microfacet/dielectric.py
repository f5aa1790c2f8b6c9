"""A rough dielectric interface (glass, water): the GGX microfacet BSDF of
reflection and refraction of Walter, Marschner, Li & Torrance 2007,
"Microfacet Models for Refraction through Rough Surfaces" (EGSR; cited below as
Walter 2007), with its value, its sampler and the sampler's pdf side by side,
in the arrangement of pbrt-v4's DielectricBxDF (Pharr, Jakob & Humphreys 2023,
sec. 9.7).

Frame and conventions.  Directions are unit vectors in the local shading frame
(:mod:`pbrkit.core.vec`: the normal n = +z points to the *outside*, x is the
tangent, y the bitangent); ``wo`` is the view (towards the eye), ``wi`` the
light (towards the light), both pointing away from the surface, on either side
of it.  ``eta`` is the relative index eta_inside / eta_outside of the glTF
convention (KHR_materials_ior / KHR_materials_transmission: outside is air,
ior defaults to 1.5).  A direction with z < 0 is inside, where the relative
index seen from it is 1 / eta.  ``etap`` below is the index on the side of wi
over the index on the side of wo (1 for reflection).

Roughness.  ``alpha_x``, ``alpha_y`` are the GGX widths along x and y, *not*
perceptual roughness: callers map roughness r to alpha = r^2
(:func:`pbrkit.microfacet.roughness.alpha_from_roughness`); no remap is applied
here.  When max(alpha_x, alpha_y) <= :data:`SMOOTH_ALPHA` (= ALPHA_MIN, so that
roughness 0 is a perfect interface) the interface is treated as smooth, as
pbrt-v4 does: the BSDF is a pair of Dirac deltas, which only the sampler
reports (flag :data:`SPECULAR`); :func:`f_dielectric_ggx` and
:func:`pdf_dielectric_ggx` return 0 there.  An index-matched interface
(eta == 1) is the straight pass-through delta, likewise sample-only.

Masking.  G is Smith's height-correlated G2 = 1 / (1 + Lambda(wo) + Lambda(wi))
(Heitz 2014, "Understanding the Masking-Shadowing Function in Microfacet-Based
BRDFs", JCGT 3(2), eq. 99), with the anisotropic GGX Lambda of
:func:`pbrkit.microfacet.ggx.lambda_ggx_anisotropic`, for both reflection and
transmission (pbrt-v4's choice; Walter 2007 eq. 23 uses the separable
G1(i) G1(o), and Heitz 2014 gives a different exact height-correlated form for
transmission).

Transport.  The transmission value comes in two forms that differ by 1 / etap^2:
``radiance=True`` (the default, what pbrkit's renderer traces: paths from the
camera carry radiance) is Walter 2007 eq. 21, which compresses radiance
entering a denser medium; ``radiance=False`` (importance, paths from lights)
omits the factor.  Reflection is the same in both.  The importance form obeys
f(wo, wi) / eta_i^2 = f(wi, wo) / eta_o^2, the radiance form
f(wo, wi) / eta_o^2 = f(wi, wo) / eta_i^2 (eta_i, eta_o: the indices on the
sides of wi and wo; Veach 1997, ch. 5), and only the importance form keeps
the integral of f |cos theta_i| over the sphere at or below 1 from both sides.

Sampling (pbrt-v4): a microfacet normal h from the GGX distribution of visible
normals of wo (Heitz 2018, :func:`pbrkit.microfacet.ggx.warp_ggx_vndf_anisotropic`,
which mirrors a view from inside), then reflection with probability
R = F(wo.h) and refraction with probability 1 - R (total internal reflection
gives R = 1).  A reflected direction below the horizon of wo's side, or a
refracted one on wo's side, is a failed sample (flag 0, f = pdf = 0): the pdf
integrates over the sphere to 1 minus the probability of failure, which is
small but not zero (grazing views, wide lobes).

Every function is a :func:`pbrkit.core.jit.dual_use` function: NumPy on arrays
(broadcasting), compiled for scalars inside Numba kernels.

The exact dielectric Fresnel lives here (:func:`fresnel_dielectric`) rather than
in :mod:`pbrkit.brdf.fresnel`, which :mod:`pbrkit.microfacet` may not import; it
also takes a signed cosine (either side of the interface), which
``pbrkit.brdf.fresnel.f_dielectric`` (cosines clamped to [0, 1]) does not.
"""

from __future__ import annotations

import numpy as np

from ..core.jit import dual_use, select
from ..sampling.warps import _TINY, _square, _stack, _vector3
from .ggx import d_ggx_anisotropic, lambda_ggx_anisotropic, pdf_ggx_vndf_anisotropic, warp_ggx_vndf_anisotropic
from .roughness import ALPHA_MIN
from .smith import COS_MIN

__all__ = [
    "SMOOTH_ALPHA",
    "FAILED",
    "REFLECTION",
    "TRANSMISSION",
    "SPECULAR",
    "fresnel_dielectric",
    "half_vector_dielectric",
    "f_dielectric_ggx",
    "pdf_dielectric_ggx",
    "warp_dielectric_ggx",
    "sample_dielectric_ggx",
]

#: The interface is smooth (a specular delta pair) when max(alpha_x, alpha_y) <= SMOOTH_ALPHA.
SMOOTH_ALPHA = ALPHA_MIN

#: Sample flags (the last value :func:`warp_dielectric_ggx` returns): no sample, reflection,
#: transmission, and the bit added to either for a smooth (delta) interface.
FAILED = 0
REFLECTION = 1
TRANSMISSION = 2
SPECULAR = 4


@dual_use
def fresnel_dielectric(cos_theta_i, eta):
    """Exact unpolarised Fresnel reflectance of a dielectric interface (Walter 2007, eq. 22).

    ``cos_theta_i`` is the *signed* cosine of the incident direction with the
    (micro-)normal that points outside; ``eta`` = eta_inside / eta_outside.  A
    negative cosine is incidence from inside, with relative index 1 / eta.
    F = (1/2) (g - c)^2 / (g + c)^2 (1 + (c (g + c) - 1)^2 / (c (g - c) + 1)^2),
    c = |cos theta_i|, g^2 = eta_rel^2 - 1 + c^2 (eq. 22); g^2 < 0 is total
    internal reflection, F = 1.  The average of the s and p reflectances of
    Fresnel's equations (Born & Wolf sec. 1.5.2).
    """
    c0 = np.minimum(np.maximum(cos_theta_i, -1.0), 1.0)
    e = select(c0 < 0.0, 1.0 / eta, eta)
    c = np.abs(c0)
    g2 = e * e - 1.0 + c * c
    g = np.sqrt(np.maximum(g2, 0.0))
    a = (g - c) / np.maximum(g + c, _TINY)
    b = (c * (g + c) - 1.0) / np.maximum(c * (g - c) + 1.0, _TINY)
    return select(g2 <= 0.0, 1.0, np.minimum(0.5 * a * a * (1.0 + b * b), 1.0))


@dual_use
def half_vector_dielectric(wox, woy, woz, wix, wiy, wiz, eta):
    """The generalised half vector of the pair (wo, wi), turned to the outside (h.z >= 0).

    Reflection (wo, wi on one side): h ~ wo + wi (Walter 2007, eq. 13).
    Refraction: h ~ -(eta_o wo + eta_i wi) (eq. 16), i.e. ~ wo + etap wi with
    etap = eta_i / eta_o = eta for wo outside, 1 / eta for wo inside.
    Returns (hx, hy, hz, etap, ok): ok is False where h is undefined (a
    direction in the tangent plane, or wo + etap wi = 0).
    """
    reflect = woz * wiz > 0.0
    etap = select(reflect, 1.0, select(woz > 0.0, eta, 1.0 / eta))
    hx = wox + etap * wix
    hy = woy + etap * wiy
    hz = woz + etap * wiz
    length2 = hx * hx + hy * hy + hz * hz
    inv = select(hz < 0.0, -1.0, 1.0) / np.sqrt(np.maximum(length2, _TINY))
    ok = (woz != 0.0) & (wiz != 0.0) & (length2 > 1e-24)
    return hx * inv, hy * inv, hz * inv, etap, ok


@dual_use
def _lobe(wox, woy, woz, wix, wiy, wiz, hx, hy, hz, etap, reflect, eta, alpha_x, alpha_y, radiance):
    """(f, pdf) of the pair (wo, wi) through the microfacet normal h (h.z >= 0), no validity checks.

    Reflection (Walter 2007, eq. 20 with eq. 14's Jacobian 1 / (4 |wo.h|)):
    f = D G F / (4 |cos o| |cos i|), pdf = D_wo(h) F / (4 |wo.h|).
    Refraction (eq. 21, Jacobian eq. 17 as |wi.h| / (wi.h + wo.h / etap)^2):
    f = D G (1 - F) |wi.h| |wo.h| / (|cos i| |cos o| (wi.h + wo.h / etap)^2), divided
    by etap^2 for radiance; pdf = D_wo(h) (1 - F) |wi.h| / (wi.h + wo.h / etap)^2.
    D_wo is the GGX distribution of visible normals (Heitz 2018, eq. 3).
    """
    # a smooth interface is handled by the callers: keep its (unused) terms finite
    alpha_x = np.maximum(alpha_x, SMOOTH_ALPHA)
    alpha_y = np.maximum(alpha_y, SMOOTH_ALPHA)
    woh = wox * hx + woy * hy + woz * hz
    wih = wix * hx + wiy * hy + wiz * hz
    cos_o = np.maximum(np.abs(woz), COS_MIN)
    cos_i = np.maximum(np.abs(wiz), COS_MIN)
    fresnel = fresnel_dielectric(woh, eta)
    d = d_ggx_anisotropic(hz, hx, hy, alpha_x, alpha_y)
    g = 1.0 / (1.0 + lambda_ggx_anisotropic(cos_o, wox, woy, alpha_x, alpha_y)
               + lambda_ggx_anisotropic(cos_i, wix, wiy, alpha_x, alpha_y))
    pdf_h = pdf_ggx_vndf_anisotropic(wox, woy, woz, hx, hy, hz, alpha_x, alpha_y)
    f_r = d * g * fresnel / (4.0 * cos_i * cos_o)
    pdf_r = pdf_h * fresnel / np.maximum(4.0 * np.abs(woh), _TINY)
    denominator = np.maximum((wih + woh / etap) ** 2, _TINY)
    f_t = d * g * (1.0 - fresnel) * np.abs(wih * woh) / (cos_i * cos_o * denominator)
    f_t = select(radiance, f_t / (etap * etap), f_t)
    pdf_t = pdf_h * (1.0 - fresnel) * np.abs(wih) / denominator
    return select(reflect, f_r, f_t), select(reflect, pdf_r, pdf_t)


@dual_use
def _rough_pair(wox, woy, woz, wix, wiy, wiz, eta, alpha_x, alpha_y, radiance):
    """(f, pdf) of :func:`f_dielectric_ggx` and :func:`pdf_dielectric_ggx` together."""
    hx, hy, hz, etap, ok = half_vector_dielectric(wox, woy, woz, wix, wiy, wiz, eta)
    woh = wox * hx + woy * hy + woz * hz
    wih = wix * hx + wiy * hy + wiz * hz
    # microfacets seen from behind by either direction scatter nothing (the chi+ factors of
    # Walter 2007's G1, eq. 34)
    front = (woh * woz > 0.0) & (wih * wiz > 0.0)
    rough = (np.maximum(alpha_x, alpha_y) > SMOOTH_ALPHA) & (eta != 1.0)
    valid = ok & front & rough
    f, pdf = _lobe(wox, woy, woz, wix, wiy, wiz, hx, hy, hz, etap, woz * wiz > 0.0, eta, alpha_x, alpha_y,
                   radiance)
    return select(valid, f, 0.0), select(valid, pdf, 0.0)


@dual_use
def f_dielectric_ggx(wox, woy, woz, wix, wiy, wiz, eta, alpha_x, alpha_y, radiance=True):
    """The rough dielectric BSDF f(wo, wi) (reflection and transmission), GGX, anisotropic.

    Reflection: D G F / (4 |cos o| |cos i|) (Walter 2007, eq. 20); transmission:
    D G (1 - F) |wi.h| |wo.h| / (|cos i| |cos o| (wi.h + wo.h / etap)^2) (eq. 21 divided
    through by eta_i^2), times 1 / etap^2 when ``radiance`` (eq. 21 exactly; module
    docstring).  h is the generalised half vector (eqs. 13 and 16,
    :func:`half_vector_dielectric`), F = :func:`fresnel_dielectric` (wo.h, eta) (eq. 22),
    D the anisotropic GGX (eq. 33; Heitz 2014 eq. 85), G the height-correlated
    Smith G2 (Heitz 2014 eq. 99).  alpha is the GGX width (alpha = roughness^2 at
    the callers).  0 for microfacets facing away from either direction, for a
    direction in the tangent plane and for a smooth interface (delta: sample-only).
    """
    return _rough_pair(wox, woy, woz, wix, wiy, wiz, eta, alpha_x, alpha_y, radiance)[0]


@dual_use
def pdf_dielectric_ggx(wox, woy, woz, wix, wiy, wiz, eta, alpha_x, alpha_y):
    """The solid-angle pdf of wi under :func:`warp_dielectric_ggx` for the view wo.

    D_wo(h) (Heitz 2018, eq. 3) times the branch probability and the Jacobian of
    h -> wi: reflection F / (4 |wo.h|) (Walter 2007, eq. 14), refraction
    (1 - F) |wi.h| / (wi.h + wo.h / etap)^2 (eq. 17 divided through by eta_o^2;
    Walter 2007 eq. 38 composes the two).  alpha is the GGX width (alpha =
    roughness^2 at the callers).  0 where :func:`f_dielectric_ggx` is 0
    (smooth interfaces included).
    """
    return _rough_pair(wox, woy, woz, wix, wiy, wiz, eta, alpha_x, alpha_y, False)[1]


@dual_use
def warp_dielectric_ggx(u1, u2, uc, wox, woy, woz, eta, alpha_x, alpha_y, radiance=True):
    """Sample wi for the view wo: (wix, wiy, wiz, f, pdf, flag).

    pbrt-v4's DielectricBxDF::Sample_f (Pharr, Jakob & Humphreys 2023, sec. 9.7):
    h from the GGX visible normals of wo with (u1, u2) (Heitz 2018; a view from
    inside is mirrored), R = F(wo.h) (Walter 2007, eq. 22); if uc < R (always under
    total internal reflection), wi = 2 (wo.h) h - wo (reflection, eq. 39 of Walter
    2007 with the VNDF in place of D), else wi is wo refracted through h with
    etap (Snell's law, eq. 40).  f and pdf are those of :func:`f_dielectric_ggx`
    and :func:`pdf_dielectric_ggx` at wi, so f |cos i| / pdf = G2 / G1(wo) <= 1
    (importance; times 1 / etap^2 for radiance through refraction).  ``flag``:
    :data:`REFLECTION` or :data:`TRANSMISSION`, plus :data:`SPECULAR` for a smooth
    interface (max alpha <= :data:`SMOOTH_ALPHA`, or eta == 1), where h = n and
    f = R / |cos i| or (1 - R) / |cos i| (/ etap^2), pdf = R or 1 - R (the
    weights of the delta pair; f and pdf are those of Dirac deltas, so
    f |cos i| / pdf is the meaningful product); :data:`FAILED` (with f = pdf = 0)
    when the direction lands on the wrong side.  alpha is the GGX width
    (alpha = roughness^2 at the callers).
    """
    smooth = (np.maximum(alpha_x, alpha_y) <= SMOOTH_ALPHA) | (eta == 1.0)
    vx, vy, vz = warp_ggx_vndf_anisotropic(u1, u2, wox, woy, woz, np.maximum(alpha_x, SMOOTH_ALPHA),
                                           np.maximum(alpha_y, SMOOTH_ALPHA))
    hx = select(smooth, 0.0, vx)
    hy = select(smooth, 0.0, vy)
    hz = select(smooth, 1.0, vz)
    woh = wox * hx + woy * hy + woz * hz
    fresnel = fresnel_dielectric(woh, eta)
    # refraction through h (Walter 2007, eq. 40), h turned to wo's side
    outside = woh > 0.0
    etap = select(outside, eta, 1.0 / eta)
    side = select(outside, 1.0, -1.0)
    cos_o = np.abs(woh)
    sin2_t = (1.0 - cos_o * cos_o) / (etap * etap)
    tir = sin2_t >= 1.0
    cos_t = np.sqrt(np.maximum(1.0 - sin2_t, 0.0))
    k = (cos_o / etap - cos_t) * side
    reflect = (uc < fresnel) | tir
    wix = select(reflect, 2.0 * woh * hx - wox, -wox / etap + k * hx)
    wiy = select(reflect, 2.0 * woh * hy - woy, -woy / etap + k * hy)
    wiz = select(reflect, 2.0 * woh * hz - woz, -woz / etap + k * hz)
    inv = 1.0 / np.sqrt(np.maximum(wix * wix + wiy * wiy + wiz * wiz, _TINY))
    wix = wix * inv
    wiy = wiy * inv
    wiz = wiz * inv
    valid = select(reflect, woz * wiz > 0.0, woz * wiz < 0.0) & (woh * woz > 0.0)
    f, pdf = _lobe(wox, woy, woz, wix, wiy, wiz, hx, hy, hz, select(reflect, 1.0, etap), reflect, eta,
                   alpha_x, alpha_y, radiance)
    branch = select(reflect, fresnel, 1.0 - fresnel)
    cos_i = np.maximum(np.abs(wiz), COS_MIN)
    delta_scale = select(radiance, select(reflect, 1.0, 1.0 / (etap * etap)), 1.0)
    f = select(smooth, branch / cos_i * delta_scale, f)
    pdf = select(smooth, branch, pdf)
    flag = select(reflect, REFLECTION, TRANSMISSION) + select(smooth, SPECULAR, 0)
    valid = valid & (pdf > 0.0)
    return wix, wiy, wiz, select(valid, f, 0.0), select(valid, pdf, 0.0), select(valid, flag, FAILED)


def sample_dielectric_ggx(u, uc, wo, eta, alpha_x, alpha_y, radiance=True):
    """NumPy wrapper of :func:`warp_dielectric_ggx`: ``u`` (..., 2) and ``uc`` (...) in [0, 1],
    ``wo`` (..., 3) unit, scalar ``eta`` > 0 and alphas >= 0 (0: smooth).  Returns
    (wi (..., 3), f, pdf, flag)."""
    u1, u2 = _square(u)
    uc = np.asarray(uc, dtype=np.float64)
    if not np.all((uc >= 0.0) & (uc <= 1.0)):
        raise ValueError("uc must lie in [0, 1]")
    if not (np.isfinite(eta) and eta > 0.0):
        raise ValueError("eta must be positive and finite")
    if not all(np.isfinite(a) and a >= 0.0 for a in (alpha_x, alpha_y)):
        raise ValueError("alpha_x and alpha_y must be finite and >= 0")
    wix, wiy, wiz, f, pdf, flag = warp_dielectric_ggx(u1, u2, uc, *_vector3(wo, "wo"), np.float64(eta),
                                                      np.float64(alpha_x), np.float64(alpha_y), bool(radiance))
    return _stack(wix, wiy, wiz), f, pdf, np.asarray(flag)
