"""Equirectangular maps: their geometry, and conversion to and from cube maps.

Equirectangular convention (``CONVENTIONS.md``): an H x W image with W = 2H,
row 0 at the top (+Y); pixel (i, j) has its centre at theta = pi (i + 0.5) / H
(from +Y) and phi = 2 pi (j + 0.5) / W - pi, direction
d = (sin theta cos phi, cos theta, sin theta sin phi), and solid angle
(2 pi / W)(pi / H) sin theta; texture coordinates u = 0.5 + atan2(z, x) /
(2 pi) = (phi + pi) / (2 pi), v = acos(y) / pi = theta / pi.  The mapping is
written once, as the dual-use helpers :func:`equirect_pixel_angles`,
:func:`equirect_angles_of_uv`, :func:`equirect_direction`,
:func:`direction_angles` and :func:`equirect_uv` (NumPy arrays from Python,
scalars in Numba kernels: the renderer's environment, the spectral
transforms).  Cube maps follow :mod:`pbrkit.ibl.cubemap`.

Equirect -> cube (:func:`equirect_to_cube`) is exact area-weighted
(conservative) remapping: the source is taken as piecewise constant over its
pixels, each a latitude-longitude cell of solid angle
(2 pi / W)(cos theta_top - cos theta_bottom), and each cube texel gets the
mean radiance over its exact footprint on the sphere.  Nothing is point
sampled, so a one-pixel sun keeps its energy, a constant map stays constant,
and the integral over the sphere is preserved to rounding for any pair of
resolutions.  (The cell solid angle differs from the CONVENTIONS midpoint
value (2 pi / W)(pi / H) sin theta by the same factor sinc(pi / 2H) in every
row, 1 - 1.6e-6 at H = 512; :func:`equirect_solid_angles` gives both.)

How: in the coordinates (phi, mu = cos theta = d.y) the solid angle is
dphi dmu (Archimedes), so with the column potential
P(phi, mu) = integral_mu^1 L dmu', Green's theorem turns each texel's
integral into the line integral of P dphi around its boundary (the
line-integral formulation of conservative remapping of P. W. Jones,
"First- and second-order conservative remapping schemes for grids in
spherical coordinates", Mon. Wea. Rev. 127, 1999).  Texel edges are
great-circle arcs; on the great circle with normal n,
cot theta = k cos(phi - phi0) with k = -sqrt(n_x^2 + n_z^2) / n_y and
phi0 = atan2(n_z, n_x), and along it the integral of mu dphi has the closed
form asin(k sin(phi - phi0) / sqrt(1 + k^2)) (differentiate to check).
Splitting each edge where it crosses the source grid (meridians and
parallels) makes every piece of the line integral exact; P is linear in mu
inside a source pixel.  Meridian edges have dphi = 0 and contribute
nothing, and P vanishes at the north pole, so texels touching or containing
it need no correction; the -Y face uses the potential integrated from the
south pole instead, for the same reason.  Cost: O(N^2 + N (H + W)) edge
pieces; memory: one float64 copy of the image (the potential).
"""

from __future__ import annotations

import math

import numpy as np

from ..core import checks
from ..core.jit import dual_use, kernel, row_kernel
from .cubemap import (
    CubeSampler,
    _as_cube,
    _check_size,
    cube_texel_solid_angles,
    face_direction,
)

__all__ = [
    "equirect_pixel_angles",
    "equirect_angles_of_uv",
    "equirect_direction",
    "direction_angles",
    "equirect_uv",
    "equirect_directions",
    "equirect_solid_angles",
    "direction_to_equirect",
    "equirect_integral",
    "equirect_to_cube",
    "cube_to_equirect",
]

# ------------------------------------------------------------ equirect geometry


def _equirect_shape(height, width):
    height = _check_size(height, "equirect height")
    width = 2 * height if width is None else _check_size(width, "equirect width")
    return height, width


@dual_use
def equirect_pixel_angles(i, j, height, width):
    """(theta, phi) of the centre of pixel (row i, column j) of a height x
    width equirect (CONVENTIONS.md): theta = pi (i + 0.5) / H from +Y and
    phi = 2 pi (j + 0.5) / W - pi.  theta depends on i only and phi on j
    only, so i and j need not broadcast together (a grid's rows and columns
    as two 1-D arrays)."""
    return np.pi * (i + 0.5) / height, 2.0 * np.pi * (j + 0.5) / width - np.pi


@dual_use
def equirect_angles_of_uv(u, v):
    """(theta, phi) = (pi v, 2 pi u - pi) of equirect texture coordinates
    (u, v) in [0, 1] (CONVENTIONS.md; the inverse of :func:`equirect_uv`)."""
    return np.pi * v, 2.0 * np.pi * u - np.pi


@dual_use
def equirect_direction(theta, phi):
    """Unit direction d = (sin theta cos phi, cos theta, sin theta sin phi) of
    the equirect angles (CONVENTIONS.md: theta from +Y, phi = atan2(z, x))."""
    st = np.sin(theta)
    return st * np.cos(phi), np.cos(theta), st * np.sin(phi)


@dual_use
def direction_angles(x, y, z):
    """(theta, phi) = (acos(y), atan2(z, x)) of a unit direction (y clamped
    to [-1, 1]): the inverse of :func:`equirect_direction` (CONVENTIONS.md)."""
    return np.arccos(np.minimum(np.maximum(y, -1.0), 1.0)), np.arctan2(z, x)


@dual_use
def equirect_uv(x, y, z):
    """Equirect texture coordinates u = 0.5 + atan2(z, x) / (2 pi),
    v = acos(y) / pi in [0, 1] of a unit direction (CONVENTIONS.md); pixel
    column floor(u W), row floor(v H)."""
    theta, phi = direction_angles(x, y, z)
    return 0.5 + phi / (2.0 * np.pi), theta / np.pi


def equirect_directions(height, width=None, rows=None):
    """Unit directions (H, W, 3) of the pixel centres of an H x W (default
    W = 2H) equirectangular image (CONVENTIONS.md); only the given ``rows``
    (an index array) when set."""
    h, w = _equirect_shape(height, width)
    theta, phi = equirect_pixel_angles(np.arange(h) if rows is None else np.asarray(rows), np.arange(w), h, w)
    return np.stack(np.broadcast_arrays(*equirect_direction(theta[:, None], phi[None, :])), axis=-1)


def equirect_solid_angles(height, width=None, exact=False, rows=None):
    """Pixel solid angles (H, W) (a read-only broadcast view, constant along
    rows): the CONVENTIONS.md value (2 pi / W)(pi / H) sin theta_i, or with
    ``exact`` the cell's true solid angle (2 pi / W)(cos theta_i0 - cos
    theta_i1) = (2 pi / W) 2 sin theta_i sin(pi / 2H), which sums to 4 pi
    exactly and is what :func:`equirect_to_cube` conserves.  Only the given
    ``rows`` when set."""
    h, w = _equirect_shape(height, width)
    theta, _ = equirect_pixel_angles(np.arange(h) if rows is None else np.asarray(rows), 0, h, w)
    if exact:
        row = (2.0 * np.pi / w) * 2.0 * np.sin(theta) * np.sin(0.5 * np.pi / h)
    else:
        row = (2.0 * np.pi / w) * (np.pi / h) * np.sin(theta)
    return np.broadcast_to(row[:, None], (theta.size, w))


def direction_to_equirect(d):
    """Texture coordinates (u, v) in [0, 1] of directions (..., 3):
    u = 0.5 + atan2(z, x) / (2 pi), v = acos(y / |d|) / pi (CONVENTIONS.md,
    :func:`equirect_uv`); pixel column floor(u W), row floor(v H)."""
    d, length = checks.direction_lengths(d)
    return equirect_uv(d[..., 0], d[..., 1] / length, d[..., 2])


def _as_equirect(image, what="equirect image"):
    a = np.asarray(image)
    if a.ndim == 2:
        a = a[..., None]
    if a.ndim != 3 or a.shape[0] < 1 or a.shape[1] != 2 * a.shape[0]:
        raise ValueError(f"{what} must have shape (H, 2H) or (H, 2H, C), got {np.shape(image)}")
    if not np.issubdtype(a.dtype, np.floating):
        a = a.astype(np.float64)
    return a


def equirect_integral(image, exact=False):
    """sum over pixels of L * dOmega, shape (C,) (scalar for (H, W)), with the
    CONVENTIONS.md pixel solid angle or, with ``exact``, the cell's true one."""
    a = _as_equirect(image)
    row = equirect_solid_angles(a.shape[0], a.shape[1], exact=exact)[:, 0]
    out = np.einsum("i,ic->c", row, a.sum(axis=1, dtype=np.float64))
    return out[0] if np.ndim(image) == 2 else out


# ---------------------------------------------------- equirect -> cube (exact)


def _column_potential(img, z, dz, band=64):
    """pot (H, W, C) float64 with pot[r, j] = (integral of L dmu from the
    north pole to the top of row r) + L[r, j] mu_r (``z`` holds the row
    boundaries mu_r = cos(pi r / H), ``dz`` their differences), so that the
    north potential inside row r is P(phi, mu) = pot[r, j] - L[r, j] mu; and
    total (W, C), the integral of L dmu over each whole column.  Rows are
    processed in bands so that no temporary larger than a band is made."""
    h, w, channels = img.shape
    pot = np.empty((h, w, channels))
    run = np.zeros((w, channels))
    for r0 in range(0, h, band):
        r1 = min(h, r0 + band)
        lz = img[r0:r1].astype(np.float64)
        step = lz * dz[r0:r1, None, None]
        np.cumsum(step, axis=0, out=step)
        pot[r0:r1] = run
        pot[r0 + 1:r1] += step[:-1]
        lz *= z[r0:r1, None, None]
        pot[r0:r1] += lz
        run += step[-1]
    return pot, run


@kernel
def _add_piece(img, pot, total, south, r, j, dphi, gc1, gs1, gc2, gs2, out, oa, ob):
    """Add the integral of P dphi over one piece of an arc inside source cell
    (r, j): P = pot - L mu (north) or total - pot + L mu (south), mu = cos
    theta.  The increment of G = integral of mu dphi is the angle between the
    end points' (cos G, sin G), so short pieces lose nothing to cancellation."""
    dg = math.atan2(gs2 * gc1 - gc2 * gs1, gc1 * gc2 + gs1 * gs2)
    for c in range(out.shape[2]):
        v = np.float64(img[r, j, c])
        if south:
            out[oa, ob, c] += (total[j, c] - pot[r, j, c]) * dphi + v * dg
        else:
            out[oa, ob, c] += pot[r, j, c] * dphi - v * dg


@kernel
def _edge_integral(ax, ay, az, bx, by, bz, pa, pb, row_a, row_b, img, pot, total, tables, south, out, oa, ob):
    """out[oa, ob] = integral of P dphi along the great-circle arc from corner
    a to corner b (phi of a and b given as pa, pb; row_a, row_b: source rows
    of the corners), with P the north (or, with ``south``, south) column
    potential; exact for the piecewise-constant source (module doc).

    With n = a x b, psi = phi - phi0, phi0 = atan2(n_z, n_x): on the arc
    cot theta = k cos psi (k = -sqrt(n_x^2 + n_z^2) / n_y), so
    mu = cos theta = k cos psi / sqrt(1 + k^2 cos^2 psi), and G = integral of
    mu dphi = asin(k sin psi / sqrt(1 + k^2)), with cos G = sqrt(1 + k^2
    cos^2 psi) / sqrt(1 + k^2).  The arc is cut at source column boundaries,
    at the extremum of mu (sin psi = 0, at most one on an arc shorter than
    pi) and, inside each monotone piece, where mu crosses a row boundary
    mu_b (cos psi = cot theta_b / k)."""
    z, cot, csc, colcos, colsin = tables
    for c in range(out.shape[2]):
        out[oa, ob, c] = 0.0
    nx = ay * bz - az * by
    ny = az * bx - ax * bz
    nz = ax * by - ay * bx
    if ny == 0.0:  # meridian (or degenerate): dphi = 0 along it
        return
    height, width = img.shape[0], img.shape[1]
    d = pb - pa
    if d > math.pi:
        d -= 2.0 * math.pi
    elif d < -math.pi:
        d += 2.0 * math.pi
    if d == 0.0:
        return
    if d > 0.0:
        lo, sx, sz, ex, ez, r = pa, ax, az, bx, bz, row_a
    else:
        lo, sx, sz, ex, ez, r = pb, bx, bz, ax, az, row_b
    hi = lo + abs(d)
    big_r = math.sqrt(nx * nx + nz * nz)
    if big_r > 0.0:
        cos0, sin0 = nx / big_r, nz / big_r
    else:
        cos0, sin0 = 1.0, 0.0
    k = -big_r / ny
    inv = 1.0 / math.sqrt(1.0 + k * k)
    kk = k * inv
    # start and end points: (cos psi, sin psi)
    rs = math.sqrt(sx * sx + sz * sz)
    c1 = (sx * cos0 + sz * sin0) / rs
    s1 = (sz * cos0 - sx * sin0) / rs
    re = math.sqrt(ex * ex + ez * ez)
    ce = (ex * cos0 + ez * sin0) / re
    se = (ez * cos0 - ex * sin0) / re
    # the extremum of y (psi = 0 or pi) lies inside the arc iff sin psi changes sign
    ext = math.inf
    ext_c = 1.0
    if (s1 > 0.0 and se < 0.0) or (s1 < 0.0 and se > 0.0):
        ext_c = 1.0 if (c1 + ce) > 0.0 else -1.0
        ext = lo + math.atan2(-s1 * ext_c, c1 * ext_c)  # angle from start to (ext_c, 0)
    t = k * c1
    w = math.sqrt(1.0 + t * t)
    y1 = t / w
    gc1 = w * inv
    gs1 = kk * s1
    while r > 0 and y1 > z[r]:
        r -= 1
    while r < height - 1 and y1 < z[r + 1]:
        r += 1
    dcol = 2.0 * math.pi / width
    m_col = int(math.floor((lo + math.pi) / dcol))
    p = lo
    while True:
        nb_col = -math.pi + (m_col + 1) * dcol
        last = hi <= nb_col and hi <= ext
        if last:
            q, c2, s2 = hi, ce, se
        elif nb_col <= ext:
            q = nb_col
            mc = (m_col + 1) % width
            c2 = colcos[mc] * cos0 + colsin[mc] * sin0
            s2 = colsin[mc] * cos0 - colcos[mc] * sin0
        else:
            q, c2, s2 = ext, ext_c, 0.0
        t = k * c2
        w = math.sqrt(1.0 + t * t)
        y2 = t / w
        gc2 = w * inv
        gs2 = kk * s2
        j = m_col % width
        rest = max(0.0, q - p)
        branch = 1.0 if s1 + s2 > 0.0 else -1.0
        if y2 > y1:  # rising: cross the tops z[r] of the rows
            while r > 0 and y2 > z[r]:
                cx = min(1.0, max(-1.0, cot[r] / k))
                sx_ = branch * math.sqrt(max(0.0, 1.0 - cx * cx))
                dphi = min(rest, max(0.0, math.atan2(sx_ * c1 - cx * s1, c1 * cx + s1 * sx_)))
                gcx = csc[r] * inv
                gsx = kk * sx_
                _add_piece(img, pot, total, south, r, j, dphi, gc1, gs1, gcx, gsx, out, oa, ob)
                c1, s1, gc1, gs1 = cx, sx_, gcx, gsx
                rest -= dphi
                r -= 1
        else:  # falling: cross the bottoms z[r + 1]
            while r < height - 1 and y2 < z[r + 1]:
                cx = min(1.0, max(-1.0, cot[r + 1] / k))
                sx_ = branch * math.sqrt(max(0.0, 1.0 - cx * cx))
                dphi = min(rest, max(0.0, math.atan2(sx_ * c1 - cx * s1, c1 * cx + s1 * sx_)))
                gcx = csc[r + 1] * inv
                gsx = kk * sx_
                _add_piece(img, pot, total, south, r, j, dphi, gc1, gs1, gcx, gsx, out, oa, ob)
                c1, s1, gc1, gs1 = cx, sx_, gcx, gsx
                rest -= dphi
                r += 1
        _add_piece(img, pot, total, south, r, j, rest, gc1, gs1, gc2, gs2, out, oa, ob)
        if last:
            break
        if q == nb_col:
            m_col += 1
        if q == ext:
            ext = math.inf
        p = q
        c1, s1, gc1, gs1, y1 = c2, s2, gc2, gs2, y2
    if d < 0.0:
        for c in range(out.shape[2]):
            out[oa, ob, c] = -out[oa, ob, c]


def _face_corners(face, n, z):
    """phi = atan2(z, x) and source row of the (n + 1)^2 texel corners of ``face``."""
    e = 2.0 * np.arange(n + 1) / n - 1.0
    x, y, zz = face_direction(face, e[None, :], e[:, None])
    x, y, zz = np.broadcast_arrays(x, y, zz)
    yn = y / np.sqrt(x * x + y * y + zz * zz)
    _, phi = direction_angles(x, yn, zz)
    height = z.shape[0] - 1
    # row r holds z[r + 1] <= y <= z[r]; z decreases with r
    row = np.clip(np.searchsorted(-z, -yn, side="right") - 1, 0, height - 1)
    return np.ascontiguousarray(phi), np.ascontiguousarray(row.astype(np.int64))


@row_kernel(lambda texels, face, n, *rest: n if texels else n + 1)
def _face_pass(start, stop, texels, face, n, phi, row, img, pot, total, tables, south, horizontal, omega, out):
    """First pass (``texels`` False): horizontal[a, j] = edge integral from
    corner (a, j) to (a, j + 1).  Second pass: out[i, j] = (1 / omega) times
    the integral of L over texel (i, j) of ``face``, whose boundary
    (i, j) -> (i, j+1) -> (i+1, j+1) -> (i+1, j) runs in the positive sense
    of the (phi, z) plane (the (s, t) frame of every face is left-handed
    about the outward normal, and the (phi, z) chart reverses orientation
    too); the -Y face's south potential flips the sign."""
    channels = out.shape[2]
    if not texels:
        for a in range(start, stop):  # rows a of corners, 0..n
            tc = 2.0 * a / n - 1.0
            for j in range(n):
                ax, ay, az = face_direction(face, 2.0 * j / n - 1.0, tc)
                bx, by, bz = face_direction(face, 2.0 * (j + 1) / n - 1.0, tc)
                _edge_integral(ax, ay, az, bx, by, bz, phi[a, j], phi[a, j + 1], row[a, j], row[a, j + 1],
                               img, pot, total, tables, south, horizontal, a, j)
        return
    sign = -1.0 if south else 1.0
    for i in range(start, stop):  # rows i of texels, 0..n-1
        vertical = np.empty((1, n + 1, channels))
        t0 = 2.0 * i / n - 1.0
        t1 = 2.0 * (i + 1) / n - 1.0
        for b in range(n + 1):
            sc = 2.0 * b / n - 1.0
            ax, ay, az = face_direction(face, sc, t0)
            bx, by, bz = face_direction(face, sc, t1)
            _edge_integral(ax, ay, az, bx, by, bz, phi[i, b], phi[i + 1, b], row[i, b], row[i + 1, b],
                           img, pot, total, tables, south, vertical, 0, b)
        for j in range(n):
            for c in range(channels):
                s = (horizontal[i, j, c] + vertical[0, j + 1, c] - horizontal[i + 1, j, c] - vertical[0, j, c])
                out[i, j, c] = sign * s / omega[i, j]


def equirect_to_cube(image, size):
    """Cube map (6, size, size, C) of an equirectangular image (H, 2H[, C]) by
    exact area-weighted resampling (module doc): every texel is the mean of
    the piecewise-constant source over the texel's footprint, so the integral
    over the sphere (with exact cell solid angles) is preserved to rounding.
    Output dtype follows the input (float32 stays float32); accumulation is
    float64.  Memory: one float64 copy of the image (the column potential)."""
    size = _check_size(size)
    a = _as_equirect(image)
    if a.dtype not in (np.float32, np.float64):
        a = a.astype(np.float64)
    if not np.all(np.isfinite(a)):
        raise ValueError("equirect image has non-finite pixels; repair them first (--fix-nonfinite on the "
                         "command line, pbrkit.io.environment.fix_nonfinite_pixels in Python)")
    a = np.ascontiguousarray(a)
    h, w, channels = a.shape
    edges = np.arange(h + 1) * (np.pi / h)
    z = np.cos(edges)
    dz = 2.0 * np.sin(equirect_pixel_angles(np.arange(h), 0, h, w)[0]) * np.sin(0.5 * np.pi / h)
    with np.errstate(divide="ignore"):
        cot = np.cos(edges) / np.sin(edges)
        csc = 1.0 / np.sin(edges)
    cot[0], cot[h] = np.inf, -np.inf  # the poles are never crossed by a non-meridian arc
    csc[0], csc[h] = np.inf, np.inf
    col = -np.pi + 2.0 * np.pi * np.arange(w) / w
    colcos, colsin = np.cos(col), np.sin(col)
    pot, total = _column_potential(a, z, dz)
    omega = cube_texel_solid_angles(size)[0]
    out = np.empty((6, size, size, channels), dtype=a.dtype)
    horizontal = np.empty((size + 1, size, channels))
    plane = np.empty((size, size, channels))
    tables = (z, cot, csc, colcos, colsin)
    for face in range(6):
        south = face == 3  # -Y: potential from the south pole, so no texel needs a pole term
        phi, row = _face_corners(face, size, z)
        _face_pass(False, face, size, phi, row, a, pot, total, tables, south, horizontal, omega, plane)
        _face_pass(True, face, size, phi, row, a, pot, total, tables, south, horizontal, omega, plane)
        out[face] = plane
    return out[..., 0] if np.ndim(image) == 2 else out


def cube_to_equirect(cube, height):
    """Equirectangular image (height, 2 height, C) of a cube map by seam-aware
    bilinear sampling at the pixel centres (:class:`pbrkit.ibl.cubemap.CubeSampler`)."""
    height = _check_size(height, "equirect height")
    sampler = CubeSampler(_as_cube(cube))
    out = np.empty((height, 2 * height, sampler.channels))
    rows = max(1, (1 << 18) // (2 * height))
    for r0 in range(0, height, rows):
        r1 = min(height, r0 + rows)
        out[r0:r1] = sampler(equirect_directions(height, rows=np.arange(r0, r1)))
    return out[..., 0] if np.ndim(cube) == 3 else out

