"""Reading and writing the image files pbrkit consumes and produces.

Every reader returns linear float32 pixels of shape (H, W, C), row 0 at the
top, and raises :class:`pbrkit.core.errors.InputError` (a ``ValueError``) with a
one-line ``"<file>: <problem>"`` message for anything it cannot read: a
missing, unreadable, truncated or corrupt file, an unknown format, or a size
that is zero or larger than :data:`MAX_SIDE` on a side or :data:`MAX_PIXELS`
in all (checked from the header, before any pixel memory is allocated).  Readers do not judge pixel
values (NaN, Inf, negatives); :func:`pbrkit.io.environment.load_environment` does.

Formats
-------
- Radiance RGBE ``.hdr`` / ``.pic``: own reader and writer (Ward, "Real
  Pixels", Graphics Gems II, 1991, and the Radiance sources
  ``src/common/color.h``, ``color.c``).  A stored (m, e) decodes to
  ``ldexp(m + 0.5, e - 136)`` (Radiance's ``colrval``/``colr_color``: the
  mantissa's bucket centre, exponent excess 128 plus 8 mantissa bits); e = 0
  is black.  Encoding is Radiance's ``setcolr``: ``frexp`` of the largest
  component, mantissas truncated.  Scanlines may be flat, old-style run
  length encoded ((1, 1, 1, n) repeats the previous pixel) or new-style RLE
  (a (2, 2, len >> 8, len & 255) prefix, then each of the four byte planes
  as runs: a count byte c > 128 repeats the next byte c - 128 times,
  otherwise c literal bytes follow), detected per scanline as in Radiance's
  ``freadcolrs``.  Every orientation of the resolution string
  (``-Y H +X W`` is the standard one) is honoured.  ``EXPOSURE=`` lines are
  reported in the notes but not applied (pixels are used as stored, as
  stb_image and three.js do).
- OpenEXR ``.exr``: through the ``OpenEXR`` Python package (``OpenEXR.File``),
  any pixel type and any compression the library reads (PIZ, DWAA/DWAB, ZIP,
  ...).  Channels R, G, B (A is dropped) or a single Y channel.
- Portable Float Map ``.pfm`` (P. Debevec, HDRShop): ``PF`` (RGB) or ``Pf``
  (grey), ``W H``, then a scale whose sign gives the byte order (negative =
  little endian); float32 rows stored bottom to top.
- PNG / JPEG through ``imageio`` (Pillow), decoded from sRGB to linear with
  the IEC 61966-2-1 transfer function and a :class:`LDRInputWarning`.
  16-bit RGB(A) PNGs, which Pillow reduces to 8 bits, are decoded here at
  full precision (non-interlaced files; PNG spec, ISO/IEC 15948, sec. 9).

Writers (:func:`write_hdr`, :func:`write_exr`, :func:`write_pfm`,
:func:`write_png`, :func:`write_image`) are atomic (temporary file in the
destination folder, then ``os.replace``; :mod:`pbrkit.core.atomic`) and
deterministic: the same pixels and options give the same bytes.  A failed
write (a full disk, a read-only folder) raises
:class:`pbrkit.core.errors.OutputError`, an ``OSError`` naming the file asked
for.
"""

from __future__ import annotations

import warnings
from pathlib import Path

from .exr import _read_exr, write_exr
from .hdr import _read_hdr, write_hdr
from .image_checks import LDRInputWarning, image_format
from .pfm import _read_pfm, write_pfm
from .png import _read_ldr, write_png

__all__ = [
    "read_image",
    "read_image_with_notes",
    "write_image",
]

# ------------------------------------------------------------------ dispatch


def read_image_with_notes(path):
    """(pixels, format, notes) for any supported file: pixels float32 (H, W, C)
    linear; notes describe what was read and any adjustment.  PNG and JPEG
    emit a :class:`LDRInputWarning`."""
    fmt = image_format(path)
    if fmt == "hdr":
        img, notes = _read_hdr(path)
    elif fmt == "exr":
        img, notes = _read_exr(path)
    elif fmt == "pfm":
        img, notes = _read_pfm(path)
    else:
        img, notes = _read_ldr(path, fmt)
        warnings.warn(f"{path}: low-dynamic-range {fmt.upper()} input, sRGB-decoded; highlights are "
                      "clipped at 1.0, so lighting from it is too dim and flat (use .hdr or .exr)",
                      LDRInputWarning, stacklevel=3)
    return img, fmt, notes


def read_image(path):
    """Pixels of any supported file as linear float32 (H, W, C)."""
    return read_image_with_notes(path)[0]


def write_image(path, image, **options):
    """Write by suffix: ``.hdr`` (:func:`write_hdr`), ``.exr`` (:func:`write_exr`),
    ``.pfm`` (:func:`write_pfm`) or ``.png`` (:func:`write_png`)."""
    suffix = Path(path).suffix.lower()
    writers = {".hdr": write_hdr, ".exr": write_exr, ".pfm": write_pfm, ".png": write_png}
    if suffix not in writers:
        raise ValueError(f"{path}: cannot write images with suffix {suffix!r}; use .hdr, .exr, .pfm or .png")
    writers[suffix](path, image, **options)

