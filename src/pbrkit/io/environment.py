"""Loading environment maps: equirectangular images, cube crosses or six face
files, validated (non-finite and negative samples) into an :class:`Environment`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..core.errors import InputError
from ..ibl.cubemap import cross_layout_of, cube_from_cross, cube_integral, resample_cube
from ..ibl.equirect import cube_to_equirect, equirect_integral, equirect_to_cube
from .image_checks import ALPHA_IGNORED
from .images import read_image_with_notes

__all__ = [
    "NegativeRadianceWarning",
    "IgnoredAlphaWarning",
    "Environment",
    "load_environment",
    "fix_nonfinite_pixels",
    "MAX_NONFINITE_FRACTION",
]

_FACES = ("+X", "-X", "+Y", "-Y", "+Z", "-Z")


class NegativeRadianceWarning(UserWarning):
    """Negative radiance samples were clamped to zero while loading."""


class IgnoredAlphaWarning(UserWarning):
    """An environment map's alpha channel was dropped: radiance is its RGB alone
    (alpha neither masks nor scales light; an RGBA map usually means the wrong file
    or an unpremultiplied export)."""




# ----------------------------------------------------------------- Environment


@dataclass
class Environment:
    """An environment as loaded: either ``equirect`` (H, 2H, 3) or ``cube``
    (6, N, N, 3) (float32 or float64, linear radiance, finite, >= 0), the
    source file(s), the layout read (``"equirect"``, ``"hcross"``,
    ``"vcross"`` or ``"faces"``) and notes on what was read or fixed."""

    source: tuple
    layout: str
    equirect: np.ndarray | None = None
    cube: np.ndarray | None = None
    notes: list = field(default_factory=list)

    @property
    def is_cube(self):
        return self.cube is not None

    def to_cube(self, size):
        """Cube map (6, size, size, 3): exact area-weighted resampling of an
        equirect source (:func:`equirect_to_cube`), or
        :func:`pbrkit.ibl.cubemap.resample_cube` of a cube source."""
        if self.cube is not None:
            return resample_cube(self.cube, size)
        return equirect_to_cube(self.equirect, size)

    def to_equirect(self, height):
        """Equirectangular image (height, 2 height, 3): a copy of an equirect
        source of that height, else bilinear from the cube."""
        if self.equirect is not None and self.equirect.shape[0] == height:
            return self.equirect.copy()
        cube = self.cube if self.cube is not None else self.to_cube(max(1, height // 2))
        return cube_to_equirect(cube, height)

    def integral(self):
        """Integral of the radiance over the sphere, (3,): exact cell solid
        angles for an equirect source, exact texel solid angles for a cube."""
        if self.cube is not None:
            return cube_integral(self.cube)
        return equirect_integral(self.equirect, exact=True)


def _neighbour_mean(img, bad, wrap):
    """For each bad sample of ``img`` (H, W, C) (in ``np.nonzero(bad)``
    order): the mean of the finite samples of the same channel among its 8
    neighbours; samples outside the image do not count, except that columns
    wrap around with ``wrap``; 0 where no neighbour is finite.  Memory is
    proportional to the number of bad samples."""
    h, w = img.shape[:2]
    r, c, ch = np.nonzero(bad)
    total = np.zeros(r.size)
    count = np.zeros(r.size)
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            if dr == 0 and dc == 0:
                continue
            rr = r + dr
            cc = (c + dc) % w if wrap else c + dc
            inside = (rr >= 0) & (rr < h) & (cc >= 0) & (cc < w)
            vals = img[np.clip(rr, 0, h - 1), np.clip(cc, 0, w - 1), ch].astype(np.float64)
            ok = inside & np.isfinite(vals)
            total += np.where(ok, vals, 0.0)
            count += ok
    return np.where(count > 0, total / np.maximum(count, 1.0), 0.0)


def fix_nonfinite_pixels(image, wrap=False):
    """Copy of ``image`` (H, W, C) with every NaN/Inf sample replaced by the
    mean of the finite samples of the same channel among its 8 neighbours
    (columns wrap with ``wrap``, as for an equirect image), or by 0 where no
    neighbour is finite.  Returns (fixed, count)."""
    arr = np.asarray(image)
    if arr.ndim not in (2, 3):
        raise ValueError(f"image must have shape (H, W) or (H, W, C), got {arr.shape}")
    img = np.array(arr[..., None] if arr.ndim == 2 else arr, dtype=np.result_type(arr.dtype, np.float32))
    bad = ~np.isfinite(img)
    count = int(np.count_nonzero(bad))
    if count:
        img[bad] = _neighbour_mean(img, bad, wrap)
    return (img[..., 0] if arr.ndim == 2 else img), count


#: With ``fix_nonfinite``, an image (or cube face) with more than this fraction
#: of non-finite samples is refused: there is too little left to fill from.
MAX_NONFINITE_FRACTION = 0.5

def _validate_pixels(images, path, fix_nonfinite, notes, wrap):
    """Check (and with ``fix_nonfinite`` repair) freshly read images
    (K, H, W, C), which this function may modify in place; negatives are
    clamped to 0 with a warning.  Counts are over all K images; an image
    with more than :data:`MAX_NONFINITE_FRACTION` non-finite samples is
    refused even with ``fix_nonfinite``."""
    bad = ~np.isfinite(images)
    count = int(np.count_nonzero(bad))
    if count:
        if not fix_nonfinite:
            raise InputError(f"{count} non-finite (NaN or Inf) sample(s) of {images.size}; use --fix-nonfinite "
                             "(Python: fix_nonfinite=True) to replace them with the mean of their finite "
                             "neighbours", path)
        for k in range(images.shape[0]):
            bad_k = int(np.count_nonzero(bad[k]))
            if bad_k > MAX_NONFINITE_FRACTION * bad[k].size:
                where = f"face {_FACES[k]}: " if images.shape[0] == 6 else ""
                if bad_k == bad[k].size:
                    raise InputError(f"{where}all {bad_k} samples are non-finite (NaN or Inf); --fix-nonfinite has "
                                     "no finite samples to fill them from", path)
                raise InputError(f"{where}{bad_k} of {bad[k].size} samples ({100.0 * bad_k / bad[k].size:.0f}%) are "
                                 "non-finite (NaN or Inf): too few finite samples for --fix-nonfinite to fill them "
                                 f"from (it repairs images with at most {MAX_NONFINITE_FRACTION:.0%} bad samples)",
                                 path)
        for k in range(images.shape[0]):
            if bad[k].any():
                images[k][bad[k]] = _neighbour_mean(images[k], bad[k], wrap)
        notes.append(f"{count} non-finite sample(s) replaced by the mean of their finite neighbours (0 if none)")
    del bad
    count = int(np.count_nonzero(images < 0))
    if count:
        lowest = float(images.min())
        np.maximum(images, 0, out=images)
        msg = f"{count} negative sample(s) clamped to 0 (most negative {lowest:.3g})"
        notes.append(msg)
        warnings.warn(f"{path}: {msg}", NegativeRadianceWarning, stacklevel=3)
    return images


def _read(path):
    """(pixels, notes) of one environment file, warning once if its alpha is dropped."""
    img, _fmt, notes = read_image_with_notes(path)
    if ALPHA_IGNORED in notes:
        warnings.warn(f"{path}: its alpha channel is ignored (an environment's radiance is its RGB; alpha "
                      "does not mask or scale light)", IgnoredAlphaWarning, stacklevel=3)
    return img, notes


def _rgb(img, path):
    if img.shape[2] == 1:
        return np.repeat(img, 3, axis=2)
    if img.shape[2] == 3:
        return img
    raise InputError(f"expected 1 or 3 colour channels, got {img.shape[2]}", path)


def load_environment(path_or_paths, fix_nonfinite=False, layout=None):
    """Read an environment map and validate it.

    ``path_or_paths`` is one image file (equirectangular with W = 2H, or a
    4:3 ``"hcross"`` / 3:4 ``"vcross"`` cube cross, see
    :mod:`pbrkit.ibl.cubemap`), or a sequence of six square face files of equal
    size in the order +X, -X, +Y, -Y, +Z, -Z (each oriented as a face of the
    cube array: row 0 = t = 0).  ``layout`` forces ``"equirect"``,
    ``"hcross"`` or ``"vcross"`` for a single file instead of deciding by
    aspect ratio.  Formats: see :mod:`pbrkit.io.images` (LDR files warn).

    Problems raise :class:`pbrkit.core.errors.InputError` (a ``ValueError``) with a
    one-line message naming the file: unreadable, truncated or corrupt
    files, zero or absurd sizes, an aspect ratio that fits no layout, faces
    of different or non-square sizes, non-finite samples (with their count;
    ``fix_nonfinite=True`` replaces each by the mean of the finite samples of
    the same channel among its 8 neighbours, 0 if none, and records a note;
    an image with more than half its samples non-finite is refused even so).
    Negative samples are clamped to 0 with a :class:`NegativeRadianceWarning`
    naming the count.  Grey images are replicated to RGB; alpha is dropped with an
    :class:`IgnoredAlphaWarning`.
    """
    if isinstance(path_or_paths, (str, Path)):
        path = Path(path_or_paths)
        img, notes = _read(path)
        h, w = img.shape[:2]
        kind = layout
        if kind is None:
            kind = "equirect" if w == 2 * h else cross_layout_of(img.shape)
        if kind is None:
            raise InputError(f"image is {w}x{h}: not an equirect map (width must be 2x height) nor a 4:3 or 3:4 "
                             "cube cross", path)
        if kind == "equirect":
            if w != 2 * h:
                raise InputError(f"equirect image is {w}x{h}: width must be twice the height", path)
        elif kind in ("hcross", "vcross"):
            if cross_layout_of(img.shape) != kind:
                raise InputError(f"image is {w}x{h}: does not fit the {kind} layout "
                                 f"({'4N x 3N' if kind == 'hcross' else '3N x 4N'})", path)
        else:
            raise ValueError(f"unknown layout {layout!r}; use 'equirect', 'hcross' or 'vcross'")
        img = _rgb(img, path)
        if kind == "equirect":
            img = _validate_pixels(img[None], path, fix_nonfinite, notes, wrap=True)[0]
            return Environment(source=(str(path),), layout=kind, equirect=img, notes=notes)
        # only the six face blocks count (the unused blocks of a cross are often junk)
        cube = cube_from_cross(img, kind)
        del img
        cube = _validate_pixels(cube, path, fix_nonfinite, notes, wrap=False)
        notes.append(f"{kind} cube cross, faces {cube.shape[1]} x {cube.shape[1]} texels")
        return Environment(source=(str(path),), layout=kind, cube=cube, notes=notes)

    paths = [Path(p) for p in path_or_paths]
    if len(paths) != 6:
        raise InputError(f"a cube needs six face files (+X, -X, +Y, -Y, +Z, -Z), got {len(paths)}")
    faces, notes, size = [], [], None
    for name, p in zip(("+X", "-X", "+Y", "-Y", "+Z", "-Z"), paths):
        img, face_notes = _read(p)
        h, w = img.shape[:2]
        if h != w:
            raise InputError(f"face {name} is {w}x{h}: cube faces must be square", p)
        if size is None:
            size = h
        elif h != size:
            raise InputError(f"face {name} is {w}x{h} but face +X is {size}x{size}: faces must have equal sizes", p)
        img = _rgb(img, p)
        faces.append(_validate_pixels(img[None], p, fix_nonfinite, notes, wrap=False)[0])
        notes.extend(f"{name}: {n}" for n in face_notes)
    dtype = np.result_type(*faces)
    cube = np.stack([f.astype(dtype, copy=False) for f in faces])
    return Environment(source=tuple(str(p) for p in paths), layout="faces", cube=cube, notes=notes)

