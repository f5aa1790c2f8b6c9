"""KHR_materials_anisotropy in the ``gltf`` model: the value against the independent
transcription of the extension's README (tests/support/reference_brdf.py
``gltf_anisotropy_brdf``: its D_GGX_anisotropic and V_GGX_anisotropic in the frame
turned by anisotropyRotation) at many random inputs and frames (1e-9 relative),
strength 0 bitwise the core model, the sampled weights and pdf against it, a
chi-square test of the composed sampler with a turned direction, the white furnace,
the shading frame's handedness, and the glTF files' factors and refusals."""

from __future__ import annotations

import zlib

import chi2
import numpy as np
import pytest
import reference_brdf as ref
from model_values import assert_matches
from quadrature import albedo_nodes, view_direction

from pbrkit import Material
from pbrkit.brdf import models
from pbrkit.brdf.bxdf import shading_frame

SEED = 20261128
N = 400
RTOL = 1e-9
Z = np.array([0.0, 0.0, 1.0])


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def _rng(tag):
    return np.random.default_rng([SEED, zlib.crc32(tag.encode())])


def _case(n=N):
    rng = _rng("case")
    u = rng.uniform
    values = dict(base=u(0.0, 1.0, (n, 3)), metallic=u(0.0, 1.0, n), roughness=u(0.05, 1.0, n),
                  strength=u(0.0, 1.0, n), rotation=u(-np.pi, np.pi, n))
    values["strength"][rng.random(n) < 0.1] = 1.0
    normal = _unit(rng.normal(size=(n, 3)))
    tangent = _unit(rng.normal(size=(n, 3)))  # not orthogonal to n: the frame projects it
    # view and light about the normal: mostly above, some below
    v = _unit(rng.normal(size=(n, 3)))
    l = _unit(rng.normal(size=(n, 3)))
    v = np.where((np.sum(v * normal, axis=1) < 0.0)[:, None] & (rng.random((n, 1)) < 0.9), -v, v)
    l = np.where((np.sum(l * normal, axis=1) < 0.0)[:, None] & (rng.random((n, 1)) < 0.9), -l, l)
    return values, normal, tangent, l, v


def _material(values, **override):
    values = dict(values, **override)
    return Material(base_color=values["base"], metallic=values["metallic"], roughness=values["roughness"],
                    anisotropy_strength=values["strength"], anisotropy_rotation=values["rotation"])


def _alpha_min(values):
    return np.maximum(values["roughness"] ** 2, ref.ALPHA_MIN)


@pytest.fixture(scope="module")
def case():
    return _case()


def test_the_anisotropic_gltf_matches_the_transcription(case):
    values, n, t, l, v = case
    actual = models.evaluate("gltf", l, v, n, _material(values), t=t)
    expected = ref.gltf_anisotropy_brdf(l, v, n, t, 1.0, values["base"], values["metallic"], values["roughness"],
                                        values["strength"], values["rotation"])
    assert_matches(actual, expected, _alpha_min(values), "gltf + KHR_materials_anisotropy", rtol=RTOL)
    # the lobe is anisotropic: turning the direction changes the value
    turned = ref.gltf_anisotropy_brdf(l, v, n, t, 1.0, values["base"], values["metallic"], values["roughness"],
                                      values["strength"], values["rotation"] + 1.0)
    lit = (np.sum(l * n, axis=1) > 0.0) & (np.sum(v * n, axis=1) > 0.0) & (values["strength"] > 0.3)
    assert np.mean(np.any(np.abs(turned - expected) > 1e-3 * np.abs(expected), axis=1)[lit]) > 0.8


def test_strength_zero_is_the_core_model_bitwise(case):
    values, n, t, l, v = case
    zero = _material(values, strength=np.zeros(N))
    core = Material(base_color=values["base"], metallic=values["metallic"], roughness=values["roughness"])
    np.testing.assert_array_equal(models.evaluate("gltf", l, v, n, zero, t=t),
                                  models.evaluate("gltf", l, v, n, core, t=t))


def test_sampled_weights_and_pdf_match_the_transcription(case):
    values, _, _, _, _ = case
    rng = _rng("sample")
    count = 200
    sub = {k: x[:count] for k, x in values.items()}
    wo = _unit(rng.normal(size=(count, 3)))
    wo[:, 2] = np.abs(wo[:, 2]) + 0.05
    wo = _unit(wo)
    material = _material(sub)
    wi, pdf, weight = models.sample("gltf", material, wo, rng.uniform(0.0, 1.0, (count, 3)))
    ok = pdf > 0.0
    assert ok.sum() >= count // 2
    np.testing.assert_allclose(models.pdf("gltf", material, wo, wi)[ok], pdf[ok], rtol=1e-12, atol=0.0)
    expected = ref.gltf_anisotropy_brdf(wi, wo, np.broadcast_to(Z, wo.shape), np.broadcast_to([1.0, 0.0, 0.0],
                                        wo.shape), 1.0, sub["base"], sub["metallic"], sub["roughness"],
                                        sub["strength"], sub["rotation"])
    expected = expected * (wi[:, 2] / np.where(ok, pdf, 1.0))[:, None]
    assert_matches(weight[ok], expected[ok], _alpha_min(sub)[ok], "sampled weight, anisotropic gltf", rtol=RTOL)


@pytest.mark.parametrize("metallic, rotation", [(1.0, 0.7), (0.3, -2.0)])
def test_chi_square_of_the_turned_anisotropic_sampler(metallic, rotation):
    """The composed sampler (diffuse and anisotropic GGX visible normals in the turned
    frame) against its own pdf, with the failures as a cell."""
    material = Material(base_color=(0.6, 0.5, 0.4), metallic=metallic, roughness=0.25, anisotropy_strength=0.8,
                        anisotropy_rotation=rotation)
    wo = view_direction(0.6, 0.9)
    n = 200_000
    wi, pdf, _ = models.sample("gltf", material, np.broadcast_to(wo, (n, 3)), _rng(f"chi-{metallic}").uniform(
        0.0, 1.0, (n, 3)))
    ok = pdf > 0.0

    def density(x, y, z):
        d = np.stack(np.broadcast_arrays(x, y, z), axis=-1)
        return models.pdf("gltf", material, np.broadcast_to(wo, d.shape), d)

    p_value, integral, _ = chi2.hemisphere_chi2_with_failures(wi[ok], n, density)
    assert integral <= 1.0 + 1e-3
    assert p_value > 1e-4, p_value


@pytest.mark.parametrize("mu", [0.3, 0.8])
def test_white_furnace_of_the_anisotropic_metal(mu):
    """A white metal with strength 1 at roughness 0.2: the albedo by its own sampler
    equals the independent quadrature of its value within 5 standard errors, and is
    at most 1 (a single-scattering microfacet lobe loses energy, never gains it)."""
    material = Material(base_color=np.ones(3), metallic=1.0, roughness=0.2, anisotropy_strength=1.0,
                        anisotropy_rotation=0.5)
    wo = view_direction(mu, 1.1)
    n = 100_000
    _, _, weight = models.sample("gltf", material, np.broadcast_to(wo, (n, 3)), _rng(f"furnace-{mu}").uniform(
        0.0, 1.0, (n, 3)))
    estimate = weight.mean(axis=0)
    stderr = weight.std(axis=0, ddof=1) / np.sqrt(n)
    # the quadrature's nodes follow the lobe: alpha_t = mix(0.04, 1, 1) = 1 along the turned
    # tangent, alpha_b = 0.04 across it; the rule is built in the frame of the tangent, so the
    # view is turned into it (the value is rotation-invariant about n as a whole)
    c, s = np.cos(0.5), np.sin(0.5)
    wo_turned = np.array([c * wo[0] + s * wo[1], c * wo[1] - s * wo[0], wo[2]])
    l, w = albedo_nodes(wo_turned, 1.0, 0.04)
    l_local = np.stack([c * l[:, 0] - s * l[:, 1], s * l[:, 0] + c * l[:, 1], l[:, 2]], axis=-1)
    f = models.evaluate("gltf", l_local, np.broadcast_to(wo, l.shape), Z, material, t=np.array([1.0, 0.0, 0.0]))
    reference = np.sum(f * w[:, None], axis=0)
    assert np.all(np.abs(estimate - reference) < 5.0 * stderr + 1e-3), (estimate, reference, stderr)
    assert np.all(reference <= 1.0 + 1e-6), reference


def test_the_frame_follows_the_tangent_handedness_and_rotation():
    """glTF's B = w (n x T): the rotation turns T towards B, so a left-handed tangent
    (w = -1) turns the other way; the bitangent is always n x t."""
    from pbrkit.brdf.bxdf import BxDF

    z3 = (0.0,) * 3
    b = BxDF(6, 0, 1, 0, 0, 0.5, 0.25, 0.5, 0.25, True, 0.3, 0.0, z3, z3, z3, 1.0, z3, z3, 0.04, z3, (0.0,) * 12)
    n = (0.0, 0.0, 1.0)
    for w, sign in ((1.0, 1.0), (-1.0, -1.0)):
        t, bt = shading_frame.py_func(*n, b, (2.0, 0.0, 0.5, w))  # projected and normalised
        np.testing.assert_allclose(t, (np.cos(0.3), sign * np.sin(0.3), 0.0), atol=1e-15)
        np.testing.assert_allclose(bt, np.cross(n, t), atol=1e-15)
    # no tangent: the parallels about +Y (a parametric sphere's dp/dphi), turned
    t, _ = shading_frame.py_func(1.0, 0.0, 0.0, b, (0.0, 0.0, 0.0, 1.0))
    np.testing.assert_allclose(t, (0.0, -np.sin(0.3), np.cos(0.3)), atol=1e-15)


# ------------------------------------------------------------------ glTF files


def test_the_factors_and_tangents_are_read_from_gltf_files(tmp_path):
    from gltf_scenes import write_quad_glb

    from pbrkit.rendering.gltf import load_gltf

    ext = {"KHR_materials_anisotropy": {"anisotropyStrength": 0.7, "anisotropyRotation": -1.25}}
    asset = load_gltf(write_quad_glb(tmp_path / "a.glb", material_extras=ext, extensions_required=tuple(ext)))
    spec = asset.materials[0].spec
    assert (spec.anisotropy_strength, spec.anisotropy_rotation) == (0.7, -1.25)
    # without TANGENT the anisotropic quad gets MikkTSpace tangents along TEXCOORD_0
    tangents = asset.meshes[0].tangents
    assert tangents is not None and np.allclose(np.linalg.norm(tangents[:, :3], axis=1), 1.0)
    assert np.allclose(np.abs(tangents[:, 3]), 1.0)
    # any angle is the same direction as its remainder in [-pi, pi]
    ext = {"KHR_materials_anisotropy": {"anisotropyStrength": 0.7, "anisotropyRotation": 7.0}}
    asset = load_gltf(write_quad_glb(tmp_path / "w.glb", material_extras=ext))
    assert asset.materials[0].spec.anisotropy_rotation == pytest.approx(7.0 - 2.0 * np.pi, abs=1e-15)
    # the extension without its factors: the README's defaults (isotropic)
    asset = load_gltf(write_quad_glb(tmp_path / "d.glb", material_extras={"KHR_materials_anisotropy": {}}))
    spec = asset.materials[0].spec
    assert (spec.anisotropy_strength, spec.anisotropy_rotation) == (0.0, 0.0)
    assert asset.meshes[0].tangents is None


def test_an_anisotropy_texture_is_read(tmp_path):
    """(Applied per shading point: tests/rendering/test_gltf_extension_textures.py.)"""
    from gltf_scenes import write_quad_glb

    from pbrkit.rendering.gltf import load_gltf

    texture = np.full((2, 2, 3), 200, dtype=np.uint8)
    ext = {"KHR_materials_anisotropy": {"anisotropyStrength": 1.0, "anisotropyTexture": {"index": 0}}}
    asset = load_gltf(write_quad_glb(tmp_path / "t.glb", texture=texture, material_extras=ext))
    material = asset.materials[0]
    assert material.spec.anisotropy_strength == 1.0 and not asset.notes
    (use, ref), = material.extension_textures
    assert use[:2] == ("KHR_materials_anisotropy", "anisotropyTexture") and ref.texcoord == 0
    assert material.textures[ref.texture].texels.shape == (2, 2, 4)  # decoded linear (not sRGB)


@pytest.mark.parametrize("ext, fragment", [
    ({"KHR_materials_anisotropy": {"anisotropyStrength": 1.5}}, "KHR_materials_anisotropy.anisotropyStrength"),
    ({"KHR_materials_anisotropy": {"anisotropyStrength": -0.1}}, "KHR_materials_anisotropy.anisotropyStrength"),
    ({"KHR_materials_anisotropy": {"anisotropyRotation": "x"}}, "KHR_materials_anisotropy.anisotropyRotation"),
    ({"KHR_materials_anisotropy": {"anisotropyRotation": [1.0]}}, "KHR_materials_anisotropy.anisotropyRotation"),
    ({"KHR_materials_anisotropy": {"anisotropyTexture": {"index": 4}}},
     "KHR_materials_anisotropy.anisotropyTexture"),
    ({"KHR_materials_anisotropy": 1}, "KHR_materials_anisotropy"),
])
def test_bad_anisotropy_fields_are_refused_naming_the_field(tmp_path, ext, fragment):
    from gltf_scenes import write_quad_glb

    from pbrkit.core.errors import InputError
    from pbrkit.rendering.gltf import load_gltf

    with pytest.raises(InputError, match=fragment.replace(".", r"\.")) as info:
        load_gltf(write_quad_glb(tmp_path / "b.glb", material_extras=ext))
    assert "\n" not in str(info.value)


def test_the_glb_writer_writes_tangents_the_reader_reads(tmp_path):
    from pbrkit.io.gltf_writer import GltfPrimitive, write_glb
    from pbrkit.rendering.gltf import load_gltf

    p = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    n = np.tile([0.0, 0.0, 1.0], (3, 1))
    t = np.array([[0.6, 0.8, 0.0, -1.0]] * 3)
    ext = {"KHR_materials_anisotropy": {"anisotropyStrength": 0.5}}
    write_glb(tmp_path / "t.glb", [GltfPrimitive(p, n, np.array([[0, 1, 2]]), tangents=t, extensions=ext)])
    mesh = load_gltf(tmp_path / "t.glb").meshes[0]
    np.testing.assert_allclose(mesh.tangents, t, atol=1e-7)
    with pytest.raises(ValueError, match="tangents must have unit xyz"):
        write_glb(tmp_path / "u.glb", [GltfPrimitive(p, n, np.array([[0, 1, 2]]), tangents=2 * t)])


# ------------------------------------------------------------------ real time


@pytest.mark.parametrize("roughness, strength", [(0.3, 1.0), (0.05, 0.6), (0.6, 1.0)])
def test_filtered_importance_sampling_keeps_the_lobe_s_albedo(roughness, strength):
    """pbrkit's real time of an anisotropic lobe (pbrkit.rendering.anisotropic_ibl) under a
    white environment: its DFG2 (the mean of the samples' weights G2 / G1) is the
    directional albedo of the lobe with F = 1, by the independent quadrature of the
    README's transcription, within 0.03, at views along and across the turned tangent;
    the prefiltered radiance of a constant environment is that constant."""
    from pbrkit.rendering.anisotropic_ibl import anisotropic_ibl
    from pbrkit.rendering.geometry import Surface
    from pbrkit.rendering.materials import material_tables
    from pbrkit.rendering.scene import MaterialSpec
    from pbrkit.rendering.textures import SurfaceMaterial

    rotation = 0.4
    spec = MaterialSpec(name="m", model="gltf", base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=roughness,
                        anisotropy_strength=strength, anisotropy_rotation=rotation)
    mat_i, mat_f = material_tables([SurfaceMaterial(spec)])
    views = [view_direction(mu, phi) for mu in (0.35, 0.8) for phi in (rotation, rotation + 0.5 * np.pi)]
    count = len(views)
    n = np.tile(Z, (count, 1))
    surface = Surface(np.zeros((count, 3)), n, n, np.zeros(count, dtype=np.int64), np.ones((count, 3)),
                      np.ones(count), np.full(count, roughness), np.ones(count), np.zeros((count, 3)))
    tangents = np.tile([1.0, 0.0, 0.0, 1.0], (count, 1))
    seen = []

    def sampler(directions, lod):
        seen.append(directions.shape[0])
        return np.full((directions.shape[0], 3), 0.7)

    lobe, dfg1, dfg2 = anisotropic_ibl(mat_i, mat_f, np.arange(count), surface, np.array(views), tangents, sampler,
                                       lambda d: d, 6, 1.0)
    assert seen and np.allclose(lobe, 0.7)
    alpha = max(roughness ** 2, ref.ALPHA_MIN)
    alpha_t = alpha + (1.0 - alpha) * strength ** 2
    for k, wo in enumerate(views):
        # the quadrature's rule follows the lobe in the turned frame (tangent at angle `rotation`)
        c, s = np.cos(rotation), np.sin(rotation)
        wo_turned = np.array([c * wo[0] + s * wo[1], c * wo[1] - s * wo[0], wo[2]])
        l, w = albedo_nodes(wo_turned, alpha_t, alpha)
        l_local = np.stack([c * l[:, 0] - s * l[:, 1], s * l[:, 0] + c * l[:, 1], l[:, 2]], axis=-1)
        # F = 1: a white metal's F = 1 + 0 (1 - v.h)^5
        f = ref.gltf_anisotropy_brdf(l_local, np.broadcast_to(wo, l.shape), np.broadcast_to(Z, l.shape),
                                     np.broadcast_to([1.0, 0.0, 0.0], l.shape), 1.0, np.ones((len(l), 3)), 1.0,
                                     roughness, strength, rotation)
        albedo = float(np.sum(f[:, 0] * w))
        assert abs(dfg2[k] - albedo) < 0.03, (k, dfg2[k], albedo)
        assert 0.0 <= dfg1[k] < dfg2[k]
