"""Hatching with tonal art maps (TAMs): Praun, Hoppe, Webb and Finkelstein,
"Real-Time Hatching", SIGGRAPH 2001.

A tonal art map is a sequence of tones, light to dark, each a mip chain of
greyscale hatch images that tile (:func:`tonal_art_map`).  Texel values are
linear paper reflectance: 1 is blank paper, 0 is ink, and a texel partly
covered by ink holds 1 - coverage.  The *darkness* of an image is 1 - its
mean texel value (the fraction of paper inked).

Construction (Praun et al. 2001, sec. 3, "stroke nesting"):

- **Nesting across tones.**  Tone k + 1 starts as a copy of tone k and only
  adds strokes, so every ink texel of tone k is at least as dark in tone
  k + 1 (texel values never increase: strokes multiply them by 1 - coverage).
- **Nesting across levels, width kept in pixels.**  Each tone is filled from
  the coarsest level to the finest.  A stroke is placed at a position, angle
  and length *relative to the texture* and is drawn into the level where it
  is chosen and into every finer level of the same tone (and so of every
  darker tone), at the same relative position, with the same width in
  *pixels* at every level.  A stroke therefore covers half the fraction of
  the texture at each finer level, and the finer levels get additional
  strokes until they too reach the tone's darkness: a surface seen from
  closer (finer mip level) shows more strokes per texture area but the same
  stroke width and the same stroke density on screen.
- **Tone targets.**  Strokes are added to (tone k, level l) while its
  darkness is below the target D_k; the last stroke is kept only if it ends
  nearer the target than without it, so each level lands within half a
  stroke's darkness of D_k (``TonalArtMap.darkness``).  Default targets are
  D_k = ``darkest`` (k + 1) / T, evenly spaced, so that with paper white as
  tone "-1" the hatched darkness is ``darkest`` times the shading tone.
- **Stroke choice.**  As Praun et al. do, each new stroke is the best of
  several random candidates (``candidates``): here the one whose
  neighbourhood holds the least ink, measured with a cone weight
  max(0, 1 - d / R) of the distance d to the stroke's segment, with
  R = max(2 w + 1, w / (2 D_k)) pixels for width w and target D_k (about
  half the spacing of parallel strokes at that tone), averaged over the
  levels it is drawn into; this spreads strokes evenly and avoids overlaps
  (pbrkit's own choice of measure).  Candidates jitter the angle (uniform within +-``angle_jitter``
  degrees), the length (relative, uniform within +-``length_jitter``) and
  the position (uniform on the torus).
- **Cross-hatching.**  Tone k draws in the first ``directions[k]`` of the
  ``angles``; each new stroke takes the active direction with the fewest
  strokes so far at that level (ties: the later one), so a newly enabled
  direction is filled first.  Default for 6 tones: (1, 1, 1, 2, 2, 3).
- **Tiling.**  Images are tori: strokes leaving one edge come back at the
  opposite one, so the maps repeat seamlessly (REPEAT addressing).

Stroke rasterisation (pbrkit's own, vectorised over each stroke's bounding
box): a stroke is a capsule, the points within w / 2 of the segment from
a = c - (L/2) t to b = c + (L/2) t.  A texel centre p at distance
d = |p - (a + clamp((p - a).t, 0, L) t)| from the segment gets ink coverage
clamp(w / 2 + 1/2 - d, 0, 1): the exact area of a unit texel (box filter)
covered by a half-plane whose edge is parallel to a texel side, used for
every orientation as anti-aliasing.  Texel (row i, column j) of an N x N
level has its centre at u = (j + 1/2) / N, v = (i + 1/2) / N (glTF: uv (0, 0)
is the top-left corner); angles are measured from +u toward +v.

Rendering (:func:`hatch`, Praun et al. 2001, sec. 4): a continuous tone
t in [0, 1] selects the two adjacent images of the sequence paper white,
tone 0, ..., tone T - 1 at s = t T and blends them linearly, (1 - frac(s))
and frac(s); each is sampled bilinearly with REPEAT addressing
(:func:`pbrkit.core.filtering.texel_pair`) and mip-mapped trilinearly
(OpenGL 4.6 sec. 8.14.3, LINEAR_MIPMAP_LINEAR: lambda = log2 of the
footprint in level-0 texels per pixel, levels floor(lambda) and the next,
blended by frac(lambda)).  Praun et al. pack six tones in the RGB channels
of two textures to blend them in one pass; :func:`tam_atlas` packs tones
3a .. 3a + 2 into atlas a.

Files (:func:`write_tam`): 8-bit PNGs (sRGB-encoded, CONVENTIONS "Colour":
decoding gives the linear texel values back), a JSON manifest and a
preview, written atomically.  Everything is deterministic: the same
arguments give the same arrays and the same bytes.
"""

from __future__ import annotations

import itertools
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.atomic import atomic_directory
from ..core.checks import integer, power_of_two
from ..core.filtering import REPEAT, texel_pair
from ..core.jit import dual_use, row_kernel, select
from ..io.png import write_png

__all__ = ["TonalArtMap", "tonal_art_map", "default_directions", "hatch", "tam_atlas", "preview_image",
           "write_tam", "MIN_LEVEL_SIZE"]

#: The smallest level a TAM may have (pixels on a side).
MIN_LEVEL_SIZE = 8
#: The default smallest level when ``levels`` is not given.
DEFAULT_MIN_SIZE = 16
#: Strokes one (tone, level) may receive at most (a guard; the defaults need a few hundred in all).
_MAX_STROKES = 100_000

_STROKE_DTYPE = np.dtype([("tone", "i4"), ("level", "i4"), ("direction", "i4"), ("u", "f8"), ("v", "f8"),
                          ("angle", "f8"), ("length", "f8")])


# ------------------------------------------------------------------ checks


def _number(value, name, lo, hi, lo_open=False):
    """``value`` as a float in [lo, hi] ((lo, hi] with ``lo_open``), else a one-line ValueError."""
    ok = not isinstance(value, (bool, np.bool_)) and isinstance(value, (int, float, np.integer, np.floating))
    if ok:
        x = float(value)
        ok = math.isfinite(x) and (x > lo if lo_open else x >= lo) and x <= hi
    if not ok:
        interval = f"({lo}, {hi}]" if lo_open else f"[{lo}, {hi}]"
        raise ValueError(f"{name} must be a finite number in {interval}; got {value!r}")
    return x


def _numbers(value, name, count=None):
    """``value`` as a 1-D float64 array of finite numbers (of length ``count``), else ValueError."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        a = None
    if a is None or a.ndim != 1 or a.size == 0 or (count is not None and a.size != count) \
            or not np.all(np.isfinite(a)):
        what = f"{count} finite numbers" if count is not None else "a non-empty list of finite numbers"
        raise ValueError(f"{name} must be {what}; got {value!r:.120}")
    return a


def default_directions(tones):
    """How many hatching directions each tone uses by default: 1 for the
    lighter half, 2 up to five sixths, 3 beyond (6 tones: (1, 1, 1, 2, 2, 3)):
    lighter tones hatch, darker ones cross-hatch."""
    tones = integer(tones, "tones", 2, 64)
    return tuple(1 if k < tones / 2 else 2 if k < 5 * tones / 6 else 3 for k in range(tones))


# ------------------------------------------------------------------ the map


@dataclass(frozen=True, eq=False)
class TonalArtMap:
    """A tonal art map (module doc).

    ``images[l]`` is level l as float32 (T, N_l, N_l), tone k (light to dark)
    at ``[k]``, level 0 the finest (``sizes[0]`` = size), each level half the
    previous one.  ``targets`` (T,) are the target darknesses, ``darkness``
    (T, L) the achieved ones (1 - mean texel value).  ``strokes`` is a
    structured array, one row per stroke in the order they were added: the
    tone and level where it was added (it is drawn into that level and every
    finer one, of that tone and every darker one), its direction index into
    ``angles``, centre (u, v), angle in degrees and length relative to the
    texture side.  The other fields are the generation parameters."""

    images: tuple
    sizes: tuple
    targets: np.ndarray
    darkness: np.ndarray
    strokes: np.ndarray
    width: float
    length: float
    angles: tuple
    directions: tuple
    angle_jitter: float
    length_jitter: float
    candidates: int
    seed: int

    @property
    def tones(self):
        """The number of tones T."""
        return int(self.images[0].shape[0])

    @property
    def levels(self):
        """The number of mip levels L."""
        return len(self.images)

    def image(self, tone, level=0):
        """Tone ``tone`` at mip level ``level``: float32 (N, N)."""
        return self.images[level][tone]

    @property
    def stroke_counts(self):
        """(T, L) int: the strokes added at each (tone, level)."""
        counts = np.zeros((self.tones, self.levels), dtype=np.int64)
        np.add.at(counts, (self.strokes["tone"], self.strokes["level"]), 1)
        return counts

    @property
    def strokes_present(self):
        """(T, L) int: the strokes drawn into each (tone, level) image: those
        added at that tone or a lighter one, at that level or a coarser one."""
        return np.cumsum(np.cumsum(self.stroke_counts, axis=0)[:, ::-1], axis=1)[:, ::-1]


# ------------------------------------------------------------- rasterising


def _capsule_distance(px, py, ax, ay, dx, dy, seg):
    """Distance from points (px, py) to the segment from a along the unit
    direction (dx, dy) of length ``seg`` (all in pixels; module doc)."""
    rx = px - ax
    ry = py - ay
    t = np.clip(rx * dx + ry * dy, 0.0, seg)
    return np.hypot(rx - t * dx, ry - t * dy)


def _footprint(u, v, angle, length, n, radius):
    """The texels of an n x n torus within ``radius`` pixels of a stroke (centre
    (u, v), ``angle`` in radians, ``length`` relative): wrapped row and column
    indices of its bounding box and the distance of each texel centre to the
    stroke's segment (module doc)."""
    dx, dy = math.cos(angle), math.sin(angle)
    seg = length * n
    ax = u * n - 0.5 * seg * dx
    ay = v * n - 0.5 * seg * dy
    bx, by = ax + seg * dx, ay + seg * dy
    x0, x1 = math.floor(min(ax, bx) - radius), math.ceil(max(ax, bx) + radius)
    y0, y1 = math.floor(min(ay, by) - radius), math.ceil(max(ay, by) + radius)
    xs = np.arange(x0, x1, dtype=np.int64)
    ys = np.arange(y0, y1, dtype=np.int64)
    dist = _capsule_distance((xs + 0.5)[None, :], (ys + 0.5)[:, None], ax, ay, dx, dy, seg)
    return ys % n, xs % n, dist


def _coverage(dist, width):
    """Anti-aliased ink coverage clamp(w / 2 + 1/2 - d, 0, 1) (module doc)."""
    return np.clip(0.5 * width + 0.5 - dist, 0.0, 1.0)


def _distinct(rows, cols):
    """Whether a footprint's box holds every texel once (it does not wrap onto itself)."""
    return np.unique(rows).size == rows.size and np.unique(cols).size == cols.size


def _gain(image, rows, cols, cov):
    """The ink a stroke would add (sum of the texels' decrease), without drawing it."""
    if _distinct(rows, cols):
        return float(np.sum(image[np.ix_(rows, cols)] * cov))
    return _draw(image.copy(), rows, cols, cov)


def _draw(image, rows, cols, cov):
    """Multiply the texels under a footprint by 1 - coverage in place; return
    the ink added (the sum of the decrease)."""
    factor = 1.0 - cov
    if _distinct(rows, cols):
        index = np.ix_(rows, cols)
        before = image[index]
        after = before * factor
        image[index] = after
        return float(np.sum(before - after))
    total = float(np.sum(image))  # the box wraps onto itself: texels repeat, multiply one by one
    np.multiply.at(image, (rows[:, None], cols[None, :]), factor)
    return total - float(np.sum(image))


def _candidate_scores(images, levels, u, v, angle, length, width, radius):
    """The mean ink near each candidate stroke (module doc, "Stroke choice"),
    averaged over ``levels``: cone weights max(0, 1 - d / radius) on a grid of
    samples one pixel apart aligned with each stroke, nearest texel, wrapped."""
    dx, dy = np.cos(angle)[:, None, None], np.sin(angle)[:, None, None]
    offsets = np.arange(-math.ceil(radius), math.ceil(radius) + 1, dtype=np.float64)
    score = np.zeros(u.size)
    for level in levels:
        image = images[level]
        n = image.shape[0]
        half = 0.5 * length * n
        reach = math.ceil(float(np.max(half)) + radius)
        along = np.arange(-reach, reach + 1, dtype=np.float64)
        s = along[None, :, None]
        t = offsets[None, None, :]
        excess = np.maximum(np.abs(s) - half[:, None, None], 0.0)
        weight = np.maximum(1.0 - np.hypot(excess, t) / radius, 0.0)
        x = u[:, None, None] * n + s * dx - t * dy
        y = v[:, None, None] * n + s * dy + t * dx
        ink = 1.0 - image[np.floor(y).astype(np.int64) % n, np.floor(x).astype(np.int64) % n]
        score += np.sum(weight * ink, axis=(1, 2)) / np.sum(weight, axis=(1, 2))
    return score / len(levels)


# ------------------------------------------------------------- generation


def _level_sizes(size, levels):
    size = power_of_two(size, "size", MIN_LEVEL_SIZE, 4096)
    most = int(math.log2(size // MIN_LEVEL_SIZE)) + 1
    if levels is None:
        levels = max(1, int(math.log2(size // DEFAULT_MIN_SIZE)) + 1) if size >= DEFAULT_MIN_SIZE else 1
    else:
        levels = integer(levels, "levels", 1, most)
    return tuple(size >> m for m in range(levels))


def _check_targets(targets, tones, darkest):
    if targets is None:
        darkest = _number(darkest, "darkest", 0.0, 0.95, lo_open=True)
        return darkest * np.arange(1, tones + 1, dtype=np.float64) / tones
    t = _numbers(targets, "targets", tones)
    if np.any(t <= 0.0) or np.any(t > 0.95) or np.any(np.diff(t) <= 0.0):
        raise ValueError(f"targets must be strictly increasing darknesses in (0, 0.95]; got {list(t)}")
    return t


def _check_directions(directions, tones, count):
    if directions is None:
        return tuple(min(d, count) for d in default_directions(tones))
    try:
        d = tuple(directions)
    except TypeError:
        d = None
    if d is None or len(d) != tones or not all(isinstance(x, (int, np.integer)) and not isinstance(x, bool)
                                               and 1 <= x <= count for x in d) \
            or any(b < a for a, b in itertools.pairwise(d)):
        raise ValueError(f"directions must be {tones} non-decreasing integers in [1, {count}] "
                         f"(directions per tone); got {directions!r}")
    return tuple(int(x) for x in d)


def tonal_art_map(tones=6, size=256, levels=None, seed=0, *, width=1.5, length=0.4, darkest=0.8,
                  targets=None, angles=(45.0, 135.0, 0.0), directions=None, angle_jitter=4.0,
                  length_jitter=0.25, candidates=16):
    """Generate a tonal art map (module doc; Praun et al. 2001, sec. 3).

    ``tones`` (2..64) images light to dark, each a mip chain of ``size``
    (a power of two, 8..4096) x ``size`` down to 16 x 16 (or ``levels`` levels,
    the smallest at least 8 x 8).  Strokes are ``width`` pixels wide at every
    level (0.25..16) and ``length`` (0..1] of the texture side long (before
    jitter); tone k reaches darkness ``targets[k]`` (default ``darkest``
    (k + 1) / T; strictly increasing, in (0, 0.95]).  ``angles`` (degrees,
    from +u toward +v) are the hatching directions, ``directions[k]`` how many
    of them tone k uses (default :func:`default_directions`).  ``seed`` (an
    integer in [0, 2^64 - 1]) fixes the random candidates: the same arguments
    give the same bytes.  Returns a :class:`TonalArtMap`.  Bad arguments raise
    ValueError with a one-line message."""
    tones = integer(tones, "tones", 2, 64)
    sizes = _level_sizes(size, levels)
    seed = integer(seed, "seed", 0, 2**64 - 1)
    width = _number(width, "width", 0.25, 16.0)
    length = _number(length, "length", 0.0, 1.0, lo_open=True)
    targets = _check_targets(targets, tones, darkest)
    angle_list = _numbers(angles, "angles")
    if angle_list.size > 8:
        raise ValueError(f"angles must be at most 8 directions; got {angle_list.size}")
    directions = _check_directions(directions, tones, angle_list.size)
    angle_jitter = _number(angle_jitter, "angle_jitter", 0.0, 45.0)
    length_jitter = _number(length_jitter, "length_jitter", 0.0, 0.9)
    candidates = integer(candidates, "candidates", 1, 256)

    rng = np.random.Generator(np.random.PCG64(seed))
    reach = 0.5 * width + 0.5  # where coverage ends
    work = [np.ones((n, n), dtype=np.float64) for n in sizes]
    ink = [0.0] * len(sizes)  # sum of 1 - texel per level, kept up to date
    present = np.zeros((len(sizes), angle_list.size), dtype=np.int64)  # strokes per level and direction
    out = [np.empty((tones, n, n), dtype=np.float32) for n in sizes]
    achieved = np.empty((tones, len(sizes)))
    records = []
    base = np.radians(angle_list)
    for k in range(tones):
        active = directions[k]
        target = float(targets[k])
        radius = max(2.0 * width + 1.0, 0.5 * width / target)  # the cone of the candidates' scores (module doc)
        for level in range(len(sizes) - 1, -1, -1):  # coarse to fine
            area = float(sizes[level]) ** 2
            finer = range(level, -1, -1)
            for _ in range(_MAX_STROKES):
                darkness = ink[level] / area
                if darkness >= target:
                    break
                counts = present[level, :active]
                direction = active - 1 - int(np.argmin(counts[::-1]))
                r = rng.random((candidates, 4))
                u, v = r[:, 0], r[:, 1]
                angle = base[direction] + np.radians(angle_jitter) * (2.0 * r[:, 2] - 1.0)
                lengths = length * (1.0 + length_jitter * (2.0 * r[:, 3] - 1.0))
                best = int(np.argmin(_candidate_scores(work, finer, u, v, angle, lengths, width, radius)))
                stroke = (float(u[best]), float(v[best]), float(angle[best]), float(lengths[best]))
                rows, cols, dist = _footprint(*stroke, sizes[level], reach)
                cov = _coverage(dist, width)
                gain = _gain(work[level], rows, cols, cov) / area
                if darkness + gain - target > target - darkness:
                    break  # this stroke would overshoot more than stopping undershoots
                for m in finer:
                    if m != level:
                        rows, cols, dist = _footprint(*stroke, sizes[m], reach)
                        cov = _coverage(dist, width)
                    ink[m] += _draw(work[m], rows, cols, cov)
                present[:level + 1, direction] += 1
                records.append((k, level, direction, stroke[0], stroke[1], math.degrees(stroke[2]), stroke[3]))
        for m, n in enumerate(sizes):
            out[m][k] = work[m]
            achieved[k, m] = 1.0 - float(np.mean(out[m][k], dtype=np.float64))
    strokes = np.array(records, dtype=_STROKE_DTYPE)
    for a in out:
        a.flags.writeable = False
    return TonalArtMap(images=tuple(out), sizes=sizes, targets=targets, darkness=achieved, strokes=strokes,
                       width=width, length=length, angles=tuple(float(a) for a in angle_list),
                       directions=directions, angle_jitter=angle_jitter, length_jitter=length_jitter,
                       candidates=candidates, seed=seed)


# ------------------------------------------------------------- rendering


def _check_tam(tam):
    if not isinstance(tam, TonalArtMap):
        raise ValueError(f"tam must be a TonalArtMap (from tonal_art_map); got {type(tam).__name__}")


@dual_use
def tam_sample(stack, u, v, index):
    """A bilinear REPEAT sample of the images ``stack`` (T, n, n) at (u, v) for the
    sequence index ``index``: 0 is paper white, k + 1 is tone k (OpenGL 4.6 sec.
    8.14.2 filtering, :func:`pbrkit.core.filtering.texel_pair`)."""
    n = stack.shape[1]
    j0, j1, fx = texel_pair(u * n - 0.5, n, REPEAT)
    i0, i1, fy = texel_pair(v * n - 0.5, n, REPEAT)
    k = np.maximum(index - 1, 0)
    value = ((stack[k, i0, j0] * (1.0 - fx) + stack[k, i0, j1] * fx) * (1.0 - fy)
             + (stack[k, i1, j0] * (1.0 - fx) + stack[k, i1, j1] * fx) * fy)
    return select(index == 0, 1.0, value)


@row_kernel(2)
def _hatch_kernel(start, stop, images, tones, uv, t, lam, out):
    """:func:`hatch` at every point: the two tones around t T blended linearly,
    each trilinear between mip levels floor(lambda) and the next."""
    top = len(images) - 1
    for i in range(start, stop):
        m0 = min(int(math.floor(lam[i])), max(top - 1, 0))
        g = lam[i] - m0
        m1 = min(m0 + 1, top)
        s = t[i] * tones
        e0 = min(int(math.floor(s)), tones - 1)
        f = s - e0
        u, v = uv[i, 0], uv[i, 1]
        a = (1.0 - f) * tam_sample(images[m0], u, v, e0) + f * tam_sample(images[m0], u, v, e0 + 1)
        b = a
        if m1 != m0:
            b = (1.0 - f) * tam_sample(images[m1], u, v, e0) + f * tam_sample(images[m1], u, v, e0 + 1)
        out[i] = (1.0 - g) * a + g * b


def _per_point(value, name, count):
    """A finite scalar or (count,) array as float64 (count,), else ValueError."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        a = None
    if a is None or a.ndim > 1 or (a.ndim == 1 and a.size != count):
        raise ValueError(f"{name} must be a number or an array of {count} numbers (one per uv); "
                         f"got {value!r:.80}")
    bad = ~np.isfinite(a)
    if np.any(bad):
        raise ValueError(f"{name} must be finite; got {int(np.sum(bad))} NaN or infinite value(s)")
    return np.broadcast_to(a, (count,))


def hatch(tone, uv, tam, *, footprint=None, level=None):
    """Hatched paper reflectance at texture coordinates ``uv`` (N, 2) for the
    shading ``tone`` (a number or (N,) array; 0 white .. 1 the darkest tone,
    clamped to [0, 1]): the two adjacent images of the sequence paper white,
    tone 0, ..., tone T - 1 blended at s = tone T (Praun et al. 2001, sec. 4),
    each sampled bilinearly with REPEAT addressing and trilinearly across mip
    levels (module doc).  The level is lambda = log2(``footprint``), the
    screen-space footprint in level-0 texels per pixel (a number or (N,)
    array > 0), or the explicit (possibly fractional) ``level``; either is
    clamped to [0, L - 1]; neither means level 0.  Returns float64 (N,) in
    [0, 1]."""
    _check_tam(tam)
    try:
        uv = np.asarray(uv, dtype=np.float64)
    except (TypeError, ValueError):
        uv = None
    if uv is None or uv.ndim != 2 or uv.shape[1] != 2:
        raise ValueError(f"uv must have shape (N, 2); got {getattr(uv, 'shape', None)}")
    if not np.all(np.isfinite(uv)):
        raise ValueError(f"uv must be finite; got {int(np.sum(~np.isfinite(uv)))} NaN or infinite value(s)")
    count = uv.shape[0]
    t = np.clip(_per_point(tone, "tone", count), 0.0, 1.0)
    if footprint is not None and level is not None:
        raise ValueError("give footprint or level, not both")
    if footprint is not None:
        fp = _per_point(footprint, "footprint", count)
        if np.any(fp <= 0.0):
            raise ValueError(f"footprint must be > 0 (texels per pixel); got {int(np.sum(fp <= 0.0))} value(s) <= 0")
        lam = np.log2(fp)
    elif level is not None:
        lam = _per_point(level, "level", count)
    else:
        lam = np.zeros(count)
    lam = np.clip(lam, 0.0, float(tam.levels - 1))
    result = np.empty(count)
    _hatch_kernel(tam.images, tam.tones, np.ascontiguousarray(uv), np.ascontiguousarray(t),
                  np.ascontiguousarray(lam), result)
    return result


# ------------------------------------------------------------------ files


def tam_atlas(tam):
    """The TAM packed as Praun et al. (2001, sec. 4) pack six tones into two RGB
    textures: per level, float32 (A, N, N, 3) with A = ceil(T / 3), channel c
    of atlas a holding tone 3 a + c (channels past the last tone are paper
    white, 1)."""
    _check_tam(tam)
    count = -(-tam.tones // 3)
    packed = []
    for stack in tam.images:
        n = stack.shape[1]
        a = np.ones((count * 3, n, n), dtype=np.float32)
        a[:tam.tones] = stack
        packed.append(np.ascontiguousarray(a.reshape(count, 3, n, n).transpose(0, 2, 3, 1)))
    return tuple(packed)


def preview_image(tam, level=0, gap=4):
    """The tones of one level side by side, light to dark, separated by
    ``gap`` columns of mid grey (0.5): float32 (N, T N + (T - 1) gap)."""
    _check_tam(tam)
    level = integer(level, "level", 0, tam.levels - 1)
    gap = integer(gap, "gap", 0, 64)
    stack = tam.images[level]
    n = stack.shape[1]
    image = np.full((n, tam.tones * (n + gap) - gap), 0.5, dtype=np.float32)
    for k in range(tam.tones):
        image[:, k * (n + gap):k * (n + gap) + n] = stack[k]
    return image


def _round(x):
    return round(float(x), 6)


def _manifest(tam, files, atlas_files):
    sizes = list(tam.sizes)
    counts = tam.stroke_counts
    present = tam.strokes_present
    per_tone = []
    for k in range(tam.tones):
        per_tone.append({
            "tone": k,
            "target_darkness": _round(tam.targets[k]),
            "darkness": [_round(d) for d in tam.darkness[k]],
            "mean_darkness": _round(np.mean(tam.darkness[k])),
            "directions": tam.directions[k],
            "strokes_added": [int(c) for c in counts[k]],
            "strokes_present": [int(c) for c in present[k]],
            "files": files[k],
        })
    manifest = {
        "kind": "tonal art map",
        "reference": "Praun, Hoppe, Webb, Finkelstein, Real-Time Hatching, SIGGRAPH 2001",
        "generator": "pbrkit.npr.hatching.tonal_art_map",
        "tones": tam.tones,
        "levels": tam.levels,
        "sizes": sizes,
        "seed": tam.seed,
        "stroke": {"width_px": _round(tam.width), "length": _round(tam.length),
                   "length_jitter": _round(tam.length_jitter),
                   "angles_deg": [_round(a) for a in tam.angles],
                   "angle_jitter_deg": _round(tam.angle_jitter), "candidates": tam.candidates},
        "total_strokes": int(tam.strokes.size),
        "texels": ("8-bit PNG, sRGB-encoded (decode as sRGB to get the linear value); value = paper "
                   "reflectance, 1 paper, 0 ink; darkness = 1 - mean value"),
        "addressing": "REPEAT (the images tile); texel (row i, column j) at u = (j + 0.5) / N, v = (i + 0.5) / N",
        "mip": "level l is sizes[l] pixels; level 0 the finest; stroke width in pixels is the same at every level",
        "blending": ("tone t in [0, 1]: s = t * tones; blend images floor(s) and floor(s) + 1 of "
                     "[paper white, tone 0, ..., tone tones - 1] by frac(s)"),
        "per_tone": per_tone,
    }
    if atlas_files is not None:
        manifest["atlas"] = {
            "files": atlas_files,
            "channels": [[3 * a + c if 3 * a + c < tam.tones else None for c in range(3)]
                         for a in range(len(atlas_files))],
            "note": "atlas a, channel c (R, G, B) holds tone 3 a + c; null channels are paper white",
        }
    return manifest


def write_tam(folder, tam, *, atlas=True, preview=True, force=False):
    """Write ``tam`` into ``folder``: ``tone{k}_mip{l}.png`` (8-bit grey, one per
    tone and level), with ``atlas`` also ``atlas{a}_mip{l}.png`` (8-bit RGB,
    :func:`tam_atlas`), with ``preview`` a ``preview.png`` of the tones at
    level 0 (:func:`preview_image`), and ``manifest.json`` (tones, sizes,
    seed, stroke parameters, per tone its target darkness, the achieved
    darkness per level, the strokes added and present per level and its
    files).  Atomic (:func:`pbrkit.core.atomic.atomic_directory`): all files
    or none; an existing non-empty ``folder`` is refused unless ``force``.
    PNGs are sRGB-encoded (CONVENTIONS "Colour") and deterministic.  Returns
    the folder as a Path."""
    _check_tam(tam)
    files = [[f"tone{k}_mip{m}.png" for m in range(tam.levels)] for k in range(tam.tones)]
    packed = tam_atlas(tam) if atlas else None
    atlas_files = None if packed is None else [[f"atlas{a}_mip{m}.png" for m in range(tam.levels)]
                                               for a in range(packed[0].shape[0])]
    manifest = _manifest(tam, files, atlas_files)
    with atomic_directory(folder, force) as tmp:
        for k in range(tam.tones):
            for m in range(tam.levels):
                write_png(tmp / files[k][m], tam.images[m][k])
        if packed is not None:
            for a in range(len(atlas_files)):
                for m in range(tam.levels):
                    write_png(tmp / atlas_files[a][m], packed[m][a])
        if preview:
            write_png(tmp / "preview.png", preview_image(tam))
        (tmp / "manifest.json").write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")
    return Path(folder)
