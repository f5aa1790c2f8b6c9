"""Image-based lighting: cube maps (:mod:`~pbrkit.ibl.cubemap`),
equirectangular maps (:mod:`~pbrkit.ibl.equirect`), real spherical harmonics
(:mod:`~pbrkit.ibl.sh`) and high-degree transforms (:mod:`~pbrkit.ibl.spectral`),
GGX prefiltering (:mod:`~pbrkit.ibl.prefilter`), irradiance
(:mod:`~pbrkit.ibl.irradiance`) and the bake (:mod:`~pbrkit.ibl.bake`, files in
:mod:`pbrkit.io.bake_files`).  The bake's entry points are importable from here;
``write_bake`` and ``load_bake`` on first use (PEP 562): the bake files sit above
the engines (:mod:`pbrkit.engines`), which build on this package."""

from .bake import Bake, bake
from .prefilter import level_of_roughness, roughness_of_level

__all__ = ["Bake", "bake", "write_bake", "load_bake", "level_of_roughness", "roughness_of_level"]


def __getattr__(name):
    if name in ("write_bake", "load_bake"):
        from ..io import bake_files

        return getattr(bake_files, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
