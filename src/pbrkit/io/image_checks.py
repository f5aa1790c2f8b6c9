"""Checks and small helpers shared by the image readers and writers.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core.errors import InputError

__all__ = [
    "MAX_SIDE",
    "MAX_PIXELS",
    "LDRInputWarning",
    "image_format",
]

MAX_SIDE = 32768
#: Largest image read, in pixels: a 32768 x 16384 equirect (6 GiB as float32 RGB).
MAX_PIXELS = 32768 * 16384


class LDRInputWarning(UserWarning):
    """An 8/16-bit display-referred image was used where HDR radiance is expected."""




# ------------------------------------------------------------------ helpers

_MAGIC = {
    b"#?": "hdr",
    b"\x76\x2f\x31\x01": "exr",
    b"PF": "pfm",
    b"Pf": "pfm",
    b"\x89PNG\r\n\x1a\n": "png",
    b"\xff\xd8\xff": "jpeg",
}
_SUFFIX = {".hdr": "hdr", ".pic": "hdr", ".rgbe": "hdr", ".exr": "exr", ".pfm": "pfm",
           ".png": "png", ".jpg": "jpeg", ".jpeg": "jpeg"}


def _check_size(path, height, width):
    if height <= 0 or width <= 0:
        raise InputError(f"image size {width}x{height} is empty", path)
    if height > MAX_SIDE or width > MAX_SIDE:
        raise InputError(f"image size {width}x{height} exceeds the {MAX_SIDE}-pixel limit on a side "
                         "(corrupt header or absurd size)", path)
    if height * width > MAX_PIXELS:
        raise InputError(f"image size {width}x{height} ({height * width:,} pixels) exceeds the limit of "
                         f"{MAX_PIXELS:,} pixels (corrupt header or absurd size)", path)


def _read_bytes(path):
    with open_or_fail(path) as f:
        return f.read()


def image_format(path):
    """The format of an image file, ``'hdr'``, ``'exr'``, ``'pfm'``, ``'png'`` or
    ``'jpeg'``, from its first bytes (its suffix only breaks no ties: content
    wins).  Raises :class:`InputError` for anything else."""
    path = Path(path)
    with open_or_fail(path) as f:
        head = f.read(8)
    if not head:
        raise InputError("file is empty", path)
    for magic, fmt in _MAGIC.items():
        if head.startswith(magic):
            return fmt
    expected = _SUFFIX.get(path.suffix.lower())
    what = f"not a valid {expected.upper()} file" if expected else "unrecognised image format"
    raise InputError(f"{what} (first bytes {head[:8]!r}); expected Radiance .hdr, OpenEXR .exr, .pfm, "
                     ".png or .jpg", path)


def _as_hwc(image, what="image"):
    a = np.asarray(image)
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3 or a.shape[2] not in (1, 2, 3, 4) or a.shape[0] < 1 or a.shape[1] < 1:
        raise ValueError(f"{what} must have shape (H, W) or (H, W, C) with C in 1..4, got {np.shape(image)}")
    if a.shape[0] > MAX_SIDE or a.shape[1] > MAX_SIDE:
        raise ValueError(f"{what} of size {a.shape[1]}x{a.shape[0]} exceeds {MAX_SIDE} pixels on a side")
    return a


def _finite_float(image, what):
    a = _as_hwc(image, what)
    if not np.issubdtype(a.dtype, np.floating) and not np.issubdtype(a.dtype, np.integer):
        raise ValueError(f"{what} must be numeric, got dtype {a.dtype}")
    bad = ~np.isfinite(a) if np.issubdtype(a.dtype, np.floating) else None
    if bad is not None and bad.any():
        raise ValueError(f"{what} has {int(bad.sum())} non-finite value(s); cannot write them")
    return a



def open_or_fail(path):
    """Open ``path`` for binary reading or raise :class:`InputError`."""
    try:
        return Path(path).open("rb")
    except FileNotFoundError:
        raise InputError("file not found", path) from None
    except IsADirectoryError:
        raise InputError("is a directory, not an image file", path) from None
    except OSError as exc:
        raise InputError(f"cannot read file ({exc.strerror or exc})", path) from None


def _one_line(exc):
    return " ".join(str(exc).split()) or type(exc).__name__


