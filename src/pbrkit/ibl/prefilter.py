"""GGX-prefiltered specular mip chains for split-sum image-based lighting.

The split-sum approximation (Karis, "Real Shading in Unreal Engine 4",
SIGGRAPH 2013 course notes, pp. 4-6) splits the specular IBL integral into a
lookup table of the BRDF (:mod:`pbrkit.albedo.tables`) and the *prefiltered
environment*, computed under the assumption n = v = r::

    P(n; alpha) = integral of L(l) D(h) (n.l) dl / Z(alpha),
    Z(alpha) = integral of D(h) (n.l) dl,   h = normalize(n + l), n.l > 0,

with the GGX distribution D of :func:`pbrkit.microfacet.ggx.d_ggx` and
alpha = r^2 for perceptual roughness r (:func:`pbrkit.microfacet.roughness.
alpha_from_roughness`, clamped at ``ALPHA_MIN``).  This is what Karis' sample
code (``PrefilterEnvMap``: l = reflect(v, h) for h drawn from D(h) (n.h),
weights n.l, divided by the sum of the weights) converges to: with n = v the
solid-angle pdf of l is D(h) (n.h) / (4 v.h) = D(h) / 4, so the weighted
mean tends to the ratio above.  Since h bisects n and l, n.h = cos(theta / 2)
for the angle theta between n and l: P is the convolution of L with the
zonal kernel k(theta) = D(cos(theta / 2)) cos(theta) / Z on theta < pi / 2
(:func:`ggx_prefilter_kernel`).  Z has a closed form
(:func:`ggx_lobe_normalization`).

Roughness of the mip levels.  Level m of an M-level chain holds perceptual
roughness r_m = m / (M - 1) (:func:`roughness_of_level`): level 0 is the
environment itself (a mirror), the last level r = 1.  A runtime shader
samples the fractional level lod = r (M - 1) (:func:`level_of_roughness`)
with trilinear filtering.  This is the linear mapping of the Khronos glTF IBL
sampler and glTF-Sample-Viewer (``lod = roughness * (mipCount - 1)``).

Method (:func:`prefilter_spectral`, the default).  The environment is split
into a bounded part and a sparse part (:func:`equirect_highlights`,
:func:`cube_highlights`): with a threshold T that at most a small
number of pixels exceed and that is at least 16 times the mean radiance,
L = min(L, T) + max(L - T, 0).

- The bounded part is convolved *exactly* in the spherical-harmonic domain
  (:mod:`pbrkit.ibl.spectral`): by the Funk-Hecke theorem the coefficients of
  the convolution are f_lm lambda_l with lambda_l = 2 pi integral k(theta)
  P_l(cos theta) sin(theta) dtheta (:func:`ggx_zonal_coefficients`),
  computed by quadrature.  The series is cut at the degree L where
  |lambda_l| < 1e-6 for the narrowest lobe of the chain
  (:func:`band_limit`), synthesised on an equirect grid and interpolated at
  the texel centres.  No sampling noise, no aliasing, cost independent of
  the roughness.
- The sparse part (a sun, lamps) would ring in a truncated series; it is a
  list of points of energy E_i = (L_i - T) Omega_i, merged per texel of a
  cube twice as fine as the output level at their energy-weighted centroids
  (:func:`merge_highlights`),
  and summed exactly: each adds E_i D(h_i) (n.l_i) / Z(alpha) to a texel
  (:func:`add_highlights`, by :func:`point_lobe_sum`, which also sums the
  brute-force references here and in :mod:`pbrkit.ibl.irradiance`).

The alternative :func:`prefilter_fis` is filtered importance sampling
(Krivanek & Colbert, "Real-time Shading with Filtered Importance Sampling",
EGSR 2008; GPU Gems 3, ch. 20, "GPU-Based Importance Sampling", sec. 20.4)
of a solid-angle-weighted mip pyramid (:func:`pbrkit.ibl.cubemap.
build_mip_pyramid`), with Hammersley points (:func:`pbrkit.sampling.
hammersley`) warped by GGX NDF sampling (:func:`pbrkit.sampling.
warp_ggx_ndf`; Walter et al. 2007, eqs. 35-36), each looked up trilinearly at

    lod = 0.5 log2(Omega_s / Omega_p) + bias,   Omega_s = 1 / (K pdf(l)),

where Omega_p is the solid angle of a level-0 texel *at the sample's
location*, (2 / N)^2 (1 + sc^2 + tc^2)^(-3/2) (:func:`cube_texel_density`),
and the weighted mean sum w_s L_s / sum w_s, w_s = n.l_s (Karis 2013); the
same highlight split can be used with it.  References for tests and
benchmarks: :func:`prefilter_reference` (direct summation of the lobe over
every texel of a cube map) and :func:`prefilter_importance_sampled` (plain
importance sampling of level 0, Karis' ``PrefilterEnvMap``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core import checks
from ..core.jit import dual_use, row_kernel, select
from ..core.vec import orthonormal_basis_xyz
from ..microfacet.ggx import d_ggx, pdf_ggx_ndf, warp_ggx_ndf
from ..microfacet.roughness import alpha_from_roughness
from ..sampling.low_discrepancy import hammersley
from ..sampling.warps import pdf_light_from_half, reflect_xyz
from .cubemap import (
    CubeSampler,
    _as_cube,
    _trilinear_add,
    build_mip_pyramid,
    cube_face_coords,
    cube_texel_directions,
    cube_texel_solid_angles,
    direction_to_cube,
)
from .spectral import convolve, sample_equirect, synthesise_equirect, zonal_coefficients

__all__ = [
    "HIGHLIGHT_RATIO",
    "MAX_HIGHLIGHT_POINTS",
    "BAND_LIMIT_TOLERANCE",
    "roughness_of_level",
    "level_of_roughness",
    "LEVEL_CURVES",
    "filament_roughness_of_level",
    "filament_level_of_roughness",
    "BABYLON_LOD_GENERATION_SCALE",
    "babylon_alpha_of_level",
    "babylon_alpha_g",
    "babylon_level_of_roughness",
    "chain_roughness",
    "ggx_lobe_normalization",
    "ggx_prefilter_kernel",
    "ggx_zonal_coefficients",
    "band_limit",
    "Highlights",
    "highlight_threshold",
    "equirect_highlights",
    "cube_highlights",
    "merge_highlights",
    "LOBE_COSINE",
    "LOBE_GGX",
    "point_lobe_sum",
    "add_highlights",
    "prefilter_spectral",
    "RESIDUAL_SAMPLES",
    "prefilter_chain",
    "cube_texel_density",
    "SampleSet",
    "sample_set",
    "default_sample_counts",
    "prefilter_level",
    "prefilter_fis",
    "prefilter_reference",
    "prefilter_importance_sampled",
]

#: The highlight threshold T is at least this many times the mean radiance.
HIGHLIGHT_RATIO = 16.0
#: At most this many highlight points per level: points are merged per
#: texel of a cube twice as fine as the level, coarser if there are more.
MAX_HIGHLIGHT_POINTS = 1024
#: The spherical-harmonic series is cut where |lambda_l| < this.
BAND_LIMIT_TOLERANCE = 1e-6


# ------------------------------------------------------------ level mapping


def _check_levels(levels):
    return checks.integer(levels, "levels of a prefiltered chain", 2)


def roughness_of_level(m, levels):
    """Perceptual roughness r_m = m / (M - 1) of level m of an M-level chain
    (the linear mapping of the Khronos glTF IBL sampler and
    glTF-Sample-Viewer); scalars or arrays, fractional m allowed.  Level 0 is
    r = 0, level M - 1 is r = 1."""
    levels = _check_levels(levels)
    m = np.asarray(m, dtype=np.float64)
    if not np.all(np.isfinite(m)) or np.any((m < 0) | (m > levels - 1)):
        raise ValueError(f"level must be in [0, {levels - 1}]")
    r = m / (levels - 1)
    return float(r) if r.ndim == 0 else r


def level_of_roughness(r, levels):
    """Fractional level lod = r (M - 1) at which a shader samples perceptual
    roughness r (the inverse of :func:`roughness_of_level`); r is clamped to
    [0, 1]."""
    levels = _check_levels(levels)
    r = np.asarray(r, dtype=np.float64)
    if not np.all(np.isfinite(r)):
        raise ValueError("roughness must be finite")
    lod = np.clip(r, 0.0, 1.0) * (levels - 1)
    return float(lod) if lod.ndim == 0 else lod


def filament_roughness_of_level(m, levels):
    """Perceptual roughness r_m = 1 - sqrt(1 - m / (M - 1)) of level m of an
    M-level chain for Filament and three.js: the inverse of their shaders' lod =
    (M - 1) r (2 - r) (:func:`filament_level_of_roughness`; Filament
    ``light_indirect.fs`` ``perceptualRoughnessToLod`` and cmgen's
    ``lodToPerceptualRoughness``; three.js r187 ``envmap_common_pars_fragment``
    and ``PMREMGenerator``).  Level 0 is r = 0, level M - 1 is r = 1; the
    levels crowd towards low roughness (0, 0.134, 0.293, 0.5, 1 for M = 5)."""
    levels = _check_levels(levels)
    m = np.asarray(m, dtype=np.float64)
    if not np.all(np.isfinite(m)) or np.any((m < 0) | (m > levels - 1)):
        raise ValueError(f"level must be in [0, {levels - 1}]")
    r = 1.0 - np.sqrt(np.maximum(0.0, 1.0 - m / (levels - 1)))
    return float(r) if r.ndim == 0 else r


def filament_level_of_roughness(r, levels):
    """Fractional level lod = (M - 1) r (2 - r) at which Filament and three.js
    sample perceptual roughness r (r clamped to [0, 1]); the inverse of
    :func:`filament_roughness_of_level`."""
    levels = _check_levels(levels)
    r = np.asarray(r, dtype=np.float64)
    if not np.all(np.isfinite(r)):
        raise ValueError("roughness must be finite")
    r = np.clip(r, 0.0, 1.0)
    lod = (levels - 1) * r * (2.0 - r)
    return float(lod) if lod.ndim == 0 else lod


#: Babylon.js's default ``lodGenerationScale`` (``CubeTexture``; written in .env files).
BABYLON_LOD_GENERATION_SCALE = 0.8
#: Babylon.js's ``MINIMUMVARIANCE``: its shaders use alpha_G = r^2 + this.
_BABYLON_MINIMUM_VARIANCE = 0.0005


@dual_use
def babylon_alpha_g(roughness):
    """Babylon.js's alpha_G = r^2 + 0.0005 of perceptual roughness r
    (``convertRoughnessToAverageSlope``, its ``MINIMUMVARIANCE``): what its shaders
    take the lod and the radiance-irradiance mix from."""
    return roughness * roughness + _BABYLON_MINIMUM_VARIANCE


def babylon_alpha_of_level(m, size, scale=BABYLON_LOD_GENERATION_SCALE):
    """GGX alpha of level m of Babylon.js's prefiltered chain for a base size N:
    alpha_m = min(1, 2^(m / scale) / N), level 0 a mirror (alpha 0).  The inverse
    of its shader's lod = scale log2(N alpha_G) (:func:`babylon_level_of_roughness`;
    Babylon.js ``HDRFiltering`` and ``pbrBlockReflection``).  The chain runs to
    1 x 1 (log2 N + 1 levels); levels past scale log2 N hold alpha 1."""
    size = checks.integer(size, "cube size", 1, 1 << 16)
    m = np.asarray(m, dtype=np.float64)
    if not np.all(np.isfinite(m)) or np.any(m < 0):
        raise ValueError("level must be a non-negative number")
    alpha = np.where(m > 0, np.minimum(1.0, np.exp2(m / float(scale)) / size), 0.0)
    return float(alpha) if alpha.ndim == 0 else alpha


def babylon_level_of_roughness(r, size, scale=BABYLON_LOD_GENERATION_SCALE):
    """Fractional level lod = scale log2(N alpha_G), alpha_G = r^2 + 0.0005, at
    which Babylon.js samples perceptual roughness r in a base-N chain (its
    ``MINIMUMVARIANCE`` offset; clamped at 0 as the hardware does)."""
    size = checks.integer(size, "cube size", 1, 1 << 16)
    r = np.asarray(r, dtype=np.float64)
    if not np.all(np.isfinite(r)):
        raise ValueError("roughness must be finite")
    lod = np.maximum(0.0, float(scale) * np.log2(size * babylon_alpha_g(np.clip(r, 0.0, 1.0))))
    return float(lod) if lod.ndim == 0 else lod


#: Level curves of the chains a bake can hold: name -> what level m holds.
LEVEL_CURVES = {
    "linear": "r = m / (M - 1); lod = r (M - 1) (pbrkit generic, Khronos glTF Sample Viewer)",
    "filament": "r = 1 - sqrt(1 - m / (M - 1)); lod = (M - 1) r (2 - r) (Filament, three.js)",
    "babylon": "alpha = min(1, 2^(m / 0.8) / N), level 0 a mirror; lod = 0.8 log2(N (r^2 + 0.0005)) (Babylon.js)",
}


def chain_roughness(curve, size, min_size):
    """(sizes, perceptual roughness) of every level of a chain with level curve
    ``curve`` (:data:`LEVEL_CURVES`) and base size ``size``: "linear" and
    "filament" run from ``size`` down to ``min_size`` (M = log2(size / min_size)
    + 1 levels), "babylon" down to 1 x 1 (its roughness is sqrt(alpha))."""
    size = checks.integer(size, "cube size", 2, 1 << 16)
    if curve == "babylon":
        levels = size.bit_length()
        m = np.arange(levels)
        return [size >> k for k in m], np.sqrt(babylon_alpha_of_level(m, size))
    if curve not in LEVEL_CURVES:
        raise ValueError(f"level curve must be one of {', '.join(LEVEL_CURVES)}, got {curve!r}")
    levels = int(math.log2(size // int(min_size))) + 1
    m = np.arange(levels)
    r = roughness_of_level(m, levels) if curve == "linear" else filament_roughness_of_level(m, levels)
    return [size >> k for k in m], np.asarray(r, dtype=np.float64)


# -------------------------------------------------------------------- terms


@dual_use
def ggx_lobe_normalization(alpha):
    """Z(alpha) = integral over n.l > 0 of D_GGX(h) (n.l) dl with n = v,
    h = normalize(n + l) (the denominator of the split-sum prefiltered
    radiance, Karis 2013).  With dl = 4 (n.h) dh and n.l = 2 (n.h)^2 - 1,
    x = (n.h)^2 and D = alpha^2 / (pi ((alpha^2 - 1) x + 1)^2) (Walter et
    al. 2007, eq. 33), Z = 4 alpha^2 integral_{1/2}^{1} (2x - 1) / ((alpha^2
    - 1) x + 1)^2 dx, which integrates to

        Z = 8 alpha^2 ln(2 alpha^2 / (1 + alpha^2)) / (alpha^2 - 1)^2 + 4 / (1 - alpha^2),

    Z(0) = 4, Z(1) = 1; for |e| = |alpha^2 - 1| < 1e-4 the series
    1 - 2e/3 + 11 e^2 / 24 - 13 e^3 / 40 replaces the cancelling closed form."""
    a2 = alpha * alpha
    e = a2 - 1.0
    near = np.abs(e) < 1e-4
    es = select(near, 1.0, e)  # a harmless value for the closed form where the series is used
    closed = 8.0 * a2 * np.log1p(es / (2.0 + es)) / (es * es) - 4.0 / es
    series = 1.0 - e * (2.0 / 3.0) + e * e * (11.0 / 24.0) - e * e * e * (13.0 / 40.0)
    return select(near, series, closed)


@dual_use
def ggx_prefilter_kernel(theta, alpha):
    """Unnormalised split-sum prefilter kernel D(n.h) (n.l) for l at angle
    theta from n = v: n.h = cos(theta / 2), n.l = cos(theta), zero for
    theta >= pi / 2 (module doc; D = :func:`pbrkit.microfacet.ggx.d_ggx`).
    Its integral over the sphere is :func:`ggx_lobe_normalization`."""
    c = np.cos(theta)
    return select(c > 0.0, d_ggx(np.cos(0.5 * theta), alpha) * c, 0.0)


@dual_use
def cube_texel_density(sc, tc):
    """(1 + sc^2 + tc^2)^(-3/2): solid angle per unit area of the face plane
    at face coordinates (sc, tc), the integrand of
    :func:`pbrkit.ibl.cubemap.cube_patch_solid_angle` (R. Driscoll, "Cubemap
    texel solid angle", 2012).  A texel of an N x N face there subtends
    about (2 / N)^2 times this."""
    q = 1.0 + sc * sc + tc * tc
    return 1.0 / (q * np.sqrt(q))


def ggx_zonal_coefficients(alpha, lmax):
    """Funk-Hecke coefficients lambda_0..lambda_L of the normalised
    prefilter kernel :func:`ggx_prefilter_kernel` / Z (lambda_0 = 1), by
    :func:`pbrkit.ibl.spectral.zonal_coefficients` with panels graded towards
    the lobe's width 2 alpha.  Returns (lambda, Z by quadrature)."""
    alpha = float(alpha)
    return zonal_coefficients(lambda t: ggx_prefilter_kernel(t, alpha), lmax, theta_max=0.5 * math.pi,
                              scale=2.0 * alpha)


def band_limit(alpha, lmax_cap, tolerance=BAND_LIMIT_TOLERANCE):
    """Smallest degree L <= ``lmax_cap`` such that |lambda_l| < ``tolerance``
    for every l > L considered (up to min(lmax_cap, 16 / alpha + 16)): the
    coefficients of a GGX lobe decay roughly like exp(-2 alpha l) (L is
    about 7.7 / alpha for 1e-6) until the kink of n.l at the horizon leaves
    an algebraic tail, above 1e-6 for alpha > 0.2, where the cap applies.
    At least 8 (or the cap)."""
    lmax_cap = int(lmax_cap)
    top = int(min(lmax_cap, 16.0 / max(float(alpha), 1e-3) + 16))
    lam, _ = ggx_zonal_coefficients(alpha, top)
    big = np.nonzero(np.abs(lam) >= tolerance)[0]
    limit = lmax_cap if big.max() >= top else int(big.max()) + 1
    return int(min(lmax_cap, max(8, limit)))


# -------------------------------------------------------------- highlights


@dataclass
class Highlights:
    """The sparse part of an environment: point directions (P, 3), energies
    (P, C) (radiance above the threshold times solid angle), and the
    threshold T."""

    directions: np.ndarray
    energies: np.ndarray
    threshold: float

    @property
    def count(self):
        return int(self.directions.shape[0])


def highlight_threshold(peak, mean, max_count, ratio=HIGHLIGHT_RATIO):
    """T = max(ratio * ``mean``, the (max_count + 1)-th largest value of
    ``peak``): at most ``max_count`` samples exceed T, and a constant (or
    nearly constant) environment has none.  ``peak`` is the largest channel
    per sample, ``mean`` the mean radiance over the sphere.  Only the
    samples above ratio * mean are sorted."""
    floor = float(ratio) * float(mean)
    flat = np.asarray(peak).reshape(-1)
    above = flat[flat > floor]
    k = int(max(0, max_count))
    if above.size <= k:
        return floor
    return max(floor, float(np.partition(above, above.size - 1 - k)[above.size - 1 - k]))


def equirect_highlights(image, max_count=None, ratio=HIGHLIGHT_RATIO):
    """The sparse part (:class:`Highlights`) of an equirect image (H, 2H, C):
    with T = :func:`highlight_threshold` (mean radiance over the sphere with
    exact cell solid angles; default ``max_count`` = pixels / 1536, at
    least 16), every pixel whose largest channel exceeds T becomes a point
    at its centre with energy max(L - T, 0) times its exact cell solid
    angle.  The bounded part is min(L, T) (not formed here: a large input
    is clamped band by band, :func:`pbrkit.ibl.spectral.halve_equirect`)."""
    from .equirect import equirect_directions, equirect_solid_angles

    img = np.asarray(image)
    h = img.shape[0]
    if max_count is None:
        max_count = max(16, img.shape[0] * img.shape[1] // 1536)
    peak = img.max(axis=2)
    omega_row = equirect_solid_angles(h, exact=True)[:, 0]
    mean = float(np.dot(peak.sum(axis=1, dtype=np.float64), omega_row)) / (4.0 * math.pi)
    threshold = highlight_threshold(peak, mean, max_count, ratio)
    rows, cols = np.nonzero(peak > threshold)
    del peak
    energies = np.maximum(img[rows, cols].astype(np.float64) - threshold, 0.0) * omega_row[rows][:, None]
    directions = np.zeros((rows.size, 3))
    uniq, inverse = np.unique(rows, return_inverse=True)
    for k0 in range(0, uniq.size, 64):  # pixel-centre directions, a few rows at a time
        pick = (inverse >= k0) & (inverse < k0 + 64)
        directions[pick] = equirect_directions(h, rows=uniq[k0:k0 + 64])[inverse[pick] - k0, cols[pick]]
    return Highlights(np.ascontiguousarray(directions), np.ascontiguousarray(energies), threshold)


def cube_highlights(cube, max_count=None, ratio=HIGHLIGHT_RATIO):
    """:func:`equirect_highlights` for a cube map (6, N, N, C): texel centres
    and exact texel solid angles (default ``max_count`` = texels / 1536)."""
    c = _as_cube(cube)
    n = c.shape[1]
    if max_count is None:
        max_count = max(16, 6 * n * n // 1536)
    peak = c.max(axis=3)
    omega = cube_texel_solid_angles(n)
    threshold = highlight_threshold(peak, float(np.sum(peak * omega)) / (4.0 * math.pi), max_count, ratio)
    f, i, j = np.nonzero(peak > threshold)
    energies = np.maximum(c[f, i, j].astype(np.float64) - threshold, 0.0) * omega[f, i, j][:, None]
    directions = cube_texel_directions(n)[f, i, j] if f.size else np.zeros((0, 3))
    return Highlights(np.ascontiguousarray(directions), np.ascontiguousarray(energies), threshold)


def merge_highlights(highlights, size, max_points=4096):
    """Merge the points of ``highlights`` that fall in the same texel of a
    size x size cube map into one point with their total energy at their
    energy-weighted (sum of channels) centroid direction; ``size`` halves
    until at most ``max_points`` remain.  Returns (directions, energies,
    size used)."""
    d, e = highlights.directions, highlights.energies
    size = int(size)
    if d.shape[0] == 0:
        return np.zeros((0, 3)), np.zeros((0, e.shape[1])), size
    face, s, t = direction_to_cube(d)
    weight = e.sum(axis=1)
    while True:
        col = np.minimum((s * size).astype(np.int64), size - 1)
        row = np.minimum((t * size).astype(np.int64), size - 1)
        key = (face * size + row) * size + col
        uniq, inverse = np.unique(key, return_inverse=True)
        if uniq.size <= max_points or size == 1:
            break
        size //= 2
    energy = np.zeros((uniq.size, e.shape[1]))
    centroid = np.zeros((uniq.size, 3))
    np.add.at(energy, inverse, e)
    np.add.at(centroid, inverse, d * weight[:, None])
    length = np.linalg.norm(centroid, axis=1, keepdims=True)
    centroid = np.where(length > 0.0, centroid / np.where(length > 0.0, length, 1.0), d[np.unique(inverse, return_index=True)[1]])
    return np.ascontiguousarray(centroid), np.ascontiguousarray(energy), size


#: Zonal lobes k(n.l) of :func:`point_lobe_sum`: the clamped cosine max(0, n.l)
#: (irradiance, :mod:`pbrkit.ibl.irradiance`) and the split-sum GGX kernel
#: D(n.h) (n.l) on n.l > 0 with n.h = sqrt((1 + n.l) / 2) (h bisects n = v and l;
#: :func:`ggx_prefilter_kernel` as a function of n.l).
LOBE_COSINE = 0
LOBE_GGX = 1


@dual_use
def _point_lobe(lobe, nol, alpha):
    """k(n.l) of lobe code ``lobe`` (:data:`LOBE_COSINE`, :data:`LOBE_GGX`) for n.l > 0."""
    if lobe == LOBE_COSINE:
        return nol
    return d_ggx(math.sqrt(0.5 + 0.5 * nol), alpha) * nol


@row_kernel(0)
def _point_lobe_kernel(start, stop, dirs, points, values, weights, lobe, alpha, scale, normalise, out):
    """out[k] += sum_i w_i L_i with w_i = k(n_k.l_i) scale weights_i over the points
    i with n_k.l_i > 0; with ``normalise`` out[k] is then divided by sum_i w_i."""
    channels = out.shape[1]
    for k in range(start, stop):
        nx, ny, nz = dirs[k, 0], dirs[k, 1], dirs[k, 2]
        total = 0.0
        for i in range(points.shape[0]):
            nol = nx * points[i, 0] + ny * points[i, 1] + nz * points[i, 2]
            if nol > 0.0:
                w = _point_lobe(lobe, nol, alpha) * scale * weights[i]
                total += w
                for c in range(channels):
                    out[k, c] += w * values[i, c]
        if normalise:
            for c in range(channels):
                out[k, c] = out[k, c] / total


def point_lobe_sum(out, directions, points, values, lobe, alpha=1.0, scale=1.0, weights=None, normalise=False):
    """Sum a zonal lobe over points on the sphere, in place: for each unit
    direction n_k (``directions`` (K, 3)), ``out[k]`` ((K, C)) += sum_i w_i
    ``values[i]`` over the points l_i (``points`` (P, 3), unit) with
    n_k.l_i > 0, w_i = k(n_k.l_i) ``scale`` ``weights[i]`` (default 1), the
    lobe k of :data:`LOBE_COSINE` or :data:`LOBE_GGX` (of ``alpha``); with
    ``normalise``, out[k] (zero on entry) is then divided by sum_i w_i.  The
    exact highlight sums (:func:`add_highlights`,
    :func:`pbrkit.ibl.irradiance.add_cosine_highlights`) and the brute-force
    references (:func:`prefilter_reference`,
    :func:`pbrkit.ibl.irradiance.irradiance_reference`) are this sum."""
    if points.shape[0]:
        weights = np.ones(points.shape[0]) if weights is None else np.ascontiguousarray(weights, dtype=np.float64)
        _point_lobe_kernel(np.ascontiguousarray(directions, dtype=np.float64), np.ascontiguousarray(points),
                           np.ascontiguousarray(values), weights, int(lobe), float(alpha), float(scale),
                           bool(normalise), out)
    return out


def add_highlights(out, directions, points, energies, alpha):
    """Add the exact prefiltered contribution of point highlights (module
    doc), E_i D(n.h_i) (n.l_i) / Z(alpha), at unit ``directions`` (K, 3) to
    ``out`` (K, C) in place (:func:`point_lobe_sum`)."""
    alpha = float(alpha)
    return point_lobe_sum(out, directions, points, energies, LOBE_GGX, alpha,
                          1.0 / float(ggx_lobe_normalization(alpha)))


# ------------------------------------------------------------ spectral path


def prefilter_spectral(coeffs, highlights, size, levels, grid_factor=2.0, progress=None):
    """Levels 1..M-1 of the prefiltered chain (module doc) from the
    spherical-harmonic coefficients ``coeffs`` (L + 1, L + 1, C) of the
    bounded environment (:func:`pbrkit.ibl.spectral.analyse_equirect`) and its
    :class:`Highlights`: level m is (6, size >> m, size >> m, C) float32
    for roughness :func:`roughness_of_level` (m, levels).  Each level's
    series is synthesised on an equirect grid of grid_factor * L + 2 rows
    and interpolated at the texel centres; negative values of the truncated
    series (ringing of order 1e-6 of the bounded part) are clamped to 0.
    ``progress(m)`` after each level.  Returns (levels, info dicts)."""
    levels = _check_levels(levels)
    chain, info = [], []
    for m in range(1, levels):
        values, entry = _spectral_level(coeffs, highlights, size >> m, roughness_of_level(m, levels), grid_factor)
        chain.append(values)
        info.append(dict(level=m, **entry))
        if progress is not None:
            progress(m)
    return chain, info


def _spectral_level(coeffs, highlights, n, r, grid_factor=2.0, lmax=None):
    """One level of :func:`prefilter_spectral`: (6, n, n, C) float32 and its info."""
    alpha = float(alpha_from_roughness(r))
    if lmax is None:
        lmax = min(coeffs.shape[0] - 1, band_limit(alpha, max(16, 4 * n)))
    height = int(grid_factor * lmax) + 2
    lam, _ = ggx_zonal_coefficients(alpha, lmax)
    grid = synthesise_equirect(convolve(coeffs[: lmax + 1, : lmax + 1], lam), height)
    dirs = cube_texel_directions(n).reshape(-1, 3)
    values = sample_equirect(grid, dirs)
    del grid
    points, energies, merged = merge_highlights(highlights, 2 * n, MAX_HIGHLIGHT_POINTS)
    add_highlights(values, dirs, points, energies, alpha)
    np.maximum(values, 0.0, out=values)
    return values.reshape(6, n, n, -1).astype(np.float32), dict(
        size=n, roughness=float(r), alpha=alpha, samples=0,
        method=f"spherical-harmonic convolution to degree {lmax} (no sampling) + "
               f"{points.shape[0]} highlight points", band_limit=lmax,
        lambda_at_band_limit=float(abs(lam[-1])), grid_height=height,
        highlight_points=int(points.shape[0]), highlight_merge_size=int(merged))


#: Filtered-importance samples per texel of a :func:`prefilter_chain` level whose
#: lobe is too narrow for the transform (its residual).
RESIDUAL_SAMPLES = 32


class _Residual:
    """What the narrow levels of :func:`prefilter_chain` share, built once: the
    level-0 cube's highlights (texel points above the threshold), and the mip
    pyramid of its bounded part minus the band-limited series at the texel centres."""

    def __init__(self, coeffs, level0, grid_factor):
        lmax = coeffs.shape[0] - 1
        self.highlights = cube_highlights(level0)
        n = level0.shape[1]
        series = sample_equirect(synthesise_equirect(coeffs, int(grid_factor * lmax) + 2),
                                 cube_texel_directions(n).reshape(-1, 3)).reshape(level0.shape)
        residual = np.minimum(level0.astype(np.float64), self.highlights.threshold) - series
        self.sampler = CubeSampler(build_mip_pyramid(residual))


def _residual_level(coeffs, shared, n, r, samples, grid_factor=2.0):
    """A level whose lobe needs more degrees than ``coeffs`` hold (:func:`prefilter_chain`)."""
    alpha = float(alpha_from_roughness(r))
    lmax = coeffs.shape[0] - 1
    lam, _ = ggx_zonal_coefficients(alpha, lmax)
    grid = synthesise_equirect(convolve(coeffs, lam), int(grid_factor * lmax) + 2)
    dirs = cube_texel_directions(n).reshape(-1, 3)
    values = sample_equirect(grid, dirs)
    del grid
    ss = sample_set(r, samples)
    values += prefilter_level(shared.sampler, dirs, ss)
    points, energies, merged = merge_highlights(shared.highlights, 2 * n, MAX_HIGHLIGHT_POINTS)
    add_highlights(values, dirs, points, energies, alpha)
    np.maximum(values, 0.0, out=values)
    return values.reshape(6, n, n, -1).astype(np.float32), dict(
        size=n, roughness=float(r), alpha=alpha, samples=ss.count, samples_used=ss.used,
        method=f"spherical-harmonic convolution to degree {lmax} + filtered importance sampling "
               f"({ss.count} GGX samples) of the level-0 cube's bounded part minus that series + "
               f"{points.shape[0]} highlight points of the level-0 cube",
        band_limit=lmax, lambda_at_band_limit=float(abs(lam[-1])),
        highlight_points=int(points.shape[0]), highlight_merge_size=int(merged))


def _resolved(alpha, lmax, tolerance=BAND_LIMIT_TOLERANCE):
    """Whether a degree-``lmax`` series holds the lobe of ``alpha``: its
    coefficients have decayed below ``tolerance`` by then, or the lobe is past
    alpha = 0.2, where they end in an algebraic tail that :func:`band_limit` cuts
    for every chain alike."""
    if alpha >= 0.2:
        return True
    lam, _ = ggx_zonal_coefficients(alpha, lmax)
    return bool(np.all(np.abs(lam[-4:]) < tolerance))


def prefilter_chain(coeffs, highlights, level0, sizes, roughness, samples=RESIDUAL_SAMPLES, grid_factor=2.0,
                    progress=None, shared=None):
    """Levels 1.. of a chain with any level sizes and perceptual roughness
    (:func:`chain_roughness`: the level curves of Filament, three.js and
    Babylon.js), from the transform ``coeffs`` of the bounded environment, its
    ``highlights`` and the level-0 cube ``level0`` (6, N, N, C).

    A level whose lobe the transform resolves (its coefficients below
    :data:`BAND_LIMIT_TOLERANCE` by the degree of ``coeffs``) is exactly
    :func:`prefilter_spectral`'s.  A narrower
    lobe (Filament's level 1, alpha = 0.018 at M = 5, needs degree 430; the
    transform of a 256 bake goes to 124) uses the series as a control variate:
    the exact convolution of the band-limited series, plus filtered importance
    sampling (:func:`prefilter_level`, ``samples`` per texel) of the residual
    level-0 cube minus that series (bounded at the level-0 cube's own highlight
    threshold, :func:`cube_highlights`), plus that cube's highlights summed
    exactly.  Sampling then only sees the residual's detail, a few per cent of
    the radiance, so its error falls about tenfold against sampling the
    environment (about 1e-3 to 7e-3 relative RMS away from the sun at 32
    samples on an outdoor map, 1e-4 near it; ``bench/bake.py``).  ``shared``, a
    dict, keeps what the narrow levels share (the residual pyramid) between
    calls on the same inputs.  Returns (levels, info dicts)."""
    if len(sizes) != len(roughness) or len(sizes) < 2:
        raise ValueError("sizes and roughness must list the same levels, at least 2")
    lmax = coeffs.shape[0] - 1
    shared = {} if shared is None else shared
    chain, info = [], []
    for m in range(1, len(sizes)):
        n, r = int(sizes[m]), float(roughness[m])
        if _resolved(float(alpha_from_roughness(r)), lmax):
            values, entry = _spectral_level(coeffs, highlights, n, r, grid_factor)
        else:
            if "residual" not in shared:
                shared["residual"] = _Residual(coeffs, level0, grid_factor)
            values, entry = _residual_level(coeffs, shared["residual"], n, r, samples, grid_factor)
        chain.append(values)
        info.append(dict(level=m, **entry))
        if progress is not None:
            progress(m)
    return chain, info


# ---------------------------------------------------- filtered importance sampling


class SampleSet:
    """A level's sample pattern in the local frame (normal +z): unit
    directions ``l`` (K', 3), weights ``weight`` = n.l (K',) and lod offsets
    ``lod_offset`` = 0.5 log2(Omega_s) + bias (K',) of the K' <= ``count``
    samples with n.l > 0; ``roughness``, ``alpha``, ``bias``."""

    def __init__(self, l, weight, lod_offset, count, roughness, alpha, bias):
        self.l = l
        self.weight = weight
        self.lod_offset = lod_offset
        self.count = count
        self.roughness = roughness
        self.alpha = alpha
        self.bias = bias

    @property
    def used(self):
        """Number of samples kept (n.l > 0)."""
        return int(self.weight.size)


def sample_set(roughness, count, bias=1.0):
    """The filtered-importance-sampling pattern (module doc) of ``count``
    Hammersley points for perceptual roughness ``roughness``: h from
    :func:`pbrkit.microfacet.ggx.warp_ggx_ndf` with alpha = max(r^2, ALPHA_MIN),
    l = reflect(n, h) (:func:`pbrkit.sampling.warps.reflect_xyz`, v = n = +z), the
    pdf of l from :func:`pbrkit.sampling.warps.pdf_light_from_half` of
    :func:`pbrkit.microfacet.ggx.pdf_ggx_ndf` (D / 4 here) and Omega_s =
    1 / (count pdf); ``bias`` 1 is Krivanek & Colbert's."""
    count = checks.integer(count, "sample count", 1, 1 << 20)
    roughness = float(roughness)
    if not 0.0 <= roughness <= 1.0:
        raise ValueError(f"roughness must be in [0, 1], got {roughness!r}")
    alpha = float(alpha_from_roughness(roughness))
    u = hammersley(int(count), 2)
    hx, hy, hz = warp_ggx_ndf(u[:, 0], u[:, 1], alpha)
    lx, ly, lz = reflect_xyz(0.0, 0.0, 1.0, hx, hy, hz)
    keep = lz > 0.0
    pdf = pdf_light_from_half(pdf_ggx_ndf(hz[keep], alpha), hz[keep])
    lod = 0.5 * np.log2(1.0 / (count * pdf)) + bias
    l = np.stack([lx, ly, lz], axis=-1)[keep]
    l /= np.linalg.norm(l, axis=-1, keepdims=True)
    return SampleSet(np.ascontiguousarray(l), np.ascontiguousarray(lz[keep]), np.ascontiguousarray(lod),
                     int(count), roughness, alpha, float(bias))


def default_sample_counts(levels, first=64):
    """Sample counts of :func:`prefilter_fis` by default: 0 for level 0 (a
    copy), ``first`` for level 1, doubling per level up to 1024 (the output
    texel count falls four-fold per level)."""
    levels = _check_levels(levels)
    return [0] + [int(min(1024, first << (m - 1))) for m in range(1, levels)]


@row_kernel(0)
def _fis_kernel(start, stop, dirs, l, weight, lod_offset, lod_base, data, offsets, sizes, out):
    """out[k] = sum_s w_s L(R_k l_s, lod_s) / sum_s w_s for each texel k with
    frame R_k = (t, b, n) (:func:`pbrkit.core.vec.orthonormal_basis_xyz`); L is the
    trilinear lookup of the bordered pyramid (``data``, ``offsets``, ``sizes``
    of :class:`pbrkit.ibl.cubemap.CubeSampler`, :func:`pbrkit.ibl.cubemap._trilinear_add`)
    and lod_s = lod_offset_s - 0.5 (lod_base + log2 density), i.e.
    0.5 log2(Omega_s / Omega_p) + bias."""
    channels = out.shape[1]
    total = 0.0
    for s in range(l.shape[0]):
        total += weight[s]
    inv_total = 1.0 / total if total > 0.0 else 0.0
    for k in range(start, stop):
        nx, ny, nz = dirs[k, 0], dirs[k, 1], dirs[k, 2]
        (tx, ty, tz), (bx, by, bz) = orthonormal_basis_xyz(nx, ny, nz)
        acc = np.zeros(channels)
        for s in range(l.shape[0]):
            a, b, c = l[s, 0], l[s, 1], l[s, 2]
            face, sc, tc = cube_face_coords(a * tx + b * bx + c * nx, a * ty + b * by + c * ny,
                                            a * tz + b * bz + c * nz)
            lod = lod_offset[s] - 0.5 * (lod_base + math.log2(cube_texel_density(sc, tc)))
            _trilinear_add(data, offsets, sizes, face, sc, tc, lod, weight[s] * inv_total, acc)
        for ch in range(channels):
            out[k, ch] = acc[ch]


def _flat_dirs(directions):
    d, length = checks.direction_lengths(directions)
    return np.ascontiguousarray((d / length[..., None]).reshape(-1, 3)), d.shape[:-1]


def prefilter_level(sampler, directions, samples):
    """Filtered-importance-sampling estimate (module doc) at unit
    ``directions`` (..., 3) -> (..., C) float64.  ``sampler`` is a
    :class:`pbrkit.ibl.cubemap.CubeSampler` of a mip pyramid whose levels halve
    from N; ``samples`` a :class:`SampleSet`."""
    dirs, shape = _flat_dirs(directions)
    out = np.empty((dirs.shape[0], sampler.channels))
    _fis_kernel(dirs, samples.l, samples.weight, samples.lod_offset, 2.0 * math.log2(2.0 / int(sampler.sizes[0])),
                sampler.data, sampler.offsets, sampler.sizes, out)
    return out.reshape(shape + (sampler.channels,))


def prefilter_fis(cube, levels, sample_counts=None, bias=1.0, highlights=None, progress=None):
    """Levels 1..M-1 of the chain by filtered importance sampling (module
    doc) of the pyramid of ``cube`` (6, N, N, C); ``highlights``, if given,
    are the sparse part split off ``cube`` (then ``cube`` must be the
    bounded part) and are added exactly as in :func:`prefilter_spectral`.
    ``sample_counts`` per level (default :func:`default_sample_counts`).
    Returns (levels, info dicts)."""
    c = _as_cube(cube)
    n = c.shape[1]
    levels = _check_levels(levels)
    if (n >> (levels - 1)) << (levels - 1) != n:
        raise ValueError(f"a {n} x {n} cube cannot hold {levels} halving levels")
    counts = default_sample_counts(levels) if sample_counts is None else [int(k) for k in sample_counts]
    if len(counts) != levels:
        raise ValueError(f"expected {levels} sample counts, got {len(counts)}")
    sampler = CubeSampler(build_mip_pyramid(c))
    chain, info = [], []
    for m in range(1, levels):
        size = n >> m
        ss = sample_set(roughness_of_level(m, levels), counts[m], bias)
        dirs = cube_texel_directions(size).reshape(-1, 3)
        values = prefilter_level(sampler, dirs, ss)
        entry = dict(level=m, size=size, roughness=ss.roughness, alpha=ss.alpha, samples=ss.count,
                     samples_used=ss.used, lod_bias=ss.bias,
                     method=f"filtered importance sampling, {ss.count} Hammersley GGX samples "
                            f"({ss.used} with n.l > 0), lod bias {ss.bias:g}")
        if highlights is not None:
            points, energies, merged = merge_highlights(highlights, 2 * size, MAX_HIGHLIGHT_POINTS)
            add_highlights(values, dirs, points, energies, ss.alpha)
            entry.update(highlight_points=int(points.shape[0]), highlight_merge_size=int(merged))
        chain.append(values.reshape(6, size, size, -1).astype(np.float32))
        info.append(entry)
        if progress is not None:
            progress(m)
    return chain, info


# ---------------------------------------------------------------- references


def prefilter_reference(cube, directions, roughness):
    """Brute-force prefiltered radiance at ``directions`` (..., 3): the ratio
    of the module doc as a sum over *every* texel i of ``cube``
    (6, N, N, C), with its centre direction l_i and exact solid angle
    Omega_i (:func:`pbrkit.ibl.cubemap.cube_texel_solid_angles`),
    n.h_i = sqrt((1 + n.l_i) / 2) and D = :func:`pbrkit.microfacet.ggx.d_ggx`
    with alpha = max(r^2, ALPHA_MIN), normalised by the same sum of weights
    (:func:`point_lobe_sum`).  O(directions x 6 N^2); for tests and
    benchmarks.  Returns (..., C)."""
    c = _as_cube(cube).astype(np.float64)
    n = c.shape[1]
    dirs, shape = _flat_dirs(directions)
    out = np.zeros((dirs.shape[0], c.shape[3]))
    point_lobe_sum(out, dirs, cube_texel_directions(n).reshape(-1, 3), c.reshape(-1, c.shape[3]), LOBE_GGX,
                   float(alpha_from_roughness(float(roughness))),
                   weights=cube_texel_solid_angles(n).reshape(-1), normalise=True)
    return out.reshape(shape + (c.shape[3],))


def prefilter_importance_sampled(cube, directions, roughness, samples=1024):
    """Plain importance-sampled prefiltered radiance, as Karis 2013's
    ``PrefilterEnvMap``: ``samples`` Hammersley GGX samples, l =
    reflect(n, h), weights n.l, each looked up bilinearly in level 0 of
    ``cube`` (no pyramid, no lod, no highlight split): the baseline the
    prefilter is compared with.  Returns (..., C) float64."""
    sampler = CubeSampler(_as_cube(cube).astype(np.float64))  # one level: every lod clamps to 0
    return prefilter_level(sampler, directions, sample_set(float(roughness), int(samples)))
