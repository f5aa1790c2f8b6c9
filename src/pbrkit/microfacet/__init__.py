"""Microfacet distributions, one unit per distribution.

Each unit holds everything about one distribution on one screen, as pbrt-v4's
TrowbridgeReitzDistribution does (Pharr, Jakob and Humphreys 2023, sec. 9.6):
its D, its Smith Lambda and G1 where it has one, the sampling of its
distribution of normals (and of visible normals) and the pdf of each sampler.

- :mod:`~pbrkit.microfacet.roughness`: the remaps from perceptual roughness
  to alpha (alpha = r^2, Kulla-Conty's and Burley's anisotropic alphas,
  Disney's masking alpha);
- :mod:`~pbrkit.microfacet.smith`: what every Smith distribution shares
  (G1 from Lambda, the separable and height-correlated G2, V = G2 / (4 n.l n.v),
  erf);
- :mod:`~pbrkit.microfacet.ggx`: GGX / Trowbridge-Reitz, isotropic and
  anisotropic (NDF and visible-normal sampling, Walter et al. 2007, Heitz 2018);
- :mod:`~pbrkit.microfacet.beckmann`: Beckmann, isotropic and anisotropic
  (NDF sampling, Walter et al. 2007; visible-normal sampling, Heitz & d'Eon 2014);
- :mod:`~pbrkit.microfacet.blinn_phong`: normalised Blinn-Phong, its masking
  through its Beckmann equivalent, exact NDF sampling;
- :mod:`~pbrkit.microfacet.gtr`: Burley's GTR family and GTR1 (Berry), the
  Disney clear coat, with NDF sampling (no closed-form Smith Lambda);
- :mod:`~pbrkit.microfacet.charlie`: Estevez and Kulla's "Charlie" sheen
  (KHR_materials_sheen): D, the fitted Lambda and the sheen visibilities, NDF
  sampling (not a model distribution: not in :data:`UNITS`).

Every term takes the distribution's alpha (or the Blinn-Phong exponent), never
perceptual roughness.  The package sits between :mod:`pbrkit.sampling` (whose
generic warps the units build on) and :mod:`pbrkit.brdf` (whose models compose
the units; ``pbrkit.brdf.distributions`` and ``pbrkit.brdf.masking`` re-export
the D and masking names of the units): core -> sampling -> microfacet -> brdf,
and nothing here imports :mod:`pbrkit.brdf`.

:data:`UNITS` maps the distribution names of the models
(:data:`pbrkit.brdf.bxdf.DISTRIBUTIONS`, and "gtr1" for the clear coat) to
their units; :func:`unit` looks one up.
"""

from . import beckmann, blinn_phong, charlie, dielectric, ggx, gtr, roughness, smith

__all__ = ["UNITS", "unit", "roughness", "smith", "ggx", "beckmann", "blinn_phong", "gtr", "charlie", "dielectric"]

#: Distribution name -> the unit module that holds its D, masking and sampling.
UNITS = {
    "ggx": ggx,
    "beckmann": beckmann,
    "blinn-phong": blinn_phong,
    "gtr1": gtr,
}


def unit(name):
    """The unit module of the distribution ``name`` (:data:`UNITS`), or ValueError naming the choices."""
    try:
        return UNITS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown microfacet distribution {name!r}; choose one of {', '.join(UNITS)}") from None
