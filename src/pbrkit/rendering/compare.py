"""Comparing a real-time image with its ground truth: relative errors, FLIP and heat maps.

The plain relative luminance error |Y - Y_ref| / Y_ref is dominated by dark pixels on
real assets (a shadowed crevice at 1 % of the mean luminance turns a small absolute
difference into errors of several hundred per cent), so a comparison also reports it
against a luminance floor: |Y - Y_ref| / max(Y_ref, f), f = :data:`FLOOR_FRACTION` of
the mean reference luminance of the surface pixels (the floor is stated beside the
figures), with its mean, median and 90th percentile, and HDR-FLIP of the whole images;
the heat map shows the floored error.
"""

from __future__ import annotations

import numpy as np

from ..core.color import luminance

__all__ = [
    "FLOOR_FRACTION",
    "HEATMAP_SCALE",
    "compare_images",
    "relative_error_pixels",
    "rms_relative_error",
    "error_heatmap",
]

# ================================================================== compare

#: The luminance floor of the floored relative error, as a fraction of the mean reference
#: luminance over the surface pixels (module docstring).
FLOOR_FRACTION = 0.1
#: The floored relative error at the top of the heat map's colour scale.
HEATMAP_SCALE = 0.2


def relative_error_pixels(reference, mask):
    """The pixels a comparison measures: ``mask`` where the reference luminance is
    above 1e-3 of its mean over ``mask`` (relative errors of black pixels mean nothing)."""
    y_ref = luminance(reference)
    floor = 1e-3 * max(float(y_ref[mask].mean()) if mask.any() else 0.0, 1e-12)
    return mask & (y_ref > floor)


def rms_relative_error(image, reference, valid, stderr=None, baseline=None):
    """Root-mean-square relative luminance difference sqrt(mean(((Y - Y_b) / Y_ref)^2))
    over the pixels ``valid``, against ``baseline`` (Y_b; default the reference
    itself).  With the reference's per-pixel standard error ``stderr`` (for a
    difference against the reference) its variance is subtracted first,
    sqrt(max(mean((d^2 - se^2) / Y_ref^2), 0)): E[d^2] = bias^2 + se^2 for an
    unbiased reference, so this estimates the error of ``image`` against the
    noise-free ground truth (what the approximations cost), not the Monte Carlo
    noise."""
    if not valid.any():
        return 0.0
    y_ref = luminance(reference)[valid]
    y_base = y_ref if baseline is None else luminance(baseline)[valid]
    d2 = (luminance(image)[valid] - y_base) ** 2
    if stderr is not None:
        d2 = d2 - luminance(stderr)[valid] ** 2
    return float(np.sqrt(max(float(np.mean(d2 / (y_ref * y_ref))), 0.0)))


def compare_images(realtime, reference, mask, stderr=None, flip=True):
    """Errors of ``realtime`` against ``reference`` (H, W, 3) over the surface pixels
    ``mask`` with a reference luminance above 1e-3 of its mean
    (:func:`relative_error_pixels`): the relative luminance error
    |Y_rt - Y_ref| / Y_ref, its mean and maximum; the RMS relative error and, given
    the reference's standard error ``stderr``, the RMS relative error with the
    reference's variance removed (:func:`rms_relative_error`: the approximation
    error without the Monte Carlo noise) and the mean standard error relative to
    Y_ref (the noise floor); and HDR-FLIP (Andersson et al., "FLIP: A Difference
    Evaluator for Alternating Images", HPG 2020; HDR-FLIP, 2021) of the whole
    images via the ``flip-evaluator`` package; the floored relative error (module
    docstring) over ``mask``, its mean, median and 90th percentile, and the floor.  The
    maps (``relative_error_map``, ``floored_error_map``) are 0 outside the pixels each
    measures."""
    y_rt = luminance(realtime)
    y_ref = luminance(reference)
    valid = relative_error_pixels(reference, mask)
    rel = np.zeros(y_ref.shape)
    rel[valid] = np.abs(y_rt[valid] - y_ref[valid]) / y_ref[valid]
    floor = FLOOR_FRACTION * (float(y_ref[mask].mean()) if mask.any() else 0.0)
    floored = np.zeros(y_ref.shape)
    floored[mask] = np.abs(y_rt[mask] - y_ref[mask]) / np.maximum(y_ref[mask], max(floor, 1e-300))

    def stats(x):
        return (float(x.mean()), float(np.median(x)), float(np.percentile(x, 90))) if x.size else (0.0, 0.0, 0.0)

    mean, median, p90 = stats(rel[valid])
    f_mean, f_median, f_p90 = stats(floored[mask])
    out = {"pixels": int(valid.sum()),
           "mean_relative_error": mean, "median_relative_error": median, "p90_relative_error": p90,
           "max_relative_error": float(rel[valid].max()) if valid.any() else 0.0,
           "rms_relative_error": rms_relative_error(realtime, reference, valid),
           "luminance_floor": floor, "floor_fraction": FLOOR_FRACTION,
           "mean_floored_error": f_mean, "median_floored_error": f_median, "p90_floored_error": f_p90,
           "relative_error_map": rel, "floored_error_map": floored}
    if stderr is not None and valid.any():
        out["mean_relative_stderr"] = float((luminance(stderr)[valid] / y_ref[valid]).mean())
        out["rms_relative_error_noise_removed"] = rms_relative_error(realtime, reference, valid, stderr)
    if flip:
        import flip_evaluator

        _, mean_flip, _ = flip_evaluator.evaluate(np.ascontiguousarray(np.maximum(reference, 0.0), dtype=np.float32),
                                                  np.ascontiguousarray(np.maximum(realtime, 0.0), dtype=np.float32),
                                                  "HDR", applyMagma=False)
        out["flip"] = float(mean_flip)
    return out


def error_heatmap(rel, mask, scale=HEATMAP_SCALE):
    """sRGB-encoded colours (H, W, 3) of the relative error through matplotlib's
    'magma' colour map, 0 to ``scale`` (clipped); pixels outside ``mask`` are black."""
    from matplotlib import colormaps

    colours = colormaps["magma"](np.clip(rel / scale, 0.0, 1.0))[..., :3]
    return np.where(mask[..., None], colours, 0.0)

