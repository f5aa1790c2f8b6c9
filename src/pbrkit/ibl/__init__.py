"""Image-based lighting: cube maps (:mod:`~pbrkit.ibl.cubemap`),
equirectangular maps (:mod:`~pbrkit.ibl.equirect`), real spherical harmonics
(:mod:`~pbrkit.ibl.sh`) and high-degree transforms (:mod:`~pbrkit.ibl.spectral`),
GGX prefiltering (:mod:`~pbrkit.ibl.prefilter`), irradiance
(:mod:`~pbrkit.ibl.irradiance`) and the bake (:mod:`~pbrkit.ibl.bake`, files in
:mod:`pbrkit.io.bake_files`).  The bake's entry points are importable from here."""

from ..io.bake_files import load_bake, write_bake
from .bake import Bake, bake
from .prefilter import level_of_roughness, roughness_of_level

__all__ = ["Bake", "bake", "write_bake", "load_bake", "level_of_roughness", "roughness_of_level"]
