"""OpenEXR ``.exr`` files through the ``OpenEXR`` package (see :mod:`pbrkit.io.images`).

The library is given Python file objects (bytes written through Python, so a
full disk is an :class:`OSError` naming the file, never a library exception
or a silently short file), and what its C core prints on stdout/stderr is
captured (:func:`pbrkit.io.native_output.captured_native_output`) and folded
into the one-line :class:`~pbrkit.core.errors.InputError`.  The header's data
window is checked (:func:`pbrkit.io.image_checks._check_size`) before any
pixel is read.
"""

from __future__ import annotations

import io
import re
from pathlib import Path

import numpy as np

from ..core.atomic import atomic_path
from ..core.errors import InputError, OutputError
from .image_checks import _check_size, _finite_float, _one_line, open_or_fail
from .native_output import captured_native_output

__all__ = [
    "read_exr",
    "write_exr",
    "exr_bytes",
]

_MAGIC = b"\x76\x2f\x31\x01"
_BUFFER_NAME = re.compile(r"\s*'?<python_buffer>'?:?\s*")

# ------------------------------------------------------------------- OpenEXR


def _library_reason(exc, said):
    """One line saying why OpenEXR failed: its C core's ``EXR_ERR_*`` message
    if it printed one, else its "Exception raised ... - reason" warning, else
    the Python exception."""
    for line in said.lines:
        match = re.search(r"\(EXR_ERR_\w+\)\s*(.*)", line)
        if match and match.group(1):
            return match.group(1)
    text = said.summary(default="") if said.lines else ""
    if not text and exc is not None:
        text = _one_line(exc)
    return _BUFFER_NAME.sub(" ", text).strip() or "unreadable"


def _call(path, fn):
    """(result, captured output) of ``fn()`` with OpenEXR's printing captured;
    a failure becomes an :class:`InputError` naming ``path``."""
    failure = None
    result = None
    with captured_native_output() as said:
        try:
            result = fn()
        except MemoryError:
            failure = MemoryError()
        except Exception as exc:  # the library raises RuntimeError (and others) for any failure
            failure = exc
    if isinstance(failure, MemoryError):
        raise InputError("not enough memory to read the OpenEXR file", path) from None
    if failure is not None:
        raise InputError(f"corrupt or truncated OpenEXR file ({_library_reason(failure, said)})", path) from None
    return result, said


def _read_exr(path):
    import OpenEXR

    path = Path(path)
    with open_or_fail(path) as f:
        head = f.read(4)
        if head != _MAGIC:
            raise InputError(f"not an OpenEXR file (first bytes {head!r})", path)
        f.seek(0)
        header = _call(path, lambda: OpenEXR.File(f, header_only=True).header())[0]
        try:
            (x0, y0), (x1, y1) = (tuple(int(v) for v in np.asarray(w).reshape(2)) for w in header["dataWindow"])
        except (KeyError, TypeError, ValueError):
            raise InputError("corrupt OpenEXR header (no valid dataWindow)", path) from None
        height, width = y1 - y0 + 1, x1 - x0 + 1
        _check_size(path, height, width)
        f.seek(0)
        exr, said = _call(path, lambda: OpenEXR.File(f, separate_channels=True))
        parts = exr.parts
        complained = any("EXR_ERR" in line or "exception raised" in line.lower() for line in said.lines)
        if not parts or complained:  # the library read what it could and printed why it stopped
            raise InputError(f"corrupt or truncated OpenEXR file ({_library_reason(None, said)})", path)
        channels = parts[0].channels
    notes = [f"OpenEXR {str(header.get('compression', '')).split('.')[-1].replace('_COMPRESSION', '')}"]
    if len(parts) > 1:
        notes.append(f"multi-part file: part 0 of {len(parts)} used")
    names = list(channels)
    if all(c in channels for c in "RGB"):
        picked = ["R", "G", "B"]
    elif "Y" in channels:
        picked = ["Y"]
    else:
        raise InputError(f"no R, G, B (or Y) channels; channels are {', '.join(sorted(names)) or 'none'}", path)
    dropped = sorted(set(names) - set(picked))
    if dropped:
        notes.append(f"channels {', '.join(dropped)} ignored")
    planes = []
    for name in picked:
        ch = channels[name]
        if getattr(ch, "xSampling", 1) != 1 or getattr(ch, "ySampling", 1) != 1:
            raise InputError(f"channel {name} is subsampled; not supported", path)
        pixels = getattr(ch, "pixels", None)
        if not isinstance(pixels, np.ndarray) or pixels.ndim != 2 or pixels.dtype.kind not in "fui":
            raise InputError(f"channel {name} holds no readable scanline pixels (deep or unsupported data)", path)
        planes.append(pixels)
    if any(p.shape != (height, width) for p in planes):
        raise InputError("pixel data does not match the data window", path)
    dtypes = {p.dtype for p in planes}
    notes[0] += " " + "/".join(sorted({"half" if d == np.float16 else str(d) for d in dtypes}))
    img = np.empty((height, width, len(planes)), dtype=np.float32)
    for i, p in enumerate(planes):
        img[..., i] = p
    dw, disp = header["dataWindow"], header.get("displayWindow", header["dataWindow"])
    if any(not np.array_equal(a, b) for a, b in zip(dw, disp)):
        notes.append("data window differs from display window; data window used")
    return img, notes


def read_exr(path):
    """OpenEXR image as float32 (H, W, 3) (or (H, W, 1) for a Y-only file)."""
    return _read_exr(path)[0]


_EXR_COMPRESSION = {"none": "NO_COMPRESSION", "zip": "ZIP_COMPRESSION", "zips": "ZIPS_COMPRESSION",
                    "piz": "PIZ_COMPRESSION", "rle": "RLE_COMPRESSION"}


def _exr_file(image, half, compression):
    import OpenEXR

    a = _finite_float(image, "image")
    if a.shape[2] == 2:
        raise ValueError("EXR output takes 1, 3 or 4 channels, got 2")
    if compression not in _EXR_COMPRESSION:
        raise ValueError(f"unknown EXR compression {compression!r}; use one of {sorted(_EXR_COMPRESSION)}")
    dtype = np.float16 if half else np.float32
    if half and np.any(np.abs(a) > 65504.0):
        raise ValueError("values exceed the float16 range (65504); write float32 instead")
    a = np.ascontiguousarray(a, dtype=dtype)
    name = {1: "Y", 3: "RGB", 4: "RGBA"}[a.shape[2]]
    pixels = a[..., 0] if name == "Y" else a
    header = {"compression": getattr(OpenEXR, _EXR_COMPRESSION[compression]), "type": OpenEXR.scanlineimage}
    return OpenEXR.File(header, {name: np.ascontiguousarray(pixels)})


def exr_bytes(image, half=False, compression="zip"):
    """The bytes of the scanline OpenEXR file :func:`write_exr` writes.
    Needs an OpenEXR package that writes to streams (3.3 and later)."""
    exr = _exr_file(image, half, compression)
    buffer = io.BytesIO()
    failure = None
    with captured_native_output() as said:
        try:
            exr.write(buffer)
        except TypeError:
            raise
        except Exception as exc:
            failure = exc
    if failure is not None:
        raise ValueError(f"OpenEXR cannot encode the image ({_library_reason(failure, said)})")
    return buffer.getvalue()


def write_exr(path, image, half=False, compression="zip"):
    """Write ``image`` (H, W), (H, W, 1|3|4) as a scanline OpenEXR file
    (channels Y, RGB or RGBA), float32 or, with ``half``, float16, lossless
    ``compression`` in none/zip/zips/piz/rle; atomically.  Write failures
    (a full disk included) raise :class:`~pbrkit.core.errors.OutputError`
    naming ``path``."""
    try:
        data = exr_bytes(image, half, compression)
    except TypeError:  # an OpenEXR without stream output: let it write the file
        data = None
    with atomic_path(path) as tmp:
        if data is not None:
            tmp.write_bytes(data)
            return
        exr = _exr_file(image, half, compression)
        failure = None
        with captured_native_output() as said:
            try:
                exr.write(str(tmp))
            except Exception as exc:
                failure = exc
        if failure is not None:
            raise OutputError.from_library_error(_library_reason(failure, said), path)
