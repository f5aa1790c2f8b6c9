"""Environment loading and equirect <-> cube conversion (pbrkit.ibl.equirect).

The exact resampler is checked against independent references: an analytic
linear radiance field (texel means from Arvo's closed-form vector integral
over a spherical polygon), equal-area stratified sampling of a one-pixel sun,
masks that must land on the faces CONVENTIONS.md assigns them, and the
integral over the sphere.  Every error path of ``load_environment`` is hit
with a synthetic file written to tmp_path; the real maps of shared/data are
used when present.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numba
import numpy as np
import pytest
from skips import needs_shared_data

from pbrkit.core.color import linear_to_srgb, srgb_to_linear
from pbrkit.core.errors import InputError
from pbrkit.ibl import cubemap as cm
from pbrkit.ibl.equirect import (
    cube_to_equirect,
    direction_angles,
    direction_to_equirect,
    equirect_angles_of_uv,
    equirect_direction,
    equirect_directions,
    equirect_integral,
    equirect_pixel_angles,
    equirect_solid_angles,
    equirect_to_cube,
    equirect_uv,
)
from pbrkit.io.environment import (
    IgnoredAlphaWarning,
    NegativeRadianceWarning,
    fix_nonfinite_pixels,
    load_environment,
)
from pbrkit.io.hdr import hdr_bytes
from pbrkit.io.image_checks import LDRInputWarning
from pbrkit.io.images import write_image
from pbrkit.io.png import write_png

DATA = Path(__file__).resolve().parents[3] / "shared" / "data"
ENV = DATA / "env"
needs_data = needs_shared_data("env")
A = np.array([0.5, -0.3, 0.2])  # gradient of the linear test field L = 1 + A.d


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


# ----------------------------------------------------------- equirect geometry


def test_equirect_directions_follow_conventions():
    h = 8
    d = equirect_directions(h)
    assert d.shape == (h, 2 * h, 3)
    theta = np.pi * 0.5 / h
    phi = 2 * np.pi * 0.5 / (2 * h) - np.pi
    assert np.allclose(d[0, 0], [np.sin(theta) * np.cos(phi), np.cos(theta), np.sin(theta) * np.sin(phi)])
    assert np.allclose(np.linalg.norm(d, axis=-1), 1.0)
    # image centre is +X on the horizon, u = 0.25 is -Z, u = 0.75 is +Z (three.js / Khronos)
    u, v = direction_to_equirect(np.array([[1, 0, 0], [0, 0, -1], [0, 0, 1], [0, 1, 0], [0, -2, 0]]))
    assert np.allclose(u[:3], [0.5, 0.25, 0.75]) and np.allclose(v, [0.5, 0.5, 0.5, 0.0, 1.0])
    # pixel centres map back to their pixels
    u, v = direction_to_equirect(d)
    rows, cols = np.meshgrid(np.arange(h), np.arange(2 * h), indexing="ij")
    assert np.array_equal(np.floor(v * h), rows) and np.array_equal(np.floor(u * 2 * h), cols)


def test_equirect_mapping_helpers_by_hand():
    # pixel centres of a 4 x 8 map: theta = pi (i + 0.5) / 4, phi = 2 pi (j + 0.5) / 8 - pi
    theta, phi = equirect_pixel_angles(np.arange(4), np.arange(8), 4, 8)
    assert np.allclose(theta, [np.pi / 8, 3 * np.pi / 8, 5 * np.pi / 8, 7 * np.pi / 8])
    assert np.allclose(phi, -np.pi + np.pi / 8 + np.arange(8) * np.pi / 4)
    # axes (CONVENTIONS.md): +Y is theta = 0; +X is phi = 0 (u = 0.5), -Z is phi = -pi/2 (u = 0.25), +Z u = 0.75
    axes = {(1, 0, 0): (np.pi / 2, 0.0, 0.5, 0.5), (0, 0, -1): (np.pi / 2, -np.pi / 2, 0.25, 0.5),
            (0, 0, 1): (np.pi / 2, np.pi / 2, 0.75, 0.5), (-1, 0, 0): (np.pi / 2, np.pi, 1.0, 0.5),
            (0, 1, 0): (0.0, 0.0, 0.5, 0.0), (0, -1, 0): (np.pi, 0.0, 0.5, 1.0)}
    for d, (t, p, u, v) in axes.items():
        assert np.allclose(direction_angles(*map(float, d)), (t, p))
        assert np.allclose(equirect_uv(*map(float, d)), (u, v))
        assert np.allclose(equirect_direction(t, p), d, atol=1e-15)
        assert np.allclose(equirect_angles_of_uv(u, v), (t, p))
    # round trips on random directions, NumPy and compiled alike
    rng = np.random.default_rng(4)
    d = unit(rng.normal(size=(1000, 3)))
    u, v = equirect_uv(d[:, 0], d[:, 1], d[:, 2])
    assert np.allclose(np.stack(equirect_direction(*equirect_angles_of_uv(u, v)), axis=-1), d, atol=1e-14)

    @numba.njit
    def compiled(d, out):
        for k in range(d.shape[0]):
            uu, vv = equirect_uv(d[k, 0], d[k, 1], d[k, 2])
            x, y, z = equirect_direction(*equirect_angles_of_uv(uu, vv))
            t, p = equirect_pixel_angles(k % 7, k % 13, 7, 14)
            out[k] = (uu, vv, x, y, z, t, p)

    out = np.zeros((d.shape[0], 7))
    compiled(d, out)
    t, p = equirect_pixel_angles(np.arange(1000) % 7, np.arange(1000) % 13, 7, 14)
    assert np.allclose(out, np.column_stack([u, v, d, t, p]), rtol=1e-14, atol=1e-14)


@pytest.mark.parametrize("h", [4, 64, 512])
def test_equirect_solid_angles(h):
    exact = equirect_solid_angles(h, exact=True)
    midpoint = equirect_solid_angles(h)
    assert exact.shape == midpoint.shape == (h, 2 * h)
    assert exact.sum() == pytest.approx(4 * np.pi, rel=1e-13)
    theta = np.pi * (np.arange(h) + 0.5) / h
    assert np.allclose(midpoint[:, 0], (2 * np.pi / (2 * h)) * (np.pi / h) * np.sin(theta), rtol=1e-15)
    # cell area / midpoint value is the same sinc(pi / 2H) in every row
    ratio = exact[:, 0] / midpoint[:, 0]
    x = np.pi / (2 * h)
    assert np.allclose(ratio, np.sin(x) / x, rtol=1e-12)


def test_equirect_integral_constant_and_linear():
    img = np.ones((32, 64, 2))
    assert np.allclose(equirect_integral(img, exact=True), 4 * np.pi, rtol=1e-13)
    d = equirect_directions(256)
    # the integral of a linear field over the sphere is 4 pi (odd part vanishes)
    assert equirect_integral(1.0 + d @ A) == pytest.approx(4 * np.pi, rel=1e-4)


# ------------------------------------------------------- equirect -> cube


@pytest.mark.parametrize("h, n", [(8, 3), (16, 5), (6, 4), (5, 7), (64, 16), (1, 1)])
def test_constant_map_stays_constant(h, n):
    img = np.full((h, 2 * h, 2), 3.0)
    cube = equirect_to_cube(img, n)
    assert cube.shape == (6, n, n, 2)
    assert np.allclose(cube, 3.0, rtol=1e-12)


@pytest.mark.parametrize("h, n", [(8, 3), (10, 9), (64, 16), (48, 5)])
def test_energy_is_conserved_exactly(h, n):
    img = np.random.default_rng(h * n).random((h, 2 * h, 3)) ** 4
    cube = equirect_to_cube(img, n)
    assert np.allclose(cm.cube_integral(cube), equirect_integral(img, exact=True), rtol=1e-12)


def _cell_mean_of_linear_field(h):
    """Exact mean of L = 1 + A.d over every lat-long cell (closed form)."""
    w = 2 * h
    t = np.pi * np.arange(h + 1) / h
    p = 2 * np.pi * np.arange(w + 1) / w - np.pi
    sin2 = (t[1:] - t[:-1]) / 2 - (np.sin(2 * t[1:]) - np.sin(2 * t[:-1])) / 4  # integral sin^2
    sincos = (np.sin(t[1:]) ** 2 - np.sin(t[:-1]) ** 2) / 2
    dphi = p[1:] - p[:-1]
    vx = sin2[:, None] * (np.sin(p[1:]) - np.sin(p[:-1]))[None, :]
    vy = sincos[:, None] * dphi[None, :]
    vz = sin2[:, None] * (np.cos(p[:-1]) - np.cos(p[1:]))[None, :]
    area = (np.cos(t[:-1]) - np.cos(t[1:]))[:, None] * dphi[None, :]
    return 1.0 + (A[0] * vx + A[1] * vy + A[2] * vz) / area


def _texel_mean_of_linear_field(n):
    """1 + A.V / Omega per texel, with V = integral of d over the texel from
    Arvo's formula for a spherical polygon with counter-clockwise vertices
    (seen from outside): V = 1/2 sum_k angle(v_k, v_k+1) normalize(v_k x v_k+1)
    (J. Arvo, "Applications of irradiance tensors to the simulation of
    non-Lambertian phenomena", SIGGRAPH 1995)."""
    out = np.empty((6, n, n))
    omega = cm.cube_texel_solid_angles(n)
    e = 2 * np.arange(n + 1) / n - 1
    for f in range(6):
        for i in range(n):
            for j in range(n):
                # (s, t) order is clockwise from outside; reverse it
                corners = [(e[j], e[i]), (e[j], e[i + 1]), (e[j + 1], e[i + 1]), (e[j + 1], e[i])]
                vs = [unit(cm.face_direction(f, s, t)) for s, t in corners]
                v = np.zeros(3)
                for k in range(4):
                    a, b = vs[k], vs[(k + 1) % 4]
                    c = np.cross(a, b)
                    v += 0.5 * np.arctan2(np.linalg.norm(c), a @ b) * c / np.linalg.norm(c)
                out[f, i, j] = 1.0 + A @ v / omega[f, i, j]
    return out


def test_linear_field_matches_arvo_texel_means():
    n = 3
    cube = equirect_to_cube(_cell_mean_of_linear_field(512), n)
    ref = _texel_mean_of_linear_field(n)
    assert np.abs(cube - ref).max() < 2e-4
    # with a coarser source the remaining error (cells cut by texel edges) grows
    coarse = np.abs(equirect_to_cube(_cell_mean_of_linear_field(32), n) - ref).max()
    assert np.abs(cube - ref).max() < coarse / 4


def test_sun_inside_one_texel_lands_there_exactly():
    h, n = 256, 4
    img = np.zeros((h, 2 * h, 1))
    target = cm.cube_texel_directions(n)[4, 1, 2]  # a texel centre on +Z
    u, v = direction_to_equirect(target)
    i, j = int(v * h), int(u * 2 * h)
    img[i, j] = 1e6
    cube = equirect_to_cube(img, n)[..., 0]
    cell = equirect_solid_angles(h, exact=True)[i, j]
    omega = cm.cube_texel_solid_angles(n)
    assert cube[4, 1, 2] * omega[4, 1, 2] == pytest.approx(1e6 * cell, rel=1e-12)
    others = np.ones(cube.shape, bool)
    others[4, 1, 2] = False
    assert np.abs(cube[others]).max() < 1e-9 * cube[4, 1, 2]


@pytest.mark.parametrize("corner", [(1, 1, 1), (-1, -1, 0.3), (0.2, -1, 1)])
def test_sun_straddling_texels_splits_by_area(corner):
    h, n = 16, 3
    img = np.zeros((h, 2 * h, 1))
    u, v = direction_to_equirect(np.array(corner, float))
    i, j = int(v * h), int(u * 2 * h)
    img[i, j] = 1.0
    cube = equirect_to_cube(img, n)[..., 0]
    omega = cm.cube_texel_solid_angles(n)
    cell = equirect_solid_angles(h, exact=True)[i, j]
    share = cube * omega / cell
    assert share.sum() == pytest.approx(1.0, rel=1e-12)  # the sun keeps its energy
    assert np.count_nonzero(share > 1e-3) >= 2
    # reference: equal-area stratified samples of the cell (uniform in phi and cos theta)
    m = 1500
    z0, z1 = np.cos(np.pi * i / h), np.cos(np.pi * (i + 1) / h)
    p0 = 2 * np.pi * j / (2 * h) - np.pi
    zz = z0 + (z1 - z0) * (np.arange(m) + 0.5) / m
    pp = p0 + (2 * np.pi / (2 * h)) * (np.arange(m) + 0.5) / m
    zg, pg = np.meshgrid(zz, pp, indexing="ij")
    sg = np.sqrt(1 - zg ** 2)
    f, s, t = cm.direction_to_cube(np.stack([sg * np.cos(pg), zg, sg * np.sin(pg)], axis=-1))
    ref = np.zeros((6, n, n))
    np.add.at(ref, (f, np.minimum((t * n).astype(int), n - 1), np.minimum((s * n).astype(int), n - 1)), 1.0)
    ref /= m * m
    assert np.abs(share - ref).max() < 2e-3


def test_one_pixel_sun_conserved_for_many_positions():
    rng = np.random.default_rng(11)
    h = 64
    for n in (1, 5, 16, 32):
        img = np.zeros((h, 2 * h, 1))
        i, j = rng.integers(0, h), rng.integers(0, 2 * h)
        img[i, j] = 7.0
        cube = equirect_to_cube(img, n)
        assert cm.cube_integral(cube)[0] == pytest.approx(7.0 * equirect_solid_angles(h, exact=True)[i, j],
                                                          rel=1e-11)
        assert cube.min() > -1e-9 * cube.max()


def test_quadrant_masks_land_on_the_right_faces():
    h, n = 64, 8
    d = equirect_directions(h)
    img = (d > 0).astype(np.float64)  # R: x > 0, G: y > 0, B: z > 0 (at pixel centres)
    cube = equirect_to_cube(img, n)
    half = n // 2
    assert np.allclose(cube[0, ..., 0], 1) and np.allclose(cube[1, ..., 0], 0, atol=1e-12)
    assert np.allclose(cube[2, ..., 1], 1) and np.allclose(cube[3, ..., 1], 0, atol=1e-12)
    assert np.allclose(cube[4, ..., 2], 1) and np.allclose(cube[5, ..., 2], 0, atol=1e-12)
    # +Y face: x = sc, z = tc; +Z face: x = sc, y = -tc (OpenGL table 8.19)
    assert np.allclose(cube[2, :, half:, 0], 1) and np.allclose(cube[2, :, :half, 0], 0, atol=1e-12)
    assert np.allclose(cube[2, half:, :, 2], 1) and np.allclose(cube[2, :half, :, 2], 0, atol=1e-12)
    assert np.allclose(cube[4, :half, :, 1], 1) and np.allclose(cube[4, half:, :, 1], 0, atol=1e-12)
    assert np.allclose(cube[4, :, half:, 0], 1) and np.allclose(cube[4, :, :half, 0], 0, atol=1e-12)


def test_float32_and_grey_inputs():
    img = np.random.default_rng(2).random((16, 32)).astype(np.float32)
    cube = equirect_to_cube(img, 4)
    assert cube.shape == (6, 4, 4) and cube.dtype == np.float32
    ref = equirect_to_cube(img.astype(np.float64), 4)
    assert np.allclose(cube, ref, rtol=1e-6)


def test_equirect_to_cube_validation():
    with pytest.raises(ValueError, match=r"\(H, 2H\)"):
        equirect_to_cube(np.ones((4, 4, 3)), 2)
    with pytest.raises(ValueError, match="non-finite"):
        equirect_to_cube(np.full((2, 4, 3), np.nan), 2)
    with pytest.raises(ValueError, match=r"integer in \[1, 32768\]"):
        equirect_to_cube(np.ones((2, 4, 3)), 0)


# ------------------------------------------------------- cube -> equirect


def test_cube_to_equirect():
    assert np.allclose(cube_to_equirect(np.full((6, 4, 4, 3), 2.0), 8), 2.0)
    n = 64
    cube = 1.0 + cm.cube_texel_directions(n) @ A
    img = cube_to_equirect(cube, 48)
    assert img.shape == (48, 96)
    assert np.abs(img - (1.0 + equirect_directions(48) @ A)).max() < 0.25 * (2.0 / n)
    # round trip of a smooth map: equirect -> cube (exact) -> equirect (bilinear)
    src = _cell_mean_of_linear_field(64)
    back = cube_to_equirect(equirect_to_cube(src, 64), 64)
    assert np.abs(back - src).max() < 0.02


# ------------------------------------------------------------- Environment


def write(path, img):
    write_image(path, img)
    return path


def test_load_equirect_hdr_and_to_cube(tmp_path):
    img = np.random.default_rng(0).random((8, 16, 3)).astype(np.float32)
    env = load_environment(write(tmp_path / "e.exr", img))
    assert env.layout == "equirect" and not env.is_cube and env.source == (str(tmp_path / "e.exr"),)
    assert np.array_equal(env.equirect, img)
    cube = env.to_cube(4)
    assert np.allclose(cm.cube_integral(cube), env.integral(), rtol=1e-6)
    assert env.to_equirect(8).shape == (8, 16, 3)


@pytest.mark.parametrize("layout", ["hcross", "vcross"])
def test_load_cross(tmp_path, layout):
    cube = np.random.default_rng(1).random((6, 4, 4, 3)).astype(np.float32)
    env = load_environment(write(tmp_path / "c.pfm", cm.cube_to_cross(cube, layout)))
    assert env.layout == layout and env.is_cube
    assert np.array_equal(env.cube, cube)
    assert np.allclose(env.to_cube(2).sum(), cm.resample_cube(cube, 2).sum())


def test_cross_unused_blocks_are_not_validated(tmp_path):
    cube = np.ones((6, 4, 4, 3), np.float32)
    cross = cm.cube_to_cross(cube, "hcross", fill=np.nan)  # unused blocks hold NaN
    env = load_environment(write_raw(tmp_path / "c.exr", cross))
    assert np.array_equal(env.cube, cube)
    cross[5, 5, 0] = np.nan  # +Z (block row 1, column 1), texel (1, 1)
    cross[6, 13, 1] = -2.0  # -Z (block row 1, column 3), texel (2, 1)
    _one_line_error(lambda: load_environment(write_raw(tmp_path / "d.exr", cross)), "1 non-finite")
    with pytest.warns(NegativeRadianceWarning, match="1 negative"):
        env = load_environment(tmp_path / "d.exr", fix_nonfinite=True)
    assert env.cube[4, 1, 1, 0] == 1.0 and env.cube[5, 2, 1, 1] == 0.0
    assert np.count_nonzero(env.cube != 1.0) == 1


def test_load_six_faces(tmp_path):
    cube = np.random.default_rng(2).random((6, 4, 4, 3)).astype(np.float32)
    paths = [write(tmp_path / f"f{k}.exr", cube[k]) for k in range(6)]
    env = load_environment(paths)
    assert env.layout == "faces" and np.array_equal(env.cube, cube)
    assert env.integral() == pytest.approx(cm.cube_integral(cube), rel=1e-12)


def test_grey_image_is_replicated(tmp_path):
    img = np.random.default_rng(3).random((4, 8)).astype(np.float32)
    env = load_environment(write(tmp_path / "g.pfm", img))
    assert env.equirect.shape == (4, 8, 3) and np.array_equal(env.equirect[..., 1], img)


def test_ldr_input_warns(tmp_path):
    path = tmp_path / "l.png"
    write_png(path, np.full((4, 8, 3), 0.5))
    with pytest.warns(LDRInputWarning):
        env = load_environment(path)
    code = np.rint(linear_to_srgb(0.5) * 255) / 255
    assert np.allclose(env.equirect, srgb_to_linear(code), rtol=1e-6)


def _rgba_exr(path, rgb, alpha):
    import OpenEXR

    channels = {c: np.ascontiguousarray(rgb[..., i], dtype=np.float32) for i, c in enumerate("RGB")}
    channels["A"] = np.ascontiguousarray(alpha, dtype=np.float32)
    OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}, channels).write(str(path))
    return path


def test_an_environment_s_alpha_is_dropped_with_one_warning(tmp_path):
    """RGBA PNG and an OpenEXR A channel: the radiance is the RGB (alpha does not scale it,
    even where it is 0), and the loader says so once; an RGB file does not warn."""
    rng = np.random.default_rng(5)
    rgb = rng.random((8, 16, 3)).astype(np.float32) + 0.1
    alpha = np.zeros((8, 16), np.float32)
    for path in (_rgba_exr(tmp_path / "a.exr", rgb, alpha), tmp_path / "a.png"):
        if path.suffix == ".png":
            write_png(path, np.concatenate([np.clip(rgb, 0, 1), alpha[..., None]], axis=2))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            env = load_environment(path)
        said = [w for w in caught if issubclass(w.category, IgnoredAlphaWarning)]
        assert len(said) == 1 and str(path) in str(said[0].message) and "alpha" in str(said[0].message)
        assert env.equirect.shape == (8, 16, 3) and env.equirect.min() > 0  # alpha 0 did not zero it
        if path.suffix == ".exr":
            assert np.array_equal(env.equirect, rgb)
    write(tmp_path / "rgb.pfm", rgb)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        load_environment(tmp_path / "rgb.pfm")
    assert not [w for w in caught if issubclass(w.category, IgnoredAlphaWarning)]


def _one_line_error(call, *message):
    with pytest.raises(InputError) as err:
        call()
    text = str(err.value)
    assert "\n" not in text and isinstance(err.value, ValueError)
    for m in message:
        assert m in text
    return text


def test_error_truncated_and_garbage(tmp_path):
    data = hdr_bytes(np.random.default_rng(4).random((16, 32, 3)))
    (tmp_path / "t.hdr").write_bytes(data[:-300])
    _one_line_error(lambda: load_environment(tmp_path / "t.hdr"), str(tmp_path / "t.hdr"), "truncated")
    (tmp_path / "g.exr").write_bytes(bytes(range(256)) * 4)
    _one_line_error(lambda: load_environment(tmp_path / "g.exr"), "g.exr", "not a valid EXR file")


def write_raw(path, img):
    """Write float32 pixels as they are, NaN and Inf included (pbrkit's own
    writers refuse non-finite values): OpenEXR through the library, PFM by hand."""
    img = np.asarray(img, np.float32)
    if path.suffix == ".exr":
        import OpenEXR

        OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage},
                     {"RGB": img}).write(str(path))
    else:
        path.write_bytes(f"PF\n{img.shape[1]} {img.shape[0]}\n-1.0\n".encode() + img[::-1].astype("<f4").tobytes())
    return path


@pytest.mark.parametrize("suffix", [".exr", ".pfm"])
def test_error_nonfinite_with_count_and_fix(tmp_path, suffix):
    img = np.ones((8, 16, 3), np.float32)
    img[3, 5, 0] = np.nan
    img[4, 9] = np.inf
    img[0, 0, 2] = -np.inf
    path = write_raw(tmp_path / f"n{suffix}", img)
    _one_line_error(lambda: load_environment(path), path.name, "5 non-finite")
    env = load_environment(path, fix_nonfinite=True)
    assert np.all(np.isfinite(env.equirect)) and any("5 non-finite" in n for n in env.notes)
    assert np.allclose(env.equirect, 1.0)


def test_fix_nonfinite_uses_finite_neighbour_mean():
    img = np.arange(30, dtype=np.float64).reshape(3, 10, 1)
    img[1, 4, 0] = np.nan
    img[0, 0, 0] = np.nan
    fixed, count = fix_nonfinite_pixels(img, wrap=True)
    assert count == 2
    ring = [img[r % 3, c % 10, 0] for r, c in [(0, 3), (0, 4), (0, 5), (1, 3), (1, 5), (2, 3), (2, 4), (2, 5)]]
    assert fixed[1, 4, 0] == pytest.approx(np.mean(ring))
    # row 0, column 0: neighbours (0, 9), (0, 1), (1, 9), (1, 0), (1, 1) with the column wrap
    assert fixed[0, 0, 0] == pytest.approx(np.mean([9, 1, 19, 10, 11]))
    all_bad = np.full((2, 2, 1), np.nan)
    assert np.array_equal(fix_nonfinite_pixels(all_bad)[0], np.zeros((2, 2, 1)))


def test_negative_values_are_clamped_with_warning(tmp_path):
    img = np.ones((8, 16, 3), np.float32)
    img[2, 3, 1] = -0.5
    img[5, 6] = -1e-3
    path = write(tmp_path / "neg.exr", img)
    with pytest.warns(NegativeRadianceWarning, match="4 negative sample"):
        env = load_environment(path)
    assert env.equirect.min() == 0.0 and env.equirect[2, 3, 1] == 0.0
    assert any("4 negative" in n for n in env.notes)


def test_error_aspect_ratios(tmp_path):
    _one_line_error(lambda: load_environment(write(tmp_path / "w.pfm", np.ones((4, 12, 3), np.float32))),
                    "w.pfm", "12x4", "width must be 2x height")
    _one_line_error(lambda: load_environment(write(tmp_path / "e.pfm", np.ones((4, 8, 3), np.float32)),
                                                layout="hcross"), "does not fit the hcross layout")
    _one_line_error(lambda: load_environment(write(tmp_path / "c.pfm", np.ones((6, 8, 3), np.float32)),
                                                layout="equirect"), "width must be twice the height")


def test_error_zero_and_absurd_sizes(tmp_path):
    (tmp_path / "z.pfm").write_bytes(b"PF\n0 0\n-1.0\n")
    _one_line_error(lambda: load_environment(tmp_path / "z.pfm"), "z.pfm", "empty")
    (tmp_path / "a.hdr").write_bytes(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 40000 +X 80000\n")
    _one_line_error(lambda: load_environment(tmp_path / "a.hdr"), "a.hdr", "exceeds the 32768-pixel limit")


def test_error_faces(tmp_path):
    faces = [write(tmp_path / f"f{k}.pfm", np.ones((4, 4, 3), np.float32)) for k in range(6)]
    faces[3] = write(tmp_path / "big.pfm", np.ones((5, 5, 3), np.float32))
    _one_line_error(lambda: load_environment(faces), "big.pfm", "face -Y is 5x5", "equal sizes")
    faces[3] = write(tmp_path / "rect.pfm", np.ones((4, 5, 3), np.float32))
    _one_line_error(lambda: load_environment(faces), "rect.pfm", "must be square")
    _one_line_error(lambda: load_environment(faces[:5]), "six face files", "got 5")


# --------------------------------------------------------------- real maps

REAL = ["rooitou_park_1k.hdr", "kloofendal_overcast_1k.hdr", "studio_small_03_1k.hdr", "venice_sunset_1k.exr",
        "potsdamer_platz_1k.hdr", "moonless_golf_1k_blender_night.exr"]


@needs_data
@pytest.mark.parametrize("name", REAL)
def test_real_map_cube_integral_equals_equirect_integral(name):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        env = load_environment(ENV / name)
    negatives = [w for w in caught if issubclass(w.category, NegativeRadianceWarning)]
    if name.startswith("moonless"):  # lossy DWAB: 250 slightly negative samples (SOURCES.md)
        assert len(negatives) == 1 and "250 negative" in str(negatives[0].message)
    else:
        assert not negatives
    assert env.equirect.shape == (512, 1024, 3) and env.equirect.min() >= 0
    reference = equirect_integral(env.equirect)  # CONVENTIONS pixel solid angles
    for size in (32, 128):
        cube = env.to_cube(size)
        assert np.allclose(cm.cube_integral(cube), env.integral(), rtol=1e-6)
        assert np.allclose(cm.cube_integral(cube), reference, rtol=1e-3)
