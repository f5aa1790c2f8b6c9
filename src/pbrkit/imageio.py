"""Reading and writing the image files pbrkit consumes and produces.

Every reader returns linear float32 pixels of shape (H, W, C), row 0 at the
top, and raises :class:`pbrkit.errors.InputError` (a ``ValueError``) with a
one-line ``"<file>: <problem>"`` message for anything it cannot read: a
missing, unreadable, truncated or corrupt file, an unknown format, or a size
that is zero or larger than :data:`MAX_SIDE` on a side (checked from the
header, before any pixel memory is allocated).  Readers do not judge pixel
values (NaN, Inf, negatives); :func:`pbrkit.envmap.load_environment` does.

Formats
-------
- Radiance RGBE ``.hdr`` / ``.pic``: own reader and writer (Ward, "Real
  Pixels", Graphics Gems II, 1991, and the Radiance sources
  ``src/common/color.h``, ``color.c``).  A stored (m, e) decodes to
  ``ldexp(m + 0.5, e - 136)`` (Radiance's ``colrval``/``colr_color``: the
  mantissa's bucket centre, exponent excess 128 plus 8 mantissa bits); e = 0
  is black.  Encoding is Radiance's ``setcolr``: ``frexp`` of the largest
  component, mantissas truncated.  Scanlines may be flat, old-style run
  length encoded ((1, 1, 1, n) repeats the previous pixel) or new-style RLE
  (a (2, 2, len >> 8, len & 255) prefix, then each of the four byte planes
  as runs: a count byte c > 128 repeats the next byte c - 128 times,
  otherwise c literal bytes follow), detected per scanline as in Radiance's
  ``freadcolrs``.  Every orientation of the resolution string
  (``-Y H +X W`` is the standard one) is honoured.  ``EXPOSURE=`` lines are
  reported in the notes but not applied (pixels are used as stored, as
  stb_image and three.js do).
- OpenEXR ``.exr``: through the ``OpenEXR`` Python package (``OpenEXR.File``),
  any pixel type and any compression the library reads (PIZ, DWAA/DWAB, ZIP,
  ...).  Channels R, G, B (A is dropped) or a single Y channel.
- Portable Float Map ``.pfm`` (P. Debevec, HDRShop): ``PF`` (RGB) or ``Pf``
  (grey), ``W H``, then a scale whose sign gives the byte order (negative =
  little endian); float32 rows stored bottom to top.
- PNG / JPEG through ``imageio`` (Pillow), decoded from sRGB to linear with
  the IEC 61966-2-1 transfer function and a :class:`LDRInputWarning`.
  16-bit RGB(A) PNGs, which Pillow reduces to 8 bits, are decoded here at
  full precision (non-interlaced files; PNG spec, ISO/IEC 15948, sec. 9).

Writers (:func:`write_hdr`, :func:`write_exr`, :func:`write_pfm`,
:func:`write_png`, :func:`write_image`) are atomic (temporary file in the
destination folder, then ``os.replace``) and deterministic: the same pixels
and options give the same bytes.
"""

from __future__ import annotations

import re
import struct
import warnings
import zlib
from pathlib import Path

import numba
import numpy as np

from ._atomic import atomic_path
from ._jit import kernel, parallel_kernel
from .errors import InputError

__all__ = [
    "MAX_SIDE",
    "LDRInputWarning",
    "srgb_to_linear",
    "linear_to_srgb",
    "image_format",
    "read_image",
    "read_image_with_notes",
    "read_hdr",
    "read_exr",
    "read_pfm",
    "read_ldr",
    "hdr_bytes",
    "pfm_bytes",
    "write_image",
    "write_hdr",
    "write_exr",
    "write_pfm",
    "write_png",
]

#: Largest accepted image side in pixels.  Larger headers are rejected as
#: absurd before any pixel memory is allocated.
MAX_SIDE = 32768


class LDRInputWarning(UserWarning):
    """An 8/16-bit display-referred image was used where HDR radiance is expected."""


# ----------------------------------------------------------------- transfer


def srgb_to_linear(c):
    """sRGB electro-optical transfer function (IEC 61966-2-1:1999):
    c / 12.92 for c <= 0.04045, else ((c + 0.055) / 1.055)^2.4."""
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((np.maximum(c, 0.04045) + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(x):
    """Inverse of :func:`srgb_to_linear` (IEC 61966-2-1:1999):
    12.92 x for x <= 0.0031308, else 1.055 x^(1/2.4) - 0.055."""
    x = np.asarray(x, dtype=np.float64)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.maximum(x, 0.0031308) ** (1.0 / 2.4) - 0.055)


# ------------------------------------------------------------------ helpers

_MAGIC = {
    b"#?": "hdr",
    b"\x76\x2f\x31\x01": "exr",
    b"PF": "pfm",
    b"Pf": "pfm",
    b"\x89PNG\r\n\x1a\n": "png",
    b"\xff\xd8\xff": "jpeg",
}
_SUFFIX = {".hdr": "hdr", ".pic": "hdr", ".rgbe": "hdr", ".exr": "exr", ".pfm": "pfm",
           ".png": "png", ".jpg": "jpeg", ".jpeg": "jpeg"}


def _check_size(path, height, width):
    if height <= 0 or width <= 0:
        raise InputError(f"image size {width}x{height} is empty", path)
    if height > MAX_SIDE or width > MAX_SIDE:
        raise InputError(f"image size {width}x{height} exceeds the {MAX_SIDE}-pixel limit on a side "
                         "(corrupt header or absurd size)", path)


def _read_bytes(path):
    with open_or_fail(path) as f:
        return f.read()


def image_format(path):
    """The format of an image file, ``'hdr'``, ``'exr'``, ``'pfm'``, ``'png'`` or
    ``'jpeg'``, from its first bytes (its suffix only breaks no ties: content
    wins).  Raises :class:`InputError` for anything else."""
    path = Path(path)
    with open_or_fail(path) as f:
        head = f.read(8)
    if not head:
        raise InputError("file is empty", path)
    for magic, fmt in _MAGIC.items():
        if head.startswith(magic):
            return fmt
    expected = _SUFFIX.get(path.suffix.lower())
    what = f"not a valid {expected.upper()} file" if expected else "unrecognised image format"
    raise InputError(f"{what} (first bytes {head[:8]!r}); expected Radiance .hdr, OpenEXR .exr, .pfm, "
                     ".png or .jpg", path)


def _as_hwc(image, what="image"):
    a = np.asarray(image)
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3 or a.shape[2] not in (1, 2, 3, 4) or a.shape[0] < 1 or a.shape[1] < 1:
        raise ValueError(f"{what} must have shape (H, W) or (H, W, C) with C in 1..4, got {np.shape(image)}")
    if a.shape[0] > MAX_SIDE or a.shape[1] > MAX_SIDE:
        raise ValueError(f"{what} of size {a.shape[1]}x{a.shape[0]} exceeds {MAX_SIDE} pixels on a side")
    return a


def _finite_float(image, what):
    a = _as_hwc(image, what)
    if not np.issubdtype(a.dtype, np.floating) and not np.issubdtype(a.dtype, np.integer):
        raise ValueError(f"{what} must be numeric, got dtype {a.dtype}")
    bad = ~np.isfinite(a) if np.issubdtype(a.dtype, np.floating) else None
    if bad is not None and bad.any():
        raise ValueError(f"{what} has {int(bad.sum())} non-finite value(s); cannot write them")
    return a


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
        elif line.startswith(b"EXPOSURE="):
            notes.append(f"header {line.decode('latin-1')} not applied (pixels used as stored)")
    if fmt is not None and fmt != "32-bit_rle_rgbe":
        if fmt == "32-bit_rle_xyze":
            raise InputError("Radiance XYZE pixels are not supported (convert to RGBE)", path)
        raise InputError(f"corrupt Radiance header: unknown FORMAT={fmt}", path)
    nl = data.find(b"\n", end + 2, end + 2 + 256)
    if nl < 0:
        raise InputError("truncated or corrupt Radiance header (no resolution line)", path)
    res = data[end + 2:nl].strip()
    m = _RES_RE.match(res)
    if m is None or m.group(2) == m.group(5):
        raise InputError(f"corrupt Radiance resolution line {res[:60]!r}", path)
    major_sign, major_axis, n_major, minor_sign, minor_axis, n_minor = m.groups()
    n_major, n_minor = int(n_major), int(n_minor)
    if major_axis == b"Y":
        height, width = n_major, n_minor
    else:
        height, width = n_minor, n_major
    _check_size(path, height, width)
    return dict(offset=nl + 1, n_major=n_major, n_minor=n_minor, major=(major_sign + major_axis).decode(),
                minor=(minor_sign + minor_axis).decode(), notes=notes)


def _read_hdr(path):
    data = _read_bytes(path)
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
    """Radiance RGBE image as float32 (H, W, 3), row 0 at the top (see module doc)."""
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


@parallel_kernel
def _rgbe_encode_rle(rgbe, out, lengths):
    """New-style RLE of each scanline of rgbe (H, W, 4) into out[y]: runs of at
    least 4 equal bytes become (128 + n, byte) with n <= 127, everything else
    literal dumps (n <= 128, bytes)."""
    height, width = rgbe.shape[0], rgbe.shape[1]
    for y in numba.prange(height):
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


# ------------------------------------------------------------------- OpenEXR


def _read_exr(path):
    import OpenEXR

    path = Path(path)
    with open_or_fail(path) as f:
        head = f.read(4)
    if head != b"\x76\x2f\x31\x01":
        raise InputError(f"not an OpenEXR file (first bytes {head!r})", path)
    try:
        header = OpenEXR.File(str(path), header_only=True).header()
    except Exception as exc:  # the library raises RuntimeError for any failure
        raise InputError(f"corrupt or truncated OpenEXR file ({_one_line(exc)})", path) from None
    (x0, y0), (x1, y1) = (np.asarray(v) for v in header["dataWindow"])
    _check_size(path, int(y1) - int(y0) + 1, int(x1) - int(x0) + 1)
    try:
        exr = OpenEXR.File(str(path), separate_channels=True)
        part = exr.parts[0]
        channels = part.channels
    except Exception as exc:
        raise InputError(f"corrupt or truncated OpenEXR file ({_one_line(exc)})", path) from None
    notes = [f"OpenEXR {str(header.get('compression', '')).split('.')[-1].replace('_COMPRESSION', '')}"]
    if len(exr.parts) > 1:
        notes.append(f"multi-part file: part 0 of {len(exr.parts)} used")
    names = list(channels)
    if all(c in channels for c in "RGB"):
        picked = ["R", "G", "B"]
    elif "Y" in channels:
        picked = ["Y"]
    else:
        raise InputError(f"no R, G, B (or Y) channels; channels are {', '.join(sorted(names))}", path)
    dropped = sorted(set(names) - set(picked))
    if dropped:
        notes.append(f"channels {', '.join(dropped)} ignored")
    planes = []
    for name in picked:
        ch = channels[name]
        if getattr(ch, "xSampling", 1) != 1 or getattr(ch, "ySampling", 1) != 1:
            raise InputError(f"channel {name} is subsampled; not supported", path)
        planes.append(ch.pixels)
    dtypes = {p.dtype for p in planes}
    notes[0] += " " + "/".join(sorted({"half" if d == np.float16 else str(d) for d in dtypes}))
    img = np.empty(planes[0].shape + (len(planes),), dtype=np.float32)
    for i, p in enumerate(planes):
        img[..., i] = p
    if int(y1) - int(y0) + 1 != img.shape[0] or int(x1) - int(x0) + 1 != img.shape[1]:
        raise InputError("pixel data does not match the data window", path)
    dw, disp = header["dataWindow"], header.get("displayWindow", header["dataWindow"])
    if any(not np.array_equal(a, b) for a, b in zip(dw, disp)):
        notes.append("data window differs from display window; data window used")
    return img, notes


def open_or_fail(path):
    """Open ``path`` for binary reading or raise :class:`InputError`."""
    try:
        return Path(path).open("rb")
    except FileNotFoundError:
        raise InputError("file not found", path) from None
    except IsADirectoryError:
        raise InputError("is a directory, not an image file", path) from None
    except OSError as exc:
        raise InputError(f"cannot read file ({exc.strerror or exc})", path) from None


def _one_line(exc):
    return " ".join(str(exc).split()) or type(exc).__name__


def read_exr(path):
    """OpenEXR image as float32 (H, W, 3) (or (H, W, 1) for a Y-only file)."""
    return _read_exr(path)[0]


_EXR_COMPRESSION = {"none": "NO_COMPRESSION", "zip": "ZIP_COMPRESSION", "zips": "ZIPS_COMPRESSION",
                    "piz": "PIZ_COMPRESSION", "rle": "RLE_COMPRESSION"}


def write_exr(path, image, half=False, compression="zip"):
    """Write ``image`` (H, W), (H, W, 1|3|4) as a scanline OpenEXR file
    (channels Y, RGB or RGBA), float32 or, with ``half``, float16, lossless
    ``compression`` in none/zip/zips/piz/rle; atomically."""
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
    with atomic_path(path) as tmp:
        OpenEXR.File(header, {name: np.ascontiguousarray(pixels)}).write(str(tmp))


# ----------------------------------------------------------------------- PFM

_PFM_RE = re.compile(rb"^(PF|Pf)\s+(\d+)\s+(\d+)\s+([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s")


def _read_pfm(path):
    data = _read_bytes(path)
    m = _PFM_RE.match(data[:256])
    if m is None:
        if data[:2] in (b"PF", b"Pf"):
            raise InputError("corrupt or truncated PFM header", path)
        raise InputError(f"not a PFM file (first bytes {data[:8]!r})", path)
    kind, width, height, scale = m.groups()
    width, height, scale = int(width), int(height), float(scale)
    _check_size(path, height, width)
    if scale == 0.0 or not np.isfinite(scale):
        raise InputError(f"corrupt PFM header: scale {scale} must be non-zero", path)
    channels = 3 if kind == b"PF" else 1
    count = width * height * channels
    offset = m.end()
    if len(data) - offset < 4 * count:
        raise InputError(f"truncated PFM data ({len(data) - offset} of {4 * count} bytes)", path)
    dtype = np.dtype("<f4" if scale < 0 else ">f4")
    img = np.frombuffer(data, dtype=dtype, count=count, offset=offset).reshape(height, width, channels)
    notes = [f"PFM {'little' if scale < 0 else 'big'}-endian"]
    if abs(scale) != 1.0:
        notes.append(f"PFM scale {abs(scale):g} not applied")
    return np.ascontiguousarray(img[::-1], dtype=np.float32), notes  # stored bottom to top


def read_pfm(path):
    """Portable Float Map as float32 (H, W, 3) or (H, W, 1), row 0 at the top."""
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


# ---------------------------------------------------------------- PNG / JPEG


@kernel
def _png_unfilter(raw, height, stride, bpp, out):
    """Undo PNG scanline filters (ISO/IEC 15948 sec. 9.2: None, Sub, Up,
    Average, Paeth) from raw (height * (1 + stride)) into out (height, stride).
    Returns the row of an unknown filter type, or -1."""
    for y in range(height):
        ftype = raw[y * (stride + 1)]
        base = y * (stride + 1) + 1
        for x in range(stride):
            v = np.int64(raw[base + x])
            a = np.int64(out[y, x - bpp]) if x >= bpp else 0
            b = np.int64(out[y - 1, x]) if y > 0 else 0
            c = np.int64(out[y - 1, x - bpp]) if (x >= bpp and y > 0) else 0
            if ftype == 0:
                r = v
            elif ftype == 1:
                r = v + a
            elif ftype == 2:
                r = v + b
            elif ftype == 3:
                r = v + (a + b) // 2
            elif ftype == 4:
                p = a + b - c
                pa = abs(p - a)
                pb = abs(p - b)
                pc = abs(p - c)
                if pa <= pb and pa <= pc:
                    r = v + a
                elif pb <= pc:
                    r = v + b
                else:
                    r = v + c
            else:
                return y
            out[y, x] = r & 255
    return -1


def _png_16bit_info(data):
    """(width, height, channels) for a non-interlaced 16-bit colour PNG, else None."""
    if len(data) < 33 or data[12:16] != b"IHDR":
        return None
    width, height, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", data[16:29])
    if depth != 16 or ctype not in (2, 6) or interlace != 0:
        return None
    return width, height, 3 if ctype == 2 else 4


def _decode_png16(data, path, width, height, channels):
    idat = []
    pos = 8
    while pos + 8 <= len(data):
        length, ctype = struct.unpack(">I4s", data[pos:pos + 8])
        if pos + 12 + length > len(data):
            raise InputError("truncated PNG chunk", path)
        if ctype == b"IDAT":
            idat.append(data[pos + 8:pos + 8 + length])
        elif ctype == b"IEND":
            break
        pos += 12 + length
    try:
        raw = np.frombuffer(zlib.decompress(b"".join(idat)), dtype=np.uint8)
    except zlib.error as exc:
        raise InputError(f"corrupt PNG image data ({exc})", path) from None
    stride = width * channels * 2
    if raw.size < height * (stride + 1):
        raise InputError("truncated PNG image data", path)
    rows = np.empty((height, stride), dtype=np.uint8)
    bad = _png_unfilter(raw, height, stride, channels * 2, rows)
    if bad >= 0:
        raise InputError(f"corrupt PNG filter type in row {bad}", path)
    return rows.view(">u2").reshape(height, width, channels).astype(np.uint16)


def _read_ldr(path, fmt):
    import imageio.v3 as iio

    data = _read_bytes(path)
    info = _png_16bit_info(data) if fmt == "png" else None
    if info is not None:
        _check_size(path, info[1], info[0])
        pixels = _decode_png16(data, path, *info)
    else:
        try:
            props = iio.improps(data, extension=".png" if fmt == "png" else ".jpg")
            shape = props.shape
            if len(shape) >= 2:
                _check_size(path, shape[0], shape[1])
            pixels = iio.imread(data, extension=".png" if fmt == "png" else ".jpg")
        except InputError:
            raise
        except Exception as exc:
            raise InputError(f"corrupt or truncated {fmt.upper()} file ({_one_line(exc)})", path) from None
    if pixels.ndim == 2:
        pixels = pixels[:, :, None]
    if pixels.dtype not in (np.uint8, np.uint16) or pixels.ndim != 3:
        raise InputError(f"unsupported {fmt.upper()} pixel layout {pixels.dtype} {pixels.shape}", path)
    bits = 8 * pixels.dtype.itemsize
    notes = [f"{fmt.upper()} {bits}-bit sRGB decoded to linear"]
    if fmt == "png" and info is None and len(data) > 28 and data[24] == 16 and pixels.dtype == np.uint8:
        notes.append("16-bit PNG read at 8-bit precision (interlaced or grey+alpha, decoded by Pillow)")
    if pixels.shape[2] in (2, 4):
        pixels = pixels[..., :-1]
        notes.append("alpha ignored")
    linear = srgb_to_linear(pixels / float((1 << bits) - 1)).astype(np.float32)
    return linear, notes


def read_ldr(path):
    """PNG or JPEG as linear float32 (H, W, C) (sRGB decoded; alpha dropped)."""
    fmt = image_format(path)
    if fmt not in ("png", "jpeg"):
        raise InputError(f"not a PNG or JPEG file ({fmt})", path)
    return _read_ldr(path, fmt)[0]


def _png_bytes16(a, srgb):
    height, width, channels = a.shape
    ctype = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    rows = a.astype(">u2").reshape(height, width * channels).view(np.uint8)
    raw = np.concatenate([np.zeros((height, 1), dtype=np.uint8), rows], axis=1)  # filter 0 per row

    def chunk(tag, body):
        return struct.pack(">I", len(body)) + tag + body + struct.pack(">I", zlib.crc32(tag + body) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", width, height, 16, ctype, 0, 0, 0)
    colour = chunk(b"sRGB", b"\x00") if srgb else b""  # sRGB chunk (perceptual intent) only for sRGB data
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + colour
            + chunk(b"IDAT", zlib.compress(raw.tobytes(), 6)) + chunk(b"IEND", b""))


def write_png(path, image, bits=8, srgb=True):
    """Write float ``image`` (H, W), (H, W, 1..4) in [0, 1] as an 8- or 16-bit
    PNG, atomically.  With ``srgb`` (the default, CONVENTIONS "Colour") colour
    channels are encoded with the sRGB transfer function (alpha, the 2nd or
    4th channel, stays linear); values are clipped to [0, 1] and rounded.
    8-bit files go through imageio (Pillow); 16-bit ones, which Pillow cannot
    write in colour, are encoded here (PNG spec: filter 0, zlib level 6, an
    sRGB chunk when ``srgb``).  Note that :func:`read_image` decodes every
    PNG as sRGB: linear PNGs are for other consumers (e.g. lookup tables)."""
    a = _finite_float(image, "image").astype(np.float64)
    if bits not in (8, 16):
        raise ValueError(f"PNG bits must be 8 or 16, got {bits}")
    if srgb:
        colour = a.shape[2] if a.shape[2] in (1, 3) else a.shape[2] - 1
        a = a.copy()
        a[..., :colour] = linear_to_srgb(np.clip(a[..., :colour], 0.0, 1.0))
    q = np.rint(np.clip(a, 0.0, 1.0) * ((1 << bits) - 1))
    with atomic_path(path, suffix=".png") as tmp:
        if bits == 16:
            tmp.write_bytes(_png_bytes16(q.astype(np.uint16), srgb))
        else:
            import imageio.v3 as iio

            q8 = q.astype(np.uint8)
            iio.imwrite(tmp, q8[..., 0] if q8.shape[2] == 1 else q8, extension=".png")


# ------------------------------------------------------------------ dispatch


def read_image_with_notes(path):
    """(pixels, format, notes) for any supported file: pixels float32 (H, W, C)
    linear; notes describe what was read and any adjustment.  PNG and JPEG
    emit a :class:`LDRInputWarning`."""
    fmt = image_format(path)
    if fmt == "hdr":
        img, notes = _read_hdr(path)
    elif fmt == "exr":
        img, notes = _read_exr(path)
    elif fmt == "pfm":
        img, notes = _read_pfm(path)
    else:
        img, notes = _read_ldr(path, fmt)
        warnings.warn(f"{path}: low-dynamic-range {fmt.upper()} input, sRGB-decoded; highlights are "
                      "clipped at 1.0, so lighting from it is too dim and flat (use .hdr or .exr)",
                      LDRInputWarning, stacklevel=3)
    return img, fmt, notes


def read_image(path):
    """Pixels of any supported file as linear float32 (H, W, C)."""
    return read_image_with_notes(path)[0]


def write_image(path, image, **options):
    """Write by suffix: ``.hdr`` (:func:`write_hdr`), ``.exr`` (:func:`write_exr`),
    ``.pfm`` (:func:`write_pfm`) or ``.png`` (:func:`write_png`)."""
    suffix = Path(path).suffix.lower()
    writers = {".hdr": write_hdr, ".exr": write_exr, ".pfm": write_pfm, ".png": write_png}
    if suffix not in writers:
        raise ValueError(f"{path}: cannot write images with suffix {suffix!r}; use .hdr, .exr, .pfm or .png")
    writers[suffix](path, image, **options)
