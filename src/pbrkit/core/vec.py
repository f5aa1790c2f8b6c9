"""Vector helpers for directions stored in the last axis of arrays (..., 3).

Conventions (``CONVENTIONS.md``): world space is right-handed with +Y up; the
shading frame has normal ``n``, view ``v`` (surface to eye), light ``l``
(surface to light) and half vector ``h = normalize(l + v)``.  Local sampling
frames follow pbrt-v4: the normal is +z, ``(x, y)`` are tangent and bitangent.
"""

from __future__ import annotations

import numpy as np

from .jit import dual_use, select

__all__ = [
    "dot",
    "normalize",
    "half_vector",
    "orthonormal_basis_xyz",
    "orthonormal_basis",
    "shading_frame",
    "to_local",
    "to_world",
    "spherical_direction",
]


def dot(a, b):
    """Dot product over the last axis."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    return np.sum(a * b, axis=-1)


def normalize(v):
    """Unit vectors along the last axis; a zero vector raises ``ValueError``."""
    v = np.asarray(v, dtype=float)
    length = np.sqrt(np.sum(v * v, axis=-1, keepdims=True))
    if np.any(length == 0.0) or not np.all(np.isfinite(length)):
        raise ValueError("cannot normalise a zero-length or non-finite vector")
    return v / length


def half_vector(l, v):
    """h = normalize(l + v).  Where l = -v the half vector is undefined; the
    normal-incidence direction +z is substituted so that callers never see NaN."""
    s = np.asarray(l, dtype=float) + np.asarray(v, dtype=float)
    length = np.sqrt(np.sum(s * s, axis=-1, keepdims=True))
    fallback = np.zeros_like(s)
    fallback[..., 2] = 1.0
    safe = length > 1e-12
    return np.where(safe, s / np.where(safe, length, 1.0), fallback)


@dual_use
def orthonormal_basis_xyz(x, y, z):
    """Tangent and bitangent ``((tx, ty, tz), (bx, by, bz))`` of unit normal
    (x, y, z), with (t, b, n) right-handed, as component tuples (a dual-use
    term: NumPy arrays from Python, scalars in Numba kernels).

    Duff, Burgess, Christensen, Hery, Kensler, Liani, Villemin, "Building an
    Orthonormal Basis, Revisited", JCGT 6(1), 2017, Listing 3 (branchless,
    continuous except at the -z pole's sign flip).
    """
    sign = select(z >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + z)
    b = x * y * a
    return (1.0 + sign * x * x * a, sign * b, -sign * x), (b, sign + y * y * a, -y)


def orthonormal_basis(n):
    """Tangent and bitangent ``(t, b)``, each (..., 3), with ``(t, b, n)``
    right-handed: :func:`orthonormal_basis_xyz` (Duff et al. 2017, Listing 3) stacked."""
    n = np.asarray(n, dtype=float)
    t, bt = orthonormal_basis_xyz(n[..., 0], n[..., 1], n[..., 2])
    return np.stack(np.broadcast_arrays(*t), axis=-1), np.stack(np.broadcast_arrays(*bt), axis=-1)


def shading_frame(n, t=None):
    """Tangent, bitangent and normal ``(t, b, n)`` of a right-handed frame.

    When the tangent ``t`` is omitted it is built by :func:`orthonormal_basis`;
    a given tangent is Gram-Schmidt orthogonalised against ``n``.
    """
    n = np.asarray(n, dtype=float)
    if t is None:
        t, b = orthonormal_basis(n)
    else:
        t = np.asarray(t, dtype=float)
        t = normalize(t - dot(t, n)[..., None] * n)
        b = np.cross(n, t)
    return t, b, n


def to_local(w, n, t=None):
    """Express world directions ``w`` in the frame (t, b, n) (normal on +z)."""
    t, b, n = shading_frame(n, t)
    w = np.asarray(w, dtype=float)
    return np.stack([dot(w, t), dot(w, b), dot(w, n)], axis=-1)


def to_world(w_local, n, t=None):
    """Inverse of :func:`to_local`."""
    t, b, n = shading_frame(n, t)
    w_local = np.asarray(w_local, dtype=float)
    return w_local[..., 0:1] * t + w_local[..., 1:2] * b + w_local[..., 2:3] * n


def spherical_direction(cos_theta, phi):
    """Local direction with polar angle from +z and azimuth ``phi`` from +x."""
    cos_theta = np.asarray(cos_theta, dtype=float)
    sin_theta = np.sqrt(np.maximum(0.0, 1.0 - cos_theta * cos_theta))
    return np.stack([sin_theta * np.cos(phi), sin_theta * np.sin(phi), cos_theta], axis=-1)
