"""Punctual lights: directional, point and spot, in the units of glTF's
``KHR_lights_punctual`` extension.

Units (Khronos, ``KHR_lights_punctual`` specification, "Light Types"):

- directional: ``intensity`` is an illuminance in lux (lm / m^2), received by
  a surface facing the light;
- point and spot: ``intensity`` is a luminous intensity in candela (lm / sr),
  so that the illuminance at distance d facing the light is intensity / d^2.

pbrkit takes the environment's radiance in the same photometric scale
(a texel value of 1 is 1 cd / m^2, i.e. 1 lm / (m^2 sr)): a surface of BRDF f
lit by illuminance E (lux) at cosine n.l reflects the luminance f E (n.l).
No 683 lm / W conversion is applied anywhere; the exposure of the output
(``--exposure``) scales both together.

A light's ``color`` is a linear RGB multiplier (Rec.709 primaries), as in
glTF.  ``direction`` is the direction the light *travels* (for glTF lights:
the node's -Z axis).  ``range`` (point and spot) ends the light's influence
with the window of :func:`window_ue4`; None is infinite.

Distance falloff, selectable per light with ``falloff``:

- ``"khr"`` (default): the inverse square law with the smooth window that
  ``KHR_lights_punctual`` recommends (its "Range Property" implementation
  note): window(d) / d^2.
- ``"ue4"``: the falloff of Unreal Engine 4 exactly as published (Karis 2013,
  "Real Shading in Unreal Engine 4", eq. 9):
  saturate(1 - (d / r)^4)^2 / (d^2 + 1); the "+ 1" (in UE4's centimetre units)
  keeps it finite at the light.

Spot cone (``KHR_lights_punctual``, "Spot" implementation note): with
cd = cos of the angle between the spot axis and the direction to the point,
attenuation = saturate(cd * s + o)^2, s = 1 / max(0.001, cos(inner) - cos(outer)),
o = -cos(outer) * s; angles in radians, 0 <= inner < outer <= pi / 2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core import checks
from ..core.jit import dual_use, select

__all__ = [
    "LIGHT_TYPES",
    "FALLOFFS",
    "Light",
    "checked_emission",
    "window_ue4",
    "falloff_khr",
    "falloff_ue4",
    "spot_attenuation",
    "light_arrays",
    "light_incidence",
]

LIGHT_TYPES = ("directional", "point", "spot")
FALLOFFS = ("khr", "ue4")
_TYPE_CODE = {"directional": 0, "point": 1, "spot": 2}
_FALLOFF_CODE = {"khr": 0, "ue4": 1}
#: Smallest distance used in 1 / d^2 (metres): keeps a light placed on a surface finite.
MIN_DISTANCE = 1e-4


@dual_use
def window_ue4(distance, light_range):
    """Smooth range window saturate(1 - (d / range)^4)^2 (Karis 2013, eq. 9;
    recommended by ``KHR_lights_punctual`` for its ``range``).  A range <= 0
    means infinite (window 1)."""
    ratio = distance / select(light_range > 0.0, light_range, 1.0)
    r2 = ratio * ratio
    w = np.minimum(np.maximum(1.0 - r2 * r2, 0.0), 1.0)
    return select(light_range > 0.0, w * w, 1.0)


@dual_use
def falloff_khr(distance, light_range):
    """Windowed inverse square law window(d) / d^2 (``KHR_lights_punctual``,
    "Range Property"; the window of :func:`window_ue4`)."""
    d = np.maximum(distance, MIN_DISTANCE)
    return window_ue4(distance, light_range) / (d * d)


@dual_use
def falloff_ue4(distance, light_range):
    """UE4's falloff saturate(1 - (d / r)^4)^2 / (d^2 + 1) (Karis 2013, eq. 9)."""
    return window_ue4(distance, light_range) / (distance * distance + 1.0)


@dual_use
def spot_attenuation(cos_angle, cos_inner, cos_outer):
    """Smooth spot-cone attenuation saturate(cd s + o)^2 with
    s = 1 / max(0.001, cos_inner - cos_outer), o = -cos_outer s
    (``KHR_lights_punctual``, spot implementation note)."""
    s = 1.0 / np.maximum(0.001, cos_inner - cos_outer)
    a = np.minimum(np.maximum(cos_angle * s - cos_outer * s, 0.0), 1.0)
    return a * a


def _is_number(value):
    """A real number (Python's or NumPy's), not a bool or a string."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def checked_emission(color, intensity):
    """A light's (color as a tuple of 3 non-negative floats, intensity as a finite
    float >= 0), or ValueError naming the one that is not (punctual and area lights):
    numbers only (not bools or strings, which ``float`` would take), and their
    product ``color * intensity`` (what the kernels use) finite and not rounded to
    zero where neither factor is zero."""
    if isinstance(color, (str, bytes)) or not all(_is_number(x) for x in np.ravel(np.asarray(color, dtype=object))):
        raise ValueError(f"light color must be 3 finite numbers; got {str(color)[:60]}")
    c = checks.vector(color, "light color")
    if np.any(c < 0.0):
        raise ValueError(f"light color must be non-negative; got {str(color)[:60]}")
    if not _is_number(intensity):
        raise ValueError(f"light intensity must be a finite number >= 0; got {str(intensity)[:60]}")
    try:
        value = float(intensity)
    except OverflowError:  # an integer beyond the float range
        value = math.inf
    if not np.isfinite(value) or value < 0.0:
        raise ValueError(f"light intensity must be finite and >= 0; got {str(intensity)[:60]}")
    with np.errstate(over="ignore", under="ignore"):
        product = c * value
    if not np.all(np.isfinite(product)):
        raise ValueError(f"light color * intensity overflows ({value:.3g} times {float(np.max(c)):.3g})")
    if np.any((c > 0.0) & (value > 0.0) & (product < np.finfo(np.float64).tiny)):  # zero or subnormal
        raise ValueError(f"light color * intensity rounds to zero ({value:.3g} times {float(np.min(c[c > 0])):.3g})"
                         "; expected a light that emits (or intensity 0 for none)")
    return tuple(float(x) for x in c), value


@dataclass(frozen=True)
class Light:
    """A punctual light (see the module docstring for units and conventions)."""

    type: str
    color: tuple = (1.0, 1.0, 1.0)
    intensity: float = 1.0
    position: tuple = (0.0, 0.0, 0.0)
    direction: tuple = (0.0, 0.0, -1.0)
    range: float | None = None
    inner_cone_angle: float = 0.0
    outer_cone_angle: float = np.pi / 4.0
    falloff: str = "khr"

    def __post_init__(self):
        set_ = object.__setattr__
        if not isinstance(self.type, str) or self.type not in LIGHT_TYPES:
            raise ValueError(f"unknown light type {str(self.type)[:40]!r}; choose one of {', '.join(LIGHT_TYPES)}")
        if not isinstance(self.falloff, str) or self.falloff not in FALLOFFS:
            raise ValueError(f"unknown light falloff {str(self.falloff)[:40]!r}; choose one of {', '.join(FALLOFFS)}")
        color, intensity = checked_emission(self.color, self.intensity)
        set_(self, "color", color)
        set_(self, "intensity", intensity)
        set_(self, "position", tuple(checks.vector(self.position, "light position")))
        set_(self, "direction", tuple(checks.vector(self.direction, "light direction", unit=True)))
        if self.range is not None:
            r = float(self.range) if _is_number(self.range) and abs(self.range) < 1e308 else math.nan
            if not np.isfinite(r) or r <= 0.0:
                raise ValueError(f"light range must be a positive number; got {self.range!r}")
            set_(self, "range", r)
        inner, outer = (float(a) if _is_number(a) and abs(a) < 10.0 else math.nan
                        for a in (self.inner_cone_angle, self.outer_cone_angle))
        if not (0.0 <= inner < outer <= np.pi / 2.0):
            raise ValueError("spot cone angles must satisfy 0 <= inner_cone_angle < outer_cone_angle <= pi/2 "
                             f"(radians); got inner {inner!r}, outer {outer!r}")
        set_(self, "inner_cone_angle", inner)
        set_(self, "outer_cone_angle", outer)


def light_arrays(lights):
    """Pack lights for the compiled kernels: ``(codes (L, 2) int64 [type, falloff],
    values (L, 13) float64 [color * intensity (3), position (3), direction (3),
    range (0 = infinite), cos inner, cos outer, unused])``."""
    codes = np.zeros((len(lights), 2), dtype=np.int64)
    values = np.zeros((len(lights), 13), dtype=np.float64)
    for i, light in enumerate(lights):
        codes[i] = (_TYPE_CODE[light.type], _FALLOFF_CODE[light.falloff])
        values[i, 0:3] = np.asarray(light.color) * light.intensity
        values[i, 3:6] = light.position
        values[i, 6:9] = light.direction
        values[i, 9] = 0.0 if light.range is None else light.range
        values[i, 10] = np.cos(light.inner_cone_angle)
        values[i, 11] = np.cos(light.outer_cone_angle)
    return codes, values


@dual_use
def light_incidence(code_type, code_falloff, values, px, py, pz):
    """Scalars only (inside compiled kernels).  For a light (one row of
    :func:`light_arrays`) seen from point p: the unit
    direction (lx, ly, lz) from p toward the light, the distance to it (inf for
    directional lights) and the scalar factor by which ``values[0:3]``
    (color * intensity) is multiplied to give the illuminance on a surface
    facing the light (falloff and spot cone).  Returns (lx, ly, lz, distance, factor)."""
    if code_type == 0:
        return -values[6], -values[7], -values[8], np.inf, 1.0
    dx = values[3] - px
    dy = values[4] - py
    dz = values[5] - pz
    d = np.sqrt(dx * dx + dy * dy + dz * dz)
    inv = 1.0 / max(d, 1e-300)
    lx = dx * inv
    ly = dy * inv
    lz = dz * inv
    if code_falloff == 0:
        factor = falloff_khr(d, values[9])
    else:
        factor = falloff_ue4(d, values[9])
    if code_type == 2:
        cd = -(lx * values[6] + ly * values[7] + lz * values[8])
        factor = factor * spot_attenuation(cd, values[10], values[11])
    return lx, ly, lz, d, factor
