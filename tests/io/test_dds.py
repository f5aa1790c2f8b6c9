"""DDS (DX10 header) writer and reader.

Expected bytes are assembled field by field from Microsoft's DDS_HEADER /
DDS_PIXELFORMAT / DDS_HEADER_DXT10 documentation with the flag values
written out as literals, not taken from the writer.
"""

from __future__ import annotations

import struct

import numpy as np
import pytest
from texels import assert_levels_decoded

from pbrkit.io.dds import DXGI_FORMATS, dds_bytes, parse_dds, read_dds, write_dds


def _header(flags, height, width, pitch, mips, caps, caps2, dxgi, misc):
    out = b"DDS "
    out += struct.pack("<7I", 124, flags, height, width, pitch, 0, mips)
    out += bytes(44)  # dwReserved1[11]
    out += struct.pack("<2I", 32, 0x4) + b"DX10" + bytes(20)  # ddspf: FOURCC 'DX10'
    out += struct.pack("<5I", caps, caps2, 0, 0, 0)
    out += struct.pack("<5I", dxgi, 3, misc, 1, 0)  # TEXTURE2D, arraySize 1
    return out


def test_dds_exact_bytes_of_2x2_r16g16_two_levels():
    level0 = np.array([[[1.0, -2.0], [0.5, 0.25]], [[3.0, 4.0], [-0.125, 8.0]]])
    level1 = np.array([[[0.75, -1.5]]])
    data = dds_bytes([level0, level1], "R16G16_FLOAT")
    # CAPS 0x1 | HEIGHT 0x2 | WIDTH 0x4 | PITCH 0x8 | PIXELFORMAT 0x1000 |
    # MIPMAPCOUNT 0x20000; pitch = 2 texels x 4 bytes; caps TEXTURE 0x1000 |
    # COMPLEX 0x8 | MIPMAP 0x400000; DXGI_FORMAT_R16G16_FLOAT = 34.
    expected = _header(0x2100F, 2, 2, 8, 2, 0x401008, 0, 34, 0)
    assert len(expected) == 148
    expected += np.array([1.0, -2.0, 0.5, 0.25, 3.0, 4.0, -0.125, 8.0], dtype="<f2").tobytes()
    expected += np.array([0.75, -1.5], dtype="<f2").tobytes()
    assert data == expected
    header, levels = parse_dds(data)
    assert header["dxgiFormat"] == 34 and header["dwMipMapCount"] == 2
    assert np.array_equal(levels[0], level0) and np.array_equal(levels[1], level1)


def test_dds_cube_is_stored_face_major_with_all_mips_per_face():
    n = 2
    # Value = 100 face + 10 level + texel index: the file order is readable.
    level0 = np.array([[[[100 * f + t * n + s] for s in range(n)] for t in range(n)] for f in range(6)], float)
    level1 = np.array([[[[100 * f + 10]]] for f in range(6)], float)
    data = dds_bytes([level0, level1], "R32_FLOAT", cube=True)
    # caps TEXTURE | COMPLEX | MIPMAP; caps2 CUBEMAP 0x200 | six faces 0xFC00;
    # miscFlag TEXTURECUBE 0x4; DXGI_FORMAT_R32_FLOAT = 41; pitch 2 x 4.
    assert data[:148] == _header(0x2100F, 2, 2, 8, 2, 0x401008, 0xFE00, 41, 0x4)
    values = np.frombuffer(data, "<f4", offset=148)
    expected = []
    for f in range(6):  # +X, -X, +Y, -Y, +Z, -Z
        expected += [100 * f + 0, 100 * f + 1, 100 * f + 2, 100 * f + 3]  # level 0, rows in order
        expected += [100 * f + 10]  # then level 1 of the same face
    assert values.tolist() == expected
    _, levels = parse_dds(data)
    assert np.array_equal(levels[0], level0) and np.array_equal(levels[1], level1)


def test_dds_single_level_flags():
    data = dds_bytes([np.zeros((2, 4, 4))], "R32G32B32A32_FLOAT")
    # One 4x2 level: caps TEXTURE only; pitch 4 x 16; mip count 1 (as DirectXTex).
    assert data[:148] == _header(0x2100F, 2, 4, 64, 1, 0x1000, 0, 2, 0)
    assert len(data) == 148 + 4 * 2 * 16


@pytest.mark.parametrize("name", list(DXGI_FORMATS))
@pytest.mark.parametrize("cube", [False, True])
def test_dds_round_trip_all_formats(tmp_path, name, cube):
    code, encoding, channels = DXGI_FORMATS[name]
    rng = np.random.default_rng(5)
    levels = []
    for p in range(3):
        size = (max(1, 8 >> p), max(1, 8 >> p)) if cube else (max(1, 4 >> p), max(1, 16 >> p))
        levels.append(rng.uniform(0.0, 20.0, ((6,) if cube else ()) + size + (channels,)))
    path = write_dds(tmp_path / f"t_{name}.dds", levels, name, cube=cube)
    header, back = read_dds(path)
    assert header["dxgiFormat"] == code and header["formatName"] == name
    assert_levels_decoded(levels, back, encoding)
    assert path.read_bytes() == dds_bytes(levels, name, cube=cube)


def test_dds_rgb_to_rgba_and_bad_input():
    _, levels = parse_dds(dds_bytes([np.full((1, 2, 3), 2.0)], 10))
    assert np.array_equal(levels[0][..., 3], [[1.0, 1.0]])
    with pytest.raises(ValueError, match="channel"):
        dds_bytes([np.zeros((2, 2, 3))], "R16G16_FLOAT")
    with pytest.raises(ValueError, match="unsupported DXGI"):
        dds_bytes([np.zeros((2, 2, 4))], "BC6H_UF16")
    with pytest.raises(ValueError, match="level 1"):
        dds_bytes([np.zeros((4, 4, 4)), np.zeros((1, 1, 4))], 2)


def test_dds_reader_is_strict(tmp_path):
    good = dds_bytes([np.ones((2, 2, 4)), np.ones((1, 1, 4))], 2)
    parse_dds(good)

    def corrupt(offset, new):
        return good[:offset] + new + good[offset + len(new):]

    cases = {
        "magic": corrupt(0, b"XDS "),
        "dwSize": corrupt(4, struct.pack("<I", 128)),
        "DX10": corrupt(84, b"DXT5"),
        "dxgiFormat": corrupt(128, struct.pack("<I", 71)),
        "resourceDimension": corrupt(132, struct.pack("<I", 4)),
        "arraySize": corrupt(140, struct.pack("<I", 2)),
        "expected": good[:-1],
        "pitch": corrupt(20, struct.pack("<I", 7)),
        "cube": corrupt(136, struct.pack("<I", 4)),
    }
    for what, data in cases.items():
        path = tmp_path / "bad.dds"
        path.write_bytes(data)
        with pytest.raises(ValueError, match="bad.dds") as info:
            read_dds(path)
        assert what.lower() in str(info.value).lower(), (what, str(info.value))
