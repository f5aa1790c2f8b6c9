"""Rectangular lights for scoring and fitting LTC tables: their geometry and
the test sets.

Frame (``docs/CONVENTIONS.md``): every function of the LTC scoring modules
works in the *local shading frame* of the shading point, which sits at the
origin with normal n = +z and view v = (sin theta_v, 0, cos theta_v) (so v is
in the xz-plane with t.v >= 0, mu = n.v = cos theta_v).  A rectangular light
is given by its four corners ``(..., 4, 3)`` in that frame, in three.js's
order (``RE_Direct_RectArea_Physical``: centre + w - h, centre - w - h,
centre - w + h, centre + w + h for half-width w and half-height h):
counter-clockwise as seen from the lit side, which is the side
cross(c1 - c0, c3 - c0) points to.  Lights are one-sided (``CONVENTIONS.md``,
Area lights): a shading point behind the light's plane receives nothing, in
the reference as in the shader.  Radiance is 1 and the quantity is the
reflected radiance L_o = integral over the light of f_r(v, l) (n.l) dl.

- :func:`rect_corners`, :func:`check_lights`: corners and the checks every
  scoring function makes;
- :class:`RectLights`, :func:`rect_lights_towards`: a set of lights and how one
  is built from directions, distances and angular sizes;
- :func:`random_rect_lights`: the random test sets (:data:`TEST_SET`);
- :data:`TUNING_SET` / :data:`REPORT_SET` and :func:`test_set`: the two mixed
  sets (lights with a normal reflectance f0 each) LTC tables are chosen on and
  reported on, kept apart (independent seeds and distributions).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["TEST_SET", "TUNING_SET", "REPORT_SET", "RectLights", "rect_corners", "check_lights",
           "random_rect_lights", "rect_lights_towards", "test_set"]


def rect_corners(centre, half_width, half_height):
    """Corners (..., 4, 3) of rectangles in three.js's order
    (``RE_Direct_RectArea_Physical``): centre + w - h, centre - w - h,
    centre - w + h, centre + w + h.  The lit side is the one
    cross(c1 - c0, c3 - c0) = -4 w x h points to (three.js: "light shines in
    local neg z direction" for w along +x and h along +y)."""
    c = np.asarray(centre, dtype=float)[..., None, :]
    w = np.asarray(half_width, dtype=float)[..., None, :]
    h = np.asarray(half_height, dtype=float)[..., None, :]
    signs_w = np.array([1.0, -1.0, -1.0, 1.0])[:, None]
    signs_h = np.array([-1.0, -1.0, 1.0, 1.0])[:, None]
    return c + signs_w * w + signs_h * h


def check_lights(nov, roughness, corners):
    """Check and broadcast lights' (n.v, roughness) (...) and ``corners`` (..., 4, 3):
    -> (nov, roughness, corners, shape), or a one-line ValueError."""
    corners = np.asarray(corners, dtype=float)
    if corners.shape[-2:] != (4, 3):
        raise ValueError(f"corners must have shape (..., 4, 3); got {corners.shape}")
    shape = corners.shape[:-2]
    nov = np.broadcast_to(np.asarray(nov, dtype=float), shape)
    roughness = np.broadcast_to(np.asarray(roughness, dtype=float), shape)
    if not (np.all(np.isfinite(corners)) and np.all(np.isfinite(nov)) and np.all(np.isfinite(roughness))):
        raise ValueError("n.v, roughness and corners must be finite")
    if np.any((nov <= 0.0) | (nov > 1.0)):
        raise ValueError("n.v values must be in (0, 1]")
    if np.any((roughness < 0.0) | (roughness > 1.0)):
        raise ValueError("roughness values must be in [0, 1]")
    return nov, roughness, corners, shape


@dataclass(frozen=True)
class RectLights:
    """A set of rectangular lights in the local shading frame (module doc), one
    per (n.v, roughness) pair: ``corners`` (K, 4, 3) in three.js's order, and
    how they were drawn: the unit direction to the centre (K, 3), the
    distance to the centre (K,), the half-width and half-height (K, 2), the
    light's unit emission normal (K, 3), and whether the light crosses the
    horizon (K,)."""

    nov: np.ndarray
    roughness: np.ndarray
    corners: np.ndarray
    centre_direction: np.ndarray
    distance: np.ndarray
    half_size: np.ndarray
    normal: np.ndarray
    crossing: np.ndarray

    def __len__(self):
        return self.nov.shape[0]

    def subset(self, index):
        """The lights at ``index`` (an index array or a boolean mask)."""
        return RectLights(*(getattr(self, name)[index] for name in self.__dataclass_fields__))


#: The test set's parameters (:func:`random_rect_lights`).
TEST_SET = {
    "roughness": (0.1, 1.0),
    "nov": (0.05, 1.0),
    "crossing_share": 0.15,
    "distance": (1.0, 4.0),
    "angular_half_size": (0.1, 0.8),
    "tilt_max": math.radians(45.0),
}

#: The set LTC defaults are chosen on (``pbrkit ltc``'s default fit options,
#: :data:`pbrkit.ltc.fit.FIT_F0`): 400 lights of :data:`TEST_SET` (seed 0, the
#: lights of issue 11's figures), half of them seen with a dielectric's normal
#: reflectance f0 = 0.04 and half with a metal's f0 = 1 (alternating).
TUNING_SET = {"count": 400, "seed": 0, "f0": (0.04, 1.0), "ranges": dict(TEST_SET)}
#: The set LTC tables are reported on, apart from the one they are chosen on
#: (another seed and other ranges): 600 lights with f0 = 0.04, 0.5 and 1 (a third
#: each), roughness from 0.08 to 1 (smooth and rough lobes), views to n.v = 0.02,
#: a quarter of the lights straddling the horizon, angular half-sizes from 0.03
#: to 1 rad (small and large lights), at 0.5 to 8 from the shading point and
#: tilted by up to 60 degrees.
REPORT_SET = {"count": 600, "seed": 2026, "f0": (0.04, 0.5, 1.0),
              "ranges": {"roughness": (0.08, 1.0), "nov": (0.02, 1.0), "crossing_share": 0.25,
                         "distance": (0.5, 8.0), "angular_half_size": (0.03, 1.0),
                         "tilt_max": math.radians(60.0)}}


def random_rect_lights(count=400, seed=0, **overrides):
    """``count`` rectangular lights with their (n.v, roughness), drawn
    deterministically from ``seed`` (NumPy's PCG64, ``numpy.random.default_rng``;
    the same seed gives the same set), the test set of issue 11.  Per light,
    in this order of draws (:data:`TEST_SET` holds the ranges; ``overrides``
    replace them by name):

    - roughness r uniform in [0.1, 1] (alpha = r^2);
    - n.v = cos theta_v uniform in [0.05, 1];
    - the angular half-sizes (a_w, a_h), each uniform in [0.1, 0.8] rad; the
      distance d from the shading point to the light's centre uniform in
      [1, 4]; the half-width and half-height are d tan(a_w), d tan(a_h);
    - the direction to the centre: azimuth phi uniform in [0, 2 pi) (v is at
      phi = 0), and with probability 0.85 an elevation above the horizon with
      sin(elevation) uniform in [sin(a_max), 1] for a_max = max(a_w, a_h) (uniform
      in solid angle over that cap), else (15% of the lights, the
      ``crossing_share``) an elevation uniform in [-a_min, a_min] for
      a_min = min(a_w, a_h), so that the light straddles the horizon;
    - the orientation: the emission normal is the direction back to the
      shading point tilted by an angle uniform in [0, 45 deg] toward an
      azimuth uniform in [0, 2 pi) about it, and the rectangle's width axis
      is at an angle uniform in [0, 2 pi) about the normal.

    ``crossing`` records whether the corners end up on both sides of the
    horizon (geometry, not the draw).  Returns :class:`RectLights`."""
    params = dict(TEST_SET)
    for key, value in overrides.items():
        if key not in params:
            raise ValueError(f"unknown test-set parameter {key!r}; choose from {', '.join(params)}")
        params[key] = value
    rng = np.random.default_rng(seed)
    k = int(count)
    r = rng.uniform(*params["roughness"], size=k)
    nov = rng.uniform(*params["nov"], size=k)
    half_angle = rng.uniform(*params["angular_half_size"], size=(k, 2))
    distance = rng.uniform(*params["distance"], size=k)
    phi = rng.uniform(0.0, 2.0 * math.pi, size=k)
    cap = rng.random(k) >= params["crossing_share"]
    a_max = half_angle.max(axis=1)
    a_min = half_angle.min(axis=1)
    sin_el_cap = rng.uniform(np.sin(a_max), 1.0)
    el_cross = rng.uniform(-a_min, a_min)
    elevation = np.where(cap, np.arcsin(sin_el_cap), el_cross)
    tilt = rng.uniform(0.0, params["tilt_max"], size=k)
    tilt_phi = rng.uniform(0.0, 2.0 * math.pi, size=k)
    spin = rng.uniform(0.0, 2.0 * math.pi, size=k)

    direction = np.stack([np.cos(elevation) * np.cos(phi), np.cos(elevation) * np.sin(phi), np.sin(elevation)], -1)
    return rect_lights_towards(nov, r, direction, distance, half_angle, tilt, tilt_phi, spin)


def rect_lights_towards(nov, roughness, direction, distance, half_angle, tilt, tilt_phi, spin):
    """Rectangular lights (:class:`RectLights`) centred at ``distance`` (K,) along the
    unit ``direction`` (K, 3), with angular half-sizes ``half_angle`` (K, 2) (half-width
    and half-height d tan(a)), the emission normal the direction back to the shading
    point tilted by ``tilt`` toward the azimuth ``tilt_phi`` about it, and the width
    axis at the angle ``spin`` about the normal (the construction of
    :func:`random_rect_lights`)."""
    k = direction.shape[0]
    nov = np.broadcast_to(np.asarray(nov, dtype=float), (k,))
    r = np.broadcast_to(np.asarray(roughness, dtype=float), (k,))
    # a frame (e1, e2, -direction) about the direction back to the shading point
    back = -direction
    helper = np.where(np.abs(back[:, 2:3]) < 0.9, np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]))
    e1 = np.cross(helper, back)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(back, e1)
    normal = (np.cos(tilt)[:, None] * back
              + np.sin(tilt)[:, None] * (np.cos(tilt_phi)[:, None] * e1 + np.sin(tilt_phi)[:, None] * e2))
    f1 = np.cross(helper, normal)
    f1 /= np.linalg.norm(f1, axis=1, keepdims=True)
    f2 = np.cross(normal, f1)
    width_axis = np.cos(spin)[:, None] * f1 + np.sin(spin)[:, None] * f2
    height_axis = np.cross(width_axis, normal)  # emission normal = height x width (three.js winding)
    half_size = distance[:, None] * np.tan(half_angle)
    centre = distance[:, None] * direction
    corners = rect_corners(centre, half_size[:, :1] * width_axis, half_size[:, 1:] * height_axis)
    z = corners[..., 2]
    crossing = (z.min(axis=1) < 0.0) & (z.max(axis=1) > 0.0)
    return RectLights(nov, r, corners, direction, distance, half_size, normal, crossing)


def test_set(spec):
    """The lights of a mixed test set ``spec`` (:data:`TUNING_SET`, :data:`REPORT_SET`
    or a dict of the same keys) and each light's normal reflectance f0 (K,), the
    values of ``spec["f0"]`` in turn (light k takes the (k mod n)-th; the lights are
    drawn independently, so each value gets an equal share of the same
    distribution): (:class:`RectLights`, f0)."""
    lights = random_rect_lights(spec["count"], spec["seed"], **spec["ranges"])
    f0 = np.asarray(spec["f0"], dtype=float)
    return lights, f0[np.arange(len(lights)) % f0.size]
