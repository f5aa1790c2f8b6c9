"""Float encodings of GPU texture formats: float16 and B10G11R11_UFLOAT_PACK32.

- :func:`to_float16` converts to IEEE 754 binary16 with round-to-nearest-even
  (NumPy's float64 -> float16 conversion rounds once, correctly).  Finite
  magnitudes above the largest finite half, 65504, would become infinity;
  pbrkit clamps them to +-65504 and emits a :class:`RangeWarning`.  Infinities
  and NaN are kept (both are representable).
- :func:`pack_b10g11r11` / :func:`unpack_b10g11r11` implement
  ``VK_FORMAT_B10G11R11_UFLOAT_PACK32`` (= ``DXGI_FORMAT_R11G11B10_FLOAT``):
  red in bits 0..10, green in bits 11..21 (unsigned 11-bit floats: 5-bit
  exponent, 6-bit mantissa, no sign) and blue in bits 22..31 (unsigned 10-bit
  float: 5-bit exponent, 5-bit mantissa).  Encoding and conversion rules are
  those of the Vulkan specification, "Unsigned 11-Bit Floating-Point Numbers"
  and "Unsigned 10-Bit Floating-Point Numbers" (identical to OpenGL 4.6,
  sec. 2.3.4.3-4):

  value = 0                              if E = 0 and M = 0
        = 2^-14 (M / 2^m)                if E = 0 and M != 0 (denormal)
        = 2^(E - 15) (1 + M / 2^m)       if 0 < E < 31
        = +inf                           if E = 31 and M = 0
        = NaN                            if E = 31 and M != 0

  with m = 6 (11-bit) or 5 (10-bit) mantissa bits.  "Finite values are
  rounded to the closest representable finite value" (pbrkit: ties to even);
  negative values and -inf become 0, finite values above the maximum
  (65024 for 11-bit, 64512 for 10-bit) become the maximum, +inf stays +inf
  and NaN becomes a positive NaN (pbrkit writes all mantissa bits set).
  Negative inputs and finite overflow emit a :class:`RangeWarning`.

The relative rounding error of normal numbers is at most 2^-(m+1):
2^-7 for the 11-bit and 2^-6 for the 10-bit channel.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..core.errors import InputError

__all__ = [
    "RangeWarning",
    "FLOAT16_MAX",
    "UF11_MAX",
    "UF10_MAX",
    "to_float16",
    "float_to_ufloat",
    "ufloat_to_float",
    "pack_b10g11r11",
    "unpack_b10g11r11",
]


#: Largest finite IEEE binary16 value, (2 - 2^-10) 2^15.
FLOAT16_MAX = 65504.0
#: Largest finite unsigned 11-bit float, (1 + 63/64) 2^15.
UF11_MAX = 65024.0
#: Largest finite unsigned 10-bit float, (1 + 31/32) 2^15.
UF10_MAX = 64512.0

_EXP_BIAS = 15
_EXP_INF = 31


class RangeWarning(UserWarning):
    """Values were clamped to fit the range of a texture format."""


def to_float16(values):
    """IEEE binary16 copy of ``values`` (round to nearest, ties to even).

    Finite values with magnitude above :data:`FLOAT16_MAX` are clamped to
    +-65504 (with a :class:`RangeWarning`) instead of overflowing to infinity.
    """
    x = np.asarray(values, dtype=np.float64)
    overflow = np.isfinite(x) & (np.abs(x) > FLOAT16_MAX)
    if np.any(overflow):
        warnings.warn(
            f"{int(np.count_nonzero(overflow))} value(s) exceed the float16 range; "
            f"clamped to +-{FLOAT16_MAX:g}",
            RangeWarning,
            stacklevel=2,
        )
        x = np.where(overflow, np.copysign(FLOAT16_MAX, x), x)
    return x.astype(np.float16)


def float_to_ufloat(values, mantissa_bits):
    """Bit patterns (uint32) of unsigned 11-bit (``mantissa_bits=6``) or
    10-bit (``mantissa_bits=5``) floats, per the Vulkan conversion rules in
    the module docstring.  Rounding is to nearest, ties to even."""
    if mantissa_bits not in (5, 6):
        raise InputError(f"mantissa_bits must be 5 (10-bit) or 6 (11-bit), got {mantissa_bits}")
    x = np.asarray(values, dtype=np.float64)
    m = mantissa_bits
    one = 1 << m
    max_code = (30 << m) | (one - 1)  # E = 30, M all ones
    nan = np.isnan(x)
    pos_inf = np.isposinf(x)
    finite_pos = np.isfinite(x) & (x > 0.0)
    negative = (x < 0.0) & np.isfinite(x)
    max_value = np.ldexp(1.0 + (one - 1) / one, 30 - _EXP_BIAS)
    overflow = finite_pos & (x > max_value)
    if np.any(negative) or np.any(overflow):
        warnings.warn(
            f"{int(np.count_nonzero(negative))} negative and {int(np.count_nonzero(overflow))} "
            f"too large value(s) clamped to the unsigned {m + 5}-bit float range [0, {max_value:g}]",
            RangeWarning,
            stacklevel=2,
        )
    xs = np.where(finite_pos, x, 1.0)
    # Normal numbers: x = s 2^e with s in [1, 2); frexp gives f in [0.5, 1).
    f, e = np.frexp(xs)
    e = e - 1
    s = 2.0 * f
    # (s - 1) 2^m is exact in float64; rint rounds ties to even.  A mantissa
    # that rounds up to 2^m carries into the exponent through the addition.
    normal_code = ((e + _EXP_BIAS).astype(np.int64) << m) + np.rint((s - 1.0) * one).astype(np.int64)
    # Denormals (x < 2^-14): M = x / 2^-14 * 2^m, rounding up to 2^m gives E = 1.
    denormal_code = np.rint(np.ldexp(xs, _EXP_BIAS - 1 + m)).astype(np.int64)
    code = np.where(e + _EXP_BIAS >= 1, normal_code, denormal_code)
    code = np.minimum(code, max_code)
    code = np.where(finite_pos, code, 0)
    code = np.where(pos_inf, _EXP_INF << m, code)
    code = np.where(nan, (_EXP_INF << m) | (one - 1), code)
    return code.astype(np.uint32)


def ufloat_to_float(codes, mantissa_bits):
    """Values (float32) of unsigned 11-bit (``mantissa_bits=6``) or 10-bit
    (``mantissa_bits=5``) float bit patterns; the decoding is exact."""
    if mantissa_bits not in (5, 6):
        raise InputError(f"mantissa_bits must be 5 (10-bit) or 6 (11-bit), got {mantissa_bits}")
    c = np.asarray(codes).astype(np.int64)
    m = mantissa_bits
    one = 1 << m
    if np.any((c < 0) | (c >= (32 << m))):
        raise InputError(f"unsigned {m + 5}-bit float codes must lie in [0, {(32 << m) - 1}]")
    exponent = c >> m
    mantissa = c & (one - 1)
    normal = np.ldexp(1.0 + mantissa / one, exponent - _EXP_BIAS)
    denormal = np.ldexp(mantissa / one, 1 - _EXP_BIAS)
    value = np.where(exponent == 0, denormal, normal)
    value = np.where(exponent == _EXP_INF, np.where(mantissa == 0, np.inf, np.nan), value)
    return value.astype(np.float32)


def pack_b10g11r11(rgb):
    """Pack (..., 3) linear RGB into (...) uint32 ``B10G11R11_UFLOAT_PACK32``
    words: R (11-bit) in bits 0..10, G (11-bit) in 11..21, B (10-bit) in 22..31."""
    rgb = np.asarray(rgb, dtype=np.float64)
    if rgb.ndim < 1 or rgb.shape[-1] != 3:
        raise InputError(f"B10G11R11 packing needs RGB values of shape (..., 3), got {rgb.shape}")
    r = float_to_ufloat(rgb[..., 0], 6)
    g = float_to_ufloat(rgb[..., 1], 6)
    b = float_to_ufloat(rgb[..., 2], 5)
    return (r | (g << np.uint32(11)) | (b << np.uint32(22))).astype(np.uint32)


def unpack_b10g11r11(words):
    """Inverse of :func:`pack_b10g11r11`: (...) uint32 -> (..., 3) float32."""
    w = np.asarray(words).astype(np.uint32)
    r = ufloat_to_float(w & np.uint32(0x7FF), 6)
    g = ufloat_to_float((w >> np.uint32(11)) & np.uint32(0x7FF), 6)
    b = ufloat_to_float((w >> np.uint32(22)) & np.uint32(0x3FF), 5)
    return np.stack([r, g, b], axis=-1)


