"""Charlie-prefiltered cube chains: the sheen environment of ``KHR_materials_sheen``
image-based lighting, as the Khronos glTF IBL Sampler bakes it (its ``charlie``
distribution; KhronosGroup/glTF-IBL-Sampler ``filter.frag``, and the same filter in
the Sample Viewer's own ``ibl_filtering.frag``) and the Sample Viewer samples it
(``getIBLRadianceCharlie``: lod = sheenRoughness (u_MipCount - 1), the mirror
direction, times the sheen LUT's blue channel).

What a level holds.  The split-sum assumption n = v = r of the GGX chain
(:mod:`pbrkit.ibl.prefilter`, Karis 2013) with the Charlie distribution in place of
GGX::

    S(n; alpha) = integral of L(l) D_C(h) (n.l) dl / integral of D_C(h) (n.l) dl,

over n.l > 0, h = normalize(n + l), D_C the Charlie distribution of Estevez and
Kulla 2017, eq. 2 (:func:`pbrkit.microfacet.charlie.d_charlie`), alpha =
sheenRoughness^2 (:func:`pbrkit.microfacet.charlie.charlie_alpha`, the
specification's ``alpha_g``).  As for GGX, n.h = cos(theta / 2) for the angle theta
between n and l, so S is the convolution of L with the zonal kernel
D_C(cos(theta / 2)) cos(theta) on theta < pi / 2 (:func:`charlie_prefilter_kernel`).
Unlike GGX's, this kernel is a ring: D_C grows with sin(theta_h), so for a small
sheen roughness the weight sits just above the horizon of n (theta near pi / 2), and
as alpha -> 0 the normalised kernel tends to the uniform distribution on the great
circle orthogonal to n (the limit :func:`charlie_sample_set` uses at roughness 0).

Level curve.  The chain has as many levels M as the bake's GGX chain, level m at
sheen roughness m / (M - 1) (:func:`pbrkit.ibl.prefilter.roughness_of_level`, the
linear curve of the generic and Khronos chains: the IBL Sampler's ``cubeMapToSheen``
filters level m at ``m / (mipmapLevels - 1)`` exactly as its GGX chain, and the
Sample Viewer reads both with the one ``u_MipCount``).  Sizes halve from a base
size that may be smaller than the GGX chain's (:func:`sheen_chain_sizes`): the
kernel is wide at every level but the first, whose content is a ring average.

Method.  Filtered importance sampling (Krivanek and Colbert 2008; GPU Gems 3,
ch. 20.4) with :func:`pbrkit.ibl.prefilter.prefilter_level` (the GGX chain's
kernel, its lod rule 0.5 log2(Omega_s / Omega_p) + bias and n.l weights) of the
solid-angle mip pyramid of the bake's level-0 cube, with half vectors from
:func:`pbrkit.microfacet.charlie.warp_charlie_ndf` (the IBL Sampler's ``Charlie``:
sin theta_h = u^(alpha / (2 alpha + 1))) and l = reflect(n, h).  The IBL Sampler
draws u over [0, 1] and drops the samples with n.l <= 0; since D_C puts most of
its mass at theta_h > 45 degrees, that drops all but a few of its 64 samples at
low roughness (at sheenRoughness 0.25, every sample but u = 0).  Here u is drawn
over [0, u_max], u_max = 2^(-(2 alpha + 1) / (2 alpha)) the lobe's cumulative
distribution at theta_h = 45 degrees (where l reaches the horizon), so every
sample lands above the horizon; the weighted mean converges to the same S (the
sampled density is D_C (n.h) / u_max on the admissible half vectors), and the
lod takes that density: pdf(l) = D_C / (4 u_max) with n = v (the IBL Sampler's
D_C / 4 before it drops samples).
"""

from __future__ import annotations

import math

import numpy as np

from ..core import checks
from ..core.jit import dual_use, select
from ..microfacet.charlie import charlie_alpha, d_charlie, pdf_charlie_ndf, warp_charlie_ndf
from ..sampling.low_discrepancy import hammersley
from ..sampling.warps import pdf_light_from_half, reflect_xyz
from .cubemap import CubeSampler, _as_cube, _block_reduce, build_mip_pyramid, cube_texel_directions
from .prefilter import SampleSet, prefilter_level, roughness_of_level

__all__ = [
    "SHEEN_SAMPLES",
    "SHEEN_MAX_BASE_SIZE",
    "RING_SAMPLES",
    "SHEEN_LOD_BIAS",
    "charlie_prefilter_kernel",
    "charlie_admissible_fraction",
    "charlie_sample_set",
    "sheen_chain_sizes",
    "prefilter_charlie",
]

#: Charlie samples per texel of every level but the first (the Sample Viewer's
#: ``sheenSamplCount`` is 64, of which it keeps only those above the horizon).  Against
#: a 12-degree cap of light (tests/ibl/test_ibl_sheen.py) the largest error of a level was
#: 43-55 % of its peak with 64 samples, 13-20 % with 256, 3-7 % with 1024; the mean
#: 5 %, 1.2-1.9 %, 0.4-0.6 %.  The first level (the horizon ring) takes :data:`RING_SAMPLES`.
SHEEN_SAMPLES = 256
#: Lod bias of the sheen chain's lookups: 0, the IBL Sampler's default (``lodBias``), where
#: the GGX chain's filtered importance sampling takes Krivanek and Colbert's 1: the Charlie
#: kernel is wide, and bias 1 blurs it further (the mean n.l of a level, 0.27 at sheen
#: roughness 1/3, came out 0.22 with bias 1 and 0.245 with 0; tests/ibl/test_ibl_sheen.py).
SHEEN_LOD_BIAS = 0.0
#: Directions on the horizon circle for the roughness-0 level (its limit).
RING_SAMPLES = 32
#: Largest base size of a sheen chain (when the GGX chain's levels allow it).
SHEEN_MAX_BASE_SIZE = 32


@dual_use
def charlie_prefilter_kernel(theta, alpha):
    """Unnormalised Charlie prefilter kernel D_C(n.h) (n.l) for l at angle theta from
    n = v: n.h = cos(theta / 2), n.l = cos(theta), zero for theta >= pi / 2 (module
    doc; D_C = :func:`pbrkit.microfacet.charlie.d_charlie`, Estevez and Kulla 2017,
    eq. 2).  alpha = sheenRoughness^2."""
    c = np.cos(theta)
    return select(c > 0.0, d_charlie(np.cos(0.5 * theta), alpha) * c, 0.0)


def charlie_admissible_fraction(alpha):
    """u_max = sin(45 deg)^(2 + 1 / alpha) = 2^(-(2 alpha + 1) / (2 alpha)): the
    probability that :func:`pbrkit.microfacet.charlie.warp_charlie_ndf` gives a half
    vector within 45 degrees of n, i.e. l = reflect(n, h) above the horizon (its
    cumulative distribution sin(theta_h)^(2 + 1 / alpha), Estevez and Kulla 2017,
    eq. 2).  alpha = sheenRoughness^2; 0 where it underflows."""
    a = float(alpha)
    return float(2.0 ** (-(2.0 * a + 1.0) / (2.0 * a)))


def _ring_sample_set(count, bias):
    # the alpha -> 0 limit: l uniform on the great circle orthogonal to n, equal weights;
    # each sample stands for a square patch of the ring's length over count
    phi = 2.0 * math.pi * (np.arange(count) + 0.5) / count
    l = np.stack([np.cos(phi), np.sin(phi), np.zeros(count)], axis=-1)
    omega = (2.0 * math.pi / count) ** 2
    lod = np.full(count, 0.5 * math.log2(omega) + bias)
    return SampleSet(np.ascontiguousarray(l), np.ones(count), lod, int(count), 0.0, 0.0, float(bias))


def charlie_sample_set(roughness, count=SHEEN_SAMPLES, bias=1.0):
    """The filtered-importance-sampling pattern (a :class:`pbrkit.ibl.prefilter.
    SampleSet`, normal +z) of ``count`` Hammersley points for sheen roughness
    ``roughness`` (module doc): h from :func:`pbrkit.microfacet.charlie.
    warp_charlie_ndf` at u = u1 u_max (:func:`charlie_admissible_fraction`), l =
    reflect(n, h) (v = n = +z), weights n.l, lod offsets 0.5 log2(1 / (count pdf(l)))
    + bias with pdf(l) = :func:`pbrkit.sampling.warps.pdf_light_from_half` of
    :func:`pbrkit.microfacet.charlie.pdf_charlie_ndf` / u_max.  alpha =
    sheenRoughness^2 (:func:`pbrkit.microfacet.charlie.charlie_alpha`).  At a roughness
    whose u_max underflows (0 included) the limit of the normalised kernel:
    min(``count``, :data:`RING_SAMPLES`) directions evenly spaced on the horizon circle, equal weights."""
    count = checks.integer(count, "sample count", 1, 1 << 20)
    r = float(roughness)
    if not 0.0 <= r <= 1.0:
        raise ValueError(f"sheen roughness must be in [0, 1], got {roughness!r}")
    alpha = float(charlie_alpha(r))
    u_max = charlie_admissible_fraction(alpha)
    if u_max <= 1e-300:
        ss = _ring_sample_set(min(count, RING_SAMPLES), bias)
        ss.roughness, ss.alpha, ss.ring = r, alpha, True
        return ss
    u = hammersley(count, 2)
    # u1 at the centres (i + 0.5) / count of its strata: the Hammersley point u1 = 0 is h = n,
    # where D_C and the pdf vanish (sin theta_h = 0) and its lod would be infinite
    hx, hy, hz = warp_charlie_ndf((u[:, 0] + 0.5 / count) * u_max, u[:, 1], alpha)
    lx, ly, lz = reflect_xyz(0.0, 0.0, 1.0, hx, hy, hz)
    keep = lz > 0.0  # all but rounding at theta_h = 45 degrees
    pdf = pdf_light_from_half(pdf_charlie_ndf(hz[keep], alpha) / u_max, hz[keep])
    lod = 0.5 * np.log2(1.0 / (count * pdf)) + bias
    l = np.stack([lx, ly, lz], axis=-1)[keep]
    l /= np.linalg.norm(l, axis=-1, keepdims=True)
    return SampleSet(np.ascontiguousarray(l), np.ascontiguousarray(lz[keep]), np.ascontiguousarray(lod),
                     int(count), r, alpha, float(bias))


def sheen_chain_sizes(size, levels, max_base=SHEEN_MAX_BASE_SIZE):
    """Face sizes of the M = ``levels`` levels of a sheen chain beside a GGX chain of
    base ``size``: from min(size, max(``max_base``, 2^(M - 1))) down by halves (M
    levels, the last at least 1 x 1, the same level count the Sample Viewer's
    ``u_MipCount`` assumes)."""
    size = checks.power_of_two(size, "cube size", 1, 1 << 16)
    levels = checks.integer(levels, "levels of a sheen chain", 2, 17)
    base = min(size, max(int(max_base), 1 << (levels - 1)))
    if base >> (levels - 1) < 1:
        raise ValueError(f"a {size} x {size} cube cannot hold {levels} halving levels")
    return [base >> m for m in range(levels)]


def prefilter_charlie(cube, levels, max_base=SHEEN_MAX_BASE_SIZE, samples=SHEEN_SAMPLES, bias=SHEEN_LOD_BIAS,
                      progress=None):
    """The M = ``levels`` levels of the Charlie-prefiltered chain of the level-0 cube
    ``cube`` (6, N, N, C) (module doc): level m at sheen roughness m / (M - 1)
    (:func:`pbrkit.ibl.prefilter.roughness_of_level`), size from
    :func:`sheen_chain_sizes`, each texel the filtered-importance-sampling estimate
    (:func:`pbrkit.ibl.prefilter.prefilter_level`) with :func:`charlie_sample_set`
    (``samples`` per texel, lod ``bias``) over the solid-angle mip pyramid of
    ``cube`` reduced to the base size (blocks averaged with their texels' exact solid
    angles, as :func:`pbrkit.ibl.cubemap.build_mip_pyramid` reduces).  Returns
    (levels (6, n_m, n_m, C) float32, roughness (M,), info dicts)."""
    sizes = sheen_chain_sizes(np.shape(cube)[1], levels, max_base)
    # the pyramid from the chain's base size on: the lobes' footprints are coarser than its
    # texels at every level (lod >= 2 at sheen roughness 1 / (M - 1) for 64 samples)
    c = _as_cube(cube)
    source = c if c.shape[1] == sizes[0] else _block_reduce(c, c.shape[1] // sizes[0], "solid_angle")
    sampler = CubeSampler(build_mip_pyramid(source))
    roughness = np.array([roughness_of_level(m, levels) for m in range(levels)])
    chain, info = [], []
    for m, n in enumerate(sizes):
        ss = charlie_sample_set(roughness[m], samples, bias)
        values = prefilter_level(sampler, cube_texel_directions(n).reshape(-1, 3), ss)
        chain.append(values.reshape(6, n, n, -1).astype(np.float32))
        info.append(dict(level=m, size=n, sheen_roughness=float(roughness[m]), alpha=ss.alpha,
                         samples=ss.count, samples_used=ss.used, lod_bias=ss.bias,
                         method=("the alpha -> 0 limit: the mean over the horizon circle of n, "
                                 f"{ss.count} points" if getattr(ss, "ring", False) else
                                 f"filtered importance sampling, {ss.count} Hammersley Charlie samples "
                                 f"above the horizon, lod bias {ss.bias:g}")))
        if progress is not None:
            progress(m)
    return chain, roughness, info
