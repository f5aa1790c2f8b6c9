"""A generic Cook & Torrance 1982 microfacet BRDF, f = D G F / (4 n.l n.v) +
diffuse, with each term chosen by name from the method tables of
:mod:`pbrkit.brdf.terms` and :mod:`pbrkit.brdf.lobes.diffuse`:

- ``distribution``: ``ggx``, ``beckmann`` (both anisotropic when the material
  is: Kulla & Conty's alphas, anisotropy in [-1, 1]), ``blinn-phong`` (exponent
  2 / alpha^2 - 2 from the Beckmann alpha, Walter et al. 2007 eq. 30; isotropic);
- ``masking``: exact Smith ``height-correlated`` or ``separable`` for the chosen
  D (Blinn-Phong uses Beckmann's Lambda), ``schlick-ggx`` (k = alpha / 2),
  ``schlick-ggx-ue4`` (k = (r + 1)^2 / 8), ``kelemen``, or ``implicit`` (G = n.l n.v);
- ``fresnel``: ``schlick``, ``schlick-pow4``, ``ue4-sg`` (f0 from the metallic
  workflow), ``exact-conductor`` (the complex IOR eta + i k), ``exact-dielectric``
  (IOR from f0 = 0.16 reflectance^2, metallic ignored), or ``none`` (F = the
  constant ``specular_color``, white by default);
- ``diffuse``: ``lambert``, ``burley``, ``eon`` (OpenPBR's energy-preserving
  Oren-Nayar, :mod:`pbrkit.brdf.lobes.eon`) or ``none``, weighted by
  base_color (1 - metallic).

alpha = r^2 throughout (UE4's masking remap aside).
"""

from __future__ import annotations

from ...core.jit import dual_use
from ..bxdf import NO_EXTRA, BxDF
from ...microfacet.roughness import alpha_from_roughness, anisotropic_alphas
from ..fresnel import f0_from_reflectance, f0_metallic
from ..lobes.diffuse import DIFFUSES, diffuse_choice
from ..lobes.microfacet import microfacet
from ..operators import add
from ..parameters import (
    ANISOTROPY,
    BASE_COLOR,
    ETA,
    K,
    METALLIC,
    REFLECTANCE,
    ROUGHNESS,
    SPECULAR_COLOR,
    Choice,
)
from ..terms import DISTRIBUTION_TABLE, DISTRIBUTIONS, FRESNEL_TABLE, FRESNELS, MASKING_TABLE, MASKINGS
from .model import Model

__all__ = ["MODEL", "SPECULAR", "CHOICES"]

_BLINN_PHONG = DISTRIBUTIONS.index("blinn-phong")

#: The terms a cook_torrance material chooses.
CHOICES = (
    Choice("distribution", DISTRIBUTIONS, "ggx", "the normal distribution D"),
    Choice("masking", MASKINGS, "height-correlated", "the masking-shadowing G (or V)"),
    Choice("fresnel", FRESNELS, "schlick", "the Fresnel factor F"),
    Choice("diffuse", DIFFUSES, "lambert", "the diffuse lobe"),
)


@dual_use(inline="llvm")
def setup(codes, row, params, q, columns, roughness, metallic, b0, b1, b2):
    alpha = alpha_from_roughness(roughness)
    anisotropy = params[q, columns.anisotropy]
    alpha_x, alpha_y, anisotropic = alpha, alpha, False
    if anisotropy != 0.0 and codes[row, 1] != _BLINN_PHONG:
        alpha_x, alpha_y = anisotropic_alphas(alpha, anisotropy)
        anisotropic = True
    f0d = f0_from_reflectance(params[q, columns.reflectance])
    f0 = (f0_metallic(b0, metallic, f0d), f0_metallic(b1, metallic, f0d), f0_metallic(b2, metallic, f0d))
    kd = 1.0 - metallic
    eta = columns.eta
    k = columns.k
    s = columns.specular_color
    return BxDF(codes[row, 0], codes[row, 1], codes[row, 2], codes[row, 3], codes[row, 4], roughness, alpha,
                alpha_x, alpha_y, anisotropic, 0.0, metallic, (b0, b1, b2), (b0 * kd, b1 * kd, b2 * kd), f0, 1.0,
                (params[q, eta], params[q, eta + 1], params[q, eta + 2]),
                (params[q, k], params[q, k + 1], params[q, k + 2]), f0d,
                (params[q, s], params[q, s + 1], params[q, s + 2]), NO_EXTRA)


def check(values, where):
    """cook_torrance's cross-parameter rules: the exact conductor needs eta and k; a
    Blinn-Phong lobe is isotropic."""
    if values.get("fresnel") == "exact-conductor" and values.get("eta") is None:
        raise ValueError(f"{where}fresnel 'exact-conductor' needs eta and k (or conductor)")
    if values.get("distribution") == "blinn-phong" and values.get("anisotropy", 0.0) != 0.0:
        raise ValueError(f"{where}the Blinn-Phong distribution is isotropic (anisotropy needs ggx or beckmann)")


SPECULAR = microfacet(DISTRIBUTION_TABLE, MASKING_TABLE, FRESNEL_TABLE)

MODEL = Model("cook_torrance", "a Cook-Torrance microfacet BRDF with every term by name",
              (BASE_COLOR, METALLIC, ROUGHNESS, REFLECTANCE, ANISOTROPY, ETA, K, SPECULAR_COLOR) + CHOICES, setup,
              add(diffuse_choice(), SPECULAR), (None, None, None, None),
              variants=(("ggx", "height-correlated", "schlick", "lambert"), ("ggx", "separable", "none", "none"),
                        ("ggx", "height-correlated", "none", "none"), ("ggx", "separable", "none", "lambert")),
              check=check)
