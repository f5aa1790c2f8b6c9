"""Statistics of an LTC table against the ground truth on a set of lights: the
shader's radiance (:mod:`pbrkit.ltc.shader`) against the converged reference
(:mod:`pbrkit.ltc.reference`), relative and albedo-normalised errors and their
summary (:func:`score_table`), on one light set or on a mixed test set of
:mod:`pbrkit.ltc.lights` with an f0 per light (:func:`score_set`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .reference import directional_albedo, lobe_codes, lobe_rect_reference
from .shader import LTCTable, ltc_exact_rect, ltc_fresnel_rect, ltc_shader_rect, ltc_table_from_published_layout

__all__ = ["RELATIVE_THRESHOLD", "LTCScore", "score_table", "set_integrals", "score_set"]

#: Lights whose reference radiance is below this fraction of the directional
#: albedo E(mu, r) (same Fresnel) are left out of the *relative* errors (their
#: relative error measures nothing a viewer sees); the albedo-normalised
#: errors include every light.
RELATIVE_THRESHOLD = 1e-3


@dataclass
class LTCScore:
    """Per-light results of :func:`score_table` and their summary."""

    reference: np.ndarray
    ltc: np.ndarray
    albedo: np.ndarray
    relative: np.ndarray  # |ltc - ref| / ref, NaN where ref <= threshold * albedo
    absolute_over_albedo: np.ndarray  # |ltc - ref| / albedo, every light
    summary: dict = field(default_factory=dict)


def _summary(rel, abs_alb, ref, ltc, used):
    r = rel[used]
    return {
        "lights": int(rel.size),
        "scored": int(used.sum()),
        "relative_median": float(np.median(r)) if r.size else float("nan"),
        "relative_mean": float(np.mean(r)) if r.size else float("nan"),
        "relative_p95": float(np.percentile(r, 95)) if r.size else float("nan"),
        "relative_max": float(np.max(r)) if r.size else float("nan"),
        "ltc_zero_share": float(np.mean(ltc[used] <= 0.0)) if r.size else float("nan"),
        "abs_over_albedo_mean": float(np.mean(abs_alb)),
        "abs_over_albedo_median": float(np.median(abs_alb)),
        "abs_over_albedo_p95": float(np.percentile(abs_alb, 95)),
        "abs_over_albedo_max": float(np.max(abs_alb)),
    }


def score_table(ltc1, ltc2, lights, f0=1.0, reference=None, threshold=RELATIVE_THRESHOLD, evaluation="shader",
                distribution="ggx", masking="height-correlated", fresnel_ltc1=None):
    """Score LTC tables in the published layout on ``lights`` (:class:`~pbrkit.ltc.lights.RectLights`)
    with Schlick's F of ``f0`` (1: F = 1; a scalar or one per light): the shader's radiance
    (:func:`~pbrkit.ltc.shader.ltc_shader_rect`) against the converged reference of the lobe of
    ``distribution`` and ``masking`` (:func:`~pbrkit.ltc.reference.lobe_rect_reference`; pass
    ``reference`` (K,) to reuse one, computed for the same lobe).

    Per light: the relative error |ltc - ref| / ref, over the lights whose
    reference exceeds ``threshold`` times the directional albedo
    E(n.v, r) of the same lobe and f0 (:func:`~pbrkit.ltc.reference.directional_albedo`; NaN elsewhere), and
    the absolute error over that albedo, |ltc - ref| / E, over every light.
    ``summary``: the count scored, median, mean, 95th percentile and maximum
    of the relative errors (percentiles by linear interpolation, NumPy's
    default), the share of scored lights where the LTC is 0, and the mean,
    median, 95th percentile and maximum of the absolute errors over the
    albedo.  ``evaluation``: ``shader`` (:func:`~pbrkit.ltc.shader.ltc_shader_rect`, what engines run)
    or ``exact`` (:func:`~pbrkit.ltc.shader.ltc_exact_rect`); with ``fresnel_ltc1`` (the matrices of
    the f Fc lobe) ``exact`` is the Fresnel-aware :func:`~pbrkit.ltc.shader.ltc_fresnel_rect`.
    Returns :class:`LTCScore`."""
    table = ltc1 if isinstance(ltc1, LTCTable) else ltc_table_from_published_layout(ltc1, ltc2)
    lobe_codes(distribution, masking)
    if reference is None:
        reference = lobe_rect_reference(lights.nov, lights.roughness, lights.corners, f0, distribution, masking)
    reference = np.asarray(reference, dtype=float)
    if fresnel_ltc1 is not None:
        if evaluation != "exact":
            raise ValueError("the Fresnel-aware LTC is evaluated with the exact clipping (evaluation='exact')")
        ltc = ltc_fresnel_rect(table, None, fresnel_ltc1, lights.nov, lights.roughness, lights.corners, f0=f0)
    else:
        evaluate = ltc_exact_rect if evaluation == "exact" else ltc_shader_rect
        ltc = evaluate(table, None, lights.nov, lights.roughness, lights.corners, f0=f0)
    albedo = directional_albedo(lights.nov, lights.roughness, f0, distribution, masking)
    used = reference > threshold * albedo
    diff = np.abs(ltc - reference)
    rel = np.where(used, diff / np.where(used, reference, 1.0), np.nan)
    abs_alb = diff / albedo
    return LTCScore(reference, ltc, albedo, rel, abs_alb, _summary(rel, abs_alb, reference, ltc, used))


def set_integrals(spec, distribution="ggx", masking="height-correlated"):
    """The lights of the mixed test set ``spec`` (:func:`pbrkit.ltc.lights.test_set`:
    :data:`~pbrkit.ltc.lights.TUNING_SET`, :data:`~pbrkit.ltc.lights.REPORT_SET`),
    each light's f0 and the lights' converged (norm, fresnel) integrals
    (:func:`pbrkit.ltc.reference.lobe_rect_integrals`), to score several tables on
    one set: (lights, f0 (K,), pair (K, 2))."""
    from .lights import test_set
    from .reference import lobe_rect_integrals

    lights, f0 = test_set(spec)
    return lights, f0, lobe_rect_integrals(lights.nov, lights.roughness, lights.corners, distribution, masking)


def score_set(ltc1, ltc2, integrals, evaluation="shader", fresnel_ltc1=None, distribution="ggx",
              masking="height-correlated"):
    """:func:`score_table` on a mixed test set, ``integrals`` = (lights, f0, pair) of
    :func:`set_integrals`: each light with its own f0 (reference f0 norm + (1 - f0)
    fresnel), the summary over all of them pooled, and ``summary["by_f0"]`` the
    same summary over the lights of each f0 (keyed by f0).  Returns
    :class:`LTCScore`."""
    lights, f0, pair = integrals
    reference = f0 * pair[:, 0] + (1.0 - f0) * pair[:, 1]
    kwargs = {"evaluation": evaluation, "fresnel_ltc1": fresnel_ltc1, "distribution": distribution,
              "masking": masking}
    result = score_table(ltc1, ltc2, lights, f0=f0, reference=reference, **kwargs)
    by_f0 = {}
    for value in np.unique(f0):
        at = f0 == value
        used = ~np.isnan(result.relative[at])
        by_f0[float(value)] = _summary(result.relative[at], result.absolute_over_albedo[at], result.reference[at],
                                       result.ltc[at], used)
    result.summary["by_f0"] = by_f0
    return result
