"""Counter-based random numbers for the Monte Carlo renderer.

The numbers are windows of SplitMix64's sequence (Steele, Lea and Flood,
"Fast Splittable Pseudorandom Number Generators", OOPSLA 2014), whose k-th
output is the finaliser :func:`_mix64` of the state s + k gamma (gamma the
golden-ratio increment):

- the stream of a (seed, pixel, bounce) starts at a state hashed from them
  (:func:`_stream_key`, two finaliser rounds);
- sample j of that stream owns the :data:`DIMENSIONS` outputs after
  ``DIMENSIONS * j`` increments (:func:`_sample_key`: a multiply-add, no hashing);
- dimension d of a sample is one finaliser round (:func:`_uniform`).

So a number depends on (seed, pixel, sample, bounce, dimension) alone, never on
thread scheduling or batch layout (the same input gives the same bytes), and a
kernel that draws all the samples of a pixel hashes the pixel once and then
pays one 64-bit finaliser per number, a loop of multiplies and shifts that
compiles to SIMD instructions.
"""

from __future__ import annotations

import numpy as np

from ..core.jit import dual_use

__all__ = [
]

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
#: Numbers per sample and vertex (the reference renderer uses dimensions 0-7).
DIMENSIONS = 8
_SAMPLE_STRIDE = np.uint64(DIMENSIONS * 0x9E3779B97F4A7C15 % (1 << 64))


@dual_use(inline=True)
def _mix64(z):
    """SplitMix64's finaliser (Steele, Lea and Flood 2014): a bijective 64-bit mix."""
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@dual_use(inline=True)
def _stream_key(seed, pixel, bounce):
    """The SplitMix64 state that starts the stream of (seed, pixel, bounce)."""
    k = _mix64(np.uint64(seed) * _GOLDEN + np.uint64(pixel))
    return _mix64(k + np.uint64(bounce) * np.uint64(0x8CB92BA72F3D8DD7))


@dual_use(inline=True)
def _sample_key(stream, sample):
    """The state before sample ``sample``'s window of the stream (DIMENSIONS gammas each)."""
    return stream + np.uint64(sample) * _SAMPLE_STRIDE


@dual_use(inline=True)
def _path_key(seed, pixel, sample, bounce):
    """The key of vertex ``bounce`` of sample ``sample`` of ``pixel``: :func:`_sample_key`
    of :func:`_stream_key`."""
    return _sample_key(_stream_key(seed, pixel, bounce), sample)


@dual_use(inline=True)
def _uniform(key, dim):
    """A uniform number in [0, 1) for dimension ``dim`` (0 <= dim < DIMENSIONS) of the
    sample ``key`` (53 bits): SplitMix64's output after dim + 1 increments."""
    z = _mix64(key + np.uint64(dim + 1) * _GOLDEN)
    return np.float64(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)
