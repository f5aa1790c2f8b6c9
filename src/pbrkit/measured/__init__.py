"""Measured materials: MERL binary BRDFs (:mod:`~pbrkit.measured.merl`: read,
write, look up, sample any BRDF onto the MERL grid) and the fitting of pbrkit's
models to them (:mod:`~pbrkit.measured.fit`: GGX or Disney parameters by
weighted least squares, with the fit error).

Matusik et al. 2003, "A Data-Driven Reflectance Model"; Ngan, Durand and
Matusik 2005, "Experimental Analysis of BRDF Models".
"""

from .merl import (
    MERL_INTERPOLATIONS,
    MERL_SCALE,
    MERL_SHAPE,
    MerlBRDF,
    half_diff_angles,
    merl_bin_centres,
    merl_bytes,
    merl_directions,
    merl_indices,
    merl_table,
    read_merl,
    write_merl,
)

__all__ = [
    "MERL_SHAPE", "MERL_SCALE", "MERL_INTERPOLATIONS", "MerlBRDF", "half_diff_angles", "merl_indices",
    "merl_bin_centres", "merl_directions", "merl_table", "merl_bytes", "read_merl", "write_merl",
    "FIT_MODELS", "FIT_WEIGHTINGS", "FitResult", "fit_measured",
]


_FIT_NAMES = ("FIT_MODELS", "FIT_WEIGHTINGS", "FitResult", "fit_measured")


def __getattr__(name):  # the fitting (SciPy, the compiled models) is imported on first use
    if name in _FIT_NAMES:
        from . import fit

        return getattr(fit, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
