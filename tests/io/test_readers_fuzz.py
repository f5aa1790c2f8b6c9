"""Property-based fuzzing of the file readers (the "Untrusted input" issue).

For each format pbrkit reads -- Radiance HDR, PFM, OpenEXR, PNG (8- and
16-bit), KTX 1.1, KTX 2.0, DDS and MERL -- a small valid file is made with pbrkit's own writer (by hand
for MERL), Hypothesis mutates it (byte flips, truncation, insertion of bytes
and of a secret text, header integer fields replaced by extreme values) and
the reader reads it back.  The property: either a clean
:class:`~pbrkit.core.errors.InputError` whose message is one line, names the
file and quotes nothing of it, or a result of the shape the file declares
(finite where the format requires it); never another exception; bounded time
(Hypothesis' deadline) and bounded memory: with the memory "available"
(:func:`pbrkit.core.inputs.available_memory`) set to 64 times the file's size
plus 256 KiB, the peak :mod:`tracemalloc` traces while reading stays within
that plus the file's own bytes -- so every allocation a header can cause is
either estimated (and refused) up front or bounded by the file.

Examples that once failed are kept with ``@example``.  The runs are
deterministic (``derandomize``), 150 examples a format (60 for MERL's 35 MB
files); ``PBRKIT_FUZZ_EXAMPLES=5000`` fuzzes longer, with fresh random examples.
"""

from __future__ import annotations

import os
import re
import struct
import tracemalloc
from datetime import timedelta
from unittest import mock

import numpy as np
import pytest
from hypothesis import HealthCheck, event, example, given, settings
from hypothesis import strategies as st

from pbrkit.core.errors import InputError
from pbrkit.io.dds import dds_bytes, read_dds
from pbrkit.io.exr import exr_bytes, read_exr
from pbrkit.io.hdr import hdr_bytes, read_hdr
from pbrkit.io.ktx1 import ktx1_bytes, read_ktx1
from pbrkit.io.ktx2 import ktx2_bytes, read_ktx2
from pbrkit.io.pfm import pfm_bytes, read_pfm
from pbrkit.io.png import png_bytes16, read_ldr
from pbrkit.measured.merl import MERL_SHAPE, read_merl

FIXED = 256 << 10
EXTREMES = [0, 1, 2, 3, 4, 6, 7, 8, 16, 255, 256, 4096, 32768, 60000, 65535, 65536, 2**31 - 1, 2**31,
            2**32 - 1, 2**32, 2**40, 2**63, 2**64 - 1, -1, -60000]
INSERTS = [b"SECRET", b"root:x:0:0:SECRET\n", b"\x00" * 4, b"\xff" * 8, b"\n", b" 99999", b"\x00" * 64]
LONG = int(os.environ.get("PBRKIT_FUZZ_EXAMPLES", "0"))
FUZZ = settings(max_examples=LONG or 150, deadline=timedelta(seconds=5), derandomize=not LONG, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


# ------------------------------------------------------------------ mutations


def mutations(fields):
    """Lists of mutations: ("field", index into ``fields``, value), ("flip", at, mask),
    ("cut", at), ("insert", at, bytes); positions are fractions of the length."""
    at = st.floats(0.0, 1.0, allow_nan=False)
    one = st.one_of(
        st.tuples(st.just("field"), st.integers(0, len(fields) - 1), st.sampled_from(EXTREMES)),
        st.tuples(st.just("flip"), at, st.integers(1, 255)),
        st.tuples(st.just("cut"), at),
        st.tuples(st.just("insert"), at, st.sampled_from(INSERTS)),
    )
    return st.lists(one, min_size=1, max_size=4)


def _pack(fmt, value):
    if fmt == "text":
        return str(value).encode()
    bits = 8 * struct.calcsize(fmt)
    value &= (1 << bits) - 1
    if fmt[-1].islower() and value >= 1 << (bits - 1):
        value -= 1 << bits
    return struct.pack(fmt, value)


def mutate(data, fields, ops):
    """``data`` with the field replacements first (at their offsets in the valid
    file), then the byte mutations in order."""
    data = bytearray(data)
    for op in sorted((op for op in ops if op[0] == "field"), key=lambda op: -fields[op[1]][0]):
        start, fmt, *end = fields[op[1]]
        stop = end[0] if end else start + struct.calcsize(fmt)
        data[start:stop] = _pack(fmt, op[2])
    for op in ops:
        if op[0] == "field":
            continue
        i = min(int(op[1] * len(data)), max(len(data) - 1, 0))
        if op[0] == "flip" and data:
            data[i] ^= op[2]
        elif op[0] == "cut":
            del data[i:]
        elif op[0] == "insert":
            data[i:i] = op[2]
    return bytes(data)


# ------------------------------------------------------------------ the property


def read_fuzzed(read, path, data):
    """``read(path)`` of ``data`` under the property (module doc): the result, or
    None for a clean refusal."""
    path.write_bytes(data)
    budget = 64 * len(data) + FIXED
    tracemalloc.start()
    try:
        with mock.patch("pbrkit.core.inputs.available_memory", lambda: budget):
            try:
                result = read(path)
            except InputError as exc:
                message = str(exc)
                assert "\n" not in message and message.startswith(f"{path}: "), message
                assert "SECRET" not in message and "root:x" not in message and "b'" not in message, message
                event(f"refused: {re.sub(r'[0-9]+', 'N', exc.problem)[:50]}")
                result = None
            else:
                event("read")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak <= budget + len(data), f"traced {peak} bytes reading {len(data)} (budget {budget})"
    return result


def _image_ok(img, channels, finite):
    assert isinstance(img, np.ndarray) and img.dtype == np.float32 and img.ndim == 3
    assert img.shape[0] >= 1 and img.shape[1] >= 1 and img.shape[2] in channels
    if finite:
        assert np.all(np.isfinite(img)) and np.all(img >= 0)


def _levels_ok(levels, width, height, cube, channels):
    for p, level in enumerate(levels):
        w, h = max(1, width >> p), max(1, height >> p)
        assert level.shape == ((6, h, w) if cube else (h, w)) + (channels,), (p, level.shape)
        assert level.dtype == np.float32


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz")


def _rng_image(h, w, c, seed=0):
    return np.random.default_rng(seed).uniform(0.01, 4.0, (h, w, c)).astype(np.float32)


# ------------------------------------------------------------------ Radiance HDR


def _text_fields(data, pattern):
    """(start, "text", end) of each number the regex ``pattern`` matches in ``data``."""
    m = re.search(pattern, data)
    return [(m.start(g), "text", m.end(g)) for g in range(1, m.lastindex + 1)]


HDR = {rle: hdr_bytes(_rng_image(5, 12, 3), rle=rle) for rle in (False, True)}
HDR_FIELDS = {rle: _text_fields(data, rb"\n\n-Y (\d+) \+X (\d+)\n") for rle, data in HDR.items()}


@pytest.fixture(scope="module")
def hdr_compiled(folder):
    """The RGBE decoder compiled (Numba) before anything is traced."""
    for rle, data in HDR.items():
        (folder / "valid.hdr").write_bytes(data)
        assert read_hdr(folder / "valid.hdr").shape == (5, 12, 3)


@FUZZ
@given(rle=st.booleans(), ops=mutations(HDR_FIELDS[False]))
@example(rle=False, ops=[("field", 1, 60000)])
@example(rle=True, ops=[("field", 0, 32768), ("field", 1, 32768)])
@example(rle=False, ops=[("field", 0, 4096)])
def test_hdr(folder, hdr_compiled, rle, ops):
    img = read_fuzzed(read_hdr, folder / "f.hdr", mutate(HDR[rle], HDR_FIELDS[rle], ops))
    if img is not None:
        _image_ok(img, (3,), finite=True)


# ------------------------------------------------------------------ PFM

PFM = {(c, le): pfm_bytes(_rng_image(5, 7, c), little_endian=le) for c in (1, 3) for le in (True, False)}
PFM_FIELDS = {k: _text_fields(data, rb"^P[Ff]\n(\d+) (\d+)\n(-?[\d.]+)\n") for k, data in PFM.items()}


@FUZZ
@given(key=st.sampled_from(sorted(PFM)), ops=mutations(PFM_FIELDS[(1, True)]))
@example(key=(3, True), ops=[("field", 0, 60000), ("field", 1, 2)])
def test_pfm(folder, key, ops):
    img = read_fuzzed(read_pfm, folder / "f.pfm", mutate(PFM[key], PFM_FIELDS[key], ops))
    if img is not None:
        _image_ok(img, (1, 3), finite=False)


# ------------------------------------------------------------------ OpenEXR


def _exr_fields(data):
    """Offsets of the integer fields of an OpenEXR header: every attribute's size,
    the box2i corners, the chlist's pixel types and samplings, the compression
    byte, then the first entries of the chunk offset table and the first chunk's
    y and size (OpenEXR "File Layout")."""
    fields, pos = [], 8
    while data[pos] != 0:
        name_end = data.index(b"\x00", pos)
        type_end = data.index(b"\x00", name_end + 1)
        kind = data[name_end + 1:type_end]
        size_at = type_end + 1
        (size,) = struct.unpack_from("<i", data, size_at)
        fields.append((size_at, "<i"))
        value = size_at + 4
        if kind == b"box2i":
            fields += [(value + 4 * k, "<i") for k in range(4)]
        elif kind == b"compression":
            fields.append((value, "<B"))
        elif kind == b"chlist":
            p = value
            while data[p] != 0:
                p = data.index(b"\x00", p) + 1
                fields += [(p, "<i"), (p + 8, "<i"), (p + 12, "<i")]
                p += 16
        pos = value + size
    table = pos + 1
    (first,) = struct.unpack_from("<Q", data, table)
    return fields + [(table, "<Q"), (table + 8, "<Q"), (first, "<i"), (first + 4, "<i")]


EXR = {(comp, half): exr_bytes(_rng_image(20, 9, 3, seed=1), half=half, compression=comp)
       for comp in ("none", "zip", "piz", "rle") for half in (False, True)}
EXR_FIELDS = {k: _exr_fields(data) for k, data in EXR.items()}


@FUZZ
@given(key=st.sampled_from(sorted(EXR)), ops=mutations(EXR_FIELDS[("none", False)]))
def test_exr(folder, key, ops):
    fields = EXR_FIELDS[key]
    ops = [op if op[0] != "field" else (op[0], op[1] % len(fields), op[2]) for op in ops]
    img = read_fuzzed(read_exr, folder / "f.exr", mutate(EXR[key], fields, ops))
    if img is not None:
        _image_ok(img, (1, 3), finite=False)


# ------------------------------------------------------------------ PNG


def _png8(image):
    import imageio.v3 as iio

    return iio.imwrite("<bytes>", (np.clip(image, 0, 1) * 255).astype(np.uint8), extension=".png")


PNG = {16: png_bytes16(_rng_image(6, 9, 3, seed=4) / 4), 8: _png8(_rng_image(6, 9, 3, seed=4) / 4)}
# IHDR (big-endian): width, height, bit depth, colour type, interlace; the IDAT chunk's length
PNG_FIELDS = [(16, ">I"), (20, ">I"), (24, ">B"), (25, ">B"), (28, ">B"), (33, ">I")]


@FUZZ
@given(bits=st.sampled_from([8, 16]), ops=mutations(PNG_FIELDS))
@example(bits=16, ops=[("field", 0, 60000), ("field", 1, 30000)])
@example(bits=8, ops=[("field", 0, 30000), ("field", 1, 30000)])
def test_png(folder, png_compiled, bits, ops):
    img = read_fuzzed(read_ldr, folder / "f.png", mutate(PNG[bits], PNG_FIELDS, ops))
    if img is not None:
        _image_ok(img, (1, 3), finite=True)


@pytest.fixture(scope="module")
def png_compiled(folder):
    """The PNG unfiltering kernel compiled (Numba) before anything is traced."""
    for data in PNG.values():
        (folder / "valid.png").write_bytes(data)
        assert read_ldr(folder / "valid.png").shape == (6, 9, 3)


# ------------------------------------------------------------------ KTX 2.0, DDS, KTX 1.1


def _chain(n, levels, channels, cube, seed=2):
    rng = np.random.default_rng(seed)
    shape = (lambda m: (6, m, m, channels)) if cube else (lambda m: (m, 2 * m, channels))
    return [rng.uniform(0, 2, shape(max(1, n >> p))).astype(np.float32) for p in range(levels)]


KTX2 = {
    ("R16G16B16A16_SFLOAT", False): ktx2_bytes(_chain(4, 3, 4, False), "R16G16B16A16_SFLOAT"),
    ("B10G11R11_UFLOAT_PACK32", True): ktx2_bytes(_chain(4, 3, 3, True), "B10G11R11_UFLOAT_PACK32", cube=True),
    ("R32G32B32A32_SFLOAT", True): ktx2_bytes(_chain(2, 2, 4, True), "R32G32B32A32_SFLOAT", cube=True),
}
# header (9 UInt32), index (4 UInt32, 2 UInt64), the level index (3 levels of 3 UInt64)
KTX2_FIELDS = ([(12 + 4 * i, "<I") for i in range(13)] + [(64, "<Q"), (72, "<Q")]
               + [(80 + 8 * i, "<Q") for i in range(6)])


@FUZZ
@given(key=st.sampled_from(sorted(KTX2)), ops=mutations(KTX2_FIELDS))
@example(key=("R16G16B16A16_SFLOAT", False), ops=[("field", 2, 60000), ("field", 3, 60000)])
def test_ktx2(folder, key, ops):
    result = read_fuzzed(read_ktx2, folder / "f.ktx2", mutate(KTX2[key], KTX2_FIELDS, ops))
    if result is not None:
        header, levels, _ = result
        channels = 3 if "B10G11R11" in header["formatName"] else 4
        assert len(levels) == max(1, header["levelCount"])
        _levels_ok(levels, header["pixelWidth"], header["pixelHeight"], header["faceCount"] == 6, channels)


DDS = {
    ("R16G16B16A16_FLOAT", False): dds_bytes(_chain(4, 3, 4, False), "R16G16B16A16_FLOAT"),
    ("R11G11B10_FLOAT", True): dds_bytes(_chain(4, 3, 3, True), "R11G11B10_FLOAT", cube=True),
    ("R32_FLOAT", False): dds_bytes(_chain(4, 2, 1, False), "R32_FLOAT"),
}
# DDS_HEADER fields (dwSize .. dwMipMapCount, ddspf, caps) and the DX10 header
DDS_FIELDS = [(4 + 4 * i, "<I") for i in range(7)] + [(76 + 4 * i, "<I") for i in range(2)] \
    + [(108 + 4 * i, "<I") for i in range(2)] + [(128 + 4 * i, "<I") for i in range(5)]


@FUZZ
@given(key=st.sampled_from(sorted(DDS)), ops=mutations(DDS_FIELDS))
@example(key=("R32_FLOAT", False), ops=[("field", 2, 60000), ("field", 3, 60000)])
def test_dds(folder, key, ops):
    result = read_fuzzed(read_dds, folder / "f.dds", mutate(DDS[key], DDS_FIELDS, ops))
    if result is not None:
        header, levels = result
        channels = {"R16G16B16A16_FLOAT": 4, "R11G11B10_FLOAT": 3, "R32_FLOAT": 1}.get(header["formatName"])
        if channels is not None:
            _levels_ok(levels, header["dwWidth"], header["dwHeight"], header["miscFlag"] & 4 == 4, channels)


KTX1 = {
    ("RGBA16F", False): ktx1_bytes(_chain(4, 3, 4, False), "RGBA16F", key_values={"pbrkit": "x"}),
    ("R11F_G11F_B10F", True): ktx1_bytes(_chain(4, 3, 3, True), "R11F_G11F_B10F", cube=True,
                                         key_values={"sh": b"1 2 3\n"}),
}
KTX1_FIELDS = [(12 + 4 * i, "<I") for i in range(13)] + [(64, "<I"), (68, "<I")]


@FUZZ
@given(key=st.sampled_from(sorted(KTX1)), ops=mutations(KTX1_FIELDS))
@example(key=("RGBA16F", False), ops=[("field", 6, 60000), ("field", 7, 60000)])
def test_ktx1(folder, key, ops):
    result = read_fuzzed(read_ktx1, folder / "f.ktx", mutate(KTX1[key], KTX1_FIELDS, ops))
    if result is not None:
        info, levels, _ = result
        channels = 4 if info["formatName"] == "RGBA16F" else 3
        assert len(levels) == info["levelCount"]
        _levels_ok(levels, info["pixelWidth"], info["pixelHeight"], info["cube"], channels)


# ------------------------------------------------------------------ MERL


@pytest.fixture(scope="module")
def merl_file():
    """A MERL file by hand (module doc of pbrkit.measured.merl): the int32 header
    (90, 90, 180), then 3 x 1458000 float64 values, some negative (missing)."""
    values = np.random.default_rng(3).uniform(-0.1, 2.0, 3 * int(np.prod(MERL_SHAPE)))
    return struct.pack("<3i", *MERL_SHAPE) + values.astype("<f8").tobytes()


MERL_FIELDS = [(0, "<i"), (4, "<i"), (8, "<i")]


@pytest.mark.slow
@settings(FUZZ, max_examples=LONG or 60, deadline=timedelta(seconds=10))
@given(ops=mutations(MERL_FIELDS))
@example(ops=[("field", 2, 360)])
@example(ops=[("insert", 0.5, b"\x00" * 8)])
def test_merl(folder, merl_file, ops):
    result = read_fuzzed(read_merl, folder / "f.binary", mutate(merl_file, MERL_FIELDS, ops))
    if result is not None:
        assert result.table.shape == (3,) + MERL_SHAPE and np.all(np.isfinite(result.table))
