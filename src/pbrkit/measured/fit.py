"""Fitting pbrkit's models to a measured BRDF by weighted least squares.

After Ngan, Durand and Matusik, "Experimental Analysis of BRDF Models"
(EGSR 2005): the model's parameters minimise the weighted squared difference
to the measured MERL values over the measured bins, optionally cut at a
maximum incidence / view angle (they cut at 80 degrees).  Two objectives:

- ``"log"``: residuals log(1 + f_model cos theta_l) - log(1 + f cos theta_l)
  (the compressed metric of Löw, Kronander, Ynnerman and Unger, "BRDF Models
  for Accurate and Efficient Rendering of Glossy Surfaces", ACM TOG 31(1), 2012),
  which keeps the specular peak from dominating;
- ``"cosine"``: residuals f_model cos theta_l - f cos theta_l (Ngan et al.'s
  cosine-weighted values).

Each bin is weighted by its share of the measure of direction pairs,
d omega_l d omega_v = 4 cos theta_d d omega_h d omega_d (Rusinkiewicz 1998), i.e.
4 cos theta_d sin theta_d sin theta_h times the bin's extent in (theta_h,
theta_d, phi_d), so that the sums approximate integrals over the hemisphere
pairs despite MERL's non-uniform theta_h bins.  The fit uses a fixed
stratified subset of the valid bins (an equal number per theta_h row, drawn
with NumPy's PCG64 from ``seed``; each weighted by its row's valid count over
the chosen count) and is solved by SciPy's bounded trust-region reflective
``least_squares`` (forward-difference Jacobian, its parameter vectors
evaluated in one batch of the compiled model) from the best start of a
roughness grid whose linear parameters are solved exactly (bounded linear
least squares).  The reported error is taken over *every* valid bin (within
``max_theta``), measure-weighted.  The same measured data, options and seed
give the same result.

Without ``max_theta`` the cosine-weighted objective reaches the horizon, where
f of a mismatched masking term grows like 1 / cos theta_v and the squared
error has no finite integral: the bins nearest the horizon then dominate the
``cosine`` fit and its ``relative_l2`` (as do the noisy grazing measurements of
the database).  Ngan et al.'s cut, ``max_theta=80``, avoids both.

Models (alpha = r^2 for perceptual roughness r, clamped at
:data:`pbrkit.microfacet.roughness.ALPHA_MIN`):

- ``"ggx"``: Lambert diffuse with an RGB albedo (``diffuse``) plus the GGX
  microfacet lobe D V with height-correlated Smith masking
  (:func:`pbrkit.brdf.models.cook_torrance`, Walter et al. 2007, Heitz 2014)
  times, with ``fresnel``, Schlick's F with an RGB f0 (``specular``; the
  lobe is cook_torrance of a metallic material whose base colour is f0), and
  without it a constant RGB scale (``specular``; cook_torrance with
  ``fresnel="none"``); one roughness.  Parameters: ``diffuse`` [r, g, b] in
  [0, 1], ``specular`` [r, g, b] (f0 in [0, 1], or a scale >= 0),
  ``roughness``.
- ``"disney"``: :func:`pbrkit.brdf.models.disney` (Burley 2012) with
  ``base_color``, ``metallic``, ``roughness``, ``specular`` (Disney's, f0 =
  0.08 specular; :meth:`pbrkit.Material.from_ue4`), ``sheen``,
  ``clearcoat``, ``clearcoat_gloss`` and ``subsurface`` fitted, each in
  [0, 1]; ``specular_tint`` 0 and ``sheen_tint`` 0.5 held (:data:`DISNEY_FIXED`:
  with the tints free, different parameter sets give the same BRDF).  Its
  Schlick Fresnel is part of the model: ``fresnel=False`` is refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..brdf import models
from ..brdf.diffuse import lambert
from ..brdf.material import Material
from ..microfacet.roughness import ALPHA_MIN
from .merl import MERL_SHAPE, MerlBRDF, merl_bin_centres, merl_directions

__all__ = ["FIT_MAX_THETA", "FIT_MODELS", "FIT_WEIGHTINGS", "FitResult", "fit_measured", "bin_measure", "fit_samples",
           "ggx_model", "disney_material", "DISNEY_PARAMETERS", "DISNEY_FIXED"]

#: Ngan, Durand & Matusik 2005's cut (degrees): fits leave out directions beyond it.
FIT_MAX_THETA = 80.0
FIT_MODELS = ("ggx", "disney")
FIT_WEIGHTINGS = ("log", "cosine")
#: The Disney parameters fitted, in the order of the parameter vector (base_color takes three).
DISNEY_PARAMETERS = ("base_color", "metallic", "roughness", "specular", "sheen", "clearcoat", "clearcoat_gloss",
                     "subsurface")
#: Disney parameters held at these values (reported with the fitted ones): the tints make the fit
#: degenerate (specular_tint trades against metallic and specular for the same f0 and diffuse colours).
DISNEY_FIXED = {"specular_tint": 0.0, "sheen_tint": 0.5}
#: Bins drawn for the fit (an equal share per theta_h row).
FIT_SAMPLES = 24000
_ROUGHNESS_MIN = math.sqrt(ALPHA_MIN)
_ROUGHNESS_GRID = (0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.75, 0.9)
_Z = np.array([0.0, 0.0, 1.0])


# ------------------------------------------------------------------ the models


def _above(l, v, n):
    return (np.sum(n * l, axis=-1) > 0.0) & (np.sum(n * v, axis=-1) > 0.0)


def ggx_model(l, v, n, diffuse, specular, roughness, fresnel=True):
    """f (..., 3) of the ``"ggx"`` fit model (module doc): diffuse / pi (Lambert,
    :func:`pbrkit.brdf.diffuse.lambert`) plus :func:`pbrkit.brdf.models.cook_torrance`
    with GGX, height-correlated Smith and either Schlick's F of f0 = ``specular``
    (a metallic material whose base colour is f0) or F = 1 times the RGB scale
    ``specular``; alpha = roughness^2."""
    l, v, n = (np.asarray(x, dtype=np.float64) for x in (l, v, n))
    diffuse = np.asarray(diffuse, dtype=np.float64)
    specular = np.asarray(specular, dtype=np.float64)
    if fresnel:
        lobe = models.cook_torrance(l, v, n, Material(base_color=specular, metallic=1.0, roughness=roughness),
                                    distribution="ggx", masking="height-correlated", fresnel="schlick",
                                    diffuse="none")
    else:
        lobe = specular * models.cook_torrance(l, v, n, Material(base_color=[1.0, 1.0, 1.0], metallic=1.0,
                                                                 roughness=roughness),
                                               distribution="ggx", masking="height-correlated", fresnel="none",
                                               diffuse="none")
    nol = np.sum(n * l, axis=-1)
    lam = np.where(_above(l, v, n), lambert(nol), 0.0)
    return lam[..., None] * diffuse + lobe


def disney_material(parameters) -> Material:
    """The :class:`pbrkit.Material` of Disney fit parameters (a dict with the keys of
    :data:`DISNEY_PARAMETERS` and :data:`DISNEY_FIXED`; Disney's ``specular`` s gives f0 = 0.08 s)."""
    p = dict(parameters)
    return Material.from_ue4(base_color=p["base_color"], metallic=p["metallic"], roughness=p["roughness"],
                             specular=p["specular"], specular_tint=p["specular_tint"], sheen=p["sheen"],
                             sheen_tint=p["sheen_tint"], clearcoat=p["clearcoat"],
                             clearcoat_gloss=p["clearcoat_gloss"], subsurface=p["subsurface"])


# ------------------------------------------------------------------ the result


@dataclass(frozen=True)
class FitResult:
    """A model fitted to a measured BRDF.

    ``parameters``: for ``"ggx"`` {"diffuse": [r, g, b], "specular": [r, g, b]
    (f0 with Fresnel, else the scale), "roughness": r}; for ``"disney"`` the keys
    of :data:`DISNEY_PARAMETERS` and :data:`DISNEY_FIXED`.  ``error`` (over every
    valid bin within ``max_theta``, each weighted by its measure, module doc; f_m the model, f the
    measurement, c = cos theta_l, summed over the three channels):
    ``rms_log`` = sqrt(sum w (log(1 + f_m c) - log(1 + f c))^2 / (3 sum w)),
    ``rms_cosine`` = sqrt(sum w (f_m c - f c)^2 / (3 sum w)),
    ``relative_l2`` = sqrt(sum w (f_m c - f c)^2 / sum w (f c)^2), and ``bins``,
    their count.  ``samples``: bins in the fit; ``evaluations``: model
    evaluations (batches) of the fit; ``max_theta`` in degrees or None;
    ``name``: the measured material's."""

    model: str
    fresnel: bool
    weighting: str
    parameters: dict
    error: dict
    samples: int = 0
    evaluations: int = 0
    max_theta: float | None = None
    name: str = field(default="")

    def evaluate(self, l, v, n=None) -> np.ndarray:
        """f (..., 3) (not f cos) of the fitted model for unit directions l, v about n
        (default +z, the local frame, as :meth:`pbrkit.measured.merl.MerlBRDF.evaluate`)."""
        n = _Z if n is None else np.asarray(n, dtype=np.float64)
        p = self.parameters
        if self.model == "ggx":
            return ggx_model(l, v, n, p["diffuse"], p["specular"], p["roughness"], self.fresnel)
        return models.disney(l, v, n, disney_material(p))

    def material(self) -> Material:
        """The fitted :class:`pbrkit.Material` of a ``"disney"`` fit (for the renderer's
        ``disney`` model).  A ``"ggx"`` fit has independent RGB diffuse and specular
        colours, which one metallic-roughness material cannot hold: ValueError."""
        if self.model != "disney":
            raise ValueError("only a 'disney' fit is a metallic-roughness Material; use FitResult.evaluate")
        return disney_material(self.parameters)


# ------------------------------------------------------------------ the bins


def bin_measure():
    """Float64 (90, 90, 180): the measure of the direction pairs (l, v) each MERL bin
    stands for, d omega_l d omega_v = 4 cos theta_d d omega_h d omega_d
    (Rusinkiewicz 1998) at the bin's centre: 4 cos theta_d sin theta_d sin theta_h
    d theta_h d theta_d d phi_d d phi_h with d theta_h = pi (i + 0.5) / 90^2 (the
    derivative of ((i + 0.5) / 90)^2 pi/2 per index), d theta_d = pi / 180,
    d phi_d = 2 pi / 180 (a stored bin also holds phi_d + pi) and 2 pi for phi_h
    (isotropy).  Summed over the bins whose centre pair is above the horizon it
    approximates (2 pi)^2, the measure of pairs of upper-hemisphere directions."""
    nh, nd, npd = MERL_SHAPE
    theta_h, theta_d, _ = merl_bin_centres()
    d_theta_h = math.pi * (np.arange(nh) + 0.5) / (nh * nh)
    wh = np.sin(theta_h) * d_theta_h
    wd = 4.0 * np.cos(theta_d) * np.sin(theta_d) * (0.5 * math.pi / nd)
    d_phi = 2.0 * math.pi / npd
    return np.broadcast_to((wh[:, None] * wd[None, :])[:, :, None] * (d_phi * 2.0 * math.pi), MERL_SHAPE).copy()


def _usable_bins(measured: MerlBRDF, max_theta):
    l, v = merl_directions()
    mask = measured.valid & (l[..., 2] > 0.0) & (v[..., 2] > 0.0)
    if max_theta is not None:
        c = math.cos(math.radians(max_theta))
        mask &= (l[..., 2] >= c) & (v[..., 2] >= c)
    return mask, l, v


def fit_samples(mask, count=FIT_SAMPLES, seed=0):
    """A fixed stratified subset of the True bins of ``mask`` (90, 90, 180): up to
    ceil(count / 90) per theta_h row, drawn without replacement by
    ``numpy.random.default_rng(seed)``.  Returns (flat indices (N,) sorted, weights
    (N,): each row's True count over its chosen count)."""
    rng = np.random.default_rng(seed)
    per_row = -(-count // MERL_SHAPE[0])
    flat = mask.reshape(MERL_SHAPE[0], -1)
    row_size = flat.shape[1]
    chosen, weights = [], []
    for i in range(MERL_SHAPE[0]):
        candidates = np.flatnonzero(flat[i])
        if candidates.size == 0:
            continue
        take = min(per_row, candidates.size)
        pick = np.sort(rng.choice(candidates, size=take, replace=False))
        chosen.append(i * row_size + pick)
        weights.append(np.full(take, candidates.size / take))
    if not chosen:
        return np.zeros(0, dtype=np.int64), np.zeros(0)
    return np.concatenate(chosen), np.concatenate(weights)


# ------------------------------------------------------------------ the fit


class _Problem:
    """The data of one fit: directions, measured f cos and weights of the chosen bins."""

    def __init__(self, l, v, f, weight, weighting):
        self.l = l
        self.v = v
        self.cos = np.maximum(l[:, 2], 0.0)
        self.target = f * self.cos[:, None]
        self.sqrt_w = np.sqrt(weight / weight.sum())[:, None]
        self.weighting = weighting
        self.evaluations = 0
        if weighting == "log":
            self.target_t = np.log1p(self.target)

    def residuals(self, f_model):
        """Weighted residuals (..., 3 N) of model values f (..., N, 3)."""
        self.evaluations += 1
        m = f_model * self.cos[:, None]
        if self.weighting == "log":
            r = np.log1p(np.maximum(m, 0.0)) - self.target_t
        else:
            r = m - self.target
        r = self.sqrt_w * r
        return r.reshape(r.shape[:-2] + (-1,))


def _solve(problem, values, x0, lower, upper):
    """Bounded trust-region reflective least squares (SciPy ``least_squares``) of the
    residuals of ``values(X)`` (f (k, N, 3) for k parameter vectors X (k, n)), with a
    forward-difference Jacobian (steps sqrt(eps) max(1, |x|), backward at an upper
    bound) whose n + 1 parameter vectors are evaluated in one batch."""
    from scipy.optimize import least_squares

    step = math.sqrt(np.finfo(float).eps)

    def residual(x):
        return problem.residuals(values(x[None, :]))[0]

    def jacobian(x):
        h = step * np.maximum(1.0, np.abs(x))
        h = np.where(x + h <= upper, h, -h)
        batch = np.vstack([x, x + np.diag(h)])
        r = problem.residuals(values(batch))
        return ((r[1:] - r[0]) / h[:, None]).T

    sol = least_squares(residual, np.clip(x0, lower, upper), jac=jacobian, bounds=(lower, upper), method="trf",
                        x_scale="jac", xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=200)
    return sol.x


def _lsq_linear_init(problem, roughness, fresnel):
    """Best diffuse and specular (per channel, bounded linear least squares) of the GGX
    model at a fixed roughness, on f cos weighted for the chosen objective (for
    ``log`` by 1 / (1 + f cos), the derivative of log(1 + x)); the basis lobes are
    cook_torrance with f0 = 0 and f0 = 1 (Schlick's F is linear in f0)."""
    from scipy.optimize import lsq_linear

    l, v = problem.l, problem.v
    zero = ggx_model(l, v, _Z, [0.0] * 3, [0.0] * 3, roughness, True)[:, 0]
    one = ggx_model(l, v, _Z, [0.0] * 3, [1.0] * 3, roughness, fresnel)[:, 0]
    lam = np.where(_above(l, v, _Z), lambert(l[:, 2]), 0.0)
    if fresnel:
        basis_spec, offset = one - zero, zero
        upper = 1.0
    else:
        basis_spec, offset = one, np.zeros_like(one)
        upper = np.inf
    c = problem.cos
    diffuse, specular = [], []
    for ch in range(3):
        y = problem.target[:, ch]
        w = problem.sqrt_w[:, 0] * (1.0 / (1.0 + y) if problem.weighting == "log" else 1.0)
        a = np.stack([lam * c * w, basis_spec * c * w], axis=1)
        sol = lsq_linear(a, (y - offset * c) * w, bounds=([0.0, 0.0], [1.0, upper]), method="bvls")
        diffuse.append(sol.x[0])
        specular.append(sol.x[1])
    return np.array(diffuse), np.array(specular)


def _fit_ggx(problem, fresnel):
    def values(batch):
        return ggx_model(problem.l, problem.v, _Z, batch[:, None, 0:3], batch[:, None, 3:6], batch[:, 6:7], fresnel)

    starts = []
    for r in _ROUGHNESS_GRID:
        d, s = _lsq_linear_init(problem, r, fresnel)
        x = np.concatenate([d, s, [r]])
        starts.append((float(np.sum(problem.residuals(values(x[None, :])) ** 2)), x))
    x0 = min(starts, key=lambda t: t[0])[1]
    lower = np.array([0.0] * 6 + [_ROUGHNESS_MIN])
    upper = np.array([1.0] * 3 + [1.0 if fresnel else np.inf] * 3 + [1.0])
    x = _solve(problem, values, x0, lower, upper)
    return {"diffuse": [float(c) for c in x[0:3]], "specular": [float(c) for c in x[3:6]], "roughness": float(x[6])}


def _disney_parameters(x):
    p = {"base_color": [float(c) for c in x[0:3]]}
    p.update(zip(DISNEY_PARAMETERS[1:], (float(value) for value in x[3:])))
    p.update(DISNEY_FIXED)
    return p


def _disney_batch(batch):
    """The Material of Disney parameter vectors (k, 11) (:data:`DISNEY_PARAMETERS`), fields (k, 1)."""
    fields = {name: batch[:, 2 + i:3 + i] for i, name in enumerate(DISNEY_PARAMETERS) if i > 0}
    return Material.from_ue4(base_color=batch[:, None, 0:3], **fields, **DISNEY_FIXED)


def _fit_disney(problem):
    def values(batch):
        return models.disney(problem.l, problem.v, _Z, _disney_batch(batch))

    # the start: the best GGX grid start (roughness r, diffuse d, f0 s) read as Disney parameters with
    # Disney's default specular 0.5 (f0 = 0.04): the metallic m on a grid that best explains
    # diffuse = base (1 - m), f0 = 0.04 (1 - m) + base m, then base = d / (1 - m) (or s for a metal)
    best = None
    for r in _ROUGHNESS_GRID:
        d, s = _lsq_linear_init(problem, r, True)
        cost = float(np.sum(problem.residuals(ggx_model(problem.l, problem.v, _Z, d, s, r, True)) ** 2))
        if best is None or cost < best[0]:
            best = (cost, d, s, r)
    _, d, s, r = best
    candidates = []
    for m in np.linspace(0.0, 1.0, 21):
        base = np.clip(s if m == 1.0 else d / (1.0 - m), 0.0, 1.0)
        predicted = np.concatenate([base * (1.0 - m), 0.04 * (1.0 - m) + base * m])
        candidates.append((float(np.sum((predicted - np.concatenate([d, s])) ** 2)), m, base))
    _, metallic, base = min(candidates, key=lambda t: t[0])
    size = 2 + len(DISNEY_PARAMETERS)
    lower, upper = np.zeros(size), np.ones(size)
    rest = {"metallic": metallic, "roughness": max(r, _ROUGHNESS_MIN), "specular": 0.5, "clearcoat_gloss": 1.0}
    x0 = np.concatenate([base, [rest.get(name, 0.0) for name in DISNEY_PARAMETERS[1:]]])
    return _disney_parameters(_solve(problem, values, x0, lower, upper))


def _errors(result: FitResult, measured: MerlBRDF, mask, l, v):
    w = bin_measure()[mask]
    lm, vm = l[mask], v[mask]
    f = np.moveaxis(measured.table[:, mask], 0, -1)
    fm = result.evaluate(lm, vm)
    c = lm[:, 2][:, None]
    x, m = f * c, fm * c
    wsum = w.sum()
    diff2 = np.sum((m - x) ** 2, axis=1)
    log2 = np.sum((np.log1p(np.maximum(m, 0.0)) - np.log1p(x)) ** 2, axis=1)
    ref2 = np.sum(x * x, axis=1)
    return {
        "rms_log": float(np.sqrt(np.sum(w * log2) / (3.0 * wsum))),
        "rms_cosine": float(np.sqrt(np.sum(w * diff2) / (3.0 * wsum))),
        "relative_l2": float(np.sqrt(np.sum(w * diff2) / np.sum(w * ref2))),
        "bins": int(mask.sum()),
    }


def fit_measured(measured: MerlBRDF, model="ggx", fresnel=True, weighting="log", *, max_theta=None,
                 seed=0, samples=FIT_SAMPLES) -> FitResult:
    """Fit ``model`` (:data:`FIT_MODELS`) to a measured BRDF by weighted least
    squares with the objective ``weighting`` (:data:`FIT_WEIGHTINGS`), over the
    valid bins whose l and v are within ``max_theta`` degrees of the normal (all
    above the horizon when None); ``seed`` draws the stratified subset of about
    ``samples`` bins (module doc).  Returns a :class:`FitResult` with the parameters and the fit error."""
    if model not in FIT_MODELS:
        raise ValueError(f"unknown fit model {model!r}; choose one of {', '.join(FIT_MODELS)}")
    if weighting not in FIT_WEIGHTINGS:
        raise ValueError(f"unknown weighting {weighting!r}; choose one of {', '.join(FIT_WEIGHTINGS)}")
    if model == "disney" and not fresnel:
        raise ValueError("disney: its Schlick Fresnel is part of the model; fresnel=False is for 'ggx' only")
    if max_theta is not None and not (0.0 < float(max_theta) <= 90.0):
        raise ValueError(f"max_theta must be in (0, 90] degrees; got {max_theta!r}")
    if int(samples) < 90:
        raise ValueError(f"samples must be at least 90 (one per theta_h row); got {samples!r}")
    if not isinstance(measured, MerlBRDF):
        raise TypeError("fit_measured: measured must be a MerlBRDF (pbrkit.measured.read_merl)")
    mask, l, v = _usable_bins(measured, max_theta)
    index, stratum = fit_samples(mask, int(samples), seed)
    if index.size < 16:
        raise ValueError(f"{measured.name}: only {index.size} valid bins to fit")
    flat_l, flat_v = l.reshape(-1, 3)[index], v.reshape(-1, 3)[index]
    f = measured.table.reshape(3, -1)[:, index].T
    weight = bin_measure().reshape(-1)[index] * stratum
    problem = _Problem(flat_l, flat_v, f, weight, weighting)
    parameters = _fit_ggx(problem, fresnel) if model == "ggx" else _fit_disney(problem)
    result = FitResult(model, bool(fresnel), weighting, parameters, {}, int(index.size), problem.evaluations,
                       None if max_theta is None else float(max_theta), measured.name)
    return FitResult(model, bool(fresnel), weighting, parameters, _errors(result, measured, mask, l, v),
                     result.samples, result.evaluations, result.max_theta, measured.name)
