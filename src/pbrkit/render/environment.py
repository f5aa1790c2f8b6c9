"""The scene's environment as both renderers see it: radiance lookups, the
backdrop, and importance sampling of the piecewise-constant equirect map.

The environment seen by the ground truth is the piecewise-constant
equirect image (nearest texel, the function :func:`pbrkit.ibl.equirect.
equirect_to_cube` integrates), rotated and scaled as the scene says.

The environment is importance sampled from the piecewise-constant equirect
radiance: a 2-D distribution over (u, v) proportional to luminance(i, j)
sin(theta_i), sampled as a marginal over rows and a conditional over columns
(pbrt-v4, Pharr, Jakob and Humphreys 2023, sec. A.5.6 ``PiecewiseConstant2D``
and sec. 12.5.2 image infinite lights), with the solid-angle pdf
p(u, v) / (2 pi^2 sin theta).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..core.color import luminance
from ..core.filtering import CLAMP_TO_EDGE, REPEAT, texel_pair
from ..core.jit import dual_use, parallel_kernel
from ..ibl.equirect import (
    equirect_angles_of_uv,
    equirect_direction,
    equirect_pixel_angles,
    equirect_uv,
)
from ..sampling.warps import pdf_uniform_sphere, warp_uniform_sphere
from .scene import bundled_environment

__all__ = [
    "EnvironmentLight",
]

# ============================================================ environment


@dual_use
def _rotate_y(x, y, z, c, s):
    """R_y(theta) (x, y, z) with c = cos theta, s = sin theta: [[c, 0, s], [0, 1, 0], [-s, 0, c]]."""
    return c * x + s * z, y, -s * x + c * z


@dual_use
def _env_texel(h, w, c, s, dx, dy, dz):
    """Texel (row, column) of the equirect (H x W, CONVENTIONS.md) seen along world
    direction d (unit) with the environment rotated by R_y(theta), and sin(theta)
    of the direction in the map's frame (texture coordinates:
    :func:`pbrkit.ibl.equirect.equirect_uv`)."""
    x, y, z = _rotate_y(dx, dy, dz, c, -s)
    u, v = equirect_uv(x, y, z)
    j = min(max(int(u * w), 0), w - 1)
    i = min(max(int(v * h), 0), h - 1)
    return i, j, math.sqrt(max(0.0, 1.0 - y * y))


@dual_use
def _env_lookup(env, c, s, dx, dy, dz):
    """Radiance of the piecewise-constant equirect ``env`` (H, 2H, 3) along world direction d."""
    i, j, _ = _env_texel(env.shape[0], env.shape[1], c, s, dx, dy, dz)
    return env[i, j, 0], env[i, j, 1], env[i, j, 2]


@dual_use
def _env_pdf_texel(func, total, i, j, sin_theta):
    """Solid-angle pdf p(u, v) / (2 pi^2 sin theta) of :func:`_env_sample` in texel (i, j)."""
    if total <= 0.0:
        return pdf_uniform_sphere(0.0)
    if sin_theta <= 0.0:
        return 0.0
    return func[i, j] / total / (2.0 * math.pi * math.pi * sin_theta)


@dual_use
def _sample_1d(cdf, guide, u):
    """pbrt-v4 PiecewiseConstant1D::Sample on a normalised cdf (n + 1 entries): the bin o
    with cdf[o] <= u < cdf[o + 1] (as searchsorted(cdf, u, 'right') - 1) and the
    continuous offset in it.  The bin is found from a guide table (guide[k] = the bin of
    u = k / n; Chen and Asau, "On generating random variates from an empirical
    distribution", AIIE Trans. 6(2), 1974) and a short forward scan: O(1) expected."""
    n = cdf.shape[0] - 1
    o = guide[min(int(u * n), n - 1)]
    while o < n - 1 and cdf[o + 1] <= u:
        o += 1
    width = cdf[o + 1] - cdf[o]
    du = (u - cdf[o]) / width if width > 0.0 else 0.5
    return o, min(max(du, 0.0), 1.0)


@dual_use
def _env_sample(func, total, marg_cdf, cond_cdf, c, s, u1, u2):
    """Direction (world), solid-angle pdf and texel (i, j) sampled from the 2-D
    distribution (pbrt-v4 PiecewiseConstant2D: row from the marginal, column from
    its conditional); the point (u, v) is mapped to a direction by
    :func:`pbrkit.ibl.equirect.equirect_angles_of_uv` and
    :func:`~pbrkit.ibl.equirect.equirect_direction`.  A black environment is
    sampled uniformly (:func:`pbrkit.sampling.warps.warp_uniform_sphere`, its
    polar axis along +Y)."""
    h = func.shape[0]
    w = func.shape[1]
    if total <= 0.0:  # black environment: uniform sphere
        sx, sy, sz = warp_uniform_sphere(u1, u2)
        i, j, _ = _env_texel(h, w, c, s, sx, sz, sy)
        return sx, sz, sy, pdf_uniform_sphere(sz), i, j
    i, dv = _sample_1d(marg_cdf[0], marg_cdf[1], u1)
    j, du = _sample_1d(cond_cdf[0][i], cond_cdf[1][i], u2)
    theta, phi = equirect_angles_of_uv((j + du) / w, (i + dv) / h)
    st = math.sin(theta)
    if st <= 0.0:
        return 0.0, 1.0, 0.0, 0.0, i, j
    x, y, z = equirect_direction(theta, phi)
    pdf = _env_pdf_texel(func, total, i, j, st)
    wx, wy, wz = _rotate_y(x, y, z, c, s)
    return wx, wy, wz, pdf, i, j


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
        """(func (H, W), total, (marginal cdf (H + 1), its guide (H,)), (conditional cdfs
        (H, W + 1), their guides (H, W))): func = luminance * sin(theta_i); total = its
        mean (so p(u, v) = func / total); guide[k] = the bin holding u = k / n."""
        if self._distribution is None:
            h, w = self.radiance.shape[:2]
            sin_t = np.sin(equirect_pixel_angles(np.arange(h), 0, h, w)[0])
            func = np.maximum(luminance(self.radiance), 0.0) * sin_t[:, None]
            row = func.sum(axis=1)
            cond = np.zeros((h, w + 1))
            np.cumsum(func, axis=1, out=cond[:, 1:])
            with np.errstate(invalid="ignore", divide="ignore"):
                cond = np.where(row[:, None] > 0, cond / row[:, None], np.linspace(0.0, 1.0, w + 1)[None, :])
            marg = np.zeros(h + 1)
            np.cumsum(row, out=marg[1:])
            total = float(marg[-1])
            marg = marg / total if total > 0 else np.linspace(0.0, 1.0, h + 1)
            marg_guide = np.clip(np.searchsorted(marg, np.arange(h) / h, side="right") - 1, 0, h - 1)
            cond_guide = np.empty((h, w), dtype=np.int64)
            for i in range(h):
                cond_guide[i] = np.clip(np.searchsorted(cond[i], np.arange(w) / w, side="right") - 1, 0, w - 1)
            self._distribution = (np.ascontiguousarray(func), total / (h * w),
                                  (np.ascontiguousarray(marg), marg_guide.astype(np.int64)),
                                  (np.ascontiguousarray(cond), cond_guide))
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
        ``min_size`` = min(16, size / 4) unless given (at least 3 levels)."""
        if self.bake_data is None:
            from ..ibl.bake import bake as bake_environment

            options.setdefault("min_size", max(1, min(16, size // 4)))
            self.bake_data = bake_environment(self.environment, size=size, irradiance_size=irradiance_size,
                                              lut_size=lut_size, **options)
        return self.bake_data


@parallel_kernel
def _background_batch(env, c, s, d, out):
    """Bilinear equirect lookup (texel centres, CONVENTIONS.md; columns wrap, rows
    clamp: :func:`pbrkit.core.filtering.texel_pair`)."""
    h = env.shape[0]
    w = env.shape[1]
    for i in numba.prange(d.shape[0]):
        x, y, z = _rotate_y(d[i, 0], d[i, 1], d[i, 2], c, -s)
        u, v = equirect_uv(x, y, z)
        j0, j1, ax = texel_pair(u * w - 0.5, w, REPEAT)
        y0, y1, ay = texel_pair(v * h - 0.5, h, CLAMP_TO_EDGE)
        for ch in range(3):
            out[i, ch] = ((env[y0, j0, ch] * (1.0 - ax) + env[y0, j1, ch] * ax) * (1.0 - ay)
                          + (env[y1, j0, ch] * (1.0 - ax) + env[y1, j1, ch] * ax) * ay)


@parallel_kernel
def _env_lookup_batch(env, c, s, d, out):
    for i in numba.prange(d.shape[0]):
        r = _env_lookup(env, c, s, d[i, 0], d[i, 1], d[i, 2])
        out[i, 0] = r[0]
        out[i, 1] = r[1]
        out[i, 2] = r[2]

