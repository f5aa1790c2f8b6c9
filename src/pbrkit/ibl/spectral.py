"""Spherical harmonic transforms of equirectangular images and convolution
with zonal (rotationally symmetric) kernels, to high degree.

:mod:`pbrkit.ibl.sh` holds the 9-coefficient real SH of the conventions; this
module is the general machinery behind the specular prefilter
(:mod:`pbrkit.ibl.prefilter`): a band-limited function on the sphere convolved
with a kernel k(n.l) is, by the Funk-Hecke theorem, the function whose
coefficients are f_lm lambda_l, with lambda_l = 2 pi integral_{-1}^{1} k(t)
P_l(t) dt (e.g. Ramamoorthi & Hanrahan 2001, eq. 6, for the cosine kernel;
Driscoll & Healy, "Computing Fourier transforms and convolutions on the
2-sphere", Adv. Appl. Math. 15, 1994, Theorem 1).

Basis (internal to this module: only transforms and convolutions use it):
complex orthonormal harmonics Y_lm(theta, phi) = Pbar_lm(cos theta)
e^{i m phi} on the angles of the equirect convention (``CONVENTIONS.md``:
theta from +Y, phi = atan2(z, x)), with the fully normalised associated
Legendre functions Pbar_lm = sqrt((2l+1)/(4 pi) (l-m)!/(l+m)!) P_l^m, without
the Condon-Shortley phase (the sign cancels between analysis and
synthesis).  They are computed by the standard stable recurrences
(e.g. Holmes & Featherstone, "A unified approach to the Clenshaw summation
and the recursive computation of very high degree and order normalised
associated Legendre functions", J. Geodesy 76, 2002, eqs. 11-13)::

    Pbar_00 = 1 / sqrt(4 pi),  Pbar_mm = sqrt((2m+1)/(2m)) sin(theta) Pbar_{m-1,m-1},
    Pbar_{m+1,m} = sqrt(2m+3) cos(theta) Pbar_mm,
    Pbar_lm = a_lm (cos(theta) Pbar_{l-1,m} - b_lm Pbar_{l-2,m}),
    a_lm = sqrt((4l^2 - 1)/(l^2 - m^2)),  b_lm = sqrt(((l-1)^2 - m^2)/(4(l-1)^2 - 1)),

with Pbar_mm formed from its logarithm so that high orders near the poles
underflow to zero instead of producing denormals (their true values there
are below 1e-300).  A real function has f_{l,-m} = (-1)^m conj(f_lm), so
only m >= 0 is stored: arrays (L + 1, L + 1, C) complex indexed [l, m, c].

Analysis (:func:`analyse_equirect`) treats the image as piecewise constant
over its cells (as :func:`pbrkit.ibl.equirect.equirect_to_cube` does): the integral
of e^{-i m phi} over a column is exact (a sinc factor), the integral of
Pbar_lm over a row band in cos(theta) uses 2-point Gauss-Legendre, exact for
cubics, with an error of order (l pi / H)^4 / 4320 for degree l on H rows.
Synthesis (:func:`synthesise_equirect`) evaluates the series at the pixel
centres of an equirect grid with one FFT per row, and
:func:`sample_equirect` interpolates such a grid at arbitrary directions
with Keys' cubic convolution (a = -1/2; Keys, "Cubic convolution
interpolation for digital image processing", IEEE TASSP 29(6), 1981),
continuing the grid across the poles (row -1 is row 0 half a turn away).
"""

from __future__ import annotations

import math

import numpy as np

from ..core import checks
from ..core.jit import kernel, row_kernel
from .equirect import direction_angles, equirect_pixel_angles

__all__ = [
    "analyse_equirect",
    "synthesise_equirect",
    "sample_equirect",
    "zonal_coefficients",
    "convolve",
    "halve_equirect",
    "legendre_p",
]

_LOG_FLOOR = -690.0  # exp(-690) ~ 1e-300


def _log_pmm_table(lmax):
    """log of sqrt((2m+1)!! / (2m)!!) / sqrt(4 pi) for m = 0..lmax
    (Pbar_mm = this times sin^m theta)."""
    m = np.arange(1, lmax + 1)
    steps = 0.5 * np.log((2.0 * m + 1.0) / (2.0 * m))
    return np.concatenate([[0.0], np.cumsum(steps)]) - 0.5 * math.log(4.0 * math.pi)


def _recurrence_tables(lmax):
    """a_lm, b_lm (L + 1, L + 1) of the module doc (zero where unused)."""
    l = np.arange(lmax + 1, dtype=np.float64)[:, None]
    m = np.arange(lmax + 1, dtype=np.float64)[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        a = np.sqrt((4.0 * l * l - 1.0) / (l * l - m * m))
        b = np.sqrt(((l - 1.0) ** 2 - m * m) / (4.0 * (l - 1.0) ** 2 - 1.0))
    valid = l >= m + 2
    return np.where(valid, a, 0.0), np.where(valid, b, 0.0)


@kernel
def _legendre_column(m, x, s_log, log_pmm, a, b, out):
    """out[l] = Pbar_lm(x) for l = m..L (out[:m] untouched); s_log =
    log(sin theta).  Returns False (out not written) when Pbar_mm underflows."""
    lmax = out.shape[0] - 1
    lg = log_pmm[m] + m * s_log if m > 0 else log_pmm[0]
    if lg < _LOG_FLOOR:
        return False
    p0 = math.exp(lg)
    out[m] = p0
    if m < lmax:
        p1 = math.sqrt(2.0 * m + 3.0) * x * p0
        out[m + 1] = p1
        for l in range(m + 2, lmax + 1):
            p2 = a[l, m] * (x * p1 - b[l, m] * p0)
            out[l] = p2
            p0 = p1
            p1 = p2
    return True


@row_kernel(lambda g_re, g_im, x_nodes, s_log, w_nodes, log_pmm, a, b, col_factor, out_re, out_im: out_re.shape[0])
def _analyse_kernel(start, stop, g_re, g_im, x_nodes, s_log, w_nodes, log_pmm, a, b, col_factor, out_re, out_im):
    """out[l, m] = sum_rows sum_nodes w Pbar_lm(x_node) * G_m(row) * col_factor[m]."""
    rows, nodes = x_nodes.shape
    lmax = out_re.shape[0] - 1
    channels = out_re.shape[2]
    for m in range(start, stop):
        p = np.zeros(lmax + 1)
        acc = np.zeros(lmax + 1)
        for i in range(rows):
            for l in range(m, lmax + 1):
                acc[l] = 0.0
            any_ = False
            for q in range(nodes):
                if _legendre_column(m, x_nodes[i, q], s_log[i, q], log_pmm, a, b, p):
                    any_ = True
                    w = w_nodes[i, q]
                    for l in range(m, lmax + 1):
                        acc[l] += w * p[l]
            if not any_:
                continue
            for c in range(channels):
                gr = g_re[i, m, c] * col_factor[m]
                gi = g_im[i, m, c] * col_factor[m]
                for l in range(m, lmax + 1):
                    out_re[l, m, c] += acc[l] * gr
                    out_im[l, m, c] += acc[l] * gi


def _check_lmax(lmax):
    return checks.integer(lmax, "degree", 0, 4096)


def analyse_equirect(image, lmax):
    """Coefficients f_lm (L + 1, L + 1, C) complex (m >= 0; module doc) of
    an equirectangular image (H, 2H, C) taken as piecewise constant over its
    cells, up to degree ``lmax``.  Cost O(L^2 H)."""
    img = np.asarray(image, dtype=np.float64)
    if img.ndim != 3 or img.shape[1] != 2 * img.shape[0] or img.shape[0] < 1:
        raise ValueError(f"equirect image must have shape (H, 2H, C), got {img.shape}")
    lmax = _check_lmax(lmax)
    h, w, channels = img.shape
    if lmax >= w // 2:
        raise ValueError(f"degree {lmax} needs an image wider than {2 * lmax} pixels, got {w}")
    # G_m(row) = sum_j f_j exp(-i m phi_j), phi_j = 2 pi (j + 0.5) / W - pi = phi_0 + 2 pi j / W
    spec = np.fft.rfft(img, axis=1)[:, : lmax + 1, :]
    m = np.arange(lmax + 1)
    mid, phi0 = equirect_pixel_angles(np.arange(h), 0, h, w)
    spec *= np.exp(-1j * m * phi0)[None, :, None]
    dphi = 2.0 * math.pi / w
    half = 0.5 * m * dphi
    col_factor = dphi * np.where(m == 0, 1.0, np.sin(half) / np.where(m == 0, 1.0, half))
    # 2-point Gauss-Legendre in theta over each row band: the integrand Pbar_lm(cos theta) sin(theta) is a
    # trigonometric polynomial in theta, smooth also at the poles
    half = 0.5 * math.pi / h
    g = half / math.sqrt(3.0)
    theta = np.stack([mid - g, mid + g], axis=1)
    x_nodes = np.cos(theta)
    s_log = np.log(np.sin(theta))
    w_nodes = half * np.sin(theta)
    a, b = _recurrence_tables(lmax)
    out_re = np.zeros((lmax + 1, lmax + 1, channels))
    out_im = np.zeros((lmax + 1, lmax + 1, channels))
    _analyse_kernel(np.ascontiguousarray(spec.real), np.ascontiguousarray(spec.imag), x_nodes, s_log, w_nodes,
                    _log_pmm_table(lmax), a, b, col_factor, out_re, out_im)
    return out_re + 1j * out_im


@row_kernel(2)
def _synthesise_kernel(start, stop, c_re, c_im, x_rows, s_log, log_pmm, a, b, out_re, out_im):
    """out[i, m] = sum_l c_lm Pbar_lm(x_i)."""
    lmax = c_re.shape[0] - 1
    channels = c_re.shape[2]
    for i in range(start, stop):
        p = np.zeros(lmax + 1)
        for m in range(lmax + 1):
            if not _legendre_column(m, x_rows[i], s_log[i], log_pmm, a, b, p):
                break  # Pbar_mm only shrinks with m
            for c in range(channels):
                sr = 0.0
                si = 0.0
                for l in range(m, lmax + 1):
                    sr += c_re[l, m, c] * p[l]
                    si += c_im[l, m, c] * p[l]
                out_re[i, m, c] = sr
                out_im[i, m, c] = si


def synthesise_equirect(coeffs, height):
    """The real function of coefficients ``coeffs`` (L + 1, L + 1, C) at the
    pixel centres of an equirect grid (height, 2 height, C); height must
    exceed L.  Cost O(L^2 H + H^2 log H)."""
    c = np.asarray(coeffs)
    if c.ndim != 3 or c.shape[0] != c.shape[1]:
        raise ValueError(f"coefficients must have shape (L + 1, L + 1, C), got {c.shape}")
    lmax = c.shape[0] - 1
    height = int(height)
    if height <= lmax:
        raise ValueError(f"a grid of {height} rows cannot hold degree {lmax}")
    width = 2 * height
    theta, phi0 = equirect_pixel_angles(np.arange(height), 0, height, width)
    x = np.cos(theta)
    s_log = np.log(np.sin(theta))
    a, b = _recurrence_tables(lmax)
    f_re = np.zeros((height, lmax + 1, c.shape[2]))
    f_im = np.zeros((height, lmax + 1, c.shape[2]))
    _synthesise_kernel(np.ascontiguousarray(c.real, dtype=np.float64), np.ascontiguousarray(c.imag, dtype=np.float64),
                       x, s_log, _log_pmm_table(lmax), a, b, f_re, f_im)
    m = np.arange(lmax + 1)
    spec = (f_re + 1j * f_im) * np.exp(1j * m * phi0)[None, :, None]
    # sum_m F_m e^{i m phi} over m = -L..L: irfft gives (1 / W) (F_0 + 2 Re sum_{m>0} F_m e^{2 pi i m j / W})
    full = np.zeros((height, width // 2 + 1, c.shape[2]), dtype=complex)
    full[:, : lmax + 1] = spec
    return np.fft.irfft(full, n=width, axis=1) * width


@kernel
def _keys(t):
    """Keys 1981 cubic-convolution weights (a = -1/2) of the 4 taps at
    offsets -1, 0, 1, 2 for fractional position t in [0, 1)."""
    t2 = t * t
    t3 = t2 * t
    return (-0.5 * t3 + t2 - 0.5 * t, 1.5 * t3 - 2.5 * t2 + 1.0, -1.5 * t3 + 2.0 * t2 + 0.5 * t, 0.5 * t3 - 0.5 * t2)


@row_kernel(1)
def _sample_kernel(start, stop, grid, dirs, out):
    h = grid.shape[0]
    w = grid.shape[1]
    channels = grid.shape[2]
    for k in range(start, stop):
        theta, phi = direction_angles(dirs[k, 0], dirs[k, 1], dirs[k, 2])
        # grid coordinates from the centre of pixel (0, 0): v H - 1/2 and u W - 1/2 (CONVENTIONS.md)
        v = theta / math.pi * h - 0.5
        u = (phi + math.pi) / (2.0 * math.pi) * w - 0.5
        i0 = int(math.floor(v))
        j0 = int(math.floor(u))
        wv = _keys(v - i0)
        wu = _keys(u - j0)
        for c in range(channels):
            out[k, c] = 0.0
        for a in range(4):
            r = i0 - 1 + a
            shift = 0
            if r < 0:  # across the north pole: row -1 - r, half a turn away
                r = -1 - r
                shift = w // 2
            elif r >= h:
                r = 2 * h - 1 - r
                shift = w // 2
            for bb in range(4):
                col = (j0 - 1 + bb + shift) % w
                wt = wv[a] * wu[bb]
                for c in range(channels):
                    out[k, c] += wt * grid[r, col, c]


def sample_equirect(grid, directions):
    """Keys cubic interpolation (module doc) of an equirect grid (H, 2H, C)
    at unit directions (..., 3) -> (..., C)."""
    g = np.ascontiguousarray(grid, dtype=np.float64)
    if g.ndim != 3 or g.shape[1] != 2 * g.shape[0] or g.shape[0] < 2:
        raise ValueError(f"grid must have shape (H, 2H, C) with H >= 2, got {g.shape}")
    d = np.asarray(directions, dtype=np.float64)
    shape = d.shape[:-1]
    flat = np.ascontiguousarray(d.reshape(-1, 3))
    out = np.empty((flat.shape[0], g.shape[2]))
    _sample_kernel(g, flat, out)
    return out.reshape(shape + (g.shape[2],))


def legendre_p(lmax, t):
    """Legendre polynomials P_0..P_L at t (array): shape (L + 1,) + t.shape,
    by Bonnet's recurrence (l + 1) P_{l+1} = (2l + 1) t P_l - l P_{l-1}."""
    t = np.asarray(t, dtype=np.float64)
    out = np.empty((lmax + 1,) + t.shape)
    out[0] = 1.0
    if lmax >= 1:
        out[1] = t
    for l in range(1, lmax):
        out[l + 1] = ((2 * l + 1) * t * out[l] - l * out[l - 1]) / (l + 1)
    return out


def zonal_coefficients(kernel, lmax, theta_max=math.pi, scale=None, normalise=True):
    """Funk-Hecke coefficients lambda_l = 2 pi integral_0^theta_max k(theta)
    P_l(cos theta) sin(theta) dtheta, l = 0..L, of a zonal kernel given as a
    vectorised function ``kernel(theta)`` of the angle from its axis (zero
    beyond ``theta_max``).  Composite 12-point Gauss-Legendre panels no wider
    than pi / (2 L + 2) (so P_l is resolved), and, when the kernel has a
    narrow peak of width ``scale`` at theta = 0, geometrically graded
    panels from scale / 64.  With ``normalise`` the kernel is divided by its
    integral (lambda_0 = 1: constants are preserved); returns (lambda,
    integral)."""
    lmax = _check_lmax(lmax)
    width = math.pi / (2 * lmax + 2)
    edges = list(np.linspace(0.0, theta_max, int(math.ceil(theta_max / width)) + 1))
    if scale is not None and scale > 0.0:
        e = scale / 64.0
        while e < theta_max:
            edges.append(e)
            e *= 1.5
    edges = np.unique(np.clip(edges, 0.0, theta_max))
    x, w = np.polynomial.legendre.leggauss(12)
    lo, hi = edges[:-1, None], edges[1:, None]
    theta = (0.5 * (hi - lo) * x[None, :] + 0.5 * (hi + lo)).ravel()
    weight = (0.5 * (hi - lo) * w[None, :]).ravel() * np.sin(theta) * kernel(theta) * (2.0 * math.pi)
    lam = legendre_p(lmax, np.cos(theta)) @ weight
    total = lam[0]
    if normalise:
        lam = lam / total
    return lam, total


def convolve(coeffs, lam):
    """Coefficients of the convolution with a zonal kernel: f_lm lambda_l."""
    c = np.asarray(coeffs)
    lam = np.asarray(lam, dtype=np.float64)
    return c * lam[: c.shape[0], None, None]


def halve_equirect(image, band=256, clip=None):
    """Equirect image (H/2, H, C) float64 whose pixels are the exact
    solid-angle-weighted means of 2 x 2 blocks of ``image`` (H even, any
    float dtype), after clamping it to at most ``clip`` if given: the
    integral over every cell, and so over the sphere, is kept.  Works
    through ``band`` rows at a time, so no full-size float64 (or clamped)
    copy of a large input is made."""
    img = np.asarray(image)
    h = img.shape[0]
    if img.ndim != 3 or h % 2 or img.shape[1] != 2 * h:
        raise ValueError(f"cannot halve an equirect image of shape {img.shape}")
    edges = np.cos(np.pi * np.arange(h + 1) / h)
    weight = edges[:-1] - edges[1:]
    out = np.empty((h // 2, h, img.shape[2]))
    band += band % 2
    for r0 in range(0, h, band):
        r1 = min(h, r0 + band)
        part = img[r0:r1].astype(np.float64)
        if clip is not None:
            np.minimum(part, clip, out=part)
        w = weight[r0:r1, None, None]
        part *= w
        part = part.reshape((r1 - r0) // 2, 2, h, 2, img.shape[2]).sum(axis=(1, 3))
        out[r0 // 2:r1 // 2] = part / (2.0 * w.reshape(-1, 2).sum(axis=1))[:, None, None]
    return out
