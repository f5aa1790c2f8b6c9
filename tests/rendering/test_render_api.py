"""``pbrkit.render``: a scene rendered in one call and returned as arrays (issue 26, "a
Python API a notebook user expects"): the same pixels as the renderers it calls, the
ground truth's standard error and a comparison's error map, ``to_srgb`` / ``save`` /
``_repr_png_`` agreeing with each other and with the files ``pbrkit render`` writes, the
scene given as a name, a file, a dict or a Scene, and options refused before any work."""

from __future__ import annotations

import json

import numpy as np
import pytest

import pbrkit
from pbrkit.rendering.realtime import render_realtime
from pbrkit.rendering.reference import render_reference
from pbrkit.rendering.scene import builtin_scene

SIZE = dict(width=16, height=8)


def test_realtime_returns_the_renderer_s_pixels():
    r = pbrkit.render("sphere", bake_size=16, **SIZE)
    assert isinstance(r, pbrkit.Rendering) and r.mode == "realtime"
    direct = render_realtime(builtin_scene("sphere", 16, 8), bake_size=16)
    np.testing.assert_array_equal(r.image, direct.image)
    assert r.realtime is r.image and r.reference is None and r.stderr is None and r.error is None
    assert r.image.shape == (8, 16, 3) and r.mask.shape == (8, 16) and r.mask.any()
    assert r.stats["mode"] == "realtime" and "timings" in r.stats["realtime"]


def test_reference_holds_the_ground_truth_and_its_error(tmp_path):
    from pbrkit.io.exr import read_exr

    r = pbrkit.render("sphere", mode="reference", spp=4, **SIZE)
    direct = render_reference(builtin_scene("sphere", 16, 8), spp=4)
    np.testing.assert_array_equal(r.image, direct.image)
    np.testing.assert_array_equal(r.stderr, direct.stderr)
    written = r.save(tmp_path / "truth.exr")
    assert [p.name for p in written] == ["truth.exr", "truth.stderr.exr"]
    np.testing.assert_array_equal(read_exr(tmp_path / "truth.exr")[..., :3], r.image.astype(np.float32))
    np.testing.assert_array_equal(read_exr(tmp_path / "truth.stderr.exr")[..., :3], r.stderr.astype(np.float32))


def test_compare_pictures_agree_with_each_other_and_the_command(tmp_path):
    import imageio.v3 as iio

    from pbrkit.rendering.run import render_scene

    options = dict(mode="compare", spp=4, bake_size=16, split=False, flip=False)
    r = pbrkit.render("sphere", **options, **SIZE)
    assert r.realtime.shape == r.reference.shape == (8, 16, 3) and r.error.shape == (8, 16)
    # the error map: |Y - Y_ref| / max(Y_ref, floor), the floor 0.1 x the mean Y_ref over the surface
    y = lambda x: x @ np.array([0.2126, 0.7152, 0.0722])  # noqa: E731
    floor = 0.1 * y(r.reference)[r.mask].mean()
    assert r.stats["errors"]["luminance_floor"] == pytest.approx(floor, rel=1e-12)
    expected = np.abs(y(r.realtime) - y(r.reference)) / np.maximum(y(r.reference), floor)
    np.testing.assert_allclose(r.error[r.mask], expected[r.mask], rtol=1e-9)
    assert np.all(r.error[~r.mask] == 0.0)
    errors = r.stats["errors"]
    for key, value in (("mean", np.mean(r.error[r.mask])), ("median", np.median(r.error[r.mask])),
                       ("p90", np.percentile(r.error[r.mask], 90))):
        assert errors[f"{key}_floored_error"] == pytest.approx(value, rel=1e-12)
    srgb = r.to_srgb()
    assert srgb.dtype == np.uint8 and srgb.shape == (8, 48, 3)  # real time | truth | error, untitled
    png = r._repr_png_()  # the titled figure: panels enlarged to at least 256 rows, the colour bar
    figure = iio.imread(png)
    assert png.startswith(b"\x89PNG") and figure.shape[0] > 256 and figure.shape[1] > 3 * 512
    assert r._repr_png_() == png  # the same bytes again
    r.save(tmp_path / "api.png")
    render_scene(builtin_scene("sphere", 16, 8), tmp_path / "cmd.png", **options)
    assert (tmp_path / "api.png").read_bytes() == (tmp_path / "cmd.png").read_bytes() == png
    assert not np.array_equal(r.to_srgb(exposure=1.0), srgb)


def test_a_scene_file_a_dict_and_a_scene_render_alike(tmp_path):
    table = {"camera": {"position": [0.0, 0.0, 4.0], "look_at": [0.0, 0.0, 0.0], "fov": 30.0, "width": 8,
                        "height": 8},
             "environment": {"color": [0.5, 0.5, 0.5]},
             "objects": [{"type": "sphere", "center": [0.0, 0.0, 0.0], "radius": 1.0}]}
    path = tmp_path / "s.json"
    path.write_text(json.dumps(table))
    from_file = pbrkit.render(str(path), bake_size=16)
    from_dict = pbrkit.render(table, bake_size=16)
    from_scene = pbrkit.render(pbrkit.load_scene(path), bake_size=16)
    np.testing.assert_array_equal(from_file.image, from_dict.image)
    np.testing.assert_array_equal(from_file.image, from_scene.image)


@pytest.mark.parametrize("kwargs, fragment", [
    (dict(mode="fast"), "unknown mode 'fast'; choose one of realtime, reference, compare"),
    (dict(tonemap="filmic"), "unknown tone mapper 'filmic'"),
    (dict(exposure=float("nan")), "exposure must be finite"),
    (dict(spp=0, mode="reference"), "--spp"),
])
def test_bad_options_are_refused_before_any_work(kwargs, fragment, monkeypatch):
    import pbrkit.rendering.run as run

    monkeypatch.setattr(run, "Geometry", lambda *a: pytest.fail("work started"))
    with pytest.raises(ValueError, match=fragment.replace("(", r"\(").replace(")", r"\)")):
        pbrkit.render("sphere", **kwargs)


def test_a_scene_object_with_overrides_and_a_missing_scene_are_refused():
    with pytest.raises(ValueError, match="width, height and environment apply to a scene given by name or file"):
        pbrkit.render(builtin_scene("sphere", 8, 8), width=16)
    with pytest.raises(ValueError, match="no-such-scene.toml"):
        pbrkit.render("no-such-scene.toml")
    with pytest.raises(ValueError, match="scene"):
        pbrkit.render(None)


def test_a_gltf_file_renders_framed_on_its_own(tmp_path):
    """``pbrkit.render("model.glb")``: the model under the bundled environment, seen from +Z,
    its bounding sphere filling 90 % of the view (the quad of ``write_quad_glb``: 2 x 2 at
    z = -1, so the camera looks at (0, 0, -1) from sqrt(2) / sin(0.9 x 17.5 degrees) away)."""
    import math

    from gltf_scenes import write_quad_glb

    from pbrkit.rendering.sources import resolve_scene

    path = write_quad_glb(tmp_path / "q.glb")
    scene = resolve_scene(path, width=24)
    cam = scene.camera
    assert (cam.width, cam.height) == (24, 24) and cam.look_at == pytest.approx((0.0, 0.0, -1.0))
    distance = math.sqrt(2.0) / math.sin(math.radians(0.9 * 17.5))
    assert cam.position == pytest.approx((0.0, 0.0, -1.0 + distance))
    assert scene.environment.file is None and scene.environment.color is None  # the bundled map
    r = pbrkit.render(path, width=24, bake_size=16)
    # the square fills the middle: the inscribed square of the framed sphere is its 0.9 / sqrt(2) share
    side = 0.9 / math.sqrt(2.0) * math.tan(math.radians(0.9 * 17.5)) / math.tan(math.radians(17.5)) * 24
    assert abs(r.mask.sum() - side * side) < 4 * side + 4


@pytest.mark.parametrize("name, size, expected", [("spheres", dict(width=128), (128, 128)),
                                                  ("area", dict(width=128), (128, 64)),
                                                  ("area", dict(height=100), (200, 100))])
def test_one_side_keeps_the_aspect_ratio(name, size, expected):
    from pbrkit.rendering.sources import resolve_scene

    cam = resolve_scene(name, **size).camera
    assert (cam.width, cam.height) == expected


def test_render_scene_without_an_output_path_says_what_to_use():
    from pbrkit.rendering.run import render_scene

    with pytest.raises(ValueError, match="the output must be a .exr or .png path; got NoneType .pbrkit.render"):
        render_scene(builtin_scene("sphere", 8, 8), None)


@pytest.mark.parametrize("args, fragment", [
    (["--width", "100000"], "--width must be an integer in [1, 16384]; got 100000"),
    (["--height", "0"], "--height must be an integer in [1, 16384]; got 0"),
    (["--mode", "reference", "--style", "toon"], "--style toon"),
])
def test_the_render_command_names_the_flag_typed_before_any_work(tmp_path, monkeypatch, args, fragment):
    from typer.testing import CliRunner

    import pbrkit.rendering.sources as sources
    from pbrkit.cli import app

    monkeypatch.setattr(sources, "resolve_scene", lambda *a, **k: pytest.fail("the scene was loaded"))
    r = CliRunner().invoke(app, ["render", "spheres", "-o", str(tmp_path / "x.png"), *args])
    assert r.exit_code != 0 and fragment in " ".join(r.output.split()), r.output
    assert not any(tmp_path.iterdir())

