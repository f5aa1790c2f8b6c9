"""Numba helpers shared by every module.

Each shading term in pbrkit is written once, as a plain NumPy function decorated
with :func:`term`.  Called from Python it runs on arrays of any leading shape
(NumPy broadcasting); called from a Numba kernel it is compiled for scalars and
inlined.  So the NumPy reference path and the compiled hot path share one
formula (numba's ``register_jitable``).
"""

from __future__ import annotations

import numba
import numpy as np
from numba import types
from numba.extending import overload, register_jitable

__all__ = ["term", "kernel", "parallel_kernel", "select"]


def term(fn):
    """Mark *fn* as a dual-use shading term (NumPy on arrays, Numba on scalars)."""
    return register_jitable(fn)


def kernel(fn):
    """Compile *fn* with Numba, cached on disk, serial."""
    return numba.njit(cache=True, fastmath=False)(fn)


def parallel_kernel(fn):
    """Compile *fn* with Numba, cached on disk, with ``prange`` parallel loops."""
    return numba.njit(cache=True, parallel=True, fastmath=False)(fn)


def select(condition, if_true, if_false):
    """Elementwise ``if_true if condition else if_false``.

    ``np.where`` on arrays from Python; inside Numba kernels, on scalars, a plain
    conditional expression (Numba's ``np.where`` would allocate a 0-d array).
    """
    return np.where(condition, if_true, if_false)


@overload(select)
def _select_numba(condition, if_true, if_false):
    if isinstance(condition, types.Boolean):
        def scalar_select(condition, if_true, if_false):
            return if_true if condition else if_false

        return scalar_select

    def array_select(condition, if_true, if_false):
        return np.where(condition, if_true, if_false)

    return array_select
