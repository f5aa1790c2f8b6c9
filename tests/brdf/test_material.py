"""Tests of pbrkit.Material: validation, constructors, and the r = 0 limit."""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest

from pbrkit import Material
from pbrkit.brdf.distributions import ALPHA_MIN
from pbrkit.brdf.fresnel import CONDUCTORS
from pbrkit.brdf.shading.filament import MODEL as FILAMENT
from pbrkit.brdf.models import (
    DIFFUSES,
    DISTRIBUTIONS,
    FRESNELS,
    MASKINGS,
    cook_torrance,
    filament,
    ue4,
    urp_mobile,
)


def test_defaults_are_valid_arrays():
    m = Material()
    assert m.base_color.shape == (3,)
    assert float(m.roughness) == 0.5 and float(m.metallic) == 0.0
    assert m.dielectric_f0 == pytest.approx(0.04, rel=1e-14)
    assert m.alpha == pytest.approx(0.25, rel=1e-15)
    assert m.eta is None and m.k is None
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.roughness = 0.3


@pytest.mark.parametrize("field, value", [
    ("roughness", 1.5), ("roughness", -0.01), ("metallic", -0.1), ("metallic", 1.0001),
    ("reflectance", 2.0), ("anisotropy", 1.5), ("anisotropy", -1.01),
    ("base_color", [0.5, 1.2, 0.5]), ("base_color", [-0.1, 0.5, 0.5]),
])
def test_out_of_range_values_raise_naming_the_field(field, value):
    with pytest.raises(ValueError, match=rf"Material\.{field} must be in"):
        Material(**{field: value})


@pytest.mark.parametrize("field, value", [
    ("roughness", np.nan), ("metallic", np.inf), ("reflectance", -np.inf), ("anisotropy", np.nan),
    ("base_color", [0.5, np.nan, 0.5]), ("roughness", [0.2, np.nan]),
])
def test_non_finite_values_raise_naming_the_field(field, value):
    with pytest.raises(ValueError, match=rf"Material\.{field} has .*non-finite"):
        Material(**{field: value})


@pytest.mark.parametrize("value", [0.5, [0.5, 0.5], [0.1, 0.2, 0.3, 0.4], np.zeros((4, 2))])
def test_base_color_needs_three_channels(value):
    with pytest.raises(ValueError, match=r"Material\.base_color must have 3 channels"):
        Material(base_color=value)


def test_eta_and_k_validation():
    eta = np.array([0.2, 0.9, 1.1])
    k = np.array([3.9, 2.4, 2.1])
    with pytest.raises(ValueError, match=r"eta and Material\.k must be given together"):
        Material(eta=eta)
    with pytest.raises(ValueError, match=r"eta and Material\.k must be given together"):
        Material(k=k)
    with pytest.raises(ValueError, match=r"Material\.eta must be in"):
        Material(eta=np.array([0.0, 1.0, 1.0]), k=k)
    with pytest.raises(ValueError, match=r"Material\.k must be in"):
        Material(eta=eta, k=np.array([-1.0, 1.0, 1.0]))
    with pytest.raises(ValueError, match=r"Material\.k has .*non-finite"):
        Material(eta=eta, k=np.array([np.nan, 1.0, 1.0]))
    with pytest.raises(ValueError, match=r"Material\.eta must have 3 channels"):
        Material(eta=1.5, k=0.0)
    m = Material(eta=eta, k=k)
    np.testing.assert_array_equal(m.eta, eta)


def test_per_pixel_fields_broadcast():
    m = Material(base_color=np.full((2, 4, 3), 0.5), roughness=np.linspace(0, 1, 4), metallic=np.zeros((2, 1)))
    assert m.alpha.shape == (4,)
    assert m.alpha[0] == ALPHA_MIN and m.alpha[-1] == 1.0
    bad = np.linspace(0, 1, 8)
    bad[5] = 1.2
    with pytest.raises(ValueError, match=r"Material\.roughness must be in \[0.0, 1.0\]; 1 value\(s\) outside"):
        Material(roughness=bad)


def test_from_ue4():
    """UE4's Specular s gives f0 = 0.08 s (Karis 2013); 0.5 is the usual 0.04."""
    for s in (0.0, 0.25, 0.5, 1.0):
        m = Material.from_ue4(base_color=[0.5, 0.5, 0.5], specular=s)
        assert m.dielectric_f0 == pytest.approx(0.08 * s, rel=1e-14, abs=1e-16)
    m = Material.from_ue4(base_color=[0.1, 0.2, 0.3], metallic=0.3, roughness=0.7, specular=0.5, anisotropy=0.2)
    assert float(m.metallic) == 0.3 and float(m.roughness) == 0.7 and float(m.anisotropy) == 0.2
    with pytest.raises(ValueError, match=r"Material\.specular must be in"):
        Material.from_ue4(base_color=[0.5, 0.5, 0.5], specular=1.2)
    with pytest.raises(ValueError, match=r"Material\.roughness"):
        Material.from_ue4(base_color=[0.5, 0.5, 0.5], roughness=2.0)


@pytest.mark.parametrize("name", sorted(CONDUCTORS))
def test_conductor(name):
    """base_color is the normal-incidence reflectance ((eta-1)^2 + k^2) / ((eta+1)^2 + k^2)."""
    m = Material.conductor(name, roughness=0.3)
    eta, k = (np.asarray(x) for x in CONDUCTORS[name])
    expected = ((eta - 1.0) ** 2 + k * k) / ((eta + 1.0) ** 2 + k * k)
    np.testing.assert_allclose(m.base_color, expected, rtol=1e-12)
    assert float(m.metallic) == 1.0 and float(m.roughness) == 0.3
    np.testing.assert_array_equal(m.eta, eta)
    np.testing.assert_array_equal(m.k, k)


def test_unknown_conductor():
    with pytest.raises(ValueError, match="unknown conductor 'unobtainium'; known: aluminium, copper"):
        Material.conductor("unobtainium")


def _directions(rng, count):
    d = rng.normal(size=(count, 3))
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    d[:, 2] = np.abs(d[:, 2])
    return d


def test_zero_roughness_is_finite_everywhere():
    """r = 0 (alpha clamped at ALPHA_MIN) gives finite, non-negative values for
    every model and option, including the exact mirror configuration (h = n,
    D at its 1 / (pi ALPHA_MIN^2) peak), grazing and normal incidence."""
    rng = np.random.default_rng(21)
    v = _directions(rng, 200)
    v[:5] = [[0, 0, 1], [1, 0, 0], [0.6, 0, 0.8], [1e-6, 0, 1.0], [1.0, 0, 1e-6]]
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    mirror = v * np.array([-1.0, -1.0, 1.0])
    lights = np.concatenate([mirror, _directions(rng, 200)])
    views = np.concatenate([v, v])
    n = np.array([0.0, 0.0, 1.0])
    for anisotropy in (0.0, 0.9):
        material = Material(base_color=np.array([0.9, 0.6, 0.3]), metallic=0.5, roughness=0.0,
                            anisotropy=anisotropy, eta=np.array([0.2, 0.9, 1.1]), k=np.array([3.9, 2.4, 2.1]))
        outputs = [ue4(lights, views, n, material),
                   urp_mobile(lights, views, n, material)]
        outputs += [filament(lights, views, n, material, diffuse=d, t=[1.0, 0.0, 0.0])
                    for d in FILAMENT.choices["diffuse"].choices]
        for d, g, f, df in itertools.product(DISTRIBUTIONS, MASKINGS, FRESNELS, DIFFUSES):
            outputs.append(cook_torrance(lights, views, n, material, distribution=d, masking=g, fresnel=f,
                                         diffuse=df, t=[1.0, 0.0, 0.0]))
        for out in outputs:
            assert out.shape == (400, 3)
            assert np.all(np.isfinite(out)) and np.all(out >= 0.0)
        # The mirror direction of a normal view sees the peak: a sharp but finite lobe.
        assert outputs[0][0, 0] > 1e4
