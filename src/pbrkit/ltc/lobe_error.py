"""How far each cell's Linearly Transformed Cosine is from the BRDF lobe it
approximates: the *lobe error*, by Monte Carlo over the sphere.

Heitz, Dupuy, Hill and Neubelt 2016 ("Real-Time Polygonal-Light Shading with
Linearly Transformed Cosines", ACM TOG 35(4), sec. 4; ``ltc_code``
``fit/fitLTC.cpp`` ``computeError``) fit each cell's matrix by minimising the
L3 distance between the cosine-weighted lobe f(v, w) cos theta_w and the LTC
scaled by the lobe's norm, estimated from 32 x 32 samples drawn half from the
BRDF and half from the LTC, each divided by the sum of the two pdfs.  pbrkit's
fit minimises polygon-integral errors instead (:mod:`pbrkit.ltc.fit`), so this
module measures the lobe distance separately, for any table in the published
layout, with the same two-sided sampling idea:

    e = sqrt( integral over the sphere of (D(w) - f^(w))^2 dw
              / integral of f^(w)^2 dw ),   f^(w) = f(v, w) max(0, cos theta_w) / E(v),

the *relative L2 distance* between the LTC's distribution D (normalised over
the sphere; :func:`pbrkit.ltc.distribution.ltc_evaluate` with M^-1 from the
``ltc_1`` texel, :func:`pbrkit.ltc.distribution.inverse_from_texel`) and the
normalised lobe f^ (F = 1, so f^ also integrates to 1; E is the lobe's
directional albedo).  Why L2 and not Heitz's L3: relative to the lobe's own
L2 norm the distance is dimensionless and invariant under the lobe's scale
(D and f^ peak at about 1 / (pi alpha^2) per steradian, 3e5 at alpha = 1e-3 and
1/pi at alpha = 1), so cells of every roughness share one colour scale; 0 is a
perfect fit, and an LTC that does not overlap the lobe at all scores
sqrt(1 + |D|^2 / |f^|^2) >= 1; and under the mixture below (which holds a share
of D and of f^) the squared difference over the pdf is bounded by a multiple
of |D - f^|, of the order of the normaliser |f^|^2, so a few thousand samples
give each cell to well under 1%, where the cubed difference over the pdf grows
like the peak height squared.  The integral
is over the whole sphere: an LTC may put mass below the horizon, where the
lobe is 0 and a renderer loses it, and that counts as error.

The estimator draws, for every cell, the same deterministic scrambled Sobol
points (:class:`scipy.stats.qmc.Sobol` seeded by ``seed``; the same
numbers in every cell, so that the map varies smoothly from cell to cell)
from a defensive mixture of three parts, and divides each term by the
mixture's pdf (the balance heuristic of multiple importance sampling, Veach
1997 sec. 9.2):

- :data:`LOBE_SHARE` (half) of the samples from the lobe's own sampling
  routine, the one :func:`pbrkit.brdf.dispatch.sample_wi` runs for every
  ``cook_torrance`` lobe (and :func:`pbrkit.brdf.models.sample` exposes): the
  view reflected about a GGX visible normal (Heitz 2018;
  :func:`pbrkit.microfacet.ggx.warp_ggx_vndf`, ``reflect_xyz``), with its pdf
  D_v(h) / (4 v.h) (:func:`pbrkit.microfacet.ggx.pdf_ggx_vndf`,
  ``pdf_light_from_half``, as :func:`pbrkit.brdf.dispatch.bxdf_pdf`), composed
  here from the NumPy warps so that no sampling kernel needs compiling;
  where f^ is large;
- :data:`LTC_SHARE` from the LTC itself (:func:`pbrkit.ltc.distribution.ltc_sample`,
  pdf D), where D is large, also where a poor table puts its peak away from
  the lobe's or below the horizon (lobe samples alone would miss that mass);
- the rest (a quarter) uniform over the sphere
  (:func:`pbrkit.sampling.warps.warp_uniform_sphere`, pdf 1 / (4 pi)), the
  defensive part that bounds the ratio everywhere.

Checked against a composite Gauss-Legendre rule over the sphere
(``tests/ltc/test_ltc_lobe_error.py``): within 0.1% for fitted cells of alpha
0.016 to 0.51 and for the clamped cosine.

The lobe is pbrkit's own: ``cook_torrance`` with ``distribution`` and
``masking``, Fresnel and diffuse "none", white and metallic
(:func:`pbrkit.brdf.models.cook_torrance`, the composition the renderer and
:func:`pbrkit.ltc.reference.lobe_codes` use), in the local frame of
:mod:`pbrkit.ltc.distribution`: n = +z, v = (sin theta_v, 0, cos theta_v) on the
+x side.  The lobe is symmetric under y -> -y, so a left-handed frame
(three.js's) gives the same values.

Roughness remap and axes (those of :func:`pbrkit.ltc.fit.cell_view`, the fit's
and ltc_code's): column a holds perceptual roughness r = a / (N - 1) with
alpha = r^2 (:func:`pbrkit.microfacet.roughness.alpha_from_roughness`, clamped
at its ALPHA_MIN = 1e-3; GGX and Beckmann alike), row t holds
n.v = 1 - (t / (N - 1))^2, at most 89.95 degrees from the normal.  A table
fitted with another clamp shows it in its r = 0 column: the published table's
(three.js) texels there are about 100 times sharper than pbrkit's alpha = 1e-3
lobe (ltc_code clamps alpha at 1e-5), an error of about 100.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["LOBE_SHARE", "LTC_SHARE", "SAMPLES", "lobe_error", "lobe_error_map", "lobe_error_summary"]

#: Samples per cell of :func:`lobe_error_map` by default (a power of two): the
#: 64 x 64 map in about 2 s on 2 cores; the cells' relative standard deviation
#: over seeds is 0.2% (median) and at most about 1% already at 1024 samples.
SAMPLES = 2048
#: Share of each cell's samples drawn from the lobe's sampling routine (a power of
#: two, so that each part is a whole Sobol net).
LOBE_SHARE = 0.5
#: Share drawn from the LTC; the rest (1 - LOBE_SHARE - LTC_SHARE) is uniform over
#: the sphere.  Of the shares tried ((1/2, 1/4), (3/8, 3/8), (1/4, 1/2)) this has the
#: lowest variance, for fitted tables as for wrong ones.
LTC_SHARE = 0.25
#: Directions per block of work (cells x samples): bounds the memory of the arrays.
_BLOCK = 1 << 17


def _counts(samples):
    samples = int(samples)
    if samples < 16 or samples & (samples - 1):
        raise ValueError(f"samples must be a power of two, at least 16; got {samples}")
    n_lobe = round(LOBE_SHARE * samples)
    n_ltc = round(LTC_SHARE * samples)
    return n_lobe, n_ltc, samples - n_lobe - n_ltc


def _points(count, seed):
    """(count, 2) scrambled Sobol points in [0, 1), deterministic for ``seed``."""
    from scipy.stats import qmc

    m = max(1, math.ceil(math.log2(count)))
    return qmc.Sobol(2, scramble=True, seed=seed).random_base2(m)[:count]


def _sample_sets(samples, seed):
    """The uniform numbers of the three parts (lobe, LTC, sphere), each (n, 2)."""
    counts = _counts(samples)
    seeds = np.random.SeedSequence(int(seed)).spawn(3)
    return [_points(n, np.random.default_rng(s)) for n, s in zip(counts, seeds)]


def lobe_error(ltc1, nov, roughness, distribution="ggx", masking="height-correlated", samples=SAMPLES, seed=0,
               albedo=None):
    """The lobe error (module docstring: relative L2 distance between the LTC's D
    and the normalised lobe f cos / E, over the sphere, by Monte Carlo) of
    ``ltc_1`` texels ``ltc1`` (C, 4) (the published layout's (m00, m20, m02,
    m22) / m11 of M^-1) for cells of view ``nov`` (C,) (n.v in (0, 1]) and
    perceptual ``roughness`` (C,) (alpha = r^2, clamped at 1e-3), against
    ``cook_torrance`` with ``distribution`` and ``masking`` (F = 1) -> (C,).

    ``samples`` per cell (a power of two), from the Sobol points of ``seed``
    (the same in every cell; the result is deterministic).  ``albedo`` (C,):
    the lobe's directional albedo E with F = 1 (e.g. a fitted table's
    ``ltc_2`` norm); by default the converged one
    (:func:`pbrkit.ltc.reference.directional_albedo`)."""
    from ..brdf.material import Material
    from ..brdf.models import cook_torrance
    from ..microfacet.ggx import pdf_ggx_vndf, warp_ggx_vndf
    from ..microfacet.roughness import alpha_from_roughness
    from ..sampling.warps import pdf_light_from_half, reflect_xyz, warp_uniform_sphere
    from .distribution import inverse_from_texel, ltc_evaluate, ltc_sample
    from .reference import directional_albedo, lobe_codes

    lobe_codes(distribution, masking)
    texels = np.asarray(ltc1, dtype=np.float64).reshape(-1, 4)
    nov = np.asarray(nov, dtype=np.float64).reshape(-1)
    roughness = np.asarray(roughness, dtype=np.float64).reshape(-1)
    cells = texels.shape[0]
    if nov.shape != (cells,) or roughness.shape != (cells,):
        raise ValueError(f"nov and roughness must have one value per texel ({cells}); got {nov.shape}, "
                         f"{roughness.shape}")
    if not (np.all(np.isfinite(texels)) and np.all(np.isfinite(nov)) and np.all(np.isfinite(roughness))):
        raise ValueError("texels, n.v and roughness must be finite")
    if np.any((nov <= 0.0) | (nov > 1.0)) or np.any((roughness < 0.0) | (roughness > 1.0)):
        raise ValueError("n.v must be in (0, 1] and roughness in [0, 1]")
    if albedo is None:
        albedo = directional_albedo(nov, roughness, 1.0, distribution, masking)
    albedo = np.broadcast_to(np.asarray(albedo, dtype=np.float64).reshape(-1), (cells,))
    if not np.all(albedo > 0.0):
        raise ValueError("the lobe's albedo must be positive")

    m_inv = inverse_from_texel(texels)
    if np.any(np.linalg.det(m_inv) == 0.0):
        raise ValueError("every ltc_1 texel must describe an invertible matrix (x w != y z)")
    m = np.linalg.inv(m_inv)
    u_lobe, u_ltc, u_sphere = _sample_sets(samples, seed)
    n_lobe, n_ltc, n_sphere = len(u_lobe), len(u_ltc), len(u_sphere)
    total = n_lobe + n_ltc + n_sphere
    c_lobe, c_ltc, c_sphere = n_lobe / total, n_ltc / total, n_sphere / total
    sphere = np.stack(warp_uniform_sphere(u_sphere[:, 0], u_sphere[:, 1]), axis=-1)
    normal = np.array([0.0, 0.0, 1.0])
    terms = {"distribution": distribution, "masking": masking, "fresnel": "none", "diffuse": "none"}
    out = np.empty(cells)
    step = max(1, _BLOCK // total)
    for start in range(0, cells, step):
        s = slice(start, min(cells, start + step))
        k = s.stop - s.start
        c = nov[s, None]
        v = np.zeros((k, 1, 3))
        v[:, 0, 0] = np.sqrt(np.maximum(0.0, 1.0 - c[:, 0] ** 2))
        v[:, 0, 2] = c[:, 0]
        alpha = alpha_from_roughness(roughness[s, None])
        material = Material(base_color=np.ones(3), metallic=1.0, roughness=roughness[s, None])
        # the lobe's sampling routine (pbrkit.brdf.dispatch.sample_wi for every cook_torrance lobe): the view
        # reflected about a GGX visible normal (Heitz 2018); a direction below the horizon is a failed sample
        h = warp_ggx_vndf(u_lobe[:, 0], u_lobe[:, 1], v[..., 0], 0.0, c, alpha)
        wi = np.stack(reflect_xyz(v[..., 0], 0.0, c, *h), axis=-1)
        wi /= np.linalg.norm(wi, axis=-1, keepdims=True)
        failed = wi[..., 2] <= 0.0
        wi[failed] = normal
        w_ltc = ltc_sample(m[s, None], u_ltc[:, 0], u_ltc[:, 1])
        w = np.concatenate([wi, w_ltc, np.broadcast_to(sphere, (k, n_sphere, 3))], axis=1)
        d = ltc_evaluate(m_inv[s, None], w)
        f = cook_torrance(w, v, normal, material, **terms)[..., 0]
        lobe = f * np.maximum(w[..., 2], 0.0) / albedo[s, None]
        # its pdf (pbrkit.brdf.dispatch.bxdf_pdf): D_v(h) / (4 v.h) at the half vector, 0 below the horizon
        half = w + v
        half /= np.maximum(np.linalg.norm(half, axis=-1, keepdims=True), 1e-300)
        voh = np.maximum(np.sum(half * v, axis=-1), 0.0)
        p_lobe = np.where(w[..., 2] > 0.0, pdf_light_from_half(pdf_ggx_vndf(c, half[..., 2], voh, alpha), voh), 0.0)
        p = c_lobe * p_lobe + c_ltc * d + c_sphere / (4.0 * math.pi)
        keep = np.ones(w.shape[:2], dtype=bool)
        keep[:, :n_lobe] = ~failed
        inv_p = np.where(keep & (p > 0.0), 1.0 / np.where(p > 0.0, p, 1.0), 0.0)
        num = np.sum((d - lobe) ** 2 * inv_p, axis=1)
        den = np.sum(lobe * lobe * inv_p, axis=1)
        out[s] = np.sqrt(num / den)
    return out


def lobe_error_map(ltc1, distribution="ggx", masking="height-correlated", samples=SAMPLES, seed=0, albedo=None):
    """The per-cell lobe error (:func:`lobe_error`; module docstring) of an N x N
    ``ltc_1`` table (N, N, 4) in the published layout, indexed [t, a]: row t at
    n.v = 1 - (t / (N - 1))^2 (at most 89.95 degrees), column a at perceptual
    roughness r = a / (N - 1), alpha = r^2 (:func:`pbrkit.ltc.fit.cell_view`),
    against ``cook_torrance`` with ``distribution`` and ``masking`` (F = 1)
    -> (N, N) float64.  ``albedo`` (N, N): the lobe's directional albedo
    per cell (a fitted table's ``ltc_2[..., 0]``), else the converged one.
    Deterministic: the same inputs give the same values."""
    from .fit import cell_view

    table = np.asarray(ltc1, dtype=np.float64)
    if table.ndim != 3 or table.shape[0] != table.shape[1] or table.shape[2] != 4 or table.shape[0] < 2:
        raise ValueError(f"ltc1 must be an (N, N, 4) table with N >= 2; got {table.shape}")
    n = table.shape[0]
    views = np.array([cell_view(t, a, n) for t in range(n) for a in range(n)])
    if albedo is not None:
        albedo = np.asarray(albedo, dtype=np.float64)
        if albedo.shape != (n, n):
            raise ValueError(f"albedo must have shape ({n}, {n}); got {albedo.shape}")
    error = lobe_error(table.reshape(-1, 4), views[:, 0], views[:, 1], distribution, masking, samples, seed,
                       None if albedo is None else albedo.reshape(-1))
    return error.reshape(n, n)


def lobe_error_summary(error):
    """{"median", "p95", "max"} of a lobe-error map (rounded to 6 digits)."""
    e = np.asarray(error, dtype=np.float64)
    return {"median": round(float(np.median(e)), 6), "p95": round(float(np.percentile(e, 95)), 6),
            "max": round(float(np.max(e)), 6)}
