"""Comparing a real-time image with its ground truth: relative errors, FLIP and heat maps.
"""

from __future__ import annotations

import numpy as np

from ..core.color import luminance

__all__ = [
    "compare_images",
    "relative_error_pixels",
    "rms_relative_error",
    "error_heatmap",
]

# ================================================================== compare


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
    images via the ``flip-evaluator`` package."""
    y_rt = luminance(realtime)
    y_ref = luminance(reference)
    valid = relative_error_pixels(reference, mask)
    rel = np.zeros(y_ref.shape)
    rel[valid] = np.abs(y_rt[valid] - y_ref[valid]) / y_ref[valid]
    out = {"pixels": int(valid.sum()),
           "mean_relative_error": float(rel[valid].mean()) if valid.any() else 0.0,
           "max_relative_error": float(rel[valid].max()) if valid.any() else 0.0,
           "rms_relative_error": rms_relative_error(realtime, reference, valid),
           "relative_error_map": rel}
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


def error_heatmap(rel, mask, scale=0.2):
    """sRGB-encoded colours (H, W, 3) of the relative error through matplotlib's
    'magma' colour map, 0 to ``scale`` (clipped); pixels outside ``mask`` are black."""
    from matplotlib import colormaps

    colours = colormaps["magma"](np.clip(rel / scale, 0.0, 1.0))[..., :3]
    return np.where(mask[..., None], colours, 0.0)

