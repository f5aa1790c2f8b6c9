"""Checks of an area light's shape and emission (:class:`pbrkit.rendering.area_lights.AreaLight`):
a polygon light is a simple convex planar polygon, and the radiance its
``color``, ``intensity`` and ``unit`` give is a usable number.

Polygon lights (:func:`polygon_vertices`).  The real-time path integrates a
polygon's edges (Heitz et al. 2016) and the reference renderer tests a hit
against each edge's half-plane: both assume a *convex* polygon traversed once.
A self-intersecting one (a five-pointed star, vertices 0, 2, 4, 1, 3 of a
pentagon) has every turn in the same direction, so a per-vertex sign test
passes it, yet its edge integral counts the core twice: real time and ground
truth then disagree (by 1.95x for a star where a convex pentagon agrees
within 5%).  So the test is the polygon's total turning: the signed exterior
angle at vertex i, turn_i = atan2((e_{i-1} x e_i) . n, e_{i-1} . e_i) with
e_i = v_{i+1} - v_i and n the Newell normal, must be >= 0 at every vertex and
the turns must sum to 2 pi.  The tangent of a simple closed curve turns by
+-2 pi in all (Hopf's Umlaufsatz: H. Hopf, "Über die Drehung der Tangenten und
Sehnen ebener Kurven", Compositio Mathematica 2, 1935, pp. 50-62), and a
closed polygon whose exterior angles all have one sign is convex exactly when
they sum to 2 pi, once around; a star turns 4 pi, twice around (Schorn and
Fisher, "Testing the Convexity of a Polygon", Graphics Gems IV, 1994,
pp. 7-15, who reject such polygons the same way).  Before it: 3 to
:data:`MAX_POLYGON_VERTICES` finite points, no two of them equal (a repeated
vertex makes an edge of no direction), a non-zero area and a plane
(:data:`PLANARITY_TOLERANCE`).

Emission (:func:`checked_radiance`): the radiance must be finite (a power
over a tiny area overflows), at most :data:`MAX_RADIANCE`, and not round to
zero (or to a subnormal number) where ``color * intensity`` is not zero (a
tiny power over a large area underflows): either would render something other than what the file asks for.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["MAX_POLYGON_VERTICES", "PLANARITY_TOLERANCE", "MAX_RADIANCE", "newell_normal", "polygon_vertices",
           "checked_radiance"]

#: Most vertices of a polygon light.
MAX_POLYGON_VERTICES = 32
#: Relative tolerance of a polygon light's planarity (distance / size).
PLANARITY_TOLERANCE = 1e-6
#: Largest emitted radiance of an area light, cd / m^2: the scene files' largest
#: intensity or radiance (:data:`pbrkit.rendering.scene.MAX_INTENSITY`; the sun's
#: luminance is about 1.6e9 cd / m^2).
MAX_RADIANCE = 1e12
#: Tolerance of the turning test, radians: a turn below -this is concave, a total
#: more than this from 2 pi is not once around.
_TURN_TOLERANCE = 1e-9
_TOTAL_TOLERANCE = 1e-6
#: The smallest normal double: below it a radiance has lost its precision, or is zero.
_TINY = float(np.finfo(np.float64).tiny)
#: Shortest edge (relative to the polygon's size): shorter is a repeated vertex.
_EDGE_TOLERANCE = 1e-9


def newell_normal(v, raw=False):
    """Newell's normal of a polygon (K, 3): twice its vector area (``raw``) or unit."""
    n = np.zeros(3)
    k = v.shape[0]
    for i in range(k):
        n += np.cross(v[i], v[(i + 1) % k])
    return n if raw else n / np.linalg.norm(n)


def _turns(v, n):
    """Signed exterior angles (K,) of the polygon v (K, 3) about its unit normal n."""
    e = np.roll(v, -1, axis=0) - v  # e_i = v_{i+1} - v_i
    prev = np.roll(e, 1, axis=0)    # e_{i-1}
    return np.arctan2(np.cross(prev, e) @ n, np.einsum("ij,ij->i", prev, e))


def polygon_vertices(vertices):
    """``vertices`` as a float64 array (K, 3) of a simple convex planar polygon,
    counter-clockwise seen from the lit side (module docstring), else ValueError
    saying which property fails."""
    try:
        v = np.asarray(vertices, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise ValueError("polygon light vertices must be a list of [x, y, z] points") from None
    if v.ndim != 2 or v.shape[1] != 3 or not 3 <= v.shape[0] <= MAX_POLYGON_VERTICES:
        raise ValueError(f"a polygon light needs 3 to {MAX_POLYGON_VERTICES} vertices of 3 numbers; "
                         f"got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError("polygon light vertices must be finite")
    k = v.shape[0]
    size = float(np.max(np.ptp(v, axis=0)))
    for i in range(k):
        for j in range(i + 1, k):
            if np.max(np.abs(v[i] - v[j])) <= _EDGE_TOLERANCE * size:
                raise ValueError(f"polygon light has repeated vertices (vertices[{i}] and vertices[{j}] are "
                                 "the same point)" if size > 0.0 else "polygon light has zero area (all its "
                                 "vertices are the same point)")
    n = newell_normal(v, raw=True)
    length = float(np.linalg.norm(n))
    if not length > 1e-12 * size ** 2:
        raise ValueError("polygon light has zero area (collinear or repeated vertices)")
    n = n / length
    if np.max(np.abs((v - v.mean(axis=0)) @ n)) > PLANARITY_TOLERANCE * size:
        raise ValueError("polygon light vertices must lie in one plane")
    turns = _turns(v, n)
    if np.any(np.abs(turns) > math.pi - _TURN_TOLERANCE):  # a turn of +-pi: an edge runs back along the last
        i = int(np.argmax(np.abs(turns)))
        raise ValueError(f"polygon light must be convex: its outline doubles back at vertices[{i}]")
    if np.any(turns < -_TURN_TOLERANCE):
        i = int(np.argmin(turns))
        raise ValueError(f"polygon light must be convex, its vertices counter-clockwise seen from the lit side "
                         f"(it turns the other way at vertices[{i}])")
    total = float(np.sum(turns))
    if abs(total - 2.0 * math.pi) > _TOTAL_TOLERANCE:
        raise ValueError(f"polygon light must be a simple convex polygon: its edges cross (its turning angles sum "
                         f"to {total / math.pi:.3g} pi, as a star's; a convex polygon's sum to 2 pi)")
    return v


def checked_radiance(emission, radiance, unit, area):
    """The radiance (3 floats) of an area light whose ``color * intensity`` is
    ``emission`` (3), if usable (module docstring), else ValueError naming
    ``intensity`` with its unit and the light's ``area``."""
    emission = np.asarray(emission, dtype=np.float64)
    radiance = np.asarray(radiance, dtype=np.float64)
    how = (f"intensity (unit {unit}) over an area of {area:.3g} m^2" if unit == "power"
           else "color * intensity (unit radiance)")
    if not np.all(np.isfinite(radiance)):
        raise ValueError(f"{how} gives a radiance that is not finite (it overflows); expected a radiance of at "
                         f"most {MAX_RADIANCE:g} cd / m^2")
    if np.any(radiance > MAX_RADIANCE):
        raise ValueError(f"{how} gives a radiance of {float(np.max(radiance)):.3g} cd / m^2, more than "
                         f"{MAX_RADIANCE:g} (the sun's is about 1.6e9)")
    if np.any((emission > 0.0) & (radiance < _TINY)):
        raise ValueError(f"{how} gives a radiance that rounds to zero (below {_TINY:.3g}, the smallest normal "
                         "double); expected a light that emits (or intensity 0 for none)")
    return tuple(float(x) for x in radiance)
