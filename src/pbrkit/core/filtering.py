"""Texel addressing for bilinear filtering, written once for every sampler of
pbrkit: lookup tables, equirect backdrops, bordered cube-map faces and glTF
textures.

OpenGL 4.6 core profile specification, sec. 8.14 "Texture Minification"
(8.14.2 "Coordinate Wrapping and Texel Selection", with the wrap modes of
its table of texel-location wrap functions) and sec. 8.15 "Texture
Magnification": along one axis of a level of N texels, texture coordinate s
becomes u = s N; texel k covers [k, k + 1) and has its centre at k + 1/2.
NEAREST reads texel wrap(floor(u)).  LINEAR reads the two texels around
t = u - 1/2 (the coordinate measured from the centre of texel 0),

    i0 = wrap(floor(t)),  i1 = wrap(floor(t) + 1),  alpha = frac(t),

and blends them as (1 - alpha) T[i0] + alpha T[i1]; two axes give bilinear
filtering.  The wrap functions (:func:`wrap_texel`), with the OpenGL enum
values as codes (the values glTF samplers store):

- ``REPEAT`` (0x2901): i mod N;
- ``CLAMP_TO_EDGE`` (0x812F): clamp(i, 0, N - 1);
- ``MIRRORED_REPEAT`` (0x8370): (N - 1) - mirror((i mod 2N) - N) with
  mirror(a) = a for a >= 0, else -(1 + a); i.e. m = i mod 2N, then m for
  m < N, else 2N - 1 - m.

For CLAMP_TO_EDGE, :func:`texel_pair` clamps the coordinate instead,
t in [0, N - 1] (texture coordinate s in [1/2N, 1 - 1/2N], the original
definition of the mode, GL_SGIS_texture_edge_clamp / OpenGL 1.2), with
i0 <= N - 2: the same filtered value, except that outside the texel centres
it is exactly the edge texel (weight 1 on it, 0 on its neighbour) rather
than a blend of two copies of it.

Each function is :func:`pbrkit.core.jit.dual_use`: NumPy on arrays from
Python, compiled for scalars into Numba kernels.
"""

from __future__ import annotations

import math

import numpy as np
from numba import types
from numba.extending import overload

from .jit import dual_use, select

__all__ = ["REPEAT", "CLAMP_TO_EDGE", "MIRRORED_REPEAT", "floor_int", "wrap_texel", "texel_pair", "linear_1d"]

#: Wrap modes: the OpenGL enum values (GL_REPEAT, GL_CLAMP_TO_EDGE, GL_MIRRORED_REPEAT), as in glTF samplers.
REPEAT = 10497
CLAMP_TO_EDGE = 33071
MIRRORED_REPEAT = 33648


def floor_int(x):
    """floor(x) as integers: int64 arrays from Python, an int inside Numba kernels."""
    return np.floor(x).astype(np.int64)


@overload(floor_int)
def _floor_int_numba(x):
    if isinstance(x, types.Float):
        def scalar_floor_int(x):
            return int(math.floor(x))

        return scalar_floor_int

    def array_floor_int(x):
        return np.floor(x).astype(np.int64)

    return array_floor_int


@dual_use
def wrap_texel(i, n, mode):
    """Texel index ``i`` (any integer) addressed into 0..n-1 by wrap ``mode``
    (OpenGL 4.6 sec. 8.14.2; module doc): ``CLAMP_TO_EDGE`` clamps,
    ``MIRRORED_REPEAT`` mirrors every other copy, any other mode repeats."""
    if mode == CLAMP_TO_EDGE:
        return np.minimum(np.maximum(i, 0), n - 1)
    if mode == MIRRORED_REPEAT:
        m = np.mod(i, 2 * n)
        return select(m < n, m, 2 * n - 1 - m)
    return np.mod(i, n)


@dual_use
def texel_pair(t, n, mode):
    """The two texels and the weight of linear filtering along one axis of
    ``n`` texels (OpenGL 4.6 sec. 8.14.2 and 8.15; module doc): (i0, i1,
    alpha), the value being (1 - alpha) T[i0] + alpha T[i1], at the
    continuous coordinate ``t`` measured in texels from the centre of texel 0
    (t = s n - 1/2 for texture coordinate s).  ``CLAMP_TO_EDGE`` clamps t to
    [0, n - 1] (with i0 <= n - 2, so a single texel is constant), the other
    modes wrap the indices (:func:`wrap_texel`)."""
    if mode == CLAMP_TO_EDGE:
        y = np.minimum(np.maximum(t, 0.0), n - 1.0)
        i0 = np.minimum(floor_int(y), max(n - 2, 0))
        return i0, np.minimum(i0 + 1, n - 1), y - i0
    i = floor_int(t)
    return wrap_texel(i, n, mode), wrap_texel(i + 1, n, mode), t - i


@dual_use
def linear_1d(table, x):
    """A 1-D table indexed like the lookup tables' columns, x in [0, 1] at texel
    centres (i + 0.5) / n, read linearly between centres and clamped to the edge
    texels (:func:`texel_pair`, CLAMP_TO_EDGE): the real-time path's tables of n.v."""
    i0, i1, f = texel_pair(x * table.shape[0] - 0.5, table.shape[0], CLAMP_TO_EDGE)
    return table[i0] * (1.0 - f) + table[i1] * f
