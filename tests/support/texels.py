"""Helpers shared by the texture-container tests (KTX2, DDS)."""

import numpy as np


def b10g11r11_tolerance(x):
    """Half a step of the 11/11/10-bit unsigned floats: 2^-7 / 2^-7 / 2^-6
    relative for normal numbers, 2^-21 / 2^-21 / 2^-20 absolute for denormals."""
    return np.maximum(np.asarray(x) * [2.0**-7, 2.0**-7, 2.0**-6], [2.0**-21, 2.0**-21, 2.0**-20])


def assert_levels_decoded(levels, back, encoding):
    """Each level read back is float32 of the written shape and equals the input
    after the format's rounding (exact for float32 / float16, half a step for
    B10G11R11)."""
    for a, b in zip(levels, back, strict=True):
        assert b.shape == a.shape and b.dtype == np.float32
        if encoding == "float32":
            assert np.array_equal(b, a.astype(np.float32))
        elif encoding == "float16":
            assert np.array_equal(b, a.astype(np.float16).astype(np.float32))
        else:
            assert np.all(np.abs(b - a) <= b10g11r11_tolerance(a))
