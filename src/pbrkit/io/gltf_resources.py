"""The files and images a glTF 2.0 document names, read as untrusted input.

A glTF model usually comes from elsewhere, so what it names is read under the
rules of :mod:`pbrkit.core.inputs`:

- a buffer or image ``uri`` (glTF 2.0 sec. 3.6.1.1 and 3.8.4, "URIs"; sec.
  2.8: relative paths are relative to the glTF file) is either a base64
  ``data:`` URI (RFC 2397) or a relative path that must resolve, after
  percent-decoding, ``..`` and symbolic links, to a *regular* file under the
  glTF file's folder or under a root the user allows (``--allow-root``, the
  scene key ``allow_roots``); :func:`pbrkit.core.inputs.confined_path`;
- an external buffer is read to exactly its ``byteLength`` (glTF 2.0 sec.
  3.6.1.1): a file shorter than that is refused before reading, a longer one is
  read no further than ``byteLength``;
- an image file is read to at most :data:`MAX_IMAGE_BYTES`;
- before any image is decoded (an embedded one or one named by uri), its
  declared width and height are read from its header: the PNG ``IHDR`` chunk
  (ISO/IEC 15948 sec. 11.2.2) or the JPEG ``SOFn`` marker segment (ITU-T T.81
  sec. B.2.2); glTF 2.0 core images are PNG or JPEG (sec. 3.8.4, "Images"),
  anything else is refused; a side over
  :data:`pbrkit.io.image_checks.MAX_SIDE` is refused, and the decoded size
  (:data:`BYTES_PER_TEXEL` per texel) is checked against the memory available
  (:func:`pbrkit.core.inputs.check_allocation`), so a decompression bomb (a
  small file that declares 60000 x 60000 texels) is refused before decoding.

Errors are :class:`ValueError` naming the JSON field (``buffers[0].uri``) and
what was expected, never the content of a file; the caller adds the file name.
"""

from __future__ import annotations

import base64
import binascii
import os
import struct
import warnings
from pathlib import Path

import numpy as np

from ..core.color import srgb_to_linear
from ..core.errors import InputError
from ..core.inputs import check_allocation, confined_path, describe, open_regular, read_bytes
from .image_checks import MAX_SIDE

__all__ = ["BYTES_PER_TEXEL", "MAX_IMAGE_BYTES", "allowed_root", "buffer_file_bytes", "data_uri_bytes", "decode_image",
           "image_header", "uri_bytes"]

#: Largest image file a glTF may name (a 16384^2 RGBA PNG compresses to far less).
MAX_IMAGE_BYTES = 1 << 30
#: Peak bytes per texel of decoding an image into RGBA float32 texels: the decoder's
#: image, its NumPy copy, the RGBA float32 result (16) and the per-channel look-ups that
#: fill it.  Measured as the growth of the peak RSS over :func:`decode_image` (a 2048^2
#: 8-bit RGB / RGBA PNG): 51 to 56 bytes; the constant leaves room for 16-bit images.
BYTES_PER_TEXEL = 96

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_JPEG_SOI = b"\xff\xd8"
#: JPEG start-of-frame markers (ITU-T T.81 table B.1): SOF0-3, 5-7, 9-11, 13-15.
_JPEG_SOF = frozenset(range(0xC0, 0xD0)) - {0xC4, 0xC8, 0xCC}
#: JPEG markers without a length (T.81 sec. B.1.1.3): TEM, RST0-7, SOI.
_JPEG_STANDALONE = frozenset([0x01, 0xD8, *range(0xD0, 0xD8)])


def allowed_root(path, base_dir, what):
    """``path`` (relative to ``base_dir`` unless absolute) as an existing folder that
    glTF models may name files under (``--allow-root``, the scene key ``allow_roots``),
    else ValueError naming ``what``."""
    p = Path(path).expanduser()
    if not p.is_absolute() and base_dir is not None:
        p = Path(base_dir) / p
    if not p.is_dir():
        raise ValueError(f"{what} {str(p)!r} is not a folder; expected a folder a glTF model may read files from")
    return str(p)


def data_uri_bytes(uri):
    """The bytes of a base64 ``data:`` URI (RFC 2397)."""
    head, comma, payload = uri.partition(",")
    if not comma:
        raise ValueError("malformed data URI: no ',' before the data")
    if not head.endswith(";base64"):
        raise ValueError("data URIs must be base64-encoded (data:<type>;base64,<data>)")
    try:
        return base64.b64decode("".join(payload.split()), validate=True)
    except (binascii.Error, ValueError) as exc:
        raise ValueError(f"malformed data URI: invalid base64 ({exc})") from None


def _reference_error(where, uri, exc):
    """A ValueError for a file a glTF names that cannot be read (``exc``: an
    :class:`InputError` about the resolved file, whose path is not repeated)."""
    return ValueError(f"{where} {describe(uri)}: {exc.problem}")


def uri_bytes(uri, where, confinement, limit, expected):
    """The bytes of a ``data:`` URI or of the confined regular file a relative ``uri``
    names (module docstring), at most ``limit`` bytes; ValueError naming ``where``."""
    if uri.startswith("data:"):
        try:
            return data_uri_bytes(uri)
        except ValueError as exc:
            raise ValueError(f"{where}: {exc}") from None
    try:
        path = confined_path(uri, confinement, where)
    except InputError as exc:
        raise ValueError(exc.problem) from None
    try:
        return read_bytes(path, limit, expected)
    except InputError as exc:
        raise _reference_error(where, uri, exc) from None


def buffer_file_bytes(uri, where, confinement, byte_length, asset=None):
    """Exactly ``byte_length`` bytes of the external buffer file ``uri`` names (module
    docstring): confined, a regular file, at least ``byte_length`` bytes long (checked
    before reading), memory for them checked, and nothing read past them."""
    try:
        path = confined_path(uri, confinement, where)
    except InputError as exc:
        raise ValueError(exc.problem) from None
    expected = f"a buffer of {byte_length} bytes"
    try:
        f = open_regular(path, None, expected)
    except InputError as exc:
        raise _reference_error(where, uri, exc) from None
    buffer = where.rsplit(".", 1)[0]  # "buffers[0]"
    with f:
        size = os.fstat(f.fileno()).st_size
        if size < byte_length:
            raise ValueError(f"{where} {describe(uri)} holds {size} bytes, fewer than the byteLength {byte_length} "
                             f"of {buffer} (truncated file?)")
        check_allocation(byte_length, f"{buffer} (byteLength {byte_length})", asset)
        try:
            data = f.read(byte_length)
        except OSError as exc:
            raise ValueError(f"{where} {describe(uri)}: cannot read file ({exc.strerror or exc})") from None
    if len(data) < byte_length:
        raise ValueError(f"{where} {describe(uri)} ended after {len(data)} bytes while it was read, fewer than "
                         f"its byteLength {byte_length}")
    return data


# ------------------------------------------------------------------ images


def _png_size(data):
    """(width, height) of the PNG ``IHDR`` chunk, which must come first (ISO/IEC 15948 sec. 5.6, 11.2.2)."""
    if len(data) < 8 + 8 + 13 or bytes(data[12:16]) != b"IHDR":
        raise ValueError("a PNG image without its IHDR header chunk (truncated or not PNG)")
    length, _, width, height = struct.unpack(">I4sII", bytes(data[8:24]))
    if length != 13:
        raise ValueError("a PNG image whose IHDR chunk is not 13 bytes long (corrupt)")
    return width, height


def _jpeg_size(data):
    """(width, height) of the first JPEG ``SOFn`` marker segment (ITU-T T.81 sec. B.2.2),
    walking the marker segments that come before it (sec. B.1.1)."""
    n = len(data)
    i = 2
    while i < n:
        if data[i] != 0xFF:
            raise ValueError("a JPEG image whose marker segments are corrupt before its frame header")
        while i < n and data[i] == 0xFF:  # fill bytes (sec. B.1.1.2)
            i += 1
        if i >= n:
            break
        marker = data[i]
        i += 1
        if marker in _JPEG_STANDALONE:
            continue
        if marker in (0xD9, 0xDA):  # EOI, SOS: image data before any frame header
            break
        if i + 2 > n:
            break
        length = (data[i] << 8) | data[i + 1]
        if length < 2:
            raise ValueError("a JPEG image with a marker segment shorter than its length field (corrupt)")
        if marker in _JPEG_SOF:
            if i + 7 > n or length < 8:
                break
            height = (data[i + 3] << 8) | data[i + 4]
            width = (data[i + 5] << 8) | data[i + 6]
            if height == 0:
                raise ValueError("a JPEG image whose frame header declares height 0 (a DNL marker, not supported)")
            return width, height
        i += length
    raise ValueError("a JPEG image without a frame header (SOFn) before its image data (truncated or corrupt)")


def image_header(data):
    """``(format, width, height)`` declared by the header of a PNG or JPEG image
    (module docstring), without decoding it; ValueError for anything else."""
    head = bytes(data[:8])
    if head == _PNG_SIGNATURE:
        return ("PNG", *_png_size(data))
    if head[:2] == _JPEG_SOI:
        return ("JPEG", *_jpeg_size(data))
    raise ValueError("not a PNG or JPEG image (glTF 2.0 images are PNG or JPEG, sec. 3.8.4; its first bytes are "
                     "neither signature)")


def _check_header(data, where, asset):
    """The declared (width, height) of image ``data``, refused when absurd or when
    decoding it would not fit in memory (module docstring)."""
    try:
        kind, width, height = image_header(data)
    except ValueError as exc:
        raise ValueError(f"cannot decode {where}: {exc}") from None
    if not (1 <= width <= MAX_SIDE and 1 <= height <= MAX_SIDE):
        raise ValueError(f"{where}: its {kind} header declares {width} x {height} texels; expected sides from 1 to "
                         f"{MAX_SIDE} (refused before decoding)")
    check_allocation(width * height * BYTES_PER_TEXEL, f"{where} ({kind}, {width} x {height} texels)", asset,
                     "a texture this large cannot be decoded here")
    return width, height


def decode_image(data, where, srgb, asset=None):
    """Texels (H, W, 4) float32 of the PNG or JPEG image ``data``, sRGB-decoded when
    ``srgb``; its header checked first (module docstring).  ValueError naming ``where``
    (:class:`InputError` naming ``asset`` when memory is short)."""
    import imageio.v3 as iio

    width, height = _check_header(data, where, asset)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            pixels = np.asarray(iio.imread(bytes(data), index=0))
    except MemoryError:
        raise
    except Exception as exc:  # decoders raise many kinds on corrupt data
        detail = " ".join(str(exc).split()) or type(exc).__name__
        raise ValueError(f"cannot decode {where} (a corrupt PNG or JPEG image): {detail[:120]}") from None
    if pixels.ndim == 2:
        pixels = pixels[..., None]
    if pixels.ndim != 3 or not 1 <= pixels.shape[2] <= 4 or pixels.shape[:2] != (height, width):
        raise ValueError(f"{where} decodes to shape {pixels.shape}; expected its declared {height} x {width} "
                         "texels with 1 to 4 channels")
    if pixels.dtype in (np.uint8, np.uint16):
        # integer texels: decode through a table of every code (exactly the formula, per code)
        top = np.iinfo(pixels.dtype).max
        codes = np.arange(top + 1, dtype=np.float64) / top
        unorm = codes.astype(np.float32)
        return _rgba(pixels, srgb, unorm, srgb_to_linear(codes).astype(np.float32))
    values = pixels.astype(np.float32)
    if not np.all(np.isfinite(values)):
        raise ValueError(f"{where} has non-finite texels")
    return _rgba(values, srgb)


def _rgba(values, srgb, unorm=None, decoded=None):
    """(H, W, C) texels -> (H, W, 4) float32 RGBA (grey and grey-alpha expanded), the
    colour channels sRGB-decoded when ``srgb``.  Float texels are values in [0, 1];
    integer ones are codes, looked up in ``unorm`` (code / max) and, for sRGB colour,
    ``decoded`` (:func:`pbrkit.core.color.srgb_to_linear` of each code)."""
    c = values.shape[2]
    colour = values[..., :1] if c in (1, 2) else values[..., :3]
    alpha = values[..., 1] if c == 2 else values[..., 3] if c == 4 else None
    rgba = np.ones(values.shape[:2] + (4,), dtype=np.float32)
    if unorm is None:
        rgba[..., :3] = srgb_to_linear(colour).astype(np.float32) if srgb else colour
    else:
        rgba[..., :3] = np.take(decoded if srgb else unorm, colour)
    if alpha is not None:
        rgba[..., 3] = alpha if unorm is None else np.take(unorm, alpha)
    return rgba

