"""Cube-map geometry, layouts, sampling and pyramids (pbrkit.ibl.cubemap).

Directions are checked against the OpenGL 4.6 table 8.19 written out here
independently, solid angles against numerical integration (SciPy), the cross
layouts by the continuity of the unfolded net, and the sampler by continuity
across face edges and by its accuracy on a smooth function.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate

from pbrkit.ibl import cubemap as cm

# OpenGL 4.6 core profile, table 8.19 (also CONVENTIONS.md), written out literally
TABLE = [
    lambda sc, tc: (1.0, -tc, -sc),
    lambda sc, tc: (-1.0, -tc, sc),
    lambda sc, tc: (sc, 1.0, tc),
    lambda sc, tc: (sc, -1.0, -tc),
    lambda sc, tc: (sc, -tc, 1.0),
    lambda sc, tc: (-sc, -tc, -1.0),
]


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def linear_field(d):
    return 1.0 + d @ np.array([0.5, -0.3, 0.2])


# ----------------------------------------------------------------- geometry


@pytest.mark.parametrize("n", [1, 3, 4])
def test_texel_directions_match_table_at_corners_and_centre(n):
    dirs = cm.cube_texel_directions(n)
    assert dirs.shape == (6, n, n, 3)
    for f in range(6):
        for i, j in [(0, 0), (0, n - 1), (n - 1, 0), (n - 1, n - 1), (n // 2, n // 2)]:
            sc, tc = 2 * (j + 0.5) / n - 1, 2 * (i + 0.5) / n - 1
            assert np.allclose(dirs[f, i, j], unit(TABLE[f](sc, tc)), atol=1e-15)


def test_face_centres_and_exact_corners():
    dirs = cm.cube_texel_directions(1)[:, 0, 0]
    assert np.allclose(dirs, [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
    for f in range(6):
        for sc in (-1.0, 1.0):
            for tc in (-1.0, 1.0):
                assert np.array_equal(cm.face_direction(f, sc, tc), TABLE[f](sc, tc))


def test_direction_to_cube_follows_major_axis_rule():
    # OpenGL sec. 8.13: face of the largest |coordinate|, sc/tc from table 8.19 over |ma|
    cases = [((0.5, -0.9, 0.1), 3, 0.5 / 0.9, -0.1 / 0.9),
             ((-0.3, 0.2, 0.8), 4, -0.3 / 0.8, -0.2 / 0.8),
             ((2.0, 1.0, -1.5), 0, 1.5 / 2.0, -1.0 / 2.0),
             ((0.1, 0.2, -0.7), 5, -0.1 / 0.7, -0.2 / 0.7),
             ((-3.0, 0.0, 1.0), 1, 1.0 / 3.0, 0.0)]
    for d, face, sc, tc in cases:
        f, s, t = cm.direction_to_cube(d)
        assert int(f) == face
        assert s == pytest.approx((sc + 1) / 2, abs=1e-15) and t == pytest.approx((tc + 1) / 2, abs=1e-15)
    # ties go to x, then y (documented)
    assert cm.direction_to_cube([1.0, 1.0, 1.0])[0] == 0
    assert cm.direction_to_cube([0.0, -1.0, 1.0])[0] == 3


@settings(max_examples=200, deadline=None)
@given(st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3).filter(lambda v: np.linalg.norm(v) > 1e-3))
def test_direction_round_trip(v):
    f, s, t = cm.direction_to_cube(v)
    assert 0 <= s <= 1 and 0 <= t <= 1
    back = unit(cm.face_direction(int(f), 2 * s - 1, 2 * t - 1))
    assert np.allclose(back, unit(v), atol=1e-12)


def test_texel_centres_map_to_their_texels():
    n = 7
    f, s, t = cm.direction_to_cube(cm.cube_texel_directions(n))
    face, row, col = np.meshgrid(np.arange(6), np.arange(n), np.arange(n), indexing="ij")
    assert np.array_equal(f, face)
    assert np.array_equal(np.floor(t * n), row) and np.array_equal(np.floor(s * n), col)


def test_direction_validation():
    with pytest.raises(ValueError, match="zero or non-finite"):
        cm.direction_to_cube([[0.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match=r"\(\.\.\., 3\)"):
        cm.direction_to_cube([1.0, 2.0])
    with pytest.raises(ValueError, match=r"integer in \[1, 32768\]"):
        cm.cube_texel_directions(0)


# -------------------------------------------------------------- solid angles


@pytest.mark.parametrize("n", [1, 2, 3, 5, 64, 1000])
def test_solid_angles_sum_to_4pi(n):
    omega = cm.cube_texel_solid_angles(n)
    assert omega.shape == (6, n, n) and np.all(omega > 0)
    assert omega.sum() == pytest.approx(4 * np.pi, rel=1e-12)


def test_solid_angles_match_numerical_integration():
    n = 5
    omega = cm.cube_texel_solid_angles(n)
    edges = 2 * np.arange(n + 1) / n - 1
    for i, j in [(0, 0), (2, 2), (1, 4), (4, 3)]:
        # area element of the face plane at unit distance: dA / (1 + x^2 + y^2)^(3/2)
        ref, err = integrate.dblquad(lambda y, x: (1 + x * x + y * y) ** -1.5, edges[j], edges[j + 1],
                                     edges[i], edges[i + 1], epsabs=1e-13, epsrel=1e-12)
        assert omega[0, i, j] == pytest.approx(ref, rel=1e-10)
    # centre texels subtend more than corner texels; the four corners are equal
    assert omega[0, 2, 2] > omega[0, 0, 0] == pytest.approx(omega[0, 4, 4], rel=1e-14)


def test_cube_integral():
    n = 6
    assert cm.cube_integral(np.ones((6, n, n))) == pytest.approx(4 * np.pi, rel=1e-12)
    # integral of d.x over the sphere is 0 and of d.x^2 is 4 pi / 3 (to discretisation error)
    d = cm.cube_texel_directions(48)
    assert cm.cube_integral(d[..., 0] ** 2) == pytest.approx(4 * np.pi / 3, rel=1e-3)


# ------------------------------------------------------------------- crosses


@pytest.mark.parametrize("layout", ["hcross", "vcross"])
def test_cross_round_trip_and_net_continuity(layout):
    n = 8
    dirs = cm.cube_texel_directions(n)
    cross = cm.cube_to_cross(dirs, layout, fill=np.nan)
    assert cross.shape == ((3 * n, 4 * n, 3) if layout == "hcross" else (4 * n, 3 * n, 3))
    assert cm.cross_layout_of(cross.shape) == layout
    assert np.array_equal(cm.cube_from_cross(cross), dirs)
    # the net folds into the cube: every pair of neighbouring pixels of the cross that
    # both hold a face are neighbouring texels on the sphere (angle ~ one texel)
    texel = np.pi / 2 / n
    pairs = 0
    for a, b in [(cross[:, :-1], cross[:, 1:]), (cross[:-1], cross[1:])]:
        both = ~np.isnan(a[..., 0]) & ~np.isnan(b[..., 0])
        angle = np.arccos(np.clip(np.sum(a[both] * b[both], axis=-1), -1, 1))
        assert angle.max() < 1.5 * texel
        pairs += both.sum()
    # 5 folds shared inside the net, each n pixel pairs, plus the pairs within faces
    assert pairs == 6 * 2 * n * (n - 1) + 5 * n


def test_hcross_blocks():
    n = 4
    cross = cm.cube_to_cross(cm.cube_texel_directions(n), "hcross")
    centre = lambda r, c: unit(cross[r * n:(r + 1) * n, c * n:(c + 1) * n].mean(axis=(0, 1)))  # noqa: E731
    expected = {(0, 1): [0, 1, 0], (1, 0): [-1, 0, 0], (1, 1): [0, 0, 1], (1, 2): [1, 0, 0],
                (1, 3): [0, 0, -1], (2, 1): [0, -1, 0]}
    for (r, c), d in expected.items():
        assert np.allclose(centre(r, c), d, atol=1e-12)
    # looking at +Z with +Y up, +X is to the right (OpenGL's mirrored cube-map space)
    z_face = cross[n:2 * n, n:2 * n]
    assert z_face[0, -1, 0] > 0 and z_face[0, 0, 1] > 0


def test_cross_errors():
    with pytest.raises(ValueError, match="not a 4:3"):
        cm.cube_from_cross(np.zeros((10, 10, 3)))
    with pytest.raises(ValueError, match="does not fit"):
        cm.cube_from_cross(np.zeros((30, 40, 3)), "vcross")
    with pytest.raises(ValueError, match="unknown cross layout"):
        cm.cube_to_cross(np.zeros((6, 2, 2, 3)), "strip")


# ------------------------------------------------------------------ sampling


def test_sampler_reproduces_texel_centres():
    rng = np.random.default_rng(0)
    cube = rng.random((6, 5, 5, 2))
    got = cm.sample_cube(cube, cm.cube_texel_directions(5))
    assert np.allclose(got, cube, atol=1e-12)
    assert cm.sample_cube(cube[..., 0], cm.cube_texel_directions(5)).shape == (6, 5, 5)


def test_constant_cube_samples_constant_everywhere():
    cube = np.full((6, 3, 3, 1), 2.5)
    d = np.random.default_rng(1).normal(size=(5000, 3))
    d = np.concatenate([d, [[1, 1, 1], [-1, 1, -1], [1, -1, 1e-9]]])
    assert np.allclose(cm.sample_cube(cube, d), 2.5, atol=1e-14)


def _edge_points(face, u, eps):
    """Directions just inside and just outside edge sc = 1 of ``face`` at tc = u."""
    inside = np.stack(cm.face_direction(face, 1 - eps, u), axis=-1)
    outside = np.stack(cm.face_direction(face, 1 + eps, u), axis=-1)
    return inside, outside


def test_sampler_is_continuous_across_face_edges():
    n = 6
    cube = np.random.default_rng(2).random((6, n, n, 3))
    sampler = cm.CubeSampler(cube)
    u = np.concatenate([np.linspace(-0.999, 0.999, 201), [-1 + 1e-7, 1 - 1e-7]])
    for face in range(6):
        for rot in range(4):  # the four edges, via the symmetric roles of sc and tc
            sc, tc = [(1, u), (-1, u), (u, 1), (u, -1)][rot]
            eps_dir = np.array([(1, 0), (-1, 0), (0, 1), (0, -1)][rot], float) * 1e-9
            inside = np.stack(cm.face_direction(face, sc - eps_dir[0], tc - eps_dir[1]), axis=-1)
            outside = np.stack(cm.face_direction(face, sc + eps_dir[0], tc + eps_dir[1]), axis=-1)
            assert not np.any(cm.direction_to_cube(outside)[0] == face)
            assert np.abs(sampler(inside) - sampler(outside)).max() < 1e-6


def test_bilinear_accuracy_and_seam_semantics():
    n = 32
    cube = linear_field(cm.cube_texel_directions(n))[..., None]
    rng = np.random.default_rng(3)
    d = unit(rng.normal(size=(20000, 3)))
    err = np.abs(cm.sample_cube(cube, d)[:, 0] - linear_field(d))
    f, s, t = cm.direction_to_cube(d)
    near = (np.minimum.reduce([s, 1 - s, t, 1 - t]) < 0.5 / n)  # within half a texel of an edge
    # interior: second-order error; within half a texel of an edge the border
    # texel is the neighbour's edge texel (as in GPU seamless filtering), which
    # sits up to half a texel along the edge from where bilinear assumes it: O(1/N)
    assert err[~near].max() < 0.25 * (2.0 / n) ** 2
    assert err[near].max() < 0.25 * (2.0 / n)
    # on a shared edge, at a texel-row centre, the sample is the mean of the two edge texels
    cube = rng.random((6, 4, 4))
    i = 1
    tc = 2 * (i + 0.5) / 4 - 1
    on_edge = np.stack(cm.face_direction(0, 1.0, tc), axis=-1)  # +X, sc = 1: shared with -Z at sc = -1
    assert cm.sample_cube(cube, on_edge) == pytest.approx(0.5 * (cube[0, i, 3] + cube[5, i, 0]), abs=1e-14)


def test_trilinear_lod():
    n = 8
    cube = np.random.default_rng(4).random((6, n, n, 3))
    pyramid = cm.build_mip_pyramid(cube)
    sampler = cm.CubeSampler(pyramid)
    d = unit(np.random.default_rng(5).normal(size=(300, 3)))
    l0, l1 = sampler(d, 0.0), sampler(d, 1.0)
    assert np.allclose(l1, cm.sample_cube(pyramid[1], d), atol=1e-14)
    assert np.allclose(sampler(d, 0.25), 0.75 * l0 + 0.25 * l1, atol=1e-14)
    assert np.allclose(sampler(d, 99.0), cm.sample_cube(pyramid[-1], d), atol=1e-14)
    assert np.allclose(sampler(d, -3.0), l0)
    lods = np.where(np.arange(300) % 2 == 0, 0.0, 1.0)
    assert np.allclose(sampler(d, lods), np.where(lods[:, None] == 0, l0, l1))
    with pytest.raises(ValueError, match="expected"):
        cm.CubeSampler([cube, cube])


# ------------------------------------------------------------------ pyramids


def test_mip_pyramid_solid_angle_weighting_keeps_the_integral():
    cube = np.random.default_rng(6).random((6, 16, 16, 2))
    levels = cm.build_mip_pyramid(cube)
    assert [lv.shape[1] for lv in levels] == [16, 8, 4, 2, 1]
    for lv in levels:
        assert np.allclose(cm.cube_integral(lv), cm.cube_integral(cube), rtol=1e-13)
    assert len(cm.build_mip_pyramid(np.ones((6, 12, 12)))) == 3  # 12, 6, 3: odd ends the chain


def test_mip_pyramid_box_is_only_approximately_conservative():
    cube = np.random.default_rng(7).random((6, 16, 16, 1))
    box = cm.build_mip_pyramid(cube, weighting="box")
    rel = abs(cm.cube_integral(box[1])[0] / cm.cube_integral(cube)[0] - 1)
    assert 1e-5 < rel < 1.0 / 16
    assert np.allclose(cm.build_mip_pyramid(np.ones((6, 4, 4)), weighting="box")[2], 1.0)
    with pytest.raises(ValueError, match="weighting"):
        cm.build_mip_pyramid(cube, weighting="gauss")


def test_resample_cube():
    cube = linear_field(cm.cube_texel_directions(12))[..., None]
    exact = cm.resample_cube(cube, 4)  # block mean: the integral is kept exactly
    assert np.allclose(cm.cube_integral(exact), cm.cube_integral(cube), rtol=1e-13)
    for size in (5, 9, 17):  # supersampled gather: constants exact, integral close
        assert np.allclose(cm.resample_cube(np.ones((6, 12, 12)), size), 1.0, atol=1e-13)
        out = cm.resample_cube(cube, size)
        assert np.allclose(cm.cube_integral(out), cm.cube_integral(cube), rtol=2e-3)
        assert np.abs(out[..., 0] - linear_field(cm.cube_texel_directions(size))).max() < 0.02
