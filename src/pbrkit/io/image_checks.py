"""Checks and small helpers shared by the image readers and writers.

Image files are untrusted input (:mod:`pbrkit.core.inputs`): a reader opens
only regular files (:func:`open_or_fail`, :func:`_read_bytes`), of at most
:data:`MAX_IMAGE_BYTES`, with the memory for reading them checked first; the
size a header declares is checked against :data:`MAX_SIDE` / :data:`MAX_PIXELS`,
against what the file can hold and against the memory available
(:func:`_check_pixels`) before any pixel is allocated; and no message quotes
the file's bytes, lines or header text (:func:`safe_reason` for the text of a
library's exception).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..core.errors import InputError
from ..core.inputs import check_allocation, open_regular, read_bytes

__all__ = [
    "MAX_SIDE",
    "MAX_PIXELS",
    "MAX_IMAGE_BYTES",
    "LDRInputWarning",
    "ALPHA_IGNORED",
    "image_format",
    "safe_reason",
]

MAX_SIDE = 32768
#: Largest image read, in pixels: a 32768 x 16384 equirect (6 GiB as float32 RGB).
MAX_PIXELS = 32768 * 16384
#: Largest image file read: :data:`MAX_PIXELS` of float32 RGBA plus 1 MiB of header.
MAX_IMAGE_BYTES = MAX_PIXELS * 16 + (1 << 20)
#: What an image reader expects, for the messages of :mod:`pbrkit.core.inputs`.
IMAGE_EXPECTED = "an image file (.hdr, .exr, .pfm, .png or .jpg)"


class LDRInputWarning(UserWarning):
    """An 8/16-bit display-referred image was used where HDR radiance is expected."""


#: The note a reader records when it drops an image's alpha channel (PNG grey+alpha or
#: RGBA, an OpenEXR ``A`` channel): a reader of radiance warns on it
#: (:func:`pbrkit.io.environment.load_environment`).
ALPHA_IGNORED = "alpha ignored"




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


def _check_pixels(path, height, width, bytes_per_pixel, what="image"):
    """:func:`_check_size`, then the memory for ``bytes_per_pixel`` bytes of each of
    the ``height`` x ``width`` pixels the reader allocates (its peak, every
    temporary included) against the memory available
    (:func:`pbrkit.core.inputs.check_allocation`): both before any pixel is allocated."""
    _check_size(path, height, width)
    check_allocation(height * width * bytes_per_pixel, f"the {width}x{height} {what}", path)


def _read_bytes(path, expected=IMAGE_EXPECTED):
    """The bytes of the regular file ``path`` (at most :data:`MAX_IMAGE_BYTES`), with
    the memory to hold them checked before reading (:func:`pbrkit.core.inputs.read_bytes`)."""
    return read_bytes(path, MAX_IMAGE_BYTES, expected)


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
    raise InputError(f"{what} (its first bytes are no known image signature); expected Radiance .hdr, "
                     "OpenEXR .exr, .pfm, .png or .jpg", path)


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



def open_or_fail(path, expected=IMAGE_EXPECTED):
    """``path`` opened for binary reading if it is a regular file (also behind a
    symbolic link) of at most :data:`MAX_IMAGE_BYTES`
    (:func:`pbrkit.core.inputs.open_regular`), else :class:`InputError`."""
    return open_regular(path, MAX_IMAGE_BYTES, expected)


_QUOTED = re.compile(r"""b?'(?:[^'\\]|\\.)*'|b?"(?:[^"\\]|\\.)*"|b?'[^']*$|b?"[^"]*$""")


def safe_reason(exc, limit=160):
    """One line from a library's exception (or text) for a message about an untrusted
    file: anything quoted (names, bytes the library echoes from the file) becomes
    ``'...'``, characters outside printable ASCII are dropped, and the text is cut
    to ``limit`` characters; the exception's type name where nothing is left."""
    text = exc if isinstance(exc, str) else str(exc)
    text = _QUOTED.sub("'...'", text)
    text = "".join(c for c in text if " " <= c <= "~")
    text = " ".join(text.split())
    if len(text) > limit:
        text = text[:limit - 3] + "..."
    return text or ("" if isinstance(exc, str) else type(exc).__name__)


def _one_line(exc):
    return safe_reason(exc)


