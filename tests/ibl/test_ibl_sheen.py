"""The Charlie-prefiltered (sheen) chain, pbrkit.ibl.sheen: the white furnace (a
constant environment stays that constant at every level), an environment linear in
the direction against the Charlie-weighted mean direction by scipy quadrature of the
zonal kernel D(cos(theta / 2)) cos(theta) (tests/support/sheen_reference.py's transcription of
the specification's D), a bright cap against Gauss-Legendre quadrature of the
Charlie-weighted integral over it, the
samples (all above the horizon, the roughness-0 ring), the sizes, determinism and
refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate
from sheen_reference import spec_d

from pbrkit.ibl.cubemap import cube_texel_directions
from pbrkit.ibl.sheen import SHEEN_SAMPLES, charlie_sample_set, prefilter_charlie, sheen_chain_sizes

LEVELS = 4
SIZE = 64


def _kernel(theta, r):
    """The prefilter kernel in l (n = v): D(h) (n.l), n.h = cos(theta / 2)."""
    return spec_d(math.cos(0.5 * theta), r) * math.cos(theta)


def mean_cosine(r):
    """The Charlie-weighted mean of n.l: integral of k cos sin / integral of k sin over theta < pi / 2."""
    points = [0.5 * math.pi - d for d in (0.3, 0.1, 0.03)]
    num, _ = integrate.quad(lambda t: _kernel(t, r) * math.cos(t) * math.sin(t), 0.0, 0.5 * math.pi, points=points,
                            limit=200, epsabs=1e-13)
    den, _ = integrate.quad(lambda t: _kernel(t, r) * math.sin(t), 0.0, 0.5 * math.pi, points=points, limit=200,
                            epsabs=1e-13)
    return num / den


def test_furnace_every_level_is_the_constant():
    value = np.array([0.5, 2.0, 7.25], np.float32)
    cube = np.broadcast_to(value, (6, SIZE, SIZE, 3)).copy()
    chain, roughness, info = prefilter_charlie(cube, LEVELS)
    assert len(chain) == LEVELS and list(roughness) == [0.0, 1 / 3, 2 / 3, 1.0]
    for level in chain:
        np.testing.assert_allclose(level, np.broadcast_to(value, level.shape), rtol=1e-6)
    assert "horizon circle" in info[0]["method"] and info[1]["samples_used"] == info[1]["samples"] == SHEEN_SAMPLES


def test_linear_environment_against_quadrature():
    """L(w) = a + b.w: the chain holds a + (b.n) c(alpha), c the kernel's mean n.l (0 for the
    roughness-0 ring, whose mean direction is 0)."""
    a, b = 1.0, np.array([0.3, -0.5, 0.4])
    cube = (a + cube_texel_directions(SIZE) @ b)[..., None].repeat(3, axis=-1).astype(np.float32)
    chain, roughness, _ = prefilter_charlie(cube, LEVELS)
    for level, r in zip(chain, roughness):
        c = 0.0 if r == 0.0 else mean_cosine(r)
        n = level.shape[1]
        want = a + (cube_texel_directions(n) @ b) * c
        err = np.abs(level[..., 0] - want)
        # the mip pyramid's texel averages shrink the linear part at coarse lods (by 1 to 3 %)
        assert err.max() < 0.01 and err.mean() < 0.004, (r, c, err.max(), err.mean())
        if r:
            fit = np.sum((level[..., 0] - a) * (want - a)) / np.sum((want - a) ** 2)
            assert fit == pytest.approx(1.0, abs=0.04), (r, fit)


def cap_reference(directions, axis, radius, radiance, r):
    """radiance times the integral over the cap (angular radius ``radius`` about ``axis``)
    of the normalised kernel k(angle(n, l)) / Z, by Gauss-Legendre in the cap's polar
    coordinates (24 x 48 nodes) and Z by scipy."""
    z, _ = integrate.quad(lambda t: 2.0 * math.pi * _kernel(t, r) * math.sin(t), 0.0, 0.5 * math.pi, limit=200)
    x, w = np.polynomial.legendre.leggauss(24)
    psi, w_psi = 0.5 * radius * (x + 1.0), 0.5 * radius * w
    x, w = np.polynomial.legendre.leggauss(48)
    phi, w_phi = math.pi * (x + 1.0), math.pi * w
    p, f = np.meshgrid(psi, phi, indexing="ij")
    weights = np.outer(w_psi * np.sin(psi), w_phi).ravel()
    t1 = np.cross(axis, [0.0, 0.0, 1.0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(axis, t1)
    l = (np.cos(p)[..., None] * axis + np.sin(p)[..., None] * (np.cos(f)[..., None] * t1
                                                             + np.sin(f)[..., None] * t2)).reshape(-1, 3)
    c = np.clip(directions @ l.T, -1.0, 1.0)
    k = np.where(c > 0.0, spec_d(np.cos(0.5 * np.arccos(c)), r) * c, 0.0)
    return radiance * (k * weights).sum(axis=1) / z


def test_bright_cap_against_quadrature():
    """A cap of angular radius 12 degrees and radiance 10: every level against the
    quadrature of the Charlie-weighted integral over the cap; filtered importance
    sampling with 256 samples is within 25 % of the level's peak everywhere and 2.5 %
    on average (64 samples: 55 % and 5.4 %, as the IBL Sampler's count)."""
    d = cube_texel_directions(SIZE)
    axis = np.array([0.3, 0.8, -0.52])
    axis /= np.linalg.norm(axis)
    cube = np.where(d @ axis > math.cos(math.radians(12.0)), 10.0, 0.0)[..., None].repeat(3, axis=-1)
    chain, roughness, _ = prefilter_charlie(cube.astype(np.float32), LEVELS)
    for m in range(1, LEVELS):
        want = cap_reference(cube_texel_directions(chain[m].shape[1]).reshape(-1, 3), axis, math.radians(12.0),
                             10.0, roughness[m])
        err = np.abs(chain[m][..., 1].ravel() - want) / want.max()
        assert err.max() < 0.25 and err.mean() < 0.025, (m, err.max(), err.mean())


def test_samples_lie_above_the_horizon():
    for r in (0.1, 1 / 3, 2 / 3, 1.0):
        ss = charlie_sample_set(r, 64)
        assert ss.used == 64 and np.all(ss.l[:, 2] > 0.0) and np.all(np.isfinite(ss.lod_offset))
        np.testing.assert_allclose(np.linalg.norm(ss.l, axis=1), 1.0, rtol=1e-12)
        # the sample mean of n.l is the kernel's, with n.l weights the weighted mean of n.l is
        # E[(n.l)^2] / E[n.l]; check the plain mean against the kernel's density D / 4 (no n.l)
        points = [0.5 * math.pi - dd for dd in (0.3, 0.1, 0.03)]
        num, _ = integrate.quad(lambda t: spec_d(math.cos(0.5 * t), r) * math.cos(t) * math.sin(t), 0.0,
                                0.5 * math.pi, points=points, limit=200)
        den, _ = integrate.quad(lambda t: spec_d(math.cos(0.5 * t), r) * math.sin(t), 0.0, 0.5 * math.pi,
                                points=points, limit=200)
        assert float(np.mean(ss.l[:, 2])) == pytest.approx(num / den, rel=0.03, abs=2e-3), r
    ring = charlie_sample_set(0.0, 64)
    assert np.all(ring.l[:, 2] == 0.0) and np.all(ring.weight == 1.0) and ring.used == 32


def test_sizes():
    assert sheen_chain_sizes(256, 5) == [32, 16, 8, 4, 2]
    assert sheen_chain_sizes(16, 2) == [16, 8]
    assert sheen_chain_sizes(4096, 9) == [256 >> m for m in range(9)]
    with pytest.raises(ValueError, match="cannot hold"):
        sheen_chain_sizes(4, 4)


def test_deterministic():
    rng = np.random.default_rng(7)
    cube = rng.random((6, 32, 32, 3)).astype(np.float32)
    a, _, _ = prefilter_charlie(cube, 3)
    b, _, _ = prefilter_charlie(cube, 3)
    assert all(x.tobytes() == y.tobytes() for x, y in zip(a, b))


def test_refusals():
    with pytest.raises(ValueError, match="sheen roughness must be in"):
        charlie_sample_set(1.5)
    with pytest.raises(ValueError, match="sample count"):
        charlie_sample_set(0.5, 0)
    with pytest.raises(ValueError, match="levels of a sheen chain"):
        prefilter_charlie(np.ones((6, 8, 8, 3), np.float32), 1)
