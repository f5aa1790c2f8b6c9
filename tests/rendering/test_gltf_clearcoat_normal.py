"""KHR_materials_clearcoat's own normal (its README, "Clearcoat": clearcoatNormalTexture,
and "no normal mapping is applied to the clear coat layer, even if normal mapping is
applied to the base material"; "Layering": fresnel_coat's ``normal`` "affects the top
layer, but not the base"): the coated material with a tilted coat normal against the
independent transcription of tests/support/reference_brdf.py (``gltf_khr_brdf`` with its
``clearcoat_normal``) at random inputs (1e-9 relative), the coat's own sampler about
its normal by chi-square against its pdf (and the composed sampler's), the white
furnace, the frame change of a hit's world-space coat normal, and glTF files: the
texture's normal in the tangent space of the unmapped normal, the unmapped normal
under a base normal map, the one-line refusal of a bad scale."""

from __future__ import annotations

import zlib

import chi2
import numpy as np
import pytest
import reference_brdf as ref
from gltf_khr_cases import KEYS, TABLE, khr_case, khr_material
from model_values import assert_matches
from quadrature import albedo_nodes, view_direction

from pbrkit import Material
from pbrkit.brdf import models

SEED = 20261128
N = 400
RTOL = 1e-9


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


def _rng(tag):
    return np.random.default_rng([SEED, zlib.crc32(tag.encode())])


def _tilted(rng, n, spread=0.6):
    """Unit coat normals about +z, up to ``spread`` radians away (a normal map's range)."""
    theta = spread * np.sqrt(rng.random(n))
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=1)


def _alpha_min(values):
    return np.minimum(np.maximum(values["roughness"] ** 2, ref.ALPHA_MIN),
                      np.maximum(values["clearcoat_roughness"] ** 2, ref.ALPHA_MIN))


@pytest.fixture(scope="module")
def case():
    values, l, v = khr_case(SEED)
    values["clearcoat"] = np.where(values["clearcoat"] > 0.0, values["clearcoat"], 0.8)
    return values, l, v, _tilted(_rng("coat"), N)


def test_the_coat_takes_its_own_normal_as_the_readme_says(case):
    """In the local frame (shading normal +z): f = mix(sheen_material, clearcoat_brdf,
    clearcoat F(|V.Nc|)), clearcoat_brdf's D and V about Nc."""
    values, l, v, nc = case
    z = np.broadcast_to([0.0, 0.0, 1.0], l.shape)
    actual = models.evaluate("gltf", l, v, z, khr_material(values), coat_normal=nc)
    expected = ref.gltf_khr_brdf(l, v, *(values[k] for k in KEYS), TABLE, clearcoat_normal=nc)
    assert_matches(actual, expected, _alpha_min(values), "gltf + a tilted clear coat normal", rtol=RTOL)
    # the tilt matters: about the shading normal the coated values differ
    plain = ref.gltf_khr_brdf(l, v, *(values[k] for k in KEYS), TABLE)
    lit = (l[:, 2] > 0.0) & (v[:, 2] > 0.0)
    assert np.mean(np.any(np.abs(plain - expected) > 1e-3 * np.abs(expected), axis=1)[lit]) > 0.5


def test_a_world_frame_coat_normal_is_turned_into_the_shading_frame(case):
    """The same material at random world frames: the world-space coat normal (a hit's
    row) turned into each frame gives the local transcription's values."""
    values, l, v, nc = case
    rng = _rng("frames")
    n = _unit(rng.normal(size=(N, 3)))
    t, b = _orthonormal(n, rng)
    frame = np.stack([t, b, n], axis=1)  # rows: the local axes in world space
    world = lambda x: np.einsum("nij,ni->nj", frame, x)  # noqa: E731
    actual = models.evaluate("gltf", world(l), world(v), n, khr_material(values), t=t, coat_normal=world(nc))
    expected = ref.gltf_khr_brdf(l, v, *(values[k] for k in KEYS), TABLE, clearcoat_normal=nc)
    assert_matches(actual, expected, _alpha_min(values), "gltf + a world-space coat normal", rtol=1e-7)


def _orthonormal(n, rng):
    t = _unit(np.cross(n, _unit(rng.normal(size=n.shape))))
    return t, np.cross(n, t)


def test_the_coat_normal_along_the_shading_normal_is_the_plain_coat(case):
    values, l, v, _ = case
    z = np.broadcast_to([0.0, 0.0, 1.0], l.shape)
    material = khr_material(values)
    np.testing.assert_allclose(models.evaluate("gltf", l, v, z, material, coat_normal=z),
                               models.evaluate("gltf", l, v, z, material), rtol=1e-12, atol=1e-300)


def test_a_coat_normal_that_is_not_unit_is_refused():
    with pytest.raises(ValueError, match="coat_normal must be unit"):
        models.evaluate("gltf", [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], Material(clearcoat=1.0),
                        coat_normal=[0.0, 0.0, 2.0])


@pytest.mark.parametrize("tilt, metallic", [((0.45, 0.2), 0.0), ((-0.3, -0.5), 1.0)])
def test_chi_square_of_the_sampler_with_a_tilted_coat(tilt, metallic):
    """The composed sampler (diffuse, specular and the coat's visible normals about Nc,
    the coat's samples below the shading horizon failing) against its own pdf."""
    nc = _unit(np.array([tilt[0], tilt[1], 1.0]))
    material = Material(base_color=(0.6, 0.5, 0.4), metallic=metallic, roughness=0.6, clearcoat=1.0,
                        clearcoat_roughness=0.15)
    wo = view_direction(0.5, 0.7)
    n = 200_000
    wi, pdf, _ = models.sample("gltf", material, np.broadcast_to(wo, (n, 3)),
                               _rng(f"chi-{tilt}").uniform(0.0, 1.0, (n, 3)), coat_normal=nc)
    ok = pdf > 0.0

    def density(x, y, z):
        d = np.stack(np.broadcast_arrays(x, y, z), axis=-1)
        return models.pdf("gltf", material, np.broadcast_to(wo, d.shape), d, coat_normal=nc)

    p_value, integral, success = chi2.hemisphere_chi2_with_failures(wi[ok], n, density)
    assert integral <= 1.0 + 1e-3
    assert abs(integral - success) < 5.0 * np.sqrt(success * (1.0 - success) / n) + 1e-3
    assert p_value > 1e-4, p_value
    np.testing.assert_allclose(pdf[ok][:2000], density(*wi[ok][:2000].T), rtol=1e-12)


@pytest.mark.parametrize("mu", [0.35, 0.85])
def test_white_furnace_with_a_tilted_coat(mu):
    """A white coated metal (base F = 1) with a tilted coat: the albedo by the model's own
    sampler equals the independent quadrature of the transcription within 5 standard
    errors, and stays at most 1.  f = (1 - t) f_base + t f_coat with t = clearcoat F(|V.Nc|)
    a function of the view alone, so each lobe is integrated with half-vector nodes about
    its own normal (the coat's rotated from Nc's frame, cut at the shading horizon)."""
    nc = _unit(np.array([0.35, -0.2, 1.0]))
    rough, coat_rough = 0.4, 0.3
    material = Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=rough, clearcoat=1.0,
                        clearcoat_roughness=coat_rough)
    wo = view_direction(mu, 0.4)
    n = 100_000
    _, _, weight = models.sample("gltf", material, np.broadcast_to(wo, (n, 3)),
                                 _rng(f"furnace-{mu}").uniform(0.0, 1.0, (n, 3)), coat_normal=nc)
    estimate = weight[:, 0].mean()
    stderr = weight[:, 0].std(ddof=1) / np.sqrt(n)

    def transcription(l, base, metallic, specular, clearcoat):
        return ref.gltf_khr_brdf(l, np.broadcast_to(wo, l.shape), base, metallic, rough, (0.0, 0.0, 0.0), 0.0,
                                 clearcoat, coat_rough, specular, (1.0, 1.0, 1.0), 1.5, TABLE,
                                 clearcoat_normal=np.broadcast_to(nc, l.shape))[:, 0]

    l, w = albedo_nodes(wo, rough * rough)  # weights with the cosine n.l
    e_base = np.sum(transcription(l, (1.0, 1.0, 1.0), 1.0, 1.0, 0.0) * w)
    tc, bc = _orthonormal(nc[None], _rng("basis"))
    frame = np.stack([tc[0], bc[0], nc])  # rows: the coat frame's axes in the local frame
    lc, wc = albedo_nodes(frame @ wo, coat_rough * coat_rough)
    l = lc @ frame
    t = 0.04 + 0.96 * (1.0 - abs(float(wo @ nc))) ** 5
    # a black, non-reflecting base under a full coat leaves t f_coat
    coat = transcription(l, (0.0, 0.0, 0.0), 0.0, 0.0, 1.0) / t
    solid = wc / np.maximum(lc[:, 2], 1e-300)  # the nodes' weights hold the coat frame's cosine
    e_coat = np.sum(np.where(l[:, 2] > 0.0, coat * l[:, 2], 0.0) * solid)
    total = (1.0 - t) * e_base + t * e_coat
    assert total <= 1.0
    assert abs(estimate - total) < 5.0 * stderr + 1e-3, (estimate, total, stderr)


# ------------------------------------------------------------------ glTF files

TEXEL = (170, 90, 220)  # a tangent-space normal tilted towards +T, -B (8-bit RGB, linear)


def _hits(path):
    """(surface, per-hit parameter rows) of a 6 x 6 view of the quad of ``path``."""
    from gltf_scenes import quad_scene

    from pbrkit.rendering.geometry import Geometry
    from pbrkit.rendering.materials import material_tables, per_hit_tables
    from pbrkit.rendering.primary import _primary

    scene = quad_scene(path, 6, 6, color=(1.0, 1.0, 1.0))
    geometry = Geometry(scene)
    surface = _primary(scene, geometry).surface
    codes, params = material_tables(geometry.materials)
    _, rows, material, _ = per_hit_tables(codes, params, surface)
    return surface, rows[material]


def _transcribed(surface, scale):
    """The glTF specification's normalTextureInfo, written out: n = normalize(TBN ((2 texel -
    1) (scale, scale, 1))), T the hit's tangent made orthogonal to the vertex normal N (+z
    here: the quad faces the camera), B = w (N x T)."""
    n = np.array([0.0, 0.0, 1.0])
    c = (2.0 * np.array(TEXEL) / 255.0 - 1.0) * np.array([scale, scale, 1.0])
    t = surface.tangent[:, :3] - np.outer(surface.tangent[:, :3] @ n, n)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    b = np.cross(n, t) * surface.tangent[:, 3:4]
    out = c[0] * t + c[1] * b + c[2] * n
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def _texture():
    return np.broadcast_to(np.array(TEXEL, dtype=np.uint8), (2, 2, 3)).copy()


def test_the_coat_normal_texture_is_read_in_the_tangent_space(tmp_path):
    from gltf_scenes import write_quad_glb

    from pbrkit.brdf.shading.registry import COLUMNS

    ext = {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatNormalTexture": {"index": 0, "scale": 0.5}}}
    surface, rows = _hits(write_quad_glb(tmp_path / "c.glb", normal_texture=_texture(), material_extras=ext))
    coat = rows[:, COLUMNS.coat_normal:COLUMNS.coat_normal + 3]
    np.testing.assert_allclose(coat, _transcribed(surface, 0.5), atol=1e-12)
    np.testing.assert_allclose(surface.n, _transcribed(surface, 1.0), atol=1e-12)  # the base's own map
    assert np.all(np.abs(coat - [0.0, 0.0, 1.0]).max(axis=1) > 0.1)


def test_under_a_base_normal_map_the_coat_keeps_the_unmapped_normal(tmp_path):
    from gltf_scenes import write_quad_glb

    from pbrkit.brdf.shading.registry import COLUMNS

    ext = {"KHR_materials_clearcoat": {"clearcoatFactor": 0.7}}
    surface, rows = _hits(write_quad_glb(tmp_path / "b.glb", normal_texture=_texture(), material_extras=ext))
    np.testing.assert_allclose(rows[:, COLUMNS.coat_normal:COLUMNS.coat_normal + 3],
                               np.broadcast_to([0.0, 0.0, 1.0], surface.n.shape), atol=1e-12)
    assert np.all(surface.n[:, 2] < 0.99)  # while the base is normal-mapped
    # without a coat (clearcoat 0) the rows carry no coat normal
    surface, rows = _hits(write_quad_glb(tmp_path / "n.glb", normal_texture=_texture()))
    assert not np.any(rows[:, COLUMNS.coat_normal:COLUMNS.coat_normal + 3])


def test_a_coat_normal_texture_alone_gets_mikktspace_tangents(tmp_path):
    from gltf_scenes import write_quad_glb

    from pbrkit.rendering.gltf import load_gltf

    ext = {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatNormalTexture": {"index": 0}}}
    asset = load_gltf(write_quad_glb(tmp_path / "m.glb", texture=_texture(), material_extras=ext))
    assert asset.meshes[0].tangents is not None and not asset.notes
    (use, ref_), = asset.materials[0].extension_textures
    assert use[1] == "clearcoatNormalTexture" and ref_.scale == 1.0


@pytest.mark.parametrize("info, fragment", [
    ({"index": 0, "scale": "x"}, "clearcoatNormalTexture.scale"),
    ({"index": 0, "scale": [1.0]}, "clearcoatNormalTexture.scale"),
    ({"index": 3}, "clearcoatNormalTexture"),
])
def test_bad_coat_normal_textures_are_refused_naming_the_field(tmp_path, info, fragment):
    from gltf_scenes import write_quad_glb

    from pbrkit.core.errors import InputError
    from pbrkit.rendering.gltf import load_gltf

    ext = {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatNormalTexture": info}}
    with pytest.raises(InputError, match=fragment.replace(".", r"\.")) as exc:
        load_gltf(write_quad_glb(tmp_path / "b.glb", texture=_texture(), material_extras=ext))
    assert "\n" not in str(exc.value)


def test_real_time_area_lights_take_the_coat_normal(tmp_path):
    """The coat's LTC term about its own normal: a coat normal texture that encodes (almost)
    the unmapped normal renders (almost) as no texture under a rect light and the
    environment; a tilted one moves the coat's highlight (the image changes)."""
    from dataclasses import replace

    from gltf_scenes import quad_scene, write_quad_glb

    from pbrkit.rendering.area_lights import AreaLight
    from pbrkit.rendering.realtime import render_realtime

    light = AreaLight(type="rect", position=(0.0, 1.5, 3.0), normal=(0.0, -0.45, -0.9), width=1.0, height=0.5,
                      intensity=6.0)

    def render(name, info, texel):
        ext = {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.6}}
        if info is not None:
            ext["KHR_materials_clearcoat"]["clearcoatNormalTexture"] = info
        texture = np.broadcast_to(np.array(texel, dtype=np.uint8), (2, 2, 3)).copy()
        path = write_quad_glb(tmp_path / f"{name}.glb", texture=texture, material_extras=ext)
        scene = replace(quad_scene(path, 12, 12, color=(0.2, 0.2, 0.2)), area_lights=(light,))
        return render_realtime(scene, bake_size=16).image

    plain = render("plain", None, (128, 128, 255))
    flat = render("flat", {"index": 0}, (128, 128, 255))  # (0.004, 0.004, 1): the normal, to 0.3 degrees
    tilted = render("tilted", {"index": 0}, TEXEL)
    assert np.abs(plain).max() > 0.0
    np.testing.assert_allclose(flat, plain, rtol=0.01, atol=1e-3 * plain.max())
    assert np.abs(tilted - plain).max() > 0.05 * plain.max()
