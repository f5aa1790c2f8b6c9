"""Shared test helper: the element-wise comparison of a shading model's values with an
independent transcription of its source, and the shading frame those tests use.

Tolerance (tests/brdf/test_model_values.py's docstring explains it): relative 1e-10
per element and channel, loosened where the formula is ill-conditioned -- the cosine
n.h of a half vector rounded to double carries a couple of ulps, and the
distributions' relative condition number with respect to n.h grows as 1 / alpha^2,
hence 16 eps / alpha_min^2 -- plus an absolute F_ABS x D V where an exact Fresnel
factor can vanish, and values below 1e-300 compare absolutely.
"""

from __future__ import annotations

import numpy as np

RTOL = 1e-10
EPS = np.finfo(float).eps
#: The condition term: 2 ulps of n.h x |d ln D / d n.h| <= 4 / alpha^2 x 2 (margin).
CONDITION = 16.0 * EPS
#: Below this, values compare absolutely (denormals carry no relative precision).
ATOL = 1e-300
#: The absolute error allowed an exact Fresnel factor F in [0, 1], times D V: where F
#: itself vanishes (the exact dielectric of reflectance 0 has IOR 1, F = 0) its relative
#: error is unbounded; pbrkit's complex-arithmetic F leaves ~1e-22 there.
F_ABS = 8.0 * EPS

#: The shading frame of the value tests: normal +Z, tangent +X.
N_DIR = np.array([0.0, 0.0, 1.0])
T_DIR = np.array([1.0, 0.0, 0.0])


def assert_matches(actual, expected, alpha_min, what, lobe=None, rtol=RTOL):
    """|actual - expected| <= (rtol + CONDITION / alpha_min^2) |expected| + F_ABS lobe + ATOL
    for every element and channel (module docstring), and every value finite; ``lobe``:
    the specular lobe without its Fresnel factor, D V (N,), for an F that can vanish."""
    actual = np.asarray(actual)
    assert actual.shape == expected.shape, what
    assert np.all(np.isfinite(actual)), f"{what}: non-finite values at {np.argwhere(~np.isfinite(actual))[:5]}"
    assert np.all(np.isfinite(expected)), f"{what}: the transcription is not finite"
    rtol = (rtol + CONDITION / np.asarray(alpha_min) ** 2)[..., None]
    error = np.abs(actual - expected)
    bound = rtol * np.abs(expected) + ATOL
    if lobe is not None:
        bound = bound + F_ABS * np.abs(np.asarray(lobe))[..., None]
    bad = error > bound
    if np.any(bad):
        with np.errstate(divide="ignore", invalid="ignore"):
            relative = np.where(bad, error / np.abs(expected), 0.0)
        rows = np.argsort(-relative.max(axis=-1))[:4]
        lines = [f"  element {i}: pbrkit {actual[i]}, reference {expected[i]}, relative error "
                 f"{relative[i].max():.3g} (tolerance {rtol[i, 0]:.3g})" for i in rows]
        raise AssertionError(f"{what}: {int(bad.any(axis=-1).sum())} of {bad.shape[0]} elements differ\n"
                             + "\n".join(lines))
