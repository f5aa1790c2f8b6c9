"""Image-space outlines from G-buffers: edge responses, outline coverage of a
given width in pixels, the anti-aliased coverage of 2D line segments, and the
blend of an outline colour over an image.

Method (Saito and Takahashi, "Comprehensible Rendering of 3-D Shapes",
SIGGRAPH 1990, sec. 3-4: edges are discontinuities of the depth buffer and of
its derivatives, found with a differential operator and thresholded; Decaudin,
"Cartoon-Looking Rendering of 3D-Scenes", INRIA research report 2919, 1996,
sec. 3: discontinuities of the depth buffer and of the normal buffer give the
silhouettes and the creases).  Object and material ids add the edges between
two objects or two materials that touch: any change of id is an edge.

Buffers (all optional, at least one given, all of one image size (H, W)):

- ``depth`` (H, W): distance from the camera, either the distance along the
  camera ray of the pixel centre (the ray parameter ``t`` of a ray caster with
  unit directions, :meth:`pbrkit.rendering.scene.Camera.ray_directions`: what the
  renderer gives) or the view depth along the camera's -Z.  Only ratios of
  depths are used, so the responses do not change when the scene is scaled.
  Background: any non-finite (inf, NaN) or non-positive depth.
- ``normal`` (H, W, 3): surface normals, any length (they are normalised); a
  zero or non-finite normal marks a pixel without a surface.
- ``object_id``, ``material_id`` (H, W) integers, the background any value of
  its own (e.g. -1).

Pair discontinuities.  Every operator is a stencil of pixel pairs (p, q = p + s);
the discontinuity d of a pair is, per buffer:

- depth: the plane-compensated relative step.  With w = 1 / depth (0 for the
  background) extrapolate each side linearly across the pair,
  a = |w_q - (2 w_p - w_{p-s})| and b = |w_p - (2 w_q - w_{q+s})|, and take
  d = min(a, b) / max(w_p, w_q), clamped to [0, 1].  The inverse view depth is
  an affine function of the image coordinates on a plane (perspective
  projection), so a plane gives d = 0 at any incidence with the view depth
  (with the ray distance, whose inverse is that times the cosine of the ray's
  angle to the view axis, at most 1.2e-3 measured on a floor seen through
  fields of view of 60 to 120 degrees at 128 pixels, away from its horizon:
  far below the default threshold 0.02); a step from depth z1 to a
  parallel surface at z2 > z1 gives 1 - z1 / z2 (the step relative to the
  farther depth) and a surface against the background gives 1.  These are
  Saito and Takahashi's first- and second-order differentials of depth made
  scale-free and exact on planes (a first-order relative step alone flags
  planes seen at grazing incidence).  Beyond the image border the inverse depth
  is continued linearly.
- normal: the angle between the two unit normals, in degrees (0 where either
  pixel has no normal: depth and ids mark the silhouettes).
- ids: 1 where the two ids differ, else 0.

Operators (``operator``), each giving an ideal straight step its own
discontinuity as response (depth: the relative step, normal: the angle, ids: 1):

- ``"crack"`` (the default): the pairs of 4-neighbours, i.e. the crack edges
  between pixels (Rosenfeld and Kak, "Digital Picture Processing", 2nd ed.,
  1982, sec. 10.4): response [i, j, 0] of the pair ((i, j), (i, j + 1)) sits at
  the midpoint (i + 0.5, j + 1), [i, j, 1] of ((i, j), (i + 1, j)) at
  (i + 1, j + 0.5) (pairs leaving the image respond 0).  The outline's centre
  line joins these midpoints as marching squares would (below), so it lies on a
  straight step at any orientation.
- ``"roberts"`` (Roberts cross, 2 x 2): the two diagonal pairs of the block
  whose top-left pixel is (i, j); response max(d_1, d_2) at the block's centre,
  the pixel corner (i + 1, j + 1) (row H - 1 and column W - 1 respond 0).
- ``"sobel"`` (Sobel, 3 x 3): pairs two pixels apart across the pixel, weighted
  (1/4, 1/2, 1/4) along the other axis, g_x = sum_k w_k d(p + (k, -1), p + (k, 1)),
  g_y likewise, response sqrt(g_x^2 + g_y^2) at the pixel centre (i + 0.5,
  j + 0.5): a step responds on the two pixels beside it (up to four across a
  45-degree step).

The 2 x 2 and 3 x 3 operators answer on bands that widen on diagonal edges
(Roberts by up to 0.7 pixel, Sobel by up to 1.4), so their outlines are wider
there (measured with a 3-pixel outline around a sphere: 18 % and 25 % more
ink than a 3-pixel band, against 2 % for crack edges).  Where a response is
above its threshold (``thresholds``, :data:`DEFAULT_THRESHOLDS`: depth 0.02,
normal 40 degrees, ids 0.25, i.e. any change of id for the crack and Roberts
operators, and for Sobel a change across the pixel's middle pair or across
two outer pairs) there is an edge point.

Centre lines (:meth:`EdgeResponses.centerlines`).  Crack edges: at each pixel
corner, two edge cracks among its four are joined by the segment between their
midpoints (marching squares; Lorensen and Cline, SIGGRAPH 1987, in 2D); one,
three or four are each joined to the corner (so a line runs to the image
border, and junctions meet); then one Laplacian smoothing step moves each
vertex joined to exactly two others to v / 2 + (n_1 + n_2) / 4, which halves
the half-pixel zigzag of the crack midpoints along edges that are neither
axis-aligned nor diagonal and leaves straight runs where they are.  Roberts
corners and Sobel centres: every two edge points 8-adjacent are joined, a
point alone is kept as a dot.

Outline coverage (:func:`outline_mask`).  A pixel's coverage is the
box-filtered overlap of the pixel with a band of full width ``width_px``
around the centre lines: with x the distance from the pixel centre to the
nearest centre line (exact Euclidean distance to the segments, computed per
segment in a window around it: a distance transform of the centre lines),
plus delta (0.5 for Sobel, whose points sit half a pixel either side of a
step; else 0), coverage = clamp(min(x + 1/2, w/2) - max(x - 1/2, -w/2), 0, 1).
Across a straight edge the coverage sums to ``width_px`` (any real width).
``antialias=False`` rounds it (coverage >= 1/2 gives 1; an edge lies between
two pixels, so an odd width rounds up to the next even one).  With
``supersample = k`` the buffers hold k x k samples per pixel (kH, kW): the
outline is made at that resolution with width k * width_px and box-filtered
down to (H, W).  (A distance transform of the edge pixels,
:func:`scipy.ndimage.distance_transform_edt`, measures distances to sample
points rather than to the line through them: on corner or crack points that
is up to 0.2 pixel too far on each side, hence the exact segment distance.)

Coverage is linear (a fraction of the pixel); :func:`composite` blends a
colour over a linear image with it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.jit import dual_use, kernel, row_kernel, select

__all__ = [
    "OPERATORS",
    "DEFAULT_THRESHOLDS",
    "EdgeResponses",
    "edge_strength",
    "outline_mask",
    "line_coverage",
    "composite",
]

OPERATORS = ("crack", "roberts", "sobel")
#: Default thresholds: depth (relative step), normal (degrees), ids (any change).
DEFAULT_THRESHOLDS = {"depth": 0.02, "normal": 40.0, "object_id": 0.25, "material_id": 0.25}
_CHANNELS = ("depth", "normal", "object_id", "material_id")
_PAD = 3  # the Sobel pairs with their extrapolation reach 3 pixels from the centre
_MAX_WIDTH = 256.0


# ------------------------------------------------------------------ input checks


def _is_real(value):
    return not isinstance(value, (bool, np.bool_)) and isinstance(value, (int, float, np.integer, np.floating))


def _thresholds(thresholds):
    th = dict(DEFAULT_THRESHOLDS)
    if thresholds is None:
        return th
    if not hasattr(thresholds, "items"):
        raise ValueError(f"thresholds must be a mapping of {', '.join(_CHANNELS)} to numbers; got {thresholds!r}")
    for key, value in thresholds.items():
        if key not in th:
            raise ValueError(f"thresholds: unknown key {key!r}; valid keys: {', '.join(_CHANNELS)}")
        if value is not None:
            if not _is_real(value) or not math.isfinite(value) or value < 0:
                raise ValueError(f"thresholds[{key!r}] must be a finite number >= 0 or None; got {value!r}")
            value = float(value)
        th[key] = value
    return th


def _width(width_px):
    if not _is_real(width_px) or not 0.0 < width_px <= _MAX_WIDTH:
        raise ValueError(f"width_px must be a number in (0, {_MAX_WIDTH:g}]; got {width_px!r}")
    return float(width_px)


def _buffers(depth, normal, object_id, material_id):
    """The buffers as float64 / int64 arrays of one image size, and that size."""
    out = {}
    shape = None

    def agree(name, hw):
        nonlocal shape
        if hw[0] < 1 or hw[1] < 1:
            raise ValueError(f"{name} must not be empty; got image size {hw}")
        if shape is None:
            shape = hw
        elif hw != shape:
            raise ValueError(f"{name} has image size {hw}, the other buffers {shape}")

    if depth is not None:
        d = np.asarray(depth)
        if d.ndim != 2 or not (np.issubdtype(d.dtype, np.floating) or np.issubdtype(d.dtype, np.integer)):
            raise ValueError(f"depth must be a real (H, W) array; got {d.dtype} {d.shape}")
        agree("depth", d.shape)
        out["depth"] = d.astype(np.float64, copy=False)
    if normal is not None:
        n = np.asarray(normal)
        if n.ndim != 3 or n.shape[-1] != 3 or not (np.issubdtype(n.dtype, np.floating)
                                                    or np.issubdtype(n.dtype, np.integer)):
            raise ValueError(f"normal must be a real (H, W, 3) array; got {n.dtype} {n.shape}")
        agree("normal", n.shape[:2])
        out["normal"] = n.astype(np.float64, copy=False)
    for name, ids in (("object_id", object_id), ("material_id", material_id)):
        if ids is not None:
            a = np.asarray(ids)
            if a.ndim != 2 or not (np.issubdtype(a.dtype, np.integer) or a.dtype == np.bool_):
                raise ValueError(f"{name} must be an integer (H, W) array; got {a.dtype} {a.shape}")
            agree(name, a.shape)
            out[name] = a.astype(np.int64, copy=False)
    if not out:
        raise ValueError("give at least one of depth, normal, object_id, material_id")
    return out, shape


def _operator(operator):
    if not isinstance(operator, str) or operator not in OPERATORS:
        raise ValueError(f"operator must be one of {', '.join(OPERATORS)}; got {operator!r}")
    return operator


# ------------------------------------------------------------- pair discontinuities


def _view(padded, di, dj, shape):
    """The (H, W) window of an array padded by _PAD, shifted by (di, dj)."""
    h, w = shape
    return padded[_PAD + di:_PAD + di + h, _PAD + dj:_PAD + dj + w]


def _pad(a, linear=False):
    """``a`` padded by _PAD: repeating the border (normals, ids, masks), or with
    ``linear`` continuing it linearly (inverse depth: a plane stays a plane)."""
    widths = ((_PAD, _PAD), (_PAD, _PAD)) + ((0, 0),) * (a.ndim - 2)
    if linear:
        return np.pad(a, widths, mode="reflect", reflect_type="odd")
    return np.pad(a, widths, mode="edge")


@dual_use
def depth_step(w_p, w_q, w_pp, w_qq, v_p, v_q, v_pp, v_qq):
    """Plane-compensated relative depth step of the pair (p, q) (module docstring)
    from the inverse depths w and validity v of p, q, the pixel beyond p (pp) and
    the one beyond q (qq): constant extrapolation next to the background, 1 where
    one side is background, 0 where both are."""
    pred_q = select(v_pp, 2.0 * w_p - w_pp, w_p)
    pred_p = select(v_qq, 2.0 * w_q - w_qq, w_q)
    big = np.maximum(w_p, w_q)
    d = np.minimum(np.abs(w_q - pred_q), np.abs(w_p - pred_p)) / select(big > 0.0, big, 1.0)
    d = select(v_p & v_q, np.minimum(d, 1.0), 0.0)
    return select(v_p ^ v_q, 1.0, d)


@dual_use
def normal_angle(ax, ay, az, bx, by, bz):
    """The angle (degrees) between unit normals a and b from the half chord
    |a - b| / 2 = sin(angle / 2) (accurate at small angles too)."""
    dx = ax - bx
    dy = ay - by
    dz = az - bz
    half = 0.5 * np.sqrt(dx * dx + dy * dy + dz * dz)
    return 2.0 * np.arcsin(np.minimum(half, 1.0)) * (180.0 / math.pi)


def _depth_pair(wp, valid, p, s, shape):
    """:func:`depth_step` of the pairs (p, p + s) of every pixel; ``wp``,
    ``valid``: padded inverse depth and mask."""
    q = (p[0] + s[0], p[1] + s[1])
    pp = (p[0] - s[0], p[1] - s[1])                         # beyond p
    qq = (q[0] + s[0], q[1] + s[1])                         # beyond q
    w = [_view(wp, *o, shape) for o in (p, q, pp, qq)]
    v = [_view(valid, *o, shape) for o in (p, q, pp, qq)]
    return depth_step(*w, *v)


def _normal_pair(npad, valid, p, s, shape):
    q = (p[0] + s[0], p[1] + s[1])
    a, b = _view(npad, *p, shape), _view(npad, *q, shape)
    angle = normal_angle(a[..., 0], a[..., 1], a[..., 2], b[..., 0], b[..., 1], b[..., 2])
    return np.where(_view(valid, *p, shape) & _view(valid, *q, shape), angle, 0.0)


def _id_pair(ipad, p, s, shape):
    q = (p[0] + s[0], p[1] + s[1])
    return (_view(ipad, *p, shape) != _view(ipad, *q, shape)).astype(np.float64)


@row_kernel(2)
def _crack_depth(start, stop, wp, vp, out):
    """The ``"crack"`` responses of :func:`depth_step` (padded inputs, pairs leaving
    the image 0) in one pass."""
    h, w = out.shape[0], out.shape[1]
    for i in range(start, stop):
        a = i + _PAD
        for j in range(w):
            b = j + _PAD
            out[i, j, 0] = 0.0 if j == w - 1 else depth_step(
                wp[a, b], wp[a, b + 1], wp[a, b - 1], wp[a, b + 2], vp[a, b], vp[a, b + 1], vp[a, b - 1], vp[a, b + 2])
            out[i, j, 1] = 0.0 if i == h - 1 else depth_step(
                wp[a, b], wp[a + 1, b], wp[a - 1, b], wp[a + 2, b], vp[a, b], vp[a + 1, b], vp[a - 1, b], vp[a + 2, b])


@row_kernel(1)
def _crack_normal(start, stop, npad, out):
    """The ``"crack"`` responses of :func:`normal_angle` of the normalised normals
    (0 where either side has no normal: zero or non-finite length) in one pass."""
    h, w = out.shape[0], out.shape[1]
    for i in range(start, stop):
        a = i + _PAD
        for j in range(w):
            b = j + _PAD
            la = math.sqrt(npad[a, b, 0] ** 2 + npad[a, b, 1] ** 2 + npad[a, b, 2] ** 2)
            for k in range(2):
                c, d = (a, b + 1) if k == 0 else (a + 1, b)
                lc = math.sqrt(npad[c, d, 0] ** 2 + npad[c, d, 1] ** 2 + npad[c, d, 2] ** 2)
                last = j == w - 1 if k == 0 else i == h - 1
                if last or not (math.isfinite(la) and la > 0.0 and math.isfinite(lc) and lc > 0.0):
                    out[i, j, k] = 0.0
                else:
                    out[i, j, k] = normal_angle(npad[a, b, 0] / la, npad[a, b, 1] / la, npad[a, b, 2] / la,
                                                npad[c, d, 0] / lc, npad[c, d, 1] / lc, npad[c, d, 2] / lc)


@row_kernel(1)
def _crack_ids(start, stop, ipad, out):
    """The ``"crack"`` responses of an id buffer (1 on a change) in one pass."""
    h, w = out.shape[0], out.shape[1]
    for i in range(start, stop):
        a = i + _PAD
        for j in range(w):
            b = j + _PAD
            out[i, j, 0] = 0.0 if j == w - 1 or ipad[a, b] == ipad[a, b + 1] else 1.0
            out[i, j, 1] = 0.0 if i == h - 1 or ipad[a, b] == ipad[a + 1, b] else 1.0


def _crack(kernel, shape, *padded):
    out = np.empty(shape + (2,))
    kernel(*(np.ascontiguousarray(x) for x in padded), out)
    return out


def _combine(pair, operator, shape):
    """Responses from a pair function ``pair(p, s)`` (offsets from the pixel)."""
    if operator == "crack":
        r = np.stack([pair((0, 0), (0, 1)), pair((0, 0), (1, 0))], axis=-1)
        r[:, -1, 0] = 0.0
        r[-1, :, 1] = 0.0
        return r
    if operator == "roberts":
        r = np.maximum(pair((0, 0), (1, 1)), pair((0, 1), (1, -1)))
        r[-1, :] = 0.0
        r[:, -1] = 0.0
        return r
    # Sobel: the central pairs once for every pixel, then [1, 2, 1] / 4 across.
    dx = np.pad(pair((0, -1), (0, 2)), 1, mode="edge")
    dy = np.pad(pair((-1, 0), (2, 0)), 1, mode="edge")
    h, w = shape
    gx = 0.25 * dx[0:h, 1:w + 1] + 0.5 * dx[1:h + 1, 1:w + 1] + 0.25 * dx[2:h + 2, 1:w + 1]
    gy = 0.25 * dy[1:h + 1, 0:w] + 0.5 * dy[1:h + 1, 1:w + 1] + 0.25 * dy[1:h + 1, 2:w + 2]
    return np.hypot(gx, gy)


@dataclass(frozen=True)
class EdgeResponses:
    """Edge responses of G-buffers (module docstring), each float64 or None where
    that buffer was not given: ``depth`` (relative step, [0, 1]), ``normal``
    (degrees), ``object_id`` and ``material_id`` (1 on a change).  Each is
    (H, W) for ``"roberts"`` (at pixel corners (i + 1, j + 1)) and ``"sobel"``
    (at pixel centres (i + 0.5, j + 0.5)), and (H, W, 2) for ``"crack"``
    ([..., 0]: with the right neighbour, at (i + 0.5, j + 1); [..., 1]: with the
    neighbour below, at (i + 1, j + 0.5))."""

    depth: np.ndarray | None
    normal: np.ndarray | None
    object_id: np.ndarray | None
    material_id: np.ndarray | None
    operator: str

    def _first(self):
        return next(getattr(self, c) for c in _CHANNELS if getattr(self, c) is not None)

    @property
    def shape(self):
        """The image size (H, W)."""
        return self._first().shape[:2]

    def edges(self, thresholds=None):
        """Bool array of the responses' shape: above its threshold in any buffer.
        ``thresholds`` maps ``depth``, ``normal``, ``object_id``, ``material_id``
        to a number (or None: that buffer makes no edges); missing keys take
        :data:`DEFAULT_THRESHOLDS`."""
        th = _thresholds(thresholds)
        mask = np.zeros(self._first().shape, dtype=bool)
        for name in _CHANNELS:
            r = getattr(self, name)
            if r is not None and th[name] is not None:
                mask |= r > th[name]
        return mask

    def centerlines(self, thresholds=None):
        """``(segments, delta)``: the centre lines of the edges (module
        docstring) as (M, 2, 2) segments of image coordinates (row, column),
        pixel (i, j) covering [i, i + 1] x [j, j + 1], in a deterministic order,
        and the distance delta (pixels) from them to the edge they stand for
        (0.5 for Sobel, else 0)."""
        e = self.edges(thresholds)
        if self.operator == "crack":
            return _crack_centerlines(e[..., 0], e[..., 1]), 0.0
        offset = 1.0 if self.operator == "roberts" else 0.5
        return _point_centerlines(e, offset), (0.5 if self.operator == "sobel" else 0.0)


def edge_strength(depth=None, normal=None, object_id=None, material_id=None, operator="crack"):
    """Edge responses of the given G-buffers (module docstring: Saito and
    Takahashi 1990; Decaudin 1996) as an :class:`EdgeResponses`.

    ``depth`` (H, W): ray distance t along unit camera rays (or view depth);
    inf / NaN / <= 0 is the background.  ``normal`` (H, W, 3).  ``object_id``,
    ``material_id`` (H, W) integers.  ``operator``: ``"crack"`` (4-neighbour
    pairs), ``"roberts"`` (2 x 2) or ``"sobel"`` (3 x 3)."""
    operator = _operator(operator)
    bufs, shape = _buffers(depth, normal, object_id, material_id)
    out = dict.fromkeys(_CHANNELS)
    if "depth" in bufs:
        z = bufs["depth"]
        valid = np.isfinite(z) & (z > 0.0)
        w = np.where(valid, 1.0 / np.where(valid, z, 1.0), 0.0)
        wp, vp = _pad(w, linear=True), _pad(valid)
        out["depth"] = (_crack(_crack_depth, shape, wp, vp) if operator == "crack" else
                        _combine(lambda p, s: _depth_pair(wp, vp, p, s, shape), operator, shape))
    if "normal" in bufs and operator == "crack":
        out["normal"] = _crack(_crack_normal, shape, _pad(bufs["normal"]))
    elif "normal" in bufs:
        n = bufs["normal"]
        with np.errstate(over="ignore", invalid="ignore"):
            length = np.sqrt(np.einsum("ijk,ijk->ij", n, n))
        valid = np.isfinite(length) & (length > 0.0)
        with np.errstate(invalid="ignore"):
            unit = np.where(valid[..., None], n / np.where(valid, length, 1.0)[..., None], 0.0)
        npad, vp = _pad(unit), _pad(valid)
        out["normal"] = _combine(lambda p, s: _normal_pair(npad, vp, p, s, shape), operator, shape)
    for name in ("object_id", "material_id"):
        if name in bufs:
            ipad = _pad(bufs[name])
            out[name] = (_crack(_crack_ids, shape, ipad) if operator == "crack" else
                         _combine(lambda p, s, ipad=ipad: _id_pair(ipad, p, s, shape), operator, shape))
    return EdgeResponses(operator=operator, **out)


# ----------------------------------------------------------------- centre lines


def _segments(a_rows, a_cols, b_rows, b_cols):
    return np.stack([np.stack([a_rows, a_cols], axis=-1), np.stack([b_rows, b_cols], axis=-1)], axis=1)


def _crack_centerlines(right, down):
    """Marching-squares centre lines of crack edges: ``right`` (H, W) the pairs
    ((i, j), (i, j + 1)), ``down`` the pairs ((i, j), (i + 1, j))."""
    h, w = right.shape
    # The four arms of every pixel corner (a, b), 0 <= a <= H, 0 <= b <= W:
    # north = right[a - 1, b - 1], south = right[a, b - 1], west = down[a - 1, b - 1], east = down[a - 1, b].
    rp = np.zeros((h + 2, w + 2), dtype=bool)
    rp[1:h + 1, 1:w + 1] = right
    dp = np.zeros((h + 2, w + 2), dtype=bool)
    dp[1:h + 1, 1:w + 1] = down
    arms = {
        "n": rp[0:h + 1, 0:w + 1], "s": rp[1:h + 2, 0:w + 1],
        "w": dp[0:h + 1, 0:w + 1], "e": dp[0:h + 1, 1:w + 2],
    }
    mid = {"n": (-0.5, 0.0), "s": (0.5, 0.0), "w": (0.0, -0.5), "e": (0.0, 0.5)}  # from the corner
    count = sum(a.astype(np.int8) for a in arms.values())
    parts = []
    for x, y in (("n", "s"), ("n", "e"), ("n", "w"), ("s", "e"), ("s", "w"), ("e", "w")):
        a, b = np.nonzero(arms[x] & arms[y] & (count == 2))
        parts.append(_segments(a + mid[x][0], b + mid[x][1], a + mid[y][0], b + mid[y][1]))
    for x in ("n", "s", "w", "e"):
        a, b = np.nonzero(arms[x] & (count != 2))
        parts.append(_segments(a + mid[x][0], b + mid[x][1], a.astype(np.float64), b.astype(np.float64)))
    return _smooth_polylines(np.concatenate(parts).astype(np.float64))


def _smooth_polylines(seg):
    """One Laplacian smoothing step of the vertices of degree two of a segment
    graph (M, 2, 2) whose vertices lie on the half-pixel grid: v <- v / 2 +
    (n_1 + n_2) / 4.  The crack midpoints of a straight edge zigzag by up to
    half a pixel at slopes other than 0 and 45 degrees; the step halves that
    (so that the band around them keeps its width), and leaves collinear
    vertices (axis-aligned and diagonal runs) where they are."""
    if not len(seg):
        return seg
    ends = seg.reshape(-1, 2)
    key = np.rint(ends * 2.0).astype(np.int64)
    _, vertex = np.unique(key[:, 0] * (int(key[:, 1].max()) + 2) + key[:, 1], return_inverse=True)
    vertex = vertex.reshape(-1, 2)
    nv = int(vertex.max()) + 1
    a, b = vertex[:, 0], vertex[:, 1]
    link = a != b
    degree = np.bincount(a[link], minlength=nv) + np.bincount(b[link], minlength=nv)
    pos = np.zeros((nv, 2))
    pos[vertex.ravel()] = ends
    total = np.stack([np.bincount(a[link], pos[b[link], c], nv) + np.bincount(b[link], pos[a[link], c], nv)
                      for c in range(2)], axis=-1)
    two = degree == 2
    pos[two] = 0.5 * pos[two] + 0.25 * total[two]
    return pos[vertex]


def _point_centerlines(points, offset):
    """Segments joining 8-adjacent edge points (H, W) at (i + offset, j + offset);
    a point with no neighbour is a dot."""
    h, w = points.shape
    p = np.zeros((h + 2, w + 2), dtype=bool)
    p[1:h + 1, 1:w + 1] = points
    centre = p[1:h + 1, 1:w + 1]
    parts = []
    lonely = centre.copy()
    for di, dj in ((0, 1), (1, 0), (1, 1), (1, -1), (0, -1), (-1, 0), (-1, -1), (-1, 1)):
        nb = p[1 + di:h + 1 + di, 1 + dj:w + 1 + dj]
        lonely &= ~nb
        if (di, dj) in ((0, 1), (1, 0), (1, 1), (1, -1)):
            i, j = np.nonzero(centre & nb)
            parts.append(_segments(i + offset, j + offset, i + di + offset, j + dj + offset))
    i, j = np.nonzero(lonely)
    parts.append(_segments(i + offset, j + offset, i + offset, j + offset))
    return np.concatenate(parts).astype(np.float64)


# ------------------------------------------------------------------ line coverage


@kernel
def _raster_kernel(seg, inv_z, zmax, use_depth, bias, width, offset, cov, best):
    """Anti-aliased coverage of 2D segments (M, 2, 2) (rows, cols), max over
    segments, into ``cov`` (H, W); ``best`` gets the index of the segment of
    largest coverage (the first on ties).  With ``use_depth``: a pixel is drawn
    where the segment point nearest to it has view depth 1 / lerp(inv_z) not
    beyond ``zmax`` (1 + bias) at the pixel holding that point."""
    h, w = cov.shape
    half = 0.5 * width
    reach = half + 0.5 - offset  # no coverage beyond this distance from the segment
    if reach <= 0.0:
        return
    for k in range(seg.shape[0]):
        r0, c0, r1, c1 = seg[k, 0, 0], seg[k, 0, 1], seg[k, 1, 0], seg[k, 1, 1]
        if not (math.isfinite(r0) and math.isfinite(c0) and math.isfinite(r1) and math.isfinite(c1)):
            continue
        dr, dc = r1 - r0, c1 - c0
        # Liang-Barsky clip to the image grown by the reach: only the pixel sweep uses it.
        s0, s1 = 0.0, 1.0
        inside = True
        for p, q in ((-dr, r0 + reach), (dr, h + reach - r0), (-dc, c0 + reach), (dc, w + reach - c0)):
            if p == 0.0:
                if q < 0.0:
                    inside = False
            else:
                t = q / p
                if p < 0.0:
                    s0 = max(s0, t)
                else:
                    s1 = min(s1, t)
        if not inside or s0 > s1:
            continue
        ra, ca, rb, cb = r0 + s0 * dr, c0 + s0 * dc, r0 + s1 * dr, c0 + s1 * dc
        len2 = dr * dr + dc * dc
        major_cols = abs(dc) >= abs(dr)
        # sweep the major axis (u), find the range of the minor one (v) at each step
        if major_cols:
            ua, va, ub, vb, nu, nv = ca, ra, cb, rb, w, h
        else:
            ua, va, ub, vb, nu, nv = ra, ca, rb, cb, h, w
        umin, umax = min(ua, ub), max(ua, ub)
        u0 = max(0, int(math.ceil(umin - reach - 0.5)))
        u1 = min(nu - 1, int(math.floor(umax + reach - 0.5)))
        for iu in range(u0, u1 + 1):
            x = iu + 0.5
            xl, xh = max(x - reach, umin), min(x + reach, umax)
            if xl > xh:
                continue
            if ub != ua:
                yl = va + (xl - ua) * (vb - va) / (ub - ua)
                yh = va + (xh - ua) * (vb - va) / (ub - ua)
            else:
                yl, yh = va, vb
            lo, hi = min(yl, yh) - reach, max(yl, yh) + reach
            v0 = max(0, int(math.ceil(lo - 0.5)))
            v1 = min(nv - 1, int(math.floor(hi - 0.5)))
            for iv in range(v0, v1 + 1):
                i, j = (iv, iu) if major_cols else (iu, iv)
                y, xx = i + 0.5, j + 0.5
                s = 0.0
                if len2 > 0.0:
                    s = min(max(((y - r0) * dr + (xx - c0) * dc) / len2, 0.0), 1.0)
                qy, qx = r0 + s * dr, c0 + s * dc
                dist = math.sqrt((y - qy) ** 2 + (xx - qx) ** 2) + offset
                c = min(dist + 0.5, half) - max(dist - 0.5, -half)
                if c <= 0.0 or c <= cov[i, j]:
                    continue
                c = min(c, 1.0)
                if use_depth:
                    z = 1.0 / ((1.0 - s) * inv_z[k, 0] + s * inv_z[k, 1])
                    pi = min(max(int(math.floor(qy)), 0), h - 1)
                    pj = min(max(int(math.floor(qx)), 0), w - 1)
                    if not z <= zmax[pi, pj] * (1.0 + bias):
                        continue
                cov[i, j] = c
                best[i, j] = k


def _rasterize(seg, shape, width, offset=0.0, inv_z=None, zmax=None, bias=0.0):
    """(coverage (H, W), index of the segment of largest coverage or -1)."""
    h, w = shape
    cov = np.zeros((h, w), dtype=np.float64)
    best = np.full((h, w), -1, dtype=np.int64)
    seg = np.ascontiguousarray(seg, dtype=np.float64).reshape(-1, 2, 2)
    use_depth = inv_z is not None
    if not use_depth:
        inv_z = np.ones((len(seg), 2))
        zmax = np.full((1, 1), np.inf)
    if len(seg):
        _raster_kernel(seg, np.ascontiguousarray(inv_z, dtype=np.float64), np.ascontiguousarray(zmax, dtype=np.float64),
                       use_depth, float(bias), float(width), float(offset), cov, best)
    return cov, best


def line_coverage(segments, shape, width_px=1.0):
    """Anti-aliased coverage (H, W) float64 in [0, 1] of 2D line segments
    ``segments`` (M, 2, 2) in image coordinates (row, column; pixel (i, j)
    covers [i, i + 1] x [j, j + 1], its centre is (i + 0.5, j + 0.5)), each a
    band of full width ``width_px`` with round caps: a pixel's coverage is
    clamp(min(x + 1/2, w/2) - max(x - 1/2, -w/2), 0, 1) with x the distance
    from its centre to the segment (the box filter across a straight band, so
    the coverage across a line sums to its width), the largest over the
    segments where they overlap.  Rasterised segment by segment over the
    pixels within reach (a compiled loop)."""
    seg = np.asarray(segments, dtype=np.float64)
    if seg.ndim != 3 or seg.shape[1:] != (2, 2):
        raise ValueError(f"segments must have shape (M, 2, 2); got {seg.shape}")
    if not np.all(np.isfinite(seg)):
        raise ValueError("segments must be finite")
    if len(shape) != 2 or any(isinstance(x, bool) or not isinstance(x, (int, np.integer)) or x < 1 for x in shape):
        raise ValueError(f"shape must be (H, W) positive integers; got {shape!r}")
    return _rasterize(seg, (int(shape[0]), int(shape[1])), _width(width_px))[0]


# ------------------------------------------------------------------ outline mask


def outline_mask(depth=None, normal=None, object_id=None, material_id=None, *, thresholds=None,
                 width_px=1.0, antialias=True, operator="crack", supersample=1):
    """Outline coverage (H, W) float64 in [0, 1] of the G-buffers' edges
    (module docstring): the responses of :func:`edge_strength` above
    ``thresholds`` (a mapping of ``depth`` (relative step), ``normal``
    (degrees), ``object_id``, ``material_id`` to numbers, or None: no edges
    from that buffer; missing keys take :data:`DEFAULT_THRESHOLDS`), drawn as
    a line of full width ``width_px`` pixels (any real width in (0, 256])
    centred on their centre lines, anti-aliased (``antialias``) by the
    box-filtered overlap of each pixel with the line.  ``supersample = k``:
    the buffers hold k x k samples per output pixel (shape (k H, k W)); the
    result is box-filtered down to (H, W)."""
    operator = _operator(operator)
    th = _thresholds(thresholds)
    width = _width(width_px)
    k = supersample
    if isinstance(k, (bool, np.bool_)) or not isinstance(k, (int, np.integer)) or not 1 <= k <= 16:
        raise ValueError(f"supersample must be an integer in [1, 16]; got {supersample!r}")
    k = int(k)
    bufs, (hk, wk) = _buffers(depth, normal, object_id, material_id)
    if hk % k or wk % k:
        raise ValueError(f"buffers of image size {(hk, wk)} are not {k} x {k} samples per pixel (supersample = {k})")
    responses = edge_strength(**bufs, operator=operator)
    segments, delta = responses.centerlines(th)
    c = _rasterize(segments, (hk, wk), width * k, delta)[0]
    if not antialias:
        c = (c >= 0.5).astype(np.float64)
    if k > 1:
        c = c.reshape(hk // k, k, wk // k, k).mean(axis=(1, 3))
    return c


def composite(image, coverage, color):
    """``image (1 - coverage) + color coverage``: a linear blend of the outline
    colour over a linear image.  ``image`` (H, W, C), ``coverage`` (H, W) in
    [0, 1], ``color`` a number, (C,) or (H, W, C).  Returns a new float64
    (H, W, C) array."""
    img = np.asarray(image, dtype=np.float64)
    cov = np.asarray(coverage, dtype=np.float64)
    if img.ndim != 3:
        raise ValueError(f"image must have shape (H, W, C); got {img.shape}")
    if cov.shape != img.shape[:2]:
        raise ValueError(f"coverage must have shape {img.shape[:2]}; got {cov.shape}")
    if not np.all((cov >= 0.0) & (cov <= 1.0)):
        raise ValueError("coverage must be in [0, 1]")
    col = np.asarray(color, dtype=np.float64)
    if col.ndim not in (0, 1, 3) or (col.ndim == 1 and col.shape != img.shape[2:]) \
            or (col.ndim == 3 and col.shape != img.shape):
        raise ValueError(f"color must be a number, ({img.shape[2]},) or {img.shape}; got shape {col.shape}")
    if not np.all(np.isfinite(col)):
        raise ValueError("color must be finite")
    c = cov[..., None]
    return img * (1.0 - c) + col * c
