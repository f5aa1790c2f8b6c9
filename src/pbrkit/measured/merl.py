"""MERL measured isotropic BRDFs: the binary format of the 100-material database,
its half/difference-angle binning, lookup, and tables sampled from any BRDF.

Matusik, Pfister, Brand and McMillan, "A Data-Driven Reflectance Model",
ACM SIGGRAPH 2003; the database's reader ``BRDFRead.cpp`` (MERL 2006) defines
the format and the binning this module follows (the code here is written from
those definitions, not copied):

- **File**: three little-endian int32 dimensions (90, 90, 180), then
  3 x 90 x 90 x 180 little-endian float64 values, channel-major (the red block,
  then green, then blue); within a channel the index is
  ``phi_d + 180 (theta_d + 90 theta_h)`` (C order over (theta_h, theta_d,
  phi_d)).  A stored value times the channel's scale :data:`MERL_SCALE`
  (1/1500, 1.15/1500, 1.66/1500) is the BRDF value f in 1/sr.  Negative values
  mark bins that were not measured (below the horizon): *missing*.
- **Coordinates** (Rusinkiewicz 1998, "A New Change of Variables for Efficient
  BRDF Representation"): h = normalize(l + v), theta_h its polar angle; the
  difference vector is l expressed in the frame of h (rotate l by -phi_h about
  the normal, then by -theta_h about the binormal), theta_d and phi_d its polar
  and azimuthal angles.  For an isotropic BRDF they do not depend on the
  tangent; :func:`half_diff_angles` computes them from dot products with the
  normal as ``phi_d = atan2(l . b_h, l . t_h)``, b_h = normalize(n x h),
  t_h = b_h x h (the images of the binormal and tangent under the reader's two
  rotations).
- **Bins**: theta_h index floor(sqrt(theta_h / (pi/2)) 90) (the non-linear
  mapping that puts half the bins within 21 degrees of the specular peak),
  theta_d index floor(theta_d / (pi/2) 90), phi_d index floor(phi_d / pi 180)
  after adding pi to a negative phi_d (reciprocity: phi_d and phi_d + pi share
  a bin); each clamped to the table.  Bin centres are the index-space centres:
  theta_h = ((i + 0.5) / 90)^2 pi/2, theta_d = (j + 0.5) / 90 pi/2,
  phi_d = (k + 0.5) / 180 pi (:func:`merl_bin_centres`).

Lookups are nearest-bin as in the reader (the bin that contains the
direction pair), or, with ``interpolation="trilinear"``, trilinear in the
index space (bin centres as nodes; phi_d periodic with period pi, the theta
axes clamped at the first and last centre) over the valid neighbours only.
Directions below the horizon, and missing bins, give 0.

The database is not bundled (its licence is non-commercial); pbrkit's tests
write synthetic files from its own models with :func:`merl_table` and
:func:`write_merl`.

A file is untrusted input (:mod:`pbrkit.core.inputs`): :func:`read_merl` opens
only a regular file, reads its 12-byte header first, and reads the values only
when the header declares the 90 x 90 x 180 table and the file's length is
exactly what that declaration gives (12 + 3 x 1458000 x 8 bytes), with the
memory checked first; no message quotes the file's bytes or the header's
numbers (a header that is not the table's is not echoed: it may be text).
"""

from __future__ import annotations

import functools
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.atomic import write_bytes
from ..core.errors import InputError
from ..core.inputs import check_allocation, open_regular
from ..core.jit import dual_use, row_kernel, select
from ..core.vec import orthonormal_basis_xyz

__all__ = [
    "MERL_SHAPE",
    "MERL_SCALE",
    "MERL_INTERPOLATIONS",
    "MerlBRDF",
    "directions_from_half_diff",
    "half_diff_angles",
    "half_diff_xyz",
    "index_coordinates",
    "merl_indices",
    "merl_bin_centres",
    "merl_directions",
    "merl_table",
    "merl_bytes",
    "read_merl",
    "write_merl",
]

#: (theta_h, theta_d, phi_d) bins of a MERL table.
MERL_SHAPE = (90, 90, 180)
#: The reader's per-channel scale (RED_SCALE, GREEN_SCALE, BLUE_SCALE): stored value x scale = f (1/sr).
MERL_SCALE = (1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0)
#: Lookups of :meth:`MerlBRDF.evaluate`.
MERL_INTERPOLATIONS = ("nearest", "trilinear")

_BINS = MERL_SHAPE[0] * MERL_SHAPE[1] * MERL_SHAPE[2]
_HEADER_BYTES = 12
_FILE_BYTES = _HEADER_BYTES + 3 * _BINS * 8
_HALF_PI = 0.5 * math.pi
_MISSING = -1.0


# ----------------------------------------------------------------- coordinates


def _dot(a, b):
    return np.sum(a * b, axis=-1)


@dual_use
def half_diff_xyz(lx, ly, lz, vx, vy, vz, nx, ny, nz):
    """(theta_h, theta_d, phi_d) of l, v about n, component by component (a
    dual-use helper: NumPy arrays from Python, scalars in the lookup kernel):
    h = normalize(l + v) (n where l = -v), theta_h = acos(n.h), theta_d = acos(l.h),
    phi_d = atan2(l.b_h, l.t_h) with b_h = normalize(n x h), t_h = b_h x h (module
    doc); where h = n the frame of :func:`pbrkit.core.vec.orthonormal_basis_xyz`
    stands in (+x, +y for n = +z: the reader's phi_h = 0)."""
    hx = lx + vx
    hy = ly + vy
    hz = lz + vz
    hl = np.sqrt(hx * hx + hy * hy + hz * hz)
    ok_h = hl > 1e-12
    inv = 1.0 / select(ok_h, hl, 1.0)
    hx = select(ok_h, hx * inv, nx)
    hy = select(ok_h, hy * inv, ny)
    hz = select(ok_h, hz * inv, nz)
    theta_h = np.arccos(np.minimum(np.maximum(nx * hx + ny * hy + nz * hz, -1.0), 1.0))
    theta_d = np.arccos(np.minimum(np.maximum(lx * hx + ly * hy + lz * hz, -1.0), 1.0))
    bx = ny * hz - nz * hy
    by = nz * hx - nx * hz
    bz = nx * hy - ny * hx
    bl = np.sqrt(bx * bx + by * by + bz * bz)
    ok_b = bl > 1e-9
    invb = 1.0 / select(ok_b, bl, 1.0)
    (t0x, t0y, t0z), (b0x, b0y, b0z) = orthonormal_basis_xyz(nx, ny, nz)
    bx = select(ok_b, bx * invb, b0x)
    by = select(ok_b, by * invb, b0y)
    bz = select(ok_b, bz * invb, b0z)
    tx = select(ok_b, by * hz - bz * hy, t0x)
    ty = select(ok_b, bz * hx - bx * hz, t0y)
    tz = select(ok_b, bx * hy - by * hx, t0z)
    phi_d = np.arctan2(lx * bx + ly * by + lz * bz, lx * tx + ly * ty + lz * tz)
    return theta_h, theta_d, phi_d


def half_diff_angles(l, v, n=None):
    """Rusinkiewicz's (theta_h, theta_d, phi_d) of unit directions l, v (..., 3)
    about the normal n (default +z: the local frame of
    :func:`pbrkit.brdf.models.sample`), each an array of the broadcast leading
    shape; phi_d in [-pi, pi] as ``atan2`` gives it (the MERL reader's
    ``std_coords_to_half_diff_coords``, computed from dot products by
    :func:`half_diff_xyz`: see the module doc)."""
    l = np.asarray(l, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    n = np.array([0.0, 0.0, 1.0]) if n is None else np.asarray(n, dtype=np.float64)
    return half_diff_xyz(l[..., 0], l[..., 1], l[..., 2], v[..., 0], v[..., 1], v[..., 2], n[..., 0], n[..., 1],
                         n[..., 2])


@dual_use
def index_coordinates(theta_h, theta_d, phi_d):
    """The continuous MERL index coordinates (u_h, u_d, u_p) of half/difference angles,
    whose floors (clamped to the table) are the reader's bins: u_h = sqrt(theta_h /
    (pi/2)) 90 (0 for theta_h <= 0; ``theta_half_index``), u_d = theta_d / (pi/2) 90
    (``theta_diff_index``), u_p = phi_d / pi 180 after adding pi to a negative phi_d
    (``phi_diff_index``: reciprocity)."""
    u_h = np.sqrt(np.maximum(theta_h, 0.0) / _HALF_PI * (MERL_SHAPE[0] * MERL_SHAPE[0]))
    u_d = theta_d / _HALF_PI * MERL_SHAPE[1]
    u_p = select(phi_d < 0.0, phi_d + math.pi, phi_d) / math.pi * MERL_SHAPE[2]
    return u_h, u_d, u_p


@dual_use
def _clamped_floor(u, size):
    return np.minimum(np.maximum(np.floor(u), 0.0), size - 1.0)


def merl_indices(theta_h, theta_d, phi_d):
    """The MERL reader's bin indices (i_h, i_d, i_p) (int64 arrays) of half/difference
    angles: ``theta_half_index``, ``theta_diff_index`` and ``phi_diff_index`` of
    ``BRDFRead.cpp`` (:func:`index_coordinates`), each clamped to the table."""
    u = index_coordinates(*(np.asarray(x, dtype=np.float64) for x in (theta_h, theta_d, phi_d)))
    return tuple(np.asarray(_clamped_floor(x, size)).astype(np.int64) for x, size in zip(u, MERL_SHAPE))


@row_kernel(2)
def _lookup_kernel(start, stop, table, valid, l, v, n, trilinear, out):
    nh, nd, npd = valid.shape
    for i in range(start, stop):
        out[i, 0] = 0.0
        out[i, 1] = 0.0
        out[i, 2] = 0.0
        lx, ly, lz = l[i, 0], l[i, 1], l[i, 2]
        vx, vy, vz = v[i, 0], v[i, 1], v[i, 2]
        nx, ny, nz = n[i, 0], n[i, 1], n[i, 2]
        if lx * nx + ly * ny + lz * nz <= 0.0 or vx * nx + vy * ny + vz * nz <= 0.0:
            continue
        theta_h, theta_d, phi_d = half_diff_xyz(lx, ly, lz, vx, vy, vz, nx, ny, nz)
        u_h, u_d, u_p = index_coordinates(theta_h, theta_d, phi_d)
        if not trilinear:
            a = int(_clamped_floor(u_h, nh))
            b = int(_clamped_floor(u_d, nd))
            c = int(_clamped_floor(u_p, npd))
            if valid[a, b, c]:
                for ch in range(3):
                    out[i, ch] = table[ch, a, b, c]
            continue
        # trilinear in index space over the bin centres: theta axes clamped, phi_d periodic (period pi)
        x = min(max(u_h - 0.5, 0.0), nh - 1.0)
        y = min(max(u_d - 0.5, 0.0), nd - 1.0)
        z = u_p - 0.5
        x0, y0, z0 = math.floor(x), math.floor(y), math.floor(z)
        fx, fy, fz = x - x0, y - y0, z - z0
        total = 0.0
        acc0 = 0.0
        acc1 = 0.0
        acc2 = 0.0
        for da in range(2):
            a = min(int(x0) + da, nh - 1)
            wa = fx if da == 1 else 1.0 - fx
            for db in range(2):
                b = min(int(y0) + db, nd - 1)
                wb = fy if db == 1 else 1.0 - fy
                for dc in range(2):
                    c = (int(z0) + dc) % npd
                    wc = fz if dc == 1 else 1.0 - fz
                    w = wa * wb * wc
                    if w > 0.0 and valid[a, b, c]:
                        total += w
                        acc0 += w * table[0, a, b, c]
                        acc1 += w * table[1, a, b, c]
                        acc2 += w * table[2, a, b, c]
        if total > 0.0:
            out[i, 0] = acc0 / total
            out[i, 1] = acc1 / total
            out[i, 2] = acc2 / total


def merl_bin_centres():
    """(theta_h (90,), theta_d (90,), phi_d (180,)) at the bins' index-space centres:
    ((i + 0.5) / 90)^2 pi/2, (j + 0.5) / 90 pi/2, (k + 0.5) / 180 pi."""
    nh, nd, npd = MERL_SHAPE
    theta_h = ((np.arange(nh) + 0.5) / nh) ** 2 * _HALF_PI
    theta_d = (np.arange(nd) + 0.5) / nd * _HALF_PI
    phi_d = (np.arange(npd) + 0.5) / npd * math.pi
    return theta_h, theta_d, phi_d


def directions_from_half_diff(theta_h, theta_d, phi_d):
    """Local unit directions (l, v) (normal +z, phi_h = 0) with the given half/difference
    angles (broadcast): d = (sin theta_d cos phi_d, sin theta_d sin phi_d, cos theta_d)
    rotated by theta_h about the binormal +y gives l, and v = 2 (l . h) h - l is its
    mirror about h = (sin theta_h, 0, cos theta_h) (Rusinkiewicz 1998)."""
    theta_h, theta_d, phi_d = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64)
                                                    for x in (theta_h, theta_d, phi_d)))
    sd = np.sin(theta_d)
    dx, dy, dz = sd * np.cos(phi_d), sd * np.sin(phi_d), np.cos(theta_d)
    ch, sh = np.cos(theta_h), np.sin(theta_h)
    l = np.stack([ch * dx + sh * dz, dy, -sh * dx + ch * dz], axis=-1)
    h = np.stack([sh, np.zeros_like(sh), ch], axis=-1)
    v = 2.0 * _dot(l, h)[..., None] * h - l
    return l, v


@functools.lru_cache(maxsize=1)
def _grid_directions():
    th, td, pd = merl_bin_centres()
    l, v = directions_from_half_diff(th[:, None, None], td[None, :, None], pd[None, None, :])
    l.flags.writeable = False
    v.flags.writeable = False
    return l, v


def merl_directions():
    """The bin-centre direction pairs (l, v) of the MERL grid, each float64
    (90, 90, 180, 3) in the local frame (normal +z, phi_h = 0;
    :func:`merl_bin_centres`, :func:`directions_from_half_diff`).  Some lie
    below the horizon (l.z <= 0 or v.z <= 0): those bins are never measured.
    Computed once and shared: the arrays are read-only."""
    return _grid_directions()


def merl_table(fn):
    """Sample a BRDF onto the MERL grid: ``fn(l, v, n)`` is called once with the
    bin-centre directions of :func:`merl_directions` ((90, 90, 180, 3), local frame)
    and n = +z, and must return f (not f cos) with shape (90, 90, 180, 3) (or
    broadcastable to it), e.g. ``lambda l, v, n: models.cook_torrance(l, v, n, material)``
    (any :mod:`pbrkit.brdf.models` function).  Returns float64 (3, 90, 90, 180)
    in physical units; bins whose centre lies below the horizon are marked
    missing (-1), as in the database."""
    l, v = merl_directions()
    n = np.array([0.0, 0.0, 1.0])
    f = np.asarray(fn(l, v, n), dtype=np.float64)
    f = np.broadcast_to(f, MERL_SHAPE + (3,))
    if not np.all(np.isfinite(f)):
        raise ValueError(f"merl_table: the BRDF gave {int((~np.isfinite(f)).sum())} non-finite value(s)")
    table = np.ascontiguousarray(np.moveaxis(f, -1, 0))
    below = (l[..., 2] <= 0.0) | (v[..., 2] <= 0.0)
    table[:, below] = _MISSING
    return table


# ------------------------------------------------------------------ the BRDF


@dataclass(frozen=True)
class MerlBRDF:
    """A measured isotropic BRDF on the MERL grid.

    ``table``: float64 (3, 90, 90, 180) [channel, theta_h, theta_d, phi_d], already
    scaled (f in 1/sr), negative where missing (stored read-only); ``name``: the
    material (a file's stem, e.g. ``gold-metallic-paint``)."""

    table: np.ndarray
    name: str = "measured"

    def __post_init__(self):
        table = np.array(self.table, dtype=np.float64, copy=True)
        if table.shape != (3,) + MERL_SHAPE:
            raise ValueError(f"MerlBRDF.table must have shape (3, 90, 90, 180); got {table.shape}")
        if not np.all(np.isfinite(table)):
            raise ValueError(f"MerlBRDF.table has {int((~np.isfinite(table)).sum())} non-finite value(s)")
        table.flags.writeable = False
        object.__setattr__(self, "table", table)

    @property
    def valid(self):
        """Bool (90, 90, 180), read-only: bins measured in every channel (no negative value)."""
        valid = self.__dict__.get("_valid")
        if valid is None:
            valid = np.all(self.table >= 0.0, axis=0)
            valid.flags.writeable = False
            object.__setattr__(self, "_valid", valid)
        return valid

    def evaluate(self, l, v, n=None, interpolation="nearest"):
        """f (..., 3) (not f cos) for unit directions l (toward the light) and v
        (toward the eye) in the last axis, about the normal n (default +z, the
        local frame; any broadcastable shapes, as :mod:`pbrkit.brdf.models`).
        ``interpolation``: ``"nearest"`` (the reader's bin) or ``"trilinear"``
        (module doc).  0 below the horizon and in missing bins.  One compiled
        parallel kernel (:func:`half_diff_xyz`, :func:`index_coordinates`)."""
        if interpolation not in MERL_INTERPOLATIONS:
            raise ValueError(f"unknown interpolation {interpolation!r}; choose one of "
                             f"{', '.join(MERL_INTERPOLATIONS)}")
        l = np.asarray(l, dtype=np.float64)
        v = np.asarray(v, dtype=np.float64)
        n = np.array([0.0, 0.0, 1.0]) if n is None else np.asarray(n, dtype=np.float64)
        shape = np.broadcast_shapes(l.shape, v.shape, n.shape)
        if shape[-1] != 3:
            raise ValueError(f"directions must have 3 components in their last axis; got shape {shape}")

        def rows(x):
            return np.ascontiguousarray(np.broadcast_to(x, shape).reshape(-1, 3))

        out = np.empty((int(np.prod(shape[:-1])), 3))
        _lookup_kernel(self.table, self.valid, rows(l), rows(v), rows(n), interpolation == "trilinear", out)
        return out.reshape(shape)


# ------------------------------------------------------------------ the file


def _other_header(dims, size):
    """Why a header ``dims`` other than (90, 90, 180) is refused.  Its numbers are
    named only where each is a plausible dimension (1 to 65536: two zero high
    bytes, which text never has), so a text file's first bytes are never echoed."""
    if not all(1 <= d <= 1 << 16 for d in dims):
        return ("not a MERL BRDF file: its 12-byte header is not three little-endian int32 dimensions; "
                "expected 90 x 90 x 180")
    declared = _HEADER_BYTES + 3 * 8 * math.prod(dims)
    agrees = "the file's length agrees" if declared == size else f"{declared} bytes, the file has {size}"
    return (f"not a MERL BRDF file of the database's table: header dimensions {dims[0]} x {dims[1]} x {dims[2]} "
            f"({agrees}); pbrkit reads 90 x 90 x 180 bins")


_EXPECTED = "a MERL BRDF file (a 90 x 90 x 180 int32 header and 3 x 1458000 float64 values)"


def _read_file(path):
    """The bytes of the MERL file ``path``: the header checked before the values
    are read (module doc)."""
    with open_regular(path, None, _EXPECTED) as f:
        size = os.fstat(f.fileno()).st_size
        try:
            head = f.read(_HEADER_BYTES)
        except OSError as exc:
            raise InputError(f"cannot read file ({exc.strerror or exc}); expected {_EXPECTED}", path) from None
        if len(head) < _HEADER_BYTES:
            raise InputError(f"not a MERL BRDF file: {size} bytes, shorter than its 12-byte header", path)
        dims = tuple(int(x) for x in np.frombuffer(head, dtype="<i4", count=3))
        if dims != MERL_SHAPE:
            raise InputError(_other_header(dims, size), path)
        if size != _FILE_BYTES:
            if size < _FILE_BYTES:
                problem = f"truncated MERL BRDF file: {size} bytes, expected the {_FILE_BYTES} its header declares"
            else:
                problem = (f"MERL BRDF file of {size} bytes, longer than the {_FILE_BYTES} its header declares "
                           "(trailing data)")
            raise InputError(problem, path)
        # the values, a non-finite mask, the scaled table and the MerlBRDF's copy
        check_allocation(_FILE_BYTES * 3 + _BINS * 3, "the MERL table", path)
        try:
            data = f.read(_FILE_BYTES - _HEADER_BYTES + 1)
        except OSError as exc:
            raise InputError(f"cannot read file ({exc.strerror or exc}); expected {_EXPECTED}", path) from None
    if len(data) != _FILE_BYTES - _HEADER_BYTES:
        raise InputError(f"changed while it was read; expected {_EXPECTED}", path)
    return data


def read_merl(path) -> MerlBRDF:
    """Read a MERL binary BRDF file (module doc) into a :class:`MerlBRDF` named
    after the file's stem.  A missing file or one that is not a regular file (a
    device, pipe or folder, also behind a symbolic link), a header other than
    (90, 90, 180), a file shorter or longer than 12 + 3 x 1458000 x 8 bytes, or
    NaN / Inf values raise :class:`pbrkit.core.errors.InputError` with one line
    naming the file and never quoting it."""
    data = _read_file(path)
    raw = np.frombuffer(data, dtype="<f8").reshape((3,) + MERL_SHAPE)
    bad = ~np.isfinite(raw)
    if np.any(bad):
        raise InputError(f"MERL BRDF file has {int(bad.sum())} non-finite (NaN / Inf) value(s)", path)
    del bad
    table = raw * np.asarray(MERL_SCALE)[:, None, None, None]
    return MerlBRDF(table, Path(path).name.split(".")[0] or Path(path).name)


def _stored_values(table):
    """The unscaled values v with v x scale == table wherever a double allows it
    (table / scale, nudged by one ulp where the division rounded the other way)."""
    scale = np.asarray(MERL_SCALE)[:, None, None, None]
    raw = table / scale
    for _ in range(2):
        back = raw * scale
        raw = np.where(back < table, np.nextafter(raw, np.inf), np.where(back > table, np.nextafter(raw, -np.inf), raw))
    return raw


def merl_bytes(table) -> bytes:
    """The MERL binary file of a table (3, 90, 90, 180) of f values (physical units,
    negative = missing): the int32 header (90, 90, 180), then the values divided by
    :data:`MERL_SCALE`, channel-major, little-endian float64."""
    table = np.asarray(table, dtype=np.float64)
    if table.shape != (3,) + MERL_SHAPE:
        raise ValueError(f"a MERL table must have shape (3, 90, 90, 180); got {table.shape}")
    if not np.all(np.isfinite(table)):
        raise ValueError(f"a MERL table must be finite; {int((~np.isfinite(table)).sum())} value(s) are not")
    header = np.asarray(MERL_SHAPE, dtype="<i4").tobytes()
    return header + np.ascontiguousarray(_stored_values(table), dtype="<f8").tobytes()


def write_merl(path, table):
    """Write ``table`` (3, 90, 90, 180) (or a :class:`MerlBRDF`) as a MERL binary
    file, atomically (:func:`merl_bytes`); :func:`read_merl` reads it back (equal to
    the table where a double allows, else within one ulp)."""
    if isinstance(table, MerlBRDF):
        table = table.table
    write_bytes(path, merl_bytes(table))
