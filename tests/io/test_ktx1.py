"""KTX 1.1 writer/reader (pbrkit.io.ktx1) and Filament's ``sh`` text.

Byte layouts are checked with ``struct`` at the offsets of the KTX 1.1
specification (Khronos), worked out by hand here, not taken from the module:
identifier 0..11, then the 13 UInt32 header words at 12..63 (endianness,
glType, glTypeSize, glFormat, glInternalFormat, glBaseInternalFormat,
pixelWidth, pixelHeight, pixelDepth, numberOfArrayElements, numberOfFaces,
numberOfMipmapLevels, bytesOfKeyValueData), the key/value data at 64, then per
level an imageSize word (one face for a non-array cube map) and the data.
Texel rounding is checked against :mod:`pbrkit.io.float_packing`.
"""

from __future__ import annotations

import re
import struct

import numpy as np
import pytest

from pbrkit.core.errors import InputError
from pbrkit.ibl.sh import lambertian_sh_prescaled
from pbrkit.io.float_packing import pack_b10g11r11, to_float16, unpack_b10g11r11
from pbrkit.io.ktx1 import (
    GL_FORMATS,
    filament_sh_text,
    ktx1_bytes,
    parse_ktx1,
    read_ktx1,
    write_ktx1,
)

IDENT = bytes([0xAB, 0x4B, 0x54, 0x58, 0x20, 0x31, 0x31, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A])
WORDS = ("endianness glType glTypeSize glFormat glInternalFormat glBaseInternalFormat pixelWidth "
         "pixelHeight pixelDepth numberOfArrayElements numberOfFaces numberOfMipmapLevels "
         "bytesOfKeyValueData").split()


def header(data):
    assert data[:12] == IDENT
    return dict(zip(WORDS, struct.unpack_from("<13I", data, 12)))


def cube_chain(n, levels, channels=3, seed=0):
    rng = np.random.default_rng(seed)
    return [rng.uniform(0.001, 40.0, size=(6, n >> m, n >> m, channels)) for m in range(levels)]


# ----------------------------------------------------------------------------
# round trips


def test_r11g11b10_cube_round_trip_matches_float_packing():
    levels = cube_chain(8, 4)
    info, back, kv = parse_ktx1(ktx1_bytes(levels, "R11F_G11F_B10F", cube=True))
    assert info["formatName"] == "R11F_G11F_B10F" and info["cube"] and info["levelCount"] == 4
    assert kv == {}
    for a, b in zip(levels, back, strict=True):
        assert b.shape == a.shape and b.dtype == np.float32
        np.testing.assert_array_equal(b, unpack_b10g11r11(pack_b10g11r11(a)))
        assert np.all(np.abs(b - a) <= a * [2.0**-7, 2.0**-7, 2.0**-6])


def test_rgba16f_cube_round_trip_rounds_like_float16_and_adds_alpha_one():
    levels = cube_chain(4, 3)
    _, back, _ = parse_ktx1(ktx1_bytes(levels, "RGBA16F", cube=True))
    for a, b in zip(levels, back, strict=True):
        assert b.shape == a.shape[:-1] + (4,)
        np.testing.assert_array_equal(b[..., :3], to_float16(a).astype(np.float32))
        assert np.all(b[..., 3] == 1.0)
    rgba = [np.concatenate([a, a[..., :1] * 0.5], axis=-1) for a in levels]
    _, back, _ = parse_ktx1(ktx1_bytes(rgba, 0x881A, cube=True))
    for a, b in zip(rgba, back, strict=True):
        np.testing.assert_array_equal(b, to_float16(a).astype(np.float32))


def test_2d_round_trip_and_file_on_disk(tmp_path):
    rng = np.random.default_rng(3)
    levels = [rng.uniform(0, 2, (4, 8, 3)), rng.uniform(0, 2, (2, 4, 3)), rng.uniform(0, 2, (1, 2, 3))]
    path = write_ktx1(tmp_path / "a.ktx", levels, "R11F_G11F_B10F")
    info, back, _ = read_ktx1(path)
    assert not info["cube"] and info["numberOfFaces"] == 1
    assert info["imageSizes"] == [8 * 4 * 4, 4 * 2 * 4, 2 * 1 * 4]  # whole image for a 2D texture
    for a, b in zip(levels, back, strict=True):
        np.testing.assert_array_equal(b, unpack_b10g11r11(pack_b10g11r11(a)))


def test_bytes_are_deterministic():
    levels = cube_chain(4, 2)
    kv = {"sh": filament_sh_text(np.ones((9, 3))), "note": "x"}
    assert ktx1_bytes(levels, "R11F_G11F_B10F", True, kv) == ktx1_bytes(levels, "R11F_G11F_B10F", True, kv)


# ----------------------------------------------------------------------------
# layout, checked against the spec


@pytest.mark.parametrize("name, words", [
    ("R11F_G11F_B10F", (0x8C3A, 1, 0x1907, 0x8C3A, 0x1907)),  # cmgen's glType 0x8C3A, what Filament reads
    ("RGBA16F", (0x140B, 2, 0x1908, 0x881A, 0x1908)),
])
def test_header_words_at_spec_offsets(name, words):
    levels = cube_chain(16, 5)
    data = ktx1_bytes(levels, name, cube=True)
    h = header(data)
    assert h["endianness"] == 0x04030201 and data[12:16] == b"\x01\x02\x03\x04"
    assert (h["glType"], h["glTypeSize"], h["glFormat"], h["glInternalFormat"], h["glBaseInternalFormat"]) == words
    assert (h["pixelWidth"], h["pixelHeight"], h["pixelDepth"], h["numberOfArrayElements"]) == (16, 16, 0, 0)
    assert (h["numberOfFaces"], h["numberOfMipmapLevels"], h["bytesOfKeyValueData"]) == (6, 5, 0)
    assert GL_FORMATS[name][:5] == (words[3], words[2], words[0], words[1], words[4])
    texel = 4 if name == "R11F_G11F_B10F" else 8
    pos = 64
    for m in range(5):
        n = 16 >> m
        (image_size,) = struct.unpack_from("<I", data, pos)
        assert image_size == n * n * texel  # one face: non-array cube map
        pos += 4 + 6 * image_size
    assert pos == len(data)


def test_faces_in_ktx_order_rows_as_given():
    levels = [np.zeros((6, 2, 2, 3))]
    for f in range(6):
        levels[0][f] = [[[f + 1, 0.5, 0.25], [f + 1, 0.5, 0.5]], [[f + 1, 1, 0.25], [f + 1, 1, 0.5]]]
    data = ktx1_bytes(levels, "RGBA16F", cube=True)
    body = np.frombuffer(data, dtype="<f2", offset=68).reshape(6, 2, 2, 4)
    for f in range(6):
        assert np.all(body[f, ..., 0] == f + 1)  # face f = +X, -X, +Y, -Y, +Z, -Z in the file's order
    assert body[0, 0, 1, 2] == 0.5 and body[0, 1, 0, 1] == 1.0  # row 0 first, column 1 second


def test_r11g11b10_texel_bits_little_endian():
    data = ktx1_bytes([np.array([[[1.0, 2.0, 0.5]]])], "R11F_G11F_B10F")
    (word,) = struct.unpack_from("<I", data, 68)
    # 1.0 = E 15 M 0 (11-bit: 15 << 6); 2.0 = E 16 (16 << 6); 0.5 = E 14 (10-bit: 14 << 5).
    assert word == (15 << 6) | ((16 << 6) << 11) | ((14 << 5) << 22)


def test_key_value_entries_and_padding():
    kv = {"sh": b"1 2 3\n", "abc": "xyz", "k": b""}
    data = ktx1_bytes([np.ones((1, 1, 3))], "R11F_G11F_B10F", key_values=kv)
    h = header(data)
    # "sh\0" + 6 bytes = 9 -> 3 padding; "abc\0" + "xyz\0" = 8 -> 0; "k\0" = 2 -> 2.
    expected = (struct.pack("<I", 9) + b"sh\x001 2 3\n" + b"\0" * 3
                + struct.pack("<I", 8) + b"abc\x00xyz\x00"
                + struct.pack("<I", 2) + b"k\x00" + b"\0" * 2)
    assert h["bytesOfKeyValueData"] == len(expected) == 16 + 12 + 8
    assert data[64:100] == expected
    assert struct.unpack_from("<I", data, 100)[0] == 4  # imageSize of the 1 x 1 level follows
    _, _, back = parse_ktx1(data)
    assert back == {"sh": b"1 2 3\n", "abc": b"xyz\x00", "k": b""}


# ----------------------------------------------------------------------------
# Filament's sh text


def test_filament_sh_text_parses_back_to_the_numbers():
    rng = np.random.default_rng(7)
    coeffs = lambertian_sh_prescaled(rng.normal(size=(9, 3)) * [1e-3, 1.0, 300.0])
    text = filament_sh_text(coeffs)
    assert isinstance(text, bytes) and b"\x00" not in text
    s = text.decode("ascii")
    lines = s.split("\n")
    assert len(lines) == 10 and lines[-1] == ""  # 9 lines, each ending in "\n"
    assert all(len(line.split(" ")) == 3 for line in lines[:9])  # single spaces
    tokens = s.split()
    assert len(tokens) == 27
    np.testing.assert_array_equal(np.float32([float(t) for t in tokens]), np.float32(coeffs).reshape(-1))
    # Filament's JS helper: split on single whitespace characters, first 27 pieces.
    js_like = re.split(r"\s", s)[:27]
    np.testing.assert_array_equal(np.float32([float(t) for t in js_like]), np.float32(coeffs).reshape(-1))


def test_filament_sh_text_refuses_bad_input():
    with pytest.raises(InputError, match="9 x 3"):
        filament_sh_text(np.zeros((9, 4)))
    bad = np.zeros((9, 3))
    bad[4, 1] = np.nan
    with pytest.raises(InputError, match="finite"):
        filament_sh_text(bad)


# ----------------------------------------------------------------------------
# what Filament accepts besides what pbrkit writes


def test_reader_accepts_the_spec_gltype_and_typesize_for_r11g11b10():
    levels = cube_chain(4, 2)
    data = bytearray(ktx1_bytes(levels, "R11F_G11F_B10F", cube=True))
    _, expected, _ = parse_ktx1(bytes(data))
    struct.pack_into("<2I", data, 16, 0x8C3B, 4)  # UNSIGNED_INT_10F_11F_11F_REV, glTypeSize 4
    struct.pack_into("<I", data, 24, 0x8C3A)  # older cmgen files: glFormat 0x8C3A
    info, back, _ = parse_ktx1(bytes(data))
    assert info["glType"] == 0x8C3B
    for a, b in zip(expected, back, strict=True):
        np.testing.assert_array_equal(a, b)


# ----------------------------------------------------------------------------
# refusals: one line, naming the file


def _refused(data, match, tmp_path):
    path = tmp_path / "bad.ktx"
    path.write_bytes(bytes(data))
    with pytest.raises(InputError, match=match) as info:
        read_ktx1(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(str(path) + ": ")
    return message


def _good():
    return bytearray(ktx1_bytes(cube_chain(4, 3), "R11F_G11F_B10F", cube=True, key_values={"sh": b"0 0 0\n"}))


def test_refuses_truncated_header(tmp_path):
    _refused(_good()[:40], "too short for a KTX1 header", tmp_path)


def test_refuses_wrong_identifier(tmp_path):
    data = _good()
    data[5] = ord("2")  # «KTX 21»
    _refused(data, "bad identifier", tmp_path)


def test_refuses_big_endian_and_bad_endianness(tmp_path):
    data = _good()
    struct.pack_into("<I", data, 12, 0x01020304)
    _refused(data, "big-endian", tmp_path)
    struct.pack_into("<I", data, 12, 0x12345678)
    _refused(data, "endianness", tmp_path)


def test_refuses_too_many_levels(tmp_path):
    data = _good()
    struct.pack_into("<I", data, 56, 4)  # a 4 x 4 face has at most 3 levels
    _refused(data, "numberOfMipmapLevels 4 exceeds the maximum 3", tmp_path)


def test_refuses_truncated_data(tmp_path):
    data = _good()
    _refused(data[:-1], "level 2 is truncated", tmp_path)
    _refused(data[:-28], "before the imageSize of level 2", tmp_path)
    _refused(data + b"\0\0\0\0", "unexpected bytes after the last level", tmp_path)


def test_refuses_bad_format(tmp_path):
    data = _good()
    struct.pack_into("<I", data, 28, 0x8814)  # RGBA32F: not supported
    _refused(data, "unsupported glInternalFormat 0x8814", tmp_path)
    data = _good()
    struct.pack_into("<I", data, 16, 0x1406)  # glType FLOAT with R11F_G11F_B10F
    _refused(data, "glType 0x1406 does not go with R11F_G11F_B10F", tmp_path)
    data = _good()
    struct.pack_into("<I", data, 24, 0)  # glFormat 0 means compressed to Filament's reader
    _refused(data, "glFormat 0x0000", tmp_path)


def test_refuses_inconsistent_header_and_sizes(tmp_path):
    for offset, value, match in [
        (52, 2, "numberOfFaces 2"),
        (48, 1, "texture arrays"),
        (44, 1, "3D textures"),
        (40, 2, "must be square"),
        (60, 7, "not a multiple of 4"),
        (60, 1 << 20, "extends past the end"),
        (64, 1 << 16, "overruns bytesOfKeyValueData"),
        (80, 4 * 4 * 4 * 6, "imageSize 384, expected 64"),  # whole-level imageSize for a cube
    ]:
        data = _good()
        struct.pack_into("<I", data, offset, value)
        _refused(data, match, tmp_path)
    data = _good()
    data[64 + 4 + 3 + 6] = 1  # non-zero valuePadding after "sh"
    _refused(data, "valuePadding", tmp_path)


def test_read_missing_file_names_it(tmp_path):
    with pytest.raises(InputError, match="missing.ktx"):
        read_ktx1(tmp_path / "missing.ktx")


def test_writer_refusals():
    with pytest.raises(InputError, match="channel"):
        ktx1_bytes([np.ones((1, 1, 4))], "R11F_G11F_B10F")
    with pytest.raises(InputError, match="unsupported"):
        ktx1_bytes([np.ones((1, 1, 3))], "RGB9_E5")
    with pytest.raises(InputError, match="level 1"):
        ktx1_bytes([np.ones((6, 4, 4, 3)), np.ones((6, 4, 4, 3))], "RGBA16F", cube=True)
    with pytest.raises(InputError, match="at most 3"):
        ktx1_bytes(cube_chain(4, 3) + [np.ones((6, 1, 1, 3))], "RGBA16F", cube=True)
    with pytest.raises(InputError, match="key"):
        ktx1_bytes([np.ones((1, 1, 3))], "RGBA16F", key_values={"a\0b": b""})
    with pytest.raises(InputError, match="value"):
        ktx1_bytes([np.ones((1, 1, 3))], "RGBA16F", key_values={"a": 3})
