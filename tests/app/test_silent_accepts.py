"""No silent accepts: a value of the wrong type (a bool where a number is expected,
a string), NaN, an infinity, a value out of range or a contradictory combination
in a style, a light, a scene file or the ``ltc`` command's flags is refused with
one line naming the file and the key (or the flag), saying what was expected,
never quoting the file's text; a file that is not a regular file (``/dev/zero``
behind a symbolic link, a named pipe) is refused before it is read.

The property test at the end takes a valid scene file (TOML), mutates it at
random (values replaced by other types, NaN, infinities, huge or negative
numbers; keys removed or renamed; bytes flipped) and loads it with the function
``pbrkit render`` parses scene files with (:func:`pbrkit.rendering.sources.command_scene`):
either the scene loads, with finite values everywhere, or a one-line
:class:`InputError` names the file; never another exception, never a warning.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import math
import os
import subprocess
import sys
import textwrap
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from pbrkit.cli import app
from pbrkit.core.errors import InputError
from pbrkit.npr.style import mtoon_style, resolve_style, style_from_dict
from pbrkit.rendering.area_lights import AreaLight, area_light_arrays
from pbrkit.rendering.light_checks import _turns, newell_normal
from pbrkit.rendering.lights import Light, light_arrays
from pbrkit.rendering.material_spec import MaterialSpec
from pbrkit.rendering.scene import load_scene, scene_from_dict
from pbrkit.rendering.sources import command_scene

NAN, INF = float("nan"), float("inf")
SECRET = "SECRET_CONTENT_7f3a"
SPHERE = {"objects": [{"type": "sphere"}]}


def invoke(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def assert_refused(result, *fragments, out=None):
    """Exit status 1, one ``pbrkit: error:`` line on stderr holding ``fragments``,
    no traceback, nothing written at ``out``."""
    assert isinstance(result.exception, SystemExit) and result.exit_code == 1, (result.exception, result.output)
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("pbrkit: error: "), result.stderr
    assert "Traceback" not in result.output
    for fragment in fragments:
        assert str(fragment) in lines[0], lines[0]
    assert out is None or not Path(out).exists()
    return lines[0]


# ------------------------------------------------------------------ styles

STYLE_CASES = [
    ({"thresholds": [True, 0.5]}, "style thresholds must increase within [0, 1]"),
    ({"thresholds": ["0.2", "0.6"]}, "style thresholds must increase within [0, 1]"),
    ({"thresholds": [0.2, NAN]}, "style thresholds must increase within [0, 1]"),
    ({"softness": True}, "style softness must be a number in [0, 1]; got true"),
    ({"specular": False}, "style specular must be a number in [0, 100]; got false"),
    ({"rim_power": "5"}, "style rim_power must be a number in [0, 100]; got '5'"),
    ({"shading_toony": NAN}, "style shading_toony must be a number in [0, 0.999]"),
    ({"outline_width": INF}, "style outline_width must be a number in [0, 64]"),
    ({"shadow_color": ["0.3", "0.3", "0.4"]}, "style shadow_color must be a list of 3 non-negative numbers"),
    ({"shadow_color": "dark blue"}, "style shadow_color must be a list of 3 non-negative numbers; got 'dark blue'"),
    ({"rim_color": [True, 0, 0]}, "style rim_color must be a list of 3 non-negative numbers"),
    ({"outline_color": [0, 0, -1]}, "style outline_color must be a list of 3 non-negative numbers"),
    ({"tones": True}, "style tones must be an integer; got true"),
    ({"environment": 1}, "style environment must be true or false; got 1"),
    ({"ramp": 3}, "style ramp must be a non-empty string; got 3"),
    ({"shading": "x" * 5000}, "style shading must be one of pbr, toon, mtoon, hatching"),
    ({"tones": 4, "thresholds": [0.3]}, "style: tones and thresholds are alternatives"),
    ({"shadow_color": [0, 0, 0], "ramp": "ramp.png"}, "style: shadow_color and ramp are alternatives"),
]


@pytest.mark.parametrize("table, fragment", STYLE_CASES, ids=[str(t)[:40] for t, _ in STYLE_CASES])
def test_style_values_of_the_wrong_type_range_or_combination_are_refused(table, fragment):
    with pytest.raises(ValueError) as info:
        style_from_dict(table)
    message = str(info.value)
    assert fragment in message and "\n" not in message, message
    assert "x" * 80 not in message  # a value is quoted short


def test_the_same_style_values_pass_as_numbers():
    """The refusals above are of the types, not the keys: numbers pass."""
    style = style_from_dict({"thresholds": [0.2, 0.6], "softness": 0.1, "shadow_color": [0.3, 0.3, 0.4],
                             "rim_color": [1, 0, 0], "environment": False, "hatching_tones": 4, "shading": "toon"})
    assert style.thresholds == (0.2, 0.6) and style.shadow_color == (0.3, 0.3, 0.4) and style.hatching_tones == 4


@pytest.mark.parametrize("value", [1.5, -0.1, True, "0.9", [0.9], NAN, INF])
def test_mtoon_toony_outside_zero_one_is_refused(value):
    """VRMC_materials_mtoon.schema.json: shadingToonyFactor in [0, 1] (it was clamped to
    0.999 from any value above, and a list raised a TypeError)."""
    with pytest.raises(ValueError, match=r"shadingToonyFactor must be a number in \[0, 1\]"):
        mtoon_style({"shadingToonyFactor": value})


def test_mtoon_factors_in_range_are_taken():
    assert mtoon_style({"shadingToonyFactor": 1.0}).shading_toony == 0.999  # the step's width stays positive
    assert mtoon_style({"shadingToonyFactor": 0}).shading_toony == 0.0
    with pytest.raises(ValueError, match="shadeColorFactor must be a list of 3 numbers in"):
        mtoon_style({"shadeColorFactor": [1, True, 0]})
    with pytest.raises(ValueError, match="giEqualizationFactor must be a number in"):
        mtoon_style({"giEqualizationFactor": 2.0})


def test_a_style_file_of_bad_json_names_the_file(tmp_path):
    path = tmp_path / "m.json"
    path.write_text(json.dumps({"VRMC_materials_mtoon": {"shadingToonyFactor": 3}}))
    with pytest.raises(InputError) as info:
        resolve_style(path)
    assert str(info.value).startswith(f"{path}: ") and "shadingToonyFactor" in str(info.value)


BAD_TEXT = {  # file name: content whose parser message would quote it
    "dup.toml": f"[style]\n{SECRET} = 1\n{SECRET} = 2\n",
    "char.toml": f'[style]\nshading = "{SECRET}\x01"\n',
    "key.toml": f"[style]\n{SECRET} {SECRET}\n",
    "bad.json": f'{{"{SECRET}": {SECRET}}}',
    "latin1.toml": f'[style]\nshading = "{SECRET}\xe9"\n'.encode("latin-1"),
}


@pytest.mark.parametrize("name", list(BAD_TEXT))
def test_style_and_scene_files_that_do_not_parse_are_not_quoted(tmp_path, name):
    """tomllib names the key it cannot declare twice and the character it cannot take;
    a refusal gives the position and what was expected instead."""
    content = BAD_TEXT[name]
    path = tmp_path / name
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    for load in (resolve_style, load_scene):
        with pytest.raises(InputError) as info:
            load(path)
        message = str(info.value)
        assert message.startswith(f"{path}: ") and "\n" not in message
        assert SECRET not in message, message
        assert "expected" in message and ("line" in message or "byte" in message or "the end" in message), message


def test_unreadable_files_are_refused_at_once(tmp_path):
    """A scene or style that is /dev/zero behind a symbolic link, or a named pipe, and a
    ramp that is a pipe: refused as not regular files (a plain read would never end, or
    block), in a child process with a time limit so that a regression fails, not hangs."""
    (tmp_path / "zero.toml").symlink_to("/dev/zero")
    (tmp_path / "zero.json").symlink_to("/dev/zero")
    os.mkfifo(tmp_path / "pipe.toml")
    os.mkfifo(tmp_path / "ramp.png")
    script = textwrap.dedent(f"""
        from pbrkit.npr.style import resolve_style, style_from_dict
        from pbrkit.rendering.sources import command_scene
        root = {str(tmp_path)!r}
        for load, name in ((command_scene, "zero.toml"), (command_scene, "pipe.toml"),
                           (resolve_style, "zero.json"), (resolve_style, "pipe.toml")):
            try:
                load(root + "/" + name)
            except ValueError as exc:
                print(exc)
        try:
            style_from_dict({{"shading": "toon", "ramp": "ramp.png"}}, root)
        except ValueError as exc:
            print(exc)
    """)
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2] / "src")}
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, env=env)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert len(lines) == 5, done.stdout
    for line, name, kind in zip(lines, ("zero.toml", "pipe.toml", "zero.json", "pipe.toml", "ramp.png"),
                                ("character device", "named pipe", "character device", "named pipe", "named pipe")):
        assert name in line and f"is a {kind}, not a regular file" in line, line


# ------------------------------------------------- styles and the render mode


@pytest.fixture
def styled_scene(tmp_path):
    path = tmp_path / "styled.toml"
    path.write_text('[camera]\nwidth = 16\nheight = 16\n[style]\nshading = "toon"\n[[objects]]\ntype = "sphere"\n')
    return path


@pytest.mark.parametrize("mode", ["reference", "compare"])
def test_a_style_flag_outside_realtime_is_refused_naming_the_flag(tmp_path, mode):
    out = tmp_path / "out.exr"
    result = invoke("render", "sphere", "-o", out, "--mode", mode, "--style", "toon", "--spp", "1", "-q",
                    "--width", "16", "--height", "16")
    assert_refused(result, "--style toon", "--mode realtime only", f"--mode {mode}", out=out)


@pytest.mark.parametrize("mode", ["reference", "compare"])
def test_a_scene_style_outside_realtime_is_refused_naming_the_key(tmp_path, styled_scene, mode):
    out = tmp_path / "out.exr"
    result = invoke("render", styled_scene, "-o", out, "--mode", mode, "--spp", "1", "-q")
    assert_refused(result, f"{styled_scene}: [style] (toon", "--mode realtime only", "--style pbr", out=out)


# ------------------------------------------------------------------ lights


def pentagon(order=(0, 1, 2, 3, 4), y=2.0):
    """A regular pentagon in the plane y, counter-clockwise seen from below (lit downwards),
    its vertices taken in ``order``: (0, 2, 4, 1, 3) is the five-pointed star."""
    points = [[math.cos(2 * math.pi * k / 5), y, math.sin(2 * math.pi * k / 5)] for k in range(5)]
    return [points[k] for k in order]


def test_turning_angles_of_a_convex_polygon_sum_to_two_pi_and_of_a_star_to_four_pi():
    """The quantity the polygon test reads (Hopf's Umlaufsatz): once around, or twice."""
    for order, turns in (((0, 1, 2, 3, 4), 1), ((0, 2, 4, 1, 3), 2)):
        v = np.asarray(pentagon(order))
        total = float(np.sum(_turns(v, newell_normal(v))))
        assert total == pytest.approx(2 * math.pi * turns, abs=1e-12)
        assert np.all(_turns(v, newell_normal(v)) > 0.0)  # every turn has one sign: no per-vertex test sees it


POLYGON_CASES = [
    (pentagon((0, 2, 4, 1, 3)), "its edges cross (its turning angles sum to 4 pi"),
    (pentagon((0, 3, 1, 4, 2)), "its edges cross (its turning angles sum to 4 pi"),
    (pentagon() + [pentagon()[0]], "repeated vertices (vertices[0] and vertices[5]"),
    (pentagon((0, 1, 1, 2, 3)), "repeated vertices (vertices[1] and vertices[2]"),
    ([[0, 2, 0]] * 3, "zero area"),
    ([[0, 2, 0], [1, 2, 0], [2, 2, 0]], "zero area"),
    ([[0, 2, 0], [1, 2, 0], [1, 2, 1], [0, 2.5, 1]], "one plane"),
    ([[0, 2, 0], [2, 2, 0], [0.5, 2, 0.5], [0, 2, 2]], "convex"),
    ([[0, 2, 0], [2, 2, 0], [1, 2, 0], [1, 2, 1]], "doubles back"),
]


@pytest.mark.parametrize("vertices, fragment", POLYGON_CASES, ids=[f for _, f in POLYGON_CASES])
def test_polygon_lights_must_be_simple_convex_and_planar(vertices, fragment):
    with pytest.raises(ValueError) as info:
        scene_from_dict({**SPHERE, "lights": [{"type": "polygon", "vertices": vertices}]})
    assert str(info.value).startswith("lights[0]: polygon light") and fragment in str(info.value), info.value


def test_convex_polygons_pass_either_way_round_and_with_a_straight_vertex():
    for vertices in (pentagon(), pentagon((4, 3, 2, 1, 0)), [[0, 2, 0], [1, 2, 0], [2, 2, 0], [2, 2, 1], [0, 2, 1]]):
        light = AreaLight(type="polygon", vertices=vertices)
        assert math.isfinite(light.area) and light.area > 0.0
    assert AreaLight(type="polygon", vertices=pentagon()).normal == pytest.approx((0.0, -1.0, 0.0))


EMISSION_CASES = [
    ({"type": "rect", "unit": "power", "intensity": 1e-300, "width": 1e6, "height": 1e6}, "intensity (unit power)",
     "rounds to zero"),
    ({"type": "disk", "unit": "power", "intensity": 1e-305, "radius": 1e3}, "intensity (unit power)",
     "rounds to zero"),
    ({"type": "rect", "unit": "power", "intensity": 1e12, "width": 1e-300, "height": 1e-300},
     "intensity (unit power)", "not finite"),
    ({"type": "sphere", "unit": "power", "intensity": 1e12, "radius": 1e-200}, "intensity (unit power)",
     "not finite"),
    ({"type": "rect", "unit": "power", "intensity": 1e12, "width": 1e-5, "height": 1e-5},
     "intensity (unit power)", "more than 1e+12"),
    ({"type": "rect", "color": [1e12, 1e12, 1e12], "intensity": 1e12}, "color * intensity", "more than 1e+12"),
    ({"type": "rect", "color": [1e-200, 1, 1], "intensity": 1e-200}, "color * intensity", "rounds to zero"),
    ({"type": "point", "color": [1e-200, 1, 1], "intensity": 1e-200}, "color * intensity", "rounds to zero"),
]


@pytest.mark.parametrize("light, key, fragment", EMISSION_CASES, ids=[str(c[0])[:50] for c in EMISSION_CASES])
def test_lights_whose_radiance_is_zero_or_not_finite_are_refused(light, key, fragment):
    with pytest.raises(ValueError) as info:
        scene_from_dict({**SPHERE, "lights": [light]})
    message = str(info.value)
    assert message.startswith("lights[0]: ") and key in message and fragment in message, message


def test_a_dark_light_is_still_allowed_and_a_small_power_is_kept():
    """Intensity 0 switches a light off on purpose; a small power that a double holds is kept."""
    assert AreaLight(type="rect", intensity=0.0).radiance == (0.0, 0.0, 0.0)
    assert AreaLight(type="rect", intensity=1e-250, unit="power").radiance[0] > 0.0


@pytest.mark.parametrize("light, key", [
    ({"type": "directional", "position": [0, 1, 0]}, "position"),
    ({"type": "directional", "range": 5.0}, "range"),
    ({"type": "directional", "falloff": "ue4"}, "falloff"),
    ({"type": "point", "direction": [0, -1, 0]}, "direction"),
    ({"type": "point", "inner_cone_angle": 0.1}, "inner_cone_angle"),
    ({"type": "point", "outer_cone_angle": 0.5}, "outer_cone_angle"),
])
def test_punctual_light_keys_of_another_type_are_refused(light, key):
    """A key its type does not use would change nothing (KHR_lights_punctual)."""
    with pytest.raises(ValueError) as info:
        scene_from_dict({**SPHERE, "lights": [light]})
    assert f"lights[0] ({light['type']}): unknown key '{key}'" in str(info.value), info.value


@pytest.mark.parametrize("kwargs, fragment", [
    ({"intensity": True}, "light intensity must be a finite number"),
    ({"intensity": "5"}, "light intensity must be a finite number"),
    ({"color": ("1", "1", "1")}, "light color must be 3 finite numbers"),
    ({"color": (True, 1, 1)}, "light color must be 3 finite numbers"),
    ({"range": True}, "light range must be a positive number"),
    ({"range": 10**400}, "light range must be a positive number"),
    ({"type": "spot", "outer_cone_angle": True}, "spot cone angles"),
    ({"color": (1e200, 1, 1), "intensity": 1e200}, "overflows"),
])
def test_lights_built_in_python_refuse_bools_strings_and_overflow(kwargs, fragment):
    with pytest.raises(ValueError, match=fragment):
        Light(**{"type": "point", **kwargs})


# ------------------------------------------------------------------ materials


@pytest.mark.parametrize("kwargs, fragment", [
    ({"roughness": "0.5"}, "roughness must be a number; got '0.5'"),
    ({"metallic": True}, "metallic must be a number; got true"),
    ({"base_color": [1, "1", 1]}, "base_color must be a list of 3 numbers"),
    ({"emissive": [True, 0, 0]}, "emissive must be 3 finite non-negative numbers"),
    ({"double_sided": "no"}, "double_sided must be true or false; got 'no'"),
    ({"model": 3}, "unknown model '3'"),
])
def test_material_specs_refuse_bools_and_strings(kwargs, fragment):
    with pytest.raises(ValueError) as info:
        MaterialSpec(**kwargs)
    assert fragment in str(info.value), info.value


def test_names_from_the_file_are_quoted_short():
    name = "m" * 5000
    with pytest.raises(ValueError) as info:
        scene_from_dict({"materials": {name: {"model": "phong"}}, "objects": [{"type": "sphere"}]})
    assert "unknown model 'phong'" in str(info.value) and len(str(info.value)) < 300
    with pytest.raises(ValueError) as info:
        scene_from_dict({"objects": [{"type": "sphere", "material": name}]})
    assert "which is not defined" in str(info.value) and len(str(info.value)) < 300
    with pytest.raises(ValueError) as info:
        scene_from_dict({"camera": {name: 1}, "objects": [{"type": "sphere"}]})
    assert "unknown key 'mmm" in str(info.value) and name not in str(info.value)


# ------------------------------------------------------------------ ltc


def test_ltc_published_without_report_is_refused_before_any_work(tmp_path):
    out = tmp_path / "tables"
    result = invoke("ltc", "-o", out, "--size", "4", "--published", tmp_path / "absent.js")
    assert_refused(result, "--published", "--report", out=out)


def test_ltc_flag_contradictions_come_before_reading_the_published_table(tmp_path):
    """--fresnel-aware without --clipping exact is refused before the (absent) published file
    is looked at: the message names --fresnel-aware, not the file."""
    out = tmp_path / "tables"
    absent = tmp_path / "absent.js"
    result = invoke("ltc", "-o", out, "--size", "4", "--report", "--published", absent, "--fresnel-aware")
    message = assert_refused(result, "--fresnel-aware", "--clipping exact", out=out)
    assert str(absent) not in message


# ------------------------------------------------ property: mutated scene files

BASE_SCENE = {
    "camera": {"position": [0.0, 1.0, 5.0], "look_at": [0.0, 0.0, 0.0], "up": [0.0, 1.0, 0.0], "fov": 40.0,
               "width": 16, "height": 16, "supersample": 1},
    "environment": {"color": [0.2, 0.2, 0.2], "intensity": 1.0, "rotation": 30.0},
    "materials": {"gold": {"model": "gltf", "base_color": [1.0, 0.78, 0.34], "metallic": 1.0, "roughness": 0.3},
                  "clay": {"model": "cook_torrance", "distribution": "ggx", "diffuse": "lambert",
                           "base_color": [0.6, 0.35, 0.25], "roughness": 0.8, "emissive": [0.0, 0.0, 0.0]}},
    "objects": [{"type": "sphere", "center": [0.0, 0.0, 0.0], "radius": 1.0, "material": "gold"},
                {"type": "plane", "point": [0.0, -1.0, 0.0], "normal": [0.0, 1.0, 0.0], "material": "clay"}],
    "lights": [{"type": "spot", "position": [0.0, 3.0, 0.0], "direction": [0.0, -1.0, 0.0], "intensity": 5.0,
                "range": 10.0, "inner_cone_angle": 0.2, "outer_cone_angle": 0.5, "falloff": "ue4"},
               {"type": "point", "position": [2.0, 2.0, 2.0], "intensity": 3.0, "color": [1.0, 0.9, 0.8]},
               {"type": "directional", "direction": [0.3, -1.0, -0.5], "intensity": 2.0},
               {"type": "rect", "position": [0.0, 3.0, 0.0], "normal": [0.0, -1.0, 0.0], "up": [0.0, 0.0, 1.0],
                "width": 2.0, "height": 1.0, "intensity": 100.0, "unit": "power", "two_sided": False},
               {"type": "polygon", "vertices": pentagon(), "intensity": 4.0},
               {"type": "disk", "position": [1.0, 3.0, 0.0], "normal": [0.0, -1.0, 0.0], "radius": 0.25},
               {"type": "sphere", "position": [-2.0, 2.0, 0.0], "radius": 0.3, "color": [1.0, 0.5, 0.25]}],
    "style": {"shading": "toon", "tones": 3, "softness": 0.1, "shadow_color": [0.3, 0.3, 0.4], "outline": "image",
              "rim_color": [0.1, 0.1, 0.1], "specular": 0.5},
}
#: Key names a renamed key may take: the scene's own, and ones of other tables.
KEY_NAMES = sorted({"file", "bake", "ramp", "vertices", "type", "unit", "two_sided", "radius", "model", "color",
                    "intensity", "thresholds", "tones", "conductor", "eta", "k", "lights", "objects", "style",
                    "scale", "rotation", "translation", "range", "falloff", "environment", "up", "normal"})
LONG = "Z" * 500
SCALARS = st.one_of(
    st.booleans(),
    st.integers(-10**6, 10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([NAN, INF, -INF, 1e308, -1e308, 5e-324, 1e-320, 0, -1, -1.0, 10**30, -10**30, 10**400, 1e6,
                     1e12, 1e13, 0.0, 2.0, 0.5]),
    st.text(alphabet="abcxyz.-_ /0123456789", max_size=8),
    st.sampled_from(["", ".", "..", "toon", "power", "ggx", "sphere", "polygon", "gold", LONG]),
)
VALUES = st.one_of(SCALARS, st.lists(SCALARS, max_size=5), st.just([]), st.just({}),
                   st.lists(st.lists(SCALARS, min_size=3, max_size=3), min_size=1, max_size=4),
                   st.dictionaries(st.sampled_from(KEY_NAMES), SCALARS, max_size=3))


NAMES = ["toon", "mtoon", "pbr", "image", "none", "power", "radiance", "ggx", "beckmann", "ue4", "khr", "gold", "clay",
         "sphere", "polygon", "rect", "disk", "point", "spot", "directional", "lambert", "per_light", "summed"]


def _like(old):
    """Values close to ``old``: other numbers (in range or just out of it), a list of the
    same length with one item changed (to a bool, a string, NaN, ...), other names:
    mutations that often still load, where a silent accept would show."""
    if isinstance(old, bool):
        return st.booleans()
    if isinstance(old, (int, float)):
        return st.one_of(st.integers(-3, 40), st.floats(-2.0, 2.0), st.floats(-1e3, 1e3),
                         st.sampled_from([0.0, 1.0, 1e-310, 1e-300, 1e-12, 1e12, 179.9]))
    if isinstance(old, str):
        return st.sampled_from(NAMES)
    if isinstance(old, list) and old and all(_is_number(x) for x in old):
        return st.tuples(st.integers(0, len(old) - 1), SCALARS, st.floats(-2.0, 2.0)).map(
            lambda t: [t[1] if i == t[0] else (x if isinstance(t[1], (bool, str)) else x * t[2])
                       for i, x in enumerate(old)])
    if isinstance(old, list) and old and all(isinstance(x, list) for x in old):  # a polygon's vertices
        return st.permutations(old).map(list)
    return VALUES


def _slots(value, path=()):
    """Every (path) to a dict entry or list element of ``value``."""
    found = []
    if isinstance(value, dict):
        for key, item in value.items():
            found.append(path + (key,))
            found.extend(_slots(item, path + (key,)))
    elif isinstance(value, list):
        for index, item in enumerate(value):
            found.append(path + (index,))
            found.extend(_slots(item, path + (index,)))
    return found


def _parent(doc, path):
    for part in path[:-1]:
        doc = doc[part]
    return doc


def _mutate(doc, data):
    """One random mutation of ``doc`` in place (module docstring)."""
    slots = _slots(doc)
    keyed = [p for p in slots if isinstance(p[-1], str)]  # whole values, more often than list items
    path = data.draw(st.sampled_from(keyed if keyed and data.draw(st.integers(0, 3), label="keyed") else slots),
                     label="where")
    parent, last = _parent(doc, path), path[-1]
    action = data.draw(st.sampled_from(["replace", "replace", "replace", "remove", "rename", "duplicate"]),
                       label="action")
    if action == "replace":
        parent[last] = data.draw(st.one_of(_like(parent[last]), VALUES), label="value")
    elif action == "remove":
        del parent[last]
    elif action == "rename" and isinstance(parent, dict):
        new = data.draw(st.one_of(st.sampled_from(KEY_NAMES), st.text(alphabet="abz_", min_size=1, max_size=5)),
                        label="new key")
        parent[new] = parent.pop(last)
    elif isinstance(parent, list):
        parent.insert(last, copy.deepcopy(parent[last]))


def _toml_key(key):
    return json.dumps(str(key))


def _toml_value(value):
    """A value as TOML (inline tables and arrays; TOML has nan and inf)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf") if math.isinf(value) else repr(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(x) for x in value) + "]"
    return "{" + ", ".join(f"{_toml_key(k)} = {_toml_value(v)}" for k, v in value.items()) + "}"


def toml_text(doc):
    return "".join(f"{_toml_key(k)} = {_toml_value(v)}\n" for k, v in doc.items())


def _finite_everywhere(value, where="scene"):
    """Every number a loaded scene holds is finite (no NaN or infinity slipped through)."""
    if isinstance(value, (bool, str)) or value is None:
        return
    if isinstance(value, (int, float, np.number)):
        assert math.isfinite(float(value)), f"{where} = {value!r}"
    elif isinstance(value, np.ndarray):
        assert np.all(np.isfinite(value)), where
    elif isinstance(value, (tuple, list)):
        for i, item in enumerate(value):
            _finite_everywhere(item, f"{where}[{i}]")
    elif isinstance(value, dict):
        for key, item in value.items():
            _finite_everywhere(item, f"{where}.{key}")
    elif dataclasses.is_dataclass(value):
        for f in dataclasses.fields(value):
            _finite_everywhere(getattr(value, f.name), f"{where}.{f.name}")


#: The keys whose values are strings, and those that are true or false (scene files, styles);
#: every other value a loaded scene took is a number or a list of numbers.
STRING_KEYS = {"type", "model", "material", "unit", "falloff", "shading", "lighting", "outline",
               "outline_width_mode", "hatching_space", "file", "bake", "ramp", "distribution", "masking",
               "fresnel", "diffuse", "conductor"}
BOOL_KEYS = {"two_sided", "environment"}
#: KHR_lights_punctual: the keys each punctual light type uses.
PUNCTUAL_KEYS = {"directional": {"type", "color", "intensity", "direction"},
                 "point": {"type", "color", "intensity", "position", "range", "falloff"},
                 "spot": {"type", "color", "intensity", "position", "direction", "range", "inner_cone_angle",
                          "outer_cone_angle", "falloff"}}


def _is_number(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _typed_as_expected(doc):
    """What a scene that loaded must have held (the oracle of the property test, from
    the documented keys, not from the code's checks): strings where strings are
    expected, true / false where those are, numbers (or lists of them) everywhere
    else, and punctual lights with their own type's keys only."""
    def leaves(table, where):
        for key, value in table.items():
            if key in ("materials",) and where == "":
                for name, material in value.items():
                    leaves(material, f"materials.{name}.")
            elif key in ("objects", "lights") and where == "":
                for item in value:
                    leaves(item, f"{key}[].")
            elif key in ("camera", "environment", "style") and where == "":
                leaves(value, f"{key}.")
            elif key in STRING_KEYS:
                assert isinstance(value, str), f"{where}{key} = {value!r}"
            elif key in BOOL_KEYS:
                assert isinstance(value, bool), f"{where}{key} = {value!r}"
            else:
                flat = np.ravel(np.asarray(value, dtype=object)) if isinstance(value, list) else [value]
                assert all(_is_number(x) for x in flat), f"{where}{key} = {value!r}"

    leaves(doc, "")
    for light in doc.get("lights", []):
        if light["type"] in PUNCTUAL_KEYS:
            assert set(light) <= PUNCTUAL_KEYS[light["type"]], light


def _faithful(scene):
    """A loaded scene renders what its file says: finite numbers everywhere, area
    lights that emit a radiance a double holds (not rounded to zero, at most 1e12 cd /
    m^2) and polygons once around (their turning angles sum to 2 pi)."""
    _finite_everywhere(scene)
    for light in scene.area_lights:
        radiance = np.asarray(light.radiance)
        emission = np.asarray(light.color) * light.intensity
        assert np.all(np.isfinite(radiance)) and np.all(radiance <= 1e12), light
        assert not np.any((emission > 0) & (radiance < np.finfo(float).tiny)), light
        assert math.isfinite(light.area) and light.area > 0.0, light
        if light.type == "polygon":
            v = np.asarray(light.vertices)
            edges = np.roll(v, -1, axis=0) - v
            prev = np.roll(edges, 1, axis=0)
            cross = np.cross(prev, edges) @ (np.asarray(light.normal))
            total = np.sum(np.arctan2(cross, np.einsum("ij,ij->i", prev, edges)))
            assert total == pytest.approx(2 * math.pi, abs=1e-6), light
    assert np.all(np.isfinite(light_arrays(scene.lights)[1]))
    assert np.all(np.isfinite(area_light_arrays(scene.area_lights).values))


@pytest.fixture(scope="module")
def scene_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("mutated")


def test_the_base_scene_loads(scene_dir):
    path = scene_dir / "base.toml"
    path.write_text(toml_text(BASE_SCENE))
    scene = command_scene(str(path))
    assert len(scene.lights) == 3 and len(scene.area_lights) == 4 and scene.style.shading == "toon"


@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_mutated_scene_files_load_or_are_refused_in_one_line(scene_dir, data):
    doc = copy.deepcopy(BASE_SCENE)
    for _ in range(data.draw(st.sampled_from([1, 1, 2, 3]), label="mutations")):
        if _slots(doc):
            _mutate(doc, data)
    raw = bytearray(toml_text(doc).encode("utf-8"))
    for _ in range(data.draw(st.sampled_from([0, 0, 0, 0, 1, 2]), label="byte flips")):
        at = data.draw(st.integers(0, len(raw) - 1), label="at")
        raw[at] ^= data.draw(st.integers(1, 255), label="xor")
    path = scene_dir / "scene.toml"
    path.write_bytes(bytes(raw))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            scene = command_scene(str(path))
        except InputError as exc:
            message = str(exc)
            assert message.startswith(f"{path}: ") and "\n" not in message, message
            assert LONG[:80] not in message, message
            scene = None
    event("refused" if scene is None else "loaded")
    assert not caught, [str(w.message) for w in caught]
    if scene is not None:
        _faithful(scene)
        _typed_as_expected(tomllib.loads(bytes(raw).decode("utf-8")))
