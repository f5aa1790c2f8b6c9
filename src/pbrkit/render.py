"""Rendering a scene two ways with the same BRDF: real-time shading with an
IBL bake, and Monte Carlo ground truth.

**The BRDF.**  Each material names a model of :mod:`pbrkit.models`
(``cook_torrance`` with its D, G and F by name, ``filament``, ``ue4``,
``urp_mobile``); :func:`brdf_value` evaluates it inside compiled kernels by
composing the same terms (:mod:`pbrkit.distributions`, :mod:`pbrkit.masking`,
:mod:`pbrkit.fresnel`, :mod:`pbrkit.diffuse`, :func:`pbrkit.models.
combine_lobes`); the tests check it against the NumPy models.  Perceptual
roughness r maps to alpha = max(r^2, ALPHA_MIN) everywhere; UE4's direct
light additionally uses its k = (r + 1)^2 / 8 (inside the model).

**Real time** (:func:`render_realtime`) is what an engine does with a bake
(:mod:`pbrkit.bake`): punctual lights evaluated with the model (with exact
shadow rays, as an ideal shadow map), plus split-sum image-based lighting
(Karis 2013, "Real Shading in Unreal Engine 4", "Image based lighting"):

- specular: the prefiltered chain sampled trilinearly (seam-aware,
  :class:`pbrkit.cubemap.CubeSampler`) in the mirror direction
  R = 2 (n.v) n - v at the fractional level ``level_of_roughness(r, M)``,
  times the DFG table (:mod:`pbrkit.tables`, texel centres, bilinear, clamp)
  as lerp(DFG1, DFG2, F0) = DFG1 + F0 (DFG2 - DFG1) (Filament sec. 5.3.4.3;
  f90 = 1).  The table's visibility matches the material's masking
  (height-correlated: the bake's table; separable; Schlick-GGX with
  k = alpha / 2 for UE4, whose IBL uses that remap); F0 is the model's (the
  metallic workflow's lerp, the exact conductor's F(1) for
  ``exact-conductor``, the constant colour S for ``fresnel = "none"``, where
  the albedo is S DFG2).  Optional energy compensation multiplies the
  specular lobes by 1 + F0 (1 / DFG2 - 1) (Filament sec. 4.7.2,
  :func:`pbrkit.tables.filament_energy_compensation`).
- diffuse: base_color / pi * E(n) * k_d with k_d = (1 - F*)(1 - metallic)
  (:func:`pbrkit.diffuse.kd_ibl`; seed 000) and E from the bake's SH
  (:func:`pbrkit.sh.irradiance_from_sh`) or its irradiance cube.
- the glTF occlusion texture scales both IBL terms; emission is added.

Known approximations of the real-time path (what ``compare`` measures):
the split sum itself (n = v = r in the prefilter, the lobe's shape), the
(1 - F*) factor on the diffuse, Lambert in place of Burley and GGX in place
of Beckmann / Blinn-Phong for the IBL, and the SH truncation.

**Ground truth** (:func:`render_reference`) integrates the same BRDF times
cos against the full environment and the lights by Monte Carlo, per pixel
(Veach 1997, "Robust Monte Carlo Methods for Light Transport Simulation",
ch. 9):

- environment importance sampling from the piecewise-constant equirect
  radiance: a 2-D distribution over (u, v) proportional to
  luminance(i, j) sin(theta_i), sampled as a marginal over rows and a
  conditional over columns (pbrt-v4, Pharr, Jakob and Humphreys 2023,
  sec. A.5.6 ``PiecewiseConstant2D`` and sec. 12.5.2 image infinite lights),
  with the solid-angle pdf p(u, v) / (2 pi^2 sin theta);
- BRDF sampling: GGX visible normals (Heitz 2018,
  :func:`pbrkit.sampling.warp_ggx_vndf`) for the specular lobe and cosine
  sampling for the diffuse one, mixed by an estimate of their albedos;
- multiple importance sampling with the power heuristic (beta = 2; Veach
  1997, sec. 9.2.4), occlusion by shadow rays;
- punctual lights evaluated exactly (with shadow rays) at every vertex;
  emissive surfaces hit by BRDF samples add their emission;
- ``bounces`` = 0 is direct lighting; each further bounce continues the
  path in the sampled BRDF direction (next-event estimation + MIS at every
  vertex).  The per-pixel standard error of the mean is returned with it.
- visibility is traced, so the glTF occlusion texture (a real-time stand-in
  for it) is not applied; ``occlusion=False`` instead lets every surface see
  the whole environment unblocked by the other objects, as real-time IBL
  assumes, to isolate the shading approximations in a comparison.
- scenes of spheres and planes run in one fused kernel per pixel (all
  samples, ray casting included); scenes with triangle meshes run as a
  wavefront loop over the samples, casting with Embree; the two give the
  same numbers for the same scene (tested).

The environment seen by the ground truth is the piecewise-constant
equirect image (nearest texel, the function :func:`pbrkit.envmap.
equirect_to_cube` integrates), rotated and scaled as the scene says.
Randomness comes from a counter-based hash (SplitMix64's finaliser;
Steele, Lea and Flood, "Fast Splittable Pseudorandom Number Generators",
OOPSLA 2014) of (seed, pixel, sample, bounce, dimension), so results do not
depend on thread scheduling: the same input gives the same bytes.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numba
import numpy as np

from numba.extending import register_jitable

from ._jit import parallel_kernel
from .diffuse import burley, kd_ibl, lambert
from .distributions import (
    alpha_from_roughness,
    d_beckmann,
    d_blinn_phong,
    d_ggx,
    phong_exponent_from_beckmann_alpha,
)
from .fresnel import f0_metallic, f90_filament, f_conductor, f_schlick, f_schlick_pow4, f_schlick_ue4_sg
from .geometry import KIND_NONE, KIND_SPHERE, Geometry, trace_analytic
from .lights import light_arrays, light_incidence
from .masking import (
    g2_height_correlated,
    g2_kelemen,
    g2_schlick_ggx,
    g2_separable,
    k_schlick_from_alpha,
    k_ue4_direct,
    lambda_beckmann,
    lambda_ggx,
    visibility,
)
from .models import DIFFUSES, DISTRIBUTIONS, FRESNELS, MASKINGS, combine_lobes, filament_specular, ue4_specular, \
    urp_specular
from .sampling import (
    pdf_cosine_hemisphere,
    pdf_ggx_vndf,
    pdf_light_from_half,
    warp_cosine_hemisphere,
    warp_ggx_vndf,
)
from .scene import SHADING_MODELS, bundled_environment
from .tables import table_bilinear
from .vec import orthonormal_basis_xyz

__all__ = [
    "MODES",
    "TONEMAPS",
    "RenderResult",
    "EnvironmentLight",
    "material_tables",
    "brdf_value",
    "brdf_values",
    "tonemap",
    "render_realtime",
    "render_reference",
    "compare_images",
    "render_scene",
    "luminance",
]

MODES = ("realtime", "reference", "compare")
#: Scalar helpers of the compiled kernels: compiled into each caller (so LLVM can inline them)
_inline = register_jitable
TONEMAPS = ("aces", "khronos-neutral", "agx", "reinhard", "none")
_REC709_Y = np.array([0.2126, 0.7152, 0.0722])
_INV_PI = 1.0 / math.pi

# material table columns (see material_tables)
_MI_MODEL, _MI_DIST, _MI_MASK, _MI_FRES, _MI_DIFF = range(5)
_MF_F0D, _MF_ETA, _MF_K, _MF_SPEC, _MF_BASE, _MF_METAL, _MF_ROUGH, _MF_EMIT, _MF_TWO_SIDED = 0, 1, 4, 7, 10, 13, 14, \
    15, 18
_MF_COLUMNS = 19


def luminance(rgb):
    """Rec.709 relative luminance Y = 0.2126 R + 0.7152 G + 0.0722 B (ITU-R BT.709)."""
    return np.asarray(rgb, dtype=float) @ _REC709_Y


# ===================================================================== BRDF


def material_tables(materials):
    """Pack :class:`pbrkit.geometry.SurfaceMaterial` s for the kernels:
    ``(mat_i (M, 5) int64 [model, distribution, masking, fresnel, diffuse] as indices
    into SHADING_MODELS, DISTRIBUTIONS, MASKINGS, FRESNELS, DIFFUSES;
    mat_f (M, 19) float64 [dielectric f0, eta (3), k (3), specular colour (3),
    base colour (3), metallic, roughness, emissive (3), double-sided])``."""
    m = len(materials)
    mat_i = np.zeros((m, 5), dtype=np.int64)
    mat_f = np.zeros((m, _MF_COLUMNS), dtype=np.float64)
    for i, sm in enumerate(materials):
        s = sm.spec
        mat_i[i] = (SHADING_MODELS.index(s.model), DISTRIBUTIONS.index(s.distribution), MASKINGS.index(s.masking),
                    FRESNELS.index(s.fresnel), DIFFUSES.index(s.diffuse))
        mat_f[i, _MF_F0D] = 0.16 * s.reflectance ** 2
        if s.eta is not None:
            mat_f[i, _MF_ETA:_MF_ETA + 3] = s.eta
            mat_f[i, _MF_K:_MF_K + 3] = s.k
        mat_f[i, _MF_SPEC:_MF_SPEC + 3] = s.specular_color
        mat_f[i, _MF_BASE:_MF_BASE + 3] = s.base_color
        mat_f[i, _MF_METAL] = s.metallic
        mat_f[i, _MF_ROUGH] = s.roughness
        mat_f[i, _MF_EMIT:_MF_EMIT + 3] = s.emissive
        mat_f[i, _MF_TWO_SIDED] = 1.0 if s.double_sided else 0.0
    return mat_i, mat_f


@_inline
def _specular_lobe(mi, m, nol, nov, noh, voh, roughness, alpha):
    """The Fresnel-free specular lobe D V of material m's model (module docstring)."""
    model = mi[m, _MI_MODEL]
    if model == 1:  # filament: GGX x height-correlated Smith (Filament sec. 4.4)
        return filament_specular(nol, nov, noh, alpha)
    if model == 2:  # ue4 (Karis 2013)
        return ue4_specular(nol, nov, noh, roughness)
    if model == 3:  # urp_mobile: URP's term carries pi (see pbrkit.models.urp_mobile)
        return urp_specular(noh, voh, alpha) * _INV_PI
    dist = mi[m, _MI_DIST]
    mask = mi[m, _MI_MASK]
    if dist == 0:
        d = d_ggx(noh, alpha)
    elif dist == 1:
        d = d_beckmann(noh, alpha)
    else:
        d = d_blinn_phong(noh, phong_exponent_from_beckmann_alpha(alpha))
    if mask <= 1:
        if dist == 0:
            lam_l = lambda_ggx(nol, alpha)
            lam_v = lambda_ggx(nov, alpha)
        else:
            lam_l = lambda_beckmann(nol, alpha)
            lam_v = lambda_beckmann(nov, alpha)
        if mask == 0:
            g2 = g2_height_correlated(lam_l, lam_v)
        else:
            g2 = g2_separable(lam_l, lam_v)
    elif mask == 2:
        g2 = g2_schlick_ggx(nol, nov, k_schlick_from_alpha(alpha))
    elif mask == 3:
        g2 = g2_schlick_ggx(nol, nov, k_ue4_direct(roughness))
    elif mask == 4:
        g2 = g2_kelemen(nol, nov, voh)
    else:
        g2 = max(nol, 0.0) * max(nov, 0.0)
    return d * visibility(g2, nol, nov)


@_inline
def _fresnel(mi, mf, m, c, voh, f0, f90):
    """Fresnel of channel c for model m (cook_torrance by name; the fixed models' own)."""
    model = mi[m, _MI_MODEL]
    if model == 1:
        return f_schlick(voh, f0, f90)
    if model == 2:
        return f_schlick_ue4_sg(voh, f0)
    if model == 3:
        return f0
    fres = mi[m, _MI_FRES]
    if fres == 0:
        return f_schlick(voh, f0, 1.0)
    if fres == 1:
        return f_schlick_pow4(voh, f0, 1.0)
    if fres == 2:
        return f_schlick_ue4_sg(voh, f0)
    if fres == 3:
        return f_conductor(voh, mf[m, _MF_ETA + c], mf[m, _MF_K + c])
    if fres == 4:
        root = math.sqrt(mf[m, _MF_F0D])
        return f_conductor(voh, (1.0 + root) / max(1.0 - root, 1e-6), 0.0)
    return mf[m, _MF_SPEC + c]


@_inline
def _f0_channel(mi, mf, m, base_c, metallic):
    """Normal-incidence specular colour of a channel in the model's metallic workflow."""
    if mi[m, _MI_MODEL] == 3:
        return f0_metallic(base_c, metallic, 0.04)
    return f0_metallic(base_c, metallic, mf[m, _MF_F0D])


@_inline
def brdf_value(mi, mf, m, nol, nov, noh, voh, roughness, metallic, b0, b1, b2, ec0, ec1, ec2):
    """BRDF f (RGB tuple) of material m for the given cosines and textured
    parameters; ``ec`` multiplies the specular lobe (energy compensation, 1 = off).
    Zero unless n.l > 0 and n.v > 0 (:func:`pbrkit.models.combine_lobes`)."""
    if nol <= 0.0 or nov <= 0.0:
        return 0.0, 0.0, 0.0
    alpha = alpha_from_roughness(roughness)
    spec = _specular_lobe(mi, m, nol, nov, noh, voh, roughness, alpha)
    model = mi[m, _MI_MODEL]
    f00 = _f0_channel(mi, mf, m, b0, metallic)
    f01 = _f0_channel(mi, mf, m, b1, metallic)
    f02 = _f0_channel(mi, mf, m, b2, metallic)
    f90 = f90_filament(f00 + f01 + f02) if model == 1 else 1.0
    if model == 3:
        dfac = _INV_PI
        kd = 0.96 * (1.0 - metallic)
    else:
        diff = mi[m, _MI_DIFF]
        if model == 2 or diff == 0:
            dfac = lambert(nol)
        elif diff == 1:
            dfac = burley(nol, nov, voh, roughness)
        else:
            dfac = 0.0
        kd = 1.0 - metallic
    r0 = combine_lobes(nol, nov, b0 * kd, dfac, spec * ec0, _fresnel(mi, mf, m, 0, voh, f00, f90))
    r1 = combine_lobes(nol, nov, b1 * kd, dfac, spec * ec1, _fresnel(mi, mf, m, 1, voh, f01, f90))
    r2 = combine_lobes(nol, nov, b2 * kd, dfac, spec * ec2, _fresnel(mi, mf, m, 2, voh, f02, f90))
    return r0, r1, r2


@_inline
def _cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz):
    hx = lx + vx
    hy = ly + vy
    hz = lz + vz
    hl = math.sqrt(hx * hx + hy * hy + hz * hz)
    if hl > 1e-12:
        hx /= hl
        hy /= hl
        hz /= hl
    else:
        hx, hy, hz = nx, ny, nz
    nol = nx * lx + ny * ly + nz * lz
    nov = nx * vx + ny * vy + nz * vz
    noh = nx * hx + ny * hy + nz * hz
    voh = max(vx * hx + vy * hy + vz * hz, 0.0)
    return nol, nov, noh, voh


@parallel_kernel
def _brdf_batch(mi, mf, mat, l, v, n, rough, metal, base, out):
    for i in numba.prange(l.shape[0]):
        nol, nov, noh, voh = _cosines(n[i, 0], n[i, 1], n[i, 2], v[i, 0], v[i, 1], v[i, 2], l[i, 0], l[i, 1],
                                      l[i, 2])
        r = brdf_value(mi, mf, mat[i], nol, nov, noh, voh, rough[i], metal[i], base[i, 0], base[i, 1], base[i, 2],
                       1.0, 1.0, 1.0)
        out[i, 0] = r[0]
        out[i, 1] = r[1]
        out[i, 2] = r[2]


def brdf_values(materials, l, v, n, material_index=0, roughness=None, metallic=None, base_color=None):
    """:func:`brdf_value` on arrays of unit directions (N, 3) from Python (for tests
    and tools); parameters default to the material's own."""
    mat_i, mat_f = material_tables(materials)
    l, v, n = (np.ascontiguousarray(np.asarray(x, dtype=np.float64).reshape(-1, 3)) for x in (l, v, n))
    count = l.shape[0]
    mat = np.ascontiguousarray(np.broadcast_to(material_index, (count,)), dtype=np.int64)
    spec = materials[int(mat[0])].spec if count else None

    def per(x, default, shape=()):
        value = default if x is None else x
        return np.ascontiguousarray(np.broadcast_to(np.asarray(value, dtype=np.float64), (count,) + shape))

    out = np.empty((count, 3))
    _brdf_batch(mat_i, mat_f, mat, l, v, n, per(roughness, spec.roughness if spec else 0.5),
                per(metallic, spec.metallic if spec else 0.0),
                per(base_color, spec.base_color if spec else (0.8, 0.8, 0.8), (3,)), out)
    return out


# ============================================================ environment


@_inline
def _rotate_y(x, y, z, c, s):
    """R_y(theta) (x, y, z) with c = cos theta, s = sin theta: [[c, 0, s], [0, 1, 0], [-s, 0, c]]."""
    return c * x + s * z, y, -s * x + c * z


@_inline
def _env_texel(h, w, c, s, dx, dy, dz):
    """Texel (row, column) of the equirect (H x W, CONVENTIONS.md) seen along world
    direction d (unit) with the environment rotated by R_y(theta), and sin(theta)
    of the direction in the map's frame."""
    x, y, z = _rotate_y(dx, dy, dz, c, -s)
    u = 0.5 + math.atan2(z, x) / (2.0 * math.pi)
    v = math.acos(min(max(y, -1.0), 1.0)) / math.pi
    j = min(max(int(u * w), 0), w - 1)
    i = min(max(int(v * h), 0), h - 1)
    return i, j, math.sqrt(max(0.0, 1.0 - y * y))


@_inline
def _env_lookup(env, c, s, dx, dy, dz):
    """Radiance of the piecewise-constant equirect ``env`` (H, 2H, 3) along world direction d."""
    i, j, _ = _env_texel(env.shape[0], env.shape[1], c, s, dx, dy, dz)
    return env[i, j, 0], env[i, j, 1], env[i, j, 2]


@_inline
def _env_pdf_texel(func, total, i, j, sin_theta):
    """Solid-angle pdf p(u, v) / (2 pi^2 sin theta) of :func:`_env_sample` in texel (i, j)."""
    if total <= 0.0:
        return 0.25 / math.pi
    if sin_theta <= 0.0:
        return 0.0
    return func[i, j] / total / (2.0 * math.pi * math.pi * sin_theta)


@_inline
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


@_inline
def _env_sample(func, total, marg_cdf, cond_cdf, c, s, u1, u2):
    """Direction (world), solid-angle pdf and texel (i, j) sampled from the 2-D
    distribution (pbrt-v4 PiecewiseConstant2D: row from the marginal, column from
    its conditional)."""
    h = func.shape[0]
    w = func.shape[1]
    if total <= 0.0:  # black environment: uniform sphere
        z = 1.0 - 2.0 * u1
        r = math.sqrt(max(0.0, 1.0 - z * z))
        phi = 2.0 * math.pi * u2
        wx, wy, wz = r * math.cos(phi), z, r * math.sin(phi)
        i, j, _ = _env_texel(h, w, c, s, wx, wy, wz)
        return wx, wy, wz, 0.25 / math.pi, i, j
    i, dv = _sample_1d(marg_cdf[0], marg_cdf[1], u1)
    j, du = _sample_1d(cond_cdf[0][i], cond_cdf[1][i], u2)
    v = (i + dv) / h
    u = (j + du) / w
    theta = math.pi * v
    phi = 2.0 * math.pi * u - math.pi
    st = math.sin(theta)
    if st <= 0.0:
        return 0.0, 1.0, 0.0, 0.0, i, j
    x = st * math.cos(phi)
    y = math.cos(theta)
    z = st * math.sin(phi)
    pdf = func[i, j] / total / (2.0 * math.pi * math.pi * st)
    wx, wy, wz = _rotate_y(x, y, z, c, s)
    return wx, wy, wz, pdf, i, j


class EnvironmentLight:
    """The scene's environment as both renderers see it.

    ``radiance``: the piecewise-constant equirect (H, 2H, 3) float64, times the
    intensity; ``rotation`` (degrees about +Y).  The luminance distribution for
    importance sampling (module docstring) is built on first use.
    ``environment``: the :class:`pbrkit.envmap.Environment` to bake (None for a
    bake directory, whose :class:`Bake` is ``bake_data``)."""

    def __init__(self, spec, equirect_height=None):
        from .envmap import Environment, cube_to_equirect, load_environment

        self.spec = spec
        self.rotation = float(spec.rotation)
        self.intensity = float(spec.intensity)
        self.bake_data = None
        self.environment = None
        if spec.bake is not None:
            from .bake import load_bake

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
            self.environment = load_environment(path)
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
            sin_t = np.sin(np.pi * (np.arange(h) + 0.5) / h)
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
        c, s = self.cos, -self.sin
        return np.stack([c * d[..., 0] + s * d[..., 2], d[..., 1], -s * d[..., 0] + c * d[..., 2]], axis=-1)

    def bake(self, size=256, irradiance_size=32, lut_size=128, **options):
        """The IBL bake (:func:`pbrkit.bake.bake`) of the un-scaled environment (the
        renderer multiplies by the intensity), cached.  The chain goes down to
        ``min_size`` = min(16, size / 4) unless given (at least 3 levels)."""
        if self.bake_data is None:
            from .bake import bake as bake_environment

            options.setdefault("min_size", max(1, min(16, size // 4)))
            self.bake_data = bake_environment(self.environment, size=size, irradiance_size=irradiance_size,
                                              lut_size=lut_size, **options)
        return self.bake_data


@parallel_kernel
def _background_batch(env, c, s, d, out):
    """Bilinear equirect lookup (texel centres, CONVENTIONS.md; columns wrap, rows clamp)."""
    h = env.shape[0]
    w = env.shape[1]
    for i in numba.prange(d.shape[0]):
        x, y, z = _rotate_y(d[i, 0], d[i, 1], d[i, 2], c, -s)
        u = 0.5 + math.atan2(z, x) / (2.0 * math.pi)
        v = math.acos(min(max(y, -1.0), 1.0)) / math.pi
        fx = u * w - 0.5
        fy = min(max(v * h - 0.5, 0.0), h - 1.0)
        x0 = int(math.floor(fx))
        y0 = min(int(math.floor(fy)), max(h - 2, 0))
        ax = fx - x0
        ay = fy - y0
        y1 = min(y0 + 1, h - 1)
        j0 = x0 % w
        j1 = (x0 + 1) % w
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


# ================================================================ results


@dataclass
class RenderResult:
    """An image (H, W, 3) float64 linear radiance, its per-pixel standard error
    (reference mode), the mask of pixels whose centre ray hit a surface, and stats."""

    image: np.ndarray
    mask: np.ndarray
    stderr: np.ndarray | None = None
    stats: dict = field(default_factory=dict)


@dataclass
class _Primary:
    """Primary hits of every (pixel, sub-pixel) ray."""

    dirs: np.ndarray        # (P * K, 3)
    hit: np.ndarray         # (P * K,) bool
    rows: np.ndarray        # indices of hit rays
    surface: object         # Surface of the hit rays
    origin: np.ndarray


def _primary(scene, geometry):
    cam = scene.camera
    dirs = cam.ray_directions().reshape(-1, 3)
    origins = np.broadcast_to(np.asarray(cam.position, dtype=np.float64), dirs.shape)
    hits = geometry.intersect(origins, dirs)
    rows = np.flatnonzero(hits.hit)
    surface = geometry.surface(hits, origins, dirs, rows)
    return _Primary(dirs, hits.hit, rows, surface, np.asarray(cam.position, dtype=np.float64))


# ============================================================ punctual lights


@parallel_kernel
def _punctual_kernel(mi, mf, mat, p, ng, n, v, rough, metal, base, ec, codes, values, li, out_dir, out_dist,
                     out_value):
    """Unshadowed radiance from light li at each point, its direction and distance."""
    ct = codes[li, 0]
    cf = codes[li, 1]
    lv = values[li]
    for i in numba.prange(p.shape[0]):
        lx, ly, lz, dist, factor = light_incidence(ct, cf, lv, p[i, 0], p[i, 1], p[i, 2])
        out_dir[i, 0] = lx
        out_dir[i, 1] = ly
        out_dir[i, 2] = lz
        out_dist[i] = dist
        out_value[i, 0] = 0.0
        out_value[i, 1] = 0.0
        out_value[i, 2] = 0.0
        if factor <= 0.0 or ng[i, 0] * lx + ng[i, 1] * ly + ng[i, 2] * lz <= 0.0:
            continue
        nol, nov, noh, voh = _cosines(n[i, 0], n[i, 1], n[i, 2], v[i, 0], v[i, 1], v[i, 2], lx, ly, lz)
        f = brdf_value(mi, mf, mat[i], nol, nov, noh, voh, rough[i], metal[i], base[i, 0], base[i, 1], base[i, 2],
                       ec[i, 0], ec[i, 1], ec[i, 2])
        e = factor * max(nol, 0.0)
        out_value[i, 0] = f[0] * lv[0] * e
        out_value[i, 1] = f[1] * lv[1] * e
        out_value[i, 2] = f[2] * lv[2] * e


@parallel_kernel
def _punctual_analytic_batch(mi, mf, mat, p, ng, n, v, rough, metal, base, ec, codes, values, eps, shadows, spheres,
                             lo, hi, skip, first, count, order, planes, out):
    for i in numba.prange(p.shape[0]):
        r = _punctual_at(mi, mf, mat[i], p[i, 0], p[i, 1], p[i, 2], ng[i, 0], ng[i, 1], ng[i, 2], n[i, 0], n[i, 1],
                         n[i, 2], v[i, 0], v[i, 1], v[i, 2], rough[i], metal[i], base[i, 0], base[i, 1], base[i, 2],
                         ec[i, 0], ec[i, 1], ec[i, 2], codes, values, eps, shadows, spheres, lo, hi, skip, first,
                         count, order, planes)
        out[i, 0] = r[0]
        out[i, 1] = r[1]
        out[i, 2] = r[2]


def _punctual(geometry, surface, v, mat_i, mat_f, ec=None, shadows=True):
    """Radiance (N, 3) from the scene's punctual lights at the surface points, seen along v."""
    count = surface.p.shape[0]
    total = np.zeros((count, 3))
    if not geometry.lights or count == 0:
        return total
    codes, values = light_arrays(geometry.lights)
    ec = np.ones((count, 3)) if ec is None else np.ascontiguousarray(ec)
    if not geometry.has_meshes:  # analytic scene: shadow rays inside the kernel
        _punctual_analytic_batch(mat_i, mat_f, np.ascontiguousarray(surface.material),
                                 *(np.ascontiguousarray(x) for x in (surface.p, surface.ng, surface.n, v,
                                                                     surface.roughness, surface.metallic,
                                                                     surface.base_color)),
                                 ec, codes, values, 1e-7 * geometry.scale, bool(shadows), geometry.spheres,
                                 *geometry.bvh, geometry.planes, total)
        return total
    args = [np.ascontiguousarray(x) for x in (surface.p, surface.ng, surface.n, v, surface.roughness,
                                              surface.metallic, surface.base_color)]
    direction = np.empty((count, 3))
    dist = np.empty(count)
    value = np.empty((count, 3))
    for li in range(len(geometry.lights)):
        _punctual_kernel(mat_i, mat_f, np.ascontiguousarray(surface.material), *args, ec, codes, values, li,
                         direction, dist, value)
        lit = np.flatnonzero(np.any(value > 0.0, axis=1))
        if shadows and lit.size:
            origins = geometry.offset_origins(surface.p[lit], surface.ng[lit], direction[lit])
            blocked = geometry.occluded(origins, direction[lit], dist[lit] * (1.0 - 1e-6))
            value[lit[blocked]] = 0.0
        total += value
    return total


# ================================================================ real time


@lru_cache(maxsize=8)
def _extra_lut(visibility, size):
    from .tables import lookup_table

    return lookup_table("dfg", size, visibility)[0]


def _lut_for(spec, bake_lut):
    """The DFG table matching a material's masking (module docstring), and its name."""
    if spec.model == "ue4" or spec.masking in ("schlick-ggx", "schlick-ggx-ue4"):
        return _extra_lut("schlick-ggx", bake_lut.shape[0]), "schlick-ggx"
    if spec.masking == "separable":
        return _extra_lut("separable", bake_lut.shape[0]), "separable"
    return np.asarray(bake_lut), "height-correlated"


@parallel_kernel
def _ibl_kernel(mi, mf, mat, lut_index, tables, n, v, rough, metal, base, occlusion, prefiltered, irradiance,
                energy_compensation, out, ec_out):
    """Split-sum IBL per pixel (module docstring); writes the radiance and the
    energy-compensation factor (for the punctual lights)."""
    for i in numba.prange(n.shape[0]):
        m = mat[i]
        nov = max(n[i, 0] * v[i, 0] + n[i, 1] * v[i, 1] + n[i, 2] * v[i, 2], 1e-4)
        r = rough[i]
        t = lut_index[m]
        dfg1 = table_bilinear(tables, t, nov, r, 0)
        dfg2 = table_bilinear(tables, t, nov, r, 1)
        model = mi[m, _MI_MODEL]
        fres = mi[m, _MI_FRES]
        diffuse_on = model == 2 or model == 3 or mi[m, _MI_DIFF] != 2
        for c in range(3):
            b = base[i, c]
            if model == 0 and fres == 3:
                f0 = min(f_conductor(1.0, mf[m, _MF_ETA + c], mf[m, _MF_K + c]), 1.0)
            elif model == 0 and fres == 4:
                f0 = mf[m, _MF_F0D]
            elif model == 0 and fres == 5:
                f0 = mf[m, _MF_SPEC + c]
            else:
                f0 = _f0_channel(mi, mf, m, b, metal[i])
            if model == 0 and fres == 5:
                albedo = f0 * dfg2
            else:
                albedo = dfg1 + f0 * (dfg2 - dfg1)
            ec = 1.0
            if energy_compensation:
                ec = 1.0 + f0 * (1.0 / max(dfg2, 1e-6) - 1.0)
            ec_out[i, c] = ec
            spec = prefiltered[i, c] * albedo * ec
            diff = 0.0
            if diffuse_on:
                metal_part = metal[i] if not (model == 0 and fres == 4) else 0.0
                kd = kd_ibl(nov, f0, r, metal_part)
                if model == 3:
                    kd *= 0.96
                diff = b * kd * irradiance[i, c] * _INV_PI
            out[i, c] = (spec + diff) * occlusion[i]


def render_realtime(scene, geometry=None, env=None, bake=None, diffuse="sh", energy_compensation=False,
                    shadows=True, bake_size=256, bake_options=None):
    """Real-time shading of ``scene`` (module docstring).  ``diffuse``: ``sh`` (the
    bake's 9 SH coefficients) or ``cube`` (its irradiance cube).  Returns a
    :class:`RenderResult`; ``stats['timings']`` has the stages in seconds."""
    from .bake import level_of_roughness
    from .cubemap import CubeSampler
    from .sh import irradiance_from_sh

    if diffuse not in ("sh", "cube"):
        raise ValueError(f"unknown diffuse source {diffuse!r}; use 'sh' or 'cube'")
    timings = {}
    t0 = time.perf_counter()
    geometry = geometry or Geometry(scene)
    env = env or EnvironmentLight(scene.environment)
    t1 = time.perf_counter()
    timings["load"] = t1 - t0
    if bake is None:
        bake = env.bake(size=bake_size, **(bake_options or {}))
    t2 = time.perf_counter()
    timings["bake"] = t2 - t1
    prim = _primary(scene, geometry)
    t3 = time.perf_counter()
    timings["primary_rays"] = t3 - t2
    s = prim.surface
    mat_i, mat_f = material_tables(geometry.materials)
    count = prim.rows.size
    v = -prim.dirs[prim.rows]
    radiance = np.zeros((prim.dirs.shape[0], 3))
    radiance[~prim.hit] = env.background(prim.dirs[~prim.hit])
    if count:
        # lookup tables per material
        tables, lut_index, names = [], np.zeros(len(geometry.materials), dtype=np.int64), []
        for mi, m in enumerate(geometry.materials):
            table, name = _lut_for(m.spec, bake.lut)
            if name not in names:
                names.append(name)
                tables.append(np.asarray(table, dtype=np.float64)[..., :2])
            lut_index[mi] = names.index(name)
        tables = np.ascontiguousarray(np.stack(tables))
        nov = np.sum(s.n * v, axis=1, keepdims=True)
        refl = 2.0 * nov * s.n - v
        levels = len(bake.specular)
        sampler = env.samplers.get(id(bake))
        if sampler is None or sampler[0] is not bake:
            sampler = (bake, CubeSampler([np.asarray(x) for x in bake.specular]))
            env.samplers[id(bake)] = sampler
        sampler = sampler[1]
        lod = np.asarray(level_of_roughness(s.roughness, levels), dtype=np.float64)
        prefiltered = sampler(env.to_env_frame(refl), lod) * env.intensity
        if diffuse == "sh":
            irradiance = irradiance_from_sh(np.asarray(bake.sh), env.to_env_frame(s.n)) * env.intensity
        else:
            irradiance = CubeSampler(np.asarray(bake.irradiance))(env.to_env_frame(s.n)) * env.intensity
        t4 = time.perf_counter()
        timings["ibl_lookups"] = t4 - t3
        out = np.empty((count, 3))
        ec = np.empty((count, 3))
        _ibl_kernel(mat_i, mat_f, np.ascontiguousarray(s.material), lut_index, tables, np.ascontiguousarray(s.n),
                    np.ascontiguousarray(v), s.roughness, s.metallic, np.ascontiguousarray(s.base_color),
                    s.occlusion, np.ascontiguousarray(prefiltered, dtype=np.float64),
                    np.ascontiguousarray(irradiance, dtype=np.float64), bool(energy_compensation), out, ec)
        t5 = time.perf_counter()
        timings["ibl_shading"] = t5 - t4
        out += _punctual(geometry, s, v, mat_i, mat_f, ec if energy_compensation else None, shadows)
        out += s.emissive
        radiance[prim.rows] = out
        timings["punctual"] = time.perf_counter() - t5
    image, mask = _resolve(scene, radiance, prim.hit)
    timings["total"] = time.perf_counter() - t0
    stats = {"mode": "realtime", "timings": timings, "bake_levels": len(bake.specular),
             "bake_size": int(np.asarray(bake.specular[0]).shape[1]), "diffuse": diffuse,
             "energy_compensation": bool(energy_compensation), "shadows": bool(shadows),
             "pixels": int(scene.camera.width * scene.camera.height)}
    return RenderResult(image, mask, None, stats)


def _resolve(scene, per_ray, hit):
    """Average the k^2 sub-pixel rays of each pixel -> (H, W, 3); mask: the pixel's rays all hit."""
    cam = scene.camera
    k2 = cam.supersample ** 2
    image = per_ray.reshape(cam.height, cam.width, k2, -1).mean(axis=2)
    mask = hit.reshape(cam.height, cam.width, k2).all(axis=2)
    return image, mask


# ============================================================== ground truth

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)


@_inline
def _mix64(z):
    """SplitMix64's finaliser (Steele, Lea and Flood 2014): a bijective 64-bit mix."""
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@_inline
def _path_key(seed, pixel, sample, bounce):
    k = _mix64(np.uint64(seed) * _GOLDEN + np.uint64(pixel))
    k = _mix64(k ^ (np.uint64(sample) * np.uint64(0xD1B54A32D192ED03)))
    return _mix64(k + np.uint64(bounce) * np.uint64(0x8CB92BA72F3D8DD7))


@_inline
def _uniform(key, dim):
    """A uniform number in [0, 1) for dimension ``dim`` of the stream ``key`` (53 bits)."""
    z = _mix64(key + np.uint64(dim + 1) * _GOLDEN)
    return np.float64(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@_inline
def _lobe_probability(mi, mf, m, nov, metallic, b0, b1, b2):
    """Probability of sampling the specular lobe: its albedo estimate (the Fresnel
    at n.v) against the diffuse colour's, by luminance."""
    model = mi[m, _MI_MODEL]
    diffuse_on = model == 2 or model == 3 or mi[m, _MI_DIFF] != 2
    if model == 0 and mi[m, _MI_FRES] == 5:
        ws = 0.2126 * mf[m, _MF_SPEC] + 0.7152 * mf[m, _MF_SPEC + 1] + 0.0722 * mf[m, _MF_SPEC + 2]
    else:
        ws = (0.2126 * f_schlick(nov, _f0_channel(mi, mf, m, b0, metallic), 1.0)
              + 0.7152 * f_schlick(nov, _f0_channel(mi, mf, m, b1, metallic), 1.0)
              + 0.0722 * f_schlick(nov, _f0_channel(mi, mf, m, b2, metallic), 1.0))
    wd = 0.0
    if diffuse_on:
        wd = (0.2126 * b0 + 0.7152 * b1 + 0.0722 * b2) * (1.0 - metallic)
    if wd <= 0.0:
        return 1.0
    if ws <= 0.0:
        return 0.0
    return min(max(ws / (ws + wd), 0.1), 0.9)


@_inline
def _brdf_pdf(p_spec, alpha, nol, nov, noh, voh):
    """Solid-angle pdf of the BRDF-sampling mixture for direction l."""
    pdf = 0.0
    if p_spec > 0.0:
        pdf += p_spec * pdf_light_from_half(pdf_ggx_vndf(nov, noh, voh, alpha), voh)
    if p_spec < 1.0:
        pdf += (1.0 - p_spec) * pdf_cosine_hemisphere(nol)
    return pdf


@_inline
def _power_heuristic(pa, pb):
    """Veach 1997, sec. 9.2.4: w = pa^2 / (pa^2 + pb^2)."""
    a = pa * pa
    b = pb * pb
    if a + b <= 0.0:
        return 0.0
    return a / (a + b)


@_inline
def _vertex(key, mi, mf, m, px, py, pz, gx, gy, gz, nx, ny, nz, vx, vy, vz, rough, metal, b0, b1, b2,
            env, func, total, marg, cond, c, s, strategy):
    """The two samples of one path vertex.  Returns
    (light direction (3), light contribution (3, unshadowed, MIS-weighted),
     BRDF direction (3), BRDF weight f cos / pdf (3), BRDF pdf).
    ``strategy`` 0 = MIS (environment + BRDF sampling), 1 = BRDF sampling only."""
    z3 = (0.0, 0.0, 0.0)
    nov = nx * vx + ny * vy + nz * vz
    if nov <= 0.0 or gx * vx + gy * vy + gz * vz <= 0.0:
        return z3, z3, z3, z3, 0.0
    alpha = alpha_from_roughness(rough)
    p_spec = _lobe_probability(mi, mf, m, nov, metal, b0, b1, b2)
    # --- environment sample
    light_dir = z3
    light_val = z3
    if strategy == 0:
        lx, ly, lz, pdf_e, ei, ej = _env_sample(func, total, marg, cond, c, s, _uniform(key, 0), _uniform(key, 1))
        light_dir = (lx, ly, lz)
        if pdf_e > 0.0 and gx * lx + gy * ly + gz * lz > 0.0:
            nol, nov_, noh, voh = _cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz)
            if nol > 0.0:
                f = brdf_value(mi, mf, m, nol, nov_, noh, voh, rough, metal, b0, b1, b2, 1.0, 1.0, 1.0)
                pdf_b = _brdf_pdf(p_spec, alpha, nol, nov_, noh, voh)
                w = _power_heuristic(pdf_e, pdf_b) * nol / pdf_e
                light_val = (f[0] * env[ei, ej, 0] * w, f[1] * env[ei, ej, 1] * w, f[2] * env[ei, ej, 2] * w)
    # --- BRDF sample
    (tx, ty, tz), (bx, by, bz) = orthonormal_basis_xyz(nx, ny, nz)
    u1 = _uniform(key, 2)
    u2 = _uniform(key, 3)
    if _uniform(key, 4) < p_spec:
        wox = vx * tx + vy * ty + vz * tz
        woy = vx * bx + vy * by + vz * bz
        woz = nov
        hx, hy, hz = warp_ggx_vndf(u1, u2, wox, woy, woz, alpha)
        two = 2.0 * (wox * hx + woy * hy + woz * hz)
        llx = two * hx - wox
        lly = two * hy - woy
        llz = two * hz - woz
    else:
        llx, lly, llz = warp_cosine_hemisphere(u1, u2)
    lx = llx * tx + lly * bx + llz * nx
    ly = llx * ty + lly * by + llz * ny
    lz = llx * tz + lly * bz + llz * nz
    norm = math.sqrt(lx * lx + ly * ly + lz * lz)
    if norm <= 0.0:
        return light_dir, light_val, z3, z3, 0.0
    lx /= norm
    ly /= norm
    lz /= norm
    if gx * lx + gy * ly + gz * lz <= 0.0:
        return light_dir, light_val, (lx, ly, lz), z3, 0.0
    nol, nov_, noh, voh = _cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz)
    if nol <= 0.0:
        return light_dir, light_val, (lx, ly, lz), z3, 0.0
    pdf_b = _brdf_pdf(p_spec, alpha, nol, nov_, noh, voh)
    if pdf_b <= 0.0:
        return light_dir, light_val, (lx, ly, lz), z3, 0.0
    f = brdf_value(mi, mf, m, nol, nov_, noh, voh, rough, metal, b0, b1, b2, 1.0, 1.0, 1.0)
    k = nol / pdf_b
    return light_dir, light_val, (lx, ly, lz), (f[0] * k, f[1] * k, f[2] * k), pdf_b


@_inline
def _env_miss(strategy, pdf_b, env, func, total, c, s, dx, dy, dz):
    """Radiance times the MIS weight of a BRDF sample that reaches the environment."""
    i, j, sin_theta = _env_texel(env.shape[0], env.shape[1], c, s, dx, dy, dz)
    w = 1.0
    if strategy == 0:
        w = _power_heuristic(pdf_b, _env_pdf_texel(func, total, i, j, sin_theta))
    return env[i, j, 0] * w, env[i, j, 1] * w, env[i, j, 2] * w


# ------------------------------------------------- fused kernel (analytic scenes)


@_inline
def _analytic_surface(kind, index, spheres, planes, sphere_mat, plane_mat, mf, ox, oy, oz, dx, dy, dz, t):
    """Position, normal (facing the ray for double-sided materials) and material of an analytic hit."""
    px = ox + t * dx
    py = oy + t * dy
    pz = oz + t * dz
    if kind == KIND_SPHERE:
        r = spheres[index, 3]
        nx = px - spheres[index, 0]
        ny = py - spheres[index, 1]
        nz = pz - spheres[index, 2]
        length = math.sqrt(nx * nx + ny * ny + nz * nz)
        nx /= length
        ny /= length
        nz /= length
        px = spheres[index, 0] + r * nx
        py = spheres[index, 1] + r * ny
        pz = spheres[index, 2] + r * nz
        m = sphere_mat[index]
    else:
        nx = planes[index, 3]
        ny = planes[index, 4]
        nz = planes[index, 5]
        m = plane_mat[index]
    if mf[m, _MF_TWO_SIDED] > 0.0 and nx * dx + ny * dy + nz * dz > 0.0:
        nx, ny, nz = -nx, -ny, -nz
    return px, py, pz, nx, ny, nz, m


@_inline
def _punctual_at(mi, mf, m, px, py, pz, gx, gy, gz, nx, ny, nz, vx, vy, vz, rough, metal, b0, b1, b2, ec0, ec1,
                 ec2, codes, values, eps, shadows, spheres, lo, hi, skip, first, count, order, planes):
    """Radiance from every punctual light at an analytic-scene point (geometric normal g,
    shading normal n), with shadow rays when ``shadows``."""
    r0 = r1 = r2 = 0.0
    for li in range(codes.shape[0]):
        lx, ly, lz, dist, factor = light_incidence(codes[li, 0], codes[li, 1], values[li], px, py, pz)
        if factor <= 0.0 or gx * lx + gy * ly + gz * lz <= 0.0:
            continue
        nol, nov, noh, voh = _cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz)
        f = brdf_value(mi, mf, m, nol, nov, noh, voh, rough, metal, b0, b1, b2, ec0, ec1, ec2)
        if f[0] <= 0.0 and f[1] <= 0.0 and f[2] <= 0.0:
            continue
        if shadows:
            t, k, _ = trace_analytic(px + eps * gx, py + eps * gy, pz + eps * gz, lx, ly, lz, 0.0,
                                     dist * (1.0 - 1e-6), True, spheres, lo, hi, skip, first, count, order, planes)
            if k != KIND_NONE:
                continue
        e = factor * nol
        r0 += f[0] * values[li, 0] * e
        r1 += f[1] * values[li, 1] * e
        r2 += f[2] * values[li, 2] * e
    return r0, r1, r2


@parallel_kernel
def _fused_kernel(seed, spp, k2, bounces, strategy, occlusion, base_value, p, ng, n, v, mat, rough, metal,
                  base, mi, mf, env, func, total, marg, cond, c, s, eps, spheres, lo, hi, skip, first, count,
                  order, planes, sphere_mat, plane_mat, codes, values, out_shift, out_sum, out_sumsq):
    """Every sample of every pixel of an analytic scene (spheres, planes) in one pass:
    rows are the (pixel, sub-pixel) rays; sample j of a pixel uses sub-pixel j mod k2.
    ``base_value`` (rays, 3) is the deterministic part of each ray (background, or
    emission + punctual light at the primary hit); ``p`` etc. are the primary hits
    (rows with mat < 0 missed).  Per pixel it accumulates the sum and the sum of
    squares of (x - K), K = the pixel's first sample (the shifted-data algorithm,
    which keeps the variance free of cancellation; Chan, Golub and LeVeque,
    "Algorithms for Computing the Sample Variance", 1983)."""
    n_pixels = out_sum.shape[0]
    for pix in numba.prange(n_pixels):
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        q0 = 0.0
        q1 = 0.0
        q2 = 0.0
        for j in range(spp):
            row = pix * k2 + (j % k2)
            x0 = base_value[row, 0]
            x1 = base_value[row, 1]
            x2 = base_value[row, 2]
            m = mat[row]
            if m >= 0:
                px, py, pz = p[row, 0], p[row, 1], p[row, 2]
                gx, gy, gz = ng[row, 0], ng[row, 1], ng[row, 2]
                nx, ny, nz = n[row, 0], n[row, 1], n[row, 2]
                vx, vy, vz = v[row, 0], v[row, 1], v[row, 2]
                r = rough[row]
                me = metal[row]
                b0, b1, b2 = base[row, 0], base[row, 1], base[row, 2]
                t0 = t1 = t2 = 1.0
                for bounce in range(bounces + 1):
                    key = _path_key(seed, pix, j, bounce)
                    ldir, lval, bdir, bw, pdf_b = _vertex(key, mi, mf, m, px, py, pz, gx, gy, gz, nx, ny, nz, vx,
                                                          vy, vz, r, me, b0, b1, b2, env, func, total, marg, cond,
                                                          c, s, strategy)
                    ox = px + eps * gx
                    oy = py + eps * gy
                    oz = pz + eps * gz
                    if lval[0] > 0.0 or lval[1] > 0.0 or lval[2] > 0.0:
                        hk = KIND_NONE
                        if occlusion:
                            _, hk, _ = trace_analytic(ox, oy, oz, ldir[0], ldir[1], ldir[2], 0.0, np.inf, True,
                                                      spheres, lo, hi, skip, first, count, order, planes)
                        if hk == KIND_NONE:
                            x0 += t0 * lval[0]
                            x1 += t1 * lval[1]
                            x2 += t2 * lval[2]
                    if pdf_b <= 0.0 or (bw[0] <= 0.0 and bw[1] <= 0.0 and bw[2] <= 0.0):
                        break
                    th, hk, hi_ = np.inf, KIND_NONE, -1
                    if occlusion:
                        th, hk, hi_ = trace_analytic(ox, oy, oz, bdir[0], bdir[1], bdir[2], 0.0, np.inf, False,
                                                     spheres, lo, hi, skip, first, count, order, planes)
                    t0 *= bw[0]
                    t1 *= bw[1]
                    t2 *= bw[2]
                    if hk == KIND_NONE:
                        le = _env_miss(strategy, pdf_b, env, func, total, c, s, bdir[0], bdir[1], bdir[2])
                        x0 += t0 * le[0]
                        x1 += t1 * le[1]
                        x2 += t2 * le[2]
                        break
                    px, py, pz, nx, ny, nz, m = _analytic_surface(hk, hi_, spheres, planes, sphere_mat, plane_mat, mf,
                                                                  ox, oy, oz, bdir[0], bdir[1], bdir[2], th)
                    x0 += t0 * mf[m, _MF_EMIT]
                    x1 += t1 * mf[m, _MF_EMIT + 1]
                    x2 += t2 * mf[m, _MF_EMIT + 2]
                    if bounce == bounces:
                        break
                    gx, gy, gz = nx, ny, nz
                    vx, vy, vz = -bdir[0], -bdir[1], -bdir[2]
                    r = mf[m, _MF_ROUGH]
                    me = mf[m, _MF_METAL]
                    b0, b1, b2 = mf[m, _MF_BASE], mf[m, _MF_BASE + 1], mf[m, _MF_BASE + 2]
                    if codes.shape[0]:
                        pr = _punctual_at(mi, mf, m, px, py, pz, gx, gy, gz, nx, ny, nz, vx, vy, vz, r, me, b0, b1,
                                          b2, 1.0, 1.0, 1.0, codes, values, eps, True, spheres, lo, hi, skip, first,
                                          count, order, planes)
                        x0 += t0 * pr[0]
                        x1 += t1 * pr[1]
                        x2 += t2 * pr[2]
            if j == 0:
                out_shift[pix, 0] = x0
                out_shift[pix, 1] = x1
                out_shift[pix, 2] = x2
            x0 -= out_shift[pix, 0]
            x1 -= out_shift[pix, 1]
            x2 -= out_shift[pix, 2]
            s0 += x0
            s1 += x1
            s2 += x2
            q0 += x0 * x0
            q1 += x1 * x1
            q2 += x2 * x2
        out_sum[pix, 0] = s0
        out_sum[pix, 1] = s1
        out_sum[pix, 2] = s2
        out_sumsq[pix, 0] = q0
        out_sumsq[pix, 1] = q1
        out_sumsq[pix, 2] = q2


# ------------------------------------------------- wavefront (scenes with meshes)


@parallel_kernel
def _vertex_batch(seed, sample, bounce, strategy, pixel, p, ng, n, v, mat, rough, metal, base, mi, mf, env, func,
                  total, marg, cond, c, s, light_dir, light_val, brdf_dir, brdf_w, brdf_pdf):
    for i in numba.prange(p.shape[0]):
        key = _path_key(seed, pixel[i], sample, bounce)
        ldir, lval, bdir, bw, pdf_b = _vertex(key, mi, mf, mat[i], p[i, 0], p[i, 1], p[i, 2], ng[i, 0], ng[i, 1],
                                              ng[i, 2], n[i, 0], n[i, 1], n[i, 2], v[i, 0], v[i, 1], v[i, 2],
                                              rough[i], metal[i], base[i, 0], base[i, 1], base[i, 2], env, func,
                                              total, marg, cond, c, s, strategy)
        for a in range(3):
            light_dir[i, a] = ldir[a]
            light_val[i, a] = lval[a]
            brdf_dir[i, a] = bdir[a]
            brdf_w[i, a] = bw[a]
        brdf_pdf[i] = pdf_b


@parallel_kernel
def _miss_batch(strategy, pdf_b, d, env, func, total, c, s, out):
    for i in numba.prange(d.shape[0]):
        le = _env_miss(strategy, pdf_b[i], env, func, total, c, s, d[i, 0], d[i, 1], d[i, 2])
        out[i, 0] = le[0]
        out[i, 1] = le[1]
        out[i, 2] = le[2]


def _wavefront(geometry, env, prim, base_value, k2, n_pixels, spp, bounces, seed, strategy, occlusion, mat_i,
               mat_f):
    func, total, marg, cond = env.distribution
    total_sum = np.zeros((n_pixels, 3))
    total_sq = np.zeros((n_pixels, 3))
    ray_pixel = np.arange(prim.dirs.shape[0]) // k2
    ray_sub = np.arange(prim.dirs.shape[0]) % k2
    for j in range(spp):
        sub = j % k2
        x = base_value[sub::k2].copy()  # rays are pixel-major: ray = pixel * k2 + sub
        sel = np.flatnonzero(ray_sub[prim.rows] == sub)
        rows = prim.rows[sel]
        surf_p = prim.surface.p[sel]
        surf_ng = prim.surface.ng[sel]
        surf_n = prim.surface.n[sel]
        surf_mat = prim.surface.material[sel]
        surf_r = prim.surface.roughness[sel]
        surf_m = prim.surface.metallic[sel]
        surf_b = prim.surface.base_color[sel]
        v = -prim.dirs[rows]
        pix = ray_pixel[rows]
        through = np.ones((rows.size, 3))
        for bounce in range(bounces + 1):
            count = pix.size
            if count == 0:
                break
            ldir = np.empty((count, 3))
            lval = np.empty((count, 3))
            bdir = np.empty((count, 3))
            bw = np.empty((count, 3))
            bpdf = np.empty(count)
            _vertex_batch(seed, j, bounce, strategy, pix.astype(np.int64), np.ascontiguousarray(surf_p),
                          np.ascontiguousarray(surf_ng), np.ascontiguousarray(surf_n), np.ascontiguousarray(v),
                          np.ascontiguousarray(surf_mat), np.ascontiguousarray(surf_r), np.ascontiguousarray(surf_m),
                          np.ascontiguousarray(surf_b), mat_i, mat_f, env.radiance, func, total, marg, cond, env.cos,
                          env.sin, ldir, lval, bdir, bw, bpdf)
            lit = np.flatnonzero(np.any(lval > 0.0, axis=1))
            if lit.size and occlusion:
                lit = lit[~geometry.occluded(geometry.offset_origins(surf_p[lit], surf_ng[lit], ldir[lit]), ldir[lit])]
            np.add.at(x, pix[lit], through[lit] * lval[lit])
            go = np.flatnonzero((bpdf > 0.0) & np.any(bw > 0.0, axis=1))
            if go.size == 0:
                break
            origins = geometry.offset_origins(surf_p[go], surf_ng[go], bdir[go])
            dirs = np.ascontiguousarray(bdir[go])
            through = through[go] * bw[go]
            pix = pix[go]
            hits = geometry.intersect(origins, dirs) if occlusion else None
            miss = np.arange(go.size) if hits is None else np.flatnonzero(~hits.hit)
            if miss.size:
                le = np.empty((miss.size, 3))
                _miss_batch(strategy, np.ascontiguousarray(bpdf[go][miss]), np.ascontiguousarray(dirs[miss]),
                            env.radiance, func, total, env.cos, env.sin, le)
                np.add.at(x, pix[miss], through[miss] * le)
            if hits is None:
                break
            hit = np.flatnonzero(hits.hit)
            if hit.size == 0:
                break
            surface = geometry.surface(hits, origins, dirs, hit)
            np.add.at(x, pix[hit], through[hit] * surface.emissive)
            if bounce == bounces:
                break
            through = through[hit]
            pix = pix[hit]
            v = -dirs[hit]
            if geometry.lights:
                np.add.at(x, pix, through * _punctual(geometry, surface, v, mat_i, mat_f))
            surf_p, surf_ng, surf_n = surface.p, surface.ng, surface.n
            surf_mat, surf_r, surf_m, surf_b = surface.material, surface.roughness, surface.metallic, \
                surface.base_color
        if j == 0:
            shift = x.copy()
        x -= shift
        total_sum += x
        total_sq += x * x
    return shift, total_sum, total_sq


def render_reference(scene, spp=64, bounces=0, seed=0, geometry=None, env=None, strategy="mis", occlusion=True,
                     engine="auto"):
    """Monte Carlo ground truth of ``scene`` (module docstring) with ``spp`` samples per
    pixel.  ``strategy``: ``mis`` (environment + BRDF sampling, power heuristic) or
    ``brdf`` (BRDF sampling only, for comparison).  ``occlusion=False`` lets every
    surface see the whole environment and every light, unblocked by the other
    objects (the assumption of real-time IBL; bounces must then be 0), so that a
    comparison isolates the shading approximations.  Returns a
    :class:`RenderResult` with the per-pixel standard error of the mean.  ``engine``:
    ``auto`` (the fused kernel for scenes of spheres and planes only, else the
    wavefront loop with Embree), ``fused`` or ``wavefront``; both give the same
    numbers for the same scene."""
    if isinstance(spp, bool) or not isinstance(spp, (int, np.integer)) or not 1 <= spp <= 1 << 20:
        raise ValueError(f"spp must be an integer in [1, 1048576]; got {spp!r}")
    if isinstance(bounces, bool) or not isinstance(bounces, (int, np.integer)) or not 0 <= bounces <= 64:
        raise ValueError(f"bounces must be an integer in [0, 64]; got {bounces!r}")
    if strategy not in ("mis", "brdf"):
        raise ValueError(f"unknown strategy {strategy!r}; use 'mis' or 'brdf'")
    if engine not in ("auto", "fused", "wavefront"):
        raise ValueError(f"unknown engine {engine!r}; use 'auto', 'fused' or 'wavefront'")
    if not occlusion and bounces:
        raise ValueError("bounces need occlusion (rays must hit the other objects); use bounces = 0")
    t0 = time.perf_counter()
    geometry = geometry or Geometry(scene)
    env = env or EnvironmentLight(scene.environment)
    func, total, marg, cond = env.distribution
    t1 = time.perf_counter()
    prim = _primary(scene, geometry)
    cam = scene.camera
    k2 = cam.supersample ** 2
    n_pixels = cam.width * cam.height
    mat_i, mat_f = material_tables(geometry.materials)
    s = prim.surface
    v = -prim.dirs[prim.rows]
    # deterministic part of each ray: background, or emission + punctual lights at the hit
    base_value = np.zeros((prim.dirs.shape[0], 3))
    base_value[~prim.hit] = env.background(prim.dirs[~prim.hit])
    if prim.rows.size:
        base_value[prim.rows] = s.emissive + _punctual(geometry, s, v, mat_i, mat_f, None, occlusion)
    t2 = time.perf_counter()
    code = 0 if strategy == "mis" else 1
    if engine == "fused" and geometry.has_meshes:
        raise ValueError("the fused engine handles spheres and planes only; this scene has triangle meshes")
    if geometry.has_meshes or engine == "wavefront":
        shift, total_sum, total_sq = _wavefront(geometry, env, prim, base_value, k2, n_pixels, spp, bounces, seed, code,
                                         bool(occlusion), mat_i, mat_f)
        engine_name = "wavefront" + (" (Embree)" if geometry.has_meshes else "")
    else:
        rays = prim.dirs.shape[0]
        mat = np.full(rays, -1, dtype=np.int64)
        p = np.zeros((rays, 3))
        ng = np.zeros((rays, 3))
        n = np.zeros((rays, 3))
        vv = np.zeros((rays, 3))
        rough = np.zeros(rays)
        metal = np.zeros(rays)
        base = np.zeros((rays, 3))
        mat[prim.rows] = s.material
        p[prim.rows] = s.p
        ng[prim.rows] = s.ng
        n[prim.rows] = s.n
        vv[prim.rows] = v
        rough[prim.rows] = s.roughness
        metal[prim.rows] = s.metallic
        base[prim.rows] = s.base_color
        codes, values = light_arrays(geometry.lights)
        shift = np.zeros((n_pixels, 3))
        total_sum = np.zeros((n_pixels, 3))
        total_sq = np.zeros((n_pixels, 3))
        eps = 1e-7 * geometry.scale
        _fused_kernel(np.uint64(seed), spp, k2, bounces, code, bool(occlusion), base_value, p, ng, n, vv, mat, rough,
                      metal, base, mat_i, mat_f, env.radiance, func, total, marg, cond, env.cos, env.sin, eps,
                      geometry.spheres, *geometry.bvh, geometry.planes,
                      geometry.sphere_material, geometry.plane_material, codes, values, shift, total_sum, total_sq)
        engine_name = "fused (analytic primitives)"
    t3 = time.perf_counter()
    mean_shifted = total_sum / spp
    mean = shift + mean_shifted
    var = np.maximum(total_sq / spp - mean_shifted * mean_shifted, 0.0) * (spp / max(spp - 1, 1))
    stderr = np.sqrt(var / spp)
    image = mean.reshape(cam.height, cam.width, 3)
    stderr = stderr.reshape(cam.height, cam.width, 3)
    mask = prim.hit.reshape(cam.height, cam.width, k2).all(axis=2)
    paths = int(spp * n_pixels)
    surface_paths = int(np.count_nonzero(prim.hit.reshape(n_pixels, k2).any(axis=1))) * spp
    stats = {"mode": "reference", "spp": int(spp), "bounces": int(bounces), "seed": int(seed),
             "strategy": strategy, "occlusion": bool(occlusion), "engine": engine_name, "paths": paths,
             "surface_paths": surface_paths,
             "timings": {"load": t1 - t0, "primary_rays": t2 - t1, "sampling": t3 - t2, "total": t3 - t0},
             "paths_per_second": surface_paths / max(t3 - t2, 1e-9), "pixels": n_pixels}
    return RenderResult(image, mask, stderr, stats)


# ============================================================== tone mapping

_ACES_IN = np.array([[0.59719, 0.35458, 0.04823], [0.07600, 0.90834, 0.01566], [0.02840, 0.13383, 0.83777]])
_ACES_OUT = np.array([[1.60475, -0.53108, -0.07367], [-0.10208, 1.10813, -0.00605], [-0.00327, -0.07276, 1.07602]])
# AgX inset / outset, rows of the matrices acting on column vectors (Wrensch 2023 lists them column-major)
_AGX_IN = np.array([[0.842479062253094, 0.0423282422610123, 0.0423756549057051],
                    [0.0784335999999992, 0.878468636469772, 0.0784336],
                    [0.0792237451477643, 0.0791661274605434, 0.879142973793104]]).T
_AGX_OUT = np.array([[1.19687900512017, -0.0528968517574562, -0.0529716355144438],
                     [-0.0980208811401368, 1.15190312990417, -0.0980434501171241],
                     [-0.0990297440797205, -0.0989611768448433, 1.15107367264116]]).T


def tonemap_aces(x):
    """ACES filmic (RRT + sRGB ODT) as fitted by Stephen Hill (``ACESFitted`` in
    MJP's BakingLab, 2016): input matrix, (v (v + 0.0245786) - 0.000090537) /
    (v (0.983729 v + 0.4329510) + 0.238081), output matrix, clamp to [0, 1]."""
    v = x @ _ACES_IN.T
    v = (v * (v + 0.0245786) - 0.000090537) / (v * (0.983729 * v + 0.4329510) + 0.238081)
    return np.clip(v @ _ACES_OUT.T, 0.0, 1.0)


def tonemap_khronos_neutral(x):
    """Khronos PBR Neutral tone mapper (Khronos 3D Commerce, 2024, reference GLSL):
    offset = x < 0.08 ? x - 6.25 x^2 : 0.04 with x = min(r, g, b); compress the peak
    above 0.76 as 1 - d^2 / (peak + d - 0.76), d = 0.24, and desaturate by
    g = 1 - 1 / (0.15 (peak - new_peak) + 1)."""
    start, desat = 0.8 - 0.04, 0.15
    x = np.asarray(x, dtype=float)
    lo = np.min(x, axis=-1, keepdims=True)
    offset = np.where(lo < 0.08, lo - 6.25 * lo * lo, 0.04)
    c = x - offset
    peak = np.max(c, axis=-1, keepdims=True)
    d = 1.0 - start
    new_peak = 1.0 - d * d / (peak + d - start)
    scaled = c * (new_peak / np.where(peak > 0, peak, 1.0))
    g = 1.0 - 1.0 / (desat * (peak - new_peak) + 1.0)
    mixed = scaled * (1.0 - g) + new_peak * g
    return np.clip(np.where(peak < start, c, mixed), 0.0, 1.0)


def tonemap_agx(x):
    """AgX (T. J. Sobotka) in the "minimal" form of B. Wrensch (iolite engine blog,
    "Minimal AgX Implementation", 2023): inset matrix, log2 encoding over
    [-12.47393, 4.026069] EV, the 6th-order polynomial fit of the default contrast
    sigmoid, outset matrix, and the 2.2 display EOTF to return display-linear values."""
    v = np.maximum(np.asarray(x, dtype=float) @ _AGX_IN.T, 1e-10)
    lo, hi = -12.47393, 4.026069
    v = (np.clip(np.log2(v), lo, hi) - lo) / (hi - lo)
    v2 = v * v
    v4 = v2 * v2
    v = 15.5 * v4 * v2 - 40.14 * v4 * v + 31.96 * v4 - 6.868 * v2 * v + 0.4298 * v2 + 0.1191 * v - 0.00232
    v = v @ _AGX_OUT.T
    return np.clip(np.maximum(v, 0.0) ** 2.2, 0.0, 1.0)


def tonemap_reinhard(x):
    """Reinhard et al. 2002 ("Photographic Tone Reproduction for Digital Images", eq. 3), per channel: x / (1 + x)."""
    x = np.maximum(np.asarray(x, dtype=float), 0.0)
    return x / (1.0 + x)


def tonemap(image, operator="aces", exposure=0.0):
    """Display-linear values in [0, 1] of linear radiance ``image`` (..., 3) scaled by
    2^exposure; encode with the sRGB transfer function for an 8-bit file."""
    if operator not in TONEMAPS:
        raise ValueError(f"unknown tone mapper {operator!r}; choose one of {', '.join(TONEMAPS)}")
    x = np.asarray(image, dtype=float) * (2.0 ** float(exposure))
    if operator == "aces":
        return tonemap_aces(x)
    if operator == "khronos-neutral":
        return tonemap_khronos_neutral(x)
    if operator == "agx":
        return tonemap_agx(x)
    if operator == "reinhard":
        return tonemap_reinhard(x)
    return np.clip(x, 0.0, 1.0)


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


# ============================================================ the command


def _write_outputs(out, panels, tonemap_name, exposure):
    """Write linear panels side by side: EXR (float32, linear; heat maps decoded to
    linear) or PNG (tone-mapped, sRGB)."""
    from .imageio import linear_to_srgb, srgb_to_linear, write_exr, write_png

    suffix = Path(out).suffix.lower()
    if suffix == ".exr":
        pieces = [srgb_to_linear(p) if kind == "srgb" else p for p, kind in panels]
        write_exr(out, np.concatenate(pieces, axis=1).astype(np.float32))
    else:
        pieces = [p if kind == "srgb" else linear_to_srgb(tonemap(p, tonemap_name, exposure)) for p, kind in panels]
        write_png(out, np.concatenate(pieces, axis=1), srgb=False)


def output_suffix_ok(out):
    suffix = Path(out).suffix.lower()
    if suffix not in (".exr", ".png"):
        raise ValueError(f"{out}: output must be .exr (linear float32) or .png (tone-mapped sRGB); got "
                         f"{suffix or 'no suffix'!r}")


def render_scene(scene, out, mode="realtime", spp=64, bounces=0, seed=0, tonemap_name="aces", exposure=0.0,
                 diffuse="sh", energy_compensation=False, bake_size=256, strategy="mis", flip=True, occlusion=True):
    """Render ``scene`` in ``mode`` and write ``out`` (.exr or .png); reference and
    compare modes also write ``<out stem>.stderr.exr``.  Nothing is written unless
    rendering succeeds.  Returns a summary dict (timings, sample counts, errors)."""
    if mode not in MODES:
        raise ValueError(f"unknown mode {mode!r}; choose one of {', '.join(MODES)}")
    if tonemap_name not in TONEMAPS:
        raise ValueError(f"unknown tone mapper {tonemap_name!r}; choose one of {', '.join(TONEMAPS)}")
    if not math.isfinite(float(exposure)):
        raise ValueError(f"exposure must be finite; got {exposure!r}")
    output_suffix_ok(out)
    from .imageio import write_exr

    out = Path(out)
    geometry = Geometry(scene)
    env = EnvironmentLight(scene.environment)
    summary = {"scene": scene.source, "mode": mode, "environment": env.source,
               "width": scene.camera.width, "height": scene.camera.height, "notes": list(geometry.notes)}
    rt = ref = None
    if mode in ("realtime", "compare"):
        rt = render_realtime(scene, geometry, env, diffuse=diffuse, energy_compensation=energy_compensation,
                             bake_size=bake_size)
        summary["realtime"] = rt.stats
    if mode in ("reference", "compare"):
        ref = render_reference(scene, spp=spp, bounces=bounces, seed=seed, geometry=geometry, env=env,
                               strategy=strategy, occlusion=occlusion)
        summary["reference"] = ref.stats
    stderr_path = out.with_name(out.stem + ".stderr.exr")
    if mode == "realtime":
        _write_outputs(out, [(rt.image, "linear")], tonemap_name, exposure)
    elif mode == "reference":
        write_exr(stderr_path, ref.stderr.astype(np.float32))
        _write_outputs(out, [(ref.image, "linear")], tonemap_name, exposure)
    else:
        metrics = compare_images(rt.image, ref.image, rt.mask & ref.mask, ref.stderr, flip=flip)
        heat = error_heatmap(metrics.pop("relative_error_map"), rt.mask & ref.mask)
        write_exr(stderr_path, ref.stderr.astype(np.float32))
        _write_outputs(out, [(rt.image, "linear"), (ref.image, "linear"), (heat, "srgb")], tonemap_name, exposure)
        summary["errors"] = metrics
    summary["outputs"] = [str(out)] + ([str(stderr_path)] if mode != "realtime" else [])
    return summary
