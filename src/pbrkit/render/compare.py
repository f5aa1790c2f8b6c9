"""Comparing a real-time image with its ground truth: relative errors, FLIP and heat maps.
"""

from __future__ import annotations

import numpy as np

from ..core.color import luminance

__all__ = [
    "compare_images",
]

# ================================================================== compare


def compare_images(realtime, reference, mask, stderr=None, flip=True):
    """Errors of ``realtime`` against ``reference`` (H, W, 3) over the surface pixels
    ``mask``: relative luminance error |Y_rt - Y_ref| / Y_ref (over the pixels
    with Y_ref above 1e-3 of its mean), its mean and maximum, the mean reference standard
    error relative to Y_ref (the noise floor), and HDR-FLIP (Andersson et al.,
    "FLIP: A Difference Evaluator for Alternating Images", HPG 2020; HDR-FLIP,
    2021) of the whole images via the ``flip-evaluator`` package."""
    y_rt = luminance(realtime)
    y_ref = luminance(reference)
    floor = 1e-3 * max(float(y_ref[mask].mean()) if mask.any() else 0.0, 1e-12)
    valid = mask & (y_ref > floor)
    rel = np.zeros(y_ref.shape)
    rel[valid] = np.abs(y_rt[valid] - y_ref[valid]) / y_ref[valid]
    out = {"pixels": int(valid.sum()),
           "mean_relative_error": float(rel[valid].mean()) if valid.any() else 0.0,
           "max_relative_error": float(rel[valid].max()) if valid.any() else 0.0,
           "relative_error_map": rel}
    if stderr is not None and valid.any():
        out["mean_relative_stderr"] = float((luminance(stderr)[valid] / y_ref[valid]).mean())
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

