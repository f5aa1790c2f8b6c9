"""Babylon.js .env files (pbrkit.io.babylon_env): RGBD, byte layout, round trip,
determinism and refusals.  The layout is checked here with an independent
parser (struct, json, zlib and a plain Python PNG unfilter), not with the
module's own reader."""

import json
import math
import struct
import zlib

import numpy as np
import pytest

from pbrkit.core.errors import InputError
from pbrkit.io.babylon_env import (
    ENV_MAGIC,
    POLYNOMIAL_TERMS,
    env_bytes,
    parse_babylon_env,
    read_babylon_env,
    rgbd_decode,
    rgbd_encode,
    write_babylon_env,
)

MAGIC = bytes([0x86, 0x16, 0x87, 0x96, 0xF6, 0xD6, 0x96, 0x36])  # Babylon's MagicBytes


def chain(n=8, seed=0, top=20.0):
    rng = np.random.default_rng(seed)
    out = []
    while True:
        out.append(rng.uniform(0.0, top, size=(6, n, n, 3)))
        if n == 1:
            return out
        n //= 2


def polynomial(seed=1):
    rng = np.random.default_rng(seed)
    return {t: list(rng.normal(size=3)) for t in POLYNOMIAL_TERMS}


def rgbd_bound(alpha):
    """Largest decode error of one channel: half an 8-bit step of (q/255)^2.2 / D,
    d/dq <= 2.2 / (255 D), D = alpha / 255."""
    return 1.1 / np.asarray(alpha, dtype=np.float64) * (1 + 1e-9)


# ------------------------------------------------------------------- RGBD


def test_rgbd_matches_babylon_formula_by_hand():
    # max 10: D byte = floor(255 / 10) = 25; colour bytes = round(255 (rgb 25/255)^(1/2.2))
    q = rgbd_encode(np.array([10.0, 5.0, 0.0]))
    assert q.dtype == np.uint8
    assert q[3] == 25
    assert q[0] == round(255 * (10 * 25 / 255) ** (1 / 2.2))
    assert q[1] == round(255 * (5 * 25 / 255) ** (1 / 2.2))
    assert q[2] == 0
    # in [0, 1]: D = 1 (byte 255), plain gamma 2.2
    q = rgbd_encode(np.array([0.5, 1.0, 0.25]))
    assert q[3] == 255
    assert list(q[:3]) == [round(255 * v ** (1 / 2.2)) for v in (0.5, 1.0, 0.25)]
    # black: Babylon's maxEps gives D = 255
    assert list(rgbd_encode(np.zeros(3))) == [0, 0, 0, 255]
    # decode is (q/255)^2.2 / (a/255)
    assert rgbd_decode(np.array([255, 128, 0, 51], np.uint8)) == pytest.approx(
        [5.0, (128 / 255) ** 2.2 * 5.0, 0.0], rel=1e-6)


def test_rgbd_round_trip_within_its_quantisation():
    rng = np.random.default_rng(3)
    scale = 10.0 ** rng.uniform(-3, math.log10(255), size=(20000, 1))
    rgb = rng.uniform(0, 1, size=(20000, 3)) * scale
    rgb[::7, 1] = 0.0
    q = rgbd_encode(rgb)
    back = rgbd_decode(q).astype(np.float64)
    err = np.abs(back - rgb)
    bound = rgbd_bound(q[:, 3:])
    assert np.all(err <= bound + 1e-6 * rgb)
    # from 1 up (D < 1), the largest channel keeps better than 1 % relative precision
    m = rgb.max(axis=1)
    big = m >= 1.0
    assert big.sum() > 1000
    assert np.max(np.abs(back.max(axis=1) - m)[big] / m[big]) < 0.0088
    # and the bound is tight enough to mean something: errors reach a good part of it
    assert np.max(err / bound) > 0.3


def test_rgbd_clips_above_255_and_below_0():
    q = rgbd_encode(np.array([1000.0, 300.0, 100.0]))
    assert q[3] == 1
    assert rgbd_decode(q) == pytest.approx([255.0, 255.0, 100.0], rel=0.005)
    q = rgbd_encode(np.array([-1.0, 2.0, 0.0]))
    assert rgbd_decode(q)[0] == 0.0
    with pytest.raises(InputError):
        rgbd_encode(np.array([np.nan, 1.0, 1.0]))
    with pytest.raises(InputError):
        rgbd_encode(np.ones((2, 4)))


# ------------------------------------------------------ byte layout (independent)


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    return a if pa <= pb and pa <= pc else (b if pb <= pc else c)


def _decode_png(data):
    """Minimal independent PNG decoder (8-bit RGBA, any filter), pure Python."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, chunks = 8, []
    while pos < len(data):
        length, tag = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        assert struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])[0] == zlib.crc32(tag + body)
        chunks.append((tag, body))
        pos += 12 + length
    tags = [t for t, _ in chunks]
    assert tags[0] == b"IHDR" and tags[-1] == b"IEND"
    assert set(tags) == {b"IHDR", b"IDAT", b"IEND"}  # no ancillary (time, gamma, colour) chunks
    w, h, depth, ctype, comp, filt, interlace = struct.unpack(">IIBBBBB", chunks[0][1])
    assert (depth, ctype, comp, filt, interlace) == (8, 6, 0, 0, 0)
    raw = zlib.decompress(b"".join(b for t, b in chunks if t == b"IDAT"))
    stride = 4 * w
    out = []
    prev = [0] * stride
    for y in range(h):
        ftype = raw[y * (stride + 1)]
        line = list(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        row = []
        for x in range(stride):
            a = row[x - 4] if x >= 4 else 0
            b = prev[x]
            c = prev[x - 4] if x >= 4 else 0
            pred = [0, a, b, (a + b) // 2, _paeth(a, b, c)][ftype]
            row.append((line[x] + pred) & 255)
        out.append(row)
        prev = row
    return np.array(out, dtype=np.uint8).reshape(h, w, 4)


def test_byte_layout():
    levels = chain(4)
    poly = polynomial()
    data = env_bytes(levels, poly, lod_generation_scale=0.75)
    assert ENV_MAGIC == MAGIC
    assert data[:8] == MAGIC
    nul = data.index(b"\x00", 8)
    text = data[8:nul].decode("ascii")
    # JSON.stringify style: compact, Babylon's key order
    assert ": " not in text and ", " not in text
    manifest = json.loads(text)
    assert list(manifest) == ["version", "width", "imageType", "irradiance", "specular"]
    assert manifest["version"] == 2 and manifest["width"] == 4 and manifest["imageType"] == "image/png"
    assert list(manifest["irradiance"]) == list(POLYNOMIAL_TERMS)
    for t in POLYNOMIAL_TERMS:
        assert manifest["irradiance"][t] == poly[t]  # shortest repr: exact
    spec = manifest["specular"]
    assert list(spec) == ["mipmaps", "lodGenerationScale"] and spec["lodGenerationScale"] == 0.75
    mips = spec["mipmaps"]
    assert len(mips) == 6 * 3
    base = nul + 1
    position = 0
    for i, entry in enumerate(mips):
        assert list(entry) == ["length", "position"]
        assert entry["position"] == position  # back to back, level-major, face-minor
        position += entry["length"]
        m, face = divmod(i, 6)
        image = _decode_png(data[base + entry["position"]:base + entry["position"] + entry["length"]])
        n = 4 >> m
        assert image.shape == (n, n, 4)
        # PNG top row = the face's last row (t = 1): the face upside down
        assert np.array_equal(image, rgbd_encode(levels[m][face])[::-1])
    assert base + position == len(data)


def test_js_number_formatting_in_manifest():
    poly = {t: [1e-7, 2.0, -0.000001] for t in POLYNOMIAL_TERMS}
    data = env_bytes(chain(1), poly)
    text = data[8:data.index(b"\x00", 8)].decode("ascii")
    assert '"x":[1e-7,2,-0.000001]' in text  # JavaScript's Number#toString, not Python's repr
    assert '"lodGenerationScale":0.8' in text
    assert '"width":1,' in text


# ------------------------------------------------------------ round trip


def test_file_round_trip(tmp_path):
    levels = chain(8, top=200.0)
    poly = polynomial()
    path = tmp_path / "sky.env"
    assert write_babylon_env(path, levels, poly) == path
    manifest, back, poly_back = read_babylon_env(path)
    assert manifest["width"] == 8 and manifest["specular"]["lodGenerationScale"] == 0.8
    assert len(back) == 4
    for a, b in zip(levels, back):
        assert b.dtype == np.float32 and b.shape == a.shape
        alpha = rgbd_encode(a)[..., 3:]
        assert np.all(np.abs(b - a) <= rgbd_bound(alpha) + 1e-6 * a)
        # and the reader gives exactly the decode of what was encoded (rows in pbrkit order)
        assert np.array_equal(b, rgbd_decode(rgbd_encode(a)))
    for t in POLYNOMIAL_TERMS:
        assert poly_back[t].tolist() == poly[t]


def test_no_polynomial_round_trip():
    manifest, _, poly = parse_babylon_env(env_bytes(chain(2), None))
    assert manifest["irradiance"] is None and poly is None


def test_deterministic():
    levels = chain(16, seed=5)
    poly = polynomial(7)
    a = env_bytes(levels, poly)
    b = env_bytes([np.array(x) for x in levels], {k: list(v) for k, v in poly.items()})
    assert a == b
    assert env_bytes(chain(16, seed=6), poly) != a


def test_reads_foreign_png_filters_and_version_1():
    """A .env written by someone else (other PNG filters, version 1 manifest)."""
    face = np.full((1, 1, 4), [10, 20, 30, 255], np.uint8)

    def png(img, ftype):
        raw = b"".join(bytes([ftype]) + img[y].tobytes() for y in range(img.shape[0]))  # Sub/Up of a 1x1 = None
        def chunk(tag, body):
            return struct.pack(">I", len(body)) + tag + body + struct.pack(">I", zlib.crc32(tag + body))
        return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 1, 1, 8, 6, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))

    images = [png(face, f) for f in (0, 1, 2, 3, 4, 0)]
    mips, pos = [], 0
    for im in images:
        mips.append({"position": pos, "length": len(im)})
        pos += len(im)
    manifest = {"version": 1, "width": 1, "irradiance": None, "specular": {"mipmaps": mips}}
    data = MAGIC + json.dumps(manifest).encode() + b"\x00" + b"".join(images)
    _, levels, _ = parse_babylon_env(data)
    assert levels[0].shape == (6, 1, 1, 3)
    assert np.allclose(levels[0], rgbd_decode(face)[None], rtol=1e-6)


# ------------------------------------------------------------ refusals


def _one_line_error(data, match):
    with pytest.raises(InputError, match=match) as info:
        parse_babylon_env(data, name="sky.env")
    assert "\n" not in str(info.value) and str(info.value).startswith("sky.env: ")


def test_refuses_corrupt_files():
    good = env_bytes(chain(2), polynomial())
    nul = good.index(b"\x00", 8)
    manifest = json.loads(good[8:nul])
    payload = good[nul + 1:]

    def rebuild(m, body=payload):
        return MAGIC + json.dumps(m).encode() + b"\x00" + body

    _one_line_error(b"\x00" * 8 + good[8:], "bad magic")
    _one_line_error(good[:5], "bad magic")
    _one_line_error(good[:nul], "NUL")
    _one_line_error(MAGIC + b"{not json" + b"\x00", "bad JSON")
    _one_line_error(MAGIC + b"[1,2]\x00", "not an object")
    _one_line_error(good[:-10], "truncated")
    _one_line_error(rebuild(dict(manifest, version=3)), "version")
    _one_line_error(rebuild(dict(manifest, width=3)), "power of two")
    _one_line_error(rebuild(dict(manifest, imageType="image/webp")), "image/png")
    _one_line_error(rebuild(dict(manifest, specular={"mipmaps": manifest["specular"]["mipmaps"][:-6]})),
                    "expected 12")
    _one_line_error(rebuild({k: v for k, v in manifest.items() if k != "specular"}), "specular.mipmaps")
    _one_line_error(rebuild(dict(manifest, width=4)), "expected 18")
    bad_poly = dict(manifest, irradiance=dict(manifest["irradiance"], xy=[1, 2]))
    _one_line_error(rebuild(bad_poly), "'xy'")
    corrupt = bytearray(payload)
    corrupt[40] ^= 0xFF  # inside the first PNG
    _one_line_error(rebuild(manifest, bytes(corrupt)), "level 0 face 0")
    swapped = json.loads(json.dumps(manifest))
    m = swapped["specular"]["mipmaps"]
    m[0], m[6] = m[6], m[0]  # a 1x1 image where a 2x2 belongs
    _one_line_error(rebuild(swapped), "expected 2x2")
    neg = json.loads(json.dumps(manifest))
    neg["specular"]["mipmaps"][2]["position"] = -1
    _one_line_error(rebuild(neg), "non-negative")


def test_read_names_the_file(tmp_path):
    path = tmp_path / "broken.env"
    path.write_bytes(b"nope")
    with pytest.raises(InputError, match="broken.env: not a Babylon.js .env file"):
        read_babylon_env(path)
    with pytest.raises(InputError, match="missing.env: file not found"):
        read_babylon_env(tmp_path / "missing.env")


def test_refuses_bad_input():
    with pytest.raises(InputError, match="full chain"):
        env_bytes(chain(4)[:2], polynomial())
    with pytest.raises(InputError, match="power-of-two"):
        env_bytes([np.ones((6, 3, 3, 3)), np.ones((6, 1, 1, 3))], polynomial())
    with pytest.raises(InputError, match="RGB"):
        env_bytes([np.ones((6, 2, 2, 4)), np.ones((6, 1, 1, 4))], polynomial())
    bad = chain(2)
    bad[1][0, 0, 0, 0] = np.inf
    with pytest.raises(InputError, match="finite"):
        env_bytes(bad, polynomial())
    with pytest.raises(InputError, match="terms"):
        env_bytes(chain(2), {"x": [0, 0, 0]})
    with pytest.raises(InputError, match="'zz'"):
        env_bytes(chain(2), dict(polynomial(), zz=[1, 2]))
    with pytest.raises(InputError, match="lod_generation_scale"):
        env_bytes(chain(2), polynomial(), lod_generation_scale=0)


def test_write_is_atomic_on_bad_input(tmp_path):
    path = tmp_path / "x.env"
    with pytest.raises(InputError):
        write_babylon_env(path, chain(2)[:1], polynomial())
    assert not path.exists() and list(tmp_path.iterdir()) == []
