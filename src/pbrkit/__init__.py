"""pbrkit: physically based shading for real-time rendering.

Modules follow the physics: :mod:`~pbrkit.distributions` (D),
:mod:`~pbrkit.masking` (G and V), :mod:`~pbrkit.fresnel` (F),
:mod:`~pbrkit.diffuse`, :mod:`~pbrkit.models` (UE4, Filament, URP mobile,
generic Cook-Torrance), :mod:`~pbrkit.sampling` (low-discrepancy points and
warps with their pdfs) and :mod:`~pbrkit.furnace` (directional albedo).
"""

from importlib.metadata import PackageNotFoundError, version

from .material import Material

try:
    __version__ = version("pbrkit")
except PackageNotFoundError:  # running from a source tree
    __version__ = "0.0.0+unknown"

__all__ = ["Material", "__version__"]
