"""Babylon.js ``.env`` environment files: an RGBD-PNG cube chain with its
spherical polynomial, written and read the way Babylon.js's own tools do.

Written from Babylon.js 9.35.0 (``Misc/environmentTextureTools.pure.ts``,
``EnvironmentTextureTools``: ``GetEnvInfo``, ``CreateEnvTextureAsync``,
``CreateRadianceImageDataArrayBufferViews``, ``UploadEnvLevelsAsync``,
``UploadEnvSpherical``) and its RGBD helpers (``toRGBD`` / ``fromRGBD`` in
``Shaders/ShadersInclude/helperFunctions``, ``Misc/rgbdTextureTools.ts``);
read to learn the layout, nothing copied.  The file is::

    magic      0x86 0x16 0x87 0x96 0xF6 0xD6 0x96 0x36             8 bytes
    manifest   JSON (ASCII), as JavaScript's JSON.stringify writes it,
               then one NUL byte
    payload    the images; every ``position`` in the manifest counts
               from the byte after the NUL

Manifest, version 2 (keys in Babylon's order)::

    {"version":2,"width":N,"imageType":"image/png",
     "irradiance":{"x":[r,g,b],"y":..,"z":..,"xx":..,"yy":..,"zz":..,
                   "yz":..,"zx":..,"xy":..},            (or null)
     "specular":{"mipmaps":[{"length":L,"position":P}, ...],
                 "lodGenerationScale":0.8}}

``irradiance`` is Babylon's ``SphericalPolynomial``
(:func:`pbrkit.ibl.sh.babylon_polynomial`).  ``mipmaps`` lists 6 (log2 N + 1)
images, level-major and face-minor (level 0 +X, -X, +Y, -Y, +Z, -Z, level 1
...): Babylon's reader refuses any other count, so the chain always goes
down to 1 x 1.  A version 1 manifest (no ``imageType``) means PNG.

Each image is an 8-bit RGBA PNG in **RGBD**: for linear ``rgb`` with largest
channel m, the divisor byte is ``a = clamp(floor(255 / m), 1, 255)`` and the
colour bytes are ``round(255 * clamp((rgb * a / 255) ** (1 / 2.2), 0, 1))``
(Babylon's default ``toGammaSpace``, a 2.2 power; an engine created with
``useExactSrgbConversions`` decodes with the sRGB curve instead and would
read these files slightly wrong).  Decoding is ``(rgb8 / 255) ** 2.2 /
(a / 255)``.  Values up to 255 are stored with about 0.5 % relative error on
the largest channel; **above 255 each channel is clipped to 255** (the
divisor bottoms out at 1/255), exactly as Babylon's encoder does, and
negative values are clipped to 0.  Values in [0, 1] get a = 255, i.e. plain
8-bit gamma-2.2 (coarse near black: below about 1e-5 everything is 0).

Row order: Babylon uploads each PNG with a y flip before rendering it into
its cube face, so the PNG's **top row is the face's last row** (t = 1);
pbrkit's faces (row 0 = t = 0, CONVENTIONS.md "Cube maps") are therefore
stored upside down.  This was confirmed inside Babylon.js (the face texels
read back from a loaded file, ``tests/engines/test_engine_babylon.py``).

The PNGs are written deterministically: 8-bit RGBA, no ancillary chunks
(no gamma or colour chunks, so browsers apply no colour conversion, and no
timestamps), the Paeth filter on every row and zlib level 6.

The reader takes the file as untrusted input (:mod:`pbrkit.io.containers`):
only a regular file is read; every image must lie inside the file and its PNG
header must declare the face size of its level before anything is
decompressed, decompression is bounded by that size (:func:`pbrkit.io.png.inflate_bounded`),
the memory of the decoded chain is checked first, and no message quotes the
manifest or the images.
"""

from __future__ import annotations

import json
import math
import struct
import zlib
from decimal import Decimal

import numpy as np

from ..core.atomic import write_bytes
from ..core.errors import InputError
from ..core.inputs import check_allocation
from .containers import read_container, validate_levels
from .png import PNG_SIGNATURE, _png_unfilter, inflate_bounded, png_file_bytes

__all__ = [
    "ENV_MAGIC",
    "POLYNOMIAL_TERMS",
    "RGBD_MAX",
    "env_bytes",
    "parse_babylon_env",
    "read_babylon_env",
    "rgbd_decode",
    "rgbd_encode",
    "write_babylon_env",
]

#: The 8 bytes every Babylon.js ``.env`` file starts with.
ENV_MAGIC = bytes([0x86, 0x16, 0x87, 0x96, 0xF6, 0xD6, 0x96, 0x36])
#: Babylon's SphericalPolynomial terms, in the manifest's order.
POLYNOMIAL_TERMS = ("x", "y", "z", "xx", "yy", "zz", "yz", "zx", "xy")
#: Largest value RGBD can store; larger channels are clipped to it.
RGBD_MAX = 255.0
_GAMMA = 2.2  # Babylon's LinearEncodePowerApprox
_EPSILON = 1e-7  # Babylon's maxEps
_VERSION = 2
_IMAGE_TYPE = "image/png"
_ZLIB_LEVEL = 3


# ----------------------------------------------------------------- RGBD


def rgbd_encode(rgb):
    """RGBD bytes (..., 4) uint8 of linear colours ``rgb`` (..., 3), as
    Babylon.js's ``toRGBD`` followed by an 8-bit render target: divisor
    D = clamp(floor(255 / max(r, g, b)), 1, 255) / 255 in alpha, colour
    (rgb D) ** (1 / 2.2) clamped to [0, 1].  Channels above 255 are clipped
    to 255 and negative ones to 0 (NaN is refused)."""
    v = np.asarray(rgb, dtype=np.float64)
    if v.ndim == 0 or v.shape[-1] != 3:
        raise InputError(f"RGBD: expected colours with 3 channels, got shape {v.shape}")
    if not np.all(np.isfinite(v) | (v == np.inf)):
        raise InputError("RGBD: colours must not be NaN or -inf")
    v = np.maximum(v, 0.0)
    m = np.maximum(v.max(axis=-1, keepdims=True), _EPSILON)
    with np.errstate(over="ignore"):
        d = np.clip(np.floor(RGBD_MAX / m), 1.0, 255.0)  # alpha byte
    scaled = np.clip(v * (d / 255.0), 0.0, 1.0)
    colour = np.rint(scaled ** (1.0 / _GAMMA) * 255.0)
    return np.concatenate([colour, d], axis=-1).astype(np.uint8)


def rgbd_decode(rgba8):
    """Linear float32 colours (..., 3) of RGBD bytes (..., 4), as Babylon.js's
    ``fromRGBD``: (rgb / 255) ** 2.2 / (a / 255).  Alpha 0 (never written by
    Babylon or pbrkit) gives inf or NaN, as on the GPU."""
    q = np.asarray(rgba8)
    if q.ndim == 0 or q.shape[-1] != 4:
        raise InputError(f"RGBD: expected 4 channels, got shape {q.shape}")
    q = q.astype(np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = (q[..., :3] / 255.0) ** _GAMMA / (q[..., 3:] / 255.0)
    return out.astype(np.float32)


# ----------------------------------------------------------------- PNG


def _png_rgba8(image):
    """Deterministic PNG bytes of an (H, W, 4) uint8 image: Paeth filter on
    every row (ISO/IEC 15948 9.2, computed from the unfiltered bytes, so it
    vectorises), zlib level 6, IHDR / IDAT / IEND only."""
    height, width, _ = image.shape
    x = image.reshape(height, width * 4).astype(np.int16)
    a = np.zeros_like(x)
    a[:, 4:] = x[:, :-4]  # left
    b = np.zeros_like(x)
    b[1:] = x[:-1]  # up
    c = np.zeros_like(x)
    c[1:, 4:] = x[:-1, :-4]  # up-left
    p = a + b - c
    pa, pb, pc = np.abs(p - a), np.abs(p - b), np.abs(p - c)
    predictor = np.where((pa <= pb) & (pa <= pc), a, np.where(pb <= pc, b, c))
    filtered = ((x - predictor) & 0xFF).astype(np.uint8)
    raw = np.concatenate([np.full((height, 1), 4, dtype=np.uint8), filtered], axis=1)
    return png_file_bytes(width, height, 8, 6, raw, _ZLIB_LEVEL)


def _decode_png_rgba8(data, what, size=None):
    """(H, W, 4) uint8 of an 8-bit RGBA or RGB PNG (RGB gets alpha 255), of
    ``size`` x ``size`` pixels when ``size`` is given (checked before anything is
    decompressed); raises ValueError with a short reason that quotes nothing of
    the data."""
    if data[:8] != PNG_SIGNATURE:
        raise ValueError(f"{what} is not a PNG image")
    pos, header, idat = 8, None, []
    while True:
        if pos + 8 > len(data):
            raise ValueError(f"{what}: truncated PNG (no IEND)")
        length, tag = struct.unpack(">I4s", data[pos:pos + 8])
        if pos + 12 + length > len(data):
            raise ValueError(f"{what}: truncated PNG chunk at byte {pos}")
        body = data[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])
        if zlib.crc32(tag + body) & 0xFFFFFFFF != crc:
            raise ValueError(f"{what}: the PNG chunk at byte {pos} fails its CRC")
        if tag == b"IHDR":
            if length != 13:
                raise ValueError(f"{what}: bad PNG IHDR")
            header = struct.unpack(">IIBBBBB", body)
        elif tag == b"IDAT":
            idat.append(body)
        elif tag == b"IEND":
            break
        pos += 12 + length
    if header is None:
        raise ValueError(f"{what}: PNG without IHDR")
    width, height, depth, ctype, _, _, interlace = header
    if depth != 8 or ctype not in (2, 6) or interlace != 0:
        raise ValueError(f"{what}: PNG must be 8-bit RGBA or RGB, non-interlaced "
                         f"(bit depth {depth}, colour type {ctype}, interlace {interlace})")
    if size is not None and (width, height) != (size, size):
        raise ValueError(f"{what}: image is {width}x{height}, expected {size}x{size}")
    channels = 4 if ctype == 6 else 3
    stride = width * channels
    try:
        raw = np.frombuffer(inflate_bounded(b"".join(idat), height * (stride + 1), None, "PNG image data"),
                            dtype=np.uint8)
    except InputError as exc:
        raise ValueError(f"{what}: {exc.problem}") from None
    rows = np.empty((height, stride), dtype=np.uint8)
    bad = _png_unfilter(raw, height, stride, channels, rows)
    if bad >= 0:
        raise ValueError(f"{what}: corrupt PNG filter type in row {bad}")
    image = rows.reshape(height, width, channels)
    if channels == 3:
        image = np.concatenate([image, np.full((height, width, 1), 255, dtype=np.uint8)], axis=2)
    return image


# ----------------------------------------------------------------- JSON


def _js_number(value):
    """``value`` as JavaScript's Number.prototype.toString writes it (ECMA-262
    Number::toString: the shortest round-trip digits, exponent form only below
    1e-6 or from 1e21), so the manifest reads as Babylon's JSON.stringify's."""
    if isinstance(value, (bool, np.bool_)):
        raise InputError(f"expected a number, got {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise InputError(f"manifest numbers must be finite, got {x}")
    if x == 0.0:
        return "0"
    sign = "-" if x < 0 else ""
    t = Decimal(repr(abs(x))).normalize().as_tuple()
    digits = "".join(map(str, t.digits))
    k = len(digits)
    n = t.exponent + k  # value = 0.digits * 10^n
    if k <= n <= 21:
        body = digits + "0" * (n - k)
    elif 0 < n <= 21:
        body = digits[:n] + "." + digits[n:]
    elif -6 < n <= 0:
        body = "0." + "0" * (-n) + digits
    else:
        e = n - 1
        mantissa = digits[0] + ("." + digits[1:] if k > 1 else "")
        body = f"{mantissa}e{'+' if e >= 0 else '-'}{abs(e)}"
    return sign + body


def _js_json(value):
    """Compact JSON as JSON.stringify writes it (no spaces, key order kept)."""
    if value is None:
        return "null"
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=True)
    if isinstance(value, dict):
        return "{" + ",".join(f"{json.dumps(str(k))}:{_js_json(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ",".join(_js_json(v) for v in value) + "]"
    if isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)):
        return str(int(value))
    return _js_number(value)


# ----------------------------------------------------------------- writer


def _check_chain(levels):
    arrays, width, _ = validate_levels(levels, cube=True)
    if width & (width - 1):
        raise InputError(f"a .env cube needs a power-of-two face size, got {width}")
    count = round(math.log2(width)) + 1
    if len(arrays) != count:
        raise InputError(f"a .env file holds the full chain down to 1x1: {count} levels for size {width}, "
                         f"got {len(arrays)}")
    for p, a in enumerate(arrays):
        if a.ndim != 4 or a.shape[-1] != 3:
            raise InputError(f"level {p}: expected RGB faces (6, n, n, 3), got shape {a.shape}")
        if not np.issubdtype(a.dtype, np.number) or np.iscomplexobj(a):
            raise InputError(f"level {p}: expected real numbers, got dtype {a.dtype}")
        if not np.all(np.isfinite(a)):
            raise InputError(f"level {p}: values must be finite")
    return arrays, width


def _check_polynomial(polynomial):
    if polynomial is None:
        return None
    if not isinstance(polynomial, dict):
        raise InputError(f"polynomial must be a dict of the terms {', '.join(POLYNOMIAL_TERMS)}")
    if set(polynomial) != set(POLYNOMIAL_TERMS):
        raise InputError(f"polynomial terms {sorted(polynomial)} differ from {list(POLYNOMIAL_TERMS)}")
    out = {}
    for term in POLYNOMIAL_TERMS:
        v = np.asarray(polynomial[term], dtype=np.float64).reshape(-1)
        if v.shape != (3,) or not np.all(np.isfinite(v)):
            raise InputError(f"polynomial term {term!r} must be 3 finite numbers, got {polynomial[term]!r}")
        out[term] = [float(c) for c in v]
    return out


def env_bytes(levels, polynomial, lod_generation_scale=0.8):
    """The bytes of a Babylon.js ``.env`` file; see :func:`write_babylon_env`."""
    arrays, width = _check_chain(levels)
    irradiance = _check_polynomial(polynomial)
    scale = float(lod_generation_scale)
    if not (math.isfinite(scale) and scale > 0):
        raise InputError(f"lod_generation_scale must be a positive number, got {lod_generation_scale!r}")
    images = []
    for a in arrays:
        encoded = rgbd_encode(a)
        for face in range(6):
            images.append(_png_rgba8(encoded[face, ::-1]))  # PNG top row = t = 1 (see the module notes)
    mipmaps, position = [], 0
    for image in images:
        mipmaps.append({"length": len(image), "position": position})
        position += len(image)
    manifest = {
        "version": _VERSION,
        "width": width,
        "imageType": _IMAGE_TYPE,
        "irradiance": irradiance,
        "specular": {"mipmaps": mipmaps, "lodGenerationScale": scale},
    }
    return ENV_MAGIC + _js_json(manifest).encode("ascii") + b"\x00" + b"".join(images)


def write_babylon_env(path, levels, polynomial, lod_generation_scale=0.8):
    """Write a Babylon.js ``.env`` file atomically and return ``path``.

    ``levels``: the full prefiltered cube chain, a list of (6, n, n, 3) float
    arrays, level 0 (n = N, a power of two) first and halving down to 1 x 1
    (log2 N + 1 levels), faces +X, -X, +Y, -Y, +Z, -Z with row 0 = t = 0 as
    everywhere in pbrkit (the file stores them upside down, as Babylon expects).
    Values are RGBD-encoded: at most 255 (larger channels are clipped),
    negatives clipped to 0, NaN / inf refused.  ``polynomial``: Babylon's
    spherical polynomial, a dict of the 9 terms :data:`POLYNOMIAL_TERMS` ->
    3 numbers (:func:`pbrkit.ibl.sh.babylon_polynomial`), or None for no
    irradiance.  ``lod_generation_scale``: the manifest's
    ``specular.lodGenerationScale`` (Babylon's lod = log2(N alpha) x scale).
    Same input, same bytes.
    """
    data = env_bytes(levels, polynomial, lod_generation_scale)
    write_bytes(path, data)  # atomic: temporary file, then rename
    return path


# ----------------------------------------------------------------- reader


def _fail(name, message):
    raise InputError(message, name)


def _non_negative_int(value):
    return isinstance(value, int) and not isinstance(value, bool) and value >= 0


def parse_babylon_env(data, name=None):
    """Parse the bytes of a ``.env`` file; see :func:`read_babylon_env`."""
    data = bytes(data)
    if len(data) < len(ENV_MAGIC) or data[:8] != ENV_MAGIC:
        _fail(name, "not a Babylon.js .env file (bad magic)")
    end = data.find(b"\x00", 8)
    if end < 0:
        _fail(name, "truncated .env file: the JSON manifest has no NUL terminator")
    try:
        text = data[8:end].decode("ascii")
    except UnicodeDecodeError as exc:
        _fail(name, f"the JSON manifest is not ASCII (byte {8 + exc.start})")
    try:
        manifest = json.loads(text)
    except json.JSONDecodeError as exc:
        _fail(name, f"bad JSON manifest ({exc.msg} at character {exc.pos})")
    except (ValueError, RecursionError):
        _fail(name, "bad JSON manifest")
    if not isinstance(manifest, dict):
        _fail(name, "the JSON manifest is not an object")
    version = manifest.get("version")
    if version not in (1, 2) or isinstance(version, bool):
        _fail(name, "unsupported .env version (1 and 2 are known)")
    image_type = manifest.get("imageType", _IMAGE_TYPE) if version == 2 else _IMAGE_TYPE
    if image_type != _IMAGE_TYPE:
        _fail(name, "imageType is not image/png, the only one that can be decoded")
    width = manifest.get("width")
    if not _non_negative_int(width) or width < 1 or width & (width - 1):
        _fail(name, "width is not a power of two")
    if width > 1 << 16:
        _fail(name, "width is more than 65536, the largest face size read (corrupt manifest)")
    count = round(math.log2(width)) + 1
    specular = manifest.get("specular")
    mipmaps = specular.get("mipmaps") if isinstance(specular, dict) else None
    if not isinstance(mipmaps, list):
        _fail(name, "the manifest has no specular.mipmaps list")
    if len(mipmaps) != 6 * count:
        _fail(name, f"{len(mipmaps)} specular images, expected {6 * count} (6 faces x {count} levels for width {width})")
    scale = specular.get("lodGenerationScale") or 0.8  # missing or 0 reads as 0.8, as in Babylon
    if not isinstance(scale, (int, float)) or isinstance(scale, bool) or not math.isfinite(scale):
        _fail(name, "lodGenerationScale is not a finite number")
    payload = end + 1
    # Every face is a PNG of at least n (3n + 1) filtered bytes, which deflate shrinks at most 1032-fold.
    texels = 6 * sum(max(1, width >> p) ** 2 for p in range(count))
    least = (3 * texels + 6 * sum(max(1, width >> p) for p in range(count))) // 1032
    if least > len(data) - payload:
        _fail(name, f"width {width}: the {6 * count} images need at least {least} bytes, the file holds "
                    f"{len(data) - payload} after the manifest (truncated or corrupt)")
    # per texel: the face's PNG rows and pixels (about 9 bytes), float64 decoding temporaries (80)
    # and the float32 faces and their stack (24)
    check_allocation(texels * 113, f"the {width}x{width} cube chain", name)
    levels = []
    for p in range(count):
        n = max(1, width >> p)
        faces = []
        for face in range(6):
            entry = mipmaps[6 * p + face]
            what = f"level {p} face {face}"
            if not isinstance(entry, dict) or not _non_negative_int(entry.get("position")) \
                    or not _non_negative_int(entry.get("length")):
                _fail(name, f"{what}: the manifest entry needs non-negative integer position and length")
            start = payload + entry["position"]
            stop = start + entry["length"]
            if stop > len(data):
                _fail(name, f"{what}: image at {entry['position']}+{entry['length']} runs past the end "
                            f"of the file (truncated, {len(data)} bytes)")
            try:
                image = _decode_png_rgba8(data[start:stop], what, n)
            except ValueError as exc:
                _fail(name, str(exc))
            if np.any(image[..., 3] == 0):
                _fail(name, f"{what}: RGBD alpha 0 (no divisor)")
            faces.append(rgbd_decode(image[::-1]))  # back to row 0 = t = 0
        levels.append(np.stack(faces))
    irradiance = manifest.get("irradiance")
    polynomial = None
    if irradiance is not None:
        if not isinstance(irradiance, dict):
            _fail(name, "irradiance is neither an object nor null")
        polynomial = {}
        for term in POLYNOMIAL_TERMS:
            v = irradiance.get(term)
            if not (isinstance(v, list) and len(v) == 3
                    and all(isinstance(c, (int, float)) and not isinstance(c, bool) for c in v)):
                _fail(name, f"irradiance term {term!r} must be 3 numbers")
            polynomial[term] = np.array(v, dtype=np.float64)
    return manifest, levels, polynomial


def read_babylon_env(path):
    """Read a Babylon.js ``.env`` file (PNG images, manifest version 1 or 2).

    Returns ``(manifest, levels, polynomial)``: the JSON manifest as a dict,
    the specular cube chain as float32 arrays (6, n, n, 3), level 0 first,
    faces +X..-Z with row 0 = t = 0 (pbrkit's order: the file's upside-down
    rows are flipped back), RGBD-decoded; and the spherical polynomial as a
    dict term -> float64 (3,), or None when the file has none.  An optional
    ``irradianceTexture`` is left in the manifest, not decoded.  A bad magic,
    unterminated or invalid JSON, wrong image counts or sizes, images outside
    the file or corrupt PNGs raise :class:`~pbrkit.core.errors.InputError`
    (a ``ValueError``) naming the file; no message quotes the file.
    """
    return read_container(path, parse_babylon_env, "a Babylon.js .env file")
