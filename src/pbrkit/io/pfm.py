"""Portable Float Map ``.pfm`` files (see :mod:`pbrkit.io.images`).

Written from Paul Debevec's description of the format (HDRShop, "PFM Portable
Float Map"): ``PF`` (RGB) or ``Pf`` (grey), white space, ``W H``, white space,
a scale whose sign gives the byte order (negative: little-endian), one white
space character, then W x H float32 pixels, rows bottom to top.  The file is
untrusted input (:mod:`pbrkit.io.image_checks`): the declared size is checked
against the file's length and the memory available before the pixels are
copied, and no message quotes the header.
"""

from __future__ import annotations

import re

import numpy as np

from ..core.atomic import atomic_path
from ..core.errors import InputError
from .image_checks import _check_pixels, _check_size, _finite_float, _read_bytes

__all__ = [
    "read_pfm",
    "pfm_bytes",
    "write_pfm",
]

# ----------------------------------------------------------------------- PFM

_PFM_RE = re.compile(rb"^(PF|Pf)\s+(\d+)\s+(\d+)\s+([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s")


def _read_pfm(path):
    data = _read_bytes(path, "a Portable Float Map .pfm file")
    m = _PFM_RE.match(data[:256])
    if m is None:
        if data[:2] in (b"PF", b"Pf"):
            raise InputError("corrupt or truncated PFM header", path)
        raise InputError("not a PFM file (no 'PF' or 'Pf' signature)", path)
    kind, width, height, scale = m.groups()
    width, height, scale = int(width), int(height), float(scale)
    _check_size(path, height, width)
    if scale == 0.0 or not np.isfinite(scale):
        raise InputError("corrupt PFM header: the scale must be a non-zero finite number", path)
    channels = 3 if kind == b"PF" else 1
    count = width * height * channels
    offset = m.end()
    if len(data) - offset < 4 * count:
        raise InputError(f"truncated PFM data ({len(data) - offset} of {4 * count} bytes)", path)
    _check_pixels(path, height, width, 8 * channels, "PFM image")  # a byte-swapped copy, then the flipped one
    dtype = np.dtype("<f4" if scale < 0 else ">f4")
    img = np.frombuffer(data, dtype=dtype, count=count, offset=offset).reshape(height, width, channels)
    notes = [f"PFM {'little' if scale < 0 else 'big'}-endian"]
    if abs(scale) != 1.0:
        notes.append(f"PFM scale {abs(scale):g} not applied")
    return np.ascontiguousarray(img[::-1], dtype=np.float32), notes  # stored bottom to top


def read_pfm(path):
    """Portable Float Map as float32 (H, W, 3) or (H, W, 1), row 0 at the top; values
    as stored (NaN and Inf included).  Refusals: :class:`~pbrkit.core.errors.InputError`."""
    return _read_pfm(path)[0]


def pfm_bytes(image, little_endian=True):
    """Bytes of a PFM file of ``image`` (H, W), (H, W, 1|3), rows bottom to top."""
    a = _finite_float(image, "image")
    if a.shape[2] not in (1, 3):
        raise ValueError(f"PFM stores 1 or 3 channels, got {a.shape[2]}")
    kind = b"PF" if a.shape[2] == 3 else b"Pf"
    header = kind + f"\n{a.shape[1]} {a.shape[0]}\n{'-1.0' if little_endian else '1.0'}\n".encode()
    body = np.ascontiguousarray(a[::-1], dtype="<f4" if little_endian else ">f4")
    return header + body.tobytes()


def write_pfm(path, image, little_endian=True):
    """Write ``image`` as a PFM file (atomically); see :func:`pfm_bytes`."""
    data = pfm_bytes(image, little_endian=little_endian)
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


