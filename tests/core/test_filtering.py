"""Texel addressing of bilinear filtering (pbrkit.core.filtering).

Independent references: hand-computed texel indices and weights for each
wrap mode of OpenGL 4.6 sec. 8.14.2 (REPEAT, CLAMP_TO_EDGE,
MIRRORED_REPEAT, including negative coordinates), and a linear ramp that
bilinear filtering must reproduce between texel centres.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest

from pbrkit.core.filtering import (
    CLAMP_TO_EDGE,
    MIRRORED_REPEAT,
    REPEAT,
    floor_int,
    texel_pair,
    wrap_texel,
)


def test_wrap_modes_are_the_opengl_enums():
    assert (REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT) == (0x2901, 0x812F, 0x8370)


@pytest.mark.parametrize("mode, expected", [
    # i = -4 .. 7 on 3 texels
    (REPEAT, [2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1]),
    (CLAMP_TO_EDGE, [0, 0, 0, 0, 0, 1, 2, 2, 2, 2, 2, 2]),
    # mirrored: ... 0 1 2 | 2 1 0 | 0 1 2 | 2 1 0 ...: texel -1 mirrors texel 0
    (MIRRORED_REPEAT, [2, 2, 1, 0, 0, 1, 2, 2, 1, 0, 0, 1]),
])
def test_wrap_texel_by_hand(mode, expected):
    i = np.arange(-4, 8)
    assert list(wrap_texel(i, 3, mode)) == expected
    assert [int(wrap_texel(int(k), 3, mode)) for k in i] == expected


# (t, n, mode) -> (i0, i1, alpha): t is measured in texels from the centre of texel 0
CASES = [
    (1.25, 4, REPEAT, (1, 2, 0.25)),
    (1.25, 4, CLAMP_TO_EDGE, (1, 2, 0.25)),
    (1.25, 4, MIRRORED_REPEAT, (1, 2, 0.25)),
    (-0.25, 4, REPEAT, (3, 0, 0.75)),            # across the seam to the last texel
    (-0.25, 4, MIRRORED_REPEAT, (0, 0, 0.75)),   # texel -1 is texel 0 mirrored
    (-0.25, 4, CLAMP_TO_EDGE, (0, 1, 0.0)),      # clamped to the centre of texel 0
    (3.5, 4, REPEAT, (3, 0, 0.5)),
    (3.5, 4, MIRRORED_REPEAT, (3, 3, 0.5)),
    (3.5, 4, CLAMP_TO_EDGE, (2, 3, 1.0)),        # clamped to the centre of texel 3, weight 1 on it
    (-9.75, 4, REPEAT, (2, 3, 0.25)),            # floor -10 = 2 mod 4
    (-9.75, 4, MIRRORED_REPEAT, (1, 0, 0.25)),   # -10 mod 8 = 6 -> 1, -9 mod 8 = 7 -> 0
    (0.7, 1, CLAMP_TO_EDGE, (0, 0, 0.0)),        # a single texel is constant
    (0.7, 1, REPEAT, (0, 0, 0.7)),
]


@pytest.mark.parametrize("t, n, mode, expected", CASES)
def test_texel_pair_by_hand(t, n, mode, expected):
    i0, i1, a = texel_pair(t, n, mode)
    assert (int(i0), int(i1)) == expected[:2]
    assert float(a) == pytest.approx(expected[2], abs=1e-15)


@numba.njit
def _compiled(t, n, mode, out_i, out_a):
    for k in range(t.shape[0]):
        i0, i1, a = texel_pair(t[k], n, mode)
        out_i[k, 0] = i0
        out_i[k, 1] = i1
        out_i[k, 2] = wrap_texel(floor_int(t[k]), n, mode)
        out_a[k] = a


@pytest.mark.parametrize("mode", [REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT])
def test_compiled_and_numpy_agree(mode):
    rng = np.random.default_rng(5)
    t = np.concatenate([rng.uniform(-20.0, 20.0, 500), np.arange(-6.0, 7.0, 0.5)])
    out_i = np.zeros((t.size, 3), dtype=np.int64)
    out_a = np.zeros(t.size)
    _compiled(t, 5, mode, out_i, out_a)
    i0, i1, a = texel_pair(t, 5, mode)
    assert np.array_equal(out_i[:, 0], i0) and np.array_equal(out_i[:, 1], i1)
    assert np.array_equal(out_i[:, 2], wrap_texel(floor_int(t), 5, mode))
    assert np.array_equal(out_a, a)
    assert np.all((a >= 0.0) & (a <= 1.0)) and np.all((i0 >= 0) & (i0 < 5) & (i1 >= 0) & (i1 < 5))


@pytest.mark.parametrize("mode", [REPEAT, CLAMP_TO_EDGE, MIRRORED_REPEAT])
def test_linear_ramp_is_reproduced_between_texel_centres(mode):
    n = 6
    texels = 2.0 + 3.0 * np.arange(n)  # T[k] = 2 + 3 k at the centre k + 0.5
    s = np.linspace(0.5 / n, 1.0 - 0.5 / n, 101)  # texture coordinates between the first and last centres
    i0, i1, a = texel_pair(s * n - 0.5, n, mode)
    value = (1.0 - a) * texels[i0] + a * texels[i1]
    assert np.allclose(value, 2.0 + 3.0 * (s * n - 0.5), atol=1e-12)
