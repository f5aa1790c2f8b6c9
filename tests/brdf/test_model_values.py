"""Every shading model's value against an independent transcription of its source.

pbrkit's NumPy API (:mod:`pbrkit.brdf.models`: ``gltf``, ``ue4``, ``filament``,
``urp_mobile``, ``disney`` and ``cook_torrance`` with every distribution x
masking x Fresnel x diffuse choice, 3 x 6 x 6 x 4) is evaluated on a few hundred
(l, v) pairs -- normal +z, tangent +x; views at normal incidence, grazing,
random and below the horizon; lights near each element's specular peak, random,
grazing, at normal incidence, retro-reflected and below the horizon -- with
random per-element materials (r = 0 and r = 1 included, anisotropic elements
for the models that have them, gold's complex IOR for the exact conductor),
and compared with the models of ``tests/support/reference_brdf.py``, written from the
published sources and importing nothing from pbrkit.  So the check is against
values computed independently, never against the code's own earlier output.

Tolerance: relative 1e-10 per element and channel, loosened only where the
formula is ill-conditioned: the cosine n.h of a half vector rounded to double
carries an error of a couple of ulps (eps = 2^-52), and the distributions'
relative condition number with respect to n.h grows as 1 / alpha^2 for sharp
lobes (GGX and GTR1: |d ln D / d n.h| = 4 n.h (1 - alpha^2) / (alpha^2 (n.h)^2 + 1 -
(n.h)^2) <= 4 / alpha^2 at the peak; Blinn-Phong: e / n.h with e = 2 / alpha^2 - 2;
Beckmann: 2 / (alpha^2 (n.h)^3) - 4 / n.h).  Any implementation -- pbrkit's and
the transcription alike -- inherits that error, so the bound is

    |pbrkit - reference| <= (1e-10 + 16 eps / alpha_min^2) |reference|   (+ 1e-300),

alpha_min the smallest width among the element's lobes (its alpha, its
anisotropic alphas, Disney's clear coat alpha): 16 eps = 2 ulps x 4 / alpha^2 x
a factor 2 of margin.  It exceeds 1e-10 only for alpha_min < 6e-3 (r < ~0.08)
and reaches 3.6e-9 at alpha = 1e-3, where the measured disagreement is ~2.2e-10
(one ulp of n.h amplified by 1 / alpha^2).  Results below 1e-300 (the denormal
range, where a value carries no relative precision) compare absolutely, and the
exact dielectric Fresnel, which vanishes at reflectance 0 (IOR 1), is allowed an
absolute error of 8 eps in F (times D V; pbrkit's complex-arithmetic F leaves
~1e-22 there).

Also: :func:`pbrkit.brdf.models.sample`'s pdf and weight against
:func:`~pbrkit.brdf.models.pdf` and :func:`~pbrkit.brdf.models.evaluate`
(weight = f cos / pdf), and the weight against the transcription's f at the
sampled directions.

One disagreement with the source is recorded as a strict xfail: Filament's
Burley diffuse takes the remapped roughness alpha = r^2 (Filament documentation
sec. 4.5, f90 = 0.5 + 2 alpha cos^2 theta_d; its shading code passes
``pixel.roughness``), pbrkit's filament model passes the perceptual r.
"""

from __future__ import annotations

import dataclasses
import zlib

import numpy as np
import pytest
import reference_brdf as ref
from model_values import N_DIR, T_DIR, assert_matches

from pbrkit import Material
from pbrkit.brdf import models
from pbrkit.brdf.fresnel import CONDUCTORS

SEED = 20260517
#: Element count of the value checks.
N = 320
#: Samples per model of the sampling checks.
N_SAMPLES = 48


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def _azimuthal(rng, cos_theta):
    phi = rng.uniform(0.0, 2.0 * np.pi, np.shape(cos_theta))
    sin_theta = np.sqrt(np.maximum(1.0 - cos_theta * cos_theta, 0.0))
    return np.stack([sin_theta * np.cos(phi), sin_theta * np.sin(phi), cos_theta], axis=-1)


def _with_extremes(rng, values, extremes, fraction):
    """values with a ``fraction`` of the elements set to each of ``extremes``."""
    values = values.copy()
    for x in extremes:
        values[rng.random(values.shape) < fraction] = x
    return values


def _materials(rng, n):
    """Per-element material values: base colour (a few black and white), metallic,
    roughness (r = 0 and r = 1 included), reflectance, Kulla-Conty anisotropy in [-1, 1]
    and Disney's extras (anisotropy in [0, 1])."""
    base = rng.uniform(0.0, 1.0, (n, 3))
    base[rng.random(n) < 0.04] = 0.0
    base[rng.random(n) < 0.04] = 1.0
    values = {
        "base": base,
        "metallic": _with_extremes(rng, rng.uniform(0.0, 1.0, n), (0.0, 1.0), 0.15),
        "roughness": _with_extremes(rng, rng.uniform(0.0, 1.0, n), (0.0, 1.0), 0.1),
        "reflectance": _with_extremes(rng, rng.uniform(0.0, 1.0, n), (0.0, 1.0), 0.05),
        # about a third isotropic (pbrkit's isotropic code paths), the extremes +-1
        "anisotropy": _with_extremes(rng, _with_extremes(rng, rng.uniform(-1.0, 1.0, n), (1.0, -1.0), 0.06),
                                     (0.0,), 0.35),
        "specular_color": rng.uniform(0.0, 1.0, (n, 3)),
    }
    values["disney"] = {name: _with_extremes(rng, rng.uniform(0.0, 1.0, n), (0.0, 1.0), 0.1)
                        for name in ("subsurface", "specular_tint", "sheen", "sheen_tint", "clearcoat",
                                     "clearcoat_gloss")}
    values["disney_anisotropy"] = np.abs(values["anisotropy"])
    return values


def _directions(rng, values):
    """(l, v) (n, 3) in the local frame: views at normal incidence, grazing (n.v in
    [1e-3, 5e-2]), uniform over the hemisphere and below it; lights near each
    element's specular peak (mirror of v about a normal drawn within a few alphas of
    n, along the anisotropic axes), uniform over the sphere, grazing, at normal
    incidence, retro-reflected (l = v) and below the horizon."""
    n = values["roughness"].shape[0]
    kind = rng.random(n)
    v = _azimuthal(rng, rng.uniform(0.0, 1.0, n))
    v[kind < 0.10] = N_DIR
    grazing = (kind >= 0.10) & (kind < 0.25)
    v[grazing] = _azimuthal(rng, np.exp(rng.uniform(np.log(1e-3), np.log(5e-2), grazing.sum())))
    below = kind >= 0.90
    v[below] = _azimuthal(rng, -rng.uniform(0.0, 1.0, below.sum()))

    alpha = np.maximum(values["roughness"] ** 2, ref.ALPHA_MIN)
    a = values["anisotropy"]
    ax = np.maximum(alpha * (1.0 + a), ref.ALPHA_MIN)
    ay = np.maximum(alpha * (1.0 - a), ref.ALPHA_MIN)
    spread = np.exp(rng.uniform(np.log(0.1), np.log(3.0), n))
    h = _unit(np.stack([ax * spread * rng.normal(size=n), ay * spread * rng.normal(size=n), np.ones(n)], axis=-1))
    mirror = 2.0 * np.sum(v * h, axis=-1, keepdims=True) * h - v
    kind = rng.random(n)
    l = _unit(rng.normal(size=(n, 3)))
    l[kind < 0.45] = mirror[kind < 0.45]
    grazing = (kind >= 0.75) & (kind < 0.85)
    l[grazing] = _azimuthal(rng, np.exp(rng.uniform(np.log(1e-3), np.log(5e-2), grazing.sum())))
    l[(kind >= 0.85) & (kind < 0.90)] = N_DIR
    retro = (kind >= 0.90) & (kind < 0.95)
    l[retro] = v[retro]
    below = kind >= 0.95
    l[below] = _azimuthal(rng, -rng.uniform(0.0, 1.0, below.sum()))
    return l, v


def _alpha_min(values, model):
    """The smallest lobe width of each element under ``model`` (the tolerance's alpha_min)."""
    alpha = np.maximum(values["roughness"] ** 2, ref.ALPHA_MIN)
    if model in ("gltf", "ue4", "urp_mobile"):
        return alpha
    if model == "disney":
        aspect = np.sqrt(1.0 - 0.9 * values["disney_anisotropy"])
        width = np.maximum(alpha * aspect, ref.ALPHA_MIN)
        extra = values["disney"]
        coat = 0.1 + (0.001 - 0.1) * extra["clearcoat_gloss"]
        return np.where(extra["clearcoat"] > 0.0, np.minimum(width, coat), width)
    return np.maximum(alpha * (1.0 - np.abs(values["anisotropy"])), ref.ALPHA_MIN)


@pytest.fixture(scope="module")
def case():
    rng = np.random.default_rng(SEED)
    values = _materials(rng, N)
    l, v = _directions(rng, values)
    return values, l, v


def _material(values, model):
    """pbrkit's Material of the per-element values for ``model``."""
    common = dict(base_color=values["base"], metallic=values["metallic"], roughness=values["roughness"],
                  reflectance=values["reflectance"])
    if model in ("gltf", "ue4", "urp_mobile"):
        return Material(**common)
    if model == "disney":
        return Material(**common, anisotropy=values["disney_anisotropy"], **values["disney"])
    return Material(**common, anisotropy=values["anisotropy"], specular_color=values["specular_color"])


def _reference(values, model, l, v, **terms):
    """The transcription of ``model`` for the per-element values."""
    b, m, r, refl = values["base"], values["metallic"], values["roughness"], values["reflectance"]
    if model == "gltf":
        return ref.gltf_brdf(l, v, b, m, r)
    if model == "ue4":
        return ref.ue4_brdf(l, v, b, m, r, refl)
    if model == "urp_mobile":
        return ref.urp_mobile_brdf(l, v, b, m, r)
    if model == "filament":
        return ref.filament_brdf(l, v, b, m, r, refl, values["anisotropy"], **terms)
    if model == "disney":
        return ref.disney_brdf(l, v, b, m, r, refl, values["disney_anisotropy"], **values["disney"])
    return ref.cook_torrance_brdf(l, v, b, m, r, refl, values["anisotropy"], terms["distribution"],
                                  terms["masking"], terms["fresnel"], terms["diffuse"],
                                  specular_color=values["specular_color"])


# ------------------------------------------------------------------ the fixed models


@pytest.mark.parametrize("model", ["gltf", "ue4", "urp_mobile", "disney"])
def test_model_value_matches_transcription(case, model):
    values, l, v = case
    material = _material(values, model)
    if model == "disney":
        actual = models.disney(l, v, N_DIR, material, t=T_DIR)
    else:
        actual = getattr(models, model)(l, v, N_DIR, material)
    assert_matches(actual, _reference(values, model, l, v), _alpha_min(values, model), model)


@pytest.mark.parametrize("diffuse", [
    "lambert",
    "none",
    pytest.param("burley", marks=pytest.mark.xfail(
        strict=True, reason="pbrkit's filament Burley diffuse takes the perceptual roughness r; Filament's "
                            "documentation (sec. 4.5: f90 = 0.5 + 2 alpha cos^2 theta_d, alpha the remapped "
                            "roughness) and shading code (diffuse(pixel.roughness, ...)) take alpha = r^2")),
])
def test_filament_value_matches_transcription(case, diffuse):
    values, l, v = case
    actual = models.filament(l, v, N_DIR, _material(values, "filament"), diffuse=diffuse, t=T_DIR)
    assert_matches(actual, _reference(values, "filament", l, v, diffuse=diffuse),
                   _alpha_min(values, "filament"), f"filament {diffuse}")


def test_filament_burley_differs_from_the_source_only_by_its_roughness(case):
    """pbrkit's filament Burley diffuse is the transcription with Burley 2012's perceptual
    roughness in F_D90 instead of Filament's alpha: the disagreement above is that one
    parameter and nothing else."""
    values, l, v = case
    actual = models.filament(l, v, N_DIR, _material(values, "filament"), diffuse="burley", t=T_DIR)
    expected = _reference(values, "filament", l, v, diffuse="burley", burley_roughness="perceptual")
    assert_matches(actual, expected, _alpha_min(values, "filament"), "filament burley (perceptual r)")


# ------------------------------------------------------------------ cook_torrance


def _dv(values, l, v, terms):
    """The transcription's specular lobe without Fresnel, D V (N,): F = 1, no diffuse."""
    white = dict(terms, fresnel="none", diffuse="none")
    return ref.cook_torrance_brdf(l, v, values["base"], values["metallic"], values["roughness"],
                                  values["reflectance"], values["anisotropy"], specular_color=1.0, **white)[:, 0]

TERMS = [(d, m, f, s) for d in ref.CT_DISTRIBUTIONS for m in ref.CT_MASKINGS for f in ref.CT_FRESNELS
         for s in ref.CT_DIFFUSES]


def test_the_term_names_are_pbrkits():
    """The transcription spells the terms as pbrkit's API does, so the product below is
    every combination pbrkit has."""
    assert ref.CT_DISTRIBUTIONS == models.DISTRIBUTIONS
    assert ref.CT_MASKINGS == models.MASKINGS
    assert ref.CT_FRESNELS == models.FRESNELS
    assert ref.CT_DIFFUSES == models.DIFFUSES
    assert len(TERMS) == 3 * 6 * 6 * 4


def test_gold_is_the_transcriptions_gold():
    """Material.conductor("gold") carries the complex IOR the transcription uses."""
    gold = Material.conductor("gold")
    np.testing.assert_array_equal(CONDUCTORS["gold"], ref.GOLD_ETA_K)
    np.testing.assert_array_equal(gold.eta, ref.GOLD_ETA_K[0])
    np.testing.assert_array_equal(gold.k, ref.GOLD_ETA_K[1])


@pytest.mark.parametrize("distribution, masking, fresnel, diffuse", TERMS, ids=["-".join(t) for t in TERMS])
def test_cook_torrance_value_matches_transcription(case, distribution, masking, fresnel, diffuse):
    values, l, v = case
    terms = dict(distribution=distribution, masking=masking, fresnel=fresnel, diffuse=diffuse)
    what = f"cook_torrance {distribution} / {masking} / {fresnel} / {diffuse}"
    alpha_min = _alpha_min(values, "cook_torrance")
    if distribution == "blinn-phong":  # isotropic: the anisotropy is ignored
        alpha_min = np.maximum(values["roughness"] ** 2, ref.ALPHA_MIN)
    if fresnel != "exact-conductor":
        actual = models.cook_torrance(l, v, N_DIR, _material(values, "cook_torrance"), t=T_DIR, **terms)
        assert_matches(actual, _reference(values, "cook_torrance", l, v, **terms), alpha_min, what,
                       lobe=_dv(values, l, v, terms) if fresnel == "exact-dielectric" else None)
        return
    # gold as Material.conductor makes it (metallic 1, no diffuse), and gold's IOR under a
    # random metallic-workflow base (the diffuse lobe beside the exact conductor's F)
    gold = Material.conductor("gold", roughness=values["roughness"], reflectance=values["reflectance"],
                              anisotropy=values["anisotropy"])
    mixed = dataclasses.replace(gold, base_color=values["base"], metallic=values["metallic"])
    for material in (gold, mixed):
        actual = models.cook_torrance(l, v, N_DIR, material, t=T_DIR, **terms)
        base = np.broadcast_to(material.base_color, (N, 3))
        expected = ref.cook_torrance_brdf(l, v, base, np.broadcast_to(material.metallic, (N,)),
                                          values["roughness"], values["reflectance"], values["anisotropy"],
                                          eta=ref.GOLD_ETA_K[0], k=ref.GOLD_ETA_K[1], **terms)
        assert_matches(actual, expected, alpha_min, what)


# ------------------------------------------------------------------ sampling

SAMPLED = ([("gltf", {}), ("ue4", {}), ("urp_mobile", {}), ("disney", {}),
            ("filament", {"diffuse": "lambert"}), ("filament", {"diffuse": "burley"}),
            ("filament", {"diffuse": "none"})]
           + [("cook_torrance", dict(distribution=d, masking=ref.CT_MASKINGS[i % len(ref.CT_MASKINGS)],
                                     fresnel=f, diffuse=s))
              for i, (d, f, s) in enumerate((d, f, s) for d in ref.CT_DISTRIBUTIONS for f in ref.CT_FRESNELS
                                           for s in ref.CT_DIFFUSES)])


@pytest.mark.parametrize("model, terms", SAMPLED,
                         ids=["-".join((m,) + tuple(t.values())) for m, t in SAMPLED])
def test_sample_pdf_and_weight_are_the_models(case, model, terms):
    """models.sample's pdf is models.pdf at the sampled direction, its weight is
    f cos / pdf with f of models.evaluate (both to 1e-12: the same compiled value), and
    that weight matches the transcription's f cos / pdf (the value tolerance); a failed
    sample has pdf 0, weight 0 and wi 0."""
    values, _, v_all = case
    rng = np.random.default_rng([SEED, zlib.crc32("-".join((model,) + tuple(terms.values())).encode())])
    keep = np.flatnonzero(v_all[:, 2] > 0.0)[:N_SAMPLES]
    sub = {key: (val[keep] if isinstance(val, np.ndarray) else {k: x[keep] for k, x in val.items()})
           for key, val in values.items()}
    wo = v_all[keep]
    if model == "cook_torrance" and terms["fresnel"] == "exact-conductor":
        material = dataclasses.replace(
            Material.conductor("gold", roughness=sub["roughness"], reflectance=sub["reflectance"],
                               anisotropy=sub["anisotropy"]), base_color=sub["base"], metallic=sub["metallic"])
    else:
        material = _material(sub, model)
    u = rng.uniform(0.0, 1.0, (keep.size, 3))
    wi, pdf, weight = models.sample(model, material, wo, u, **terms)
    ok = pdf > 0.0
    assert ok.sum() >= keep.size // 2, f"{model} {terms}: {np.sum(~ok)} of {keep.size} samples failed"
    assert np.all(weight[~ok] == 0.0) and np.all(wi[~ok] == 0.0)
    assert np.all(np.isfinite(pdf)) and np.all(np.isfinite(weight))
    np.testing.assert_allclose(models.pdf(model, material, wo, wi, **terms)[ok], pdf[ok], rtol=1e-12, atol=0.0)
    f = models.evaluate(model, wi, wo, N_DIR, material, t=T_DIR, **terms)
    np.testing.assert_allclose(weight[ok], (f * (wi[:, 2] / np.where(ok, pdf, 1.0))[:, None])[ok], rtol=1e-12,
                               atol=0.0)
    if model == "cook_torrance" and terms["fresnel"] == "exact-conductor":
        expected = ref.cook_torrance_brdf(wi, wo, sub["base"], sub["metallic"], sub["roughness"], sub["reflectance"],
                                          sub["anisotropy"], eta=ref.GOLD_ETA_K[0], k=ref.GOLD_ETA_K[1], **terms)
    else:
        expected = _reference(sub, model, wi, wo, **terms)
    alpha_min = _alpha_min(sub, model)
    if model == "filament" and terms["diffuse"] == "burley":  # the recorded disagreement (xfail above)
        expected = ref.filament_brdf(wi, wo, sub["base"], sub["metallic"], sub["roughness"], sub["reflectance"],
                                     sub["anisotropy"], diffuse="burley", burley_roughness="perceptual")
    if model == "cook_torrance" and terms["distribution"] == "blinn-phong":
        alpha_min = np.maximum(sub["roughness"] ** 2, ref.ALPHA_MIN)
    cos_over_pdf = wi[:, 2] / np.where(ok, pdf, 1.0)
    lobe = None
    if model == "cook_torrance" and terms["fresnel"] == "exact-dielectric":
        lobe = (_dv(sub, wi, wo, terms) * cos_over_pdf)[ok]
    assert_matches(weight[ok], (expected * cos_over_pdf[:, None])[ok], alpha_min[ok],
                   f"sampled weight of {model} {terms}", lobe=lobe)
