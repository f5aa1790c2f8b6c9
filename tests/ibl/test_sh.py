"""Spherical harmonics: basis, projection and irradiance.

References used here are independent of pbrkit.ibl.sh: SciPy's complex
spherical harmonics, Gauss-Legendre x uniform-azimuth product quadrature
(exact for spherical polynomials of low degree), brute-force cosine
convolution over the hemisphere, and the equirect / cube-map conventions
re-derived in this file from CONVENTIONS.md.
"""

from __future__ import annotations

import numpy as np
import pytest
from quadrature import hemisphere_rule
from scipy.special import sph_harm_y
from skips import shared_data_reason

from pbrkit.core.vec import to_world
from pbrkit.ibl import sh


def _sphere_quadrature(n_cos, n_phi):
    """Directions and weights of a product rule on the sphere (polar axis z):
    exact for polynomials in (x, y, z) of degree < min(2 n_cos, n_phi)."""
    x, w = np.polynomial.legendre.leggauss(n_cos)
    phi = 2 * np.pi * (np.arange(n_phi) + 0.5) / n_phi
    ct, ph = np.meshgrid(x, phi, indexing="ij")
    st = np.sqrt(1 - ct**2)
    d = np.stack([st * np.cos(ph), st * np.sin(ph), ct], axis=-1)
    weights = np.broadcast_to(w[:, None] * (2 * np.pi / n_phi), ct.shape)
    return d.reshape(-1, 3), weights.reshape(-1)


def _equirect_directions(H, W):
    """Pixel-centre directions from the (u, v) form of CONVENTIONS.md:
    u = 0.5 + atan2(z, x) / (2 pi), v = acos(y) / pi."""
    v = (np.arange(H) + 0.5) / H
    u = (np.arange(W) + 0.5) / W
    theta = np.pi * v[:, None]
    phi = 2 * np.pi * (u[None, :] - 0.5)
    return np.stack(np.broadcast_arrays(np.sin(theta) * np.cos(phi), np.cos(theta),
                                        np.sin(theta) * np.sin(phi)), axis=-1)


def _random_directions(n, seed):
    d = np.random.default_rng(seed).normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def test_basis_matches_scipy_real_harmonics():
    d = _random_directions(200, 1)
    theta, phi = np.arccos(d[:, 2]), np.arctan2(d[:, 1], d[:, 0])
    ref = []
    for l in range(3):
        for m in range(-l, l + 1):
            y = sph_harm_y(l, abs(m), theta, phi)  # with the Condon-Shortley phase
            if m > 0:
                ref.append(np.sqrt(2) * (-1) ** m * y.real)
            elif m < 0:
                ref.append(np.sqrt(2) * (-1) ** m * y.imag)
            else:
                ref.append(y.real)
    assert np.allclose(sh.sh_basis(d), np.stack(ref, axis=-1), atol=1e-14, rtol=0)


def test_basis_constants_are_the_conventions_ones():
    # CONVENTIONS.md lists 6-digit values; pbrkit uses full precision.
    x, y, z = 0.48, 0.6, 0.64
    got = sh.sh_basis([x, y, z])
    listed = [0.282095, 0.488603 * y, 0.488603 * z, 0.488603 * x, 1.092548 * x * y,
              1.092548 * y * z, 0.315392 * (3 * z * z - 1), 1.092548 * x * z, 0.546274 * (x * x - y * y)]
    assert np.allclose(got, listed, atol=1e-6, rtol=0)
    assert sh.sh_basis([0, 0, 1.0])[0] == pytest.approx(0.5 / np.sqrt(np.pi), rel=1e-15)


def test_gram_matrix_is_identity():
    d, w = _sphere_quadrature(6, 12)  # products have degree <= 4: exact
    basis = sh.sh_basis(d)
    gram = basis.T @ (basis * w[:, None])
    assert np.abs(gram - np.eye(9)).max() < 1e-12


def test_constant_radiance_gives_sqrt_4pi_and_irradiance_pi():
    d, w = _sphere_quadrature(4, 8)
    coeffs = sh.project(d, w, np.ones((len(d), 3)))
    assert np.allclose(coeffs[0], np.sqrt(4 * np.pi), rtol=1e-13)
    assert np.abs(coeffs[1:]).max() < 1e-13
    normals = _random_directions(50, 2)
    assert np.allclose(sh.irradiance_from_sh(coeffs, normals), np.pi, rtol=1e-13)
    # Equirect: exact integrals over the pixels' cells, so exact at any size.
    for h in (1, 2, 3, 256):
        c = sh.project_equirect(np.ones((h, 2 * h)))
        assert c[0] == pytest.approx(np.sqrt(4 * np.pi), rel=1e-12)
        assert np.abs(c[1:]).max() < 1e-12


def test_cosine_lobe_coefficients_match_quadrature_and_exact_values():
    import math
    from fractions import Fraction

    from pbrkit.ibl.spectral import zonal_coefficients

    a = sh.cosine_lobe_coefficients(64)
    quad, _ = zonal_coefficients(lambda t: np.maximum(np.cos(t), 0.0), 64, theta_max=0.5 * np.pi, normalise=False)
    assert np.allclose(a, quad, rtol=0, atol=1e-10)
    assert sh.COSINE_LOBE_COEFFICIENTS == (np.pi, 2 * np.pi / 3, np.pi / 4)
    assert np.array_equal(sh.cosine_lobe_coefficients(2), sh.COSINE_LOBE_COEFFICIENTS)
    # high degree: exact rational factor binom(l, l/2) / 2^l / ((l + 2)(l - 1)) of R&H 2001 eq. 9
    big = sh.cosine_lobe_coefficients(1000)
    assert np.all(np.isfinite(big)) and np.all(big[3::2] == 0.0)
    for l in (2, 4, 10, 100, 512, 998, 1000):
        exact = Fraction(math.comb(l, l // 2), 2 ** l * (l + 2) * (l - 1))
        assert big[l] == pytest.approx(2 * np.pi * (-1) ** (l // 2 - 1) * float(exact), rel=1e-13)


def test_equirect_projection_is_exact_per_cell():
    # A piecewise-constant image: reference by a 12 x 12 Gauss-Legendre product rule in
    # (theta, phi) inside every cell (the integrand Y_lm sin(theta) is a smooth, low-degree
    # trigonometric polynomial, so the rule is exact to rounding), directions from CONVENTIONS.md.
    H, W = 3, 6
    image = np.random.default_rng(8).random((H, W, 2))
    x, w = np.polynomial.legendre.leggauss(12)
    reference = np.zeros((9, 2))
    for i in range(H):
        theta = np.pi * (i + 0.5 + 0.5 * x) / H
        for j in range(W):
            phi = 2 * np.pi * (j + 0.5 + 0.5 * x) / W - np.pi
            t, p = np.meshgrid(theta, phi, indexing="ij")
            d = np.stack([np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)], axis=-1)
            weight = np.outer(w, w) * (0.5 * np.pi / H) * (np.pi / W) * np.sin(t)
            reference += np.einsum("abk,ab->k", sh.sh_basis(d), weight)[:, None] * image[i, j]
    np.testing.assert_allclose(sh.project_equirect(image), reference, rtol=0, atol=1e-14)
    np.testing.assert_allclose(sh.project_equirect(image[..., 1]), reference[:, 1], rtol=0, atol=1e-14)


def test_projection_recovers_band_limited_coefficients():
    rng = np.random.default_rng(3)
    truth = rng.normal(size=(9, 3))
    d, w = _sphere_quadrature(6, 12)
    radiance = sh.sh_basis(d) @ truth  # evaluated independently of eval_sh
    assert np.allclose(sh.project(d, w, radiance), truth, atol=1e-12)
    assert np.allclose(sh.eval_sh(truth, d), radiance, atol=1e-12)
    # Single band, single coefficient, via the equirect path (midpoint rule).
    for k in range(9):
        single = np.zeros(9)
        single[k] = 1.0
        image = sh.sh_basis(_equirect_directions(128, 256)) @ single
        got = sh.project_equirect(image)
        assert np.abs(got - single).max() < 1e-3, k


def test_irradiance_equals_brute_force_cosine_convolution_for_band_limited_light():
    rng = np.random.default_rng(4)
    coeffs = rng.normal(size=(9, 2))
    normals = _random_directions(20, 5)
    # Hemisphere around each normal (tests/support/quadrature.py, independent of
    # pbrkit): L(w) cos theta is a polynomial of degree 3 in the direction.
    local, w = hemisphere_rule(8, 24)
    weights = w * local[:, 2]
    for n in normals:
        world = to_world(local, np.broadcast_to(n, local.shape))
        radiance = sh.sh_basis(world) @ coeffs
        brute = weights @ radiance
        assert np.allclose(sh.irradiance_from_sh(coeffs, n), brute, atol=1e-12)


def _sun_and_sky(H):
    """A sky gradient plus a small, very bright sun (radius of 2 pixel heights)."""
    d = _equirect_directions(H, 2 * H)
    sun = np.array([0.3, 0.25, -0.92])
    sun /= np.linalg.norm(sun)
    sky = 0.2 + 0.8 * np.clip(d[..., 1], 0, 1)[..., None] * np.array([0.5, 0.7, 1.0])
    disc = (d @ sun) > np.cos(2 * np.pi / H)
    return sky + 5e4 * disc[..., None] * np.array([1.0, 0.9, 0.8])


def _truncation_check(image, n_normals=300):
    H, W = image.shape[:2]
    d = _equirect_directions(H, W)
    theta = np.pi * (np.arange(H) + 0.5) / H
    omega = (2 * np.pi / W) * (np.pi / H) * np.sin(theta)[:, None] * np.ones((1, W))
    normals = _random_directions(n_normals, 9)
    cosines = np.maximum(0.0, d.reshape(-1, 3) @ normals.T)  # (pixels, normals)
    brute = cosines.T @ (image.reshape(-1, image.shape[-1]) * omega.reshape(-1, 1))
    approx = sh.irradiance_from_sh(sh.project_equirect(image), normals)
    total = (image * omega[..., None]).sum(axis=(0, 1))  # integral of L dw
    return np.abs(approx - brute), total, brute


def test_irradiance_truncation_error_within_bound_sun_and_sky():
    # For non-negative radiance |E - E_2| <= 3/32 * integral of L dw
    # (pbrkit.ibl.sh module docstring); a tiny sun makes it nearly tight.
    err, total, brute = _truncation_check(_sun_and_sky(64))
    assert np.all(err <= sh.TRUNCATION_ERROR_BOUND * total * (1 + 1e-9))
    assert err.max() > 0.5 * sh.TRUNCATION_ERROR_BOUND * total.max()  # the bound is near-tight here


def test_irradiance_truncation_error_real_map():
    OpenEXR = pytest.importorskip("OpenEXR")
    import pathlib

    path = pathlib.Path(__file__).resolve().parents[3] / "shared/data/env/venice_sunset_1k.exr"
    if not path.exists():
        pytest.skip(shared_data_reason("env/venice_sunset_1k.exr"))
    with OpenEXR.File(str(path)) as f:
        rgb = np.asarray(f.channels()["RGB"].pixels, dtype=np.float64)
    assert rgb.shape == (512, 1024, 3)
    image = rgb.reshape(128, 4, 256, 4, 3).mean(axis=(1, 3))  # 4x4 box: 128 x 256
    err, total, brute = _truncation_check(image)
    assert np.all(err <= sh.TRUNCATION_ERROR_BOUND * total)
    # Measured (sun 3 deg above the horizon): mean error 0.7-2.2% of the mean
    # irradiance, max error 1.6-2.4% of the max irradiance per channel, the
    # "few percent" of Ramamoorthi & Hanrahan 2001 for natural lighting.
    assert np.all(err.mean(axis=0) < 0.05 * brute.mean(axis=0))
    assert np.all(err.max(axis=0) < 0.05 * brute.max(axis=0))


def test_equirect_projection_matches_fine_quadrature_of_smooth_environment():
    a = np.array([0.2, 0.9, -0.4]) / np.linalg.norm([0.2, 0.9, -0.4])
    b = np.array([-0.7, 0.1, 0.7]) / np.linalg.norm([-0.7, 0.1, 0.7])

    def env(d):  # smooth, not band-limited
        return np.stack([np.exp(2 * d @ a), 1 + np.maximum(0, d @ b) ** 3, np.cos(3 * d[..., 0])], axis=-1)

    image = env(_equirect_directions(96, 192))
    got = sh.project_equirect(image)
    d, w = _sphere_quadrature(96, 192)
    reference = sh.sh_basis(d).T @ (env(d) * w[:, None])
    assert np.abs(got - reference).max() <= 1e-3 * np.abs(reference).max()


def test_equirect_orientation_from_uv_mapping():
    H, W = 256, 512
    for target in ([0.3, 0.8, -0.5], [-0.9, -0.2, 0.38], [0.05, -0.99, 0.1]):
        t = np.array(target) / np.linalg.norm(target)
        u = 0.5 + np.arctan2(t[2], t[0]) / (2 * np.pi)
        v = np.arccos(t[1]) / np.pi
        image = np.zeros((H, W))
        image[int(v * H), int(u * W)] = 1.0
        c = sh.project_equirect(image)
        assert np.allclose(c / c[0], sh.sh_basis(t) / sh.sh_basis(t)[0], atol=0.03)


def _cube_texels(n):
    """CONVENTIONS.md "Cube maps": directions and exact solid angles."""
    s = (np.arange(n) + 0.5) / n
    sc, tc = np.meshgrid(2 * s - 1, 2 * s - 1, indexing="xy")  # [row t, column s]
    one = np.ones_like(sc)
    faces = [(one, -tc, -sc), (-one, -tc, sc), (sc, one, tc), (sc, -one, -tc), (sc, -tc, one), (-sc, -tc, -one)]
    d = np.stack([np.stack(f, axis=-1) for f in faces])
    d /= np.linalg.norm(d, axis=-1, keepdims=True)

    def corner(x, y):  # solid angle of [0, x] x [0, y] on the unit-distance face
        return np.arctan2(x * y, np.sqrt(x * x + y * y + 1))

    e = 2 * np.arange(n + 1) / n - 1
    x0, x1 = e[None, :-1], e[None, 1:]
    y0, y1 = e[:-1, None], e[1:, None]
    omega = corner(x1, y1) - corner(x0, y1) - corner(x1, y0) + corner(x0, y0)
    return d, np.broadcast_to(omega, (6, n, n))


def test_cube_projection():
    d, omega = _cube_texels(32)
    assert omega.sum() == pytest.approx(4 * np.pi, rel=1e-13)
    c = sh.project(d, omega, np.ones((6, 32, 32)))
    assert c[0] == pytest.approx(np.sqrt(4 * np.pi), rel=1e-13)
    truth = np.random.default_rng(8).normal(size=(9, 3))
    got = sh.project(d, omega, sh.sh_basis(d) @ truth)
    assert np.abs(got - truth).max() < 2e-3 * np.abs(truth).max()


def test_project_cube_uses_the_conventions_layout():
    d, omega = _cube_texels(16)
    cube = np.random.default_rng(12).uniform(size=(6, 16, 16, 3))
    assert np.allclose(sh.project_cube(cube), sh.project(d, omega, cube), rtol=1e-10, atol=1e-12)


def test_windows():
    assert np.array_equal(sh.sh_window(None), np.ones(9))
    assert np.allclose(sh.sh_window("hanning", 3.0), [1] + [0.75] * 3 + [0.25] * 5)
    lanczos = [1] + [np.sin(np.pi / 3) / (np.pi / 3)] * 3 + [np.sin(2 * np.pi / 3) / (2 * np.pi / 3)] * 5
    assert np.allclose(sh.sh_window("lanczos", 3.0), lanczos)
    assert np.allclose(sh.sh_window("hanning", 1.5), [1] + [0.25] * 3 + [0.0] * 5)  # l > w -> 0
    coeffs = np.random.default_rng(6).normal(size=(9, 3))
    n = _random_directions(10, 7)
    assert np.array_equal(sh.irradiance_from_sh(coeffs, n), sh.irradiance_from_sh(coeffs, n, window=None))
    # Windowing scales band l of the irradiance by w_l: check on pure bands.
    for k, band in enumerate(sh.SH_BANDS):
        single = np.zeros(9)
        single[k] = 1.0
        ratio = sh.irradiance_from_sh(single, n, window="hanning") / sh.irradiance_from_sh(single, n)
        finite = np.abs(sh.irradiance_from_sh(single, n)) > 1e-9
        assert np.allclose(ratio[finite], [1.0, 0.75, 0.25][band])
    with pytest.raises(ValueError, match="window"):
        sh.sh_window("gauss")


def test_sh9_compiles_in_numba_kernels():
    import numba

    @numba.njit
    def first_and_last(x, y, z):
        b = sh.sh9(x, y, z)
        return b[0] + b[8]

    d = np.array([0.48, 0.6, 0.64])
    assert first_and_last(*d) == pytest.approx(sh.sh_basis(d)[0] + sh.sh_basis(d)[8], rel=1e-14)


def test_bad_shapes():
    with pytest.raises(ValueError, match="2H"):
        sh.project_equirect(np.ones((4, 4, 3)))
    with pytest.raises(ValueError, match=r"\(9,\)"):
        sh.eval_sh(np.ones(4), [0, 0, 1.0])
    with pytest.raises(ValueError, match="solid_angles"):
        sh.project(np.ones((5, 3)), np.ones(4), np.ones(5))
    with pytest.raises(ValueError, match="cube map"):
        sh.project_cube(np.ones((5, 4, 4, 3)))
