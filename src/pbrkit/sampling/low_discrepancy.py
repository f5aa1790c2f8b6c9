"""Low-discrepancy point sets on the unit cube: radical inverses, the van der
Corput, Halton and Hammersley sequences, and the L2-star discrepancy by
Warnock's closed form (a quality measure used in the tests).
"""

from __future__ import annotations

import math

import numpy as np

from ..core import checks

__all__ = [
    "ONE_MINUS_EPSILON",
    "radical_inverse",
    "van_der_corput",
    "primes",
    "halton",
    "hammersley",
    "l2_star_discrepancy",
]

#: The largest float64 below 1 (pbrt's OneMinusEpsilon): radical inverses stay in [0, 1).
ONE_MINUS_EPSILON = 1.0 - 2.0**-53
_TINY = 1e-300

# =========================================================================
# Low-discrepancy points
# =========================================================================


def _as_indices(index):
    """Non-negative integer indices as a uint64 array (exact for all 64-bit values)."""
    arr = np.asarray(index)
    if arr.dtype == object:
        try:
            arr = np.asarray(arr.tolist(), dtype=np.uint64)
        except (OverflowError, TypeError, ValueError):
            raise ValueError("index must hold integers in [0, 2**64)") from None
    if arr.dtype.kind not in "iu":
        raise ValueError(f"index must be an integer array; got dtype {arr.dtype}")
    if arr.dtype.kind == "i" and arr.size and arr.min() < 0:
        raise ValueError("index must be non-negative")
    return arr.astype(np.uint64)


def _reverse_bits64(a):
    """Reverse the 64 bits of each uint64 (swap halves, then 16-, 8-, 4-, 2-, 1-bit groups)."""
    a = a.copy()
    for shift, mask in ((32, 0x00000000FFFFFFFF), (16, 0x0000FFFF0000FFFF), (8, 0x00FF00FF00FF00FF),
                        (4, 0x0F0F0F0F0F0F0F0F), (2, 0x3333333333333333), (1, 0x5555555555555555)):
        s = np.uint64(shift)
        m = np.uint64(mask)
        a = ((a >> s) & m) | ((a & m) << s)
    return a


def radical_inverse(index, base):
    """Radical inverse phi_b(i) = sum_k d_k b^-(k+1) of i = sum_k d_k b^k.

    van der Corput 1935; Halton 1960; pbrt-v4 (Pharr, Jakob, Humphreys,
    "Physically Based Rendering", 4th ed.), sec. 8.6.1.  ``index`` is any
    non-negative integer or integer array (int64 or uint64, so every 64-bit
    index is handled exactly: digits are extracted with integer arithmetic).
    Base 2 reverses the 64 bits and rounds once, so it is correctly rounded;
    other bases accumulate exact integer blocks of digits (each block below
    2^53) and are within a few ulp of the exact value.  Results are clamped to
    1 - 2^-53 so they stay in [0, 1), as in pbrt.
    """
    base = checks.integer(base, "base", 2, 2**53)
    a = _as_indices(index)
    if base == 2:
        value = _reverse_bits64(a).astype(np.float64) * 2.0**-64
        return np.minimum(value, ONE_MINUS_EPSILON)
    shape = a.shape
    a = a.reshape(-1)
    result = np.zeros(a.shape, dtype=np.float64)
    if a.size == 0:
        return result.reshape(shape)
    n_digits = 0
    top = int(a.max())
    while top:
        top //= base
        n_digits += 1
    block = 1  # digits per block: the largest m with base^m <= 2^53
    while base ** (block + 1) <= 2**53:
        block += 1
    b = np.uint64(base)
    remaining = a.copy()
    acc = np.zeros_like(a)
    for k in range(n_digits):
        quotient = remaining // b
        acc = acc * b + (remaining - quotient * b)
        remaining = quotient
        if (k + 1) % block == 0 or k + 1 == n_digits:
            # acc holds digits d_{k-m+1} .. d_k reversed, worth acc / b^(k+1)
            result += acc.astype(np.float64) / float(base ** (k + 1))
            acc[...] = 0
    return np.minimum(result, ONE_MINUS_EPSILON).reshape(shape)


def van_der_corput(n):
    """The first ``n`` points of the base-2 van der Corput sequence phi_2(0), ..., phi_2(n - 1)
    (van der Corput 1935)."""
    n = checks.integer(n, "n", 0)
    return radical_inverse(np.arange(n, dtype=np.uint64), 2)


def primes(count):
    """The first ``count`` primes (2, 3, 5, ...), by a sieve of Eratosthenes sized with
    Rosser's bound p_n < n (ln n + ln ln n) for n >= 6."""
    count = checks.integer(count, "count", 0)
    if count == 0:
        return np.zeros(0, dtype=np.int64)
    limit = 15 if count < 6 else int(count * (math.log(count) + math.log(math.log(count)))) + 1
    sieve = np.ones(limit + 1, dtype=bool)
    sieve[:2] = False
    for p in range(2, math.isqrt(limit) + 1):
        if sieve[p]:
            sieve[p * p::p] = False
    return np.flatnonzero(sieve)[:count].astype(np.int64)


def halton(n, dim, skip=0):
    """Points ``skip .. skip + n - 1`` of the Halton sequence in ``dim`` dimensions, shape (n, dim).

    Halton 1960: coordinate k of point i is the radical inverse of i in the k-th
    prime (2, 3, 5, ...).  Point 0 is the origin; pass ``skip`` to start later.
    Any dimension (primes are generated on demand); high dimensions correlate
    badly without scrambling, as is well known.
    """
    n = checks.integer(n, "n", 0)
    dim = checks.integer(dim, "dim", 1)
    skip = checks.integer(skip, "skip", 0)
    if skip + n > 2**64:
        raise ValueError("skip + n must not exceed 2**64")
    index = np.arange(n, dtype=np.uint64) + np.uint64(skip)
    out = np.empty((n, dim))
    for k, p in enumerate(primes(dim)):
        out[:, k] = radical_inverse(index, int(p))
    return out


def hammersley(n, dim=2):
    """The ``n``-point Hammersley set in ``dim`` dimensions, shape (n, dim).

    Hammersley 1960: point i is (i / n, phi_2(i), phi_3(i), ...) with the
    radical inverses in the first dim - 1 primes.
    """
    n = checks.integer(n, "n", 1)
    dim = checks.integer(dim, "dim", 1)
    index = np.arange(n, dtype=np.uint64)
    out = np.empty((n, dim))
    out[:, 0] = np.arange(n) / n
    for k, p in enumerate(primes(dim - 1)):
        out[:, k + 1] = radical_inverse(index, int(p))
    return out


def l2_star_discrepancy(points, chunk_elements=1 << 22):
    """L2-star discrepancy T of points in [0, 1]^d (shape (n, d)), by Warnock's formula.

    Warnock 1972 ("Computational investigations of low-discrepancy point sets",
    in Zaremba (ed.), Applications of Number Theory to Numerical Analysis):
    T^2 = 3^-d - (2^(1-d) / n) sum_i prod_k (1 - x_ik^2)
          + (1 / n^2) sum_i sum_j prod_k (1 - max(x_ik, x_jk)),
    the L2 norm over anchored boxes [0, y) of (#points in box / n - volume).
    O(n^2 d), vectorised over blocks of rows of at most ``chunk_elements`` pairs.
    Returns T (not T^2).  For n i.i.d. uniform points E[T^2] = (2^-d - 3^-d) / n.
    """
    x = np.asarray(points, dtype=np.float64)
    if x.ndim != 2 or x.shape[0] == 0 or x.shape[1] == 0:
        raise ValueError(f"points must have shape (n, d) with n, d >= 1; got {x.shape}")
    if not np.all((x >= 0.0) & (x <= 1.0)):
        raise ValueError("points must lie in the unit cube [0, 1]^d")
    n, d = x.shape
    term1 = 3.0**-d
    term2 = 2.0 ** (1 - d) / n * np.sum(np.prod(1.0 - x * x, axis=1))
    rows = max(1, int(chunk_elements) // n)
    pair_sum = 0.0
    for start in range(0, n, rows):
        block = x[start:start + rows]
        prod = 1.0 - np.maximum(block[:, None, 0], x[None, :, 0])
        for k in range(1, d):
            prod *= 1.0 - np.maximum(block[:, None, k], x[None, :, k])
        pair_sum += float(np.sum(prod))
    t2 = term1 - term2 + pair_sum / (n * n)
    return math.sqrt(max(t2, 0.0))


