"""DirectDraw Surface (DDS) files with the DX10 header: writer and strict reader.

Written from Microsoft's "Programming Guide for DDS" and the reference pages
for ``DDS_HEADER``, ``DDS_PIXELFORMAT`` and ``DDS_HEADER_DXT10`` (Win32 /
Direct3D 11 docs), with the choices of Microsoft's DirectXTex
(``DirectXTex/DirectXTexDDS.cpp``) where the pages leave room.  The file is::

    magic            "DDS " (0x20534444)                           4 bytes
    DDS_HEADER       dwSize 124, dwFlags, dwHeight, dwWidth,
                     dwPitchOrLinearSize, dwDepth 0, dwMipMapCount,
                     dwReserved1[11], ddspf (32 bytes), dwCaps,
                     dwCaps2, dwCaps3, dwCaps4, dwReserved2       124 bytes
    DDS_HEADER_DXT10 dxgiFormat, resourceDimension,
                     miscFlag, arraySize, miscFlags2               20 bytes
    data             for each array slice (cube face +X, -X, +Y, -Y,
                     +Z, -Z): each mip level, largest first, rows
                     tightly packed, row 0 first

- dwFlags = DDSD_CAPS | DDSD_HEIGHT | DDSD_WIDTH | DDSD_PIXELFORMAT |
  DDSD_PITCH | DDSD_MIPMAPCOUNT; uncompressed formats give the row pitch of
  level 0, (width * bits per pixel + 7) / 8, in dwPitchOrLinearSize, and
  DirectXTex always writes DDSD_MIPMAPCOUNT with the level count.
- ddspf: dwSize 32, dwFlags DDPF_FOURCC, dwFourCC "DX10", other fields 0.
- dwCaps = DDSCAPS_TEXTURE, plus DDSCAPS_COMPLEX | DDSCAPS_MIPMAP when there
  is more than one level, plus DDSCAPS_COMPLEX for a cube map; dwCaps2 =
  DDSCAPS2_CUBEMAP and the six DDSCAPS2_CUBEMAP_* face flags for a cube map.
- DX10 header: resourceDimension D3D10_RESOURCE_DIMENSION_TEXTURE2D (3),
  miscFlag D3D11_RESOURCE_MISC_TEXTURECUBE (0x4) for cube maps, arraySize 1
  (for a cube map: the number of cubes), miscFlags2 0 (alpha mode unknown).

Row 0 is the top of a 2D image and t = 0 of a cube face (CONVENTIONS.md
"Cube maps"); the faces' order is D3D's array-slice order for cube maps.
All data are little-endian; float formats hold linear values.
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

__all__ = ["DXGI_FORMATS", "dxgi_format_code", "dds_bytes", "write_dds", "parse_dds", "read_dds"]

#: Supported DXGI formats: name -> (code, texel encoding, channels).
DXGI_FORMATS = {
    "R32G32B32A32_FLOAT": (2, "float32", 4),
    "R32G32B32_FLOAT": (6, "float32", 3),
    "R16G16B16A16_FLOAT": (10, "float16", 4),
    "R32G32_FLOAT": (16, "float32", 2),
    "R11G11B10_FLOAT": (26, "b10g11r11", 3),
    "R16G16_FLOAT": (34, "float16", 2),
    "R32_FLOAT": (41, "float32", 1),
    "R16_FLOAT": (54, "float16", 1),
}
_BY_CODE = {v[0]: (name,) + v[1:] for name, v in DXGI_FORMATS.items()}

DDS_MAGIC = b"DDS "
_DDSD_CAPS = 0x1
_DDSD_HEIGHT = 0x2
_DDSD_WIDTH = 0x4
_DDSD_PITCH = 0x8
_DDSD_PIXELFORMAT = 0x1000
_DDSD_MIPMAPCOUNT = 0x20000
_DDSD_DEPTH = 0x800000
_DDPF_FOURCC = 0x4
_DDSCAPS_COMPLEX = 0x8
_DDSCAPS_TEXTURE = 0x1000
_DDSCAPS_MIPMAP = 0x400000
_DDSCAPS2_CUBEMAP = 0x200
_DDSCAPS2_CUBEMAP_ALLFACES = 0x400 | 0x800 | 0x1000 | 0x2000 | 0x4000 | 0x8000
_DDSCAPS2_VOLUME = 0x200000
_D3D10_RESOURCE_DIMENSION_TEXTURE2D = 3
_D3D11_RESOURCE_MISC_TEXTURECUBE = 0x4
_FOURCC_DX10 = b"DX10"
_HEADER_SIZE = 4 + 124 + 20


def dxgi_format_code(dxgi_format):
    """DXGI_FORMAT code of ``dxgi_format``: an int, or a name with or without
    the ``DXGI_FORMAT_`` prefix.  Raises :class:`~pbrkit.core.errors.InputError` (a ``ValueError``) for unsupported ones."""
    return format_code(dxgi_format, DXGI_FORMATS, _BY_CODE, "DXGI_FORMAT_", "DXGI format")



def dds_bytes(levels, dxgi_format, cube=False):
    """The bytes of a DDS file; see :func:`write_dds`."""
    code = dxgi_format_code(dxgi_format)
    name, encoding, channels = _BY_CODE[code]
    arrays, width, height = validate_levels(levels, cube)
    n_levels = len(arrays)
    texel = texel_size(encoding, channels)

    flags = _DDSD_CAPS | _DDSD_HEIGHT | _DDSD_WIDTH | _DDSD_PIXELFORMAT | _DDSD_PITCH | _DDSD_MIPMAPCOUNT
    pitch = (width * texel * 8 + 7) // 8
    caps = _DDSCAPS_TEXTURE
    if n_levels > 1:
        caps |= _DDSCAPS_COMPLEX | _DDSCAPS_MIPMAP
    caps2 = 0
    misc = 0
    if cube:
        caps |= _DDSCAPS_COMPLEX
        caps2 = _DDSCAPS2_CUBEMAP | _DDSCAPS2_CUBEMAP_ALLFACES
        misc = _D3D11_RESOURCE_MISC_TEXTURECUBE

    header = struct.pack(
        "<4s7I44x2I4s5I5I",
        DDS_MAGIC,
        124,  # dwSize
        flags,
        height,
        width,
        pitch,
        0,  # dwDepth
        n_levels,  # dwMipMapCount; dwReserved1[11] = 0
        32,  # ddspf.dwSize
        _DDPF_FOURCC,
        _FOURCC_DX10,
        0, 0, 0, 0, 0,  # dwRGBBitCount and the four masks
        caps,
        caps2,
        0, 0, 0,  # dwCaps3, dwCaps4, dwReserved2
    )
    dx10 = struct.pack("<5I", code, _D3D10_RESOURCE_DIMENSION_TEXTURE2D, misc, 1, 0)
    encoded = [encode_texels(a, encoding, channels, what=f"{name} level {p}") for p, a in enumerate(arrays)]
    if cube:
        # Per face (array slice), all of its mips, largest first.
        chunks = []
        for face in range(6):
            for p, data in enumerate(encoded):
                size = len(data) // 6
                chunks.append(data[face * size : (face + 1) * size])
    else:
        chunks = encoded
    return header + dx10 + b"".join(chunks)


def write_dds(path, levels, dxgi_format, cube=False):
    """Write a DDS file (DX10 header) of float texels and return ``path``.

    ``levels`` as in :func:`pbrkit.io.ktx2.write_ktx2`: level 0 first, (H, W, C)
    for 2D or (6, N, N, C) for a cube map (+X, -X, +Y, -Y, +Z, -Z).
    ``dxgi_format`` is a code or name from :data:`DXGI_FORMATS` (e.g. 10 or
    "R16G16B16A16_FLOAT"); RGB input gets alpha 1 for RGBA formats.
    """
    data = dds_bytes(levels, dxgi_format, cube=cube)
    write_bytes(path, data)  # atomic: temporary file, then rename
    return path


def _fail(name, message):
    raise InputError(message, name)


def parse_dds(data, name=None):
    """Parse the bytes of a DDS file; see :func:`read_dds`."""
    data = bytes(data)
    if len(data) < _HEADER_SIZE:
        _fail(name, f"{len(data)} bytes is too short for a DDS file with a DX10 header")
    if data[:4] != DDS_MAGIC:
        _fail(name, "not a DDS file (bad magic)")
    (size, flags, height, width, pitch, depth, mips) = struct.unpack_from("<7I", data, 4)
    reserved1 = struct.unpack_from("<11I", data, 32)
    pf_size, pf_flags, fourcc = struct.unpack_from("<2I4s", data, 76)
    pf_rest = struct.unpack_from("<5I", data, 88)
    caps, caps2, caps3, caps4, reserved2 = struct.unpack_from("<5I", data, 108)
    dxgi, dimension, misc, array_size, misc2 = struct.unpack_from("<5I", data, 128)
    header = {
        "dwSize": size, "dwFlags": flags, "dwHeight": height, "dwWidth": width,
        "dwPitchOrLinearSize": pitch, "dwDepth": depth, "dwMipMapCount": mips,
        "ddspf": {"dwSize": pf_size, "dwFlags": pf_flags, "dwFourCC": fourcc,
                  "dwRGBBitCount": pf_rest[0], "masks": list(pf_rest[1:])},
        "dwCaps": caps, "dwCaps2": caps2, "dwCaps3": caps3, "dwCaps4": caps4,
        "dxgiFormat": dxgi, "resourceDimension": dimension, "miscFlag": misc,
        "arraySize": array_size, "miscFlags2": misc2,
    }
    if size != 124:
        _fail(name, f"DDS_HEADER dwSize {size}, expected 124")
    if pf_size != 32:
        _fail(name, f"DDS_PIXELFORMAT dwSize {pf_size}, expected 32")
    if not pf_flags & _DDPF_FOURCC or fourcc != _FOURCC_DX10:
        _fail(name, f"pixel format is not FOURCC 'DX10' (flags 0x{pf_flags:X}); pbrkit reads DX10 headers only")
    if any(reserved1) or reserved2:
        _fail(name, "reserved header fields are not zero")
    required = _DDSD_CAPS | _DDSD_HEIGHT | _DDSD_WIDTH | _DDSD_PIXELFORMAT
    if flags & required != required:
        _fail(name, f"dwFlags 0x{flags:X} lacks CAPS|HEIGHT|WIDTH|PIXELFORMAT")
    if not caps & _DDSCAPS_TEXTURE:
        _fail(name, f"dwCaps 0x{caps:X} lacks DDSCAPS_TEXTURE")
    if dxgi not in _BY_CODE:
        _fail(name, f"unsupported dxgiFormat {dxgi}; supported: {sorted(_BY_CODE)}")
    fmt_name, encoding, channels = _BY_CODE[dxgi]
    header["formatName"] = fmt_name
    if dimension != _D3D10_RESOURCE_DIMENSION_TEXTURE2D:
        _fail(name, f"resourceDimension {dimension}: only TEXTURE2D (3) is supported")
    if flags & _DDSD_DEPTH or caps2 & _DDSCAPS2_VOLUME or depth > 1:
        _fail(name, "volume textures are not supported")
    if array_size != 1:
        _fail(name, f"arraySize {array_size}: only single textures / single cube maps are supported")
    cube = bool(misc & _D3D11_RESOURCE_MISC_TEXTURECUBE)
    if misc & ~_D3D11_RESOURCE_MISC_TEXTURECUBE:
        _fail(name, f"miscFlag 0x{misc:X} has unsupported bits")
    if cube:
        all_faces = _DDSCAPS2_CUBEMAP | _DDSCAPS2_CUBEMAP_ALLFACES
        if caps2 & all_faces != all_faces:
            _fail(name, f"cube map without all six DDSCAPS2 face flags (dwCaps2 0x{caps2:X})")
        if not caps & _DDSCAPS_COMPLEX:
            _fail(name, "cube map without DDSCAPS_COMPLEX")
        if width != height:
            _fail(name, f"cube map faces must be square, got {width} x {height}")
    elif caps2 & _DDSCAPS2_CUBEMAP:
        _fail(name, "DDSCAPS2_CUBEMAP set but the DX10 miscFlag has no TEXTURECUBE")
    if width == 0 or height == 0:
        _fail(name, f"empty image {width} x {height}")
    n_levels = mips if flags & _DDSD_MIPMAPCOUNT and mips > 0 else 1
    max_levels = max_mip_levels(width, height)
    if n_levels > max_levels:
        _fail(name, f"dwMipMapCount {n_levels} exceeds the maximum {max_levels} for {width} x {height}")
    if n_levels > 1 and caps & (_DDSCAPS_MIPMAP | _DDSCAPS_COMPLEX) != _DDSCAPS_MIPMAP | _DDSCAPS_COMPLEX:
        _fail(name, f"mipmapped texture without DDSCAPS_MIPMAP|DDSCAPS_COMPLEX (dwCaps 0x{caps:X})")
    texel = texel_size(encoding, channels)
    if flags & _DDSD_PITCH and pitch != width * texel:
        _fail(name, f"dwPitchOrLinearSize {pitch}, expected the row pitch {width * texel}")
    faces = 6 if cube else 1
    sizes = [max(1, width >> p) * max(1, height >> p) * texel for p in range(n_levels)]
    expected = _HEADER_SIZE + faces * sum(sizes)
    if len(data) != expected:
        _fail(name, f"file has {len(data)} bytes, expected {expected} for the declared images")
    check_decoded(name, encoding, channels, faces * sum(sizes) // texel, f"the {n_levels} level(s) of the DDS file")
    per_level = [[] for _ in range(n_levels)]
    offset = _HEADER_SIZE
    for _face in range(faces):
        for p in range(n_levels):
            shape = (max(1, height >> p), max(1, width >> p))
            per_level[p].append(decode_texels(data[offset : offset + sizes[p]], encoding, channels, shape))
            offset += sizes[p]
    levels = [np.stack(images) if cube else images[0] for images in per_level]
    return header, levels


def read_dds(path):
    """Read a DDS file (DX10 header, a float format of :data:`DXGI_FORMATS`).

    Returns ``(header, levels)``: the header fields (Microsoft's names, the
    DX10 fields, ``formatName``) and the images as float32 arrays, level 0
    first, (H, W, C) or (6, N, N, C) for a cube map.  Strict: magic, sizes,
    FOURCC, flags and caps, DX10 fields, pitch and the exact file length are
    checked; a violation raises :class:`~pbrkit.core.errors.InputError` (a
    ``ValueError``) naming the file.  Only a regular file is read, and the
    images the header declares must match the file's length before any is
    decoded (:mod:`pbrkit.io.containers`).
    """
    return read_container(path, parse_dds, "a DDS file (DX10 header, float format)")
