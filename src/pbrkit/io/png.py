"""PNG and JPEG files: 8- and 16-bit, sRGB-decoded on reading (see :mod:`pbrkit.io.images`).

16-bit colour PNGs are decoded here from the PNG specification (ISO/IEC 15948,
sections 5 "Datastream structure", 9 "Filtering" and 10 "Compression"); the
others go through imageio (Pillow).  The file is untrusted input
(:mod:`pbrkit.io.image_checks`): the IHDR size is checked against the size
limits, against what the compressed data can hold (deflate expands at most
1032-fold, RFC 1951) and against the memory available before decompressing,
which is bounded by the size declared; no message quotes the file.
"""

from __future__ import annotations

import struct
import zlib

import numpy as np

from ..core.atomic import atomic_path
from ..core.color import linear_to_srgb, srgb_to_linear
from ..core.errors import InputError
from ..core.jit import kernel
from .image_checks import (
    ALPHA_IGNORED,
    _check_pixels,
    _check_size,
    _finite_float,
    _read_bytes,
    image_format,
    safe_reason,
)

__all__ = [
    "read_ldr",
    "PNG_SIGNATURE",
    "png_chunk",
    "png_file_bytes",
    "png_bytes16",
    "write_png",
]

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


#: Largest expansion of deflate (RFC 1951): 258 bytes from a 2-bit code, about 1032 to 1.
DEFLATE_MAX_RATIO = 1032


def inflate_bounded(compressed, size, path, what="PNG image data"):
    """The first ``size`` bytes zlib-decompressed from ``compressed``, refused
    (:class:`InputError`) when ``compressed`` cannot hold that many (deflate's
    largest expansion, :data:`DEFLATE_MAX_RATIO`), is corrupt, or ends before them;
    never more than ``size`` bytes are produced."""
    if size > DEFLATE_MAX_RATIO * len(compressed) + 64:
        raise InputError(f"truncated {what}: {size} bytes declared, {len(compressed)} compressed bytes can hold "
                         f"at most {DEFLATE_MAX_RATIO * len(compressed) + 64}", path)
    try:
        raw = zlib.decompressobj().decompress(compressed, size)
    except zlib.error:
        raise InputError(f"corrupt {what} (not valid zlib data)", path) from None
    if len(raw) < size:
        raise InputError(f"truncated {what} ({len(raw)} of {size} bytes)", path)
    return raw


def _decode_png16(data, path, width, height, channels):
    """The pixels (H, W, C) uint16 of a non-interlaced 16-bit colour PNG: the size
    checked against the limits, the compressed data (:func:`inflate_bounded`) and
    the memory before anything is decompressed."""
    _check_size(path, height, width)
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
    stride = width * channels * 2
    compressed = b"".join(idat)
    need = height * (stride + 1)
    if need > DEFLATE_MAX_RATIO * len(compressed) + 64:
        raise InputError(f"truncated PNG image data: a {width}x{height} image needs {need} bytes, its "
                         f"{len(compressed)} compressed bytes hold at most {DEFLATE_MAX_RATIO * len(compressed) + 64}",
                         path)
    # compressed rows (1 + 8C bytes a pixel), unfiltered rows, uint16, float64 and float32 samples
    _check_pixels(path, height, width, 1 + 24 * channels, "PNG image")
    raw = np.frombuffer(inflate_bounded(compressed, need, path), dtype=np.uint8)
    rows = np.empty((height, stride), dtype=np.uint8)
    bad = _png_unfilter(raw, height, stride, channels * 2, rows)
    if bad >= 0:
        raise InputError(f"corrupt PNG filter type in row {bad}", path)
    return rows.view(">u2").reshape(height, width, channels).astype(np.uint16)


def _read_ldr(path, fmt):
    import imageio.v3 as iio

    data = _read_bytes(path, "a PNG or JPEG file")
    info = _png_16bit_info(data) if fmt == "png" else None
    if info is not None:
        pixels = _decode_png16(data, path, *info)
    else:
        try:
            props = iio.improps(data, plugin="pillow", extension=".png" if fmt == "png" else ".jpg")
            shape = props.shape
            if len(shape) >= 2:
                channels = shape[2] if len(shape) > 2 else 1
                # decoded samples (up to 2 bytes), the float64 sRGB decoding (2 arrays) and float32
                _check_pixels(path, shape[0], shape[1], 22 * channels, f"{fmt.upper()} image")
            pixels = iio.imread(data, plugin="pillow", extension=".png" if fmt == "png" else ".jpg")
        except InputError:
            raise
        except MemoryError:
            raise InputError(f"not enough memory to decode the {fmt.upper()} file", path) from None
        except Exception as exc:
            raise InputError(f"corrupt or truncated {fmt.upper()} file ({safe_reason(exc)})", path) from None
    if pixels.ndim == 2:
        pixels = pixels[:, :, None]
    if pixels.dtype not in (np.uint8, np.uint16) or pixels.ndim != 3:
        raise InputError(f"unsupported {fmt.upper()} pixel layout {pixels.dtype} {pixels.shape}; expected 8- or "
                         "16-bit grey, RGB or RGBA", path)
    bits = 8 * pixels.dtype.itemsize
    notes = [f"{fmt.upper()} {bits}-bit sRGB decoded to linear"]
    if fmt == "png" and info is None and len(data) > 28 and data[24] == 16 and pixels.dtype == np.uint8:
        notes.append("16-bit PNG read at 8-bit precision (interlaced or grey+alpha, decoded by Pillow)")
    if pixels.shape[2] in (2, 4):
        pixels = pixels[..., :-1]
        notes.append(ALPHA_IGNORED)
    linear = srgb_to_linear(pixels / float((1 << bits) - 1)).astype(np.float32)
    return linear, notes


def read_ldr(path):
    """PNG or JPEG as linear float32 (H, W, C) (sRGB decoded; alpha dropped)."""
    fmt = image_format(path)
    if fmt not in ("png", "jpeg"):
        raise InputError(f"not a PNG or JPEG file ({fmt})", path)
    return _read_ldr(path, fmt)[0]


PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_chunk(tag, body):
    """One PNG chunk: length, type, data, CRC-32 of type and data (ISO/IEC 15948 sec. 5.3)."""
    return struct.pack(">I", len(body)) + tag + body + struct.pack(">I", zlib.crc32(tag + body) & 0xFFFFFFFF)


def png_file_bytes(width, height, depth, colour_type, filtered, level=6, extra=b""):
    """The bytes of a non-interlaced PNG from its ``filtered`` scanlines (each row
    its filter-type byte then the row): signature, IHDR, the ``extra`` chunks,
    one IDAT (zlib at ``level``), IEND; deterministic (no time or text chunks)."""
    ihdr = struct.pack(">IIBBBBB", width, height, depth, colour_type, 0, 0, 0)
    return (PNG_SIGNATURE + png_chunk(b"IHDR", ihdr) + extra
            + png_chunk(b"IDAT", zlib.compress(np.ascontiguousarray(filtered).tobytes(), level))
            + png_chunk(b"IEND", b""))


def _png_bytes16(a, srgb):
    height, width, channels = a.shape
    ctype = {1: 0, 2: 4, 3: 2, 4: 6}[channels]
    rows = a.astype(">u2").reshape(height, width * channels).view(np.uint8)
    raw = np.concatenate([np.zeros((height, 1), dtype=np.uint8), rows], axis=1)  # filter 0 per row
    colour = png_chunk(b"sRGB", b"\x00") if srgb else b""  # sRGB chunk (perceptual intent) only for sRGB data
    return png_file_bytes(width, height, 16, ctype, raw, 6, colour)


def _quantised(image, bits, srgb):
    a = _finite_float(image, "image").astype(np.float64)
    if bits not in (8, 16):
        raise ValueError(f"PNG bits must be 8 or 16, got {bits}")
    if srgb:
        colour = a.shape[2] if a.shape[2] in (1, 3) else a.shape[2] - 1
        a = a.copy()
        a[..., :colour] = linear_to_srgb(np.clip(a[..., :colour], 0.0, 1.0))
    return np.rint(np.clip(a, 0.0, 1.0) * ((1 << bits) - 1))


def png_bytes16(image, srgb=True):
    """The bytes of the 16-bit PNG :func:`write_png` writes with ``bits=16``."""
    return _png_bytes16(_quantised(image, 16, srgb).astype(np.uint16), srgb)


def write_png(path, image, bits=8, srgb=True):
    """Write float ``image`` (H, W), (H, W, 1..4) in [0, 1] as an 8- or 16-bit
    PNG, atomically.  With ``srgb`` (the default, CONVENTIONS "Colour") colour
    channels are encoded with the sRGB transfer function (alpha, the 2nd or
    4th channel, stays linear); values are clipped to [0, 1] and rounded.
    8-bit files go through imageio (Pillow); 16-bit ones, which Pillow cannot
    write in colour, are encoded here (PNG spec: filter 0, zlib level 6, an
    sRGB chunk when ``srgb``).  Note that :func:`read_image` decodes every
    PNG as sRGB: linear PNGs are for other consumers (e.g. lookup tables).
    Write failures raise :class:`~pbrkit.core.errors.OutputError` naming ``path``."""
    q = _quantised(image, bits, srgb)
    if bits == 16:
        data = _png_bytes16(q.astype(np.uint16), srgb)
    else:
        import imageio.v3 as iio

        q8 = q.astype(np.uint8)
        # encoded in memory: the file is written here, so a full disk is one OSError (Pillow
        # writing the file itself fails again when imageio closes it, as an "ignored" exception)
        data = iio.imwrite("<bytes>", q8[..., 0] if q8.shape[2] == 1 else q8, extension=".png")
    with atomic_path(path, suffix=".png") as tmp:
        tmp.write_bytes(data)
