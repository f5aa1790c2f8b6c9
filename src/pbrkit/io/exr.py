"""OpenEXR ``.exr`` files through the ``OpenEXR`` package (see :mod:`pbrkit.io.images`).

The library is given Python file objects (bytes written through Python, so a
full disk is an :class:`OSError` naming the file, never a library exception
or a silently short file), and what its C core prints on stdout/stderr is
captured (:func:`pbrkit.io.native_output.captured_native_output`) and folded
into the one-line :class:`~pbrkit.core.errors.InputError`, stripped of
anything it quotes from the file (:func:`pbrkit.io.image_checks.safe_reason`).

The file is untrusted input: the library reads it itself, so it is handed an
open *regular* file (:func:`pbrkit.io.image_checks.open_or_fail`), and every
part's header is read first (``header_only``): the data window is checked
(:func:`pbrkit.io.image_checks._check_size`), the chunk table a scanline part
needs must fit in the file (OpenEXR "File Layout": one 8-byte offset and a chunk
of at least 8 bytes per 1, 16, 32 or 256 scanlines, by compression) and the
memory of the channels must be available
(:func:`pbrkit.core.inputs.check_allocation`) before any pixel is read.
"""

from __future__ import annotations

import io
import os
import re
from pathlib import Path

import numpy as np

from ..core.atomic import atomic_path
from ..core.errors import InputError, OutputError
from ..core.inputs import check_allocation
from .image_checks import ALPHA_IGNORED, _check_size, _finite_float, open_or_fail, safe_reason
from .native_output import captured_native_output

__all__ = [
    "read_exr",
    "write_exr",
    "exr_bytes",
]

_MAGIC = b"\x76\x2f\x31\x01"
_BUFFER_NAME = re.compile(r"\s*'?<python_buffer>'?:?\s*")
#: Channel names a note may list (short plain names such as A, Z, N.x); others are counted.
_PLAIN_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_.]{0,15}$")

# ------------------------------------------------------------------- OpenEXR


def _library_reason(exc, said):
    """One line saying why OpenEXR failed, without the file's content
    (:func:`~pbrkit.io.image_checks.safe_reason`): its C core's ``EXR_ERR_*``
    message if it printed one, else its "Exception raised ... - reason" warning,
    else the Python exception."""
    for line in said.lines:
        match = re.search(r"\(EXR_ERR_\w+\)\s*(.*)", line)
        if match and match.group(1):
            return safe_reason(match.group(1)) or "unreadable"
    text = said.summary(default="") if said.lines else ""
    if not text and exc is not None:
        text = str(exc)
    return safe_reason(_BUFFER_NAME.sub(" ", text)).strip() or "unreadable"


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


#: Scanlines per chunk of each compression (OpenEXR file layout, "Scan Line Based Images");
#: 256, the largest, for any other.
_LINES_PER_CHUNK = {"NO": 1, "RLE": 1, "ZIPS": 1, "ZIP": 16, "PXR24": 16, "PIZ": 32, "B44": 32, "B44A": 32,
                    "DWAA": 32, "HTJ2K32": 32}


def _window(header, path):
    """(height, width) of a part's dataWindow, checked (:func:`_check_size`)."""
    try:
        (x0, y0), (x1, y1) = (tuple(int(v) for v in np.asarray(w).reshape(2)) for w in header["dataWindow"])
    except (KeyError, TypeError, ValueError):
        raise InputError("corrupt OpenEXR header (no valid dataWindow)", path) from None
    height, width = y1 - y0 + 1, x1 - x0 + 1
    _check_size(path, height, width)
    return height, width


def _check_parts(parts, path, size):
    """Before any pixel is read: every part's data window within the size limits, its
    chunk table within the file (a scanline part of H lines has ceil(H / lines per
    chunk) chunks, each an 8-byte offset and at least an 8-byte chunk header), and
    the memory of all the parts' channels (at most 4 bytes a sample) plus the float32
    RGB image made from part 0 within the memory available.  Returns (height, width)
    of part 0."""
    first = None
    total = 0
    for index, part in enumerate(parts):
        header = part.header
        height, width = _window(header, path)
        first = first or (height, width)
        kind = str(header.get("type", "")).split(".")[-1]
        compression = str(header.get("compression", "")).split(".")[-1].replace("_COMPRESSION", "")
        if kind == "scanlineimage":
            chunks = -(-height // _LINES_PER_CHUNK.get(compression, 256))
            if 16 * chunks > size:
                raise InputError(f"the chunk table of part {index} ({width}x{height}, {chunks} chunks) needs at "
                                 f"least {16 * chunks} bytes; the file has {size} (truncated or corrupt)", path)
        total += height * width * 4 * max(1, len(header.get("channels") or ()))
    height, width = first
    check_allocation(total + height * width * 12, f"the {width}x{height} OpenEXR image", path)
    return first


def _read_exr(path):
    import OpenEXR

    path = Path(path)
    with open_or_fail(path, "an OpenEXR .exr file") as f:
        head = f.read(4)
        if head != _MAGIC:
            raise InputError("not an OpenEXR file (no OpenEXR magic number)", path)
        size = os.fstat(f.fileno()).st_size
        f.seek(0)
        heads = _call(path, lambda: OpenEXR.File(f, header_only=True))[0]
        if not heads.parts:
            raise InputError("corrupt OpenEXR header (no part)", path)
        header = heads.parts[0].header
        height, width = _check_parts(heads.parts, path, size)
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
        raise InputError(f"no R, G, B (or Y) channels among its {len(names)} channel(s)", path)
    dropped = sorted(set(names) - set(picked))
    if "A" in dropped:
        notes.append(ALPHA_IGNORED)
        dropped.remove("A")
    if dropped and len(dropped) <= 8 and all(_PLAIN_NAME.match(n) for n in dropped):
        notes.append(f"channels {', '.join(dropped)} ignored")
    elif dropped:
        notes.append(f"{len(dropped)} other channels ignored")
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
    """OpenEXR image as float32 (H, W, 3) (or (H, W, 1) for a Y-only file), part 0 of
    the file; values as stored.  Refusals: :class:`~pbrkit.core.errors.InputError`."""
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
