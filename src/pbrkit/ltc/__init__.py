"""Linearly Transformed Cosines (Heitz, Dupuy, Hill, Neubelt 2016, "Real-Time
Polygonal-Light Shading with Linearly Transformed Cosines", ACM TOG 35(4)).

- :mod:`~pbrkit.ltc.polygon`: the closed-form integral of the clamped cosine
  max(0, z) / pi over a spherical polygon (the form factor; Lambert 1760,
  Arvo 1995, Heitz et al. 2016 eq. 11) after exact clipping to the upper
  hemisphere, its edge terms and the vector form factor.
- :mod:`~pbrkit.ltc.distribution`: the LTC distribution D(w) = D_o(w_o)
  |d w_o / d w| (Heitz et al. 2016, eqs. 1-3): evaluation, sampling, pdf,
  polygon integrals, and the matrix parameterisation of the published fit
  with the normalised-inverse storage of the ``ltc_1`` table.

Directions are in the local shading frame of ``docs/CONVENTIONS.md`` (normal
+z, directions pointing away from the surface).  No roughness remap is
involved anywhere here: the matrices are what a fit produces.
"""

from .distribution import *  # noqa: F401,F403
from .distribution import __all__ as _distribution_all
from .polygon import *  # noqa: F401,F403
from .polygon import __all__ as _polygon_all

__all__ = list(_polygon_all) + list(_distribution_all)
