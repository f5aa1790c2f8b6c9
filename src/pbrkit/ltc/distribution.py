"""The Linearly Transformed Cosine distribution: evaluation, sampling, polygon
integrals, and the matrix parameterisation and storage of the published fit.

Heitz, Dupuy, Hill, Neubelt 2016, "Real-Time Polygonal-Light Shading with
Linearly Transformed Cosines", ACM TOG 35(4) (SIGGRAPH 2016): with
D_o(w_o) = max(0, w_o.z) / pi the clamped cosine and M an invertible 3 x 3
matrix, the directions w = M w_o / |M w_o| have the distribution (eqs. 1-3)

    D(w) = D_o(w_o) |d w_o / d w|,   w_o = M^-1 w / |M^-1 w|,
    |d w_o / d w| = |det M^-1| / |M^-1 w|^3,

so D(w) = max(0, (M^-1 w)_z) |det M^-1| / (pi |M^-1 w|^4) for unit w.  D is
normalised (it integrates to 1 over the sphere, whatever M), so it is its own
pdf, and its integral over a polygon P is the clamped-cosine integral over
the polygon M^-1 P (the same change of variables), which :mod:`pbrkit.ltc.polygon` gives in closed
form.  D is unchanged when M (or M^-1) is multiplied by a *positive* number;
a negative factor maps the lobe to its antipode.

Frame (``docs/CONVENTIONS.md``): the local shading frame, normal +z,
directions pointing away from the surface.  For an isotropic BRDF the fit
places the view in the xz plane on the +x side, v = (sin theta_v, 0, cos theta_v)
(ltc_code's ``fitLTC.cpp``), and x, y = z x x, z form pbrkit's right-handed
frame.  D then approximates the cosine-weighted BRDF lobe over light
directions w, f(v, w) w_z, divided by its norm (the directional albedo).

Parameterisation (Heitz's fit; ltc_code ``fit/LTC.h``, ``fitLTC.cpp``): an
isotropic lobe in that frame is symmetric under y -> -y, so M has the form

    M = [[a, 0, b],
         [0, c, 0],
         [d, 0, 1]]      (rows; M_22 normalised to 1),

    M^-1 = 1 / (a - b d) [[1, 0, -b], [0, (a - b d) / c, 0], [-d, 0, a]],

with c > 0 and a - b d > 0 for a fit (det M = c (a - b d) > 0).  Because the
lobe has that symmetry, a left-handed frame (three.js uses y = -(z x x))
gives the same values; only polygon windings flip.

Storage (the ``ltc_1`` table; ltc_code ``fitLTC.cpp`` ``packTab``, three.js
``RectAreaLightUniformsLib``, ``docs/CONVENTIONS.md``): the four entries
(m00, m20, m02, m22) of M^-1 / (M^-1)_11, with (row, column) indices, which a
shader reads back as GLSL ``mat3(vec3(x, 0, y), vec3(0, 1, 0), vec3(z, 0, w))``
(column-major: column 0 is (x, 0, y)).  For the parameters above the texel is
c / (a - b d) (1, -d, -b, a).  The normalisation divides by (M^-1)_11 = 1 / c,
a positive factor exactly when c > 0, so the stored matrix gives the same D.

Every term is a :func:`pbrkit.core.jit.dual_use` function (matrix entries and
direction components as scalars, as in :mod:`pbrkit.sampling.warps`), with
NumPy wrappers on (..., 3, 3) matrices and (..., 3) directions.  No roughness
remap is involved anywhere in this module: the matrices are what a fit
produces; the fit's table axes (perceptual roughness, alpha = r^2) belong to
the fitter.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import dual_use
from ..sampling.warps import warp_cosine_hemisphere
from .polygon import transformed_polygon_form_factor, transformed_polygon_integrals

__all__ = [
    "ltc_matrix",
    "ltc_inverse_matrix",
    "ltc_texel",
    "texel_from_inverse",
    "inverse_from_texel",
    "params_from_texel",
    "ltc_evaluate_xyz",
    "warp_ltc",
    "ltc_polygon_integral_single",
    "ltc_evaluate",
    "ltc_pdf",
    "ltc_sample",
    "ltc_polygon_integral",
]

_INV_PI = 1.0 / math.pi


# =========================================================================
# Parameterisation and storage (NumPy)
# =========================================================================


def _params(a, b, c, d):
    a, b, c, d = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64) for x in (a, b, c, d)))
    if not all(np.all(np.isfinite(x)) for x in (a, b, c, d)):
        raise ValueError("the LTC parameters (a, b, c, d) must be finite")
    return a, b, c, d


def ltc_matrix(a, b, c, d):
    """M = [[a, 0, b], [0, c, 0], [d, 0, 1]] (rows), shape (..., 3, 3): Heitz et
    al. 2016's isotropic parameterisation with M_22 = 1 (ltc_code
    ``fit/LTC.h``; module docstring for the frame).  The parameters broadcast.
    No roughness remap is involved."""
    a, b, c, d = _params(a, b, c, d)
    m = np.zeros(a.shape + (3, 3))
    m[..., 0, 0] = a
    m[..., 0, 2] = b
    m[..., 1, 1] = c
    m[..., 2, 0] = d
    m[..., 2, 2] = 1.0
    return m


def ltc_inverse_matrix(a, b, c, d):
    """M^-1 = [[1, 0, -b], [0, (a - b d) / c, 0], [-d, 0, a]] / (a - b d) for
    :func:`ltc_matrix` (a, b, c, d), shape (..., 3, 3), in closed form (the
    adjugate; ltc_code ``fitLTC.cpp`` ``packTab`` inverts the same form).
    Raises ValueError where M is singular (c = 0 or a = b d).  No roughness
    remap is involved."""
    a, b, c, d = _params(a, b, c, d)
    det2 = a - b * d
    if np.any(det2 == 0.0) or np.any(c == 0.0):
        raise ValueError("the LTC matrix is singular (c = 0 or a - b d = 0)")
    m = np.zeros(a.shape + (3, 3))
    m[..., 0, 0] = 1.0 / det2
    m[..., 0, 2] = -b / det2
    m[..., 1, 1] = 1.0 / c
    m[..., 2, 0] = -d / det2
    m[..., 2, 2] = a / det2
    return m


def ltc_texel(a, b, c, d):
    """The ``ltc_1`` texel (x, y, z, w) = (m00, m20, m02, m22) of M^-1 / (M^-1)_11
    for :func:`ltc_matrix` (a, b, c, d): c / (a - b d) (1, -d, -b, a), shape (..., 4).

    The storage of ltc_code (``fitLTC.cpp`` ``packTab``: ``invM /= invM[1][1]``,
    GLM column-major, so its ``invM[0][2]`` is our m20) and three.js
    (``RectAreaLightUniformsLib``), read back by
    ``mat3(vec3(x, 0, y), vec3(0, 1, 0), vec3(z, 0, w))`` (:func:`inverse_from_texel`).
    Same lobe as M when c > 0 (module docstring).  No roughness remap is
    involved."""
    a, b, c, d = _params(a, b, c, d)
    det2 = a - b * d
    if np.any(det2 == 0.0) or np.any(c == 0.0):
        raise ValueError("the LTC matrix is singular (c = 0 or a - b d = 0)")
    scale = c / det2
    return np.stack([scale, -d * scale, -b * scale, a * scale], axis=-1)


def texel_from_inverse(m_inv):
    """(m00, m20, m02, m22) / m11 of inverse matrices (..., 3, 3) -> (..., 4):
    the ``ltc_1`` storage (ltc_code ``packTab``; :func:`ltc_texel`).  Only
    those five entries are read: the matrix must have the isotropic sparsity
    (m01 = m10 = m12 = m21 = 0) for the texel to represent it, and m11 > 0
    for the same lobe (a negative m11 would flip it).  Raises ValueError if
    m11 is 0.  No roughness remap is involved."""
    m = np.asarray(m_inv, dtype=np.float64)
    if m.ndim < 2 or m.shape[-2:] != (3, 3):
        raise ValueError(f"m_inv must have shape (..., 3, 3); got {m.shape}")
    m11 = m[..., 1, 1]
    if np.any(m11 == 0.0) or not np.all(np.isfinite(m)):
        raise ValueError("m_inv must be finite with m11 != 0")
    return np.stack([m[..., 0, 0], m[..., 2, 0], m[..., 0, 2], m[..., 2, 2]], axis=-1) / m11[..., None]


def inverse_from_texel(texel):
    """The normalised inverse matrix [[x, 0, z], [0, 1, 0], [y, 0, w]] (rows) of
    ``ltc_1`` texels (x, y, z, w), (..., 4) -> (..., 3, 3): what three.js and
    ltc_code's shaders build with ``mat3(vec3(x, 0, y), vec3(0, 1, 0),
    vec3(z, 0, w))`` (GLSL constructors take columns).  It is M^-1 scaled by
    c > 0, so :func:`ltc_evaluate` gives the same D with it.  No roughness
    remap is involved."""
    t = np.asarray(texel, dtype=np.float64)
    if t.ndim < 1 or t.shape[-1] != 4:
        raise ValueError(f"texel must have shape (..., 4); got {t.shape}")
    m = np.zeros(t.shape[:-1] + (3, 3))
    m[..., 0, 0] = t[..., 0]
    m[..., 2, 0] = t[..., 1]
    m[..., 0, 2] = t[..., 2]
    m[..., 2, 2] = t[..., 3]
    m[..., 1, 1] = 1.0
    return m


def params_from_texel(texel):
    """(a, b, c, d) of :func:`ltc_matrix` from ``ltc_1`` texels (..., 4), the
    inverse of :func:`ltc_texel`: inverting [[x, 0, z], [0, 1, 0], [y, 0, w]]
    and scaling to M_22 = 1 gives a = w / x, b = -z / x, c = (x w - y z) / x,
    d = -y / x.  Valid for texels of a lobe with M_22 > 0 and c > 0 (every
    fitted texel: then x > 0 and x w - y z > 0).  Raises ValueError where x
    or x w - y z is 0.  No roughness remap is involved."""
    t = np.asarray(texel, dtype=np.float64)
    if t.ndim < 1 or t.shape[-1] != 4:
        raise ValueError(f"texel must have shape (..., 4); got {t.shape}")
    x, y, z, w = t[..., 0], t[..., 1], t[..., 2], t[..., 3]
    det = x * w - y * z
    if np.any(x == 0.0) or np.any(det == 0.0):
        raise ValueError("texel does not describe an invertible LTC with M_22 != 0")
    return w / x, -z / x, det / x, -y / x


# =========================================================================
# Terms (dual-use scalars)
# =========================================================================


@dual_use
def ltc_evaluate_xyz(i00, i01, i02, i10, i11, i12, i20, i21, i22, x, y, z):
    """D(w) of the LTC with inverse matrix M^-1 = [[i00, i01, i02], [i10, i11, i12],
    [i20, i21, i22]] at the direction w = (x, y, z).

    Heitz et al. 2016, eqs. 1-3: D(w) = D_o(w_o) |det M^-1| / |M^-1 w|^3 with
    w_o = M^-1 w / |M^-1 w| and D_o = max(0, w_o.z) / pi, written as
    max(0, t_z) |det M^-1| |w|^3 / (pi |t|^4) with t = M^-1 w, which is the
    same for unit w and makes D a function of the direction of w only (any
    non-zero length).  Normalised over the sphere for any invertible M; also
    the pdf of :func:`warp_ltc`.  No roughness remap is involved.
    """
    tx = i00 * x + i01 * y + i02 * z
    ty = i10 * x + i11 * y + i12 * z
    tz = i20 * x + i21 * y + i22 * z
    det = (i00 * (i11 * i22 - i12 * i21) - i01 * (i10 * i22 - i12 * i20) + i02 * (i10 * i21 - i11 * i20))
    t2 = tx * tx + ty * ty + tz * tz
    w2 = x * x + y * y + z * z
    return np.maximum(tz, 0.0) * np.abs(det) * w2 * np.sqrt(w2) * _INV_PI / (t2 * t2)


@dual_use
def warp_ltc(m00, m01, m02, m10, m11, m12, m20, m21, m22, u1, u2):
    """A direction distributed as the LTC with matrix M = [[m00, m01, m02], ...]
    from (u1, u2) in [0, 1]^2: w_o by cosine-weighted hemisphere sampling
    (Malley's method on the concentric disk,
    :func:`pbrkit.sampling.warps.warp_cosine_hemisphere`), then
    w = M w_o / |M w_o| (Heitz et al. 2016; ltc_code ``LTC.h``
    ``sample``).  Returns (x, y, z); pdf :func:`ltc_evaluate_xyz` with M^-1.
    No roughness remap is involved."""
    ox, oy, oz = warp_cosine_hemisphere(u1, u2)
    x = m00 * ox + m01 * oy + m02 * oz
    y = m10 * ox + m11 * oy + m12 * oz
    z = m20 * ox + m21 * oy + m22 * oz
    inv = 1.0 / np.sqrt(x * x + y * y + z * z)
    return x * inv, y * inv, z * inv


@dual_use
def ltc_polygon_integral_single(m_inv, vertices):
    """The signed integral of the LTC with inverse matrix ``m_inv`` (3, 3) over
    one polygon ``vertices`` (K, 3): the clamped-cosine integral of the
    polygon M^-1 P (Heitz et al. 2016: eqs. 1-3 as a change of variables, then eq. 11;
    :func:`pbrkit.ltc.polygon.transformed_polygon_form_factor`), times the sign
    of det M^-1 so that the winding convention of
    :mod:`pbrkit.ltc.polygon` holds for P itself (a reflecting M^-1 reverses
    the transformed polygon).  No roughness remap is involved."""
    det = (m_inv[0, 0] * (m_inv[1, 1] * m_inv[2, 2] - m_inv[1, 2] * m_inv[2, 1])
           - m_inv[0, 1] * (m_inv[1, 0] * m_inv[2, 2] - m_inv[1, 2] * m_inv[2, 0])
           + m_inv[0, 2] * (m_inv[1, 0] * m_inv[2, 1] - m_inv[1, 1] * m_inv[2, 0]))
    value = transformed_polygon_form_factor(m_inv, vertices)
    return -value if det < 0.0 else value


# =========================================================================
# NumPy API
# =========================================================================


def _matrices(m, name):
    m = np.asarray(m, dtype=np.float64)
    if m.ndim < 2 or m.shape[-2:] != (3, 3):
        raise ValueError(f"{name} must have shape (..., 3, 3); got {m.shape}")
    if not np.all(np.isfinite(m)):
        raise ValueError(f"{name} must be finite")
    if np.any(np.linalg.det(m) == 0.0):
        raise ValueError(f"{name} must be invertible")
    return m


def _entries(m):
    return tuple(m[..., r, c] for r in range(3) for c in range(3))


def ltc_evaluate(m_inv, w):
    """D(w) of the LTC with inverse matrix ``m_inv`` (..., 3, 3) at directions
    ``w`` (..., 3) (leading dimensions broadcast) -> (...).

    Heitz et al. 2016, eqs. 1-3 (:func:`ltc_evaluate_xyz`); normalised over
    the sphere.  ``w`` need not be unit length (D depends on its direction).
    Frame and parameterisation: module docstring.  No roughness remap is
    involved."""
    m = _matrices(m_inv, "m_inv")
    w = np.asarray(w, dtype=np.float64)
    if w.ndim < 1 or w.shape[-1] != 3:
        raise ValueError(f"w must have shape (..., 3); got {w.shape}")
    if not np.all(np.isfinite(w)) or np.any(np.all(w == 0.0, axis=-1)):
        raise ValueError("w must be finite and non-zero")
    return ltc_evaluate_xyz(*_entries(m), w[..., 0], w[..., 1], w[..., 2])


def ltc_pdf(m_inv, w):
    """The solid-angle pdf of :func:`ltc_sample` (with M = m_inv^-1): D itself,
    which is normalised (Heitz et al. 2016, eqs. 1-3); :func:`ltc_evaluate`.
    No roughness remap is involved."""
    return ltc_evaluate(m_inv, w)


def ltc_sample(m, u1, u2):
    """Directions distributed as the LTC with matrix ``m`` (..., 3, 3) from
    ``u1``, ``u2`` in [0, 1] (all broadcast) -> (..., 3) unit vectors.

    Cosine-weighted sample of the hemisphere transformed by M and normalised
    (Heitz et al. 2016; :func:`warp_ltc`).  Its pdf is
    :func:`ltc_pdf` with ``np.linalg.inv(m)``.  No roughness remap is
    involved."""
    m = _matrices(m, "m")
    u1 = np.asarray(u1, dtype=np.float64)
    u2 = np.asarray(u2, dtype=np.float64)
    if not (np.all((u1 >= 0.0) & (u1 <= 1.0)) and np.all((u2 >= 0.0) & (u2 <= 1.0))):
        raise ValueError("u1 and u2 must lie in [0, 1] (and be finite)")
    x, y, z = warp_ltc(*_entries(m), u1, u2)
    return np.stack(np.broadcast_arrays(x, y, z), axis=-1)


def ltc_polygon_integral(m_inv, vertices):
    """The integral of the LTC with inverse matrix ``m_inv`` (..., 3, 3) over the
    polygons ``vertices`` (..., K, 3) (leading dimensions broadcast) -> (...).

    Heitz et al. 2016 (eqs. 1-3 as a change of variables): the integral of D over P equals that of the
    clamped cosine over M^-1 P, given in closed form with exact horizon
    clipping by :func:`pbrkit.ltc.polygon.polygon_clamped_cosine_integral`
    (Arvo 1995; Heitz et al. eq. 11).  Signed with the winding convention of
    :mod:`pbrkit.ltc.polygon` for P (the sign of det M^-1 is accounted for):
    positive for vertices counter-clockwise as seen from the shading point.
    Runs in a parallel Numba kernel; :func:`ltc_polygon_integral_single` is
    the same for one polygon inside other kernels.  No roughness remap is
    involved."""
    m = _matrices(m_inv, "m_inv")
    values = transformed_polygon_integrals(m, vertices)
    return values * np.sign(np.linalg.det(m))
