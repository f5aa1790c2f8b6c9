"""Fitting LTC tables in the published layout, for the integrals a shader computes.

Heitz, Dupuy, Hill and Neubelt (2016, sec. 4; ``ltc_code`` ``fit/fitLTC.cpp``)
fit each cell's matrix by Nelder-Mead on the L3 distance between the lobe and the
LTC, estimated from 32 x 32 samples, with the albedo from the same samples.  A
renderer does not use the lobe's shape, though: it integrates the LTC over a
polygon with the shader's shortcuts (the edge terms' rational fit and the
horizon clipping by the sphere approximation, :func:`pbrkit.ltc.shader.
ltc_shader_form_factor`) and multiplies by the stored norm.  pbrkit fits that
directly (:func:`fit_cell`):

- per cell, ``polygons`` rectangular lights (:func:`fit_lights`): half of them
  centred on directions drawn from the lobe itself (the GGX visible-normal
  distribution, Heitz 2018, reflected about the view), the rest uniform in
  solid angle over the hemisphere; :data:`CROSSING_SHARE` of them straddle the
  horizon, the others are kept above it; angular
  half-sizes log-uniform between the lobe's width (0.05 rad for the uniform ones)
  and 0.8 rad; drawn from the same seed in every cell, so that the lights, and
  the fitted entries, vary smoothly from cell to cell (bilinear lookups
  interpolate them), and the fit is deterministic;
- their converged integrals of the lobe (F = 1; :func:`pbrkit.ltc.reference.lobe_rect_integrals`):
  GGX with height-correlated Smith by default, or ``distribution`` (GGX,
  Beckmann) and ``masking`` (the Smith-family terms of ``cook_torrance``,
  :data:`pbrkit.ltc.reference.MASKINGS_FOR`; ``pbrkit ltc --distribution
  --masking``), and the same lobe's converged albedo E
  (:func:`pbrkit.ltc.reference.lobe_split_integrals`: :func:`pbrkit.albedo.tables.specular_integrals`
  where it has the lobe, else :func:`pbrkit.albedo.furnace.albedo_quadrature`);
- the objective sum_k ((E FF_k - I_k) / (I_k + eps E))^2, the shader's form factor
  FF_k under the candidate matrix against the reference I_k: relative errors
  where a light matters, errors relative to eps of the albedo where it does not
  (eps = :data:`EPSILON`), summed over the normal reflectances ``fit_f0``
  (by default :data:`FIT_F0`, a metal's and a dielectric's: the shader scales one
  shape by the Fresnel split, so a shape fitted for F = 1 alone serves
  dielectrics poorly; :func:`default_fit_f0`);
- Nelder-Mead (SciPy) over the four stored entries of M^-1 / m11 themselves
  (x, y, z, w of ``ltc_1``), from the neighbouring cell's solution: cells are
  fitted from rough to smooth and, for each roughness, from normal incidence
  to grazing, as Heitz et al. do; at normal incidence the lobe is symmetric and
  only w is fitted (x = 1, y = z = 0).

``ltc_2`` holds (norm, fresnel, 0, sphere) = (A + B, B) of the converged split
integrals (:func:`pbrkit.ltc.reference.lobe_split_integrals`; Schlick's F: f0 norm
+ (1 - f0) fresnel) and the sphere table (:func:`sphere_form_factor_table`).
Roughness: column a holds perceptual roughness r = a / (N - 1) with alpha = r^2
for GGX and Beckmann alike (:func:`pbrkit.microfacet.roughness.alpha_from_roughness`,
clamped at its ALPHA_MIN);
row t holds cos theta_v = 1 - (t / (N - 1))^2, at most 89.95 degrees.
The lights a cell is fitted on do not depend on the lobe (its lobe-centred
lights follow GGX's visible normals of the same alpha, which cover a Beckmann
lobe of that alpha too), so tables of different lobes are fitted on the same
lights.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..choices import LTC_CLIPPINGS, LTC_FIT_F0
from ..core.jit import kernel
from .reference import LTC_DISTRIBUTIONS, LTC_MASKINGS, lobe_codes
from .shader import exact_rect_form_factor, shader_rect_form_factor

#: How the LTC's integral is clipped at the horizon (``pbrkit ltc --clipping``):
#: ``sphere``, the shaders' approximation from the vector form factor (the
#: published layout's evaluation, what engines run), or ``exact``, the polygon
#: clipped against the true horizon (pbrkit's own evaluation,
#: :func:`pbrkit.ltc.shader.ltc_exact_rect`).
CLIPPINGS = LTC_CLIPPINGS  # pbrkit.choices

__all__ = ["EPSILON", "CROSSING_SHARE", "FIT_F0", "FRESNEL_SPLIT_F0", "default_fit_f0", "CLIPPINGS", "DISTRIBUTIONS",
           "MASKINGS", "MAX_THETA", "cell_view",
           "fit_lights", "cell_data", "albedos", "references", "fit_cell", "fit_table", "sphere_form_factor_table",
           "LTCFit", "cell_errors"]

#: ``pbrkit ltc --distribution`` / ``--masking`` (:data:`pbrkit.ltc.reference.LTC_DISTRIBUTIONS`,
#: :data:`pbrkit.ltc.reference.LTC_MASKINGS`; which pairs: :data:`pbrkit.ltc.reference.MASKINGS_FOR`).
DISTRIBUTIONS = LTC_DISTRIBUTIONS
MASKINGS = LTC_MASKINGS

#: Floor of the objective's relative errors, as a share of the albedo.
EPSILON = 0.01
#: Share of each cell's lights that straddle the horizon (the test set's: 15%).
CROSSING_SHARE = 0.15
#: The normal reflectances the objective weighs by default (``pbrkit ltc --fit-f0``;
#: :data:`pbrkit.choices.LTC_FIT_F0`, this very tuple): a metal's F = 1 (the lobe's
#: shape without Fresnel, which the published table fits) and a dielectric's
#: Schlick-weighted lobe, f0 = 0.04, which leans further to grazing.  The shader
#: scales one shape by the Fresnel split, so a shape fitted for F = 1 alone serves
#: dielectrics poorly; the pair was chosen on the tuning set of metals and
#: dielectrics (:data:`pbrkit.ltc.lights.TUNING_SET`) among 1, 0.04, 0.5, 1,0.04
#: and 1,0.5,0.04, and is reported on :data:`pbrkit.ltc.lights.REPORT_SET`
#: (``bench/ltc.md``).
FIT_F0 = LTC_FIT_F0
#: The first matrix of pbrkit's Fresnel-aware pair (``pbrkit ltc --fresnel-aware``,
#: :func:`pbrkit.ltc.shader.ltc_fresnel_rect`) is the F = 1 lobe's by construction
#: (Schlick's F splits f F into f0 f + (1 - f0) f Fc; the second matrix is f Fc's).
FRESNEL_SPLIT_F0 = (1.0,)
#: The grazing row's view angle (radians): cos theta_v = 0 would put v in the horizon.
MAX_THETA = math.radians(89.95)


def default_fit_f0(fresnel=False):
    """The normal reflectances ``pbrkit ltc`` fits for without ``--fit-f0``:
    :data:`FIT_F0` for a table of one matrix per cell (the drop-in), and with
    ``fresnel`` (the Fresnel-aware pair) :data:`FRESNEL_SPLIT_F0`."""
    return FRESNEL_SPLIT_F0 if fresnel else FIT_F0


def cell_view(t, a, n):
    """(n.v, perceptual roughness) of cell (row t, column a) of an N x N table."""
    u = t / (n - 1.0)
    nov = max(1.0 - u * u, math.cos(MAX_THETA))
    return nov, a / (n - 1.0)


def fit_lights(nov, roughness, count, seed):
    """The rectangular lights a cell is fitted on (module doc), as
    :class:`pbrkit.ltc.lights.RectLights`."""
    from ..microfacet.ggx import warp_ggx_vndf
    from ..microfacet.roughness import alpha_from_roughness
    from ..sampling.warps import reflect_xyz
    from .lights import rect_lights_towards

    rng = np.random.default_rng(seed)
    k = int(count)
    alpha = float(alpha_from_roughness(roughness))
    v = np.array([math.sqrt(max(0.0, 1.0 - nov * nov)), 0.0, nov])
    from_lobe = np.arange(k) < k // 2
    # lobe directions: visible normals reflected about the view (kept above the horizon)
    u1, u2 = rng.random(k), rng.random(k)
    hx, hy, hz = warp_ggx_vndf(u1, u2, v[0], v[1], v[2], alpha)
    lx, ly, lz = reflect_xyz(v[0], v[1], v[2], hx, hy, hz)
    lobe = np.stack([lx, ly, lz], -1)
    lobe[:, 2] = np.maximum(lobe[:, 2], 0.02)
    lobe /= np.linalg.norm(lobe, axis=1, keepdims=True)
    # the rest: uniform in solid angle over the hemisphere; CROSSING_SHARE of all the lights straddle the
    # horizon, the others stay above it (as in the test set: crossing lights are where the shader's sphere
    # approximation of the clipping is poorest, and a fit that sees too many of them bends every other light)
    phi = rng.uniform(0.0, 2.0 * math.pi, k)
    width = math.sqrt(alpha)  # the lobe's angular width, about
    smallest = np.where(from_lobe, max(0.01, 0.5 * width), 0.05)[:, None]
    half_angle = np.exp(np.log(smallest) + rng.random((k, 2)) * (math.log(0.8) - np.log(smallest)))
    cross = (~from_lobe) & (rng.random(k) < 2.0 * CROSSING_SHARE)
    a_min = half_angle.min(axis=1)
    a_max = half_angle.max(axis=1)
    above = np.arcsin(np.sin(a_max) + (1.0 - np.sin(a_max)) * rng.random(k))
    elevation = np.where(cross, rng.uniform(-1.0, 1.0, k) * a_min, above)
    uniform = np.stack([np.cos(elevation) * np.cos(phi), np.cos(elevation) * np.sin(phi), np.sin(elevation)], -1)
    direction = np.where(from_lobe[:, None], lobe, uniform)
    # a lobe light must not cross the horizon either: at most as large as its elevation
    lobe_elevation = np.arcsin(np.clip(lobe[:, 2], 0.0, 1.0))
    shrink = from_lobe & (a_max > 0.9 * lobe_elevation)
    half_angle[shrink] *= (0.9 * lobe_elevation[shrink] / a_max[shrink])[:, None]
    distance = rng.uniform(1.0, 4.0, k)
    tilt = rng.uniform(0.0, math.radians(45.0), k)
    tilt_phi = rng.uniform(0.0, 2.0 * math.pi, k)
    spin = rng.uniform(0.0, 2.0 * math.pi, k)
    return rect_lights_towards(nov, roughness, direction, distance, half_angle, tilt, tilt_phi, spin)


@kernel
def _objective_kernel(x, y, z, w, corners, reference, albedo, epsilon, exact):
    """sum_k ((E FF_k - I_k) / (I_k + eps E))^2 with FF_k the LTC's integral over
    light k under the texel (x, y, z, w) as the shader evaluates it
    (:func:`pbrkit.ltc.shader.shader_rect_form_factor`) or, with ``exact``, clipped
    at the true horizon (:func:`pbrkit.ltc.shader.exact_rect_form_factor`)."""
    total = 0.0
    for k in range(corners.shape[0]):
        if exact:
            ff = exact_rect_form_factor(x, y, z, w, corners[k])
        else:
            ff = shader_rect_form_factor(x, y, z, w, corners[k])
        e = (albedo * ff - reference[k]) / (reference[k] + epsilon * albedo)
        total += e * e
    return total


def _objective(texel, corners, reference, albedo, fit_f0=FIT_F0, clipping="sphere"):
    """The objective summed over ``fit_f0`` (:data:`FIT_F0`): ``reference`` (K, 2)
    the lights' (norm, fresnel) integrals, ``albedo`` (A + B, B); with Schlick's F
    the reference is f0 norm + (1 - f0) fresnel and the LTC's the form factor
    times f0 (A + B) + (1 - f0) B (the shader's Fresnel split)."""
    x, y, z, w = (float(v) for v in texel)
    total = 0.0
    for f0 in fit_f0:
        ref = np.ascontiguousarray(f0 * reference[:, 0] + (1.0 - f0) * reference[:, 1])
        total += _objective_kernel(x, y, z, w, corners, ref, f0 * albedo[0] + (1.0 - f0) * albedo[1], EPSILON,
                                   clipping == "exact")
    return total


def cell_data(nov, roughness, polygons=32, seed=0, distribution="ggx", masking="height-correlated"):
    """What a cell is fitted on: its lights' corners (K, 4, 3) (:func:`fit_lights`;
    the same for every lobe) and the lobe's albedo (A + B, B) (:func:`albedos`);
    the lights' references come from :func:`references` (batched)."""
    lights = fit_lights(nov, roughness, polygons, seed)
    norm, fresnel = albedos([nov], [roughness], distribution, masking)[0]
    return np.ascontiguousarray(lights.corners, dtype=np.float64), float(norm), float(fresnel)


def albedos(nov, roughness, distribution="ggx", masking="height-correlated"):
    """``ltc_2``'s (norm, fresnel) = (A + B, B) of the lobe's converged split
    integrals (:func:`pbrkit.ltc.reference.lobe_split_integrals`) per cell: ``nov``,
    ``roughness`` (C,) -> (C, 2)."""
    from .reference import lobe_split_integrals

    ab = lobe_split_integrals(np.asarray(nov, dtype=float), np.asarray(roughness, dtype=float), distribution,
                              masking)
    return np.stack([ab[..., 0] + ab[..., 1], ab[..., 1]], axis=-1)


def references(nov, roughness, corners, distribution="ggx", masking="height-correlated"):
    """Converged integrals of lights for the lobe (:func:`pbrkit.ltc.reference.lobe_rect_integrals`
    at 1e-5), (norm, fresnel) parts: ``nov``, ``roughness`` (C,), ``corners``
    (C, K, 4, 3) -> (C, K, 2)."""
    from .reference import lobe_rect_integrals

    c, k = corners.shape[:2]
    mu = np.repeat(np.asarray(nov, dtype=float), k)
    r = np.repeat(np.asarray(roughness, dtype=float), k)
    return lobe_rect_integrals(mu, r, corners.reshape(c * k, 4, 3), distribution, masking,
                               tol=1e-5).reshape(c, k, 2)





def fit_cell(nov, start, corners, reference, albedo, fit_f0=FIT_F0, clipping="sphere"):
    """Fit one cell (module doc) from the ``ltc_1`` texel ``start`` (4,) on its
    lights ``corners`` (K, 4, 3) with references ``reference`` (K, 2) (norm,
    fresnel) and ``albedo`` (A + B, B); returns (texel (4,), the RMS of the
    objective's errors over the lights and ``fit_f0``)."""
    from scipy.optimize import minimize

    start = np.asarray(start, dtype=float)
    reference = np.ascontiguousarray(reference, dtype=np.float64)
    albedo = (float(albedo[0]), float(albedo[1]))
    if nov >= 1.0 - 1e-12:  # normal incidence: a symmetric lobe, x = 1, y = z = 0
        def objective(p):
            return _objective(np.array([1.0, 0.0, 0.0, p[0]]), corners, reference, albedo, fit_f0, clipping)

        result = minimize(objective, [start[3]], method="Nelder-Mead",
                          options={"xatol": 1e-6, "fatol": 1e-12, "maxiter": 400})
        texel = np.array([1.0, 0.0, 0.0, result.x[0]])
    else:
        def objective(p):
            return _objective(p, corners, reference, albedo, fit_f0, clipping)

        result = minimize(objective, start, method="Nelder-Mead",
                          options={"xatol": 1e-6, "fatol": 1e-12, "maxiter": 1500})
        texel = np.asarray(result.x, dtype=float)
    return texel, math.sqrt(_objective(texel, corners, reference, albedo, fit_f0, clipping)
                            / (corners.shape[0] * len(fit_f0)))


class LTCFit:
    """A fitted table: ``ltc1``, ``ltc2`` (N, N, 4) float32 in the published
    layout, ``error`` (N, N) the RMS objective error per cell, ``seconds``, and
    what each cell was fitted on (``corners`` (N, N, K, 4, 3), ``reference``
    (N, N, K, 2)), to score other tables on the same lights (:func:`cell_errors`);
    the lobe it was fitted for (``distribution``, ``masking``), ``fit_f0`` and
    ``clipping``."""

    def __init__(self, ltc1, ltc2, error, seconds, polygons, seed, corners, reference, distribution="ggx",
                 masking="height-correlated", fit_f0=FIT_F0, clipping="sphere"):
        self.ltc1, self.ltc2, self.error, self.seconds = ltc1, ltc2, error, seconds
        self.polygons, self.seed = polygons, seed
        self.corners, self.reference = corners, reference
        self.distribution, self.masking = distribution, masking
        self.fit_f0, self.clipping = tuple(fit_f0), clipping


def cell_errors(fit, ltc1):
    """The RMS objective error per cell (N, N) of the texels ``ltc1`` (N, N, 4) on
    the lights ``fit`` was fitted on (e.g. the published table's)."""
    n = fit.ltc1.shape[0]
    out = np.zeros((n, n))
    for t in range(n):
        for a in range(n):
            f0s = getattr(fit, "fit_f0", FIT_F0)
            k = fit.corners.shape[2] * len(f0s)
            out[t, a] = math.sqrt(_objective(np.asarray(ltc1[t, a], dtype=float), fit.corners[t, a],
                                             fit.reference[t, a], (float(fit.ltc2[t, a, 0]),
                                                                   float(fit.ltc2[t, a, 1])), f0s,
                                             getattr(fit, "clipping", "sphere")) / k)
    return out


def fit_table(n=64, polygons=64, seed=0, progress=None, fit_f0=FIT_F0, clipping="sphere", distribution="ggx",
              masking="height-correlated"):
    """Fit an N x N table (module doc) for the lobe of ``distribution`` and
    ``masking`` (:data:`DISTRIBUTIONS`, :data:`MASKINGS`; the pairs of
    :data:`pbrkit.ltc.reference.MASKINGS_FOR`, else a one-line ValueError) and the
    normal reflectances ``fit_f0``.  ``progress(done, total)`` after each
    roughness column.  Deterministic: the same arguments give the same table."""
    lobe_codes(distribution, masking)
    if clipping not in CLIPPINGS:
        raise ValueError(f"--clipping: choose one of {', '.join(CLIPPINGS)}, got {clipping!r}")
    fit_f0 = tuple(float(f) for f in fit_f0)
    if not fit_f0 or any(not 0.0 <= f <= 1.0 for f in fit_f0):
        raise ValueError(f"--fit-f0: normal reflectances in [0, 1], got {fit_f0}")
    t0 = time.perf_counter()
    n = int(n)
    ltc1 = np.zeros((n, n, 4))
    ltc2 = np.zeros((n, n, 4))
    error = np.zeros((n, n))
    all_corners = np.zeros((n, n, int(polygons), 4, 3))
    all_refs = np.zeros((n, n, int(polygons), 2))
    previous_column = None
    for a in range(n - 1, -1, -1):
        views = [cell_view(t, a, n) for t in range(n)]
        # the same draws in every cell: the lights move smoothly with (n.v, r), and so do the fitted entries
        corners = np.stack([np.ascontiguousarray(fit_lights(nov, r, polygons, int(seed)).corners, dtype=np.float64)
                            for nov, r in views])
        norms = albedos([v[0] for v in views], [v[1] for v in views], distribution, masking)
        refs = references([v[0] for v in views], [v[1] for v in views], corners, distribution, masking)
        all_corners[:, a] = corners
        all_refs[:, a] = refs
        for t in range(n):
            if t > 0:
                start = ltc1[t - 1, a]
            elif previous_column is not None:
                start = previous_column
            else:
                start = np.array([1.0, 0.0, 0.0, 1.0])  # r = 1 at normal incidence: close to the cosine
            texel, rms = fit_cell(views[t][0], start, corners[t], refs[t], (norms[t, 0], norms[t, 1]), fit_f0,
                                  clipping)
            ltc1[t, a] = texel
            ltc2[t, a, :2] = norms[t]
            error[t, a] = rms
        previous_column = ltc1[0, a]
        if progress is not None:
            progress(n - a, n)
    ltc2[..., 3] = sphere_form_factor_table(n)
    return LTCFit(ltc1.astype(np.float32), ltc2.astype(np.float32), error, time.perf_counter() - t0, polygons,
                  seed, all_corners, all_refs, distribution, masking, fit_f0, clipping)


def _clipped_cap_form_factor(sigma, cos_omega, nodes=96):
    """Form factor of a spherical cap of angular radius ``sigma`` centred at the
    angle omega from the normal, clipped at the horizon: the integral of
    max(0, z) / pi over the cap, by Gauss-Legendre quadrature in the cap's own
    polar coordinates (cos of the angle from the cap's centre, azimuth), with
    the clipped integrand continuous and the azimuthal kink handled by many
    nodes (converged to about 1e-7)."""
    from ..core.quadrature import gauss_legendre_01

    x, w = gauss_legendre_01(nodes)
    cos_s = math.cos(sigma)
    mu = cos_s + (1.0 - cos_s) * x  # cos of the angle from the cap's centre
    phi = 2.0 * math.pi * x
    sin_o = math.sqrt(max(0.0, 1.0 - cos_omega * cos_omega))
    sin_mu = np.sqrt(np.maximum(0.0, 1.0 - mu * mu))
    z = mu[:, None] * cos_omega + sin_mu[:, None] * np.cos(phi)[None, :] * sin_o
    return float((1.0 - cos_s) * 2.0 * math.pi * np.einsum("i,j,ij->", w, w, np.maximum(z, 0.0)) / math.pi)


def sphere_form_factor_table(n=64):
    """``ltc_2``'s fourth channel: the horizon-clipped form factor of a sphere
    from its vector form factor, divided by that vector's length, for shaders
    that clip by a table (ltc_code's ``ltc_quad.fs``: uv = (z / 2 + 1/2, |F|) at
    texel centres; Hill and Heitz 2016, "a Journey from Research to
    Production", p. 101): row j holds |F| = j / (N - 1) (= sin^2 sigma for a cap
    of angular radius sigma), column i holds z = cos omega = 2 i / (N - 1) - 1,
    the direction's height; the value is the clipped cap's form factor over
    |F| (:func:`_clipped_cap_form_factor`; for |F| -> 0 the limit max(z, 0))."""
    out = np.zeros((n, n))
    z = 2.0 * np.arange(n) / (n - 1.0) - 1.0
    for j in range(n):
        length = j / (n - 1.0)
        if length == 0.0:
            out[j] = np.maximum(z, 0.0)
            continue
        sigma = math.asin(math.sqrt(min(1.0, length)))
        for i in range(n):
            out[j, i] = _clipped_cap_form_factor(sigma, float(z[i])) / length
    return out
