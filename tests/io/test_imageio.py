"""Image reading and writing (pbrkit.io.images).

Decoders are checked against hand-built files whose bytes follow the format
specifications (Radiance RGBE, PFM, PNG), writers by round trips with their
stated error bounds, and the real maps in shared/data against the peak
luminances listed in shared/data/SOURCES.md (measured independently).
"""

from __future__ import annotations

import struct
import warnings
from pathlib import Path

import numpy as np
import pytest
from skips import needs_shared_data

from pbrkit.core.color import linear_to_srgb, srgb_to_linear
from pbrkit.core.errors import InputError
from pbrkit.io.exr import read_exr, write_exr
from pbrkit.io.hdr import hdr_bytes, read_hdr, write_hdr
from pbrkit.io.image_checks import LDRInputWarning
from pbrkit.io.images import read_image, read_image_with_notes, write_image
from pbrkit.io.pfm import read_pfm, write_pfm
from pbrkit.io.png import write_png

DATA = Path(__file__).resolve().parents[3] / "shared" / "data"
ENV = DATA / "env"
needs_data = needs_shared_data("env")


def hdr_header(res=b"-Y 2 +X 3", extra=b""):
    return b"#?RADIANCE\n" + extra + b"FORMAT=32-bit_rle_rgbe\n\n" + res + b"\n"


# ------------------------------------------------------------------- sRGB


def test_srgb_transfer_known_values():
    # IEC 61966-2-1: 0.5 -> ((0.555)/1.055)^2.4; breakpoints 0.04045 <-> 0.0031308
    assert srgb_to_linear(0.5) == pytest.approx((0.555 / 1.055) ** 2.4, rel=1e-15)
    assert srgb_to_linear(0.04045) == pytest.approx(0.04045 / 12.92, rel=1e-15)
    assert srgb_to_linear([0.0, 1.0]) == pytest.approx([0.0, 1.0], abs=1e-15)
    assert linear_to_srgb(0.0031308) == pytest.approx(0.0031308 * 12.92, rel=1e-12)
    x = np.linspace(0, 1, 1001)
    assert np.allclose(srgb_to_linear(linear_to_srgb(x)), x, atol=1e-12)
    # the two branches meet (continuity within 1e-7 at the breakpoint)
    assert abs(1.055 * 0.0031308 ** (1 / 2.4) - 0.055 - 12.92 * 0.0031308) < 1e-7


# ------------------------------------------------------------ Radiance RGBE


def test_hdr_decoding_rule_on_hand_built_flat_file(tmp_path):
    # Radiance colrval: ldexp(m + 0.5, e - 136); e = 0 is black
    pixels = [(128, 64, 0, 129), (255, 0, 10, 136), (0, 0, 0, 0),
              (200, 100, 50, 120), (1, 2, 3, 0), (128, 128, 128, 128)]
    path = tmp_path / "flat.hdr"
    path.write_bytes(hdr_header() + bytes(np.array(pixels, np.uint8).ravel()))
    img = read_hdr(path)
    expected = np.array([[m + 0.5 for m in p[:3]] for p in pixels]) * np.array(
        [2.0 ** (p[3] - 136) if p[3] else 0.0 for p in pixels])[:, None]
    assert img.dtype == np.float32 and img.shape == (2, 3, 3)
    assert np.array_equal(img.reshape(-1, 3), expected.astype(np.float32))
    assert img[0, 0, 0] == np.float32(128.5 / 128)


def test_hdr_new_style_rle_hand_built(tmp_path):
    width = 10
    # each plane: a run of 6 (134, v) then a literal of 4
    planes = [(7, [1, 2, 3, 4]), (9, [5, 6, 7, 8]), (11, [9, 10, 11, 12]), (130, [131, 132, 133, 134])]
    body = bytes([2, 2, 0, width])
    for run_value, literal in planes:
        body += bytes([128 + 6, run_value, 4] + literal)
    path = tmp_path / "rle.hdr"
    path.write_bytes(hdr_header(b"-Y 1 +X 10") + body)
    img = read_hdr(path)
    rgbe = np.array([[p[0]] * 6 + p[1] for p in planes]).T  # (10, 4)
    expected = (rgbe[:, :3] + 0.5) * np.ldexp(1.0, rgbe[:, 3] - 136)[:, None]
    assert np.array_equal(img[0], expected.astype(np.float32))


def test_hdr_old_style_run(tmp_path):
    # (1, 1, 1, n) repeats the previous pixel n times (Radiance oldreadcolrs)
    body = bytes([100, 50, 25, 130, 1, 1, 1, 3, 10, 20, 30, 131])
    path = tmp_path / "old.hdr"
    path.write_bytes(hdr_header(b"-Y 1 +X 5") + body)
    img = read_hdr(path)[0]
    first = (np.array([100, 50, 25]) + 0.5) * 2.0 ** -6
    assert np.array_equal(img[:4], np.tile(first, (4, 1)).astype(np.float32))
    assert np.array_equal(img[4], ((np.array([10, 20, 30]) + 0.5) * 2.0 ** -5).astype(np.float32))


@pytest.mark.parametrize("res, flip", [(b"+Y 2 +X 3", "rows"), (b"-Y 2 -X 3", "cols"),
                                       (b"+X 3 -Y 2", "transpose")])
def test_hdr_orientations(tmp_path, res, flip):
    codes = np.arange(6, dtype=np.uint8) * 20 + 10
    rgbe = np.zeros((6, 4), np.uint8)
    rgbe[:, 0] = codes
    rgbe[:, 3] = 136  # value = code + 0.5
    path = tmp_path / "o.hdr"
    path.write_bytes(hdr_header(res) + rgbe.tobytes())
    img = read_hdr(path)[..., 0] - 0.5
    stream = codes.astype(float)
    if flip == "rows":  # scanlines bottom to top
        expected = stream.reshape(2, 3)[::-1]
    elif flip == "cols":  # pixels right to left
        expected = stream.reshape(2, 3)[:, ::-1]
    else:  # scanlines are columns, left to right, each top to bottom
        expected = stream.reshape(3, 2).T
    assert np.array_equal(img, expected)


@pytest.mark.parametrize("rle", [True, False])
def test_hdr_round_trip_error_bound(tmp_path, rle):
    rng = np.random.default_rng(7)
    img = np.exp(rng.uniform(-8, 10, size=(9, 40, 3))).astype(np.float32)
    img[2, 5:30] = 3.25  # a run for the RLE coder
    img[3, :] = 0.0
    path = tmp_path / "rt.hdr"
    write_hdr(path, img, rle=rle)
    back = read_hdr(path)
    peak = img.max(axis=-1, keepdims=True)
    # truncated 8-bit mantissa, decoded at the bucket centre: error <= peak / 256
    assert np.all(np.abs(back - img) <= peak / 256 * (1 + 1e-6))
    assert np.all(back[3] == 0)
    assert hdr_bytes(img, rle=rle) == path.read_bytes()  # deterministic


def test_hdr_rle_is_smaller_and_decodes_the_same(tmp_path):
    img = np.ones((4, 300, 3), np.float32)
    img[:, 100:] = 2.0
    img[:, 7] = [0.1, 0.2, 0.3]
    assert len(hdr_bytes(img, rle=True)) < len(hdr_bytes(img, rle=False)) / 10
    write_hdr(tmp_path / "r.hdr", img, rle=True)
    write_hdr(tmp_path / "f.hdr", img, rle=False)
    assert np.array_equal(read_hdr(tmp_path / "r.hdr"), read_hdr(tmp_path / "f.hdr"))


def test_hdr_writer_rejects_bad_values(tmp_path):
    with pytest.raises(ValueError, match="non-finite"):
        write_hdr(tmp_path / "x.hdr", np.full((2, 2, 3), np.nan))
    with pytest.raises(ValueError, match="too large"):
        write_hdr(tmp_path / "x.hdr", np.full((2, 2, 3), 1e39))
    assert not list(tmp_path.iterdir())


def _bad(path, data):
    path.write_bytes(data)
    return path


@pytest.mark.parametrize("name, data, message", [
    ("trunc.hdr", None, "truncated RGBE pixel data"),
    ("garbage.hdr", b"\x00\x01garbage bytes here" * 10, "not a valid HDR file"),
    ("nohead.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n", "truncated Radiance header"),
    ("badres.hdr", b"#?RADIANCE\n\n-Y two +X 3\n", "corrupt Radiance resolution line"),
    ("zero.hdr", b"#?RADIANCE\n\n-Y 0 +X 0\n", "is empty"),
    ("huge.hdr", b"#?RADIANCE\n\n-Y 40000 +X 80000\n", "exceeds the 32768-pixel limit"),
    ("xyze.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n\0\0\0\0", "XYZE"),
    ("rlelen.hdr", hdr_header(b"-Y 1 +X 10") + bytes([2, 2, 0, 9]) + bytes(40), "corrupt RGBE run-length"),
    ("overrun.hdr", hdr_header(b"-Y 1 +X 10") + bytes([2, 2, 0, 10, 128 + 20, 1]) + bytes(40),
     "corrupt RGBE run-length"),
    ("empty.hdr", b"", "file is empty"),
])
def test_hdr_errors(tmp_path, name, data, message):
    if data is None:
        full = hdr_bytes(np.random.default_rng(1).random((16, 32, 3)))
        data = full[: len(full) - 200]
    path = _bad(tmp_path / name, data)
    with pytest.raises(InputError, match=message) as err:
        read_image(path)
    assert str(err.value).startswith(str(path) + ": ") and "\n" not in str(err.value)


def test_missing_and_directory(tmp_path):
    with pytest.raises(InputError, match="file not found"):
        read_image(tmp_path / "nope.exr")
    with pytest.raises(InputError, match="directory"):
        read_image(tmp_path)


# -------------------------------------------------------------------- EXR


def test_exr_round_trip_float_and_half(tmp_path):
    rng = np.random.default_rng(3)
    img = (rng.random((7, 12, 3)) * 100).astype(np.float32)
    write_exr(tmp_path / "f.exr", img)
    assert np.array_equal(read_exr(tmp_path / "f.exr"), img)
    write_exr(tmp_path / "h.exr", img, half=True, compression="piz")
    assert np.array_equal(read_exr(tmp_path / "h.exr"), img.astype(np.float16).astype(np.float32))
    first = (tmp_path / "f.exr").read_bytes()
    write_exr(tmp_path / "f.exr", img)
    assert (tmp_path / "f.exr").read_bytes() == first  # deterministic


def test_exr_grey_alpha_and_channels(tmp_path):
    grey = np.linspace(0, 1, 20, dtype=np.float32).reshape(4, 5)
    write_exr(tmp_path / "y.exr", grey)
    assert np.array_equal(read_exr(tmp_path / "y.exr")[..., 0], grey)
    rgba = np.random.default_rng(0).random((3, 4, 4)).astype(np.float32)
    write_exr(tmp_path / "a.exr", rgba)
    img, fmt, notes = read_image_with_notes(tmp_path / "a.exr")
    assert fmt == "exr" and np.array_equal(img, rgba[..., :3]) and "alpha ignored" in notes  # pbrkit.io.image_checks.ALPHA_IGNORED


def test_exr_errors(tmp_path):
    import OpenEXR

    z = OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage},
                     {"Z": np.zeros((2, 3), np.float32)})
    z.write(str(tmp_path / "z.exr"))
    with pytest.raises(InputError, match="no R, G, B"):
        read_image(tmp_path / "z.exr")
    write_exr(tmp_path / "ok.exr", np.ones((64, 64, 3), np.float32))
    data = (tmp_path / "ok.exr").read_bytes()
    _bad(tmp_path / "trunc.exr", data[: len(data) // 3])
    with pytest.raises(InputError, match="corrupt or truncated OpenEXR"):
        read_image(tmp_path / "trunc.exr")
    _bad(tmp_path / "garbage.exr", b"\x76\x2f\x31\x01" + b"\xff" * 64)
    with pytest.raises(InputError, match="OpenEXR"):
        read_image(tmp_path / "garbage.exr")
    with pytest.raises(ValueError, match="float16 range"):
        write_exr(tmp_path / "big.exr", np.full((2, 2, 3), 1e5), half=True)


# -------------------------------------------------------------------- PFM


def test_pfm_byte_order_and_row_order_hand_built(tmp_path):
    # Debevec's PFM: rows stored bottom to top; negative scale = little endian
    rows = np.array([[[1, 2, 3], [4, 5, 6]], [[7, 8, 9], [10, 11, 12]]], dtype=np.float32)  # top, bottom
    little = b"PF\n2 2\n-1.0\n" + rows[::-1].astype("<f4").tobytes()
    big = b"PF\n2 2\n1.0\n" + rows[::-1].astype(">f4").tobytes()
    assert np.array_equal(read_pfm(_bad(tmp_path / "l.pfm", little)), rows)
    assert np.array_equal(read_pfm(_bad(tmp_path / "b.pfm", big)), rows)
    grey = b"Pf\n3 1\n-1\n" + np.array([1, 2, 3], "<f4").tobytes()
    assert np.array_equal(read_pfm(_bad(tmp_path / "g.pfm", grey))[..., 0], [[1, 2, 3]])


@pytest.mark.parametrize("little", [True, False])
def test_pfm_round_trip(tmp_path, little):
    img = np.random.default_rng(5).normal(size=(5, 6, 3)).astype(np.float32)
    write_pfm(tmp_path / "x.pfm", img, little_endian=little)
    assert np.array_equal(read_pfm(tmp_path / "x.pfm"), img)


@pytest.mark.parametrize("data, message", [
    (b"PF\n4 4\n-1.0\n" + bytes(20), "truncated PFM data"),
    (b"PF\nfour 4\n-1.0\n", "corrupt or truncated PFM header"),
    (b"PF\n0 0\n-1.0\n", "is empty"),
    (b"PF\n2 2\n0.0\n" + bytes(48), "scale"),
    (b"PF\n99999 2\n-1.0\n", "exceeds"),
])
def test_pfm_errors(tmp_path, data, message):
    with pytest.raises(InputError, match=message):
        read_image(_bad(tmp_path / "bad.pfm", data))


# ------------------------------------------------------------ PNG and JPEG


@pytest.mark.parametrize("bits", [8, 16])
def test_png_write_read(tmp_path, bits):
    rng = np.random.default_rng(2)
    img = rng.random((6, 9, 3))
    path = tmp_path / f"p{bits}.png"
    write_png(path, img, bits=bits)
    scale = (1 << bits) - 1
    codes = np.rint(linear_to_srgb(img) * scale)
    with pytest.warns(LDRInputWarning, match="low-dynamic-range"):
        back = read_image(path)
    assert np.allclose(back, srgb_to_linear(codes / scale), atol=1e-7)
    # independent check of the stored codes through Pillow (8 bits) or the raw bytes (16 bits)
    if bits == 8:
        import imageio.v3 as iio

        assert np.array_equal(iio.imread(path), codes.astype(np.uint8))
    else:
        assert path.read_bytes()[24:26] == bytes([16, 2])  # IHDR bit depth 16, colour type RGB


def test_png16_linear_grey_codes(tmp_path):
    import imageio.v3 as iio

    x = np.linspace(0, 1, 12).reshape(3, 4)
    write_png(tmp_path / "g.png", x, bits=16, srgb=False)
    codes = iio.imread(tmp_path / "g.png")  # Pillow reads 16-bit grey exactly
    assert codes.dtype == np.uint16 and np.array_equal(codes, np.rint(x * 65535).astype(np.uint16))
    assert b"sRGB" not in (tmp_path / "g.png").read_bytes()
    write_png(tmp_path / "s.png", x, bits=16)
    assert np.array_equal(iio.imread(tmp_path / "s.png"), np.rint(linear_to_srgb(x) * 65535))


def test_png16_decoder_filters(tmp_path):
    # hand-built 16-bit RGB PNG using all five filter types (ISO/IEC 15948 sec. 9.2)
    import zlib

    rng = np.random.default_rng(4)
    img = rng.integers(0, 65536, size=(5, 4, 3), dtype=np.uint16)
    raw = img.astype(">u2").reshape(5, -1).view(np.uint8).astype(np.int64)
    bpp = 6
    lines = []
    for y, ftype in enumerate([0, 1, 2, 3, 4]):
        cur = raw[y]
        prev = raw[y - 1] if y else np.zeros_like(cur)
        out = []
        for x in range(cur.size):
            a = cur[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            pred = [0, a, b, (a + b) // 2, None][ftype]
            if ftype == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            out.append((cur[x] - pred) % 256)
        lines.append(bytes([ftype] + out))

    def chunk(tag, body):
        return struct.pack(">I", len(body)) + tag + body + struct.pack(">I", zlib.crc32(tag + body))

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 4, 5, 16, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(b"".join(lines))) + chunk(b"IEND", b""))
    path = _bad(tmp_path / "f.png", png)
    with pytest.warns(LDRInputWarning):
        back = read_image(path)
    assert np.allclose(back, srgb_to_linear(img / 65535.0), atol=1e-7)


def test_jpeg_reads_with_warning(tmp_path):
    import imageio.v3 as iio

    iio.imwrite(tmp_path / "x.jpg", np.full((8, 8, 3), 128, np.uint8), extension=".jpg", quality=100)
    with pytest.warns(LDRInputWarning):
        img = read_image(tmp_path / "x.jpg")
    assert np.allclose(img, srgb_to_linear(128 / 255), atol=2e-3)


def test_png_corrupt(tmp_path):
    write_png(tmp_path / "ok.png", np.ones((32, 32, 3)) * 0.5)
    data = (tmp_path / "ok.png").read_bytes()
    with pytest.raises(InputError, match="PNG"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        read_image(_bad(tmp_path / "t.png", data[:40]))


def test_atomic_write_leaves_nothing_on_failure(tmp_path, monkeypatch):
    target = tmp_path / "keep.png"
    write_png(target, np.zeros((2, 2, 3)), bits=16)
    before = target.read_bytes()

    def boom(*args, **kwargs):
        raise RuntimeError("disk full")

    import pbrkit.io.png as png_module

    monkeypatch.setattr(png_module, "_png_bytes16", boom)
    with pytest.raises(RuntimeError):
        write_png(target, np.ones((2, 2, 3)), bits=16)
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.png"]


def test_write_image_dispatch(tmp_path):
    img = np.random.default_rng(0).random((4, 8, 3)).astype(np.float32)
    for suffix in (".exr", ".pfm"):
        write_image(tmp_path / f"x{suffix}", img)
        assert np.array_equal(read_image(tmp_path / f"x{suffix}"), img)
    with pytest.raises(ValueError, match="suffix"):
        write_image(tmp_path / "x.tif", img)


# -------------------------------------------------------------- real data


@needs_data
@pytest.mark.parametrize("name, peak, negatives", [
    ("rooitou_park_1k.hdr", 65000, 0), ("kloofendal_overcast_1k.hdr", 5.9, 0),
    ("studio_small_03_1k.hdr", 3350, 0), ("venice_sunset_1k.exr", 2100, 0),
    ("potsdamer_platz_1k.hdr", 11, 0), ("moonless_golf_1k_blender_night.exr", 6450, 250),
])
def test_real_maps_match_sources(name, peak, negatives):
    img = read_image(ENV / name)
    assert img.shape == (512, 1024, 3) and img.dtype == np.float32 and np.all(np.isfinite(img))
    luminance = img.astype(np.float64) @ [0.2126, 0.7152, 0.0722]  # Rec. 709
    assert luminance.max() == pytest.approx(peak, rel=0.03)
    assert int((img < 0).sum()) == negatives
