"""Texel encodings, level checks and the file reading shared by the texture
containers (KTX 1.1, KTX 2.0, DDS, Babylon.js ``.env``).

The files are untrusted input (:mod:`pbrkit.core.inputs`): :func:`read_container`
reads only a regular file of at most :data:`MAX_CONTAINER_BYTES`, with the memory
for it checked first, and each parser checks the level sizes its header declares
against the file's length, then the memory of the decoded levels
(:func:`check_decoded`), before decoding any.
"""

from __future__ import annotations

import math
import os

import numpy as np

from ..core.errors import InputError
from ..core.inputs import check_allocation, read_bytes
from .float_packing import pack_b10g11r11, to_float16, unpack_b10g11r11

#: Largest texture container file read (a float32 RGBA cube map chain of 16384^2 faces is 8.6 GB).
MAX_CONTAINER_BYTES = 16 << 30

__all__ = [
    "texel_size",
    "encode_texels",
    "decode_texels",
]

# ----------------------------------------------------------------------------
# Texel encodings shared by the KTX2 and DDS writers.

#: Bytes per texel component of each encoding ('b10g11r11' packs 3 in 4).
_ENCODING_COMPONENT_BYTES = {"float16": 2, "float32": 4}


def texel_size(encoding, channels):
    """Bytes per texel of ``encoding`` ('float16', 'float32' or 'b10g11r11')
    with ``channels`` components."""
    if encoding == "b10g11r11":
        return 4
    return _ENCODING_COMPONENT_BYTES[encoding] * channels


def encode_texels(values, encoding, channels, what="texels"):
    """Little-endian bytes of the texels ``values`` (..., C) in ``encoding``.

    ``C`` must equal ``channels``, except that RGB input (C = 3) gets alpha 1
    for a 4-channel encoding and single-channel input may omit the last axis.
    Rows are tightly packed in C order, as KTX2 and DDS store them.
    """
    v = np.asarray(values)
    if not np.issubdtype(v.dtype, np.number) or np.iscomplexobj(v):
        raise InputError(f"{what}: expected real numbers, got dtype {v.dtype}")
    v = v.astype(np.float64, copy=False)
    if channels == 1 and (v.ndim == 0 or v.shape[-1] != 1):
        v = v[..., None]
    c = v.shape[-1] if v.ndim else 0
    if c == 3 and channels == 4:
        v = np.concatenate([v, np.ones(v.shape[:-1] + (1,))], axis=-1)
    elif c != channels:
        raise InputError(f"{what}: the format has {channels} channel(s) but the data has {c}")
    if encoding == "float16":
        out = to_float16(v).astype("<f2", copy=False)
    elif encoding == "float32":
        out = v.astype("<f4")
    elif encoding == "b10g11r11":
        out = pack_b10g11r11(v).astype("<u4", copy=False)
    else:
        raise InputError(f"unknown texel encoding {encoding!r}")
    return np.ascontiguousarray(out).tobytes()


def decode_texels(buffer, encoding, channels, shape):
    """Float32 array ``shape + (channels,)`` from little-endian texel bytes."""
    count = int(np.prod(shape, dtype=np.int64))
    if encoding == "float16":
        v = np.frombuffer(buffer, dtype="<f2", count=count * channels).astype(np.float32)
    elif encoding == "float32":
        v = np.frombuffer(buffer, dtype="<f4", count=count * channels).astype(np.float32)
    elif encoding == "b10g11r11":
        v = unpack_b10g11r11(np.frombuffer(buffer, dtype="<u4", count=count))
    else:
        raise InputError(f"unknown texel encoding {encoding!r}")
    return v.reshape(tuple(shape) + (channels,))


def max_mip_levels(width, height):
    """Length of a full mip chain of a width x height image,
    floor(log2(max(width, height))) + 1 (each level halves, rounding down, to 1 x 1)."""
    return int(math.floor(math.log2(max(width, height)))) + 1


def read_file(path, expected, limit=MAX_CONTAINER_BYTES):
    """The bytes of the regular file ``path`` of at most ``limit`` bytes, with the
    memory to hold them checked before reading (:func:`pbrkit.core.inputs.read_bytes`)."""
    return read_bytes(path, limit, expected)


def read_container(path, parse, expected="a texture container file"):
    """``parse(data, name=path)`` of the bytes of the texture container file
    ``path`` (:func:`read_file`); a file that cannot be read raises
    :class:`InputError` naming it and what was ``expected``."""
    return parse(read_file(path, expected), name=os.fspath(path))


#: Bytes :func:`decode_texels` allocates per decoded channel: the float32 result, plus
#: the float16 values it converts from, or the unpacking temporaries of B10G11R11.
_DECODED_CHANNEL_BYTES = {"float16": 6, "float32": 4, "b10g11r11": 16}


def check_decoded(name, encoding, channels, texels, what="the texture's levels"):
    """Refuse (:class:`InputError`) decoding ``texels`` texels when their memory
    exceeds what is available: :func:`decode_texels`'s allocations, a copy of the
    stored bytes and one of the result (a parser stacks cube faces)."""
    per_texel = 2 * channels * _DECODED_CHANNEL_BYTES[encoding] + texel_size(encoding, channels)
    check_allocation(texels * per_texel, f"{what} ({texels:,} texels)", name)


def validate_levels(levels, cube):
    """Check a full or partial mip chain for a texture container (KTX2, DDS):
    returns (arrays, width, height) of level 0."""
    if isinstance(levels, np.ndarray) or not len(levels):
        raise InputError("levels must be a non-empty list of arrays, level 0 (largest) first")
    arrays = [np.asarray(level) for level in levels]
    first = arrays[0]
    if cube:
        if first.ndim != 4 or first.shape[0] != 6 or first.shape[1] != first.shape[2]:
            raise InputError(f"cube map level 0 must have shape (6, N, N, C), got {first.shape}")
        width = height = first.shape[1]
    else:
        if first.ndim not in (2, 3):
            raise InputError(f"2D level 0 must have shape (H, W, C) or (H, W), got {first.shape}")
        height, width = first.shape[:2]
    if width < 1 or height < 1:
        raise InputError(f"level 0 must not be empty, got shape {first.shape}")
    max_levels = max_mip_levels(width, height)
    if len(arrays) > max_levels:
        raise InputError(f"{len(arrays)} levels given but a {width}x{height} image has at most {max_levels}")
    for p, a in enumerate(arrays):
        w, h = max(1, width >> p), max(1, height >> p)
        expected = (6, h, w) if cube else (h, w)
        if a.shape[: len(expected)] != expected or a.ndim - len(expected) > 1:
            raise InputError(f"level {p} has shape {a.shape}, expected {expected} + (channels,)")
        if a.ndim > len(expected) and a.shape[-1] != first.shape[-1]:
            raise InputError(f"level {p} has {a.shape[-1]} channels but level 0 has {first.shape[-1]}")
    return arrays, width, height


def format_code(value, formats, by_code, prefix, label):
    """Code of a texture format given as an int or a name with or without ``prefix``
    (``VK_FORMAT_`` / ``DXGI_FORMAT_``); ``formats`` maps names to (code, ...)."""
    if isinstance(value, str):
        name = value.upper()
        if name.startswith(prefix):
            name = name[len(prefix):]
        if name not in formats:
            raise InputError(f"unsupported {label} {value!r}; supported: {', '.join(formats)}")
        return formats[name][0]
    code = int(value)
    if code not in by_code:
        raise InputError(f"unsupported {label} {value!r}; supported codes: {sorted(by_code)}")
    return code

