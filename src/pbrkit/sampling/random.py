"""Counter-based random numbers for the Monte Carlo renderer.

Randomness comes from a counter-based hash (SplitMix64's finaliser;
Steele, Lea and Flood, "Fast Splittable Pseudorandom Number Generators",
OOPSLA 2014) of (seed, pixel, sample, bounce, dimension), so results do not
depend on thread scheduling: the same input gives the same bytes.
"""

from __future__ import annotations

import numpy as np

from ..core.jit import dual_use

__all__ = [
]

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)


@dual_use
def _mix64(z):
    """SplitMix64's finaliser (Steele, Lea and Flood 2014): a bijective 64-bit mix."""
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@dual_use
def _path_key(seed, pixel, sample, bounce):
    k = _mix64(np.uint64(seed) * _GOLDEN + np.uint64(pixel))
    k = _mix64(k ^ (np.uint64(sample) * np.uint64(0xD1B54A32D192ED03)))
    return _mix64(k + np.uint64(bounce) * np.uint64(0x8CB92BA72F3D8DD7))


@dual_use
def _uniform(key, dim):
    """A uniform number in [0, 1) for dimension ``dim`` of the stream ``key`` (53 bits)."""
    z = _mix64(key + np.uint64(dim + 1) * _GOLDEN)
    return np.float64(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)

