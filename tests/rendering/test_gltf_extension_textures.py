"""The KHR_materials extension textures (issue 25: "every texture and factor of each
extension is read"), applied per shading point as the extensions' READMEs define them
(pbrkit.io.gltf_materials.TEXTURE_USES): each texture's channel times its factor (the
sRGB ones decoded), the thin film's thickness mixed between its minimum and maximum,
the anisotropy direction turned by the texture's and its strength scaled, against the
READMEs' formulas at a uniform texel; and rendered: a clear-coat texture half 0, half 1
gives, to float precision, the uncoated and the coated material's real-time pixels, and
the ground truth's of each within its noise."""

from __future__ import annotations

import math

import numpy as np
import pytest
from gltf_scenes import quad_scene, write_quad_glb

from pbrkit.brdf.shading.registry import COLUMNS
from pbrkit.io.gltf_materials import TEXTURE_USES
from pbrkit.rendering.geometry import Geometry
from pbrkit.rendering.materials import material_tables, per_hit_tables
from pbrkit.rendering.primary import _primary

TEXEL = (51, 102, 153, 204)  # RGBA, 8-bit


def _srgb_decode(c):
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


FACTORS = {"KHR_materials_sheen": {"sheenColorFactor": [0.9, 0.8, 0.7], "sheenRoughnessFactor": 0.6},
           "KHR_materials_clearcoat": {"clearcoatFactor": 0.9, "clearcoatRoughnessFactor": 0.7},
           "KHR_materials_specular": {"specularFactor": 0.8, "specularColorFactor": [1.5, 1.2, 0.9]},
           "KHR_materials_iridescence": {"iridescenceFactor": 0.9, "iridescenceThicknessMinimum": 150.0,
                                         "iridescenceThicknessMaximum": 550.0},
           "KHR_materials_transmission": {"transmissionFactor": 0.7},
           "KHR_materials_volume": {"thicknessFactor": 0.4},
           "KHR_materials_anisotropy": {"anisotropyStrength": 0.8, "anisotropyRotation": 0.5}}


def test_each_texture_changes_its_parameter_as_its_readme_says(tmp_path):
    ext = {name: dict(factors) for name, factors in FACTORS.items()}
    for name, key, *_ in TEXTURE_USES:
        ext[name][key] = {"index": 0}
    texture = np.broadcast_to(np.array(TEXEL, dtype=np.uint8), (2, 2, 4))
    path = write_quad_glb(tmp_path / "t.glb", texture=texture, material_extras=ext)
    geometry = Geometry(quad_scene(path, 8, 8, color=(1.0, 1.0, 1.0)))
    prim = _primary(quad_scene(path, 8, 8, color=(1.0, 1.0, 1.0)), geometry)
    surface = prim.surface
    assert surface.extension_values is not None
    codes, params = material_tables(geometry.materials)
    codes2, params2, material, origin = per_hit_tables(codes, params, surface)
    assert np.all(origin[material] == surface.material) and np.all(material >= codes.shape[0])
    row = params2[material[0]]
    linear = np.array(TEXEL) / 255.0
    srgb = _srgb_decode(linear[:3])
    r, g, b, a = linear

    def at(name, k=0):
        return row[getattr(COLUMNS, name) + k]

    expected = {
        ("sheen_color", 0): 0.9 * srgb[0], ("sheen_color", 1): 0.8 * srgb[1], ("sheen_color", 2): 0.7 * srgb[2],
        ("sheen_roughness", 0): 0.6 * a,
        ("clearcoat", 0): 0.9 * r, ("clearcoat_roughness", 0): 0.7 * g,
        ("specular", 0): 0.8 * a,
        ("specular_color", 0): 1.5 * srgb[0], ("specular_color", 1): 1.2 * srgb[1],
        ("specular_color", 2): 0.9 * srgb[2],
        ("iridescence", 0): 0.9 * r,
        ("iridescence_thickness_maximum", 0): 150.0 + (550.0 - 150.0) * g,  # mix(minimum, maximum, G)
        ("transmission", 0): 0.7 * r, ("thickness", 0): 0.4 * g,
        ("anisotropy_strength", 0): 0.8 * b,
        # the README: direction = rotate(anisotropyRotation) normalize(RG 2 - 1)
        ("anisotropy_rotation", 0): math.remainder(0.5 + math.atan2(2.0 * g - 1.0, 2.0 * r - 1.0), 2.0 * math.pi),
    }
    for (name, k), value in expected.items():
        assert at(name, k) == pytest.approx(value, rel=1e-6, abs=1e-7), (name, k)
    # the untextured parameters keep the scene material's values
    for name in ("base_color", "metallic", "roughness", "ior", "iridescence_ior"):
        assert at(name) == params[surface.material[0], getattr(COLUMNS, name)]


def _coat_quad(tmp_path, name, extras):
    texture = np.zeros((2, 2, 3), dtype=np.uint8)
    texture[:, 1] = 255  # u >= 0.5 (x > 0): R = 1
    return write_quad_glb(tmp_path / name, texture=texture, material_extras=extras,
                          sampler={"magFilter": 9728, "minFilter": 9728})


def test_a_clearcoat_texture_coats_its_half_of_the_quad(tmp_path):
    from pbrkit.rendering.realtime import render_realtime
    from pbrkit.rendering.reference import render_reference

    textured = _coat_quad(tmp_path, "t.glb", {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0,
                                                                          "clearcoatTexture": {"index": 0}}})
    coated = _coat_quad(tmp_path, "c.glb", {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0}})
    bare = _coat_quad(tmp_path, "b.glb", {})
    env = (0.3, 0.5, 0.9)
    rt = {k: render_realtime(quad_scene(p, 8, 8, color=env), bake_size=16).image for k, p in
          (("t", textured), ("c", coated), ("b", bare))}
    left, right = slice(1, 3), slice(5, 7)  # away from the texel edge at x = 0 and the quad's
    np.testing.assert_allclose(rt["t"][2:6, right], rt["c"][2:6, right], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(rt["t"][2:6, left], rt["b"][2:6, left], rtol=1e-9, atol=1e-12)
    assert np.abs(rt["c"][2:6, right] - rt["b"][2:6, right]).max() > 1e-3  # the coat shows
    gt = {k: render_reference(quad_scene(p, 8, 8, color=env), spp=64, seed=3)
          for k, p in (("t", textured), ("c", coated), ("b", bare))}
    for half, other in ((right, "c"), (left, "b")):
        d = gt["t"].image[2:6, half] - gt[other].image[2:6, half]
        s = np.hypot(gt["t"].stderr[2:6, half], gt[other].stderr[2:6, half])
        assert np.abs(d.mean()) < 4.0 * np.sqrt(np.mean(s * s) / s.size) + 1e-6, (other, d.mean())
