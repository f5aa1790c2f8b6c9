"""Shared test helper: the harness of the GLSL-in-WebGL2 tests (tests/shaders/): a
:class:`Case` (a GLSL expression over N rows of float32 inputs and the pbrkit values it
must equal), the random float32 inputs the cases draw (unit vectors, cosines crowded
near 0 and 1, roughness alphas, direction triples with near-mirror pairs), the sizes
of the shaders page (WIDTH, CUBE_SIZE, CUBE_LEVELS), and :func:`assert_cases_match`,
which compares the page's results with each case's bound."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from pbrkit.brdf.bxdf import EXTRA_SLOTS, BxDF
from pbrkit.brdf.lobes.sheen import SHEEN_COLOR_SLOT, SHEEN_ROUGHNESS_SLOT

WIDTH = 64
N = 512


@dataclass
class Case:
    """A GLSL expression (a vec4 of the inputs a, b, ..., l) over N rows of inputs and
    the pbrkit values it must equal: |gl - expected| <= rtol |expected| + atol."""

    name: str
    covers: tuple
    expr: str
    inputs: list  # up to 12 arrays (N, 4) float32
    expected: np.ndarray  # (N, C) float64
    rtol: float = 1e-4
    atol: float = 0.0
    extra: dict = field(default_factory=dict)


def f32(x):
    return np.asarray(x, dtype=np.float32).astype(np.float64)


def vec4s(*columns):
    """(N, 4) float32 from up to 4 columns (N,) or (N, k)."""
    cols = [np.asarray(c, dtype=np.float64).reshape(N, -1) for c in columns]
    out = np.concatenate(cols, axis=1) if cols else np.zeros((N, 0))
    return np.pad(out, ((0, 0), (0, 4 - out.shape[1]))).astype(np.float32)


def random_units(rng, n=N):
    d = rng.normal(size=(n, 3))
    return f32(d / np.linalg.norm(d, axis=1, keepdims=True))


def random_cosines(rng, lo=-0.1):
    """Cosines in [lo, 1]: uniform, plus many close to 1 and to 0 (float32 values)."""
    u = rng.uniform(lo, 1.0, N)
    u[: N // 4] = 1.0 - 10.0 ** rng.uniform(-6, 0, N // 4)
    u[N // 4: N // 3] = 10.0 ** rng.uniform(-6, -1, N // 3 - N // 4)
    u[:4] = (1.0, 0.0, -0.5, 1e-7)
    return f32(u)


def random_alphas(rng, lo=1e-3):
    return f32(np.exp(rng.uniform(np.log(lo), 0.0, N)))


def random_directions(rng):
    """(l, v, n) float32 unit vectors: random pairs (some below the horizon) and
    near-mirror pairs (l = reflect(v) plus a little noise)."""
    n = random_units(rng)
    v = random_units(rng)
    v = np.where(np.sum(v * n, axis=1, keepdims=True) < -0.3, -v, v)  # mostly above, a few below
    l = random_units(rng)
    mirror = 2.0 * np.sum(v * n, axis=1, keepdims=True) * n - v
    mirror += 0.05 * rng.normal(size=mirror.shape)
    mirror /= np.linalg.norm(mirror, axis=1, keepdims=True)
    l[N // 2:] = f32(mirror[N // 2:])
    l[0], v[0], n[0] = (0.0, 1.0, 0.0), (0.0, 1.0, 0.0), (0.0, 1.0, 0.0)  # normal incidence
    l[1], v[1] = -v[1], v[1]  # l = -v: h = n
    return f32(l), f32(v), f32(n)


CUBE_SIZE = 16
CUBE_LEVELS = 4


def _measured(case, values):
    got = np.array([np.nan if x is None else x for x in values], dtype=float).reshape(N, 4)[:, :case.expected.shape[1]]
    return got, np.abs(got - case.expected)


def assert_cases_match(cases, result, width=22):
    """Each case's GLSL values (``result["results"]``) within its bound rtol |expected| +
    atol of pbrkit's (NaN fails); prints each case's largest differences and asserts with
    the first failing row of every case that fails."""
    failures = []
    lines = [f"renderer: {result['renderer']}, {result['seconds']:.1f} s"]
    for case in cases:
        got, diff = _measured(case, result["results"][case.name])
        scale = np.abs(case.expected)
        bound = case.rtol * scale + case.atol
        bad = ~(diff <= bound)  # NaN fails
        sized = scale > max(case.atol, 1e-30)  # relative differences where the value is above atol
        rel = diff[sized] / scale[sized]
        lines.append(f"{case.name:{width}s} max |diff| {np.nanmax(diff):.3g}  "
                     f"max rel {np.nanmax(rel, initial=0.0):.3g} (rtol {case.rtol:g}, atol {case.atol:.3g})")
        if np.any(bad):
            k = np.argwhere(bad)[0]
            failures.append(f"{case.name}: {int(bad.sum())} values off, e.g. row {k[0]}: inputs "
                            f"{[x[k[0]].tolist() for x in case.inputs]} -> GL {got[tuple(k)]!r}, pbrkit "
                            f"{case.expected[tuple(k)]!r}")
    print("\n".join(lines))
    assert not failures, "\n".join(failures)


def sheen_bxdf(color, roughness):
    """A BxDF carrying the sheen lobe's slots (colour, roughness); the rest unused."""
    z3 = (0.0, 0.0, 0.0)
    extra = [0.0] * EXTRA_SLOTS
    extra[SHEEN_COLOR_SLOT:SHEEN_COLOR_SLOT + 3] = [float(x) for x in color]
    extra[SHEEN_ROUGHNESS_SLOT] = float(roughness)
    return BxDF(0, 0, 0, 0, 0, 0.5, 0.25, 0.25, 0.25, False, 0.0, 0.0, z3, z3, z3, 1.0, z3, z3, 0.04, z3, tuple(extra))
