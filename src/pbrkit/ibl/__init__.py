"""Image-based lighting: cube maps (:mod:`~pbrkit.ibl.cubemap`),
equirectangular maps (:mod:`~pbrkit.ibl.equirect`), real spherical harmonics
(:mod:`~pbrkit.ibl.sh`) and high-degree transforms (:mod:`~pbrkit.ibl.spectral`),
GGX prefiltering (:mod:`~pbrkit.ibl.prefilter`), irradiance
(:mod:`~pbrkit.ibl.irradiance`) and the bake (:mod:`~pbrkit.ibl.bake`).  The bake's
files are written and read by :mod:`pbrkit.io.bake_files` (``write_bake``,
``load_bake``; also ``pbrkit.write_bake`` and ``pbrkit.load_bake``), which sits
above this package and the engines (:mod:`pbrkit.engines`) that build on it."""

from .bake import Bake, bake
from .prefilter import level_of_roughness, roughness_of_level

__all__ = ["Bake", "bake", "level_of_roughness", "roughness_of_level"]
