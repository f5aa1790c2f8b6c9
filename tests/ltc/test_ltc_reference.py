"""The LTC ground truth (:mod:`pbrkit.ltc.reference`) against independent
references: the GGX-over-rectangle cubature against Monte Carlo, against the
directional albedo of the lookup-table quadrature and against itself at a
tighter tolerance; the other lobes (Beckmann, separable Smith) against a
composite Gauss-Legendre rule over the rectangle built from pbrkit.brdf's term
functions (``ltc_reference.rect_lobe_quadrature``), and their albedo against
the cubature over the faces of a cube; horizon clipping and one-sidedness.  The
Monte Carlo estimator is written here from the formulas, not taken from the
module."""

import math

import numpy as np
import pytest
from ltc_reference import facing_rect, rect_lobe_quadrature

from pbrkit.albedo.tables import specular_integrals
from pbrkit.brdf.distributions import d_beckmann, d_ggx
from pbrkit.brdf.fresnel import f_schlick
from pbrkit.brdf.masking import g2_height_correlated, g2_separable, lambda_beckmann, lambda_ggx
from pbrkit.ltc import lights as light_sets
from pbrkit.ltc import reference, shader, statistics


def _monte_carlo(nov, roughness, corners, f0, n=1_000_000, seed=7):
    """Uniform area sampling of the rectangle: mean and standard error of
    f F (n.l) cos theta' / d^2 times the area (f: GGX D, height-correlated
    Smith, Schlick F, written from the terms)."""
    rng = np.random.default_rng(seed)
    s, t = rng.random(n), rng.random(n)
    e1, e3 = corners[1] - corners[0], corners[3] - corners[0]
    p = corners[0] + s[:, None] * e1 + t[:, None] * e3
    normal = np.cross(e1, e3)
    area = np.linalg.norm(normal)
    normal /= area
    d = np.linalg.norm(p, axis=1)
    l = p / d[:, None]
    alpha = roughness * roughness
    v = np.array([math.sqrt(1.0 - nov * nov), 0.0, nov])
    h = l + v
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    nol = l[:, 2]
    f = (d_ggx(h[:, 2], alpha) * g2_height_correlated(lambda_ggx(nol, alpha), lambda_ggx(nov, alpha))
         / (4.0 * nov * np.maximum(nol, 1e-12)))
    g = np.where(nol > 0.0, f * f_schlick(h @ v, f0) * nol * np.abs(l @ normal) / d ** 2 * area, 0.0)
    return g.mean(), g.std() / math.sqrt(n)


# a broad lobe, the tail of a sharp one, a light crossing the horizon, grazing view near the mirror direction
MC_LIGHTS = [
    (0.8, 0.7, facing_rect([0.4, 0.2, 1.5], [0.6, 0.0, 0.2], [0.0, 0.5, 0.0])),
    (0.5, 0.2, facing_rect([0.9, -0.3, 1.0], [0.4, 0.4, 0.0], [0.0, 0.0, 0.3])),
    (0.6, 0.5, facing_rect([-1.5, 0.5, 0.2], [0.0, 0.8, 0.0], [0.2, 0.0, 0.7])),
    (0.25, 0.35, facing_rect([-2.0, 0.0, 0.8], [0.0, 0.6, 0.0], [0.3, 0.0, 0.5])),
]


@pytest.mark.parametrize("case", range(len(MC_LIGHTS)))
def test_reference_against_monte_carlo(case):
    nov, r, corners = MC_LIGHTS[case]
    for f0 in (1.0, 0.04):
        ref = reference.ggx_rect_reference(nov, r, corners, f0=f0)
        mean, stderr = _monte_carlo(nov, r, corners, f0)
        assert ref > 0.0
        assert abs(mean - ref) < 4.0 * stderr, (case, f0, ref, mean, stderr)
        assert abs(mean - ref) < 3e-3 * ref


def test_reference_converged():
    """The default tolerance against a 1000x tighter run: agreement far below
    the 1e-4 the scores need."""
    nov = np.array([m[0] for m in MC_LIGHTS])
    r = np.array([m[1] for m in MC_LIGHTS])
    corners = np.stack([m[2] for m in MC_LIGHTS])
    a = reference.ggx_rect_integrals(nov, r, corners)
    b = reference.ggx_rect_integrals(nov, r, corners, tol=1e-9, max_triangles=200000)
    np.testing.assert_allclose(a, b, rtol=1e-6)


@pytest.mark.parametrize("nov", [0.2, 0.6, 1.0])
def test_hemisphere_light_gives_directional_albedo(nov):
    """A 2e4 x 2e4 light at height 1 fills the hemisphere but 1e-4 rad above the
    horizon: its integrals are the directional albedo (F = 1) and its Schlick
    part, as the tables' half-vector quadrature computes them."""
    big = light_sets.rect_corners([0.0, 0.0, 1.0], [1e4, 0.0, 0.0], [0.0, 1e4, 0.0])
    roughness = np.array([0.1, 0.5, 1.0])
    pair = reference.ggx_rect_integrals(nov, roughness, np.broadcast_to(big, (3, 4, 3)))
    ab = specular_integrals([nov], roughness, "height-correlated", nodes=(48, 96, 24))[:, 0]
    np.testing.assert_allclose(pair[:, 0], ab.sum(axis=-1), rtol=2e-5)
    np.testing.assert_allclose(pair[:, 1], ab[:, 1], rtol=1e-4, atol=1e-9)


# (n.v, roughness, the light, the part of it above the horizon when it crosses it)
LOBE_LIGHTS = [
    (0.8, 0.7, facing_rect([0.4, 0.2, 1.5], [0.6, 0.0, 0.2], [0.0, 0.5, 0.0]), None),
    (0.5, 0.3, facing_rect([-0.9, 0.1, 0.9], [0.3, 0.3, 0.0], [0.0, 0.0, 0.3]), None),  # about the mirror direction
    (0.15, 0.8, facing_rect([-2.0, 0.4, 0.45], [0.0, 0.6, 0.0], [0.1, 0.0, 0.3]), None),  # grazing: masking matters
    (0.3, 0.6, facing_rect([-2.0, -0.3, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.6]),  # vertical, across the horizon
     facing_rect([-2.0, -0.3, 0.3], [0.0, 0.5, 0.0], [0.0, 0.0, 0.3])),
]
TERMS = {"ggx": (d_ggx, lambda_ggx), "beckmann": (d_beckmann, lambda_beckmann),
         "height-correlated": g2_height_correlated, "separable": g2_separable}


@pytest.mark.parametrize("distribution, masking",
                         [("beckmann", "height-correlated"), ("beckmann", "separable"), ("ggx", "separable")])
def test_lobe_reference_against_tensor_quadrature(distribution, masking):
    """The cubature with another lobe (one code path: pbrkit.brdf's specular_lobe
    of a cook_torrance BxDF) against a 384 x 384-node composite Gauss-Legendre
    rule over the rectangle, whose lobe is written from D, Lambda and G2 (converged
    to 1e-15 against 128 x 128 nodes): agreement to 1e-6 (measured: at most 5e-9),
    while the other distribution is 16% to 150% away and, on the grazing light, the
    other masking 12% to 44%."""
    d, lam = TERMS[distribution]
    for nov, r, corners, upper in LOBE_LIGHTS:
        expected = rect_lobe_quadrature(nov, r * r, corners if upper is None else upper, d, lam, TERMS[masking],
                                        panels=48)
        got = reference.lobe_rect_integrals(nov, r, corners, distribution, masking)
        np.testing.assert_allclose(got, expected, rtol=1e-6)
        other_d = reference.lobe_rect_integrals(nov, r, corners, "ggx" if distribution == "beckmann" else "beckmann",
                                            masking)
        other_g = reference.lobe_rect_integrals(nov, r, corners, distribution,
                                            "separable" if masking == "height-correlated" else "height-correlated")
        assert np.all(np.abs(other_d / expected - 1.0) > 0.1)
        if nov < 0.2:  # at grazing; elsewhere Beckmann's Lambdas are too small for the two G2 to differ
            assert np.all(np.abs(other_g / expected - 1.0) > 5e-3)
        np.testing.assert_allclose(reference.lobe_rect_reference(nov, r, corners, 0.04, distribution, masking),
                                   0.04 * got[0] + 0.96 * got[1], rtol=1e-12)
    # the default lobe keeps its name
    np.testing.assert_array_equal(reference.ggx_rect_integrals(0.5, 0.3, LOBE_LIGHTS[1][2]),
                                  reference.lobe_rect_integrals(0.5, 0.3, LOBE_LIGHTS[1][2]))


def _cube(nov):
    """The six faces of a cube about the shading point, lit on the inside, one face
    centred on the mirror direction: together they cover the sphere once."""
    sin_v = math.sqrt(1.0 - nov * nov)
    r = np.array([-sin_v, 0.0, nov])
    e1 = np.array([nov, 0.0, sin_v])
    faces = []
    for axis, width in ((r, e1), (-r, e1), (e1, [0.0, 1.0, 0.0]), (-e1, [0.0, 1.0, 0.0]), ([0.0, 1.0, 0.0], r),
                        ([0.0, -1.0, 0.0], r)):
        faces.append(facing_rect(axis, width, np.cross(axis, width)))
    return np.stack(faces)


@pytest.mark.parametrize("distribution, masking", [("beckmann", "height-correlated"), ("beckmann", "separable"),
                                                   ("ggx", "schlick-ggx-ue4"), ("ggx", "separable")])
def test_lobe_albedo_is_the_cube_of_lights(distribution, masking):
    """The converged albedo (half-vector quadrature: albedo.furnace or the
    tables') equals the rectangle cubature summed over the faces of a cube about
    the shading point, to 1e-6 (measured: at most 1.2e-7), roughness 0 (alpha =
    1e-3, where a Beckmann peak hides from a coarse rule) to 1."""
    nov = np.array([1.0, 0.7, 0.2, 0.05, 0.5, 0.9])
    r = np.array([0.6, 0.0, 1.0, 0.3, 0.1, 0.45])
    ab = reference.lobe_split_integrals(nov, r, distribution, masking)
    cubes = np.stack([_cube(m) for m in nov])
    pair = reference.lobe_rect_integrals(np.repeat(nov, 6), np.repeat(r, 6), cubes.reshape(-1, 4, 3), distribution,
                                     masking).reshape(-1, 6, 2).sum(axis=1)
    np.testing.assert_allclose(pair[:, 0], ab.sum(axis=-1), rtol=1e-6)
    np.testing.assert_allclose(pair[:, 1], ab[:, 1], rtol=1e-6, atol=1e-12)
    e = reference.directional_albedo(nov, r, 0.04, distribution, masking)
    np.testing.assert_allclose(e, 0.04 * ab[:, 0] + ab[:, 1], rtol=1e-12)


def test_unknown_lobes_are_refused():
    for distribution, masking, message in (("blinn-phong", "separable", "--distribution: unknown distribution"),
                                           ("beckmann", "schlick-ggx", "--masking: schlick-ggx is Schlick's"),
                                           ("beckmann", "schlick-ggx-ue4", "with --distribution beckmann"),
                                           ("ggx", "kelemen", "--masking: unknown masking 'kelemen'"),
                                           ("ggx", "implicit", "--masking: unknown masking")):
        with pytest.raises(ValueError, match=message):
            reference.lobe_rect_integrals(0.5, 0.5, LOBE_LIGHTS[0][2], distribution, masking)
        with pytest.raises(ValueError, match=message):
            reference.lobe_split_integrals(0.5, 0.5, distribution, masking)
    lights = light_sets.random_rect_lights(4, seed=1)
    with pytest.raises(ValueError, match="--masking"):
        statistics.score_table(np.ones((4, 4, 4)), np.ones((4, 4, 4)), lights, distribution="beckmann",
                          masking="schlick-ggx")


def test_horizon_clipping_and_one_sidedness():
    nov, r = 0.5, 0.6
    below = facing_rect([1.0, 0.0, -1.0], [0.3, 0.0, 0.0], [0.0, 0.3, 0.0])
    assert reference.ggx_rect_reference(nov, r, below) == 0.0
    # a vertical light across the horizon counts as its upper half
    across = facing_rect([-2.0, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.8])
    upper = facing_rect([-2.0, 0.0, 0.4], [0.0, 0.5, 0.0], [0.0, 0.0, 0.4])
    a, b = reference.ggx_rect_reference(nov, r, np.stack([across, upper]))
    assert a > 0.0
    assert abs(a - b) < 1e-6 * b
    # seen from behind (reversed winding) a one-sided light gives nothing
    assert reference.ggx_rect_reference(nov, r, upper[::-1]) == 0.0
    t1 = np.broadcast_to([1.0, 0.0, 0.0, 1.0], (8, 8, 4))
    t2 = np.broadcast_to([1.0, 0.0, 0.0, 0.0], (8, 8, 4))
    assert shader.ltc_shader_rect(t1, t2, nov, r, upper[::-1]) == 0.0
    assert shader.ltc_shader_rect(t1, t2, nov, r, below) == 0.0


