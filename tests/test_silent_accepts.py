"""No silent accepts: a value of the wrong type (a bool where a number is expected,
a string), NaN, an infinity, a value out of range or a contradictory combination
in a style, a light, a scene file or the ``ltc`` command's flags is refused with
one line naming the file and the key (or the flag), saying what was expected,
never quoting the file's text; a file that is not a regular file (``/dev/zero``
behind a symbolic link, a named pipe) is refused before it is read.

The property test at the end takes a valid scene file (TOML), mutates it at
random (values replaced by other types, NaN, infinities, huge or negative
numbers; keys removed or renamed; bytes flipped) and loads it with the function
``pbrkit render`` parses scene files with (:func:`pbrkit.render.scene.command_scene`):
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

from pbrkit.app.cli import app
from pbrkit.core.errors import InputError
from pbrkit.npr.style import mtoon_style, resolve_style, style_from_dict
from pbrkit.render.area_lights import AreaLight, area_light_arrays
from pbrkit.render.light_checks import _turns, newell_normal
from pbrkit.render.lights import Light, light_arrays
from pbrkit.render.material_spec import MaterialSpec
from pbrkit.render.scene import command_scene, load_scene, scene_from_dict

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
