"""Toon shading terms: bands of a lighting value, thresholded highlights, rim light,
and VRM MToon 1.0's shading, GI equalisation and parametric rim.

Every term except :func:`ramp_lookup` and :func:`default_thresholds` is a
``dual_use`` function (:mod:`pbrkit.core.jit`): NumPy arrays from Python, scalars
inside the styled renderer's kernel (:mod:`pbrkit.npr.render`), one formula for both.

Bands (cel shading; Lake, Marshall, Harris and Blackstein, "Stylized Rendering
Techniques for Scalable Real-Time 3D Animation", NPAR 2000, sec. 3: the diffuse
term quantised through a one-dimensional texture): a value x in [0, 1] (n.l of a
light, or the summed lighting relative to its largest possible value) is mapped to
a tone by K thresholds t_1 < ... < t_K, tone(x) = (1 / K) sum_k step_s(x - t_k),
so K thresholds give K + 1 tones 0, 1/K, ..., 1; ``softness`` s > 0 replaces each
step by a smoothstep of width s centred on its threshold (anti-aliased bands).  A
tone becomes a colour multiplier by a two-colour ramp mix(shadow colour, 1, tone)
or by a ramp image (:func:`ramp_lookup`).

MToon (VRM Consortium, "VRMC_materials_mtoon 1.0" specification, sections
Lighting, Global Illumination, Rim Lighting): shading = linearstep(-1 + toony,
1 - toony, n.l + shift), colour = mix(shade colour, lit colour, shading) x light;
GI lerps the irradiance towards the mean of the up and down directions by the
equalisation factor; the parametric rim is pow(saturate(1 - n.v + lift), power).
No roughness remap is involved in any of these.
"""

from __future__ import annotations

import numpy as np

from ..core.filtering import CLAMP_TO_EDGE, texel_pair
from ..core.jit import dual_use, select

__all__ = [
    "smooth_step_band",
    "toon_tone",
    "default_thresholds",
    "toon_shade",
    "ramp_channel",
    "ramp_lookup",
    "linearstep",
    "mtoon_shading",
    "parametric_rim",
    "gi_equalized",
    "highlight_tone",
]


@dual_use
def smooth_step_band(x, edge, softness):
    """0 below ``edge`` and 1 above it: a step, or with ``softness`` s > 0 the
    smoothstep 3u^2 - 2u^3 of u = saturate((x - edge) / s + 1/2), a transition of
    width s centred on the edge (GLSL ``smoothstep``; Lake et al. 2000 use the hard
    step, anti-aliasing by supersampling)."""
    u = np.minimum(np.maximum((x - edge) / max(softness, 1e-300) + 0.5, 0.0), 1.0)
    return select(softness > 0.0, u * u * (3.0 - 2.0 * u), select(x >= edge, 1.0, 0.0))


@dual_use
def toon_tone(x, thresholds, softness):
    """The tone in [0, 1] of a lighting value x (module docstring): the mean of the
    steps at the K ``thresholds``; K + 1 tones with hard steps."""
    k = thresholds.shape[0]
    if k == 0:
        return np.minimum(np.maximum(x, 0.0), 1.0)
    total = 0.0 * x
    for i in range(k):  # K steps, each over every pixel
        total = total + smooth_step_band(x, thresholds[i], softness)
    return total / k


@dual_use
def toon_shade(shadow, tone):
    """The colour multiplier of a tone by the two-colour ramp mix(shadow colour, 1,
    tone) (one channel, or arrays that broadcast)."""
    return shadow + (1.0 - shadow) * tone


def default_thresholds(tones):
    """Thresholds that split [0, 1] into ``tones`` equal bands: k / tones, k = 1 ..
    tones - 1 (so ``tones`` tones)."""
    tones = int(tones)
    if tones < 2:
        raise ValueError(f"toon bands need at least 2 tones; got {tones}")
    return np.arange(1, tones, dtype=np.float64) / tones


@dual_use
def ramp_channel(ramp, tone, c):
    """Channel c of a ramp (M, 3) at ``tone`` in [0, 1]: linear between texel centres
    (i + 0.5) / M, clamp to edge (a 1-D texture as Lake et al. 2000 use;
    :func:`pbrkit.core.filtering.texel_pair`)."""
    i0, i1, f = texel_pair(np.minimum(np.maximum(tone, 0.0), 1.0) * ramp.shape[0] - 0.5, ramp.shape[0],
                           CLAMP_TO_EDGE)
    return ramp[i0, c] * (1.0 - f) + ramp[i1, c] * f


def ramp_lookup(ramp, tone):
    """:func:`ramp_channel` of every channel: the ramp (M, 3) at tones (...) -> (..., 3)."""
    ramp = np.asarray(ramp, dtype=np.float64)
    tone = np.asarray(tone, dtype=np.float64)
    return np.stack([ramp_channel(ramp, tone, c) for c in range(3)], axis=-1)


@dual_use
def linearstep(a, b, x):
    """saturate((x - a) / (b - a)) (MToon 1.0, "Lighting", its ``linearstep``)."""
    return np.minimum(np.maximum((x - a) / (b - a), 0.0), 1.0)


@dual_use
def mtoon_shading(nol, shift, toony):
    """MToon 1.0's shading factor linearstep(-1 + toony, 1 - toony, n.l + shift)
    ("Lighting", Implementation; toony < 1)."""
    return linearstep(-1.0 + toony, 1.0 - toony, nol + shift)


@dual_use
def parametric_rim(nov, power, lift):
    """MToon 1.0's parametric rim pow(saturate(1 - n.v + lift), max(power, 1e-5))
    ("Rim Lighting", Parametric Rim Lighting: the epsilon the specification asks for)."""
    return np.power(np.minimum(np.maximum(1.0 - nov + lift, 0.0), 1.0), np.maximum(power, 1e-5))


@dual_use
def gi_equalized(gi, gi_up, gi_down, factor):
    """MToon 1.0's equalised global illumination lerp(gi(n), (gi(up) + gi(down)) / 2,
    factor) ("Global Illumination", Implementation)."""
    return gi + ((gi_up + gi_down) * 0.5 - gi) * factor


@dual_use
def highlight_tone(d, d_peak, threshold, softness):
    """A toon highlight: the microfacet distribution's value D(n.h) relative to its
    peak D(1), thresholded (the specular term of Lake et al. 2000's cel shading,
    here on the material's own D so the highlight keeps the lobe's shape:
    ``threshold`` 0.5 draws the lobe's half-maximum)."""
    ratio = select(d_peak > 0.0, d / np.maximum(d_peak, 1e-300), 0.0)
    return smooth_step_band(ratio, threshold, softness)
