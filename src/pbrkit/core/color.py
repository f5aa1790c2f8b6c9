"""Colour: the sRGB transfer functions, Rec.709 luminance and tone mapping.

Linear values use the Rec.709 / sRGB primaries (``CONVENTIONS.md``, "Colour").
"""

from __future__ import annotations

import numpy as np

from ..choices import TONEMAPS as _TONEMAPS
from .jit import dual_use

__all__ = [
    "srgb_to_linear",
    "linear_to_srgb",
    "TONEMAPS",
    "tonemap",
    "luminance",
    "rec709_luminance",
]

# ----------------------------------------------------------------- transfer


def srgb_to_linear(c):
    """sRGB electro-optical transfer function (IEC 61966-2-1:1999):
    c / 12.92 for c <= 0.04045, else ((c + 0.055) / 1.055)^2.4."""
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((np.maximum(c, 0.04045) + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(x):
    """Inverse of :func:`srgb_to_linear` (IEC 61966-2-1:1999):
    12.92 x for x <= 0.0031308, else 1.055 x^(1/2.4) - 0.055."""
    x = np.asarray(x, dtype=np.float64)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.maximum(x, 0.0031308) ** (1.0 / 2.4) - 0.055)



TONEMAPS = _TONEMAPS  # pbrkit.choices
#: Rec.709 / sRGB luminance weights of linear R, G, B (ITU-R BT.709).
REC709_WEIGHTS = (0.2126, 0.7152, 0.0722)
_REC709_Y = np.array(REC709_WEIGHTS)


@dual_use
def rec709_luminance(r, g, b):
    """Rec.709 relative luminance Y = 0.2126 R + 0.7152 G + 0.0722 B of linear
    components (ITU-R BT.709), :data:`REC709_WEIGHTS`; scalars in kernels or arrays."""
    return REC709_WEIGHTS[0] * r + REC709_WEIGHTS[1] * g + REC709_WEIGHTS[2] * b


def luminance(rgb):
    """Rec.709 relative luminance Y = 0.2126 R + 0.7152 G + 0.0722 B (ITU-R BT.709,
    :data:`REC709_WEIGHTS`) of RGB in the last axis, as one matrix product."""
    return np.asarray(rgb, dtype=float) @ _REC709_Y



# ============================================================== tone mapping

_ACES_IN = np.array([[0.59719, 0.35458, 0.04823], [0.07600, 0.90834, 0.01566], [0.02840, 0.13383, 0.83777]])
_ACES_OUT = np.array([[1.60475, -0.53108, -0.07367], [-0.10208, 1.10813, -0.00605], [-0.00327, -0.07276, 1.07602]])
# AgX inset / outset, rows of the matrices acting on column vectors (Wrensch 2023 lists them column-major)
_AGX_IN = np.array([[0.842479062253094, 0.0423282422610123, 0.0423756549057051],
                    [0.0784335999999992, 0.878468636469772, 0.0784336],
                    [0.0792237451477643, 0.0791661274605434, 0.879142973793104]]).T
_AGX_OUT = np.array([[1.19687900512017, -0.0528968517574562, -0.0529716355144438],
                     [-0.0980208811401368, 1.15190312990417, -0.0980434501171241],
                     [-0.0990297440797205, -0.0989611768448433, 1.15107367264116]]).T


def tonemap_aces(x):
    """ACES filmic (RRT + sRGB ODT) as fitted by Stephen Hill (``ACESFitted`` in
    MJP's BakingLab, 2016): input matrix, (v (v + 0.0245786) - 0.000090537) /
    (v (0.983729 v + 0.4329510) + 0.238081), output matrix, clamp to [0, 1]."""
    v = x @ _ACES_IN.T
    v = (v * (v + 0.0245786) - 0.000090537) / (v * (0.983729 * v + 0.4329510) + 0.238081)
    return np.clip(v @ _ACES_OUT.T, 0.0, 1.0)


def tonemap_khronos_neutral(x):
    """Khronos PBR Neutral tone mapper (Khronos 3D Commerce, 2024, reference GLSL):
    offset = x < 0.08 ? x - 6.25 x^2 : 0.04 with x = min(r, g, b); compress the peak
    above 0.76 as 1 - d^2 / (peak + d - 0.76), d = 0.24, and desaturate by
    g = 1 - 1 / (0.15 (peak - new_peak) + 1)."""
    start, desat = 0.8 - 0.04, 0.15
    x = np.asarray(x, dtype=float)
    lo = np.min(x, axis=-1, keepdims=True)
    offset = np.where(lo < 0.08, lo - 6.25 * lo * lo, 0.04)
    c = x - offset
    peak = np.max(c, axis=-1, keepdims=True)
    d = 1.0 - start
    new_peak = 1.0 - d * d / (peak + d - start)
    scaled = c * (new_peak / np.where(peak > 0, peak, 1.0))
    g = 1.0 - 1.0 / (desat * (peak - new_peak) + 1.0)
    mixed = scaled * (1.0 - g) + new_peak * g
    return np.clip(np.where(peak < start, c, mixed), 0.0, 1.0)


def tonemap_agx(x):
    """AgX (T. J. Sobotka) in the "minimal" form of B. Wrensch (iolite engine blog,
    "Minimal AgX Implementation", 2023): inset matrix, log2 encoding over
    [-12.47393, 4.026069] EV, the 6th-order polynomial fit of the default contrast
    sigmoid, outset matrix, and the 2.2 display EOTF to return display-linear values."""
    v = np.maximum(np.asarray(x, dtype=float) @ _AGX_IN.T, 1e-10)
    lo, hi = -12.47393, 4.026069
    v = (np.clip(np.log2(v), lo, hi) - lo) / (hi - lo)
    v2 = v * v
    v4 = v2 * v2
    v = 15.5 * v4 * v2 - 40.14 * v4 * v + 31.96 * v4 - 6.868 * v2 * v + 0.4298 * v2 + 0.1191 * v - 0.00232
    v = v @ _AGX_OUT.T
    return np.clip(np.maximum(v, 0.0) ** 2.2, 0.0, 1.0)


def tonemap_reinhard(x):
    """Reinhard et al. 2002 ("Photographic Tone Reproduction for Digital Images", eq. 3), per channel: x / (1 + x)."""
    x = np.maximum(np.asarray(x, dtype=float), 0.0)
    return x / (1.0 + x)


def tonemap(image, operator="aces", exposure=0.0):
    """Display-linear values in [0, 1] of linear radiance ``image`` (..., 3) scaled by
    2^exposure; encode with the sRGB transfer function for an 8-bit file."""
    if operator not in TONEMAPS:
        raise ValueError(f"unknown tone mapper {operator!r}; choose one of {', '.join(TONEMAPS)}")
    x = np.asarray(image, dtype=float) * (2.0 ** float(exposure))
    if operator == "aces":
        return tonemap_aces(x)
    if operator == "khronos-neutral":
        return tonemap_khronos_neutral(x)
    if operator == "agx":
        return tonemap_agx(x)
    if operator == "reinhard":
        return tonemap_reinhard(x)
    return np.clip(x, 0.0, 1.0)

