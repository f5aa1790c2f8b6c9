"""Toon and MToon shading (pbrkit.npr.toon, pbrkit.npr.render), checked against the
analytic n.l of a sphere computed here, the MToon 1.0 specification's formulas, and
the style's one-line errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from typer.testing import CliRunner

from pbrkit.cli import app
from pbrkit.npr.render import render_styled
from pbrkit.npr.style import Style, style_from_dict
from pbrkit.npr.toon import default_thresholds, linearstep, toon_tone
from pbrkit.rendering.lights import Light
from pbrkit.rendering.scene import (
    Camera,
    EnvironmentSpec,
    MaterialSpec,
    Scene,
    Sphere,
    scene_from_dict,
)

BASE = np.array([0.8, 0.3, 0.2])
E = 2.0
TO_LIGHT = np.array([0.6, 0.3, 0.74])
TO_LIGHT = TO_LIGHT / np.linalg.norm(TO_LIGHT)


def sphere_scene(size=96):
    cam = Camera(position=(0.0, 0.0, 5.0), look_at=(0.0, 0.0, 0.0), fov=26.0, width=size, height=size)
    light = Light(type="directional", direction=tuple(-TO_LIGHT), intensity=E)
    mat = MaterialSpec(name="m", base_color=tuple(BASE), metallic=0.0, roughness=0.5)
    return Scene(camera=cam, environment=EnvironmentSpec(color=(0.0, 0.0, 0.0)),
                 materials={"default": MaterialSpec(), "m": mat},
                 objects=(Sphere(center=(0.0, 0.0, 0.0), radius=1.0, material="m"),), lights=(light,))


def analytic_nol(scene):
    """n.l at every pixel centre from the ray-sphere intersection (NaN off the sphere)."""
    cam = scene.camera
    d = cam.ray_directions().reshape(cam.height, cam.width, 3)
    o = np.asarray(cam.position)
    b = d @ o
    disc = b * b - (o @ o - 1.0)
    t = -b - np.sqrt(np.where(disc >= 0, disc, np.nan))
    n = o + t[..., None] * d
    return n @ TO_LIGHT


PLAIN = dict(environment=False, specular=0.0, rim_color=(0.0, 0.0, 0.0))


@pytest.mark.parametrize("tones, thresholds", [(3, None), (4, None), (5, None), (3, (0.2, 0.6))])
def test_toon_sphere_has_the_requested_tones_where_n_dot_l_crosses_the_thresholds(tones, thresholds):
    scene = sphere_scene()
    style = Style(shading="toon", tones=tones, thresholds=thresholds, **PLAIN)
    result = render_styled(scene, style)
    nol = analytic_nol(scene)
    on = result.mask & np.isfinite(nol)
    levels = np.unique(np.round(result.image[on][:, 0], 12))
    assert levels.size == (len(thresholds) + 1 if thresholds else tones)
    edges = np.asarray(thresholds) if thresholds else default_thresholds(tones)
    expected_tone = toon_tone(np.maximum(nol, 0.0), edges, 0.0)
    shadow = np.asarray(style.shadow_color)
    expected = BASE / math.pi * E * (shadow + (1 - shadow) * expected_tone[..., None])
    wrong = on & ~np.isclose(result.image, expected, rtol=1e-9, atol=1e-12).all(axis=-1)
    # a pixel may differ only where a threshold passes between its n.l and a neighbour's (within a pixel)
    lo = np.minimum.reduce([np.roll(nol, s, a) for s in (-1, 0, 1) for a in (0, 1)])
    hi = np.maximum.reduce([np.roll(nol, s, a) for s in (-1, 0, 1) for a in (0, 1)])
    near = np.zeros_like(on)
    for t in edges:
        near |= (lo <= t) & (t <= hi)
    assert not np.any(wrong & ~near), np.argwhere(wrong & ~near)[:5]
    assert np.count_nonzero(wrong) <= 0.01 * np.count_nonzero(on)


def test_summed_and_per_light_agree_for_one_light_and_differ_for_two():
    scene = sphere_scene(48)
    a = render_styled(scene, Style(shading="toon", lighting="summed", **PLAIN)).image
    b = render_styled(scene, Style(shading="toon", lighting="per_light", **PLAIN)).image
    np.testing.assert_allclose(a, b, rtol=1e-12)
    two = Scene(camera=scene.camera, environment=scene.environment, materials=scene.materials, objects=scene.objects,
                lights=scene.lights + (Light(type="directional", direction=(0.7, 0.0, -0.7), intensity=1.0),))
    a = render_styled(two, Style(shading="toon", lighting="summed", **PLAIN)).image
    b = render_styled(two, Style(shading="toon", lighting="per_light", **PLAIN)).image
    assert np.abs(a - b).max() > 1e-3
    # summed: the number of distinct tones stays the requested one, whatever the lights
    on = render_styled(two, Style(shading="toon", **PLAIN)).mask
    assert np.unique(np.round(a[on][:, 0] / a[on][:, 0].max(), 9)).size == 3


def test_mtoon_follows_the_specification():
    """mix(shade, base, linearstep(-1 + toony, 1 - toony, n.l + shift) V) E / pi with no
    environment light (MToon 1.0, Lighting), V the shadow term: 0 where the surface
    faces away from the light (its own shadow)."""
    scene = sphere_scene(48)
    shade = np.array([0.1, 0.05, 0.3])
    style = Style(shading="mtoon", shade_color=tuple(shade), shading_shift=-0.2, shading_toony=0.6,
                  rim_color=(0.0, 0.0, 0.0))
    result = render_styled(scene, style, bake_size=16)
    nol = analytic_nol(scene)
    on = result.mask & np.isfinite(nol)
    s = (linearstep(-1 + 0.6, 1 - 0.6, nol - 0.2) * (nol > 0))[..., None]
    expected = (shade + (BASE - shade) * s) * E / math.pi
    np.testing.assert_allclose(result.image[on], expected[on], rtol=1e-3, atol=1e-6)


def test_styles_are_deterministic_and_rim_and_highlights_add_light():
    scene = sphere_scene(48)
    style = Style(shading="toon", rim_color=(0.3, 0.3, 0.3), outline="none")
    a = render_styled(scene, style, bake_size=16).image
    b = render_styled(scene, style, bake_size=16).image
    assert a.tobytes() == b.tobytes()
    plain = render_styled(scene, Style(shading="toon", **PLAIN)).image
    assert np.all(a >= plain - 1e-12) and np.any(a > plain + 1e-6)


def test_scene_style_section_and_its_errors():
    base = {"objects": [{"type": "sphere"}]}
    scene = scene_from_dict({**base, "style": {"shading": "toon", "tones": 4}})
    assert scene.style.shading == "toon" and scene.style.tones == 4
    for table, fragment in [({"shading": "cel"}, "style shading must be one of"),
                            ({"tones": 1}, "style tones must be an integer in [2, 64]"),
                            ({"tones": 2.5}, "style tones must be an integer"),
                            ({"thresholds": [0.6, 0.2]}, "increase"),
                            ({"softness": -1}, "style softness"),
                            ({"bands": 3}, "unknown key 'bands'"),
                            ({"environment": "yes"}, "true or false")]:
        with pytest.raises(ValueError) as info:
            style_from_dict(table)
        assert fragment in str(info.value)
        assert "\n" not in str(info.value)


def test_cli_style_presets_files_and_refusals(tmp_path):
    runner = CliRunner()
    out = tmp_path / "toon.png"
    r = runner.invoke(app, ["render", "sphere", "-o", str(out), "--width", "32", "--height", "32", "--style", "toon",
                            "--bake-size", "16", "-q"])
    assert r.exit_code == 0, r.output
    assert out.exists()
    r = runner.invoke(app, ["render", "sphere", "-o", str(tmp_path / "x.png"), "--style", "watercolour", "-q"])
    assert r.exit_code != 0 and "presets" in r.output and not (tmp_path / "x.png").exists()
    bad = tmp_path / "style.toml"
    bad.write_text('[style]\nshading = "toon"\ntones = 0\n')
    r = runner.invoke(app, ["render", "sphere", "-o", str(tmp_path / "y.png"), "--style", str(bad), "-q"])
    assert r.exit_code != 0 and "style.toml" in r.output and "tones" in r.output
    r = runner.invoke(app, ["render", "sphere", "-o", str(tmp_path / "z.png"), "--style", "toon", "--mode", "compare",
                            "--spp", "1", "-q"])
    assert r.exit_code != 0 and "--mode realtime" in r.output and not (tmp_path / "z.png").exists()


def test_inverted_hull_of_a_sphere_is_a_ring_of_the_requested_width():
    """The hull of a unit sphere 5 units away, pushed out by w pixels' worth of its
    distance: outline pixels form a ring from the sphere's silhouette to that of the
    grown sphere, about w pixels wide (measured along the image's middle row)."""
    from pbrkit.npr.hull import hull_pixel_size

    size = 160
    scene = sphere_scene(size)
    width = 4.0
    result = render_styled(scene, Style(shading="toon", outline="hull", outline_width=width,
                                        outline_color=(0.0, 1.0, 0.0), **PLAIN))
    ring = (result.image[..., 1] > 0.99) & (result.image[..., 0] < 1e-9)
    row = ring[size // 2]
    assert abs(np.count_nonzero(row) / 2 - width) <= 1.0, np.count_nonzero(row)
    # the ring's outer radius is where rays graze the grown sphere: asin((r + w px d) / d)
    cam = scene.camera
    d = 5.0
    grown = 1.0 + width * hull_pixel_size(cam) * d
    f = (size / 2) / math.tan(math.radians(cam.fov) / 2)
    outer = f * math.tan(math.asin(grown / d))
    cols = np.flatnonzero(row)
    measured = (cols.max() + 0.5 - size / 2)
    assert abs(measured - outer) <= 1.0, (measured, outer)
    assert not ring[result.mask].any()  # never over the sphere itself


def _hull_ring_outer_radius(scene, style):
    result = render_styled(scene, style)
    ring = (result.image[..., 1] > 0.99) & (result.image[..., 0] < 1e-9)
    cols = np.flatnonzero(ring[scene.camera.height // 2])
    assert not ring[result.mask].any()
    return cols.max() + 0.5 - scene.camera.width / 2


@pytest.mark.parametrize("mode, width", [("world", 0.05), ("screen", 0.02)])
def test_hull_width_in_world_and_screen_units(mode, width):
    """MToon's outlineWidthMode: ``world`` pushes the unit sphere's hull out by the width
    in scene units (the ring's outer edge is where rays graze a sphere of radius 1 + w);
    ``screen`` makes the ring a fraction of the image height wide, at any distance."""
    size = 160
    scene = sphere_scene(size)
    cam = scene.camera
    style = Style(shading="toon", outline="hull", outline_width=width, outline_width_mode=mode,
                  outline_color=(0.0, 1.0, 0.0), **PLAIN)
    f = (size / 2) / math.tan(math.radians(cam.fov) / 2)
    measured = _hull_ring_outer_radius(scene, style)
    silhouette = f * math.tan(math.asin(1.0 / 5.0))
    if mode == "world":
        assert abs(measured - f * math.tan(math.asin((1.0 + width) / 5.0))) <= 1.0
        # twice as far, the same world width covers about half the pixels
        far = Scene(camera=Camera(position=(0.0, 0.0, 10.0), look_at=(0.0, 0.0, 0.0), fov=cam.fov, width=size,
                                  height=size), environment=scene.environment, materials=scene.materials,
                    objects=scene.objects, lights=scene.lights)
        expected = f * (math.tan(math.asin((1.0 + width) / 10.0)) - math.tan(math.asin(1.0 / 10.0)))
        assert abs(_hull_ring_outer_radius(far, style) - f * math.tan(math.asin(0.1)) - expected) <= 1.0
    else:
        assert abs((measured - silhouette) - width * size) <= 1.5


def test_mtoon_style_maps_the_vrm_extension(tmp_path):
    """A VRMC_materials_mtoon 1.0 object (as a glTF material carries it) becomes a
    ``mtoon`` style with the specification's meaning of each property."""
    import json

    from pbrkit.npr.style import mtoon_style, resolve_style

    ext = {"specVersion": "1.0", "shadeColorFactor": [0.3, 0.2, 0.4], "shadingShiftFactor": -0.1,
           "shadingToonyFactor": 0.8, "giEqualizationFactor": 0.5, "parametricRimColorFactor": [0.2, 0.1, 0.0],
           "parametricRimFresnelPowerFactor": 3.0, "parametricRimLiftFactor": 0.1, "rimLightingMixFactor": 0.25,
           "outlineWidthMode": "worldCoordinates", "outlineWidthFactor": 0.02, "outlineColorFactor": [0.1, 0.0, 0.0],
           "matcapFactor": [1, 1, 1]}
    s = mtoon_style(ext)
    assert (s.shading, s.shade_color, s.shading_shift, s.shading_toony, s.gi_equalization) == \
        ("mtoon", (0.3, 0.2, 0.4), -0.1, 0.8, 0.5)
    assert (s.rim_color, s.rim_power, s.rim_lift, s.rim_mix) == ((0.2, 0.1, 0.0), 3.0, 0.1, 0.25)
    assert (s.outline, s.outline_width_mode, s.outline_width, s.outline_color) == ("hull", "world", 0.02,
                                                                                   (0.1, 0.0, 0.0))
    assert mtoon_style({**ext, "outlineWidthMode": "screenCoordinates"}).outline_width_mode == "screen"
    assert mtoon_style({"specVersion": "1.0"}).outline == "none"  # the specification's default mode
    path = tmp_path / "material.json"
    path.write_text(json.dumps({"name": "skin", "VRMC_materials_mtoon": ext}))
    assert resolve_style(path) == s
    for bad in ({"outlineWidthMode": "pixels"}, {"shadingToonyFactor": "x"}, {"shadeColorFactor": [1, 2]},
                {"rimColor": [0, 0, 0]}):
        with pytest.raises(ValueError, match="VRMC_materials_mtoon"):
            mtoon_style({**ext, **bad})
    with pytest.raises(ValueError, match="world"):
        Style(outline="image", outline_width_mode="world")
