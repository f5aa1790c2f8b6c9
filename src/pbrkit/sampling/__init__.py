"""Sampling: low-discrepancy point sets (:mod:`~pbrkit.sampling.low_discrepancy`),
the generic warps from the unit square to directions with their pdfs
(:mod:`~pbrkit.sampling.warps`: sphere, hemisphere, concentric disk, cosine,
reflection), solid-angle sampling of area-light shapes
(:mod:`~pbrkit.sampling.spherical`: rectangles, triangles, spheres, disks) and
counter-based random numbers (:mod:`~pbrkit.sampling.random`).  The names of the
first three are importable from here (``pbrkit.sampling.hammersley``,
``pbrkit.sampling.sample_cosine_hemisphere``,
``pbrkit.sampling.sample_spherical_rectangle``).  The sampling of the microfacet
distributions (GGX, Beckmann, Blinn-Phong and GTR1 normals and visible normals)
lives with each distribution in :mod:`pbrkit.microfacet`; this package imports
nothing from :mod:`pbrkit.microfacet` or :mod:`pbrkit.brdf`."""

from .low_discrepancy import *  # noqa: F401,F403
from .low_discrepancy import __all__ as _low_discrepancy_all
from .spherical import *  # noqa: F401,F403
from .spherical import __all__ as _spherical_all
from .warps import *  # noqa: F401,F403
from .warps import __all__ as _warps_all

__all__ = list(_low_discrepancy_all) + list(_warps_all) + list(_spherical_all)
