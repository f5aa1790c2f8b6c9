"""Disney principled BRDF: reductions to independent forms, its extra lobes, reciprocity."""

import numpy as np
import pytest
from quadrature import directional_albedo, view_direction

from pbrkit import Material
from pbrkit.brdf.diffuse import burley_subsurface
from pbrkit.brdf.models import cook_torrance, disney

RNG = np.random.default_rng(11)
N = np.array([0.0, 0.0, 1.0])


def _hemisphere(n):
    d = RNG.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    d[:, 2] = np.abs(d[:, 2])
    return d


def test_without_extras_it_is_ggx_smith_schlick_burley():
    # No subsurface, sheen, clear coat or tint: Burley's diffuse plus GGX with separable
    # Smith masking and Schlick Fresnel, the same terms composed by cook_torrance.
    n = 500
    l, v = _hemisphere(n), _hemisphere(n)
    m = Material(base_color=RNG.random((n, 3)), metallic=RNG.random(n), roughness=RNG.random(n),
                 reflectance=RNG.random(n))
    np.testing.assert_allclose(disney(l, v, N, m),
                               cook_torrance(l, v, N, m, masking="separable", diffuse="burley"), rtol=1e-12)


def test_reciprocity_with_every_lobe():
    n = 500
    l, v = _hemisphere(n), _hemisphere(n)
    m = Material(base_color=RNG.random((n, 3)), metallic=RNG.random(n), roughness=RNG.random(n),
                 anisotropy=RNG.random(n), subsurface=RNG.random(n), sheen=RNG.random(n),
                 sheen_tint=RNG.random(n), clearcoat=RNG.random(n), clearcoat_gloss=RNG.random(n),
                 specular_tint=RNG.random(n))
    t = np.array([1.0, 0.0, 0.0])
    np.testing.assert_allclose(disney(l, v, N, m, t=t), disney(v, l, N, m, t=t), rtol=1e-10, atol=1e-14)


def test_subsurface_factor_known_values():
    # l = v = n: F_ss = 1, so f = 1.25 / pi (1 / 2 - 0.5 + 0.5) = 0.625 / pi for any roughness.
    assert burley_subsurface(1.0, 1.0, 1.0, 0.3) == pytest.approx(0.625 / np.pi)
    # Grazing on both sides with r = 0: F_ss90 = 0, F_ss = 0 -> 1.25 / pi * 0.5.
    assert burley_subsurface(1e-12, 1e-12, 1.0, 0.0) == pytest.approx(0.625 / np.pi, rel=1e-6)


def test_sheen_lobe_is_schlick_weight_times_tinted_sheen():
    l = np.array([0.6, 0.0, 0.8])
    v = np.array([-0.6, 0.0, 0.8])
    base = np.array([0.2, 0.5, 0.3])
    plain = Material(base_color=base, roughness=0.5)
    sheen = Material(base_color=base, roughness=0.5, sheen=1.0, sheen_tint=0.0)
    h = (l + v) / np.linalg.norm(l + v)
    assert np.allclose(disney(l, v, N, sheen) - disney(l, v, N, plain), (1.0 - l @ h) ** 5)


def test_clear_coat_reflects_at_most_a_quarter():
    # The coat is 0.25 D_GTR1 F V with F <= 1 and an energy-bounded Smith V: its albedo
    # (by an independent quadrature over the half vector) lies in (0, 0.25).
    base = np.array([0.5, 0.5, 0.5])
    for gloss in (0.0, 0.5, 1.0):
        with_coat = Material(base_color=base, roughness=0.5, clearcoat=1.0, clearcoat_gloss=gloss)
        without = Material(base_color=base, roughness=0.5)
        alpha = 0.1 + (0.001 - 0.1) * gloss
        for cos_v in (0.2, 0.7, 1.0):
            v = view_direction(cos_v)
            e = directional_albedo(lambda l, vv: (disney(l, vv, N, with_coat) - disney(l, vv, N, without))[..., 0],
                                   v, alpha)
            assert 0.0 < e < 0.25


def test_negative_anisotropy_is_rejected():
    with pytest.raises(ValueError, match="anisotropy"):
        disney(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]), N, Material(anisotropy=-0.5))
