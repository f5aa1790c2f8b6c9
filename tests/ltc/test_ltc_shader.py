"""The shader's evaluation of LTC tables (:mod:`pbrkit.ltc.shader`): with an
identity table against the clamped-cosine form factor by Gauss quadrature
(written here, not taken from the module), and the published layout's
conventions (texel centres, flat tables, refusals)."""

import math

import numpy as np
import pytest
from ltc_reference import facing_rect

from pbrkit.ltc import lights as light_sets
from pbrkit.ltc import shader


def _form_factor_quadrature(corners, n=96):
    """Integral of max(0, z) / pi over the rectangle's solid angle by an n x n
    Gauss-Legendre rule on the rectangle (for lights wholly above the horizon)."""
    x, w = np.polynomial.legendre.leggauss(n)
    s, t = 0.5 * (x + 1.0), 0.5 * w
    e1, e3 = corners[1] - corners[0], corners[3] - corners[0]
    p = corners[0] + s[:, None, None] * e1 + s[None, :, None] * e3
    normal = np.cross(e1, e3)
    area = np.linalg.norm(normal)
    d = np.linalg.norm(p, axis=-1)
    integrand = (p[..., 2] / d) / math.pi * np.abs(p @ (normal / area)) / d ** 3
    return area * np.einsum("i,j,ij->", t, t, integrand)


def test_shader_with_identity_table_is_the_cosine_form_factor():
    """M^-1 = I and norm 1: the shader computes the clamped-cosine form factor
    (the vector form factor's z for a light above the horizon), with the
    rational theta / sin theta fit (~1e-3) and the clipped-sphere formula
    (close to f.z for lights that subtend little)."""
    t1 = np.broadcast_to([1.0, 0.0, 0.0, 1.0], (64, 64, 4))
    t2 = np.broadcast_to([1.0, 0.25, 0.0, 0.0], (64, 64, 4))
    lights = [
        facing_rect([0.0, 0.0, 3.0], [0.3, 0.0, 0.0], [0.0, 0.2, 0.0]),
        facing_rect([1.0, 2.0, 4.0], [0.3, -0.1, 0.0], [0.0, 0.0, 0.2]),
        facing_rect([-2.0, 0.5, 1.5], [0.0, 0.2, 0.0], [0.1, 0.0, 0.15]),
        facing_rect([0.5, -3.0, 2.0], [0.2, 0.1, 0.0], [0.0, 0.1, 0.3]),
    ]
    for nov in (1.0, 0.7, 0.2):
        for corners in lights:
            exact = _form_factor_quadrature(corners)
            got = shader.ltc_shader_rect(t1, t2, nov, 0.5, corners)
            assert abs(got - exact) < 1.5e-2 * exact, (nov, corners, got, exact)
            # Hill's Fresnel split: f0 norm + (1 - f0) fresnel
            np.testing.assert_allclose(shader.ltc_shader_rect(t1, t2, nov, 0.5, corners, f0=0.2),
                                       got * (0.2 + 0.8 * 0.25), rtol=1e-12)
    # the edge sum alone: the vector form factor's z is the form factor to the rational fit's accuracy
    for corners in lights:
        q = corners * np.array([1.0, -1.0, 1.0])
        q = q / np.linalg.norm(q, axis=-1, keepdims=True)
        f = sum(shader.edge_vector_form_factor(q[k], q[(k + 1) % 4]) for k in range(4))
        assert abs(f[2] - _form_factor_quadrature(corners)) < 2e-3 * f[2]
    # a light overhead subtending the whole hemisphere: form factor 1
    big = light_sets.rect_corners([0.0, 0.0, 1.0], [1e4, 0.0, 0.0], [0.0, 1e4, 0.0])
    assert abs(shader.ltc_shader_rect(t1, t2, 0.9, 0.3, big) - 1.0) < 1e-3


def test_published_layout_conventions():
    rng = np.random.default_rng(3)
    a = rng.random((16, 16, 4))
    b = rng.random((16, 16, 4))
    flat = shader.ltc_table_from_published_layout(a.reshape(-1), b.reshape(-1))
    full = shader.ltc_table_from_published_layout(a, b)
    np.testing.assert_array_equal(flat.ltc1, full.ltc1)
    np.testing.assert_array_equal(flat.ltc2, b)
    with pytest.raises(ValueError, match="shape"):
        shader.ltc_table_from_published_layout(a[:, :8], b)
    with pytest.raises(ValueError, match="N \\* N \\* 4"):
        shader.ltc_table_from_published_layout(np.zeros(99), b)
    # texel centres: at r = a / (N - 1), sqrt(1 - n.v) = t / (N - 1) the lookup is texel [t, a]
    t2 = np.zeros((16, 16, 4))
    t2[5, 9, 0] = 1.0
    t1 = np.broadcast_to([1.0, 0.0, 0.0, 1.0], (16, 16, 4))
    corners = facing_rect([0.0, 0.0, 3.0], [0.3, 0.0, 0.0], [0.0, 0.2, 0.0])
    nov = 1.0 - (5 / 15) ** 2
    assert shader.ltc_shader_rect(t1, t2, nov, 9 / 15, corners) > 0.0
    assert shader.ltc_shader_rect(t1, t2, nov, 8.5 / 15, corners) == pytest.approx(
        0.5 * shader.ltc_shader_rect(t1, t2, nov, 9 / 15, corners))
    assert shader.ltc_shader_rect(t1, t2, nov, 10 / 15, corners) == 0.0


