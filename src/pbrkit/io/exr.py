"""OpenEXR ``.exr`` files through the ``OpenEXR`` package (see :mod:`pbrkit.io.images`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core.atomic import atomic_path
from ..core.errors import InputError
from .image_checks import _check_size, _finite_float, _one_line, open_or_fail

__all__ = [
    "read_exr",
    "write_exr",
]

# ------------------------------------------------------------------- OpenEXR


def _read_exr(path):
    import OpenEXR

    path = Path(path)
    with open_or_fail(path) as f:
        head = f.read(4)
    if head != b"\x76\x2f\x31\x01":
        raise InputError(f"not an OpenEXR file (first bytes {head!r})", path)
    try:
        header = OpenEXR.File(str(path), header_only=True).header()
    except Exception as exc:  # the library raises RuntimeError for any failure
        raise InputError(f"corrupt or truncated OpenEXR file ({_one_line(exc)})", path) from None
    (x0, y0), (x1, y1) = (np.asarray(v) for v in header["dataWindow"])
    _check_size(path, int(y1) - int(y0) + 1, int(x1) - int(x0) + 1)
    try:
        exr = OpenEXR.File(str(path), separate_channels=True)
        part = exr.parts[0]
        channels = part.channels
    except Exception as exc:
        raise InputError(f"corrupt or truncated OpenEXR file ({_one_line(exc)})", path) from None
    notes = [f"OpenEXR {str(header.get('compression', '')).split('.')[-1].replace('_COMPRESSION', '')}"]
    if len(exr.parts) > 1:
        notes.append(f"multi-part file: part 0 of {len(exr.parts)} used")
    names = list(channels)
    if all(c in channels for c in "RGB"):
        picked = ["R", "G", "B"]
    elif "Y" in channels:
        picked = ["Y"]
    else:
        raise InputError(f"no R, G, B (or Y) channels; channels are {', '.join(sorted(names))}", path)
    dropped = sorted(set(names) - set(picked))
    if dropped:
        notes.append(f"channels {', '.join(dropped)} ignored")
    planes = []
    for name in picked:
        ch = channels[name]
        if getattr(ch, "xSampling", 1) != 1 or getattr(ch, "ySampling", 1) != 1:
            raise InputError(f"channel {name} is subsampled; not supported", path)
        planes.append(ch.pixels)
    dtypes = {p.dtype for p in planes}
    notes[0] += " " + "/".join(sorted({"half" if d == np.float16 else str(d) for d in dtypes}))
    img = np.empty(planes[0].shape + (len(planes),), dtype=np.float32)
    for i, p in enumerate(planes):
        img[..., i] = p
    if int(y1) - int(y0) + 1 != img.shape[0] or int(x1) - int(x0) + 1 != img.shape[1]:
        raise InputError("pixel data does not match the data window", path)
    dw, disp = header["dataWindow"], header.get("displayWindow", header["dataWindow"])
    if any(not np.array_equal(a, b) for a, b in zip(dw, disp)):
        notes.append("data window differs from display window; data window used")
    return img, notes




def read_exr(path):
    """OpenEXR image as float32 (H, W, 3) (or (H, W, 1) for a Y-only file)."""
    return _read_exr(path)[0]


_EXR_COMPRESSION = {"none": "NO_COMPRESSION", "zip": "ZIP_COMPRESSION", "zips": "ZIPS_COMPRESSION",
                    "piz": "PIZ_COMPRESSION", "rle": "RLE_COMPRESSION"}


def write_exr(path, image, half=False, compression="zip"):
    """Write ``image`` (H, W), (H, W, 1|3|4) as a scanline OpenEXR file
    (channels Y, RGB or RGBA), float32 or, with ``half``, float16, lossless
    ``compression`` in none/zip/zips/piz/rle; atomically."""
    import OpenEXR

    a = _finite_float(image, "image")
    if a.shape[2] == 2:
        raise ValueError("EXR output takes 1, 3 or 4 channels, got 2")
    if compression not in _EXR_COMPRESSION:
        raise ValueError(f"unknown EXR compression {compression!r}; use one of {sorted(_EXR_COMPRESSION)}")
    dtype = np.float16 if half else np.float32
    if half and np.any(np.abs(a) > 65504.0):
        raise ValueError("values exceed the float16 range (65504); write float32 instead")
    a = np.ascontiguousarray(a, dtype=dtype)
    name = {1: "Y", 3: "RGB", 4: "RGBA"}[a.shape[2]]
    pixels = a[..., 0] if name == "Y" else a
    header = {"compression": getattr(OpenEXR, _EXR_COMPRESSION[compression]), "type": OpenEXR.scanlineimage}
    with atomic_path(path) as tmp:
        OpenEXR.File(header, {name: np.ascontiguousarray(pixels)}).write(str(tmp))


