"""Input checks shared by every subpackage: integers in a range, powers of two,
small vectors and arrays of directions.

Each raises ``ValueError`` with a message that names the parameter and the
value it got, so a user error reads the same wherever it is caught:

- :func:`integer`: ``"{name} must be an integer in [lo, hi]; got {value!r}"``
  (``">= lo"`` / ``"<= hi"`` with one bound);
- :func:`power_of_two`: ``"{name} must be a power of two in [lo, hi]; got {value!r}"``;
- :func:`vector`: ``"{name} must be 3 finite numbers; got {value!r}"`` and,
  with ``unit``, ``"{name} must not be the zero vector"``;
- :func:`directions` / :func:`direction_lengths`: ``"{name} must have shape
  (..., 3); got (...)"`` and ``"{name} must be finite and non-zero; got k zero
  or non-finite vector(s)"``.

Integers are Python or NumPy integers; ``bool`` (and ``numpy.bool_``) is
rejected although Python counts it as one, and so are floats, even integral
ones: a count given as ``2.0`` is a mistake worth reporting.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["integer", "power_of_two", "vector", "directions", "direction_lengths", "is_finite_number"]


def is_finite_number(value):
    """A finite real number as parsed from JSON or TOML: an int or a float, not a
    bool (Python counts ``True`` as 1), not NaN or Inf, and not an integer beyond
    the float range."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:  # an integer beyond the float range
        return False


def _is_integer(value):
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def _range_text(lo, hi):
    if lo is not None and hi is not None:
        return f" in [{lo}, {hi}]"
    if lo is not None:
        return f" >= {lo}"
    if hi is not None:
        return f" <= {hi}"
    return ""


def integer(value, name, lo=None, hi=None):
    """``value`` as a Python ``int`` if it is an integer (not a bool) with
    lo <= value <= hi (either bound None: unbounded); else ValueError
    ``"{name} must be an integer in [lo, hi]; got {value!r}"``."""
    if not _is_integer(value) or (lo is not None and value < lo) or (hi is not None and value > hi):
        raise ValueError(f"{name} must be an integer{_range_text(lo, hi)}; got {value!r}")
    return int(value)


def power_of_two(value, name, lo, hi):
    """``value`` as a Python ``int`` if it is an integer (not a bool) power of two
    in [lo, hi]; else ValueError ``"{name} must be a power of two in [lo, hi]; got {value!r}"``."""
    if not _is_integer(value) or not lo <= value <= hi or value < 1 or int(value) & (int(value) - 1):
        raise ValueError(f"{name} must be a power of two in [{lo}, {hi}]; got {value!r}")
    return int(value)


def vector(value, name, n=3, unit=False):
    """``value`` as a float64 array of shape (n,) with finite entries, else
    ValueError ``"{name} must be {n} finite numbers; got {value!r}"``.  With
    ``unit`` it is divided by its length; a zero vector raises ValueError
    ``"{name} must not be the zero vector"``."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        a = None
    if a is None or a.shape != (n,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be {n} finite numbers; got {value!r}")
    if unit:
        length = float(np.linalg.norm(a))
        if length == 0.0:
            raise ValueError(f"{name} must not be the zero vector")
        a = a / length
    return a


def _directions_array(d, name):
    d = np.asarray(d, dtype=np.float64)
    if d.ndim < 1 or d.shape[-1] != 3:
        raise ValueError(f"{name} must have shape (..., 3); got {d.shape}")
    return d


def _reject(bad, name):
    if np.any(bad):
        raise ValueError(f"{name} must be finite and non-zero; got {int(np.sum(bad))} zero or non-finite vector(s)")


def directions(d, name="directions"):
    """``d`` as a float64 array (..., 3) of directions that need not be unit
    length: every component finite and no vector exactly zero (what a
    cube-map lookup, which divides by the largest component, needs).
    ValueError otherwise (module doc)."""
    d = _directions_array(d, name)
    _reject(~np.all(np.isfinite(d), axis=-1) | np.all(d == 0.0, axis=-1), name)
    return d


def direction_lengths(d, name="directions"):
    """``(d, |d|)``: ``d`` as a float64 array (..., 3) and its lengths
    ``np.linalg.norm(d, axis=-1)`` (...), for callers that divide by the
    length: a length that is zero (also by underflow) or not finite (also by
    overflow) raises ValueError (module doc)."""
    d = _directions_array(d, name)
    with np.errstate(over="ignore"):  # an overflowing length is reported below, not warned about
        length = np.linalg.norm(d, axis=-1)
    _reject((length == 0.0) | ~np.isfinite(length), name)
    return d, length
