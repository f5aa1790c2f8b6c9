"""The layering operators (pbrkit.brdf.operators) on lobes of pbrkit.brdf.lobes:
for every operator, its value against an independent transcription of its
definition (the glTF 2.0 Appendix B and KHR formulas, written here from the
specifications with the microfacet terms of tests/support/reference_brdf.py), its
directional albedo against the independent quadrature of tests/support/quadrature.py,
and the composed sampling routine against the composed pdf (chi-square, with
the failed samples as a cell); and proof that a wrong lobe weight, or a pdf
with wrong lobe probabilities, is caught."""

from __future__ import annotations

import math
import zlib

import chi2
import numba
import numpy as np
import pytest
from quadrature import albedo_nodes, hemisphere_rule, view_direction
from reference_brdf import d_ggx, eon_diffuse, fresnel_schlick, lambda_ggx

from pbrkit.brdf.bxdf import EXTRA_SLOTS, BxDF, local_cosines
from pbrkit.brdf.lobes.diffuse import BURLEY, LAMBERT
from pbrkit.brdf.lobes.eon import EON
from pbrkit.brdf.lobes.microfacet import microfacet
from pbrkit.brdf.operators import add, compose, fresnel_mix, layer, mix, weighted
from pbrkit.brdf.terms import CONSTANT, GGX, SEPARABLE
from pbrkit.core.jit import dual_use

SEED = 20261127
RHO = (0.7, 0.45, 0.2)
ROUGHNESS = 0.55
ALPHA = ROUGHNESS * ROUGHNESS
#: The white GGX lobe with separable Smith masking and F = 1 (the constant colour, white).
SPECULAR = microfacet(GGX, SEPARABLE, CONSTANT)


def record(metallic=0.35, roughness=ROUGHNESS):
    """A BxDF with a diffuse colour RHO, a white constant F and an isotropic GGX lobe."""
    z3 = (0.0, 0.0, 0.0)
    alpha = max(roughness * roughness, 1e-3)
    return BxDF(0, 0, 1, 5, 0, roughness, alpha, alpha, alpha, False, 0.0, metallic, RHO, RHO, (0.04,) * 3, 1.0, z3, z3,
                0.04, (1.0, 1.0, 1.0), (0.0,) * EXTRA_SLOTS)


@dual_use(inline=True)
def _metallic(b):
    return b.metallic


@dual_use(inline=True)
def _half_weight(b, c):
    return 0.5 + 0.5 * c.voh


def _harness(composition):
    """Compiled loops over the composed value, sampling routine and pdf."""
    value, probabilities, sample, pdf = (composition.value, composition.probabilities, composition.sample,
                                         composition.pdf)

    @numba.njit
    def values(b, wo, wi, out):
        for i in range(wi.shape[0]):
            c = local_cosines(wo[0], wo[1], wo[2], wi[i, 0], wi[i, 1], wi[i, 2])
            f = value(b, c, (1.0, 1.0, 1.0))
            ok = c.nol > 0.0 and c.nov > 0.0
            for a in range(3):
                out[i, a] = f[a] if ok else 0.0

    @numba.njit
    def samples(b, wo, u, out):
        p_spec, p_coat = probabilities(b, wo[2])
        for i in range(u.shape[0]):
            x, y, z = sample(b, wo[0], wo[1], wo[2], u[i, 0], u[i, 1], u[i, 2], p_spec, p_coat)
            length = math.sqrt(x * x + y * y + z * z)
            out[i, 0] = x / length
            out[i, 1] = y / length
            out[i, 2] = z / length

    @numba.njit
    def pdfs(b, wo, wi, out, shift):
        p_spec, p_coat = probabilities(b, wo[2])
        p_spec = min(max(p_spec + shift, 0.0), 1.0 - p_coat)
        for i in range(wi.shape[0]):
            c = local_cosines(wo[0], wo[1], wo[2], wi[i, 0], wi[i, 1], wi[i, 2])
            out[i] = pdf(b, c, p_spec, p_coat) if c.nol > 0.0 else 0.0

    return values, samples, pdfs


def _evaluate(fn, b, wo, wi, *extra):
    out = np.empty((wi.shape[0], 3)) if not extra else np.empty(wi.shape[0])
    fn(b, wo, np.ascontiguousarray(wi, dtype=np.float64), out, *extra)
    return out


def _quadrature_albedo(values, b, mu, alpha=ALPHA):
    """The independent quadrature of f cos over the hemisphere (tests/support/quadrature.py's
    half-vector rule around the lobe), RGB."""
    wo = view_direction(mu, 0.3)
    l, w = albedo_nodes(wo, alpha)
    return np.tensordot(w, _evaluate(values, b, wo, l), axes=(0, 0))


def _reference_dv(l, v, alpha):
    """D V of GGX with separable Smith masking, from tests/support/reference_brdf.py."""
    h = l + v
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    nol, nov = l[:, 2], v[2]
    g2 = 1.0 / ((1.0 + lambda_ggx(nol, alpha)) * (1.0 + lambda_ggx(nov, alpha)))
    dv = d_ggx(h[:, 2], h[:, 0] ** 2 + h[:, 1] ** 2, alpha) * g2 / (4.0 * nol * nov)
    return dv, np.clip(h @ v, 0.0, 1.0)


#: (id, composition, reference value f(l, v, b) (N, 3) written from the definition)
def _cases():
    rho = np.asarray(RHO)
    f0 = ((1.5 - 1.0) / (1.5 + 1.0)) ** 2

    def ref_add(l, v, b):
        dv, _ = _reference_dv(l, v, b.alpha)
        return rho / np.pi + dv[:, None]

    def ref_mix(l, v, b):
        dv, _ = _reference_dv(l, v, b.alpha)
        return (1.0 - b.metallic) * rho / np.pi + b.metallic * dv[:, None]

    def ref_fresnel_mix(l, v, b):  # glTF 2.0 Appendix B.3.4: mix(base, layer, F), F Schlick of IOR 1.5 at v.h
        dv, voh = _reference_dv(l, v, b.alpha)
        f = fresnel_schlick(voh, f0)[:, None]
        return (1.0 - f) * rho / np.pi + f * dv[:, None]

    def ref_weighted(l, v, b):
        dv, voh = _reference_dv(l, v, b.alpha)
        return (0.5 + 0.5 * voh)[:, None] * rho / np.pi + dv[:, None]

    def ref_layer(l, v, b):  # albedo scaling (KHR_materials_sheen): top + (1 - max E_top(n.v)) base
        dv, _ = _reference_dv(l, v, b.alpha)
        e_top = EON.albedo(b, v[2])
        return eon_diffuse(l, v, rho, b.roughness) + (1.0 - max(e_top)) * dv[:, None]

    return [
        ("add", add(LAMBERT, SPECULAR), ref_add),
        ("mix", mix(LAMBERT, SPECULAR, _metallic), ref_mix),
        ("fresnel_mix", fresnel_mix(1.5, LAMBERT, SPECULAR), ref_fresnel_mix),
        ("weighted", add(weighted(_half_weight, LAMBERT), SPECULAR), ref_weighted),
        ("layer", layer(EON, SPECULAR), ref_layer),
    ]


CASES = _cases()


@pytest.mark.parametrize("case_id, composition, reference", CASES, ids=[c[0] for c in CASES])
def test_operator_value_is_its_definition(case_id, composition, reference):
    b = record()
    values, _, _ = _harness(compose(composition))
    rng = np.random.default_rng([SEED, zlib.crc32(case_id.encode())])
    for mu in (0.9, 0.4, 0.1):
        v = view_direction(mu, 0.3)
        l = rng.normal(size=(2000, 3))
        l /= np.linalg.norm(l, axis=1, keepdims=True)
        l[:, 2] = np.abs(l[:, 2]) + 1e-3
        l /= np.linalg.norm(l, axis=1, keepdims=True)
        np.testing.assert_allclose(_evaluate(values, b, v, l), reference(l, v, b), rtol=1e-11, atol=1e-14)


@pytest.mark.parametrize("case_id, composition, reference", CASES, ids=[c[0] for c in CASES])
def test_operator_albedo_against_independent_quadrature(case_id, composition, reference):
    """The composition's own albedo (quadrature through its mixture sampling routine)
    against the independent quadrature of its value; for add, mix and layer also
    the operator's rule on its operands' albedos (E_a + E_b, (1 - w) E_a + w E_b,
    E_top + (1 - max E_top) E_base)."""
    b = record()
    composed = compose(composition)
    values, _, _ = _harness(composed)
    rules = {"add": lambda ea, eb: ea + eb, "mix": lambda ea, eb: (1.0 - b.metallic) * ea + b.metallic * eb,
             "layer": lambda ea, eb: ea + (1.0 - max(ea)) * eb}
    operands = {"add": (LAMBERT, SPECULAR), "mix": (LAMBERT, SPECULAR), "layer": (EON, SPECULAR)}
    for mu in (0.95, 0.5, 0.15):
        reference_albedo = _quadrature_albedo(values, b, mu)
        np.testing.assert_allclose(composed.albedo(b, mu), reference_albedo, rtol=2e-4, atol=1e-6)
        if case_id in rules:
            a, c = operands[case_id]
            rule = rules[case_id](np.asarray(a.albedo(b, mu)), np.asarray(c.albedo(b, mu)))
            np.testing.assert_allclose(rule, reference_albedo, rtol=2e-4, atol=1e-6)


def test_a_wrong_lobe_weight_is_caught():
    """The albedo check above rejects a mix whose weight is off by 0.02."""
    b = record()
    values, _, _ = _harness(compose(mix(LAMBERT, SPECULAR, _metallic)))
    reference = _quadrature_albedo(values, b, 0.5)
    w = b.metallic + 0.02
    wrong = (1.0 - w) * np.asarray(LAMBERT.albedo(b, 0.5)) + w * np.asarray(SPECULAR.albedo(b, 0.5))
    assert np.max(np.abs(wrong / reference - 1.0)) > 10 * 2e-4


N_SAMPLES = 120_000
ALPHA_TEST = chi2.sidak_alpha(0.01, len(CASES))


def _chi2(case_id, composition, mu, shift=0.0):
    b = record()
    _, samples, pdfs = _harness(compose(composition))
    wo = view_direction(mu, 0.7)
    u = np.random.default_rng([SEED, zlib.crc32(case_id.encode())]).random((N_SAMPLES, 3))
    wi = np.empty((N_SAMPLES, 3))
    samples(b, wo, u, wi)
    ok = wi[:, 2] > 0.0

    def pdf(x, y, z):
        d = np.stack(np.broadcast_arrays(x, y, z), axis=-1).reshape(-1, 3)
        out = np.empty(d.shape[0])
        pdfs(b, wo, np.ascontiguousarray(d), out, shift)
        return out.reshape(np.shape(x))

    return chi2.hemisphere_chi2_with_failures(wi[ok], N_SAMPLES, pdf)


@pytest.mark.slow
@pytest.mark.parametrize("case_id, composition, reference", CASES, ids=[c[0] for c in CASES])
def test_composed_sampling_matches_composed_pdf(case_id, composition, reference):
    for mu in (0.8, 0.3):
        p_value, integral, success = _chi2(case_id, composition, mu)
        assert p_value > ALPHA_TEST, (case_id, mu, p_value)
        sigma = math.sqrt(max(success * (1.0 - success), 1.0 / N_SAMPLES) / N_SAMPLES)
        assert abs(integral - success) < 5.0 * sigma + 1e-4, (case_id, mu)


def test_a_pdf_with_wrong_lobe_probabilities_is_rejected():
    """The same samples against the mixture's pdf with the specular probability off by 0.05."""
    p_value, *_ = _chi2("wrong", add(LAMBERT, SPECULAR), 0.6, shift=0.05)
    assert p_value < 1e-6


def test_probabilities_follow_the_estimates_with_their_clamps():
    """p_spec = clamp(w_s / (w_s + w_d), 0.1, 0.9) with w_s = luminance(F = 1) = 1 and
    w_d = luminance(rho)(1 - metallic); a mix scales the estimates by its weights."""
    lum = 0.2126 * RHO[0] + 0.7152 * RHO[1] + 0.0722 * RHO[2]
    for metallic in (0.0, 0.35, 0.95):
        b = record(metallic=metallic)
        wd = lum * (1.0 - metallic)
        p_spec, p_coat = compose(add(LAMBERT, SPECULAR)).probabilities(b, 0.5)
        assert p_coat == 0.0 and p_spec == pytest.approx(min(max(1.0 / (1.0 + wd), 0.1), 0.9), rel=1e-14)
        p_spec, _ = compose(mix(LAMBERT, SPECULAR, _metallic)).probabilities(b, 0.5)
        ws, wdm = metallic, wd * (1.0 - metallic)
        expected = 1.0 if wdm <= 0.0 else (0.0 if ws <= 0.0 else min(max(ws / (ws + wdm), 0.1), 0.9))
        assert p_spec == pytest.approx(expected, rel=1e-14)


def test_compose_refuses_what_it_cannot_sample():
    with pytest.raises(ValueError, match="at most one specular"):
        compose(add(SPECULAR, SPECULAR))
    with pytest.raises(TypeError, match="top must be a lobe"):
        layer(add(LAMBERT, SPECULAR), LAMBERT)


def test_gltf_specification_and_the_folded_composition_agree():
    """glTF 2.0 Appendix B as written (mix(fresnel_mix(1.5, diffuse, specular),
    conductor_fresnel(base, specular), metallic)) and the composition the model
    evaluates (the metallic mix folded into f0) agree to rounding."""
    from pbrkit.brdf.models import model_codes
    from pbrkit.brdf.dispatch import make_bxdf
    from pbrkit.brdf.shading import gltf
    from pbrkit.brdf.shading.registry import LAYOUT

    spec_values, _, _ = _harness(compose(_as_sampled(gltf.SPECIFICATION)))
    model_values, _, _ = _harness(compose(gltf.COMPOSITION))
    rng = np.random.default_rng(SEED)
    params = np.zeros((1, LAYOUT.size))
    for metallic, roughness in ((0.0, 0.3), (0.4, 0.6), (1.0, 0.9)):
        b = make_bxdf(model_codes("gltf"), 0, params, 0, roughness, metallic, 0.9, 0.5, 0.1)
        v = view_direction(0.6, 0.2)
        l = rng.normal(size=(500, 3))
        l[:, 2] = np.abs(l[:, 2]) + 0.05
        l /= np.linalg.norm(l, axis=1, keepdims=True)
        np.testing.assert_allclose(_evaluate(spec_values, b, v, l), _evaluate(model_values, b, v, l),
                                   rtol=1e-13, atol=1e-15)


def _as_sampled(node):
    """A specification node whose lobes carry no sampling, with a diffuse lobe added at
    weight 0 so that :func:`compose` accepts it (only its value is compared)."""
    return add(node, weighted(_zero, LAMBERT))


@dual_use(inline=True)
def _zero(b, c):
    return 0.0


def _hemisphere_albedo(values, b, mu, n=256):
    """The independent product rule of tests/support/quadrature.py over the whole hemisphere
    (broad lobes whose value has kinks, such as EON's max(n.l, n.v))."""
    wo = view_direction(mu, 0.3)
    l, w = hemisphere_rule(n, n)
    return np.tensordot(w * l[:, 2], _evaluate(values, b, wo, l), axes=(0, 0))


def test_burley_and_eon_albedo():
    """Burley's albedo by the half-vector quadrature, and EON's closed form, against the
    independent product rule over the hemisphere."""
    b = record(roughness=0.8)
    for lobe in (BURLEY, EON):
        values, _, _ = _harness(compose(lobe))
        for mu in (0.9, 0.4, 0.05):
            np.testing.assert_allclose(lobe.albedo(b, mu), _hemisphere_albedo(values, b, mu), rtol=5e-5)


def test_eon_is_energy_preserving_reciprocal_and_lambert_when_smooth():
    """EON (Portsmouth et al. 2025): a white EON reflects everything at every view and
    roughness (closed form and quadrature), it is reciprocal, and r = 0 is Lambert."""
    values, _, _ = _harness(compose(EON))
    z3 = (0.0, 0.0, 0.0)
    for r in (0.0, 0.3, 1.0):
        white = BxDF(0, 0, 0, 0, 3, r, 0.1, 0.1, 0.1, False, 0.0, 0.0, (1.0,) * 3, (1.0,) * 3, z3, 1.0, z3, z3, 0.04,
                     z3, (0.0,) * EXTRA_SLOTS)
        for mu in (0.95, 0.5, 0.1):
            np.testing.assert_allclose(EON.albedo(white, mu), 1.0, rtol=1e-12)
            np.testing.assert_allclose(_hemisphere_albedo(values, white, mu), 1.0, rtol=1e-4)
    rng = np.random.default_rng(SEED)
    b = record(roughness=0.7)
    for _ in range(20):
        l, v = rng.normal(size=(2, 3))
        l[2], v[2] = abs(l[2]), abs(v[2])
        l /= np.linalg.norm(l)
        v /= np.linalg.norm(v)
        np.testing.assert_allclose(_evaluate(values, b, v, l[None]), _evaluate(values, b, l, v[None]), rtol=1e-12)
    smooth = record(roughness=0.0)
    l = view_direction(0.3, 2.0)[None]
    np.testing.assert_allclose(_evaluate(values, smooth, view_direction(0.8, 0.1), l)[0], np.asarray(RHO) / np.pi,
                               rtol=1e-12)
