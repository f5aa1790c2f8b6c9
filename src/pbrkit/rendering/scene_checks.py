"""The checks of a scene file's keys and values (:mod:`pbrkit.rendering.scene`): for each
section the keys it may hold and, for each key, the type and range of its value, so
that a string, a bool, a list of the wrong length, NaN or an absurd size is refused
with its key before anything is built (``float("0.5")`` and ``float(True)`` would
pass).  Messages quote a value only through :func:`pbrkit.core.inputs.describe`
(short, escaped)."""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass

from ..core import checks
from ..core.inputs import describe
from .material_spec import CHOICES, NUMBERS, SURFACE_KEYS

# A scene file's values are checked for type and range before anything is built
# from them, so that a string, a bool, a list of the wrong length, NaN or an
# absurd size is refused with its key (float("0.5") and float(True) would pass).

#: Largest coordinate, radius or light range in a scene file: beyond it the
#: single-precision ray casting of meshes (Embree) loses all precision.
MAX_COORDINATE = 1e6
#: Largest intensity or emitted radiance (the sun's luminance is about 1.6e9 cd / m^2).
MAX_INTENSITY = 1e12


@dataclass(frozen=True)
class _Check:
    """A test of one value and the phrase that says what it must be."""

    ok: object      # value -> bool
    phrase: str


def _in_range(x, lo, hi, lo_open=False):
    return (lo is None or (x > lo if lo_open else x >= lo)) and (hi is None or x <= hi)


def _range_text(lo, hi, lo_open=False):
    if lo is not None and hi is not None:
        return f" in {'(' if lo_open else '['}{lo:g}, {hi:g}]"
    if lo is not None:
        return f" {'>' if lo_open else '>='} {lo:g}"
    return f" <= {hi:g}" if hi is not None else ""


def _number(lo=None, hi=None, lo_open=False, none_ok=False):
    """A finite number in [lo, hi] (``lo_open``: (lo, hi]); ``none_ok``: JSON null allowed."""
    return _Check(lambda v: (none_ok and v is None) or (checks.is_finite_number(v) and _in_range(v, lo, hi, lo_open)),
                  "a number" + _range_text(lo, hi, lo_open))


def _integer(lo, hi):
    return _Check(lambda v: isinstance(v, int) and not isinstance(v, bool) and lo <= v <= hi,
                  f"an integer in [{lo}, {hi}]")


def _numbers(n, lo=None, hi=None, nonzero=False):
    """A list of ``n`` finite numbers in [lo, hi] (``nonzero``: not all zero)."""
    def ok(v):
        return (isinstance(v, list) and len(v) == n and all(checks.is_finite_number(x) and _in_range(x, lo, hi) for x in v)
                and not (nonzero and not any(v)))

    return _Check(ok, f"a list of {n} numbers" + _range_text(lo, hi) + (", not all zero" if nonzero else ""))


def _scale_check():
    """glTF object scale: one number or three, non-zero, at most MAX_COORDINATE in size."""
    one = _number(-MAX_COORDINATE, MAX_COORDINATE)
    three = _numbers(3, -MAX_COORDINATE, MAX_COORDINATE)
    return _Check(lambda v: (one.ok(v) and v != 0) or (three.ok(v) and all(v)),
                  f"a non-zero number or a list of 3 non-zero numbers in [{-MAX_COORDINATE:g}, {MAX_COORDINATE:g}]")


_STRING = _Check(lambda v: isinstance(v, str) and v != "", "a non-empty string")
_POINT = _numbers(3, -MAX_COORDINATE, MAX_COORDINATE)
_DIRECTION = _numbers(3, nonzero=True)
_UNIT = _number(0.0, 1.0)
_COLOR = _numbers(3, 0.0, 1.0)
_RADIANCE = _numbers(3, 0.0, MAX_INTENSITY)

_FOV = _Check(lambda v: checks.is_finite_number(v) and 0.0 < v < 180.0, "a number of degrees in (0, 180)")
_CAMERA_VALUES = {"position": _POINT, "look_at": _POINT, "up": _DIRECTION, "fov": _FOV,
                  "width": _integer(1, 16384), "height": _integer(1, 16384), "supersample": _integer(1, 16)}
_ENV_VALUES = {"file": _STRING, "bake": _STRING, "color": _RADIANCE, "intensity": _number(0.0, MAX_INTENSITY),
               "rotation": _number()}
#: The material keys' checks, from the models' declarations: numbers in their ranges
#: (RGB ones as lists of 3), term names as strings (their tables check the names).
def _declared(p):
    """The check of a declared parameter's scene value: its range (and the values it
    allows beside it, :attr:`pbrkit.brdf.parameters.Parameter.also`)."""
    if p.channels == 3:
        return _numbers(3, p.low, p.high)
    if not p.also:
        return _number(p.low, p.high)
    inside = _number(p.low, p.high)
    return _Check(lambda v: inside.ok(v) or (checks.is_finite_number(v) and v in p.also), p.phrase)


_MATERIAL_VALUES = {**{p.name: _declared(p) for p in NUMBERS},
                    **{c.name: _STRING for c in CHOICES},
                    "emissive": _RADIANCE, "model": _STRING, "conductor": _STRING}
_OBJECT_VALUES = {"type": _STRING, "material": _STRING, "center": _POINT, "radius": _number(0.0, MAX_COORDINATE, True),
                  "point": _POINT, "normal": _DIRECTION, "file": _STRING, "translation": _POINT,
                  "rotation": _numbers(4, nonzero=True), "scale": _scale_check()}
_LIGHT_VALUES = {"type": _STRING, "falloff": _STRING, "color": _numbers(3, 0.0, MAX_INTENSITY),
                 "intensity": _number(0.0, MAX_INTENSITY), "position": _POINT, "direction": _DIRECTION,
                 "range": _number(0.0, MAX_COORDINATE, True, none_ok=True),
                 "inner_cone_angle": _number(0.0, math.pi / 2.0), "outer_cone_angle": _number(0.0, math.pi / 2.0)}


def _show(value):
    """A value as the file wrote it, kept short and escaped: true, '0.5' (a string), [1, 2]."""
    text = json.dumps(value) if isinstance(value, bool) or value is None else ascii(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _name(name):
    """A material name from the file for a message: as it is if short and plain, else
    escaped and cut (:func:`pbrkit.core.inputs.describe`)."""
    return name if isinstance(name, str) and re.fullmatch(r"[\w.+-]{1,40}", name, re.ASCII) else describe(name)


def _check_values(table, checks, label):
    """ValueError ``"<label(key)> must be <phrase>, got <value>"`` for the first value of
    ``table`` that fails its check in ``checks``."""
    for key, value in table.items():
        check = checks.get(key)
        if check is not None and not check.ok(value):
            raise ValueError(f"{label(key)} must be {check.phrase}, got {_show(value)}")


_SECTIONS = {"camera", "environment", "materials", "objects", "lights", "style", "allow_roots"}
_CAMERA_KEYS = {"position", "look_at", "up", "fov", "width", "height", "supersample"}
_ENV_KEYS = {"file", "bake", "color", "intensity", "rotation"}
_MATERIAL_KEYS = {p.name for p in NUMBERS + CHOICES} | set(SURFACE_KEYS) - {"double_sided"}
_OBJECT_KEYS = {"sphere": {"type", "center", "radius", "material"},
                "plane": {"type", "point", "normal", "material"},
                "gltf": {"type", "file", "translation", "rotation", "scale"}}
#: A punctual light's keys by type: those another type needs would change nothing
#: (KHR_lights_punctual: a directional light has no position or range, only a spot a cone).
_LIGHT_KEYS = {"directional": {"type", "color", "intensity", "direction"},
               "point": {"type", "color", "intensity", "position", "range", "falloff"},
               "spot": {"type", "color", "intensity", "position", "direction", "range", "inner_cone_angle",
                        "outer_cone_angle", "falloff"}}
_AREA_COMMON = {"type", "color", "intensity", "unit"}
_AREA_LIGHT_KEYS = {"rect": _AREA_COMMON | {"position", "normal", "up", "width", "height", "two_sided"},
                    "polygon": _AREA_COMMON | {"vertices", "two_sided"},
                    "disk": _AREA_COMMON | {"position", "normal", "radius", "two_sided"},
                    "sphere": _AREA_COMMON | {"position", "radius"}}
_BOOL = _Check(lambda v: isinstance(v, bool), "true or false")
_AREA_LIGHT_VALUES = {"type": _STRING, "unit": _STRING, "color": _numbers(3, 0.0, MAX_INTENSITY),
                      "intensity": _number(0.0, MAX_INTENSITY), "position": _POINT, "normal": _DIRECTION,
                      "up": _DIRECTION, "width": _number(0.0, MAX_COORDINATE, True),
                      "height": _number(0.0, MAX_COORDINATE, True), "radius": _number(0.0, MAX_COORDINATE, True),
                      "two_sided": _BOOL,
                      "vertices": _Check(lambda v: isinstance(v, list) and 3 <= len(v) <= 32
                                         and all(_POINT.ok(x) for x in v),
                                         "a list of 3 to 32 points, each " + _POINT.phrase)}


def _check_keys(where, table, allowed):
    if not isinstance(table, dict):
        raise ValueError(f"{where} must be a table/object; got {type(table).__name__}")
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise ValueError(f"{where}: unknown key {describe(unknown[0])}; allowed: {', '.join(sorted(allowed))}")
