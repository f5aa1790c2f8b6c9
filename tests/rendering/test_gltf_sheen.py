"""KHR_materials_sheen in the ``gltf`` model: its value against the independent
transcription of tests/support/reference_brdf.py (``gltf_sheen_brdf``: the Charlie D,
the specification's Lambda and V, and the albedo scaling 1 - max3(sheenColor)
E(VdotN) written from the extension's README) at many random inputs (1e-9
relative), the sampled weights against it, the transcription's own quadrature
of E against the baked table the model reads, and a black sheen colour giving
bitwise the core glTF composition's value, sampling probabilities and pdf."""

from __future__ import annotations

import math
import zlib

import numba
import numpy as np
import pytest
import reference_brdf as ref
from model_values import N_DIR, assert_matches

from pbrkit import Material
from pbrkit.brdf import models
from pbrkit.brdf.bxdf import EXTRA_SLOTS, BxDF, local_cosines
from pbrkit.brdf.lobes.sheen import SHEEN_TABLE_FILE
from pbrkit.brdf.operators import compose
from pbrkit.brdf.shading import gltf as gltf_model

SEED = 20261128
N = 400
#: The tolerance of the value checks (relative, plus the GGX condition term of
#: tests/brdf/test_model_values.py for sharp specular lobes).
RTOL = 1e-9
#: The table the model reads, as data (np.load; no pbrkit function computes it here).
TABLE = np.load(SHEEN_TABLE_FILE)


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def _case(seed, n=N):
    rng = np.random.default_rng(seed)
    base = rng.uniform(0.0, 1.0, (n, 3))
    base[rng.random(n) < 0.05] = 1.0
    metallic = rng.uniform(0.0, 1.0, n)
    metallic[rng.random(n) < 0.15] = 0.0
    metallic[rng.random(n) < 0.15] = 1.0
    roughness = rng.uniform(0.05, 1.0, n)
    roughness[rng.random(n) < 0.05] = 1.0
    sheen_color = rng.uniform(0.0, 1.0, (n, 3))
    sheen_color[rng.random(n) < 0.1] = 1.0
    sheen_color[rng.random(n) < 0.1] = 0.0
    sheen_roughness = rng.uniform(0.0, 1.0, n)
    sheen_roughness[rng.random(n) < 0.05] = 1.0
    sheen_roughness[rng.random(n) < 0.05] = 0.0
    v = _unit(rng.normal(size=(n, 3)))
    v[:, 2] = np.abs(v[:, 2])
    v[rng.random(n) < 0.1] = N_DIR
    grazing = rng.random(n) < 0.1
    v[grazing, 2] = 0.02
    v = _unit(v)
    v[rng.random(n) < 0.05, 2] *= -1.0
    l = _unit(rng.normal(size=(n, 3)))
    l[:, 2] = np.abs(l[:, 2])
    retro = rng.random(n) < 0.05
    l[retro] = v[retro]
    l[rng.random(n) < 0.05, 2] *= -1.0
    values = dict(base=base, metallic=metallic, roughness=roughness, sheen_color=sheen_color,
                  sheen_roughness=sheen_roughness)
    return values, l, v


def _material(values):
    return Material(base_color=values["base"], metallic=values["metallic"], roughness=values["roughness"],
                    sheen_color=values["sheen_color"], sheen_roughness=values["sheen_roughness"])


def _reference(values, l, v, table=TABLE):
    return ref.gltf_sheen_brdf(l, v, values["base"], values["metallic"], values["roughness"],
                               values["sheen_color"], values["sheen_roughness"], table)


def _alpha_min(values):
    return np.maximum(values["roughness"] ** 2, ref.ALPHA_MIN)


@pytest.fixture(scope="module")
def case():
    return _case(SEED)


def test_gltf_with_sheen_matches_the_transcription(case):
    values, l, v = case
    actual = models.gltf(l, v, N_DIR, _material(values))
    expected = _reference(values, l, v)
    assert_matches(actual, expected, _alpha_min(values), "gltf + KHR_materials_sheen", rtol=RTOL)
    # the sheen is there: the layering changes the core model's value
    core = ref.gltf_brdf(l, v, values["base"], values["metallic"], values["roughness"])
    lit = (values["sheen_color"].max(axis=1) > 0.0) & (l[:, 2] > 0.0) & (v[:, 2] > 0.0)
    assert np.mean(np.any(np.abs(expected - core) > 1e-6 * np.abs(core), axis=1)[lit]) > 0.9


def test_a_black_sheen_is_the_core_model(case):
    """sheen_color 0 (any sheen roughness): the transcription of the core glTF model."""
    values, l, v = case
    values = dict(values, sheen_color=np.zeros_like(values["sheen_color"]))
    actual = models.gltf(l, v, N_DIR, _material(values))
    core = ref.gltf_brdf(l, v, values["base"], values["metallic"], values["roughness"])
    assert_matches(actual, core, _alpha_min(values), "gltf, black sheen")


def _bxdf(base, metallic, roughness, sheen_color, sheen_roughness):
    z3 = (0.0, 0.0, 0.0)
    alpha = max(roughness * roughness, 1e-3)
    d = gltf_model.GLTF_DIELECTRIC_F0  # ((1.5 - 1) / (1.5 + 1))^2, not the literal 0.04
    f0 = tuple(d + (c - d) * metallic for c in base)
    # the extended model's slots: sheen (0-3), no clear coat (4-5), specular factor 1 (6)
    extra = tuple(sheen_color) + (sheen_roughness, 0.0, 1e-3, 1.0) + (0.0,) * (EXTRA_SLOTS - 7)
    return BxDF(5, 0, 1, 0, 0, roughness, alpha, alpha, alpha, False, 0.0, metallic, tuple(base),
                tuple(c * (1.0 - metallic) for c in base), f0, 1.0, z3, z3, d, z3, extra)


def _loop(composition):
    value, probabilities, pdf = composition.value, composition.probabilities, composition.pdf

    @numba.njit
    def run(b, wo, wi, out):
        p_spec, p_coat = probabilities(b, wo[2])
        for i in range(wi.shape[0]):
            c = local_cosines(wo[0], wo[1], wo[2], wi[i, 0], wi[i, 1], wi[i, 2])
            f = value(b, c, (1.0, 1.0, 1.0))
            out[i, 0], out[i, 1], out[i, 2] = f
            out[i, 3] = pdf(b, c, p_spec, p_coat)
            out[i, 4] = p_spec
        return out

    return run


def test_a_black_sheen_is_bitwise_the_core_composition():
    """The model's composition with sheen_color 0 gives exactly (bitwise) the value,
    sampling probability and pdf of the core glTF composition (no layer): the sheen
    lobe's value and albedo are 0 and the scaling 1.0 exactly."""
    with_sheen = _loop(gltf_model.MODEL.compiled)
    core = _loop(compose(gltf_model.COMPOSITION))
    rng = np.random.default_rng(SEED + 1)
    for _ in range(6):
        b = _bxdf(rng.uniform(0.0, 1.0, 3), float(rng.choice([0.0, 1.0, rng.uniform()])), float(rng.uniform()),
                  (0.0, 0.0, 0.0), float(rng.uniform()))
        wo = _unit(rng.normal(size=3))
        wo[2] = abs(wo[2])
        wi = _unit(rng.normal(size=(500, 3)))
        wi[:, 2] = np.abs(wi[:, 2])
        a = with_sheen(b, wo, wi, np.empty((500, 5)))
        e = core(b, wo, wi, np.empty((500, 5)))
        assert np.array_equal(a, e)
        assert np.array_equal(np.signbit(a), np.signbit(e))


def test_a_material_without_sheen_compiles_as_the_core_model():
    """The code row of a gltf material names the core model (the composition without
    the sheen, today's code) unless a sheen parameter is not at its default, and the
    extended form otherwise; the dispatch runs each one's own composition."""
    from pbrkit.brdf.dispatch import SAMPLING_BY_MODEL
    from pbrkit.brdf.shading.registry import COMPILED, EXTENDED_CODES, MODELS
    from pbrkit.rendering.materials import material_tables
    from pbrkit.rendering.scene import MaterialSpec
    from pbrkit.rendering.textures import SurfaceMaterial

    core, extended = MODELS.index("gltf"), EXTENDED_CODES["gltf"]
    assert COMPILED[core] is gltf_model.CORE and COMPILED[extended] is gltf_model.MODEL
    assert core != extended and len(SAMPLING_BY_MODEL) == len(COMPILED)
    specs = [MaterialSpec(name="a", base_color=(0.5, 0.4, 0.3)),
             MaterialSpec(name="b", sheen_roughness=0.7),
             MaterialSpec(name="c", sheen_color=(0.0, 0.1, 0.0)),
             MaterialSpec(name="d", model="disney")]
    codes, _ = material_tables([SurfaceMaterial(spec=s) for s in specs])
    assert list(codes[:, 0]) == [core, extended, extended, MODELS.index("disney")]
    assert models.model_codes("gltf")[0, 0] == core
    assert models.model_codes("gltf", material=Material(sheen_color=(1.0, 1.0, 1.0)))[0, 0] == extended


def test_sampled_weights_match_the_transcription(case):
    """models.sample with sheen: pdf = models.pdf, weight = f cos / pdf of models.evaluate,
    and the weight against the transcription's f cos / pdf."""
    values, _, v_all = case
    keep = np.flatnonzero(v_all[:, 2] > 0.0)[:80]
    sub = {k: x[keep] for k, x in values.items()}
    material = _material(sub)
    wo = v_all[keep]
    u = np.random.default_rng([SEED, zlib.crc32(b"sheen-sample")]).uniform(0.0, 1.0, (keep.size, 3))
    wi, pdf, weight = models.sample("gltf", material, wo, u)
    ok = pdf > 0.0
    assert ok.sum() >= keep.size // 2
    np.testing.assert_allclose(models.pdf("gltf", material, wo, wi)[ok], pdf[ok], rtol=1e-12, atol=0.0)
    cos_over_pdf = wi[:, 2] / np.where(ok, pdf, 1.0)
    expected = _reference(sub, wi, wo) * cos_over_pdf[:, None]
    assert_matches(weight[ok], expected[ok], _alpha_min(sub)[ok], "sampled weight, gltf + sheen", rtol=RTOL)


#: (sheenRoughness row, n.v column) of the table checked against the transcription's
#: own quadrature (a spread of the 33 x 33 grid; column 0 is n.v = 1e-4)
GRID = [(1, 0), (1, 3), (2, 8), (4, 1), (5, 16), (8, 0), (8, 32), (12, 5), (16, 16), (20, 2), (24, 28), (32, 0),
        (32, 12), (32, 32)]


def test_the_table_is_the_transcriptions_albedo():
    """E_sheen of the baked table against tests/support/reference_brdf.py's own quadrature
    (ref.charlie_albedo): 2e-4 relative, 1e-3 at n.v = 1e-4 (column 0, where E is steep)."""
    n_r, n_mu = TABLE.shape
    for i, j in GRID:
        e = ref.charlie_albedo(j / (n_mu - 1), i / (n_r - 1))
        assert TABLE[i, j] == pytest.approx(e, rel=1e-3 if j == 0 else 2e-4), (i, j)


def test_the_transcription_with_its_own_table_agrees(case):
    """The model against the transcription with E from the transcription's own
    quadrature on the rows and columns the elements read (a sub-sample): within the
    table's accuracy (2e-4 of E; column 0 excepted, the views are not that grazing)."""
    values, l, v = case
    pick = np.flatnonzero((v[:, 2] > 0.05) & (l[:, 2] > 0.0))[:12]
    sub = {k: x[pick] for k, x in values.items()}
    n_r, n_mu = TABLE.shape
    own = np.full(TABLE.shape, np.nan)
    for r, mu in zip(sub["sheen_roughness"], v[pick, 2]):
        i = min(int(r * (n_r - 1)), n_r - 2)
        j = min(int(mu * (n_mu - 1)), n_mu - 2)
        for a, b in ((i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)):
            if np.isnan(own[a, b]):
                own[a, b] = ref.charlie_albedo(b / (n_mu - 1), a / (n_r - 1), n_u=256, n_phi=64)
    actual = models.gltf(l[pick], v[pick], N_DIR, _material(sub))
    expected = _reference(sub, l[pick], v[pick], table=own)
    core = ref.gltf_brdf(l[pick], v[pick], sub["base"], sub["metallic"], sub["roughness"])
    # the difference is max3(sheenColor) (E_table - E_own) times the core model's value
    assert np.all(np.abs(actual - expected) <= 5e-4 * np.abs(core) + 1e-12)


# ------------------------------------------------------------------ glTF files and scene files


def test_khr_materials_sheen_is_read_from_gltf_files(tmp_path):
    from gltf_scenes import write_quad_glb

    from pbrkit.rendering.gltf import load_gltf

    sheen = {"sheenColorFactor": [0.9, 0.5, 0.25], "sheenRoughnessFactor": 0.4}
    path = write_quad_glb(tmp_path / "s.glb", material_extras={"KHR_materials_sheen": sheen},
                          extensions_required=("KHR_materials_sheen",))
    asset = load_gltf(path)
    spec = asset.materials[0].spec
    assert spec.model == "gltf" and spec.sheen_color == (0.9, 0.5, 0.25) and spec.sheen_roughness == 0.4
    assert not any("sheen" in note for note in asset.notes)
    # absent factors take the extension's defaults (black, 0); without the extension: no sheen
    asset = load_gltf(write_quad_glb(tmp_path / "d.glb", material_extras={"KHR_materials_sheen": {}}))
    assert asset.materials[0].spec.sheen_color == (0.0, 0.0, 0.0) and asset.materials[0].spec.sheen_roughness == 0.0
    assert load_gltf(write_quad_glb(tmp_path / "n.glb")).materials[0].spec.sheen_color == (0.0, 0.0, 0.0)


def test_a_sheen_texture_is_read(tmp_path):
    """(Applied per shading point, sRGB-decoded: tests/rendering/test_gltf_extension_textures.py.)"""
    from gltf_scenes import write_quad_glb

    from pbrkit.rendering.gltf import load_gltf

    texture = np.full((2, 2, 3), 200, dtype=np.uint8)
    sheen = {"sheenColorFactor": [1.0, 1.0, 1.0], "sheenColorTexture": {"index": 0}}
    asset = load_gltf(write_quad_glb(tmp_path / "t.glb", texture=texture,
                                     material_extras={"KHR_materials_sheen": sheen}))
    material = asset.materials[0]
    assert material.spec.sheen_color == (1.0, 1.0, 1.0) and not asset.notes
    (use, ref), = material.extension_textures
    assert use[:3] == ("KHR_materials_sheen", "sheenColorTexture", True)  # sRGB


@pytest.mark.parametrize("sheen, fragment", [
    ({"sheenColorFactor": [1.0, 2.0, 0.0]}, "KHR_materials_sheen.sheenColorFactor"),
    ({"sheenColorFactor": [1.0, 1.0]}, "KHR_materials_sheen.sheenColorFactor"),
    ({"sheenRoughnessFactor": -0.1}, "KHR_materials_sheen.sheenRoughnessFactor"),
    ({"sheenRoughnessFactor": "rough"}, "KHR_materials_sheen.sheenRoughnessFactor"),
    ({"sheenColorTexture": {"index": 7}}, "KHR_materials_sheen.sheenColorTexture"),
    ([1, 2], "KHR_materials_sheen"),
])
def test_bad_sheen_values_are_refused_naming_the_field(tmp_path, sheen, fragment):
    from gltf_scenes import write_quad_glb

    from pbrkit.core.errors import InputError
    from pbrkit.rendering.gltf import load_gltf

    path = write_quad_glb(tmp_path / "b.glb", material_extras={"KHR_materials_sheen": sheen})
    with pytest.raises(InputError, match=fragment) as info:
        load_gltf(path)
    assert "\n" not in str(info.value)


def test_a_scene_with_sheen_loads(tmp_path):
    from pbrkit.rendering.scene import load_scene

    path = tmp_path / "s.toml"
    path.write_text('[materials.velvet]\nmodel = "gltf"\nbase_color = [0.2, 0.05, 0.1]\nsheen_color = [1, 1, 1]\n'
                    'sheen_roughness = 0.5\n[[objects]]\ntype = "sphere"\nmaterial = "velvet"\n')
    velvet = load_scene(path).materials["velvet"]
    assert velvet.sheen_color == (1.0, 1.0, 1.0) and velvet.sheen_roughness == 0.5
    path.write_text('[materials.velvet]\nmodel = "gltf"\nsheen_color = [1, 1, 2]\n[[objects]]\ntype = "sphere"\n'
                    'material = "velvet"\n')
    with pytest.raises(ValueError, match="sheen_color"):
        load_scene(path)


# ------------------------------------------------------------------ real time


def test_realtime_ibl_has_the_sheen_over_the_scaled_base():
    """Real time under a constant white environment (the prefiltered chain constant, 1):
    with a white sheen, each pixel is base (1 - E) + E, E = E_sheen(n.v, sheenRoughness)
    (KHR_materials_sheen's albedo scaling of the base's split sum plus the Sample
    Viewer's sheenColor E times the prefiltered radiance); a black sheen is the
    core model's render bitwise."""
    from render_scenes import pixel_geometry, sphere_scene

    from pbrkit.brdf.lobes.sheen import sheen_albedo_lookup
    from pbrkit.rendering.realtime import render_realtime
    from pbrkit.rendering.scene import EnvironmentSpec, MaterialSpec

    env = EnvironmentSpec(color=(1.0, 1.0, 1.0))
    core = MaterialSpec(name="m", metallic=1.0, roughness=0.5, base_color=(0.3, 0.2, 0.1))
    plain = render_realtime(sphere_scene(core, env, size=16), bake_size=16)
    black = MaterialSpec(name="m", metallic=1.0, roughness=0.5, base_color=(0.3, 0.2, 0.1), sheen_roughness=0.5)
    assert np.array_equal(render_realtime(sphere_scene(black, env, size=16), bake_size=16).image, plain.image)
    velvet = MaterialSpec(name="m", metallic=1.0, roughness=0.5, base_color=(0.3, 0.2, 0.1),
                          sheen_color=(1.0, 1.0, 1.0), sheen_roughness=0.5)
    scene = sphere_scene(velvet, env, size=16)
    sheen = render_realtime(scene, bake_size=16)
    mask, n, v = pixel_geometry(scene)
    nov = np.sum(n * v, axis=-1)
    sel = mask & plain.mask & sheen.mask & (nov > 0.2)
    assert sel.sum() > 50
    e = np.vectorize(sheen_albedo_lookup)(nov[sel], 0.5)[:, None]
    np.testing.assert_allclose(sheen.image[sel], plain.image[sel] * (1.0 - e) + e, rtol=2e-3, atol=1e-4)
