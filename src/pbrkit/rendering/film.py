"""The film of the ground truth: per pixel and channel, the shifted sums of its samples,
and the estimate and standard error of the mean they give.

Summing x and x^2 and taking E[x^2] - E[x]^2 cancels catastrophically where the
variance is small against the mean (a bright, smooth pixel).  The shifted-data
algorithm (Chan, Golub and LeVeque, "Algorithms for Computing the Sample Variance:
Analysis and Recommendations", 1983) sums the samples less a shift K close to their
mean instead; K = the pixel's first sample::

    S = sum_j (x_j - K),    Q = sum_j (x_j - K)^2    (j = 1 .. N)

                S                   Q / N - (S / N)^2                    var
    mean = K + ---,      var = N -------------------,      stderr = sqrt(---)
                N                        N - 1                            N

:func:`shifted_add` adds samples to (S, Q); it is a ``dual_use`` function, so the
kernels call it on each pixel's scalars and the wavefront engine on whole arrays of
pixels.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..core.jit import dual_use

__all__ = ["Film", "new_film", "shifted_add", "store_pixel", "film_estimate"]


class Film(NamedTuple):
    """The kernels' output, (pixels, 3) each: the shift K (each pixel's first sample), the
    sum of (x - K) and the sum of (x - K)^2 of its samples."""

    shift: np.ndarray
    sum: np.ndarray
    sumsq: np.ndarray


def new_film(pixels):
    """A :class:`Film` of ``pixels`` pixels, zero."""
    return Film(np.zeros((pixels, 3)), np.zeros((pixels, 3)), np.zeros((pixels, 3)))


@dual_use
def shifted_add(k, s, q, x, n):
    """(S, Q) of a pixel (module docstring) with ``n`` more samples of value x added,
    shift k: (s + n (x - k), q + n (x - k)^2).  Scalars in the kernels, arrays from
    Python."""
    d = x - k
    return s + n * d, q + n * (d * d)


@dual_use
def store_pixel(film, pix, k0, k1, k2, s0, s1, s2, q0, q1, q2):
    """Write pixel ``pix`` of ``film``: its shift K, sum of (x - K) and sum of (x - K)^2,
    per channel."""
    film.shift[pix, 0] = k0
    film.shift[pix, 1] = k1
    film.shift[pix, 2] = k2
    film.sum[pix, 0] = s0
    film.sum[pix, 1] = s1
    film.sum[pix, 2] = s2
    film.sumsq[pix, 0] = q0
    film.sumsq[pix, 1] = q1
    film.sumsq[pix, 2] = q2


def film_estimate(film, spp):
    """(mean, standard error of the mean) per pixel and channel of ``film`` after ``spp``
    samples per pixel (module docstring; the variance clamped at 0 against rounding)."""
    mean_shifted = film.sum / spp
    mean = film.shift + mean_shifted
    var = np.maximum(film.sumsq / spp - mean_shifted * mean_shifted, 0.0) * (spp / max(spp - 1, 1))
    return mean, np.sqrt(var / spp)
