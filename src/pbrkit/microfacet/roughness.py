"""Roughness remaps: from the perceptual roughness r of the material to the
width parameter alpha of a microfacet distribution.

Every distribution term, masking term and sampler of :mod:`pbrkit.microfacet`
takes the distribution's alpha, *not* perceptual roughness; the public models
map perceptual roughness r to alpha = r^2 (:func:`alpha_from_roughness`),
following Burley 2012 and Karis 2013, and anisotropy to a pair of alphas
(:func:`anisotropic_alphas`, Kulla & Conty 2017; :func:`anisotropic_alphas_burley`,
Burley 2012).  Disney's masking term alone uses the "hotter" alpha of
:func:`alpha_g_disney`.

All functions are :func:`pbrkit.core.jit.dual_use` functions: NumPy on arrays of any
broadcastable shape, and compiled for scalars inside Numba kernels.
"""

from __future__ import annotations

import numpy as np

from ..core.jit import dual_use

__all__ = [
    "ALPHA_MIN",
    "alpha_from_roughness",
    "anisotropic_alphas",
    "anisotropic_alphas_burley",
    "alpha_g_disney",
]

#: Smallest alpha the public API uses.  Keeps D finite in float64 at r = 0
#: (peak D(n) = 1 / (pi alpha^2) ~ 3.2e5) so a smooth surface is mirror-like
#: without NaN.  (Filament clamps perceptual roughness at 0.045 for fp16
#: shaders; pbrkit computes in float64 and can afford a sharper lobe.)
ALPHA_MIN = 1e-3


@dual_use
def alpha_from_roughness(roughness):
    """alpha = r^2 for perceptual roughness r, clamped below at :data:`ALPHA_MIN`.

    The perceptual remap of Burley 2012 ("Physically-Based Shading at Disney",
    SIGGRAPH course notes, sec. 5.4) adopted by Karis 2013 and glTF 2.0.
    """
    return np.maximum(roughness * roughness, ALPHA_MIN)


@dual_use
def anisotropic_alphas(alpha, anisotropy):
    """(alpha_t, alpha_b) from alpha and anisotropy in [-1, 1].

    Kulla & Conty, "Revisiting Physically Based Shading at Imageworks",
    SIGGRAPH 2017 course notes, sec. 2.2 (also Filament's parameterisation):
    alpha_t = alpha (1 + a), alpha_b = alpha (1 - a), clamped at ALPHA_MIN.
    """
    at = np.maximum(alpha * (1.0 + anisotropy), ALPHA_MIN)
    ab = np.maximum(alpha * (1.0 - anisotropy), ALPHA_MIN)
    return at, ab


@dual_use
def anisotropic_alphas_burley(alpha, anisotropy):
    """(alpha_x, alpha_y) from alpha and anisotropy in [0, 1].

    Burley 2012, Appendix B.2: aspect = sqrt(1 - 0.9 a),
    alpha_x = alpha / aspect, alpha_y = alpha * aspect.
    """
    aspect = np.sqrt(1.0 - 0.9 * anisotropy)
    return np.maximum(alpha / aspect, ALPHA_MIN), np.maximum(alpha * aspect, ALPHA_MIN)


@dual_use
def alpha_g_disney(roughness):
    """Disney's "hotness" remap for the masking term only: alpha_g = (0.5 + r / 2)^2.

    Burley 2012, sec. 5.6 (adopted by Karis 2013 for direct lighting).
    """
    return (0.5 + 0.5 * roughness) ** 2
