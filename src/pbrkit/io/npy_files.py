"""Reading ``.npy`` arrays as untrusted input (the bake's ``brdf_lut.npy``, LTC tables).

Written from NumPy's "NEP 1 — A simple file format for NumPy arrays" (the
``.npy`` format, versions 1.0 and 2.0): the magic ``\\x93NUMPY``, two version
bytes, a little-endian header length (2 bytes in 1.0, 4 in 2.0), then a Python
literal dict with ``descr``, ``fortran_order`` and ``shape``, padded so the data
start at a multiple of 64; then the data, ``prod(shape) * itemsize`` bytes.

:func:`read_npy` opens only a regular file (:mod:`pbrkit.core.inputs`), parses
the header with NumPy's own parser, refuses object arrays, requires the file's
length to be exactly the header plus the data the shape declares, and checks
the memory before reading the data: a header declaring an absurd shape is
refused before anything is allocated.  No message quotes the header.
"""

from __future__ import annotations

import math
import os

import numpy as np

from ..core.errors import InputError
from ..core.inputs import check_allocation, open_regular

__all__ = ["MAX_NPY_BYTES", "read_npy"]

#: Largest ``.npy`` file read.
MAX_NPY_BYTES = 4 << 30


def read_npy(path, expected="a .npy array file", limit=MAX_NPY_BYTES):
    """The array stored in the ``.npy`` file ``path`` (module doc), writable; a file
    that is not a regular ``.npy`` file of numbers of at most ``limit`` bytes, or
    whose length is not what its header declares, raises :class:`InputError`
    naming it and what was ``expected``."""
    fmt = np.lib.format
    with open_regular(path, limit, expected) as f:
        size = os.fstat(f.fileno()).st_size
        try:
            version = fmt.read_magic(f)
            if version == (1, 0):
                shape, fortran, dtype = fmt.read_array_header_1_0(f)
            elif version == (2, 0):
                shape, fortran, dtype = fmt.read_array_header_2_0(f)
            else:
                raise InputError(f"a .npy file of format version {version[0]}.{version[1]}; expected 1.0 or 2.0",
                                 path)
        except InputError:
            raise
        except (ValueError, TypeError, SyntaxError, OSError, EOFError, RecursionError, MemoryError):
            raise InputError(f"not a .npy file (no valid NumPy header); expected {expected}", path) from None
        if dtype.hasobject or dtype.kind not in "biufc" or dtype.fields is not None:
            raise InputError(f"a .npy file of non-numeric {dtype.kind!r} values; expected {expected}", path)
        count = math.prod(shape)
        nbytes = count * dtype.itemsize
        start = f.tell()
        if size - start != nbytes:
            raise InputError(f"its header declares shape {shape} ({nbytes} bytes of data) but the file holds "
                             f"{size - start} after the header; expected {expected}", path)
        check_allocation(nbytes, f"the array of shape {shape}", path)
        buffer = bytearray(nbytes)
        try:
            got = f.readinto(buffer)
        except OSError as exc:
            raise InputError(f"cannot read file ({exc.strerror or exc}); expected {expected}", path) from None
    if got != nbytes:
        raise InputError(f"changed while it was read; expected {expected}", path)
    return np.frombuffer(buffer, dtype=dtype, count=count).reshape(shape, order="F" if fortran else "C")
