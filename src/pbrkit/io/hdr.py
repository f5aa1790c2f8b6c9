"""Radiance RGBE ``.hdr`` files: reader and writer (see :mod:`pbrkit.io.images`).

Written from Ward, "Real Pixels" (Graphics Gems II, 1991) and the Radiance
sources (``src/common/color.c`` ``freadcolrs``, ``resolu.h``).  The file is
untrusted input (:mod:`pbrkit.io.image_checks`): the resolution line's size is
checked against what the rest of the file can hold (every scanline takes at
least 4 bytes, 4 more per old-style run marker needed to span it) and against
the memory available before the pixels are allocated, and no message quotes
the header.
"""

from __future__ import annotations

import re

import numpy as np

from ..core.atomic import atomic_path
from ..core.errors import InputError
from ..core.jit import kernel, row_kernel
from .image_checks import _check_pixels, _check_size, _finite_float, _read_bytes

__all__ = [
    "read_hdr",
    "hdr_bytes",
    "write_hdr",
]

# ------------------------------------------------------------- Radiance RGBE

_RES_RE = re.compile(rb"^([-+])([XY]) +(\d+) +([-+])([XY]) +(\d+)$")
_HEADER_LIMIT = 1 << 16


@kernel
def _rgbe_decode(buf, pos, n_scan, length, out):
    """Decode n_scan scanlines of ``length`` RGBE pixels from buf[pos:] into
    out (n_scan, length, 4).  Returns (status, scanline, pos): status 0 = ok,
    1 = data ends early (truncated), 2 = corrupt run-length data."""
    n = buf.shape[0]
    for y in range(n_scan):
        if pos + 4 > n:
            return 1, y, pos
        if buf[pos] == 2 and buf[pos + 1] == 2 and (buf[pos + 2] & 0x80) == 0:
            # new-style RLE: (2, 2, len >> 8, len & 255), then four byte planes
            if (np.int64(buf[pos + 2]) << 8 | np.int64(buf[pos + 3])) != length:
                return 2, y, pos
            pos += 4
            for c in range(4):
                j = 0
                while j < length:
                    if pos >= n:
                        return 1, y, pos
                    code = np.int64(buf[pos])
                    pos += 1
                    if code > 128:
                        code -= 128
                        if j + code > length:
                            return 2, y, pos
                        if pos >= n:
                            return 1, y, pos
                        val = buf[pos]
                        pos += 1
                        for k in range(code):
                            out[y, j + k, c] = val
                        j += code
                    else:
                        if j + code > length:
                            return 2, y, pos
                        if pos + code > n:
                            return 1, y, pos
                        for k in range(code):
                            out[y, j + k, c] = buf[pos + k]
                        pos += code
                        j += code
        else:
            # flat pixels, with old-style runs (1, 1, 1, count << shift)
            j = 0
            shift = 0
            while j < length:
                if pos + 4 > n:
                    return 1, y, pos
                if buf[pos] == 1 and buf[pos + 1] == 1 and buf[pos + 2] == 1:
                    if j == 0 or shift > 16:
                        return 2, y, pos
                    count = np.int64(buf[pos + 3]) << shift
                    if j + count > length:
                        return 2, y, pos
                    for k in range(count):
                        for c in range(4):
                            out[y, j + k, c] = out[y, j - 1, c]
                    j += count
                    shift += 8
                else:
                    for c in range(4):
                        out[y, j, c] = buf[pos + c]
                    j += 1
                    shift = 0
                pos += 4
    return 0, n_scan, pos


def _rgbe_to_float(rgbe):
    """Radiance ``colrval``: (m + 0.5) 2^(e - 136), zero where e = 0 (float32)."""
    e = rgbe[..., 3].astype(np.int32)
    scale = np.where(e > 0, np.ldexp(np.float32(1.0), e - 136), np.float32(0.0)).astype(np.float32)
    out = rgbe[..., :3].astype(np.float32)
    out += np.float32(0.5)
    out *= scale[..., None]
    return out


def _parse_hdr_header(data, path):
    if not data.startswith(b"#?"):
        raise InputError("not a Radiance HDR file (missing '#?' signature)", path)
    end = data.find(b"\n\n", 0, _HEADER_LIMIT)
    if end < 0:
        if len(data) < _HEADER_LIMIT:
            raise InputError("truncated Radiance header (no blank line ending it)", path)
        raise InputError(f"corrupt Radiance header (no blank line in the first {_HEADER_LIMIT} bytes)", path)
    notes = []
    fmt = None
    for line in data[:end].split(b"\n")[1:]:
        line = line.strip()
        if line.startswith(b"FORMAT="):
            fmt = line[7:].strip().decode("latin-1")
        elif line.startswith(b"EXPOSURE=") and "EXPOSURE" not in " ".join(notes):
            notes.append("header EXPOSURE= not applied (pixels used as stored)")
    if fmt is not None and fmt != "32-bit_rle_rgbe":
        if fmt == "32-bit_rle_xyze":
            raise InputError("Radiance XYZE pixels are not supported (convert to RGBE)", path)
        raise InputError("corrupt Radiance header: unknown FORMAT= line; expected FORMAT=32-bit_rle_rgbe", path)
    nl = data.find(b"\n", end + 2, end + 2 + 256)
    if nl < 0:
        raise InputError("truncated or corrupt Radiance header (no resolution line)", path)
    res = data[end + 2:nl].strip()
    m = _RES_RE.match(res)
    if m is None or m.group(2) == m.group(5):
        raise InputError("corrupt Radiance resolution line; expected one such as '-Y 512 +X 1024'", path)
    major_sign, major_axis, n_major, minor_sign, minor_axis, n_minor = m.groups()
    n_major, n_minor = int(n_major), int(n_minor)
    if major_axis == b"Y":
        height, width = n_major, n_minor
    else:
        height, width = n_minor, n_major
    _check_size(path, height, width)
    # Every scanline takes at least one flat pixel (4 bytes) and one old-style run
    # marker (4 bytes) per base-256 digit of the rest of its length (freadcolrs).
    least = n_major * 4 * (1 + ((n_minor - 1).bit_length() + 7) // 8) if n_minor > 0 else 0
    if least > len(data) - (nl + 1):
        raise InputError(f"truncated RGBE pixel data: {width}x{height} pixels need at least {least} bytes, "
                         f"the file holds {len(data) - (nl + 1)} after its header", path)
    # peak of _read_hdr: RGBE bytes (4), decoding temporaries (16), float RGB and a reoriented copy (24)
    _check_pixels(path, height, width, 44, "Radiance image")
    return dict(offset=nl + 1, n_major=n_major, n_minor=n_minor, major=(major_sign + major_axis).decode(),
                minor=(minor_sign + minor_axis).decode(), notes=notes)


def _read_hdr(path):
    data = _read_bytes(path, "a Radiance RGBE .hdr file")
    head = _parse_hdr_header(data, path)
    n_major, n_minor = head["n_major"], head["n_minor"]
    buf = np.frombuffer(data, dtype=np.uint8)
    rgbe = np.empty((n_major, n_minor, 4), dtype=np.uint8)
    status, line, _ = _rgbe_decode(buf, head["offset"], n_major, n_minor, rgbe)
    if status == 1:
        raise InputError(f"truncated RGBE pixel data (ends in scanline {line} of {n_major})", path)
    if status == 2:
        raise InputError(f"corrupt RGBE run-length data in scanline {line} of {n_major}", path)
    img = _rgbe_to_float(rgbe)
    del rgbe
    # Radiance resolution string: first axis = scanline order; -Y is top to
    # bottom, +X left to right (Radiance "resolu.h").
    if head["major"][1] == "X":
        img = img.transpose(1, 0, 2)  # scanlines were columns
    y_sign = head["major"][0] if head["major"][1] == "Y" else head["minor"][0]
    x_sign = head["minor"][0] if head["minor"][1] == "X" else head["major"][0]
    if y_sign == "+":
        img = img[::-1]
    if x_sign == "-":
        img = img[:, ::-1]
    if head["major"] != "-Y" or head["minor"] != "+X":
        head["notes"].append(f"non-standard orientation {head['major']} {head['minor']} reoriented")
    return np.ascontiguousarray(img), ["Radiance RGBE"] + head["notes"]


def read_hdr(path):
    """Radiance RGBE image as float32 (H, W, 3), row 0 at the top (see module doc).
    A file that is not a regular file, a header or size it cannot hold, or corrupt
    run-length data raise :class:`~pbrkit.core.errors.InputError` naming it."""
    return _read_hdr(path)[0]


def _float_to_rgbe(image):
    """Radiance ``setcolr``: e from frexp of the largest component, mantissas
    truncated; components <= 0 store 0; a pixel whose largest component is
    below 1e-32 is (0, 0, 0, 0)."""
    rgb = np.maximum(image.astype(np.float64), 0.0)
    peak = rgb.max(axis=-1)
    mant, e = np.frexp(peak)
    if np.any((e > 127) & (peak > 1e-32)):
        raise ValueError(f"value {peak.max():g} too large for RGBE (limit 2^127)")
    small = (peak <= 1e-32) | (e < -127)
    scale = np.ldexp(1.0, 8 - e)
    out = np.empty(image.shape[:2] + (4,), dtype=np.uint8)
    out[..., :3] = np.minimum(rgb * scale[..., None], 255.0).astype(np.uint8)
    out[..., 3] = np.where(small, 0, e + 128).astype(np.uint8)
    out[small] = 0
    return out


@row_kernel(0)
def _rgbe_encode_rle(start, stop, rgbe, out, lengths):
    """New-style RLE of each scanline of rgbe (H, W, 4) into out[y]: runs of at
    least 4 equal bytes become (128 + n, byte) with n <= 127, everything else
    literal dumps (n <= 128, bytes)."""
    width = rgbe.shape[1]
    for y in range(start, stop):
        p = 0
        out[y, 0] = 2
        out[y, 1] = 2
        out[y, 2] = width >> 8
        out[y, 3] = width & 255
        p = 4
        for c in range(4):
            j = 0
            while j < width:
                beg = j
                run = 0
                while beg < width:
                    run = 1
                    while beg + run < width and run < 127 and rgbe[y, beg + run, c] == rgbe[y, beg, c]:
                        run += 1
                    if run >= 4:
                        break
                    beg += run
                if beg >= width:
                    beg = width
                    run = 0
                while j < beg:
                    n = min(128, beg - j)
                    out[y, p] = n
                    p += 1
                    for k in range(n):
                        out[y, p + k] = rgbe[y, j + k, c]
                    p += n
                    j += n
                if run >= 4:
                    out[y, p] = 128 + run
                    out[y, p + 1] = rgbe[y, beg, c]
                    p += 2
                    j = beg + run
        lengths[y] = p


def hdr_bytes(image, rle=True):
    """The bytes of a Radiance RGBE file of ``image`` (H, W) or (H, W, 1|3)
    (grey is replicated), standard orientation ``-Y H +X W``.  ``rle`` writes
    new-style run-length encoded scanlines (for 8 <= W <= 32767, as Radiance
    does), otherwise flat pixels."""
    a = _finite_float(image, "image")
    if a.shape[2] == 1:
        a = np.repeat(a, 3, axis=2)
    elif a.shape[2] != 3:
        raise ValueError(f"RGBE stores 3 channels; got {a.shape[2]}")
    height, width = a.shape[:2]
    header = (b"#?RADIANCE\n# written by pbrkit\nFORMAT=32-bit_rle_rgbe\n\n"
              + f"-Y {height} +X {width}\n".encode())
    rgbe = _float_to_rgbe(a)
    if not rle or not 8 <= width <= 0x7FFF:
        return header + rgbe.tobytes()
    out = np.empty((height, 4 + 4 * (width + (width + 127) // 128)), dtype=np.uint8)
    lengths = np.empty(height, dtype=np.int64)
    _rgbe_encode_rle(rgbe, out, lengths)
    return header + b"".join(out[y, :lengths[y]].tobytes() for y in range(height))


def write_hdr(path, image, rle=True):
    """Write ``image`` as a Radiance RGBE file (atomically); see :func:`hdr_bytes`."""
    data = hdr_bytes(image, rle=rle)
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


