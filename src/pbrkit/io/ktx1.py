"""KTX 1.1 texture files, as Filament loads them: a writer and a strict reader.

Written from the Khronos "KTX File Format Specification" version 1.1
(Khronos Group, 2013, with the 2021 clarifications).  The file is::

    identifier   «KTX 11»\\r\\n\\x1A\\n                            12 bytes
    header       endianness (0x04030201), glType, glTypeSize, glFormat,
                 glInternalFormat, glBaseInternalFormat, pixelWidth,
                 pixelHeight, pixelDepth = 0, numberOfArrayElements = 0,
                 numberOfFaces (1 or 6), numberOfMipmapLevels,
                 bytesOfKeyValueData                            13 x UInt32
    key/value    each entry: keyAndValueByteSize (UInt32), the key (UTF-8,
                 NUL-terminated), the value bytes, zero padding to 4 bytes
    levels       level 0 (largest) first; each: imageSize (UInt32), then
                 the faces +X, -X, +Y, -Y, +Z, -Z (or the one image) back
                 to back, rows tightly packed (4- and 8-byte texels need
                 no row, cube or mip padding)

``imageSize`` is the size of one level of the image, except for a cube map
that is not an array, where it is the size of **one face** (spec section
"imageSize").  Everything is little-endian; pbrkit writes and reads only
files whose endianness word reads 0x04030201.  Row 0 of a stored image is
t = 0 of a cube face (pbrkit ``CONVENTIONS.md``, "Cube maps"), which is how
Filament's cmgen writes its cube maps and how its reader uploads them.

Formats (:data:`GL_FORMATS`) are the two Filament's IBL loader takes:

* ``R11F_G11F_B10F``: glInternalFormat 0x8C3A, glFormat 0x1907 (RGB),
  glType **0x8C3A**, glTypeSize 1, glBaseInternalFormat 0x1907.  The texel
  is the packed 32-bit B10G11R11 unsigned float (R in bits 0..10,
  :mod:`pbrkit.io.float_packing`).  The spec's glType for it would be
  UNSIGNED_INT_10F_11F_11F_REV (0x8C3B) with glTypeSize 4, but Filament's
  KTX1 reader (``libs/ktxreader/src/Ktx1Reader.cpp``, its pixel-type
  mapping) recognises only 0x8C3A in glType, which is what cmgen
  (``tools/cmgen/src/cmgen.cpp``) writes, with glTypeSize 1; with 0x8C3B,
  Filament 1.53.4's ``createIblFromKtx1`` fails a ``Texture::setImage``
  precondition and aborts (tests/engines/test_engine_filament.py).  pbrkit writes
  what Filament reads; on reading it accepts both glTypes (0x8C3B files are
  valid KTX 1.1, e.g. from other tools), glTypeSize 1 or 4, and the
  glFormat / glBaseInternalFormat 0x8C3A of older cmgen files.
* ``RGBA16F``: glInternalFormat 0x881A, glFormat 0x1908 (RGBA), glType
  0x140B (HALF_FLOAT), glTypeSize 2, glBaseInternalFormat 0x1908.  RGB input
  gets alpha 1.  Filament loads it; its JS ``createIblFromKtx1`` prints a
  console warning for any format but R11F_G11F_B10F / RG16F / RGB16F.

Filament's container class (``libs/image/src/Ktx1Bundle.cpp``) keeps each
key/value value as raw bytes; its ``sh`` key holds the 9 pre-scaled SH
coefficients as text (:func:`filament_sh_text`).  The code here is written
from the specification and from reading those files; nothing is copied.
The output is deterministic: the same input gives the same bytes.
"""

from __future__ import annotations

import struct

import numpy as np

from ..core.atomic import write_bytes
from ..core.errors import InputError
from .containers import (
    check_decoded,
    decode_texels,
    encode_texels,
    format_code,
    max_mip_levels,
    read_container,
    texel_size,
    validate_levels,
)

__all__ = [
    "GL_FORMATS",
    "KTX1_IDENTIFIER",
    "filament_sh_text",
    "gl_format_code",
    "ktx1_bytes",
    "parse_ktx1",
    "read_ktx1",
    "write_ktx1",
]

#: The 12-byte file identifier, «KTX 11»\r\n\x1A\n.
KTX1_IDENTIFIER = b"\xabKTX 11\xbb\r\n\x1a\n"
#: The endianness word as a little-endian writer stores it.
KTX1_ENDIANNESS = 0x04030201

_GL_RGB = 0x1907
_GL_RGBA = 0x1908
_GL_HALF_FLOAT = 0x140B
_GL_R11F_G11F_B10F = 0x8C3A
_GL_UNSIGNED_INT_10F_11F_11F_REV = 0x8C3B
_GL_RGBA16F = 0x881A

#: Supported formats: name -> (glInternalFormat, glFormat, glType, glTypeSize,
#: glBaseInternalFormat, texel encoding, channels); the values written.
GL_FORMATS = {
    "R11F_G11F_B10F": (_GL_R11F_G11F_B10F, _GL_RGB, _GL_R11F_G11F_B10F, 1, _GL_RGB, "b10g11r11", 3),
    "RGBA16F": (_GL_RGBA16F, _GL_RGBA, _GL_HALF_FLOAT, 2, _GL_RGBA, "float16", 4),
}
_BY_CODE = {v[0]: (name,) + v[1:] for name, v in GL_FORMATS.items()}

# What the reader accepts besides the values written, per glInternalFormat:
# (glFormat, glType, glTypeSize, glBaseInternalFormat) sets.
_ACCEPTED = {
    _GL_R11F_G11F_B10F: (
        {_GL_RGB, _GL_R11F_G11F_B10F},  # older cmgen files carry 0x8C3A in glFormat
        {_GL_R11F_G11F_B10F, _GL_UNSIGNED_INT_10F_11F_11F_REV},  # cmgen's / the spec's glType
        {1, 4},  # cmgen's / the spec's glTypeSize for a packed 32-bit type
        {_GL_RGB, _GL_R11F_G11F_B10F},
    ),
    _GL_RGBA16F: ({_GL_RGBA}, {_GL_HALF_FLOAT}, {2}, {_GL_RGBA}),
}

_HEADER_FIELDS = (
    "endianness glType glTypeSize glFormat glInternalFormat glBaseInternalFormat "
    "pixelWidth pixelHeight pixelDepth numberOfArrayElements numberOfFaces "
    "numberOfMipmapLevels bytesOfKeyValueData"
).split()
_HEADER_SIZE = 12 + 4 * len(_HEADER_FIELDS)  # 64


def gl_format_code(gl_format):
    """glInternalFormat of ``gl_format``: an int, or a name of
    :data:`GL_FORMATS` with or without the ``GL_`` prefix.  Raises
    :class:`~pbrkit.core.errors.InputError` for unsupported formats."""
    return format_code(gl_format, GL_FORMATS, _BY_CODE, "GL_", "KTX1 glInternalFormat")


def _pad4(n):
    return -n % 4


def _key_value_block(key_values):
    """The key/value data: entries in the given order, each padded to 4 bytes."""
    out = bytearray()
    for key, value in (key_values or {}).items():
        if not isinstance(key, str) or not key or "\x00" in key:
            raise InputError(f"KTX1 key {key!r} must be a non-empty string without NUL")
        if isinstance(value, str):
            value = value.encode("utf-8") + b"\x00"
        elif isinstance(value, (bytes, bytearray, memoryview)):
            value = bytes(value)
        else:
            raise InputError(f"KTX1 value of {key!r} must be str (stored NUL-terminated UTF-8) or bytes")
        key_and_value = key.encode("utf-8") + b"\x00" + value
        out += struct.pack("<I", len(key_and_value)) + key_and_value + b"\x00" * _pad4(len(key_and_value))
    return bytes(out)


def ktx1_bytes(levels, gl_format, cube=False, key_values=None):
    """The bytes of a KTX 1.1 file; see :func:`write_ktx1`."""
    code = gl_format_code(gl_format)
    name, gl_fmt, gl_type, gl_type_size, gl_base, encoding, channels = _BY_CODE[code]
    arrays, width, height = validate_levels(levels, cube)
    kvd = _key_value_block(key_values)
    header = struct.pack(
        "<12s13I",
        KTX1_IDENTIFIER,
        KTX1_ENDIANNESS,
        gl_type,
        gl_type_size,
        gl_fmt,
        code,
        gl_base,
        width,
        height,
        0,  # pixelDepth: 2D or cube
        0,  # numberOfArrayElements: not an array
        6 if cube else 1,
        len(arrays),
        len(kvd),
    )
    parts = [header, kvd]
    for p, a in enumerate(arrays):
        data = encode_texels(a, encoding, channels, what=f"{name} level {p}")
        # Non-array cube map: imageSize counts one face; the 6 faces follow.
        image_size = len(data) // 6 if cube else len(data)
        parts += [struct.pack("<I", image_size), data]  # 4-byte texels: no padding
    return b"".join(parts)


def write_ktx1(path, levels, gl_format, cube=False, key_values=None):
    """Write a KTX 1.1 file of float texels and return ``path``.

    ``levels`` is a list of arrays, level 0 (largest) first: (H, W, C) images
    for a 2D texture, (6, N, N, C) for a cube map with faces +X, -X, +Y, -Y,
    +Z, -Z (row 0 of a face is t = 0, CONVENTIONS.md "Cube maps").  Level p
    must be max(1, W >> p) x max(1, H >> p); a partial chain is allowed (the
    header records how many levels there are).  ``gl_format`` is a name or
    glInternalFormat of :data:`GL_FORMATS` ("R11F_G11F_B10F", as Filament's
    cmgen writes it, or "RGBA16F").  Float16 rounds to nearest even and
    clamps at +-65504, R11F_G11F_B10F follows the Vulkan / OpenGL rules
    (:mod:`pbrkit.io.float_packing`), both with a warning when clamping.
    ``key_values`` maps keys to bytes (stored as given, e.g.
    :func:`filament_sh_text` for Filament's ``sh`` key) or str (stored as
    NUL-terminated UTF-8), written in the order given.  Written atomically.
    """
    data = ktx1_bytes(levels, gl_format, cube=cube, key_values=key_values)
    write_bytes(path, data)  # atomic: temporary file, then rename
    return path


def filament_sh_text(prescaled):
    """Filament's ``sh`` key value for 9 RGB coefficients ``prescaled`` (9, 3),
    as bytes of ASCII text.

    ``prescaled`` are the coefficients Filament's shader takes (E / pi form,
    :func:`pbrkit.ibl.sh.lambertian_sh_prescaled`), l = 0..2, m = -l..l.  The
    text is 9 lines ``"r g b\\n"``, single spaces, each number as ``%.9g``
    (enough digits to give the same float32 back), no NUL, as cmgen writes it
    and as Filament's readers split it (the JS helper splits on single
    whitespace characters, so exactly one separator between numbers)."""
    c = np.asarray(prescaled, dtype=np.float64)
    if c.shape != (9, 3):
        raise InputError(f"Filament sh needs 9 x 3 coefficients, got shape {c.shape}")
    c = c.astype(np.float32)
    if not np.all(np.isfinite(c)):
        raise InputError("Filament sh coefficients must be finite (the value is read with parseFloat / strtof)")
    return "".join(" ".join(f"{float(x):.9g}" for x in row) + "\n" for row in c).encode("ascii")


# ----------------------------------------------------------------------------
# Reader


def _fail(name, message):
    raise InputError(message, name)


def _parse_key_values(data, name):
    """Key/value entries as a dict of raw value bytes."""
    entries = {}
    pos = 0
    while pos < len(data):
        if pos + 4 > len(data):
            _fail(name, f"truncated keyAndValueByteSize at key/value offset {pos}")
        (length,) = struct.unpack_from("<I", data, pos)
        if length < 1 or pos + 4 + length > len(data):
            _fail(name, f"keyAndValueByteSize {length} at key/value offset {pos} overruns bytesOfKeyValueData "
                        f"({len(data)})")
        kv = data[pos + 4 : pos + 4 + length]
        nul = kv.find(b"\x00")
        if nul < 1:
            _fail(name, f"key/value entry at key/value offset {pos} has no NUL-terminated key")
        try:
            key = kv[:nul].decode("utf-8")
        except UnicodeDecodeError:
            _fail(name, f"key at key/value offset {pos} is not UTF-8")
        if key in entries:
            _fail(name, f"the key at key/value offset {pos} appears more than once")
        entries[key] = kv[nul + 1 :]
        end = pos + 4 + length
        padded = end + _pad4(length)
        if padded > len(data) or any(data[end:padded]):
            _fail(name, f"valuePadding after the key at key/value offset {pos} is missing or not zero")
        pos = padded
    return entries


def parse_ktx1(data, name=None):
    """Parse the bytes of a KTX 1.1 file; see :func:`read_ktx1`."""
    data = bytes(data)
    if len(data) < _HEADER_SIZE:
        _fail(name, f"{len(data)} bytes is too short for a KTX1 header ({_HEADER_SIZE} bytes)")
    if data[:12] != KTX1_IDENTIFIER:
        _fail(name, "not a KTX 1.1 file (bad identifier)")
    info = dict(zip(_HEADER_FIELDS, struct.unpack_from("<13I", data, 12)))
    if info["endianness"] != KTX1_ENDIANNESS:
        if info["endianness"] == 0x01020304:
            _fail(name, "big-endian KTX1 files are not supported")
        _fail(name, f"endianness 0x{info['endianness']:08X} is neither 0x04030201 nor 0x01020304")
    code = info["glInternalFormat"]
    if code not in _BY_CODE:
        _fail(name, f"unsupported glInternalFormat 0x{code:04X}; supported: "
                    + ", ".join(f"{n} (0x{v[0]:04X})" for n, v in GL_FORMATS.items()))
    fmt_name, _, _, _, _, encoding, channels = _BY_CODE[code]
    info["formatName"] = fmt_name
    for field, accepted in zip(("glFormat", "glType", "glTypeSize", "glBaseInternalFormat"), _ACCEPTED[code]):
        if info[field] not in accepted:
            _fail(name, f"{field} 0x{info[field]:04X} does not go with {fmt_name}; expected "
                        + " or ".join(f"0x{v:04X}" for v in sorted(accepted)))
    width, height = info["pixelWidth"], info["pixelHeight"]
    faces = info["numberOfFaces"]
    if width == 0 or height == 0:
        _fail(name, f"pixelWidth {width} x pixelHeight {height}: only 2D textures and cube maps are supported")
    if info["pixelDepth"] != 0:
        _fail(name, f"pixelDepth {info['pixelDepth']}: 3D textures are not supported")
    if info["numberOfArrayElements"] != 0:
        _fail(name, f"numberOfArrayElements {info['numberOfArrayElements']}: texture arrays are not supported")
    if faces not in (1, 6):
        _fail(name, f"numberOfFaces {faces} must be 1 or 6")
    if faces == 6 and width != height:
        _fail(name, f"cube map faces must be square, got {width} x {height}")
    n_levels = max(1, info["numberOfMipmapLevels"])  # 0 = "generate mipmaps": level 0 only is stored
    max_levels = max_mip_levels(width, height)
    if n_levels > max_levels:
        _fail(name, f"numberOfMipmapLevels {n_levels} exceeds the maximum {max_levels} for {width} x {height}")
    kv_len = info["bytesOfKeyValueData"]
    if kv_len % 4:
        _fail(name, f"bytesOfKeyValueData {kv_len} is not a multiple of 4")
    if _HEADER_SIZE + kv_len > len(data):
        _fail(name, f"key/value data ({kv_len} bytes) extends past the end of the file ({len(data)} bytes)")
    key_values = _parse_key_values(data[_HEADER_SIZE : _HEADER_SIZE + kv_len], name)

    texel = texel_size(encoding, channels)
    pos = _HEADER_SIZE + kv_len
    spans = []  # (offset, shape) of each level, all checked against the file before any is decoded
    info["imageSizes"] = []
    for p in range(n_levels):
        w, h = max(1, width >> p), max(1, height >> p)
        # imageSize: the one image, or one face of a non-array cube map.  4- and
        # 8-byte texels need no row or cube padding.
        expected = face_size = w * h * texel
        if pos + 4 > len(data):
            _fail(name, f"file ends before the imageSize of level {p} (offset {pos})")
        (image_size,) = struct.unpack_from("<I", data, pos)
        if image_size != expected:
            what = "one face of " if faces == 6 else ""
            _fail(name, f"level {p}: imageSize {image_size}, expected {expected} ({what}{w} x {h} x {texel} bytes)")
        pos += 4
        n = faces * face_size
        if pos + n > len(data):
            _fail(name, f"level {p} is truncated: needs {n} bytes at offset {pos}, the file has {len(data) - pos}")
        spans.append((pos, n, (6, h, w) if faces == 6 else (h, w)))
        info["imageSizes"].append(image_size)
        pos += n + _pad4(n)  # mipPadding: none for 4- and 8-byte texels
    if pos != len(data):
        _fail(name, f"{len(data) - pos} unexpected bytes after the last level")
    check_decoded(name, encoding, channels, sum(n for _, n, _ in spans) // texel,
                  f"the {n_levels} level(s) of the KTX1 file")
    levels = [decode_texels(data[at : at + n], encoding, channels, shape) for at, n, shape in spans]
    info["cube"] = faces == 6
    info["levelCount"] = n_levels
    return info, levels, key_values


def read_ktx1(path):
    """Read a KTX 1.1 file with a format of :data:`GL_FORMATS`.

    Returns ``(info, levels, key_values)``: the header fields (spec names)
    plus ``formatName``, ``imageSizes``, ``cube`` and ``levelCount``; the
    images as float32 arrays, level 0 first, (H, W, C) or (6, N, N, C) for
    cube maps (R11F_G11F_B10F unpacked to RGB, RGBA16F as RGBA); and the
    key/value data as a dict of raw value bytes.

    Accepts the files Filament's reader takes for these formats (glType
    0x8C3A as cmgen writes it) and also the spec's glType 0x8C3B and
    glTypeSize 4 for the packed format (which Filament itself refuses; see
    the module docstring), and checks the identifier, endianness, header
    consistency, key/value entries and padding, every imageSize and the
    exact file length; any violation raises
    :class:`~pbrkit.core.errors.InputError` (a ``ValueError``) with a
    one-line message naming the file.  Only a regular file is read, every
    level is checked against the file's length before any is decoded, and no
    message quotes a key or value (:mod:`pbrkit.io.containers`).
    """
    return read_container(path, parse_ktx1, "a KTX 1.1 file (R11F_G11F_B10F or RGBA16F)")
