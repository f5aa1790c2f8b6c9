"""Whole-BxDF tests of every model's sampling routine against its pdf, as
Mitsuba tests its BSDFs (not only the warps): chi-square goodness of fit of the
sampled light directions, with the failed samples (reflected below the
horizon) as one more cell whose expected count is N (1 - integral of the pdf);
the pdf's integral over the hemisphere against the fraction of successful
samples; a white-furnace Monte Carlo estimate with the model's own sampler and
value against an independent quadrature (tests/support/quadrature.py); and proof that
the tests reject a wrong pdf.

Directions are in the local frame (normal +z, tangent +x), as
:func:`pbrkit.brdf.models.sample` takes them.
"""

from __future__ import annotations

import math
import zlib

import chi2
import numpy as np
import pytest
from quadrature import albedo_nodes, view_direction

from pbrkit import Material
from pbrkit.brdf import models

SEED = 20261123
FAMILY_ALPHA = 0.01

# (id, model, terms, material keyword arguments, view cos theta, view phi)
CASES = [
    ("ggx-iso", "cook_torrance", {}, dict(roughness=0.5, metallic=0.2), 0.7, 0.3),
    ("ggx-smooth-grazing", "cook_torrance", {}, dict(roughness=0.25, metallic=0.9), 0.2, 1.1),
    ("ggx-aniso", "cook_torrance", {}, dict(roughness=0.5, anisotropy=0.7, metallic=0.5), 0.6, 0.9),
    ("beckmann-aniso", "cook_torrance", dict(distribution="beckmann"), dict(roughness=0.6, anisotropy=-0.6), 0.5,
     2.0),
    ("blinn-phong", "cook_torrance", dict(distribution="blinn-phong", masking="separable"), dict(roughness=0.4),
     0.8, 0.0),
    ("no-diffuse", "cook_torrance", dict(diffuse="none"), dict(roughness=0.45), 0.6, 0.5),
    ("eon", "cook_torrance", dict(diffuse="eon"), dict(roughness=0.8, metallic=0.1), 0.35, 0.5),
    ("filament", "filament", {}, dict(roughness=0.35, metallic=0.3), 0.9, 0.2),
    ("filament-aniso-burley", "filament", dict(diffuse="burley"), dict(roughness=0.4, anisotropy=0.8), 0.55, 0.7),
    ("ue4", "ue4", {}, dict(roughness=0.3, metallic=0.1), 0.5, 0.4),
    ("urp_mobile", "urp_mobile", {}, dict(roughness=0.6, metallic=0.4), 0.4, 1.5),
    ("disney", "disney", {}, dict(roughness=0.5, metallic=0.3, sheen=0.6, subsurface=0.5), 0.65, 0.25),
    ("disney-coat-aniso", "disney", {}, dict(roughness=0.45, anisotropy=0.8, clearcoat=1.0, clearcoat_gloss=0.3),
     0.5, 0.8),
    ("gltf", "gltf", {}, dict(roughness=0.4, metallic=0.35), 0.45, 0.6),
    ("gltf-smooth-grazing", "gltf", {}, dict(roughness=0.15, metallic=0.0), 0.15, 2.2),
    ("gltf-sheen", "gltf", {}, dict(roughness=0.4, metallic=0.0, sheen_color=np.ones(3), sheen_roughness=0.5), 0.45,
     0.6),
    ("gltf-sheen-metal", "gltf", {}, dict(roughness=0.3, metallic=1.0, sheen_color=np.array([0.9, 0.6, 0.3]),
                                          sheen_roughness=0.25), 0.3, 1.3),
    ("gltf-coat", "gltf", {}, dict(roughness=0.5, metallic=0.2, clearcoat=1.0, clearcoat_roughness=0.1), 0.6, 0.4),
    ("gltf-coat-sheen-specular", "gltf", {}, dict(roughness=0.35, metallic=0.5, clearcoat=0.4,
                                                  clearcoat_roughness=0.3, sheen_color=np.array([0.5, 0.4, 0.3]),
                                                  sheen_roughness=0.6, specular=0.5, ior=1.8), 0.3, 1.0),
    ("gltf-iridescence", "gltf", {}, dict(roughness=0.3, metallic=0.4, iridescence=1.0, iridescence_ior=1.8,
                                          iridescence_thickness_maximum=300.0), 0.5, 0.7),
]
N_SAMPLES = 200_000
ALPHA_TEST = chi2.sidak_alpha(FAMILY_ALPHA, len(CASES))


def _material(kwargs):
    base = dict(base_color=np.array([0.8, 0.45, 0.2]))
    base.update(kwargs)
    return Material(**base)


def _u(case_id, n=N_SAMPLES):
    return np.random.default_rng([SEED, zlib.crc32(case_id.encode())]).random((n, 3))


bxdf_chi2 = chi2.hemisphere_chi2_with_failures


def _run(case_id, model, terms, material, mu, phi, pdf_model=None, pdf_material=None):
    wo = view_direction(mu, phi)
    wi, pdf_s, weight = models.sample(model, material, wo, _u(case_id), **terms)
    ok = pdf_s > 0.0
    assert np.all(wi[ok, 2] > 0.0) and np.all(np.isfinite(weight))

    def pdf(x, y, z):
        d = np.stack(np.broadcast_arrays(x, y, z), axis=-1)
        return models.pdf(pdf_model or model, pdf_material or material, wo, d, **terms)

    return (*bxdf_chi2(wi[ok], ok.size, pdf), wi, pdf_s, weight, ok)


@pytest.mark.slow
@pytest.mark.parametrize("case_id, model, terms, kwargs, mu, phi", CASES, ids=[c[0] for c in CASES])
def test_sampling_routine_matches_its_pdf(case_id, model, terms, kwargs, mu, phi):
    material = _material(kwargs)
    p_value, integral, success, wi, pdf_s, weight, ok = _run(case_id, model, terms, material, mu, phi)
    assert p_value > ALPHA_TEST, f"{case_id}: p = {p_value:.3g}, integral {integral:.6f}, success {success:.6f}"
    # the pdf integrates to 1 minus the probability of a failed sample (binomial error, 5 sigma + quadrature)
    sigma = math.sqrt(max(success * (1.0 - success), 1.0 / N_SAMPLES) / N_SAMPLES)
    assert abs(integral - success) < 5.0 * sigma + 1e-4, case_id
    # pdf returned by sample() is the pdf function's value at the sample
    wo = view_direction(mu, phi)
    np.testing.assert_allclose(pdf_s[ok][:2000], models.pdf(model, material, wo, wi[ok][:2000], **terms),
                               rtol=1e-12)


def _white(model, roughness, **extra):
    return Material(base_color=np.ones(3), metallic=1.0, roughness=roughness, **extra)


@pytest.mark.parametrize("model, terms, roughness, anisotropy, mu", [
    ("cook_torrance", dict(fresnel="none", diffuse="none"), 0.3, 0.0, 0.4),
    ("cook_torrance", dict(fresnel="none", diffuse="none", distribution="beckmann", masking="separable"), 0.6, 0.5,
     0.7),
    ("filament", {}, 0.5, -0.7, 0.3),
    ("disney", {}, 0.7, 0.6, 0.8),
    ("gltf", {}, 0.35, 0.0, 0.25),
])
def test_white_furnace_with_the_models_own_sampler(model, terms, roughness, anisotropy, mu):
    """E(mu) = integral f cos = mean of the sampler's weights f cos / pdf (a metal with
    white base: F = 1 for Schlick's f0 = 1), against the independent quadrature of
    the same model's value (tests/support/quadrature.py nodes, which share no code with pbrkit)."""
    material = _white(model, roughness, anisotropy=anisotropy)
    wo = view_direction(mu, 0.4)
    n = 100_000
    _, _, weight = models.sample(model, material, wo, _u(f"furnace-{model}-{roughness}", n), **terms)
    estimate = weight[:, 0].mean()
    stderr = weight[:, 0].std(ddof=1) / math.sqrt(n)
    a = max(roughness * roughness, 1e-3)
    ax, ay = a * (1.0 + anisotropy), a * (1.0 - anisotropy)
    if model == "disney":
        aspect = math.sqrt(1.0 - 0.9 * anisotropy)
        ax, ay = a / aspect, a * aspect
    l, w = albedo_nodes(wo, max(ax, 1e-3), max(ay, 1e-3))
    f = models.evaluate(model, l, np.broadcast_to(wo, l.shape), np.array([0.0, 0.0, 1.0]), material, **terms)
    reference = float(np.sum(f[:, 0] * w))  # the weights carry n.l
    assert 0.2 < reference < 1.01
    assert abs(estimate - reference) < 4.0 * stderr + 1e-3, (estimate, stderr, reference)


@pytest.mark.parametrize("metallic", [0.0, 1.0])
@pytest.mark.parametrize("sheen_roughness", [0.3, 0.6, 1.0])
def test_white_furnace_of_gltf_with_sheen(metallic, sheen_roughness):
    """A white glTF material under a white sheen (sheen_color 1; KHR_materials_sheen's
    albedo scaling): E(mu) = E_sheen + (1 - E_sheen) E_base <= max(1, E_base), by the
    independent quadrature of the model's value and by the mean of its own sampler's
    weights (which agree); + 0.01 for the E table's interpolation error.  The core
    model's white dielectric itself exceeds 1 (1.056 at n.v = 0.25, roughness 0.5:
    glTF's fresnel_mix weights the diffuse by 1 - F(v.h), not by the specular
    albedo); the sheen layer brings it towards 1, never above it or 1."""
    material = Material(base_color=np.ones(3), metallic=metallic, roughness=0.5, sheen_color=np.ones(3),
                        sheen_roughness=sheen_roughness)
    n = 100_000
    for mu in (0.25, 0.7):
        wo = view_direction(mu, 0.4)
        _, _, weight = models.sample("gltf", material, wo, _u(f"sheen-{metallic}-{sheen_roughness}-{mu}", n))
        estimate = weight[:, 0].mean()
        stderr = weight[:, 0].std(ddof=1) / math.sqrt(n)
        l, w = albedo_nodes(wo, 0.25)
        f = models.evaluate("gltf", l, np.broadcast_to(wo, l.shape), np.array([0.0, 0.0, 1.0]), material)
        reference = float(np.sum(f[:, 0] * w))
        core = Material(base_color=np.ones(3), metallic=metallic, roughness=0.5)
        base = float(np.sum(models.evaluate("gltf", l, np.broadcast_to(wo, l.shape), np.array([0.0, 0.0, 1.0]),
                                            core)[:, 0] * w))
        bound = max(1.0, base) + 0.01
        assert reference <= bound, (mu, base, reference)
        # E - 1 = (1 - E_sheen)(E_base - 1): the sheen takes the albedo towards 1
        assert abs(reference - 1.0) <= abs(base - 1.0) + 0.01, (mu, base, reference)
        assert abs(estimate - reference) < 4.0 * stderr + 2e-3, (mu, estimate, stderr, reference)
        assert estimate <= bound + 4.0 * stderr


def test_the_chi2_test_rejects_a_wrong_pdf():
    """The sampler of an anisotropic lobe against the isotropic lobe's pdf, and a
    Disney sampler against the pdf without its clear-coat lobe, must fail."""
    aniso = _material(dict(roughness=0.5, anisotropy=0.7, metallic=0.5))
    iso = _material(dict(roughness=0.5, metallic=0.5))
    p_value, *_ = _run("wrong-aniso", "cook_torrance", {}, aniso, 0.6, 0.9, pdf_material=iso)
    assert p_value < 1e-6
    coat = _material(dict(roughness=0.45, clearcoat=1.0, clearcoat_gloss=0.3))
    no_coat = _material(dict(roughness=0.45))
    p_value, integral, success, *_ = _run("wrong-coat", "disney", {}, coat, 0.5, 0.8, pdf_material=no_coat)
    assert p_value < 1e-6


def test_sample_and_pdf_handle_bad_views_and_numbers():
    material = _material(dict(roughness=0.5))
    wi, pdf_s, weight = models.sample("filament", material, np.array([0.6, 0.0, -0.8]), np.full(3, 0.5))
    assert pdf_s == 0.0 and np.all(wi == 0.0) and np.all(weight == 0.0)
    assert models.pdf("filament", material, np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.6, -0.8])) == 0.0
    with pytest.raises(ValueError, match="u must"):
        models.sample("filament", material, np.array([0.0, 0.0, 1.0]), np.array([0.5, 1.5, 0.2]))
    with pytest.raises(ValueError, match="unknown model"):
        models.sample("phong", material, np.array([0.0, 0.0, 1.0]), np.full(3, 0.5))
