"""The scene's environment as both renderers see it: radiance lookups, the
backdrop, and importance sampling of the piecewise-constant equirect map.

The environment seen by the ground truth is the piecewise-constant
equirect image (nearest texel, the function :func:`pbrkit.ibl.equirect.
equirect_to_cube` integrates), rotated and scaled as the scene says.

It is importance sampled texel by texel (pbrt-v4, Pharr, Jakob and Humphreys
2023, sec. 12.5.2, image infinite lights, with the texel's exact solid angle
in place of the sin(theta) of the (u, v) parameterisation):

- a texel is drawn with probability proportional to luminance(i, j) times its
  solid angle (2 pi / W)(cos theta_i - cos theta_{i+1}) from an alias table
  (Walker 1977; Vose 1991): O(1) per sample, one comparison, two loads;
- the direction is uniform in the texel's solid angle: cos theta uniform
  between the row's boundary cosines, phi uniform across the column;
- so the solid-angle pdf is constant over a texel, luminance(i, j) / sum of
  luminance x solid angle: proportional to the radiance's luminance itself.

The kernels evaluate the equirect mapping with :func:`_sincos` and
:func:`_atan2`, polynomial elementary functions written with multiplies,
selects and one division, which LLVM compiles to SIMD instructions where the
C library's sin, cos, atan2 and acos stay scalar calls.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.color import luminance
from ..core.filtering import CLAMP_TO_EDGE, REPEAT, texel_pair
from ..core.jit import dual_use, kernel, row_kernel
from ..ibl.equirect import (
    equirect_angles_of_uv,
    equirect_uv,
)
from ..sampling.warps import ONE_MINUS_EPSILON
from .scene import bundled_environment

__all__ = [
    "EnvironmentLight",
]

# ============================================================ elementary functions

# Cody and Waite's two-part pi / 2 (fdlibm's pio2_1, pio2_1t: the first part has 33
# significant bits, so q pio2_1 is exact for |q| < 2^20).
_PIO2_HI = 1.57079632673412561417e+00
_PIO2_LO = 6.07710050650619224932e-11
_TWO_OVER_PI = 0.63661977236758134308
# pi / 2 and pi rounded to double, and what the rounding left out (Cephes' MOREBITS).
_PIO2 = 1.57079632679489661923
_PIO4 = 0.78539816339744830962
_PI = 3.14159265358979323846
_MOREBITS = 6.123233995736765886130e-17


@dual_use(inline=True)
def _sincos(x):
    """(sin x, cos x) for |x| < 2^20, within 2 ulp: x = q pi / 2 + r with q the
    nearest integer and r in [-pi/4, pi/4] (Cody and Waite's reduction with a
    two-part pi / 2), then Cephes' minimax polynomials for sin r and cos r
    (S. L. Moshier, Cephes Math Library, ``sin.c``) and the quadrant q mod 4
    by selects, without branches."""
    q = math.floor(x * _TWO_OVER_PI + 0.5)
    r = (x - q * _PIO2_HI) - q * _PIO2_LO
    z = r * r
    s = r + r * (z * ((((((1.58962301576546568060e-10 * z - 2.50507477628578072866e-8) * z
                          + 2.75573136213857245213e-6) * z - 1.98412698295895385996e-4) * z
                        + 8.33333333332211858878e-3) * z - 1.66666666666666307295e-1)))
    c = 1.0 - 0.5 * z + z * z * (((((-1.13585365213876817300e-11 * z + 2.08757008419747316778e-9) * z
                                    - 2.75573141792967388112e-7) * z + 2.48015872888517045348e-5) * z
                                  - 1.38888888888730564116e-3) * z + 4.16666666666665929218e-2)
    n = np.int64(q) & 3
    sin_x = c if n & 1 else s
    cos_x = s if n & 1 else c
    sin_x = -sin_x if n & 2 else sin_x
    cos_x = -cos_x if (n + 1) & 2 else cos_x
    return sin_x, cos_x


@dual_use(inline=True)
def _atan2(y, x):
    """atan2(y, x) in [-pi, pi] within 2 ulp: atan of t = min(|x|, |y|) / max(|x|, |y|)
    in [0, 1] by Cephes' rational approximation (``atan.c``: t > 0.66 is reduced
    by atan t = pi/4 + atan((t - 1) / (t + 1))), then pi/2 - a where |y| > |x|,
    pi - a where x < 0 and the sign of y, by selects.  atan2(0, 0) = 0."""
    ax = abs(x)
    ay = abs(y)
    big = max(ax, ay)
    t = min(ax, ay) / (big if big > 0.0 else 1.0)
    reduce = t > 0.66
    t = (t - 1.0) / (t + 1.0) if reduce else t
    z = t * t
    p = (((-8.750608600031904122785e-1 * z - 1.615753718733365076637e1) * z - 7.500855792314704667340e1) * z
         - 1.228866684490136173410e2) * z - 6.485021904942025371773e1
    q = ((((z + 2.485846490142306297962e1) * z + 1.650270098316988542046e2) * z + 4.328810604912902668951e2) * z
         + 4.853903996359136964868e2) * z + 1.945506571482613964425e2
    a = t * (z * p / q) + t
    a = (_PIO4 + (a + 0.5 * _MOREBITS)) if reduce else a
    a = ((_PIO2 - a) + _MOREBITS) if ay > ax else a
    a = ((_PI - a) + 2.0 * _MOREBITS) if x < 0.0 else a
    return math.copysign(a, y)


# ============================================================ environment


@dual_use(inline=True)
def _rotate_y(x, y, z, c, s):
    """R_y(theta) (x, y, z) with c = cos theta, s = sin theta: [[c, 0, s], [0, 1, 0], [-s, 0, c]]."""
    return c * x + s * z, y, -s * x + c * z


@dual_use(inline=True)
def _env_uv(x, y, z):
    """Equirect texture coordinates (u, v) = (0.5 + atan2(z, x) / (2 pi), acos(y) / pi) of a
    unit direction in the map's frame (CONVENTIONS.md; :func:`pbrkit.ibl.equirect.equirect_uv`),
    with acos(y) = atan2(sqrt((1 - y)(1 + y)), y) and :func:`_atan2`; and sin theta."""
    y = min(max(y, -1.0), 1.0)
    sin_theta = math.sqrt((1.0 - y) * (1.0 + y))
    return 0.5 + _atan2(z, x) * (0.5 / _PI), _atan2(sin_theta, y) * (1.0 / _PI), sin_theta


@dual_use(inline=True)
def _env_texel(h, w, c, s, dx, dy, dz):
    """Texel (row, column) of the equirect (H x W, CONVENTIONS.md) seen along world
    direction d (unit) with the environment rotated by R_y(theta) (:func:`_env_uv`)."""
    x, y, z = _rotate_y(dx, dy, dz, c, -s)
    u, v, _ = _env_uv(x, y, z)
    j = min(max(np.int64(u * w), 0), w - 1)
    i = min(max(np.int64(v * h), 0), h - 1)
    return i, j


@dual_use
def _env_lookup(env, c, s, dx, dy, dz):
    """Radiance of the piecewise-constant equirect ``env`` (H, 2H, 3) along world direction d."""
    i, j = _env_texel(env.shape[0], env.shape[1], c, s, dx, dy, dz)
    return env[i, j, 0], env[i, j, 1], env[i, j, 2]


@dual_use(inline=True)
def _texel_pdf(value, total):
    """The solid-angle pdf of :func:`_env_sample` over a texel whose ``func`` is ``value``:
    value / total (module docstring)."""
    return value / total


@dual_use
def _env_pdf_texel(func, total, i, j):
    """Solid-angle pdf of :func:`_env_sample` in texel (i, j), constant over the texel
    (:func:`_texel_pdf`)."""
    return _texel_pdf(func[i, j], total)


@dual_use(inline=True)
def _alias_column(n, u):
    """The column k = floor(u n) (at most n - 1) of an alias table of n columns that
    one uniform u picks, and the fraction f = u n - k in [0, 1) left over."""
    x = u * n
    k = min(np.int64(x), n - 1)
    return k, min(x - k, ONE_MINUS_EPSILON)


@dual_use(inline=True)
def _alias_choice(k, f, threshold, alias):
    """The index an alias table (Walker 1977; Vose 1991) draws from column k with
    fraction f (:func:`_alias_column`): k if f is below the column's threshold, else
    its alias; and f rescaled to [0, 1) within the part of the column that chose it
    (f / q or (f - q) / (1 - q)), a uniform number independent of the index."""
    keep = f < threshold
    index = k if keep else np.int64(alias)
    rest = f / threshold if keep else (f - threshold) / (1.0 - threshold)
    return index, min(rest, ONE_MINUS_EPSILON)


@dual_use
def _alias_sample(table, u):
    """An index drawn from the alias table ``table`` (n, 2) (thresholds, then aliases,
    side by side: one cache line per draw) with one uniform u, and the uniform number
    left over (:func:`_alias_column`, :func:`_alias_choice`)."""
    k, f = _alias_column(table.shape[0], u)
    return _alias_choice(k, f, table[k, 0], table[k, 1])


@dual_use(inline=True)
def _texel_of(k, w):
    """Row and column (i, j) of texel k of a flattened map of width w: k // w without an
    integer division (exact for k < 2^40)."""
    i = np.int64((k + 0.5) * (1.0 / w))
    return i, k - i * w


@dual_use(inline=True)
def _texel_point(y0, y1, w, j, dv, u2, c, s):
    """A world direction in a texel of column j (width w) between the boundary cosines
    y0 = cos theta_i and y1 = cos theta_{i+1} of its row: cos theta = y0 + (y1 - y0) dv,
    phi uniform across the column with u2 (:func:`pbrkit.ibl.equirect.equirect_angles_of_uv`),
    the direction (sin theta cos phi, cos theta, sin theta sin phi) of CONVENTIONS.md,
    turned by the environment's rotation (c, s): uniform in the texel's solid angle."""
    y = y0 + (y1 - y0) * dv
    sin_theta = math.sqrt(max((1.0 - y) * (1.0 + y), 0.0))
    _, phi = equirect_angles_of_uv((j + u2) / w, 0.0)
    sin_phi, cos_phi = _sincos(phi)
    return _rotate_y(sin_theta * cos_phi, y, sin_theta * sin_phi, c, s)


@dual_use
def _env_sample(func, total, alias, rows, c, s, u1, u2):
    """Direction (world), solid-angle pdf and texel (i, j) drawn from the environment
    (module docstring): the texel from the alias table ``alias`` (H W, 2) over the
    flattened (H, W) texels with u1 (:func:`_alias_sample`), then a direction in it
    (:func:`_texel_point`, with the boundary cosines ``rows`` (H + 1) of its row), and
    the pdf there (:func:`_texel_pdf`).  The kernels that draw many samples at once
    take these steps in separate loops, with the same functions."""
    k, dv = _alias_sample(alias, u1)
    w = func.shape[1]
    i, j = _texel_of(k, w)
    wx, wy, wz = _texel_point(rows[i], rows[i + 1], w, j, dv, u2, c, s)
    return wx, wy, wz, _texel_pdf(func[i, j], total), i, j


@kernel
def _alias_table(weight, threshold, alias):
    """Vose's alias table ("A linear algorithm for generating random numbers with a
    given distribution", IEEE TSE 17(9), 1991; the numerically careful form of
    K. Schwarz, "Darts, Dice, and Coins", 2011) for non-negative weights that
    sum to 1: column k keeps probability threshold[k] / n for itself and gives
    the rest of its 1 / n to alias[k].  Zero weights are never drawn."""
    n = weight.shape[0]
    small = np.empty(n, dtype=np.int64)
    large = np.empty(n, dtype=np.int64)
    scaled = weight * n
    ns = 0
    nl = 0
    first = -1
    for k in range(n):
        alias[k] = k
        if weight[k] > 0.0 and first < 0:
            first = k
        if scaled[k] < 1.0:
            small[ns] = k
            ns += 1
        else:
            large[nl] = k
            nl += 1
    while ns > 0 and nl > 0:
        ns -= 1
        lo = small[ns]
        g = large[nl - 1]
        threshold[lo] = scaled[lo]
        alias[lo] = g
        scaled[g] = (scaled[g] + scaled[lo]) - 1.0
        if scaled[g] < 1.0:
            nl -= 1
            small[ns] = g
            ns += 1
    for m in range(nl):
        threshold[large[m]] = 1.0
    for m in range(ns):  # left over by rounding: whole columns, unless weightless
        k = small[m]
        threshold[k] = 1.0 if weight[k] > 0.0 else 0.0
        alias[k] = k if weight[k] > 0.0 else max(first, 0)


class EnvironmentLight:
    """The scene's environment as both renderers see it.

    ``radiance``: the piecewise-constant equirect (H, 2H, 3) float64, times the
    intensity; ``rotation`` (degrees about +Y).  The luminance distribution for
    importance sampling (module docstring) is built on first use.
    ``environment``: the :class:`pbrkit.io.environment.Environment` to bake (None for a
    bake directory, whose :class:`Bake` is ``bake_data``)."""

    def __init__(self, spec, equirect_height=None):
        from ..ibl.equirect import cube_to_equirect
        from ..io.environment import Environment, load_environment

        self.spec = spec
        self.rotation = float(spec.rotation)
        self.intensity = float(spec.intensity)
        self.bake_data = None
        self.environment = None
        if spec.bake is not None:
            from ..io.bake_files import load_bake

            self.bake_data = load_bake(spec.bake)
            cube = np.asarray(self.bake_data.specular[0], dtype=np.float64)
            base = cube_to_equirect(cube, equirect_height or 2 * cube.shape[1])
            self.source = f"bake {spec.bake}"
        elif spec.color is not None:
            base = np.broadcast_to(np.asarray(spec.color, dtype=np.float64), (4, 8, 3)).copy()
            self.environment = Environment(source=("constant",), layout="equirect", equirect=base.astype(np.float32))
            self.source = f"constant {tuple(spec.color)}"
        elif spec.equirect is not None:
            base = np.asarray(spec.equirect, dtype=np.float64)
            self.environment = Environment(source=("array",), layout="equirect",
                                           equirect=np.ascontiguousarray(base, dtype=np.float32))
            self.source = "array"
        else:
            path = spec.file or str(bundled_environment())
            self.environment = load_environment(path, fix_nonfinite=bool(spec.fix_nonfinite))
            if self.environment.equirect is not None:
                base = np.asarray(self.environment.equirect, dtype=np.float64)
            else:
                base = cube_to_equirect(self.environment.cube, equirect_height or 2 * self.environment.cube.shape[1])
            self.source = path
        self.radiance = np.ascontiguousarray(base * self.intensity, dtype=np.float64)
        theta = math.radians(self.rotation)
        self.cos, self.sin = math.cos(theta), math.sin(theta)
        self._distribution = None
        self.samplers = {}  # id(bake) -> (bake, CubeSampler of its specular chain)

    @property
    def distribution(self):
        """(func (H, W), total, alias table (H W, 2), rows (H + 1)): func = the luminance
        (negative values as 0; 1 everywhere for a black environment, which is then
        sampled uniformly), total = its integral over the sphere, the sum of func x
        texel solid angle, so the sampling pdf is func / total (module docstring); the
        alias table (thresholds, then aliases as floats) draws texel i W + j with
        probability func x solid angle / total; rows[i] = cos theta of the upper
        boundary of row i."""
        if self._distribution is None:
            h, w = self.radiance.shape[:2]
            theta, _ = equirect_angles_of_uv(0.0, np.arange(h + 1) / h)
            rows = np.cos(theta)
            rows[0], rows[-1] = 1.0, -1.0
            solid_angle = (2.0 * np.pi / w) * (rows[:-1] - rows[1:])
            func = np.maximum(luminance(self.radiance), 0.0)
            weight = (func * solid_angle[:, None]).ravel()
            if not weight.sum() > 0.0:  # black: sample the sphere uniformly, pdf 1 / (4 pi)
                func = np.ones((h, w))
                weight = np.broadcast_to(solid_angle[:, None], (h, w)).ravel()
            total = float(weight.sum())
            threshold = np.zeros(h * w)
            alias = np.zeros(h * w, dtype=np.int64)
            _alias_table(weight / total, threshold, alias)
            table = np.ascontiguousarray(np.stack([threshold, alias], axis=1))
            self._distribution = (np.ascontiguousarray(func), total, table, np.ascontiguousarray(rows))
        return self._distribution

    def lookup(self, directions):
        """Radiance (N, 3) along world directions (N, 3) (nearest texel)."""
        d = np.ascontiguousarray(np.asarray(directions, dtype=np.float64).reshape(-1, 3))
        out = np.empty_like(d)
        _env_lookup_batch(self.radiance, self.cos, self.sin, d, out)
        return out

    def background(self, directions):
        """Radiance (N, 3) of the environment seen directly (the backdrop of both
        renderers): bilinear between texel centres of the equirect (columns wrap,
        rows clamp), as a sky box is drawn; lighting uses :meth:`lookup`."""
        d = np.ascontiguousarray(np.asarray(directions, dtype=np.float64).reshape(-1, 3))
        out = np.empty_like(d)
        _background_batch(self.radiance, self.cos, self.sin, d, out)
        return out

    def to_env_frame(self, directions):
        """World directions expressed in the environment map's frame: R_y(-theta) d."""
        d = np.asarray(directions, dtype=np.float64)
        return np.stack(np.broadcast_arrays(*_rotate_y(d[..., 0], d[..., 1], d[..., 2], self.cos, -self.sin)),
                        axis=-1)

    def bake(self, size=256, irradiance_size=32, lut_size=128, **options):
        """The IBL bake (:func:`pbrkit.ibl.bake.bake`) of the un-scaled environment (the
        renderer multiplies by the intensity), cached.  The chain goes down to
        ``min_size`` = min(16, size / 4) unless given (at least 3 levels).  Without the
        sheen's Charlie chain and table unless ``sheen=True``: the real-time renderer
        prefilters the chain when a material first needs it
        (:func:`pbrkit.rendering.realtime.render_realtime`)."""
        if self.bake_data is None:
            from ..ibl.bake import bake as bake_environment

            options.setdefault("min_size", max(1, min(16, size // 4)))
            options.setdefault("sheen", False)
            self.bake_data = bake_environment(self.environment, size=size, irradiance_size=irradiance_size,
                                              lut_size=lut_size, **options)
        return self.bake_data


@row_kernel(3)
def _background_batch(start, stop, env, c, s, d, out):
    """Bilinear equirect lookup (texel centres, CONVENTIONS.md; columns wrap, rows
    clamp: :func:`pbrkit.core.filtering.texel_pair`)."""
    h = env.shape[0]
    w = env.shape[1]
    for i in range(start, stop):
        x, y, z = _rotate_y(d[i, 0], d[i, 1], d[i, 2], c, -s)
        u, v = equirect_uv(x, y, z)
        j0, j1, ax = texel_pair(u * w - 0.5, w, REPEAT)
        y0, y1, ay = texel_pair(v * h - 0.5, h, CLAMP_TO_EDGE)
        for ch in range(3):
            out[i, ch] = ((env[y0, j0, ch] * (1.0 - ax) + env[y0, j1, ch] * ax) * (1.0 - ay)
                          + (env[y1, j0, ch] * (1.0 - ax) + env[y1, j1, ch] * ax) * ay)


@row_kernel(3)
def _env_lookup_batch(start, stop, env, c, s, d, out):
    for i in range(start, stop):
        r = _env_lookup(env, c, s, d[i, 0], d[i, 1], d[i, 2])
        out[i, 0] = r[0]
        out[i, 1] = r[1]
        out[i, 2] = r[2]

