"""Real spherical harmonics of bands l = 0..2 and irradiance environment maps.

Basis, order and normalisation follow ``CONVENTIONS.md`` ("Spherical
harmonics"): the real, orthonormal SH on world (x, y, z), in the order
(0,0), (1,-1), (1,0), (1,1), (2,-2), (2,-1), (2,0), (2,1), (2,2)::

    Y00  = 1/2 sqrt(1/pi)                   Y2-2 = 1/2 sqrt(15/pi) x y
    Y1-1 = sqrt(3/(4 pi)) y                 Y2-1 = 1/2 sqrt(15/pi) y z
    Y10  = sqrt(3/(4 pi)) z                 Y20  = 1/4 sqrt(5/pi) (3 z^2 - 1)
    Y11  = sqrt(3/(4 pi)) x                 Y21  = 1/2 sqrt(15/pi) x z
                                            Y22  = 1/4 sqrt(15/pi) (x^2 - y^2)

(1/2 sqrt(15/pi) = sqrt(15/(4 pi)) = 1.092548..., 1/4 sqrt(5/pi) =
sqrt(5/(16 pi)) = 0.315392..., 1/4 sqrt(15/pi) = sqrt(15/(16 pi)) =
0.546274...).  These are Ramamoorthi & Hanrahan, "An Efficient
Representation for Irradiance Environment Maps", SIGGRAPH 2001, eq. 3
(no Condon-Shortley phase: Y11 = +0.488603 x; z is the polar axis of the
basis, although world "up" is +Y).

Coefficients are the *radiance* projection L_lm = integral of L(w) Y_lm(w)
dw.  An equirect image is taken as piecewise constant over its pixels' cells
and each cell's integral of Y_lm is computed in closed form
(:func:`project_equirect`: exact, L_00 of a constant map is sqrt(4 pi) to
rounding at any size); cube maps and direction samples use the sum
sum_i L(w_i) Y_lm(w_i) dOmega_i over texels with their exact solid angles
(:func:`project_cube`, :func:`project`).  Irradiance E(n) = integral of L(w) max(0, n.w) dw is, by the
Funk-Hecke theorem, E(n) = sum_lm A_l L_lm Y_lm(n) with the clamped-cosine
coefficients A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4 (Ramamoorthi & Hanrahan
2001, eqs. 7-9; every degree: :func:`cosine_lobe_coefficients`), exact for
radiance band-limited to l <= 2.

Truncation error.  For any non-negative radiance the 9-coefficient
irradiance E_2 differs from the exact E by at most (3/32) times the total
radiance integral of L dw:  E - E_2 = integral of L(w) [max(0, t) - k_2(t)] dw
with t = n.w and the truncated kernel k_2(t) = sum_{l<=2} A_l (2l + 1) /
(4 pi) P_l(t) = 1/4 + t/2 + (5/32) (3 t^2 - 1), whose largest deviation from
max(0, t) on [-1, 1] is 3/32 at t = 0 (see :data:`TRUNCATION_ERROR_BOUND`).
For a single directional light this is 9.4% of the peak irradiance, the
worst case; smooth environments do far better.

No roughness remap is involved (the cosine lobe is Lambertian).
"""

from __future__ import annotations

import math

import numpy as np

from ..core.errors import InputError
from ..core.jit import dual_use, row_kernel
from .cubemap import cube_texel_directions, cube_texel_solid_angles
from .equirect import equirect_pixel_angles

__all__ = [
    "SH_COUNT",
    "SH_BANDS",
    "cosine_lobe_coefficients",
    "COSINE_LOBE_COEFFICIENTS",
    "TRUNCATION_ERROR_BOUND",
    "sh9",
    "sh_basis",
    "sh_window",
    "apply_window",
    "project",
    "project_equirect",
    "project_cube",
    "eval_sh",
    "irradiance_from_sh",
    "SH_POLYNOMIAL_CONSTANTS",
    "mirror_sh",
    "lambertian_sh_prescaled",
    "CONDON_SHORTLEY_SIGNS",
    "BABYLON_POLYNOMIAL_TERMS",
    "babylon_harmonics",
    "babylon_polynomial",
]

SH_COUNT = 9
#: Band l of each of the 9 coefficients.
SH_BANDS = np.array([0, 1, 1, 1, 2, 2, 2, 2, 2])


def cosine_lobe_coefficients(lmax):
    """A_l (l = 0..L, float64 (L + 1,)) of the clamped cosine max(0, cos
    theta): its Funk-Hecke coefficients 2 pi integral_0^1 t P_l(t) dt, in
    closed form (Ramamoorthi & Hanrahan 2001, eqs. 8-9): A_0 = pi,
    A_1 = 2 pi / 3, A_l = 0 for odd l > 1 and, for even l >= 2,

        A_l = 2 pi (-1)^(l/2 - 1) / ((l + 2)(l - 1)) * l! / (2^l ((l/2)!)^2).

    The last factor c_l = binom(l, l/2) / 2^l comes from the ratio
    recurrence c_0 = 1, c_l = c_{l-2} (l - 1) / l (no factorials, so no
    overflow: stable to any degree; c_l ~ sqrt(2 / (pi l)))."""
    if isinstance(lmax, bool) or not isinstance(lmax, (int, np.integer)) or lmax < 0:
        raise ValueError(f"degree must be a non-negative integer, got {lmax!r}")
    a = np.zeros(int(lmax) + 1)
    a[0] = math.pi
    if lmax >= 1:
        a[1] = 2.0 * math.pi / 3.0
    l = np.arange(2, lmax + 1, 2, dtype=np.float64)
    c = np.cumprod((l - 1.0) / l)
    sign = np.where((np.arange(2, lmax + 1, 2) // 2) % 2 == 1, 1.0, -1.0)
    a[2::2] = 2.0 * math.pi * sign / ((l + 2.0) * (l - 1.0)) * c
    return a


#: A_l of the clamped cosine max(0, cos theta) for l = 0, 1, 2: pi, 2 pi / 3,
#: pi / 4 (:func:`cosine_lobe_coefficients`; Ramamoorthi & Hanrahan 2001, eqs. 8-9).
COSINE_LOBE_COEFFICIENTS = tuple(float(a) for a in cosine_lobe_coefficients(2))
#: max over t in [-1, 1] of |max(0, t) - k_2(t)|: bound of the irradiance
#: truncation error per unit of integral of L dw (module docstring).
TRUNCATION_ERROR_BOUND = 3.0 / 32.0

_Y00 = 0.5 * math.sqrt(1.0 / math.pi)
_Y1 = math.sqrt(3.0 / (4.0 * math.pi))
_Y2_XY = math.sqrt(15.0 / (4.0 * math.pi))
_Y20 = math.sqrt(5.0 / (16.0 * math.pi))
_Y22 = math.sqrt(15.0 / (16.0 * math.pi))


@dual_use
def sh9(x, y, z):
    """The 9 real SH basis functions at unit direction (x, y, z), as a tuple
    in CONVENTIONS.md order (Ramamoorthi & Hanrahan 2001, eq. 3)."""
    return (
        _Y00 + 0.0 * x,
        _Y1 * y,
        _Y1 * z,
        _Y1 * x,
        _Y2_XY * x * y,
        _Y2_XY * y * z,
        _Y20 * (3.0 * z * z - 1.0),
        _Y2_XY * x * z,
        _Y22 * (x * x - y * y),
    )


def sh_basis(d):
    """Y_lm(d) for unit directions ``d`` (..., 3) -> (..., 9)."""
    d = np.asarray(d, dtype=float)
    if d.ndim < 1 or d.shape[-1] != 3:
        raise InputError(f"directions must have shape (..., 3), got {d.shape}")
    return np.stack(sh9(d[..., 0], d[..., 1], d[..., 2]), axis=-1)


def sh_window(window=None, width=3.0):
    """Per-coefficient (9,) window factors for ringing suppression.

    Sloan 2008, "Stupid Spherical Harmonics (SH) Tricks" (GDC), on
    windowing to reduce ringing: band l is scaled by w_l, with window width
    w (> 0):

    - ``None``: w_l = 1 (no windowing, the default everywhere);
    - ``'hanning'``: w_l = (1 + cos(pi l / w)) / 2 for l <= w, else 0;
    - ``'lanczos'``: w_l = sin(pi l / w) / (pi l / w) (w_0 = 1) for l <= w,
      else 0.

    The default width, 3, is the SH order (number of bands) of l = 0..2;
    larger widths window less.
    """
    if window is None:
        return np.ones(SH_COUNT)
    width = float(width)
    if not width > 0.0:
        raise InputError(f"SH window width must be positive, got {width}")
    bands = SH_BANDS.astype(float)
    x = np.pi * bands / width
    if window == "hanning":
        w = 0.5 * (1.0 + np.cos(x))
    elif window == "lanczos":
        w = np.where(bands == 0, 1.0, np.sin(x) / np.where(bands == 0, 1.0, x))
    else:
        raise InputError(f"unknown SH window {window!r}; use None, 'hanning' or 'lanczos'")
    return np.where(bands <= width, w, 0.0)


def _check_coeffs(coeffs):
    c = np.asarray(coeffs, dtype=float)
    if c.ndim < 1 or c.shape[0] != SH_COUNT:
        raise InputError(f"SH coefficients must have shape (9,) or (9, C), got {c.shape}")
    return c


def apply_window(coeffs, window=None, width=3.0):
    """Coefficients (9, ...) multiplied band-wise by :func:`sh_window`."""
    c = _check_coeffs(coeffs)
    w = sh_window(window, width)
    return c * w.reshape((SH_COUNT,) + (1,) * (c.ndim - 1))


def project(directions, solid_angles, radiance, chunk=1 << 16):
    """Radiance SH coefficients L_lm = sum_i L_i Y_lm(w_i) dOmega_i.

    ``directions`` (..., 3) unit vectors, ``solid_angles`` (...) in
    steradians and ``radiance`` (...) or (..., C).  Returns (9,) or (9, C)
    float64.  Works in chunks of ``chunk`` samples to bound memory.
    """
    d = np.asarray(directions, dtype=float)
    w = np.asarray(solid_angles, dtype=float)
    L = np.asarray(radiance, dtype=float)
    if d.ndim < 1 or d.shape[-1] != 3:
        raise InputError(f"directions must have shape (..., 3), got {d.shape}")
    lead = d.shape[:-1]
    if w.shape != lead:
        raise InputError(f"solid_angles shape {w.shape} does not match directions {d.shape}")
    scalar = L.shape == lead
    if not scalar and L.shape[:-1] != lead:
        raise InputError(f"radiance shape {L.shape} does not match directions {d.shape}")
    d = d.reshape(-1, 3)
    w = w.reshape(-1)
    L = L.reshape(d.shape[0], -1)
    out = np.zeros((SH_COUNT, L.shape[1]))
    for start in range(0, d.shape[0], chunk):
        sl = slice(start, start + chunk)
        out += sh_basis(d[sl]).T @ (L[sl] * w[sl, None])
    return out[:, 0] if scalar else out


def _equirect_cell_integrals_theta(rows, h):
    """Integrals over the row bands [theta_i0, theta_i1] (theta_i0 = pi i / H) of
    sin, cos sin, sin^2, sin^2 cos, sin^3 and cos^2 sin of theta, in closed form
    (product forms around the band centre theta_i, half width a = pi / 2H, to
    avoid cancellation); each (rows,)."""
    a = 0.5 * math.pi / h
    t, _ = equirect_pixel_angles(np.asarray(rows, dtype=np.float64), 0, h, 2 * h)
    c0, c1 = np.cos(t - a), np.cos(t + a)
    s0, s1 = np.sin(t - a), np.sin(t + a)
    s_1 = 2.0 * np.sin(t) * math.sin(a)                        # int sin = cos0 - cos1
    s_cs = 0.5 * np.sin(2.0 * t) * math.sin(2.0 * a)           # int cos sin = (cos 2t0 - cos 2t1) / 4
    s_ss = a - 0.5 * np.cos(2.0 * t) * math.sin(2.0 * a)       # int sin^2 = a - (sin 2t1 - sin 2t0) / 4
    s_ssc = (s1 ** 3 - s0 ** 3) / 3.0                          # int sin^2 cos
    s_ccs = (c0 ** 3 - c1 ** 3) / 3.0                          # int cos^2 sin
    s_sss = s_1 - s_ccs                                        # int sin^3 = int (1 - cos^2) sin
    return s_1, s_cs, s_ss, s_ssc, s_sss, s_ccs


def _equirect_cell_integrals_phi(w):
    """Integrals over the column bands [phi_j0, phi_j1] (phi_j0 = 2 pi j / W - pi)
    of 1, cos, sin, cos^2, sin^2 and sin cos of phi, in closed form (product
    forms around the column centre phi_j, half width b = pi / W); (W, 6)."""
    b = math.pi / w
    _, p = equirect_pixel_angles(0, np.arange(w), w // 2, w)
    half = 0.5 * math.sin(2.0 * b)
    return np.stack([
        np.full(w, 2.0 * b),                  # int 1
        2.0 * np.cos(p) * math.sin(b),        # int cos = sin1 - sin0
        2.0 * np.sin(p) * math.sin(b),        # int sin = cos0 - cos1
        b + half * np.cos(2.0 * p),           # int cos^2 = b + (sin 2p1 - sin 2p0) / 4
        b - half * np.cos(2.0 * p),           # int sin^2
        half * np.sin(2.0 * p),               # int sin cos = (cos 2p0 - cos 2p1) / 4
    ], axis=-1)


def project_equirect(image):
    """Radiance SH coefficients (9, C) of an equirectangular image (H, W, C)
    with W = 2 H (or (9,) for (H, W)), the image taken as piecewise constant
    over its pixels' cells (CONVENTIONS.md: row 0 = +Y, cell (i, j) spans
    theta in pi [i, i + 1] / H and phi in 2 pi [j, j + 1] / W - pi; the model
    of :func:`pbrkit.ibl.equirect.equirect_to_cube`).

    L_lm = sum over cells of L_ij times the exact integral of Y_lm over the
    cell.  With d = (sin theta cos phi, cos theta, sin theta sin phi) every
    basis function times the area element sin theta is a sum of products
    f(theta) g(phi) of powers of sines and cosines, so each cell integral is
    a closed form (:func:`_equirect_cell_integrals_theta`,
    :func:`_equirect_cell_integrals_phi`) and the projection has no
    quadrature error at any size: a constant radiance c gives
    L_00 = c sqrt(4 pi) and zero elsewhere to rounding, even for H = 1.
    Work is by bands of rows (memory bounded, no per-pixel loop)."""
    img = np.asarray(image)
    if img.ndim not in (2, 3) or img.shape[1] != 2 * img.shape[0] or img.shape[0] < 1:
        raise InputError(f"equirectangular image must have shape (H, 2H) or (H, 2H, C), got {img.shape}")
    scalar = img.ndim == 2
    if scalar:
        img = img[..., None]
    h, w = img.shape[:2]
    phi = _equirect_cell_integrals_phi(w)
    # r[i, k, c] = sum_j phi_k(j) L[i, j, c] for the six phi factors k
    r = np.empty((h, 6, img.shape[2]))
    rows_per_chunk = max(1, (1 << 16) // w)
    for r0 in range(0, h, rows_per_chunk):
        band = np.asarray(img[r0:r0 + rows_per_chunk], dtype=np.float64)
        r[r0:r0 + band.shape[0]] = np.matmul(phi.T, band)
    s_1, s_cs, s_ss, s_ssc, s_sss, s_ccs = _equirect_cell_integrals_theta(np.arange(h), h)
    one, cos, sin, cos2, sin2, sincos = (r[:, k] for k in range(6))
    out = np.stack([
        _Y00 * (s_1 @ one),                              # 1
        _Y1 * (s_cs @ one),                              # y = cos theta
        _Y1 * (s_ss @ sin),                              # z = sin theta sin phi
        _Y1 * (s_ss @ cos),                              # x = sin theta cos phi
        _Y2_XY * (s_ssc @ cos),                          # x y
        _Y2_XY * (s_ssc @ sin),                          # y z
        _Y20 * (3.0 * (s_sss @ sin2) - s_1 @ one),       # 3 z^2 - 1
        _Y2_XY * (s_sss @ sincos),                       # x z
        _Y22 * (s_sss @ cos2 - s_ccs @ one),             # x^2 - y^2
    ])
    return out[:, 0] if scalar else out


def project_cube(cube):
    """Radiance SH coefficients (9, C) of a cube map (6, N, N, C), faces
    +X, -X, +Y, -Y, +Z, -Z (CONVENTIONS.md "Cube maps"), each texel weighted
    by its exact solid angle.  Texel directions and solid angles come from
    :mod:`pbrkit.ibl.cubemap` (``cube_texel_directions``,
    ``cube_texel_solid_angles``)."""
    c = np.asarray(cube, dtype=float)
    if c.ndim not in (3, 4) or c.shape[0] != 6 or c.shape[1] != c.shape[2]:
        raise InputError(f"cube map must have shape (6, N, N) or (6, N, N, C), got {c.shape}")
    n = c.shape[1]
    return project(cube_texel_directions(n), cube_texel_solid_angles(n), c)


def eval_sh(coeffs, d):
    """sum_lm c_lm Y_lm(d): coefficients (9,) or (9, C) at unit directions
    (..., 3) -> (...) or (..., C).  One compiled pass over the directions
    (:func:`_eval_sh_kernel`: the basis of :func:`sh9` summed in place, no (..., 9)
    array)."""
    c = _check_coeffs(coeffs)
    d = np.asarray(d, dtype=np.float64)
    if d.ndim < 1 or d.shape[-1] != 3:
        raise InputError(f"directions must have shape (..., 3), got {d.shape}")
    flat = np.ascontiguousarray(c.reshape(SH_COUNT, -1), dtype=np.float64)
    out = np.empty((int(np.prod(d.shape[:-1], dtype=np.int64)), flat.shape[1]))
    _eval_sh_kernel(flat, np.ascontiguousarray(d.reshape(-1, 3)), out)
    return out.reshape(d.shape[:-1] + c.shape[1:])


@row_kernel(1)
def _eval_sh_kernel(start, stop, coeffs, d, out):
    """out[i, c] = sum_lm coeffs[lm, c] Y_lm(d[i]) (:func:`sh9`)."""
    for i in range(start, stop):
        y = sh9(d[i, 0], d[i, 1], d[i, 2])
        for c in range(coeffs.shape[1]):
            out[i, c] = (coeffs[0, c] * y[0] + coeffs[1, c] * y[1] + coeffs[2, c] * y[2] + coeffs[3, c] * y[3]
                         + coeffs[4, c] * y[4] + coeffs[5, c] * y[5] + coeffs[6, c] * y[6]
                         + coeffs[7, c] * y[7] + coeffs[8, c] * y[8])


def irradiance_from_sh(coeffs, normals, window=None, width=3.0):
    """Irradiance E(n) = sum_lm A_l w_l L_lm Y_lm(n) from radiance SH.

    Ramamoorthi & Hanrahan 2001, eq. 7 with A_0 = pi, A_1 = 2 pi / 3,
    A_2 = pi / 4 (:func:`cosine_lobe_coefficients`); w_l is the optional
    window of :func:`sh_window` (none by default).  A constant radiance 1
    gives E = pi.  ``coeffs`` (9,) or (9, C), ``normals`` (..., 3) unit
    vectors; returns (...) or (..., C).
    """
    c = apply_window(coeffs, window, width)
    a = cosine_lobe_coefficients(2)[SH_BANDS]
    return eval_sh(c * a.reshape((SH_COUNT,) + (1,) * (c.ndim - 1)), normals)


# ------------------------------------------------------- engines' SH forms

#: K_lm: Y_lm(d) = K_lm p_lm(d) with the polynomials p = (1, y, z, x, x y, y z,
#: 3 z^2 - 1, x z, x^2 - y^2) of :func:`sh9`.
SH_POLYNOMIAL_CONSTANTS = np.array([_Y00, _Y1, _Y1, _Y1, _Y2_XY, _Y2_XY, _Y20, _Y2_XY, _Y22])
#: Sign of each coefficient under the Condon-Shortley phase (-1)^m used by
#: Filament's and Babylon.js's bases: the basis functions odd in x or y with
#: odd m, (1,-1), (1,1), (2,-1), (2,1), change sign.
CONDON_SHORTLEY_SIGNS = np.array([1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0])
# which coefficients are odd in x, y, z (p_lm(-x, y, z) = -p_lm(x, y, z) ...)
_ODD = {"x": (3, 4, 7), "y": (1, 4, 5), "z": (2, 5, 7)}


def mirror_sh(coeffs, axis):
    """The coefficients of L'(d) = L(d mirrored in ``axis``) ("x", "y" or "z"):
    the basis functions odd in that coordinate change sign (:func:`sh9`), e.g.
    x: (1,1), (2,-2), (2,1).  Exact; used for engines whose cube lookups mirror a
    coordinate (three.js x, Babylon.js z)."""
    c = np.array(_check_coeffs(coeffs), dtype=np.float64)
    if axis not in _ODD:
        raise ValueError(f"axis must be 'x', 'y' or 'z', got {axis!r}")
    c[list(_ODD[axis])] *= -1.0
    return c


def lambertian_sh_prescaled(coeffs, window=None, width=3.0):
    """Coefficients c_lm = L_lm (A_l / pi) K_lm such that sum_lm c_lm p_lm(n),
    with the bare polynomials p of :data:`SH_POLYNOMIAL_CONSTANTS`, is E(n) / pi:
    the Lambertian-reflected radiance of a white surface.  This is the form
    Filament keeps in its KTX ``sh`` key and ``IndirectLight.irradianceSh`` (cmgen
    ``--sh-shader``: CubemapSH ``preprocessSHForShader``; Filament's basis carries
    the Condon-Shortley sign, which cancels in the product of coefficient and
    basis constant, so these are its numbers for pbrkit's L_lm).  Optional
    window as :func:`irradiance_from_sh`."""
    c = apply_window(coeffs, window, width)
    scale = cosine_lobe_coefficients(2)[SH_BANDS] / math.pi * SH_POLYNOMIAL_CONSTANTS
    return c * scale.reshape((SH_COUNT,) + (1,) * (c.ndim - 1))


#: Babylon.js's SphericalPolynomial terms, in its order.
BABYLON_POLYNOMIAL_TERMS = ("x", "y", "z", "xx", "yy", "zz", "yz", "zx", "xy")


def babylon_harmonics(coeffs):
    """Babylon.js ``SphericalHarmonics`` H_lm = s_lm (A_l / pi) L_lm of radiance
    coefficients L_lm in the same frame: its basis has the Condon-Shortley sign
    s_lm (:data:`CONDON_SHORTLEY_SIGNS`), and its cube-to-SH tool converts the
    radiance projection to irradiance (A_l) and then to Lambertian radiance (1/pi)
    (Babylon.js ``CubeMapToSphericalPolynomialTools``, ``SphericalHarmonics.
    convertIncidentRadianceToIrradiance`` / ``convertIrradianceToLambertianRadiance``).
    Frame changes (Babylon's cube lookups negate z in right-handed scenes) are
    the caller's: :func:`mirror_sh`."""
    c = _check_coeffs(coeffs)
    scale = CONDON_SHORTLEY_SIGNS * cosine_lobe_coefficients(2)[SH_BANDS] / math.pi
    return c * scale.reshape((SH_COUNT,) + (1,) * (c.ndim - 1))


def babylon_polynomial(coeffs):
    """Babylon.js's ``SphericalPolynomial`` of radiance coefficients L_lm, as a dict
    :data:`BABYLON_POLYNOMIAL_TERMS` -> value (C,): the harmonics of
    :func:`babylon_harmonics` through ``SphericalPolynomial.FromHarmonics``, the
    irradiance polynomial of Ramamoorthi & Hanrahan 2001 (eq. 13: c1 = 0.429043,
    c2 = 0.511664, c3 = 0.743125, c4 = 0.886227, c5 = 0.247708) in Babylon's
    normalisation, divided by pi.  Babylon's own constants are used (its
    0.886277 for c4 among them) so that its ``FromPolynomial`` recovers H exactly
    and its default pre-scaled-harmonics shader path gives E / pi; evaluated as a
    polynomial it is not irradiance (the cosine would be applied twice).  What
    Babylon writes in a ``.env`` manifest's ``irradiance``."""
    h = np.asarray(babylon_harmonics(coeffs), dtype=np.float64)
    h00, h1m1, h10, h11, h2m2, h2m1, h20, h21, h22 = h
    inv_pi = 1.0 / math.pi
    return {
        "x": -1.02333 * h11 * inv_pi,
        "y": -1.02333 * h1m1 * inv_pi,
        "z": 1.02333 * h10 * inv_pi,
        "xx": (0.886277 * h00 - 0.247708 * h20 + 0.429043 * h22) * inv_pi,
        "yy": (0.886277 * h00 - 0.247708 * h20 - 0.429043 * h22) * inv_pi,
        "zz": (0.886277 * h00 + 0.495417 * h20) * inv_pi,
        "yz": -0.858086 * h2m1 * inv_pi,
        "zx": -0.858086 * h21 * inv_pi,
        "xy": 0.858086 * h2m2 * inv_pi,
    }
