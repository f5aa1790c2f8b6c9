"""KTX 2.0 texture files: a writer and a strict reader for float formats.

Written from the Khronos "KTX File Format Specification", version 2.0
(document revision 4, 2025), and the Khronos Data Format Specification 1.4
for the Data Format Descriptor (DFD).  The file is::

    identifier   «KTX 20»\\r\\n\\x1A\\n                           12 bytes
    header       vkFormat, typeSize, pixelWidth, pixelHeight,
                 pixelDepth = 0, layerCount = 0, faceCount (1 or 6),
                 levelCount, supercompressionScheme = 0          9 x UInt32
    index        dfdByteOffset, dfdByteLength, kvdByteOffset,
                 kvdByteLength (UInt32), sgdByteOffset,
                 sgdByteLength (UInt64, both 0)                  32 bytes
    level index  levelCount x (byteOffset, byteLength,
                 uncompressedByteLength), UInt64, level 0 first  at byte 80
    DFD          dfdTotalSize + one Khronos Basic descriptor block
    key/value    entries sorted by key code points, each padded to 4 bytes
    levels       smallest level first; each level aligned to
                 lcm(texel block size, 4) from the start of the file

Inside a level the faces follow one another (+X, -X, +Y, -Y, +Z, -Z for a
cube map), each an image of tightly packed rows, row 0 first.  Row 0 is the
top of a 2D image (``KTXorientation`` = "rd", the spec's recommended
top-left origin) and t = 0 of a cube face (pbrkit ``CONVENTIONS.md``,
"Cube maps"; the spec requires "rd" for cube maps too).  All data are
little-endian; float formats hold linear values.

The DFD is a Khronos Basic Data Format Descriptor block (version 2) with
colorModel RGBSDA, primaries BT709, transfer LINEAR, texelBlockDimension
0 (1 x 1 x 1 x 1), bytesPlane0 = texel size and one sample per channel in
memory order (R, G, B, A; for the packed ``B10G11R11`` format R in bits
0..10, G in 11..21, B in 22..31).  Each sample carries the channel id
(R 0, G 1, B 2, A 15) with the qualifier bits FLOAT (0x80) and, for SFLOAT
formats, SIGNED (0x40), and sampleLower / sampleUpper as 32-bit floats:
-1.0 / 1.0 (0xBF800000 / 0x3F800000) for signed floats and 0 / 1.0 for
unsigned floats (the values of the Khronos reference DFD generator,
KTX-Software ``lib/dfdutils/createdfd.c``).
"""

from __future__ import annotations

import math
import struct

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
    "KTX2_IDENTIFIER",
    "VK_FORMATS",
    "vk_format_code",
    "ktx2_bytes",
    "write_ktx2",
    "parse_ktx2",
    "read_ktx2",
]

#: The 12-byte file identifier, «KTX 20»\r\n\x1A\n.
KTX2_IDENTIFIER = b"\xabKTX 20\xbb\r\n\x1a\n"

#: Supported vkFormat values: name -> (code, texel encoding, channels,
#: typeSize, signed).  Codes are VkFormat enum values (Vulkan 1.0 core).
VK_FORMATS = {
    "R16_SFLOAT": (76, "float16", 1, 2, True),
    "R16G16_SFLOAT": (83, "float16", 2, 2, True),
    "R16G16B16_SFLOAT": (90, "float16", 3, 2, True),
    "R16G16B16A16_SFLOAT": (97, "float16", 4, 2, True),
    "R32_SFLOAT": (100, "float32", 1, 4, True),
    "R32G32_SFLOAT": (103, "float32", 2, 4, True),
    "R32G32B32_SFLOAT": (106, "float32", 3, 4, True),
    "R32G32B32A32_SFLOAT": (109, "float32", 4, 4, True),
    "B10G11R11_UFLOAT_PACK32": (122, "b10g11r11", 3, 4, False),
}
_BY_CODE = {v[0]: (name,) + v[1:] for name, v in VK_FORMATS.items()}

# Khronos Data Format Specification 1.4 enumerants (khr_df.h).
_KHR_DF_VENDORID_KHRONOS = 0
_KHR_DF_KHR_DESCRIPTORTYPE_BASICFORMAT = 0
_KHR_DF_VERSIONNUMBER_1_3 = 2  # the value of versionNumber for DFD 1.3 and 1.4
_KHR_DF_MODEL_RGBSDA = 1
_KHR_DF_PRIMARIES_BT709 = 1
_KHR_DF_TRANSFER_LINEAR = 1
_KHR_DF_TRANSFER_SRGB = 2
_KHR_DF_FLAG_ALPHA_STRAIGHT = 0
_CHANNEL_IDS = (0, 1, 2, 15)  # KHR_DF_CHANNEL_RGBSDA_RED, GREEN, BLUE, ALPHA
_QUALIFIER_FLOAT = 0x80  # KHR_DF_SAMPLE_DATATYPE_FLOAT, in the channelType byte
_QUALIFIER_SIGNED = 0x40  # KHR_DF_SAMPLE_DATATYPE_SIGNED
_FLOAT_BITS = {1.0: 0x3F800000, -1.0: 0xBF800000, 0.0: 0x00000000}

_HEADER_SIZE = 80  # identifier + 9 UInt32 + index
_LEVEL_ENTRY_SIZE = 24
_WRITER = "KTXwriter"
_ORIENTATION = "KTXorientation"


def vk_format_code(vk_format):
    """VkFormat code of ``vk_format``: an int, or a name with or without the
    ``VK_FORMAT_`` prefix.  Raises :class:`~pbrkit.core.errors.InputError` (a ``ValueError``) for unsupported formats."""
    return format_code(vk_format, VK_FORMATS, _BY_CODE, "VK_FORMAT_", "vkFormat")


def _align(offset, alignment):
    return -(-offset // alignment) * alignment


def _sample_layout(code):
    """(bitOffset, bitLength) of each channel, in memory order."""
    _, encoding, channels, _, _ = _BY_CODE[code]
    if encoding == "b10g11r11":
        return [(0, 11), (11, 11), (22, 10)]
    bits = 16 if encoding == "float16" else 32
    return [(i * bits, bits) for i in range(channels)]


def _dfd_bytes(code):
    """The DFD (dfdTotalSize + Khronos Basic descriptor block) of a format."""
    _, encoding, channels, _, signed = _BY_CODE[code]
    samples = _sample_layout(code)
    block_size = 24 + 16 * len(samples)
    words = [
        (_KHR_DF_KHR_DESCRIPTORTYPE_BASICFORMAT << 17) | _KHR_DF_VENDORID_KHRONOS,
        (block_size << 16) | _KHR_DF_VERSIONNUMBER_1_3,
        _KHR_DF_MODEL_RGBSDA
        | (_KHR_DF_PRIMARIES_BT709 << 8)
        | (_KHR_DF_TRANSFER_LINEAR << 16)
        | (_KHR_DF_FLAG_ALPHA_STRAIGHT << 24),
        0,  # texelBlockDimension0..3 = 0 (1 x 1 x 1 x 1 texel blocks)
        texel_size(encoding, channels),  # bytesPlane0; bytesPlane1..3 = 0
        0,  # bytesPlane4..7
    ]
    qualifiers = _QUALIFIER_FLOAT | (_QUALIFIER_SIGNED if signed else 0)
    lower = _FLOAT_BITS[-1.0] if signed else _FLOAT_BITS[0.0]
    for channel, (bit_offset, bit_length) in enumerate(samples):
        channel_type = _CHANNEL_IDS[channel] | qualifiers
        words += [
            bit_offset | ((bit_length - 1) << 16) | (channel_type << 24),
            0,  # samplePosition0..3
            lower,
            _FLOAT_BITS[1.0],
        ]
    body = struct.pack(f"<{len(words)}I", *words)
    return struct.pack("<I", 4 + len(body)) + body


def _kvd_bytes(entries):
    """Key/value data: entries sorted by the code points of their keys."""
    out = bytearray()
    for key in sorted(entries):
        value = entries[key]
        key_and_value = key.encode("utf-8") + b"\x00" + value
        out += struct.pack("<I", len(key_and_value)) + key_and_value
        out += b"\x00" * (_align(len(out), 4) - len(out))
    return bytes(out)


def _key_value_entries(key_values, version):
    from .. import __version__

    entries = {
        _ORIENTATION: b"rd\x00",
        _WRITER: f"pbrkit {version or __version__}".encode("utf-8") + b"\x00",
    }
    for key, value in (key_values or {}).items():
        if not isinstance(key, str) or not key or "\x00" in key:
            raise InputError(f"KTX2 key {key!r} must be a non-empty string without NUL")
        if key[:3] in ("KTX", "ktx"):
            raise InputError(f"KTX2 key {key!r}: keys starting with 'KTX' or 'ktx' are reserved by the spec")
        if isinstance(value, str):
            value = value.encode("utf-8") + b"\x00"
        elif isinstance(value, (bytes, bytearray, memoryview)):
            value = bytes(value)
        else:
            raise InputError(f"KTX2 value of {key!r} must be str (stored NUL-terminated UTF-8) or bytes")
        entries[key] = value
    return entries



def ktx2_bytes(levels, vk_format, cube=False, key_values=None, writer_version=None):
    """The bytes of a KTX 2.0 file; see :func:`write_ktx2`.  ``writer_version``
    overrides the version in ``KTXwriter`` (default: the installed pbrkit's)."""
    code = vk_format_code(vk_format)
    name, encoding, channels, type_size, _ = _BY_CODE[code]
    arrays, width, height = validate_levels(levels, cube)
    faces = 6 if cube else 1
    texel = texel_size(encoding, channels)
    alignment = math.lcm(texel, 4)  # mipPadding alignment, supercompressionScheme 0

    level_data = [
        encode_texels(a, encoding, channels, what=f"{name} level {p}") for p, a in enumerate(arrays)
    ]
    dfd = _dfd_bytes(code)
    kvd = _kvd_bytes(_key_value_entries(key_values, writer_version))

    n_levels = len(arrays)
    dfd_offset = _HEADER_SIZE + _LEVEL_ENTRY_SIZE * n_levels
    kvd_offset = dfd_offset + len(dfd)
    end = kvd_offset + len(kvd)
    # Mip level array: smallest level first, each at the next aligned offset.
    offsets = [0] * n_levels
    for p in reversed(range(n_levels)):
        offsets[p] = _align(end, alignment)
        end = offsets[p] + len(level_data[p])

    out = bytearray(end)
    struct.pack_into(
        "<12s9I4I2Q",
        out,
        0,
        KTX2_IDENTIFIER,
        code,
        type_size,
        width,
        height,
        0,  # pixelDepth
        0,  # layerCount
        faces,
        n_levels,
        0,  # supercompressionScheme: none
        dfd_offset,
        len(dfd),
        kvd_offset,
        len(kvd),
        0,  # sgdByteOffset
        0,  # sgdByteLength
    )
    for p in range(n_levels):
        n = len(level_data[p])
        struct.pack_into("<3Q", out, _HEADER_SIZE + _LEVEL_ENTRY_SIZE * p, offsets[p], n, n)
        out[offsets[p] : offsets[p] + n] = level_data[p]
    out[dfd_offset:kvd_offset] = dfd
    out[kvd_offset : kvd_offset + len(kvd)] = kvd
    return bytes(out)


def write_ktx2(path, levels, vk_format, cube=False, key_values=None):
    """Write a KTX 2.0 file of float texels and return ``path``.

    ``levels`` is a list of arrays, level 0 (largest) first: (H, W, C) images
    for a 2D texture, (6, N, N, C) for a cube map with faces +X, -X, +Y, -Y,
    +Z, -Z (row 0 of a face is t = 0, CONVENTIONS.md "Cube maps").  Level p
    must be max(1, W >> p) x max(1, H >> p); a partial chain is allowed.
    ``vk_format`` is a code or name from :data:`VK_FORMATS` (e.g. 97 or
    "R16G16B16A16_SFLOAT"); RGB input gets alpha 1 for RGBA formats.
    Float16 formats round to nearest even and clamp at +-65504 (with a
    warning), B10G11R11 follows the Vulkan rules (:mod:`pbrkit.io.float_packing`).
    ``key_values`` maps extra keys to str (stored as NUL-terminated UTF-8) or
    bytes; keys starting with "KTX"/"ktx" are reserved.  ``KTXorientation``
    = "rd" and ``KTXwriter`` = "pbrkit <version>" are always written.
    """
    data = ktx2_bytes(levels, vk_format, cube=cube, key_values=key_values)
    write_bytes(path, data)  # atomic: temporary file, then rename
    return path


# ----------------------------------------------------------------------------
# Reader


def _fail(name, message):
    raise InputError(message, name)


def _parse_dfd(data, name, code):
    """Validate the DFD against the format; return it as a dict."""
    fmt_name, encoding, channels, _, signed = _BY_CODE[code]
    if len(data) < 4 + 24:
        _fail(name, f"DFD of {len(data)} bytes is too short for a basic descriptor block")
    (total,) = struct.unpack_from("<I", data, 0)
    if total != len(data):
        _fail(name, f"dfdTotalSize {total} != dfdByteLength {len(data)}")
    w0, w1, w2, w3, w4, w5 = struct.unpack_from("<6I", data, 4)
    vendor, dtype = w0 & 0x1FFFF, w0 >> 17
    version, block_size = w1 & 0xFFFF, w1 >> 16
    if vendor != 0 or dtype != 0:
        _fail(name, f"DFD block is not a Khronos basic block (vendorId {vendor}, descriptorType {dtype})")
    if version != 2:
        _fail(name, f"DFD versionNumber {version}, expected 2")
    if block_size + 4 != total or (block_size - 24) % 16:
        _fail(name, f"descriptorBlockSize {block_size} does not match dfdTotalSize {total}")
    dfd = {
        "colorModel": w2 & 0xFF,
        "colorPrimaries": (w2 >> 8) & 0xFF,
        "transferFunction": (w2 >> 16) & 0xFF,
        "flags": w2 >> 24,
        "texelBlockDimension": [(w3 >> s) & 0xFF for s in (0, 8, 16, 24)],
        "bytesPlane": [(w >> s) & 0xFF for w in (w4, w5) for s in (0, 8, 16, 24)],
        "samples": [],
    }
    if dfd["colorModel"] != _KHR_DF_MODEL_RGBSDA:
        _fail(name, f"DFD colorModel {dfd['colorModel']}, expected RGBSDA (1) for {fmt_name}")
    if dfd["transferFunction"] == _KHR_DF_TRANSFER_SRGB:
        _fail(name, f"DFD transferFunction is sRGB, not allowed for {fmt_name}")
    if dfd["texelBlockDimension"] != [0, 0, 0, 0]:
        _fail(name, f"DFD texelBlockDimension {dfd['texelBlockDimension']}, expected 0s")
    size = texel_size(encoding, channels)
    if dfd["bytesPlane"] != [size] + [0] * 7:
        _fail(name, f"DFD bytesPlane {dfd['bytesPlane']}, expected [{size}, 0, ...] for {fmt_name}")
    n_samples = (block_size - 24) // 16
    if n_samples != channels:
        _fail(name, f"DFD has {n_samples} samples, {fmt_name} has {channels} channels")
    # Samples in memory order, contiguous, covering the texel exactly.
    if encoding == "b10g11r11":
        expected_bits = [11, 11, 10]
    else:
        expected_bits = [8 * size // channels] * channels
    bit = 0
    for i in range(n_samples):
        s0, pos, lower, upper = struct.unpack_from("<4I", data, 28 + 16 * i)
        sample = {
            "bitOffset": s0 & 0xFFFF,
            "bitLength": ((s0 >> 16) & 0xFF) + 1,
            "channelType": s0 >> 24,
            "samplePosition": [(pos >> s) & 0xFF for s in (0, 8, 16, 24)],
            "sampleLower": lower,
            "sampleUpper": upper,
        }
        dfd["samples"].append(sample)
        channel_id = sample["channelType"] & 0x0F
        qualifiers = sample["channelType"] & 0xF0
        want_q = _QUALIFIER_FLOAT | (_QUALIFIER_SIGNED if signed else 0)
        if channel_id != _CHANNEL_IDS[i] or qualifiers != want_q:
            _fail(name, f"DFD sample {i} channelType 0x{sample['channelType']:02X}, "
                        f"expected 0x{_CHANNEL_IDS[i] | want_q:02X} for {fmt_name}")
        if sample["bitOffset"] != bit or sample["bitLength"] != expected_bits[i]:
            _fail(name, f"DFD sample {i} covers bits {sample['bitOffset']}+{sample['bitLength']}, "
                        f"expected {bit}+{expected_bits[i]} for {fmt_name}")
        bit += expected_bits[i]
        want_lower = 0xBF800000 if signed else 0
        if lower != want_lower or upper != 0x3F800000:
            _fail(name, f"DFD sample {i} sampleLower/Upper 0x{lower:08X}/0x{upper:08X}, "
                        f"expected 0x{want_lower:08X}/0x3F800000 for a float format")
    if bit != 8 * size:
        _fail(name, f"DFD samples cover {bit} bits of a {8 * size}-bit texel")
    return dfd


def _parse_kvd(data, name):
    """Key/value entries; str for NUL-terminated UTF-8 values, else bytes."""
    entries = {}
    keys = []
    pos = 0
    while pos < len(data):
        if pos + 4 > len(data):
            _fail(name, "truncated keyAndValueByteLength in the key/value data")
        (length,) = struct.unpack_from("<I", data, pos)
        pos += 4
        if length < 2 or pos + length > len(data):
            _fail(name, f"keyAndValueByteLength {length} at kvd offset {pos - 4} is invalid")
        kv = data[pos : pos + length]
        nul = kv.find(b"\x00")
        if nul < 1:
            _fail(name, f"key/value entry at kvd offset {pos - 4} has no NUL-terminated key")
        try:
            key = kv[:nul].decode("utf-8")
        except UnicodeDecodeError:
            _fail(name, f"key at kvd offset {pos - 4} is not UTF-8")
        value = kv[nul + 1 :]
        if value.endswith(b"\x00"):
            try:
                value = value[:-1].decode("utf-8")
            except UnicodeDecodeError:
                pass
        if key in entries:
            _fail(name, f"the key at kvd offset {pos - 4} appears more than once")
        entries[key] = value
        keys.append(key)
        pos += length
        padded = _align(pos, 4)
        if padded > len(data) or any(data[pos:padded]):
            _fail(name, f"valuePadding after the key at kvd offset {pos - length - 4} is missing or not zero")
        pos = padded
    if keys != sorted(keys):
        _fail(name, f"the {len(keys)} keys are not sorted by code point")
    return entries


def parse_ktx2(data, name=None):
    """Parse the bytes of a KTX 2.0 file; see :func:`read_ktx2`."""
    data = bytes(data)
    if len(data) < _HEADER_SIZE:
        _fail(name, f"{len(data)} bytes is too short for a KTX2 header")
    if data[:12] != KTX2_IDENTIFIER:
        _fail(name, "not a KTX 2.0 file (bad identifier)")
    fields = struct.unpack_from("<9I4I2Q", data, 12)
    keys = (
        "vkFormat typeSize pixelWidth pixelHeight pixelDepth layerCount faceCount levelCount "
        "supercompressionScheme dfdByteOffset dfdByteLength kvdByteOffset kvdByteLength "
        "sgdByteOffset sgdByteLength"
    ).split()
    header = dict(zip(keys, fields))
    code = header["vkFormat"]
    if code not in _BY_CODE:
        _fail(name, f"unsupported vkFormat {code}; supported: {sorted(_BY_CODE)}")
    fmt_name, encoding, channels, type_size, _ = _BY_CODE[code]
    header["formatName"] = fmt_name
    if header["typeSize"] != type_size:
        _fail(name, f"typeSize {header['typeSize']}, expected {type_size} for {fmt_name}")
    if header["supercompressionScheme"] != 0:
        _fail(name, f"supercompressionScheme {header['supercompressionScheme']} is not supported (only 0)")
    width, height = header["pixelWidth"], header["pixelHeight"]
    faces = header["faceCount"]
    if width == 0 or height == 0:
        _fail(name, f"pixelWidth {width} x pixelHeight {height}: only 2D textures and cube maps are supported")
    if header["pixelDepth"] != 0 or header["layerCount"] != 0:
        _fail(name, "3D and array textures are not supported (pixelDepth and layerCount must be 0)")
    if faces not in (1, 6):
        _fail(name, f"faceCount {faces} must be 1 or 6")
    if faces == 6 and width != height:
        _fail(name, f"cube map faces must be square, got {width} x {height}")
    n_levels = max(1, header["levelCount"])
    max_levels = max_mip_levels(width, height)
    if n_levels > max_levels:
        _fail(name, f"levelCount {n_levels} exceeds the maximum {max_levels} for {width} x {height}")
    if header["sgdByteOffset"] != 0 or header["sgdByteLength"] != 0:
        _fail(name, "supercompression global data must be absent for supercompressionScheme 0")

    index_end = _HEADER_SIZE + _LEVEL_ENTRY_SIZE * n_levels
    if len(data) < index_end:
        _fail(name, "file ends inside the level index")
    dfd_off, dfd_len = header["dfdByteOffset"], header["dfdByteLength"]
    if dfd_off != index_end:
        _fail(name, f"dfdByteOffset {dfd_off}, expected {index_end} (right after the level index)")
    if dfd_off + dfd_len > len(data):
        _fail(name, "DFD extends past the end of the file")
    kvd_off, kvd_len = header["kvdByteOffset"], header["kvdByteLength"]
    if kvd_len == 0:
        if kvd_off != 0:
            _fail(name, "kvdByteOffset must be 0 when kvdByteLength is 0")
        meta_end = dfd_off + dfd_len
    else:
        if kvd_off - dfd_off != dfd_len:
            _fail(name, f"dfdTotalSize {dfd_len} != kvdByteOffset - dfdByteOffset ({kvd_off - dfd_off})")
        if kvd_off % 4:
            _fail(name, f"kvdByteOffset {kvd_off} is not 4-byte aligned")
        meta_end = kvd_off + kvd_len
        if meta_end > len(data):
            _fail(name, "key/value data extends past the end of the file")
    header["dfd"] = _parse_dfd(data[dfd_off : dfd_off + dfd_len], name, code)
    key_values = _parse_kvd(data[kvd_off : kvd_off + kvd_len], name) if kvd_len else {}
    orientation = key_values.get("KTXorientation")
    if orientation is not None and orientation != "rd":
        _fail(name, "KTXorientation is not 'rd' (top-left origin), the only one pbrkit reads")

    texel = texel_size(encoding, channels)
    alignment = math.lcm(texel, 4)
    entries = [struct.unpack_from("<3Q", data, _HEADER_SIZE + _LEVEL_ENTRY_SIZE * p) for p in range(n_levels)]
    header["levels"] = [
        {"byteOffset": o, "byteLength": n, "uncompressedByteLength": u} for o, n, u in entries
    ]
    # Levels are stored smallest first, each at the next lcm(texel, 4) boundary
    # with zero mipPadding; level 0 ends the file.  All are checked against the
    # file before any is decoded.
    expected_offset = _align(meta_end, alignment)
    previous_end = meta_end
    for p in reversed(range(n_levels)):
        offset, length, uncompressed = entries[p]
        w, h = max(1, width >> p), max(1, height >> p)
        expected_length = faces * w * h * texel
        if length != expected_length or uncompressed != length:
            _fail(name, f"level {p}: byteLength {length} / uncompressedByteLength {uncompressed}, "
                        f"expected {expected_length}")
        if offset != expected_offset:
            _fail(name, f"level {p}: byteOffset {offset}, expected {expected_offset} "
                        f"(levels smallest first, aligned to {alignment})")
        if offset + length > len(data):
            _fail(name, f"level {p} ({length} bytes at offset {offset}) extends past the end of the file "
                        f"({len(data)} bytes)")
        if any(data[previous_end:offset]):
            _fail(name, f"mipPadding before level {p} is not zero")
        previous_end = offset + length
        expected_offset = _align(previous_end, alignment)
    if previous_end != len(data):
        _fail(name, f"{len(data) - previous_end} unexpected bytes after level 0")
    check_decoded(name, encoding, channels, sum(n for _, n, _ in entries) // texel,
                  f"the {n_levels} level(s) of the KTX2 file")
    levels = []
    for p, (offset, length, _) in enumerate(entries):
        w, h = max(1, width >> p), max(1, height >> p)
        shape = (6, h, w) if faces == 6 else (h, w)
        levels.append(decode_texels(data[offset : offset + length], encoding, channels, shape))
    return header, levels, key_values


def read_ktx2(path):
    """Read a KTX 2.0 file written with a float format of :data:`VK_FORMATS`.

    Returns ``(header, levels, key_values)``: the header fields (spec names)
    plus ``formatName``, ``levels`` (the level index) and ``dfd`` (parsed
    descriptor); the images as float32 arrays, level 0 first, (H, W, C) or
    (6, N, N, C) for cube maps (packed B10G11R11 unpacked to RGB); and the
    key/value data (NUL-terminated UTF-8 values as str, others as bytes).

    The parser is strict: identifier, header consistency, section offsets
    and lengths, DFD contents for the format, key order and padding, level
    order, alignment, zero padding and the exact file length are checked;
    any violation raises :class:`~pbrkit.core.errors.InputError` (a
    ``ValueError``) naming the file.  Only a regular file is read, every
    level is checked against the file's length before any is decoded, and
    no message quotes a key or value (:mod:`pbrkit.io.containers`).
    """
    return read_container(path, parse_ktx2, "a KTX 2.0 file (float format)")
