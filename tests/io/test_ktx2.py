"""KTX 2.0 writer/reader and the float16 / B10G11R11 encodings.

Byte layouts are checked against values worked out by hand from the KTX 2.0
specification (field order, offsets, alignment, DFD words), not against the
writer; packing against bit patterns computed from the Vulkan definition of
unsigned 11/10-bit floats and against a brute-force nearest-value search.
"""

from __future__ import annotations

import struct
import warnings

import numpy as np
import pytest
from texels import assert_levels_decoded, b10g11r11_tolerance

from pbrkit.io.containers import encode_texels
from pbrkit.io.float_packing import (
    RangeWarning,
    float_to_ufloat,
    pack_b10g11r11,
    to_float16,
    ufloat_to_float,
    unpack_b10g11r11,
)
from pbrkit.io.ktx2 import VK_FORMATS, ktx2_bytes, parse_ktx2, read_ktx2, write_ktx2

IDENT = bytes([0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A])


# ----------------------------------------------------------------------------
# float16


def test_float16_rounds_to_nearest_even_from_float64():
    ulp = 2.0**-10
    values = np.array([1.0 + ulp / 2, 1.0 + 3 * ulp / 2, 1.0 + ulp / 2 + 2.0**-40, -(1.0 + ulp / 2)])
    expected = np.array([1.0, 1.0 + 2 * ulp, 1.0 + ulp, -1.0])
    # The third value is just above a tie: a float32 intermediate would lose
    # the 2^-40 and round down; a single correct rounding goes up.
    assert np.array_equal(to_float16(values).astype(np.float64), expected)


def test_float16_clamps_overflow_with_warning_and_keeps_inf_nan():
    with pytest.warns(RangeWarning):
        out = to_float16([65504.0, 65519.0, 70000.0, -1e9])
    assert np.array_equal(out.astype(float), [65504.0, 65504.0, 65504.0, -65504.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = to_float16([np.inf, -np.inf, np.nan, 6e-8])
    assert np.isposinf(out[0]) and np.isneginf(out[1]) and np.isnan(out[2])
    assert out[3] == np.float16(2.0**-24)  # smallest half denormal


# ----------------------------------------------------------------------------
# Unsigned 11/10-bit floats (Vulkan "Unsigned 11-Bit Floating-Point Numbers")


@pytest.mark.parametrize(
    "value, code11, code10",
    [
        (0.0, 0x000, 0x000),
        (1.0, 15 << 6, 15 << 5),  # E = 15, M = 0
        (0.5, 14 << 6, 14 << 5),
        (1.5, (15 << 6) | 32, (15 << 5) | 16),
        (65024.0, (30 << 6) | 63, None),  # 11-bit max: 2^15 (1 + 63/64)
        (64512.0, (30 << 6) | 62, (30 << 5) | 31),  # 10-bit max: 2^15 (1 + 31/32)
        (2.0**-14, 1 << 6, 1 << 5),  # smallest normal
        (2.0**-20, 0x001, None),  # 11-bit denormal unit 2^-14 / 64
        (2.0**-19, 0x002, 0x001),  # 10-bit denormal unit 2^-14 / 32
        (63 * 2.0**-20, 0x03F, None),  # largest 11-bit denormal
        (63.5 * 2.0**-20, 0x040, None),  # tie -> even (64 = E 1, M 0)
        (2.0**-21, 0x000, 0x000),  # tie between 0 and the first denormal -> 0
        (1.0 + 2.0**-7, 15 << 6, 15 << 5),  # 11-bit tie -> even mantissa 0
        (1.0 + 3 * 2.0**-7, (15 << 6) | 2, (15 << 5) | 1),
        (64513.0, (30 << 6) | 62, None),  # rounds to nearest (11-bit); 10-bit clamps, below
    ],
)
def test_ufloat_bit_patterns(value, code11, code10):
    if code11 is not None:
        assert int(float_to_ufloat(value, 6)) == code11
        # Within half a step: 2^-7 relative for normals, 2^-21 absolute for denormals.
        assert abs(float(ufloat_to_float(code11, 6)) - value) <= max(value * 2.0**-7, 2.0**-21)
    if code10 is not None:
        assert int(float_to_ufloat(value, 5)) == code10


def test_ufloat_special_values():
    with pytest.warns(RangeWarning):
        codes = float_to_ufloat([-1.0, 1e9, 65025.0], 6)
    assert list(codes) == [0, (30 << 6) | 63, (30 << 6) | 63]
    with pytest.warns(RangeWarning):
        assert int(float_to_ufloat(65024.0, 5)) == (30 << 5) | 31
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        codes = float_to_ufloat([np.inf, -np.inf, np.nan, -0.0], 6)
    assert codes[0] == 31 << 6  # +inf: E = 31, M = 0
    assert codes[1] == 0  # -inf -> 0
    assert codes[2] >> 6 == 31 and codes[2] & 63 != 0  # NaN: E = 31, M != 0
    assert codes[3] == 0
    decoded = ufloat_to_float([31 << 6, (31 << 6) | 5], 6)
    assert np.isposinf(decoded[0]) and np.isnan(decoded[1])


@pytest.mark.parametrize("mbits, rel_bound", [(6, 2.0**-7), (5, 2.0**-6)])
def test_ufloat_round_to_nearest_against_brute_force(mbits, rel_bound):
    rng = np.random.default_rng(7)
    x = np.exp(rng.uniform(np.log(1e-7), np.log(6.4e4), 20000))
    # All finite codes, decoded from the definition independently of pbrkit.
    codes = np.arange(31 << mbits)
    e, m = codes >> mbits, codes & ((1 << mbits) - 1)
    table = np.where(e == 0, m / 2.0**mbits * 2.0**-14, (1 + m / 2.0**mbits) * 2.0 ** (e - 15.0))
    idx = np.clip(np.searchsorted(table, x), 1, len(table) - 1)
    lo, hi = table[idx - 1], table[idx]
    nearest_err = np.minimum(x - lo, hi - x)
    got = ufloat_to_float(float_to_ufloat(x, mbits), mbits).astype(np.float64)
    assert np.all(np.abs(got - x) <= nearest_err * (1 + 1e-12))
    assert np.all(np.isin(got, table))
    normal = x >= 2.0**-14
    rel = np.abs(got - x)[normal] / x[normal]
    assert rel.max() <= rel_bound
    assert rel.max() > 0.9 * rel_bound  # the bound is attained: no truncation slack


def test_b10g11r11_word_layout():
    # R in bits 0..10, G in 11..21, B (10-bit) in 22..31.
    word = int(pack_b10g11r11([1.0, 0.5, 2.0]))
    assert word == (15 << 6) | ((14 << 6) << 11) | ((16 << 5) << 22)
    assert int(pack_b10g11r11([1.0, 1.0, 1.0])) == 0x781E03C0
    assert np.array_equal(unpack_b10g11r11(np.uint32(0x781E03C0)), [1.0, 1.0, 1.0])
    rgb = np.random.default_rng(3).uniform(0, 100, (50, 3))
    back = unpack_b10g11r11(pack_b10g11r11(rgb))
    assert np.all(np.abs(back - rgb) <= b10g11r11_tolerance(rgb))


# ----------------------------------------------------------------------------
# KTX2 byte layout, worked out by hand from the spec


def _dfd_words_r16g16():
    return [
        60,  # dfdTotalSize = 4 + 24 + 16 * 2
        0,  # vendorId 0 (17 bits), descriptorType 0
        2 | (56 << 16),  # versionNumber 2, descriptorBlockSize 24 + 32
        1 | (1 << 8) | (1 << 16),  # RGBSDA, BT709, LINEAR, flags 0
        0,  # texelBlockDimension 0..3
        4,  # bytesPlane0 = 4 (two 16-bit halves)
        0,
        0xC00F0000,  # R: bitOffset 0, bitLength 16 - 1, channel 0 | FLOAT | SIGNED
        0,
        0xBF800000,  # -1.0f
        0x3F800000,  # 1.0f
        0xC10F0010,  # G: bitOffset 16, bitLength 15, channel 1 | 0xC0
        0,
        0xBF800000,
        0x3F800000,
    ]


def _kvd(entries):
    out = b""
    for key, value in entries:
        kv = key + b"\x00" + value
        out += struct.pack("<I", len(kv)) + kv + b"\x00" * (-len(kv) % 4)
    return out


def test_ktx2_exact_bytes_of_2x2_r16g16_two_levels():
    level0 = np.array([[[1.0, -2.0], [0.5, 0.25]], [[3.0, 4.0], [-0.125, 65504.0]]])
    level1 = np.array([[[0.75, -1.5]]])
    data = ktx2_bytes([level0, level1], "R16G16_SFLOAT", writer_version="9.9")

    # Header 80 bytes, level index 2 x 24 -> DFD at 128, 60 bytes -> kvd at 188.
    # kvd: "KTXorientation\0rd\0" is 18 bytes (+4 length, +2 pad = 24);
    # "KTXwriter\0pbrkit 9.9\0" is 21 bytes (+4, +3 pad = 28): 52 in all.
    # Texel 4 bytes -> alignment lcm(4, 4) = 4; kvd ends at 240: level 1
    # (smallest, 4 bytes) at 240, level 0 (16 bytes) at 244, file 260 bytes.
    expected = IDENT
    expected += struct.pack("<9I", 83, 2, 2, 2, 0, 0, 1, 2, 0)
    expected += struct.pack("<4I2Q", 128, 60, 188, 52, 0, 0)
    expected += struct.pack("<3Q", 244, 16, 16) + struct.pack("<3Q", 240, 4, 4)
    expected += struct.pack("<15I", *_dfd_words_r16g16())
    expected += _kvd([(b"KTXorientation", b"rd\x00"), (b"KTXwriter", b"pbrkit 9.9\x00")])
    assert len(expected) == 240
    expected += np.array([0.75, -1.5], dtype="<f2").tobytes()
    expected += np.array([1.0, -2.0, 0.5, 0.25, 3.0, 4.0, -0.125, 65504.0], dtype="<f2").tobytes()
    assert len(expected) == 260
    assert data == expected

    header, levels, kv = parse_ktx2(data)
    assert header["levels"][1] == {"byteOffset": 240, "byteLength": 4, "uncompressedByteLength": 4}
    assert np.array_equal(levels[0], level0) and np.array_equal(levels[1], level1)
    assert kv == {"KTXorientation": "rd", "KTXwriter": "pbrkit 9.9"}


def test_ktx2_mip_padding_for_6_byte_texels():
    # R16G16B16_SFLOAT: 6-byte texels -> levels aligned to lcm(6, 4) = 12.
    # 4x2 image, 3 levels: index ends at 80 + 72 = 152; DFD 4 + 24 + 48 = 76
    # -> kvd 228..280.  Level 2 (6 B) at align(280, 12) = 288, level 1 (12 B)
    # at align(294, 12) = 300, level 0 (48 B) at 312; file 360 bytes.
    rng = np.random.default_rng(0)
    levels = [rng.random((2, 4, 3)), rng.random((1, 2, 3)), rng.random((1, 1, 3))]
    data = ktx2_bytes(levels, "R16G16B16_SFLOAT", writer_version="9.9")
    assert len(data) == 360
    assert struct.unpack_from("<9Q", data, 80) == (312, 48, 48, 300, 12, 12, 288, 6, 6)
    assert data[280:288] == bytes(8) and data[294:300] == bytes(6)
    assert struct.unpack_from("<2I", data, 12) == (90, 2)  # vkFormat, typeSize
    _, back, _ = parse_ktx2(data)
    for a, b in zip(levels, back):
        assert np.array_equal(b, a.astype(np.float16).astype(np.float32))


def test_ktx2_b10g11r11_dfd_words():
    data = ktx2_bytes([np.ones((1, 1, 3))], "B10G11R11_UFLOAT_PACK32")
    assert struct.unpack_from("<9I", data, 12) == (122, 4, 1, 1, 0, 0, 1, 1, 0)
    dfd_offset, dfd_length = struct.unpack_from("<2I", data, 48)
    assert (dfd_offset, dfd_length) == (104, 76)
    words = struct.unpack_from("<19I", data, dfd_offset)
    assert words[:7] == (76, 0, 2 | (72 << 16), 0x00010101, 0, 4, 0)
    assert words[7:] == (
        0x800A0000, 0, 0, 0x3F800000,  # R: bits 0..10, FLOAT only (unsigned), 0 / 1.0f
        0x810A000B, 0, 0, 0x3F800000,  # G: bits 11..21
        0x82090016, 0, 0, 0x3F800000,  # B: bits 22..31 (10 bits)
    )
    assert data[-4:] == struct.pack("<I", 0x781E03C0)


def test_ktx2_cube_layout_and_user_keys_sorted_by_code_point():
    n = 4
    level0 = np.arange(6 * n * n * 4, dtype=float).reshape(6, n, n, 4)
    level1 = -np.arange(6 * 2 * 2 * 4, dtype=float).reshape(6, 2, 2, 4)
    level2 = np.full((6, 1, 1, 4), 0.5)
    data = ktx2_bytes([level0, level1, level2], 109, cube=True,
                      key_values={"zeta": "last", "Abc": b"\x01\x02", "pbrkit.manifest": "{}"})
    header, levels, kv = parse_ktx2(data)
    assert header["faceCount"] == 6 and header["pixelWidth"] == header["pixelHeight"] == n
    assert list(kv) == ["Abc", "KTXorientation", "KTXwriter", "pbrkit.manifest", "zeta"]
    assert kv["Abc"] == b"\x01\x02" and kv["zeta"] == "last"
    # Level 0 stored face by face, row by row: +X first, row 0 first.
    off, length, _ = header["levels"][0]["byteOffset"], header["levels"][0]["byteLength"], None
    assert length == 6 * n * n * 16 and off % 16 == 0
    assert np.array_equal(np.frombuffer(data, "<f4", 6 * n * n * 4, off), level0.ravel())
    for a, b in zip([level0, level1, level2], levels):
        assert np.array_equal(a, b)


@pytest.mark.parametrize("name", list(VK_FORMATS))
@pytest.mark.parametrize("cube", [False, True])
def test_ktx2_round_trip_all_formats(tmp_path, name, cube):
    _, encoding, channels, _, _ = VK_FORMATS[name]
    rng = np.random.default_rng(11)
    shape0 = (6, 8, 8) if cube else (4, 8)
    levels = []
    for p in range(4):
        shape = tuple(max(1, s >> p) for s in shape0[-2:])
        shape = ((6,) if cube else ()) + shape
        levels.append(rng.uniform(0.0, 50.0, shape + (channels,)))
    path = write_ktx2(tmp_path / f"t_{name}.ktx2", levels, name, cube=cube)
    header, back, kv = read_ktx2(path)
    assert header["vkFormat"] == VK_FORMATS[name][0]
    assert kv["KTXorientation"] == "rd"
    assert_levels_decoded(levels, back, encoding)
    # Deterministic: same input, same bytes.
    assert path.read_bytes() == ktx2_bytes(levels, name, cube=cube)


def test_ktx2_rgb_input_gets_alpha_one():
    _, levels, _ = parse_ktx2(ktx2_bytes([np.full((2, 2, 3), 0.25)], "R32G32B32A32_SFLOAT"))
    assert np.array_equal(levels[0][..., 3], np.ones((2, 2)))
    assert np.array_equal(levels[0][..., :3], np.full((2, 2, 3), 0.25))


@pytest.mark.parametrize(
    "levels, fmt, cube, match",
    [
        ([np.zeros((4, 4, 3))], "R16G16_SFLOAT", False, "2 channel"),
        ([np.zeros((4, 4, 2)), np.zeros((3, 2, 2))], 83, False, "level 1"),
        ([np.zeros((6, 4, 2, 2))], 83, True, "cube map level 0"),
        ([np.zeros((2, 2, 2))] + [np.zeros((1, 1, 2))] * 2, 83, False, "at most 2"),
        ([np.zeros((2, 2, 2))], "R8G8_UNORM", False, "unsupported vkFormat"),
        ([], 83, False, "non-empty"),
    ],
)
def test_ktx2_writer_rejects_bad_input(levels, fmt, cube, match):
    with pytest.raises(ValueError, match=match):
        ktx2_bytes(levels, fmt, cube=cube)


def test_ktx2_writer_rejects_reserved_keys():
    with pytest.raises(ValueError, match="reserved"):
        ktx2_bytes([np.zeros((1, 1, 2))], 83, key_values={"KTXswizzle": "rg01"})


def _corrupt(data, offset, new):
    return data[:offset] + new + data[offset + len(new):]


def test_ktx2_reader_is_strict(tmp_path):
    good = ktx2_bytes([np.ones((2, 2, 2)), np.ones((1, 1, 2))], 83, writer_version="9.9")
    parse_ktx2(good)
    cases = {
        "identifier": _corrupt(good, 1, b"k"),
        "typeSize": _corrupt(good, 16, struct.pack("<I", 4)),
        "byteOffset": _corrupt(good, 80 + 24, struct.pack("<Q", 241)),
        "byteLength": _corrupt(good, 80 + 8, struct.pack("<Q", 12)),
        "unexpected bytes": good + b"\x00" * 4,
        "dfdTotalSize": _corrupt(good, 128, struct.pack("<I", 64)),
        "channelType": _corrupt(good, 128 + 28 + 3, b"\x80"),
        "sampleLower": _corrupt(good, 128 + 28 + 8, struct.pack("<I", 0)),
        "valuePadding": _corrupt(good, 188 + 22, b"\x01"),
        "supercompressionScheme": _corrupt(good, 44, struct.pack("<I", 2)),
        "too short": good[:60],
    }
    for what, data in cases.items():
        path = tmp_path / "bad.ktx2"
        path.write_bytes(data)
        with pytest.raises(ValueError, match="bad.ktx2") as info:
            read_ktx2(path)
        assert what.split()[0].lower() in str(info.value).lower(), (what, str(info.value))


def test_ktx2_reader_rejects_unsorted_keys():
    good = ktx2_bytes([np.ones((1, 1, 2))], 83, writer_version="9.9")
    kvd_offset, kvd_length = struct.unpack_from("<2I", good, 56)
    swapped = _kvd([(b"KTXwriter", b"pbrkit 9.9\x00"), (b"KTXorientation", b"rd\x00")])
    assert len(swapped) == kvd_length
    with pytest.raises(ValueError, match="sorted"):
        parse_ktx2(_corrupt(good, kvd_offset, swapped))


def test_halfpack_texel_helpers_reject_wrong_channels():
    with pytest.raises(ValueError, match="channel"):
        encode_texels(np.zeros((2, 2, 2)), "b10g11r11", 3)
