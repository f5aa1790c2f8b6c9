"""Cube-map geometry, layouts, seam-aware sampling and mip pyramids.

Conventions (``CONVENTIONS.md`` "Cube maps", the OpenGL / KTX / DDS layout):
faces in the order +X, -X, +Y, -Y, +Z, -Z; arrays (6, N, N, C) indexed
[face, row, column]; texel (row i, column j) has face coordinates
s = (j + 0.5) / N, t = (i + 0.5) / N, sc = 2s - 1, tc = 2t - 1 and direction
(OpenGL 4.6 core profile, sec. 8.13, table 8.19)::

    +X: ( 1, -tc, -sc)   -X: (-1, -tc,  sc)
    +Y: ( sc,  1,  tc)   -Y: ( sc, -1, -tc)
    +Z: ( sc, -tc,  1)   -Z: (-sc, -tc, -1)

The table is stored once, as the matrices ``_FACE_MATRIX[f]`` with
d = M_f (sc, tc, 1); since each M_f is a signed permutation, the inverse
(major axis -> face, sc, tc) uses the same matrices transposed.  In every face
the (s, t) frame is left-handed about the outward normal (the faces are laid
out "as seen from inside" in OpenGL's left-handed cube-map space).

Cross layouts (one image holding the six faces on a 4 x 3 or 3 x 4 grid of
N x N blocks, block (row, column); faces are stored exactly as in the cube
array, row 0 up, except where rotated):

- ``"hcross"`` (4N wide, 3N high)::

      .   +Y   .   .
      -X  +Z  +X  -Z
      .   -Y   .   .

- ``"vcross"`` (3N wide, 4N high), -Z rotated by 180 degrees::

      .   +Y   .
      -X  +Z  +X
      .   -Y   .
      .   -Z'  .

With the faces placed like this (unrotated, except -Z in the vertical cross,
which is turned upside down so that it joins -Y) the nets fold into the cube:
the texels on both sides of every shared edge of the image are neighbours on
the sphere (tested).  This is the common cross layout for cube maps stored
with OpenGL / DirectX face orientation.  Looking at the +Z block with
+Y up, +X is to the right: the image shows the world mirrored left-right
compared with a viewer inside a right-handed (+Y up) world, as every OpenGL
cube map does.

Solid angles are exact (the closed-form integral of the area element of the
face plane, :func:`cube_patch_solid_angle`), so they sum to 4 pi.
"""

from __future__ import annotations

import math

import numpy as np

from ..core import checks
from ..core.filtering import CLAMP_TO_EDGE, texel_pair
from ..core.jit import dual_use, row_kernel, select

__all__ = [
    "FACE_NAMES",
    "CROSS_LAYOUTS",
    "face_direction",
    "cube_face_coords",
    "direction_to_cube",
    "cube_texel_directions",
    "cube_patch_solid_angle",
    "cube_texel_solid_angles",
    "cube_integral",
    "cross_layout_of",
    "cube_from_cross",
    "cube_to_cross",
    "CubeSampler",
    "sample_cube",
    "build_mip_pyramid",
    "resample_cube",
    "mirror_cube",
]

FACE_NAMES = ("+X", "-X", "+Y", "-Y", "+Z", "-Z")

#: d = _FACE_MATRIX[f] @ (sc, tc, 1): OpenGL 4.6 table 8.19 (CONVENTIONS.md).
_FACE_MATRIX = np.array([
    [[0, 0, 1], [0, -1, 0], [-1, 0, 0]],    # +X: ( 1, -tc, -sc)
    [[0, 0, -1], [0, -1, 0], [1, 0, 0]],    # -X: (-1, -tc,  sc)
    [[1, 0, 0], [0, 0, 1], [0, 1, 0]],      # +Y: ( sc,  1,  tc)
    [[1, 0, 0], [0, 0, -1], [0, -1, 0]],    # -Y: ( sc, -1, -tc)
    [[1, 0, 0], [0, -1, 0], [0, 0, 1]],     # +Z: ( sc, -tc,  1)
    [[-1, 0, 0], [0, -1, 0], [0, 0, -1]],   # -Z: (-sc, -tc, -1)
], dtype=np.float64)

#: Block (row, column) of each face in the cross layouts, and whether the
#: block is rotated by 180 degrees.
CROSS_LAYOUTS = {
    "hcross": dict(grid=(3, 4), blocks=((1, 2), (1, 0), (0, 1), (2, 1), (1, 1), (1, 3)),
                   rotated=(False,) * 6),
    "vcross": dict(grid=(4, 3), blocks=((1, 2), (1, 0), (0, 1), (2, 1), (1, 1), (3, 1)),
                   rotated=(False, False, False, False, False, True)),
}


# ------------------------------------------------------------------ geometry


@dual_use
def face_direction(face, sc, tc):
    """Unnormalised direction (x, y, z) = M_face (sc, tc, 1) of face coordinates
    sc, tc in [-1, 1] (OpenGL 4.6 table 8.19, CONVENTIONS.md "Cube maps").
    ``face`` is an integer 0..5 (+X, -X, +Y, -Y, +Z, -Z); scalars or arrays."""
    m = _FACE_MATRIX
    x = m[face, 0, 0] * sc + m[face, 0, 1] * tc + m[face, 0, 2]
    y = m[face, 1, 0] * sc + m[face, 1, 1] * tc + m[face, 1, 2]
    z = m[face, 2, 0] * sc + m[face, 2, 1] * tc + m[face, 2, 2]
    return x, y, z


@dual_use
def cube_face_coords(x, y, z):
    """(face, sc, tc) of a direction by OpenGL's major-axis rule (OpenGL 4.6,
    sec. 8.13: the face of the largest-magnitude coordinate, sc and tc from
    table 8.19 divided by that magnitude).  Ties, which the specification
    leaves to the implementation, go to x over y over z; a zero coordinate
    counts as positive.  The inverse of :func:`face_direction`."""
    ax = np.abs(x)
    ay = np.abs(y)
    az = np.abs(z)
    face = select((ax >= ay) & (ax >= az), select(x >= 0.0, 0, 1),
                  select(ay >= az, select(y >= 0.0, 2, 3), select(z >= 0.0, 4, 5)))
    ma = np.maximum(ax, np.maximum(ay, az))
    m = _FACE_MATRIX
    sc = (m[face, 0, 0] * x + m[face, 1, 0] * y + m[face, 2, 0] * z) / ma
    tc = (m[face, 0, 1] * x + m[face, 1, 1] * y + m[face, 2, 1] * z) / ma
    return face, sc, tc


def direction_to_cube(d):
    """(face, s, t) for directions (..., 3): face index 0..5 (int64) and face
    coordinates s, t in [0, 1] (texel j = floor(s N), row i = floor(t N)).
    Directions need not be unit length."""
    d = checks.directions(d)
    face, sc, tc = cube_face_coords(d[..., 0], d[..., 1], d[..., 2])
    return np.asarray(face, dtype=np.int64), 0.5 * (np.asarray(sc) + 1.0), 0.5 * (np.asarray(tc) + 1.0)


def _check_size(n, what="cube size"):
    return checks.integer(n, what, 1, 32768)


def cube_texel_directions(n):
    """Unit directions (6, N, N, 3) of the texel centres of an N x N cube map."""
    n = _check_size(n)
    c = 2.0 * (np.arange(n) + 0.5) / n - 1.0
    tc, sc = np.meshgrid(c, c, indexing="ij")
    out = np.empty((6, n, n, 3))
    for f in range(6):
        out[f] = np.stack(face_direction(f, sc, tc), axis=-1)
    return out / np.linalg.norm(out, axis=-1, keepdims=True)


@dual_use
def _area_integral(x, y):
    """F(x, y) = atan2(x y, sqrt(x^2 + y^2 + 1)): the solid angle subtended by
    the rectangle [0, x] x [0, y] of the plane at unit distance."""
    return np.arctan2(x * y, np.sqrt(x * x + y * y + 1.0))


@dual_use
def cube_patch_solid_angle(x0, y0, x1, y1):
    """Exact solid angle of the face-plane rectangle [x0, x1] x [y0, y1] (face
    coordinates sc, tc in [-1, 1]): the integral of the area element
    dA / (1 + x^2 + y^2)^(3/2) is F(x1, y1) - F(x0, y1) - F(x1, y0) + F(x0, y0)
    with F(x, y) = atan2(x y, sqrt(1 + x^2 + y^2)) (R. Driscoll, "Cubemap
    texel solid angle", blog post, 2012, rorydriscoll.com)."""
    return (_area_integral(x1, y1) - _area_integral(x0, y1)
            - _area_integral(x1, y0) + _area_integral(x0, y0))


def cube_texel_solid_angles(n):
    """Exact solid angles (6, N, N) of the texels of an N x N cube map (the
    same on every face); they sum to 4 pi."""
    n = _check_size(n)
    e = 2.0 * np.arange(n + 1) / n - 1.0
    omega = cube_patch_solid_angle(e[None, :-1], e[:-1, None], e[None, 1:], e[1:, None])
    return np.broadcast_to(omega, (6, n, n)).copy()


def _as_cube(cube, what="cube"):
    c = np.asarray(cube)
    if c.ndim == 3:
        c = c[..., None]
    if c.ndim != 4 or c.shape[0] != 6 or c.shape[1] != c.shape[2] or c.shape[1] < 1:
        raise ValueError(f"{what} must have shape (6, N, N) or (6, N, N, C), got {np.shape(cube)}")
    if not np.issubdtype(c.dtype, np.floating):
        c = c.astype(np.float64)
    return c


def cube_integral(cube):
    """sum over texels of L * dOmega: the integral of the radiance over the
    sphere, shape (C,) (or a scalar for a (6, N, N) cube)."""
    c = _as_cube(cube)
    omega = cube_texel_solid_angles(c.shape[1])
    out = np.einsum("fij,fijc->c", omega, c.astype(np.float64))
    return out[0] if np.ndim(cube) == 3 else out


# ------------------------------------------------------------------- crosses


def cross_layout_of(shape):
    """``"hcross"`` for a 4:3 image, ``"vcross"`` for 3:4, else None."""
    h, w = shape[:2]
    if 3 * w == 4 * h and w % 4 == 0:
        return "hcross"
    if 4 * w == 3 * h and w % 3 == 0:
        return "vcross"
    return None


def cube_from_cross(image, layout=None):
    """Cube (6, N, N, C) from a cross image (see the module doc).  ``layout``
    is ``"hcross"``, ``"vcross"`` or None to choose by aspect ratio."""
    img = np.asarray(image)
    if img.ndim == 2:
        img = img[..., None]
    if img.ndim != 3:
        raise ValueError(f"cross image must have shape (H, W) or (H, W, C), got {np.shape(image)}")
    found = cross_layout_of(img.shape)
    layout = layout or found
    if layout not in CROSS_LAYOUTS:
        raise ValueError(f"image of {img.shape[1]}x{img.shape[0]} pixels is not a 4:3 (hcross) or 3:4 (vcross) "
                         "cube cross" if layout is None else f"unknown cross layout {layout!r}")
    rows, cols = CROSS_LAYOUTS[layout]["grid"]
    n = img.shape[1] // cols
    if img.shape[0] != rows * n or img.shape[1] != cols * n or n < 1:
        raise ValueError(f"image of {img.shape[1]}x{img.shape[0]} pixels does not fit the {layout} layout "
                         f"({cols}N x {rows}N)")
    spec = CROSS_LAYOUTS[layout]
    out = np.empty((6, n, n, img.shape[2]), dtype=img.dtype)
    for f, ((r, c), rot) in enumerate(zip(spec["blocks"], spec["rotated"])):
        block = img[r * n:(r + 1) * n, c * n:(c + 1) * n]
        out[f] = block[::-1, ::-1] if rot else block
    return out


def cube_to_cross(cube, layout="hcross", fill=0.0):
    """Cross image of a cube (inverse of :func:`cube_from_cross`); unused blocks
    are set to ``fill``."""
    c = _as_cube(cube)
    if layout not in CROSS_LAYOUTS:
        raise ValueError(f"unknown cross layout {layout!r}; use 'hcross' or 'vcross'")
    spec = CROSS_LAYOUTS[layout]
    rows, cols = spec["grid"]
    n = c.shape[1]
    out = np.full((rows * n, cols * n, c.shape[3]), fill, dtype=c.dtype)
    for f, ((r, col), rot) in enumerate(zip(spec["blocks"], spec["rotated"])):
        out[r * n:(r + 1) * n, col * n:(col + 1) * n] = c[f, ::-1, ::-1] if rot else c[f]
    return out[..., 0] if np.ndim(cube) == 3 else out


# ------------------------------------------------------------------ sampling


def _bordered(cube):
    """Faces (6, N + 2, N + 2, C) with a one-texel border copied from the
    neighbouring faces: each border texel centre, continued on the face plane
    beyond the edge, is projected onto the cube and takes the value of the
    texel it lands in (which is the adjacent face's edge texel of the same
    row or column); each corner of the border, where three faces meet, is the
    mean of the three texels around that cube corner."""
    n = cube.shape[1]
    out = np.zeros((6, n + 2, n + 2, cube.shape[3]), dtype=cube.dtype)
    out[:, 1:-1, 1:-1] = cube
    idx = np.arange(n)
    # border positions (row, column) in bordered coordinates: top, bottom, left, right
    pos_i = np.concatenate([np.zeros(n, int), np.full(n, n + 1), idx + 1, idx + 1])
    pos_j = np.concatenate([idx + 1, idx + 1, np.zeros(n, int), np.full(n, n + 1)])
    tc = 2.0 * (pos_i - 1 + 0.5) / n - 1.0
    sc = 2.0 * (pos_j - 1 + 0.5) / n - 1.0
    for f in range(6):
        x, y, z = face_direction(f, sc, tc)
        g, s2, t2 = cube_face_coords(x, y, z)
        si = np.minimum((0.5 * (s2 + 1.0) * n).astype(np.int64), n - 1)
        ti = np.minimum((0.5 * (t2 + 1.0) * n).astype(np.int64), n - 1)
        out[f, pos_i, pos_j] = cube[g, ti, si]
    for ci, ni in ((0, 1), (n + 1, n)):
        for cj, nj in ((0, 1), (n + 1, n)):
            out[:, ci, cj] = (out[:, ni, nj] + out[:, ci, nj] + out[:, ni, cj]) / 3.0
    return out


@dual_use(inline=True)
def _bilinear_add(data, offset, n, face, sc, tc, weight, out):
    """out += weight * bilinear sample of the bordered level (6, n+2, n+2, C)
    stored flat at data[offset:] at face coordinates (sc, tc), clamped to the
    bordered face (:func:`pbrkit.core.filtering.texel_pair`).  Inlined (at
    Numba IR level) into every kernel that calls it (here and in
    :mod:`pbrkit.ibl.prefilter`): a call to a separately compiled function in an
    inner loop costs about as much as the lookup itself."""
    nb = n + 2
    channels = out.shape[0]
    # coordinates from the centre of bordered texel 0: face texel j (bordered j + 1) has s = (j + 0.5) / n
    x0, _, fx = texel_pair(0.5 * (sc + 1.0) * n + 0.5, nb, CLAMP_TO_EDGE)
    y0, _, fy = texel_pair(0.5 * (tc + 1.0) * n + 0.5, nb, CLAMP_TO_EDGE)
    base = offset + ((face * nb + y0) * nb + x0) * channels
    row = nb * channels
    w00 = weight * (1.0 - fx) * (1.0 - fy)
    w01 = weight * fx * (1.0 - fy)
    w10 = weight * (1.0 - fx) * fy
    w11 = weight * fx * fy
    for c in range(channels):
        out[c] += (w00 * data[base + c] + w01 * data[base + channels + c]
                   + w10 * data[base + row + c] + w11 * data[base + row + channels + c])


@dual_use(inline=True)
def _trilinear_add(data, offsets, sizes, face, sc, tc, lod, weight, out):
    """out += weight * trilinear sample of the bordered pyramid (levels stored
    flat in ``data`` at ``offsets``, sizes ``sizes``) at face coordinates
    (sc, tc) and level of detail ``lod``, clamped to [0, levels - 1]: the
    bilinear samples of levels floor(lod) and floor(lod) + 1 blended linearly.
    Inlined like :func:`_bilinear_add` (used here and in :mod:`pbrkit.ibl.prefilter`)."""
    levels = sizes.shape[0]
    lod = min(max(lod, 0.0), levels - 1.0)
    l0 = int(math.floor(lod))
    frac = lod - l0
    if l0 >= levels - 1:
        l0 = levels - 1
        frac = 0.0
    _bilinear_add(data, offsets[l0], sizes[l0], face, sc, tc, weight * (1.0 - frac), out)
    if frac > 0.0:
        _bilinear_add(data, offsets[l0 + 1], sizes[l0 + 1], face, sc, tc, weight * frac, out)


@row_kernel(0)
def _sample_kernel(start, stop, dirs, lods, data, offsets, sizes, out):
    for m in range(start, stop):
        face, sc, tc = cube_face_coords(dirs[m, 0], dirs[m, 1], dirs[m, 2])
        for c in range(out.shape[1]):
            out[m, c] = 0.0
        _trilinear_add(data, offsets, sizes, face, sc, tc, lods[m], 1.0, out[m])


class CubeSampler:
    """Seam-aware bilinear / trilinear sampler of a cube map or mip pyramid.

    Built once from a cube (6, N, N[, C]) or a pyramid (a list of cubes whose
    sizes halve, as from :func:`build_mip_pyramid`); each level gets the
    one-texel border of :func:`_bordered` so that ordinary bilinear filtering
    of the bordered face reads across face edges: the texels past an edge
    are the adjacent face's edge texels, as in GPU seamless cube-map
    filtering (OpenGL 4.6 sec. 8.13, ARB_seamless_cube_map), and at the
    three-face corners the border texel is the mean of the three corner
    texels (the usual choice; the specification leaves it open).  The
    result is continuous across edges; within half a texel of an edge the
    interpolation error is first order (the neighbour's texel sits up to
    half a texel along the edge from where bilinear weights assume it),
    elsewhere second order, as on a GPU.  Calling it with
    directions (..., 3) and an optional level of detail (scalar or per
    direction, clamped to [0, levels - 1]; fractional lods blend the two
    nearest levels linearly, i.e. trilinear filtering) returns (..., C).
    """

    def __init__(self, cube_or_pyramid):
        levels = list(cube_or_pyramid) if isinstance(cube_or_pyramid, (list, tuple)) else [cube_or_pyramid]
        if not levels:
            raise ValueError("empty mip pyramid")
        self.channelless = np.ndim(levels[0]) == 3
        cubes = [_as_cube(c, f"mip level {k}") for k, c in enumerate(levels)]
        self.channels = cubes[0].shape[3]
        self.sizes = np.array([c.shape[1] for c in cubes], dtype=np.int64)
        for k, c in enumerate(cubes):
            if c.shape[3] != self.channels:
                raise ValueError(f"mip level {k} has {c.shape[3]} channels, level 0 has {self.channels}")
            if k and self.sizes[k] != max(1, self.sizes[k - 1] // 2):
                raise ValueError(f"mip level {k} has size {self.sizes[k]}, expected {max(1, self.sizes[k - 1] // 2)}")
        flat = [_bordered(c.astype(np.float64, copy=False)).ravel() for c in cubes]  # one compiled variant
        self.offsets = np.cumsum([0] + [f.size for f in flat[:-1]]).astype(np.int64)
        self.data = np.concatenate(flat)

    @property
    def levels(self):
        return len(self.sizes)

    def __call__(self, directions, lod=None):
        d = checks.directions(directions)
        shape = d.shape[:-1]
        flat = np.ascontiguousarray(d.reshape(-1, 3))
        lods = np.zeros(flat.shape[0]) if lod is None else np.ascontiguousarray(
            np.broadcast_to(np.asarray(lod, dtype=np.float64), shape).reshape(-1))
        if not np.all(np.isfinite(lods)):
            raise ValueError("lod must be finite")
        out = np.empty((flat.shape[0], self.channels))
        _sample_kernel(flat, lods, self.data, self.offsets, self.sizes, out)
        out = out.reshape(shape + (self.channels,))
        return out[..., 0] if self.channelless else out


def sample_cube(cube_or_pyramid, directions, lod=None):
    """Sample a cube map (6, N, N[, C]), a mip pyramid (list of cubes) or a
    :class:`CubeSampler` at directions (..., 3): seam-aware bilinear at level
    0, or trilinear at ``lod`` (scalar or per direction, clamped to the
    available levels).  Build a :class:`CubeSampler` once to sample the same
    cube repeatedly."""
    sampler = cube_or_pyramid if isinstance(cube_or_pyramid, CubeSampler) else CubeSampler(cube_or_pyramid)
    return sampler(directions, lod)


# ----------------------------------------------------------------- pyramids


def _block_reduce(cube, k, weighting):
    n = cube.shape[1]
    m = n // k
    c = cube.astype(np.float64).reshape(6, m, k, m, k, cube.shape[3])
    if weighting == "box":
        return c.mean(axis=(2, 4))
    omega = cube_texel_solid_angles(n).reshape(6, m, k, m, k, 1)
    return (c * omega).sum(axis=(2, 4)) / omega.sum(axis=(2, 4))


def build_mip_pyramid(cube, weighting="solid_angle"):
    """Mip levels [N, N/2, ..., 1] of a cube map by 2 x 2 reduction, while the
    size is even (an odd size ends the chain).

    ``weighting="solid_angle"`` (default) averages the four children weighted
    by their exact solid angles, so that each level keeps the integral of the
    radiance exactly (the four child texels tile their parent).  ``"box"`` is
    the plain 2 x 2 mean of GPU mip generation (e.g. glGenerateMipmap), which
    keeps the solid-angle-weighted mean only approximately: texels near face
    corners subtend less solid angle than those at face centres, so the box
    mean over-weights them (by up to ~1/N relative for the finest levels).
    Levels are float64 (C kept; a (6, N, N) input gives (6, n, n) levels).
    """
    if weighting not in ("solid_angle", "box"):
        raise ValueError(f"unknown weighting {weighting!r}; use 'solid_angle' or 'box'")
    c = _as_cube(cube).astype(np.float64)
    levels = [c]
    while c.shape[1] > 1 and c.shape[1] % 2 == 0:
        c = _block_reduce(c, 2, weighting)
        levels.append(c)
    return [lv[..., 0] for lv in levels] if np.ndim(cube) == 3 else levels


@row_kernel(lambda data, n_src, size, *rest: 6 * size)
def _resample_kernel(start, stop, data, n_src, size, k, out):
    """out[f, i, j] = solid-angle-weighted mean of k x k sub-texel bilinear
    samples of the bordered source (flat ``data``, size n_src)."""
    channels = out.shape[3]
    for fi in range(start, stop):
        f = fi // size
        i = fi % size
        acc = np.zeros(channels)
        for j in range(size):
            for c in range(channels):
                acc[c] = 0.0
            total = 0.0
            for a in range(k):
                t0 = 2.0 * (i + a / k) / size - 1.0
                t1 = 2.0 * (i + (a + 1.0) / k) / size - 1.0
                for b in range(k):
                    s0 = 2.0 * (j + b / k) / size - 1.0
                    s1 = 2.0 * (j + (b + 1.0) / k) / size - 1.0
                    w = cube_patch_solid_angle(s0, t0, s1, t1)
                    x, y, z = face_direction(f, 0.5 * (s0 + s1), 0.5 * (t0 + t1))
                    g, sc, tc = cube_face_coords(x, y, z)
                    _bilinear_add(data, 0, n_src, g, sc, tc, w, acc)
                    total += w
            for c in range(channels):
                out[f, i, j, c] = acc[c] / total


def resample_cube(cube, size, weighting="solid_angle"):
    """Cube map of another size.  When N is a multiple of ``size`` the result
    is the exact solid-angle-weighted block mean (the integral is preserved);
    otherwise each output texel is the solid-angle-weighted mean of k x k
    seam-aware bilinear samples (k = clamp(ceil(2 N / size), 2, 16)).
    Returns float64 (6, size, size[, C])."""
    size = _check_size(size)
    c = _as_cube(cube)
    n = c.shape[1]
    if size == n:
        out = c.astype(np.float64)
    elif n % size == 0:
        out = _block_reduce(c, n // size, weighting)
    else:
        k = int(min(16, max(2, math.ceil(2 * n / size))))
        data = _bordered(c.astype(np.float64)).ravel()
        out = np.empty((6, size, size, c.shape[3]))
        _resample_kernel(data, n, size, k, out)
    return out[..., 0] if np.ndim(cube) == 3 else out


def mirror_cube(cube, axis):
    """The cube map of L'(d) = L(d with coordinate ``axis`` ("x", "y", "z")
    negated): ``cube`` (6, N, N[, C]) re-indexed, exactly (a mirror maps texel
    centres onto texel centres: the face of that axis swaps with its opposite
    and every face flips in sc or tc, by OpenGL 4.6 table 8.19; the face
    permutation and flips are found once from the table, :func:`_mirror_plan`).
    For engines whose cube lookups mirror a coordinate: three.js flips x for cube
    textures, Babylon.js negates z in right-handed scenes (docs/engine-targets.md)."""
    c = np.asarray(cube)
    if c.ndim not in (3, 4) or c.shape[0] != 6 or c.shape[1] != c.shape[2]:
        raise ValueError(f"cube map must have shape (6, N, N) or (6, N, N, C), got {c.shape}")
    if axis not in ("x", "y", "z"):
        raise ValueError(f"axis must be 'x', 'y' or 'z', got {axis!r}")
    faces = []
    for source, flip_rows, flip_columns in _mirror_plan(axis):
        face = c[source]
        faces.append(face[::-1 if flip_rows else 1, ::-1 if flip_columns else 1])
    return np.ascontiguousarray(np.stack(faces))


_MIRROR_PLANS = {}


def _mirror_plan(axis):
    """For each face f: (source face, rows flipped, columns flipped) such that
    texel (f, i, j) of the mirrored cube is texel (source, i', j') of the
    original.  Read off the face table at N = 2 (each face maps affinely, so a
    2 x 2 face fixes the map for every N)."""
    if axis not in _MIRROR_PLANS:
        k = "xyz".index(axis)
        d = cube_texel_directions(2)
        d[..., k] = -d[..., k]
        face, s, t = direction_to_cube(d)
        plan = []
        for f in range(6):
            rows = np.floor(t[f] * 2).astype(int)
            cols = np.floor(s[f] * 2).astype(int)
            plan.append((int(face[f, 0, 0]), bool(rows[0, 0] == 1), bool(cols[0, 0] == 1)))
        _MIRROR_PLANS[axis] = tuple(plan)
    return _MIRROR_PLANS[axis]
