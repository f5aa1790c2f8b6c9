"""Area lights: rectangles, convex polygons, disks and spheres of constant
radiance, shaded by Linearly Transformed Cosines in real time and sampled
exactly by the reference renderer.

Shapes (scene files: ``[[lights]]`` with ``type`` = ``rect``, ``polygon``,
``disk`` or ``sphere``; lengths in metres):

- ``rect``: centred at ``position``, emitting towards ``normal``; its
  ``height`` edge runs along ``up`` (projected onto the light's plane; default
  +Y, or +Z when the normal is along Y) and its ``width`` edge along
  up x normal, so the corners c -+ w/2 -+ h/2 run counter-clockwise seen from
  the lit side (as three.js's ``RectAreaLight`` faces its -Z).
- ``polygon``: 3 to :data:`MAX_POLYGON_VERTICES` ``vertices``, planar, simple
  and convex, counter-clockwise seen from the lit side (the right-hand rule gives
  the normal; the tests: :mod:`pbrkit.rendering.light_checks`).
- ``disk``: centre ``position``, ``normal``, ``radius``.
- ``sphere``: centre ``position``, ``radius``; emits outwards everywhere.

Planar lights emit from the side their normal points to, or from both sides
with ``two_sided = true``.

Units (``unit``): ``radiance`` (default): ``color * intensity`` is the emitted
luminance in cd / m^2 (the environment's scale, :mod:`pbrkit.rendering.lights`);
``power``: ``intensity`` is the luminous flux in lumens of a Lambertian emitter
(``color`` multiplies it), L = Phi / (pi A) for a one-sided planar light of
area A, Phi / (2 pi A) two-sided, Phi / (4 pi^2 r^2) for a sphere (e.g.
Pharr, Jakob and Humphreys 2023, pbrt-v4 sec. 12.5 ``DiffuseAreaLight``:
L = Phi / (pi A) per side).  A radiance that overflows, exceeds 1e12 cd / m^2 or
rounds to zero from a non-zero power is refused
(:func:`pbrkit.rendering.light_checks.checked_radiance`).

In the reference renderer (:mod:`pbrkit.rendering.reference`) an area light is
an opaque black emitter: camera and BRDF rays that hit it see its radiance
(front side, or both when two-sided; its back is black), it blocks the
environment and the other area lights behind it, and its surface reflects
nothing.  Punctual lights' shadow rays pass through it.  With
``occlusion=False`` (the like-for-like comparison with real-time shading)
nothing is shadowed and the lights do not hide the environment: real-time
shading adds the two.  The direct light from area lights is estimated at
every path vertex by light sampling (one light picked uniformly, then a
direction: :func:`area_light_sample`) and BRDF sampling, combined with the
power heuristic (Veach 1997, sec. 9.2.4).

Real-time shading (:func:`area_light_ltc`) integrates each light's polygon
against pbrkit's own LTC table (fitted with the exact horizon clipping,
:mod:`pbrkit.ltc`, bundled as :func:`bundled_ltc_table`) for the specular
lobe and against the clamped cosine (the exact polygon form factor) for the
diffuse one, clipped at the true horizon (Heitz, Dupuy, Hill and Neubelt
2016, sec. 3-5).  Disks and spheres are integrated as regular polygons of
:data:`DISK_POLYGON_SIDES` sides with the disk's area (a sphere as the disk
that subtends its cone); without shadows, as in engines.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

import numpy as np

from ..core import checks
from ..core.filtering import CLAMP_TO_EDGE, texel_pair
from ..core.jit import dual_use, row_kernel
from ..core.vec import orthonormal_basis_xyz
from ..ltc.polygon import polygon_form_factor, transformed_polygon_form_factor
from ..sampling.spherical import (
    MIN_SOLID_ANGLE,
    area_solid_angle_pdf,
    disk_solid_angle_pdf,
    rectangle_solid_angle,
    sample_disk_area,
    sample_sphere_cone,
    sample_spherical_rectangle,
    sample_spherical_triangle,
    sphere_cone_pdf,
    triangle_solid_angle,
)
from .light_checks import MAX_POLYGON_VERTICES, checked_radiance, polygon_vertices
from .light_checks import newell_normal as _newell_normal
from .lights import checked_emission
from .primitives import _ray_sphere

__all__ = [
    "AREA_LIGHT_TYPES",
    "AREA_UNITS",
    "MAX_POLYGON_VERTICES",
    "DISK_POLYGON_SIDES",
    "AreaLight",
    "AreaLights",
    "area_light_arrays",
    "area_light_hit",
    "area_light_sample",
    "area_light_pdf",
    "area_light_samples",
    "area_light_pdfs",
    "area_light_hits",
    "area_light_polygon",
    "bundled_ltc_table",
    "bundled_fresnel_table",
    "LTCLighting",
    "area_light_ltc",
]

AREA_LIGHT_TYPES = ("rect", "polygon", "disk", "sphere")
AREA_UNITS = ("radiance", "power")
_TYPE_CODE = {"rect": 0, "polygon": 1, "disk": 2, "sphere": 3}
RECT, POLYGON, DISK, SPHERE = 0, 1, 2, 3
#: Sides of the regular polygon a disk or sphere light is integrated as in real time:
#: its form factor is within 2e-5 (median), 1.7e-4 (95th percentile) and 1.1e-3
#: (largest) of the disk's over 300 random placements, horizon crossings included.
DISK_POLYGON_SIDES = 16
_INF = np.inf


def _unit(v, name):
    return checks.vector(v, name, unit=True)


def _default_up(normal):
    """+Y, or +Z when the normal is (nearly) along Y."""
    return np.array([0.0, 0.0, 1.0]) if abs(normal[1]) > 0.999 else np.array([0.0, 1.0, 0.0])


@dataclass(frozen=True)
class AreaLight:
    """An area light (module docstring for shapes, sides and units)."""

    type: str
    color: tuple = (1.0, 1.0, 1.0)
    intensity: float = 1.0
    unit: str = "radiance"
    position: tuple = (0.0, 0.0, 0.0)
    normal: tuple = (0.0, -1.0, 0.0)
    up: tuple | None = None
    width: float = 1.0
    height: float = 1.0
    radius: float = 0.5
    vertices: tuple = ()
    two_sided: bool = False

    def __post_init__(self):
        set_ = object.__setattr__
        if self.type not in AREA_LIGHT_TYPES:
            raise ValueError(f"unknown area light type {self.type!r}; choose one of {', '.join(AREA_LIGHT_TYPES)}")
        if self.unit not in AREA_UNITS:
            raise ValueError(f"unknown light unit {self.unit!r}; choose one of {', '.join(AREA_UNITS)}")
        color, intensity = checked_emission(self.color, self.intensity)
        set_(self, "color", color)
        set_(self, "intensity", intensity)
        set_(self, "two_sided", bool(self.two_sided))
        set_(self, "position", tuple(checks.vector(self.position, "light position")))
        if self.type == "sphere" and self.two_sided:
            raise ValueError("a sphere light has no sides: two_sided applies to rect, polygon and disk lights")
        for name in ("width", "height", "radius"):
            value = float(getattr(self, name))
            if not np.isfinite(value) or value <= 0.0:
                raise ValueError(f"light {name} must be a positive number; got {getattr(self, name)!r}")
            set_(self, name, value)
        if self.type == "polygon":
            set_(self, "vertices", tuple(tuple(v) for v in self._polygon_vertices()))
            set_(self, "normal", tuple(_newell_normal(np.asarray(self.vertices))))
        else:
            if self.vertices:
                raise ValueError(f"vertices apply to polygon lights only (this is a {self.type} light)")
            set_(self, "normal", tuple(_unit(self.normal, "light normal")))
        if self.up is not None:
            if self.type != "rect":
                raise ValueError(f"up applies to rect lights only (this is a {self.type} light)")
            up = _unit(self.up, "light up")
            if abs(float(np.dot(up, self.normal))) > 0.999:
                raise ValueError("light up must not be parallel to its normal")
            set_(self, "up", tuple(up))
        with np.errstate(all="ignore"):  # overflow and underflow are refused below, with the figures
            radiance = self.radiance
        checked_radiance(np.asarray(self.color) * self.intensity, radiance, self.unit, self.area)

    def _polygon_vertices(self):
        """The vertices of a simple convex planar polygon (:func:`pbrkit.rendering.light_checks.polygon_vertices`)."""
        return polygon_vertices(self.vertices)

    # ------------------------------------------------------------ derived

    @property
    def edges(self):
        """(corner c0, edge vectors e1 (width), e2 (height)) of a rect light:
        corners c0, c0 + e1, c0 + e1 + e2, c0 + e2, counter-clockwise from the lit side."""
        n = np.asarray(self.normal)
        up = np.asarray(self.up) if self.up is not None else _default_up(n)
        up = up - np.dot(up, n) * n
        up /= np.linalg.norm(up)
        right = np.cross(up, n)
        e1 = right * self.width
        e2 = up * self.height
        return np.asarray(self.position) - 0.5 * (e1 + e2), e1, e2

    @property
    def area(self):
        """Emitting surface area (one side), m^2."""
        if self.type == "rect":
            return self.width * self.height
        if self.type == "disk":
            return math.pi * self.radius * self.radius
        if self.type == "sphere":
            return 4.0 * math.pi * self.radius * self.radius
        v = np.asarray(self.vertices)
        return 0.5 * float(np.linalg.norm(_newell_normal(v, raw=True)))

    @property
    def radiance(self):
        """Emitted radiance (RGB, cd / m^2) of the module docstring's units."""
        value = np.asarray(self.color) * self.intensity
        if self.unit == "power":
            sides = 2.0 if self.two_sided else 1.0
            value = value / (math.pi * self.area * sides)
        return tuple(float(x) for x in value)


# --------------------------------------------------------------- packing


@dataclass(frozen=True)
class AreaLights:
    """Area lights packed for the compiled kernels: ``codes`` (A, 4) int64 [type,
    two-sided, first vertex, vertex count], ``values`` (A, 16) float64 [radiance
    (3), centre (3), unit normal (3), e1 (3), e2 (3), radius], ``vertices`` (V, 3)
    (polygons, and the polygon a disk is integrated as in real time; rects: their
    corner in values and edges e1, e2)."""

    codes: np.ndarray
    values: np.ndarray
    vertices: np.ndarray

    def __len__(self):
        return self.codes.shape[0]

    def arrays(self):
        return self.codes, self.values, self.vertices


def area_light_arrays(lights):
    """Pack :class:`AreaLight` objects into :class:`AreaLights`."""
    codes = np.zeros((len(lights), 4), dtype=np.int64)
    values = np.zeros((len(lights), 16), dtype=np.float64)
    vertices = []
    for i, light in enumerate(lights):
        codes[i, 0] = _TYPE_CODE[light.type]
        codes[i, 1] = int(light.two_sided)
        values[i, 0:3] = light.radiance
        values[i, 3:6] = light.position
        values[i, 6:9] = light.normal
        values[i, 15] = light.radius
        if light.type == "rect":
            corner, e1, e2 = light.edges
            values[i, 3:6] = corner
            values[i, 9:12] = e1
            values[i, 12:15] = e2
        elif light.type in ("polygon", "disk"):  # a disk's vertices: its real-time polygon
            v = area_light_polygon(light)
            codes[i, 2] = sum(len(x) for x in vertices)
            codes[i, 3] = v.shape[0]
            if light.type == "polygon":
                values[i, 3:6] = v.mean(axis=0)
            vertices.append(v)
    verts = np.concatenate(vertices) if vertices else np.zeros((0, 3))
    return AreaLights(codes, values, np.ascontiguousarray(verts, dtype=np.float64))


# ------------------------------------------------------------ ray casting


@dual_use
def _front(values, li, two_sided, px, py, pz):
    """Whether the point p sees the emitting side of planar light li."""
    if two_sided:
        return True
    return ((px - values[li, 3]) * values[li, 6] + (py - values[li, 4]) * values[li, 7]
            + (pz - values[li, 5]) * values[li, 8]) > 0.0


@dual_use
def _plane_t(values, li, ox, oy, oz, dx, dy, dz):
    """Ray parameter where o + t d meets light li's plane (inf if parallel)."""
    den = dx * values[li, 6] + dy * values[li, 7] + dz * values[li, 8]
    if den == 0.0:
        return _INF
    return ((values[li, 3] - ox) * values[li, 6] + (values[li, 4] - oy) * values[li, 7]
            + (values[li, 5] - oz) * values[li, 8]) / den


@dual_use
def _inside_polygon(values, vertices, first, count, li, qx, qy, qz):
    """Whether the point q of the plane of convex polygon light li lies inside it."""
    nx, ny, nz = values[li, 6], values[li, 7], values[li, 8]
    for k in range(count):
        a = vertices[first + k]
        b = vertices[first + (k + 1) % count]
        ex, ey, ez = b[0] - a[0], b[1] - a[1], b[2] - a[2]
        wx, wy, wz = qx - a[0], qy - a[1], qz - a[2]
        cx = ey * wz - ez * wy
        cy = ez * wx - ex * wz
        cz = ex * wy - ey * wx
        if cx * nx + cy * ny + cz * nz < 0.0:
            return False
    return True


@dual_use
def _light_t(codes, values, vertices, li, ox, oy, oz, dx, dy, dz, tmax):
    """Ray parameter of the hit of o + t d (unit d) on light li in (0, tmax), else inf."""
    kind = codes[li, 0]
    if kind == SPHERE:
        t = _ray_sphere(ox, oy, oz, dx, dy, dz, values[li, 3], values[li, 4], values[li, 5], values[li, 15], 0.0)
        return t if t < tmax else _INF
    t = _plane_t(values, li, ox, oy, oz, dx, dy, dz)
    if not (0.0 < t < tmax):
        return _INF
    qx = ox + t * dx
    qy = oy + t * dy
    qz = oz + t * dz
    if kind == RECT:
        rx = qx - values[li, 3]
        ry = qy - values[li, 4]
        rz = qz - values[li, 5]
        e1 = values[li, 9] * values[li, 9] + values[li, 10] * values[li, 10] + values[li, 11] * values[li, 11]
        e2 = values[li, 12] * values[li, 12] + values[li, 13] * values[li, 13] + values[li, 14] * values[li, 14]
        a = (rx * values[li, 9] + ry * values[li, 10] + rz * values[li, 11]) / e1
        b = (rx * values[li, 12] + ry * values[li, 13] + rz * values[li, 14]) / e2
        return t if (0.0 <= a <= 1.0 and 0.0 <= b <= 1.0) else _INF
    if kind == DISK:
        rx = qx - values[li, 3]
        ry = qy - values[li, 4]
        rz = qz - values[li, 5]
        return t if rx * rx + ry * ry + rz * rz <= values[li, 15] * values[li, 15] else _INF
    return t if _inside_polygon(values, vertices, codes[li, 2], codes[li, 3], li, qx, qy, qz) else _INF


@dual_use
def _emitted(codes, values, li, dx, dy, dz):
    """Whether a ray travelling along d that hits light li sees its emitting side."""
    if codes[li, 0] == SPHERE or codes[li, 1]:
        return True
    return dx * values[li, 6] + dy * values[li, 7] + dz * values[li, 8] < 0.0


@dual_use
def area_light_hit(codes, values, vertices, ox, oy, oz, dx, dy, dz, tmax):
    """Nearest area light on the ray o + t d (unit d), 0 < t < tmax.  Returns (t,
    light index or -1, emitted radiance seen along the ray (3): 0 on a one-sided
    light's back)."""
    best = tmax
    hit = -1
    for li in range(codes.shape[0]):
        t = _light_t(codes, values, vertices, li, ox, oy, oz, dx, dy, dz, best)
        if t < best:
            best = t
            hit = li
    if hit < 0:
        return _INF, -1, 0.0, 0.0, 0.0
    if not _emitted(codes, values, hit, dx, dy, dz):
        return best, hit, 0.0, 0.0, 0.0
    return best, hit, values[hit, 0], values[hit, 1], values[hit, 2]


@row_kernel(3)
def _hit_kernel(start, stop, codes, values, vertices, origins, dirs, tmax, out_t, out_index, out_radiance):
    for i in range(start, stop):
        t, k, r0, r1, r2 = area_light_hit(codes, values, vertices, origins[i, 0], origins[i, 1], origins[i, 2],
                                          dirs[i, 0], dirs[i, 1], dirs[i, 2], tmax[i])
        out_t[i] = t
        out_index[i] = k
        out_radiance[i, 0] = r0
        out_radiance[i, 1] = r1
        out_radiance[i, 2] = r2


def area_light_hits(lights, origins, dirs, tmax=None):
    """:func:`area_light_hit` of rays (N, 3) -> (t (N,), index (N,), radiance (N, 3))."""
    origins = np.ascontiguousarray(origins, dtype=np.float64).reshape(-1, 3)
    dirs = np.ascontiguousarray(np.broadcast_to(dirs, origins.shape), dtype=np.float64)
    n = origins.shape[0]
    tmax = np.full(n, np.inf) if tmax is None else np.ascontiguousarray(np.broadcast_to(tmax, (n,)),
                                                                        dtype=np.float64)
    t = np.empty(n)
    index = np.empty(n, dtype=np.int64)
    radiance = np.empty((n, 3))
    _hit_kernel(*lights.arrays(), origins, dirs, tmax, t, index, radiance)
    return t, index, radiance


# ------------------------------------------------------------ sampling


@dual_use
def _polygon_solid_angle(values, vertices, first, count, px, py, pz):
    """Solid angle of convex polygon light (fan of triangles from its first vertex) seen from p."""
    total = 0.0
    ax = vertices[first, 0] - px
    ay = vertices[first, 1] - py
    az = vertices[first, 2] - pz
    for k in range(1, count - 1):
        b = vertices[first + k]
        c = vertices[first + k + 1]
        total += triangle_solid_angle(ax, ay, az, b[0] - px, b[1] - py, b[2] - pz, c[0] - px, c[1] - py,
                                      c[2] - pz)
    return total


@dual_use
def _rect_solid_angle(values, li, px, py, pz):
    return rectangle_solid_angle(px, py, pz, values[li, 3], values[li, 4], values[li, 5], values[li, 9],
                                 values[li, 10], values[li, 11], values[li, 12], values[li, 13], values[li, 14])


@dual_use
def _rect_area(values, li):
    """|e1 x e2| of rect light li."""
    cx = values[li, 10] * values[li, 14] - values[li, 11] * values[li, 13]
    cy = values[li, 11] * values[li, 12] - values[li, 9] * values[li, 14]
    cz = values[li, 9] * values[li, 13] - values[li, 10] * values[li, 12]
    return math.sqrt(cx * cx + cy * cy + cz * cz)


@dual_use
def _polygon_area_point(vertices, first, count, u1, u2):
    """A point uniform by area on a convex polygon (a fan triangle picked in proportion
    to its area with u1, reused, then the square-root map of Turk 1990 / pbrt-v4
    sec. A.5.5 ``SampleUniformTriangle``) and the polygon's area."""
    a = vertices[first]
    total = 0.0
    for k in range(1, count - 1):
        total += _triangle_area(a, vertices[first + k], vertices[first + k + 1])
    target = u1 * total
    acc = 0.0
    k = 1
    part = 0.0
    for k in range(1, count - 1):
        part = _triangle_area(a, vertices[first + k], vertices[first + k + 1])
        if acc + part >= target or k == count - 2:
            break
        acc += part
    u = min(max((target - acc) / part, 0.0), 1.0) if part > 0.0 else 0.5
    b = vertices[first + k]
    c = vertices[first + k + 1]
    s = math.sqrt(u)
    w1 = 1.0 - s
    w2 = u2 * s
    w0 = 1.0 - w1 - w2
    return (w1 * a[0] + w2 * b[0] + w0 * c[0], w1 * a[1] + w2 * b[1] + w0 * c[1], w1 * a[2] + w2 * b[2] + w0 * c[2],
            total)


@dual_use
def _triangle_area(a, b, c):
    ex, ey, ez = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    fx, fy, fz = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    cx = ey * fz - ez * fy
    cy = ez * fx - ex * fz
    cz = ex * fy - ey * fx
    return 0.5 * math.sqrt(cx * cx + cy * cy + cz * cz)


@dual_use
def _towards(values, li, px, py, pz, qx, qy, qz, area):
    """Direction and distance from p to the point q of planar light li drawn by area,
    and its solid-angle pdf (:func:`pbrkit.sampling.spherical.area_solid_angle_pdf`)."""
    dx = qx - px
    dy = qy - py
    dz = qz - pz
    dist = math.sqrt(dx * dx + dy * dy + dz * dz)
    if not dist > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0
    dx /= dist
    dy /= dist
    dz /= dist
    cos_l = abs(dx * values[li, 6] + dy * values[li, 7] + dz * values[li, 8])
    return dx, dy, dz, dist, area_solid_angle_pdf(dist, cos_l, area)


@dual_use
def area_light_sample(codes, values, vertices, li, px, py, pz, u1, u2):
    """A direction towards light li from p, sampled by solid angle where a closed
    form exists: spherical rectangles (Ureña, Fajardo and King 2013), spherical
    triangles of a polygon's fan, picked in proportion to their solid angles
    (Arvo 1995), the cone of a sphere (pbrt-v4 sec. 6.2.3); disks by area
    (concentric map, pdf converted to solid angle), and rects and polygons by
    area too where they subtend less than
    :data:`pbrkit.sampling.spherical.MIN_SOLID_ANGLE` (as pbrt-v4's triangles
    do, sec. 6.5.4), where the spherical parametrisations lose precision.  Returns (lx, ly, lz,
    distance, pdf (solid angle; 0 when p sees no emitting side or the light is
    degenerate from p), radiance (3))."""
    kind = codes[li, 0]
    z = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    if kind == SPHERE:
        lx, ly, lz, dist, pdf = sample_sphere_cone(values[li, 3] - px, values[li, 4] - py, values[li, 5] - pz,
                                                   values[li, 15], u1, u2)
    else:
        if not _front(values, li, codes[li, 1] != 0, px, py, pz):
            return z
        if kind == RECT:
            if _rect_solid_angle(values, li, px, py, pz) < MIN_SOLID_ANGLE:  # tiny: by area
                lx, ly, lz, dist, pdf = _towards(values, li, px, py, pz,
                                                 values[li, 3] + u1 * values[li, 9] + u2 * values[li, 12],
                                                 values[li, 4] + u1 * values[li, 10] + u2 * values[li, 13],
                                                 values[li, 5] + u1 * values[li, 11] + u2 * values[li, 14],
                                                 _rect_area(values, li))
            else:
                lx, ly, lz, dist, pdf = sample_spherical_rectangle(px, py, pz, values[li, 3], values[li, 4],
                                                                   values[li, 5], values[li, 9], values[li, 10],
                                                                   values[li, 11], values[li, 12], values[li, 13],
                                                                   values[li, 14], u1, u2)
        elif kind == DISK:
            lx, ly, lz, dist, pdf = sample_disk_area(px, py, pz, values[li, 3], values[li, 4], values[li, 5],
                                                     values[li, 6], values[li, 7], values[li, 8], values[li, 15],
                                                     u1, u2)
        else:
            first = codes[li, 2]
            count = codes[li, 3]
            total = _polygon_solid_angle(values, vertices, first, count, px, py, pz)
            if not total > 0.0:
                return z
            if total < MIN_SOLID_ANGLE:  # tiny: by area
                qx, qy, qz, area = _polygon_area_point(vertices, first, count, u1, u2)
                lx, ly, lz, dist, pdf = _towards(values, li, px, py, pz, qx, qy, qz, area)
                if not pdf > 0.0:
                    return z
                return lx, ly, lz, dist, pdf, values[li, 0], values[li, 1], values[li, 2]
            ax = vertices[first, 0] - px
            ay = vertices[first, 1] - py
            az = vertices[first, 2] - pz
            target = u1 * total
            acc = 0.0
            k = 1
            omega = 0.0
            for k in range(1, count - 1):
                b = vertices[first + k]
                c = vertices[first + k + 1]
                omega = triangle_solid_angle(ax, ay, az, b[0] - px, b[1] - py, b[2] - pz, c[0] - px, c[1] - py,
                                             c[2] - pz)
                if acc + omega >= target or k == count - 2:
                    break
                acc += omega
            u = min(max((target - acc) / omega, 0.0), 1.0 - 1e-16) if omega > 0.0 else 0.5
            b = vertices[first + k]
            c = vertices[first + k + 1]
            lx, ly, lz, dist, pdf_t = sample_spherical_triangle(ax, ay, az, b[0] - px, b[1] - py, b[2] - pz,
                                                                c[0] - px, c[1] - py, c[2] - pz, u, u2)
            if not pdf_t > 0.0:
                return z
            pdf = 1.0 / total
    if not pdf > 0.0 or not dist < _INF:
        return z
    return lx, ly, lz, dist, pdf, values[li, 0], values[li, 1], values[li, 2]


@dual_use
def area_light_pdf(codes, values, vertices, li, px, py, pz, dx, dy, dz, t):
    """Solid-angle pdf with which :func:`area_light_sample` gives the direction d
    from p, which meets light li at distance t (0 if that side does not emit to p)."""
    kind = codes[li, 0]
    if kind == SPHERE:
        return sphere_cone_pdf(values[li, 3] - px, values[li, 4] - py, values[li, 5] - pz, values[li, 15])
    if not _front(values, li, codes[li, 1] != 0, px, py, pz):
        return 0.0
    cos_l = abs(dx * values[li, 6] + dy * values[li, 7] + dz * values[li, 8])
    if kind == RECT:
        omega = _rect_solid_angle(values, li, px, py, pz)
        if omega < MIN_SOLID_ANGLE:
            return area_solid_angle_pdf(t, cos_l, _rect_area(values, li)) if omega > 0.0 else 0.0
        return 1.0 / omega
    if kind == DISK:
        return disk_solid_angle_pdf(t, cos_l, values[li, 15])
    omega = _polygon_solid_angle(values, vertices, codes[li, 2], codes[li, 3], px, py, pz)
    if omega < MIN_SOLID_ANGLE:
        if not omega > 0.0:
            return 0.0
        _, _, _, area = _polygon_area_point(vertices, codes[li, 2], codes[li, 3], 0.5, 0.5)
        return area_solid_angle_pdf(t, cos_l, area)
    return 1.0 / omega


@row_kernel(5)
def _sample_kernel(start, stop, codes, values, vertices, li, p, u, out_dir, out_dist, out_pdf):
    for i in range(start, stop):
        r = area_light_sample(codes, values, vertices, li, p[0], p[1], p[2], u[i, 0], u[i, 1])
        out_dir[i, 0] = r[0]
        out_dir[i, 1] = r[1]
        out_dir[i, 2] = r[2]
        out_dist[i] = r[3]
        out_pdf[i] = r[4]


def area_light_samples(lights, index, point, u):
    """:func:`area_light_sample` of light ``index`` of :class:`AreaLights` from one
    point (3,) for uniform pairs u (N, 2): (directions (N, 3), distances (N,),
    solid-angle pdfs (N,))."""
    u = np.ascontiguousarray(u, dtype=np.float64).reshape(-1, 2)
    dirs = np.empty((u.shape[0], 3))
    dist = np.empty(u.shape[0])
    pdf = np.empty(u.shape[0])
    _sample_kernel(*lights.arrays(), int(index), np.ascontiguousarray(point, dtype=np.float64), u, dirs, dist, pdf)
    return dirs, dist, pdf


@row_kernel(5)
def _pdf_kernel(start, stop, codes, values, vertices, li, p, d, out):
    for i in range(start, stop):
        t = _light_t(codes, values, vertices, li, p[0], p[1], p[2], d[i, 0], d[i, 1], d[i, 2], _INF)
        out[i] = area_light_pdf(codes, values, vertices, li, p[0], p[1], p[2], d[i, 0], d[i, 1], d[i, 2],
                                t) if t < _INF else 0.0


def area_light_pdfs(lights, index, point, directions):
    """Solid-angle pdf of :func:`area_light_sample` of light ``index`` from one point
    (3,) for unit directions (N, 3): :func:`area_light_pdf` where the direction
    meets the light, else 0."""
    d = np.ascontiguousarray(directions, dtype=np.float64).reshape(-1, 3)
    out = np.empty(d.shape[0])
    _pdf_kernel(*lights.arrays(), int(index), np.ascontiguousarray(point, dtype=np.float64), d, out)
    return out


# ------------------------------------------------------- real time (LTC)


def area_light_polygon(light):
    """The polygon (K, 3) a planar light is integrated as in real time, counter-clockwise
    seen from its lit side: a rect's corners, a polygon's vertices, a disk's regular
    :data:`DISK_POLYGON_SIDES`-gon of the same area (circumradius r sqrt(2 pi / (K
    sin(2 pi / K)))), starting along the tangent of :func:`pbrkit.core.vec.
    orthonormal_basis_xyz` (Duff et al. 2017).  A sphere light's depends on the
    shading point (the disk that subtends its cone, :func:`_local_polygon`)."""
    if light.type == "rect":
        c0, e1, e2 = light.edges
        return np.array([c0, c0 + e1, c0 + e1 + e2, c0 + e2])
    if light.type == "polygon":
        return np.asarray(light.vertices, dtype=np.float64)
    if light.type == "disk":
        t, b = (np.array(x) for x in orthonormal_basis_xyz(*light.normal))
        rho = light.radius * _CIRCUMRADIUS
        return np.asarray(light.position) + rho * (_CIRCLE[:, :1] * t + _CIRCLE[:, 1:] * b)
    raise ValueError("a sphere light's polygon depends on the shading point")


#: Circumradius of the regular DISK_POLYGON_SIDES-gon with the area of the unit disk.
_CIRCUMRADIUS = math.sqrt(2.0 * math.pi / (DISK_POLYGON_SIDES * math.sin(2.0 * math.pi / DISK_POLYGON_SIDES)))
#: (cos, sin) of its vertices' angles.
_CIRCLE = np.stack([np.cos(2.0 * np.pi * np.arange(DISK_POLYGON_SIDES) / DISK_POLYGON_SIDES),
                    np.sin(2.0 * np.pi * np.arange(DISK_POLYGON_SIDES) / DISK_POLYGON_SIDES)], axis=-1)


@lru_cache(maxsize=1)
def bundled_fresnel_table():
    """The ``ltc_1`` matrices of pbrkit's Fresnel-aware LTC (:func:`pbrkit.ltc.shader.
    ltc_fresnel_rect`): fitted for the f Fc lobe, Fc = (1 - v.h)^5, with the exact
    horizon clipping (``pbrkit ltc --clipping exact --fit-f0 0``), bundled with the
    package: float64 (64, 64, 4), indexed [t, a, channel]."""
    with resources.as_file(resources.files("pbrkit.data") / "ltc" / "fresnel_ltc_1.npy") as path:
        return np.ascontiguousarray(np.load(path, allow_pickle=False).astype(np.float64))


@lru_cache(maxsize=1)
def bundled_ltc_table():
    """pbrkit's LTC table fitted for the exact horizon clipping (``pbrkit ltc
    --clipping exact``; the published layout, :func:`pbrkit.ltc.shader.
    ltc_table_from_published_layout`), bundled with the package: (ltc_1, ltc_2),
    float64 (64, 64, 4) each, indexed [t, a, channel]."""
    folder = resources.files("pbrkit.data") / "ltc"
    with resources.as_file(folder / "ltc_1.npy") as p1, resources.as_file(folder / "ltc_2.npy") as p2:
        ltc1 = np.load(p1, allow_pickle=False).astype(np.float64)
        ltc2 = np.load(p2, allow_pickle=False).astype(np.float64)
    return np.ascontiguousarray(ltc1), np.ascontiguousarray(ltc2)


@dual_use
def _table_value(table, roughness, nov, c):
    """Channel c of an (N, N, 4) LTC table at uv = (r, sqrt(1 - n.v)) on texel centres,
    bilinear, clamp to edge (three.js ``LTC_Uv``; :func:`pbrkit.ltc.shader._bilinear_published`)."""
    n = table.shape[0]
    x0, x1, ax = texel_pair(min(max(roughness, 0.0), 1.0) * (n - 1), n, CLAMP_TO_EDGE)
    y0, y1, ay = texel_pair(math.sqrt(1.0 - min(max(nov, 0.0), 1.0)) * (n - 1), n, CLAMP_TO_EDGE)
    return ((table[y0, x0, c] * (1.0 - ax) + table[y0, x1, c] * ax) * (1.0 - ay)
            + (table[y1, x0, c] * (1.0 - ax) + table[y1, x1, c] * ax) * ay)


@dual_use
def _table_texel(table, roughness, nov, m):
    """The ``ltc_1`` texel at (r, n.v) (:func:`_table_value`) written into the 3 x 3 ``m``
    as M^-1 = [[x, 0, z], [0, 1, 0], [y, 0, w]] (:func:`pbrkit.ltc.distribution.inverse_from_texel`)."""
    m[:, :] = 0.0
    m[1, 1] = 1.0
    m[0, 0] = _table_value(table, roughness, nov, 0)
    m[2, 0] = _table_value(table, roughness, nov, 1)
    m[0, 2] = _table_value(table, roughness, nov, 2)
    m[2, 2] = _table_value(table, roughness, nov, 3)


@dual_use
def _local_polygon(codes, values, vertices, li, px, py, pz, tx, ty, tz, bx, by, bz, nx, ny, nz, out):
    """Light li's polygon in the shading frame (t, b, n) at p, written to ``out``;
    returns its vertex count (0 when p sees no emitting side or is inside a sphere)."""
    kind = codes[li, 0]
    count = 0
    if kind == SPHERE:
        cx = values[li, 3] - px
        cy = values[li, 4] - py
        cz = values[li, 5] - pz
        d2 = cx * cx + cy * cy + cz * cz
        r = values[li, 15]
        if d2 <= r * r:
            return 0
        d = math.sqrt(d2)
        wx, wy, wz = cx / d, cy / d, cz / d
        scale = 1.0 - r * r / d2  # the cap's circle: centre c (1 - r^2/d^2), radius r sqrt(...)
        rho = r * math.sqrt(scale) * _CIRCUMRADIUS
        (ux, uy, uz), (vx, vy, vz) = orthonormal_basis_xyz(wx, wy, wz)
        ox, oy, oz = cx * scale, cy * scale, cz * scale
        for k in range(DISK_POLYGON_SIDES):
            a = _CIRCLE[k, 0] * rho
            b = _CIRCLE[k, 1] * rho
            qx = ox + a * ux + b * vx
            qy = oy + a * uy + b * vy
            qz = oz + a * uz + b * vz
            out[k, 0] = qx * tx + qy * ty + qz * tz
            out[k, 1] = qx * bx + qy * by + qz * bz
            out[k, 2] = qx * nx + qy * ny + qz * nz
        return DISK_POLYGON_SIDES
    if not _front(values, li, codes[li, 1] != 0, px, py, pz):
        return 0
    if kind == POLYGON or kind == DISK:
        first = codes[li, 2]
        count = codes[li, 3]
        for k in range(count):
            qx = vertices[first + k, 0] - px
            qy = vertices[first + k, 1] - py
            qz = vertices[first + k, 2] - pz
            out[k, 0] = qx * tx + qy * ty + qz * tz
            out[k, 1] = qx * bx + qy * by + qz * bz
            out[k, 2] = qx * nx + qy * ny + qz * nz
        return count
    for k in range(4):  # rect: its corner c0 and edges e1, e2
        s1 = 1.0 if (k == 1 or k == 2) else 0.0
        s2 = 1.0 if k >= 2 else 0.0
        qx = values[li, 3] + s1 * values[li, 9] + s2 * values[li, 12] - px
        qy = values[li, 4] + s1 * values[li, 10] + s2 * values[li, 13] - py
        qz = values[li, 5] + s1 * values[li, 11] + s2 * values[li, 14] - pz
        out[k, 0] = qx * tx + qy * ty + qz * tz
        out[k, 1] = qx * bx + qy * by + qz * bz
        out[k, 2] = qx * nx + qy * ny + qz * nz
    return 4


#: Points per work item of the real-time kernel (its scratch arrays are allocated once per item).
_CHUNK = 256


@row_kernel(lambda codes, values, vertices, ltc1, ltc2, fresnel1, p, *rest: (p.shape[0] + _CHUNK - 1) // _CHUNK)
def _ltc_kernel(start, stop, codes, values, vertices, ltc1, ltc2, fresnel1, p, n, v, rough, coat_rough, out_spec,
                out_fresnel, out_split, out_irr, out_coat):
    """Per point: sums over lights of L FF (specular: the LTC of the f lobe, of the
    f Fc lobe where ``fresnel1`` has rows, and of the f lobe at the clear coat's
    roughness where coat_rough >= 0) and pi L FF_cos (irradiance); and (norm,
    fresnel) of ``ltc2``."""
    cap = max(MAX_POLYGON_VERTICES, DISK_POLYGON_SIDES)
    count = p.shape[0]
    fresnel_aware = fresnel1.shape[0] > 0
    for chunk in range(start, stop):
        poly = np.empty((cap, 3))
        m = np.empty((3, 3))
        mfr = np.empty((3, 3))
        mc = np.empty((3, 3))
        for i in range(chunk * _CHUNK, min(count, (chunk + 1) * _CHUNK)):
            for c in range(3):
                out_spec[i, c] = 0.0
                out_fresnel[i, c] = 0.0
                out_irr[i, c] = 0.0
                out_coat[i, c] = 0.0
            nx, ny, nz = n[i, 0], n[i, 1], n[i, 2]
            nov = nx * v[i, 0] + ny * v[i, 1] + nz * v[i, 2]
            tx = v[i, 0] - nov * nx
            ty = v[i, 1] - nov * ny
            tz = v[i, 2] - nov * nz
            tl = math.sqrt(tx * tx + ty * ty + tz * tz)
            if tl < 1e-9:  # view along the normal: any tangent (the lobe is symmetric)
                (tx, ty, tz), _ = orthonormal_basis_xyz(nx, ny, nz)
                tl = 1.0
            tx /= tl
            ty /= tl
            tz /= tl
            bx = ny * tz - nz * ty
            by = nz * tx - nx * tz
            bz = nx * ty - ny * tx
            nov = max(nov, 1e-4)
            _table_texel(ltc1, rough[i], nov, m)
            out_split[i, 0] = _table_value(ltc2, rough[i], nov, 0)
            out_split[i, 1] = _table_value(ltc2, rough[i], nov, 1)
            if fresnel_aware:
                _table_texel(fresnel1, rough[i], nov, mfr)
            coated = coat_rough[i] >= 0.0
            if coated:
                _table_texel(ltc1, coat_rough[i], nov, mc)
            for li in range(codes.shape[0]):
                k = _local_polygon(codes, values, vertices, li, p[i, 0], p[i, 1], p[i, 2], tx, ty, tz, bx, by, bz,
                                   nx, ny, nz, poly)
                if k == 0:
                    continue
                verts = poly[:k]
                diff = abs(polygon_form_factor(verts))
                if diff == 0.0:  # wholly below the horizon
                    continue
                spec = abs(transformed_polygon_form_factor(m, verts))
                fres = abs(transformed_polygon_form_factor(mfr, verts)) if fresnel_aware else spec
                coat = abs(transformed_polygon_form_factor(mc, verts)) if coated else 0.0
                for c in range(3):
                    out_spec[i, c] += values[li, c] * spec
                    out_fresnel[i, c] += values[li, c] * fres
                    out_irr[i, c] += values[li, c] * diff * math.pi
                    out_coat[i, c] += values[li, c] * coat


def area_light_ltc(lights, p, n, v, roughness, coat_roughness=None, table=None, fresnel_table=None):
    """Real-time area lighting (module docstring) at points p with shading normals n
    and view directions v (N, 3), perceptual roughness (N,).  Returns
    :class:`LTCLighting`: ``specular`` (N, 3), the sum of L times the LTC's
    normalised integral over each light (to be scaled by the specular albedo as
    IBL's prefiltered radiance is), ``fresnel`` (N, 3) the same for the LTC of the
    f Fc lobe (equal to ``specular`` without a Fresnel table), ``split`` (N, 2) the
    table's (norm, fresnel), ``irradiance`` (N, 3), the sum of pi L times each
    polygon's form factor, and ``coat`` (N, 3) the specular term at
    ``coat_roughness`` where it is >= 0.  ``table``: (ltc_1, ltc_2) in the published
    layout, default :func:`bundled_ltc_table`; ``fresnel_table``: the f Fc lobe's
    ltc_1, default the bundled one with the bundled table
    (:func:`bundled_fresnel_table`), none with another table."""
    if table is None:
        table = bundled_ltc_table()
        if fresnel_table is None:
            fresnel_table = bundled_fresnel_table()
    ltc1 = np.ascontiguousarray(table[0], dtype=np.float64)
    ltc2 = np.ascontiguousarray(table[1], dtype=np.float64)
    fresnel1 = (np.zeros((0, 1, 4)) if fresnel_table is None
                else np.ascontiguousarray(fresnel_table, dtype=np.float64))
    count = np.asarray(p).shape[0]
    coat_roughness = np.full(count, -1.0) if coat_roughness is None else coat_roughness
    out = LTCLighting(*(np.empty((count, 3)) for _ in range(2)), np.empty((count, 2)),
                      *(np.empty((count, 3)) for _ in range(2)))
    if count:
        _ltc_kernel(*lights.arrays(), ltc1, ltc2, fresnel1,
                    *(np.ascontiguousarray(x, dtype=np.float64) for x in (p, n, v, roughness, coat_roughness)),
                    out.specular, out.fresnel, out.split, out.irradiance, out.coat)
    return out


@dataclass
class LTCLighting:
    """What :func:`area_light_ltc` returns (its docstring)."""

    specular: np.ndarray
    fresnel: np.ndarray
    split: np.ndarray
    irradiance: np.ndarray
    coat: np.ndarray
