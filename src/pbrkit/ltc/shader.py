"""What a shader computes with an LTC table in the published layout (Heitz,
Dupuy, Hill and Neubelt 2016, ``ltc_code`` ``fit/results/ltc.js``; three.js's
``RectAreaLightTexturesLib``): the table lookups, the edge-vector form factor
with Hill and Heitz's rational fit, the horizon clipping by the sphere
approximation (:func:`ltc_shader_rect`, what three.js, Filament and Babylon
run), and pbrkit's own evaluations with the exact horizon clipping
(:func:`ltc_exact_rect`) and Fresnel-aware (:func:`ltc_fresnel_rect`).  Frame
and lights: :mod:`pbrkit.ltc.lights`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.filtering import CLAMP_TO_EDGE, texel_pair
from ..core.jit import dual_use, row_kernel, select
from .lights import check_lights
from .polygon import transformed_polygon_form_factor

__all__ = ["LTCTable", "ltc_table_from_published_layout", "edge_vector_form_factor", "edge_vector_form_factor_xyz",
           "clipped_sphere_form_factor", "clipped_sphere_form_factor_xyz", "ltc_shader_rect", "ltc_exact_rect",
           "ltc_fresnel_rect", "shader_rect_form_factor", "exact_rect_form_factor", "ltc_shader_form_factor"]


@dataclass(frozen=True)
class LTCTable:
    """Two LTC textures in the published layout, float64 (N, N, 4) indexed
    [t, a, c] (:func:`ltc_table_from_published_layout`)."""

    ltc1: np.ndarray
    ltc2: np.ndarray

    @property
    def size(self):
        return self.ltc1.shape[0]


def ltc_table_from_published_layout(ltc1, ltc2):
    """Check and normalise two tables in the published layout (Heitz et al.
    2016, ``ltc_code`` ``fit/results/ltc.js``; three.js
    ``RectAreaLightTexturesLib``; ``CONVENTIONS.md``, Area lights) into an
    :class:`LTCTable`.

    Each is an N x N RGBA texture, given as an array (N, N, 4) indexed
    [t, a, c], or flat (N * N * 4,) in the order a ``DataTexture`` of width
    and height N is uploaded (row t, then column a, then channel), which is
    the same order.  Column a holds perceptual roughness r = a / (N - 1)
    (alpha = r^2), row t holds sqrt(1 - cos theta_v) = t / (N - 1); a shader
    reads texel coordinate p (N - 1) of either axis, i.e. uv = p (N - 1) / N
    + 0.5 / N with bilinear filtering and clamp to edge.
    ``ltc1`` = (m00, m20, m02, m22) of the inverse matrix M^-1 divided by
    m11, which a shader builds as GLSL ``mat3(vec3(x, 0, y), vec3(0, 1, 0),
    vec3(z, 0, w))`` (column-major: M^-1 = [[x, 0, z], [0, 1, 0], [y, 0, w]]).
    ``ltc2`` = (norm, fresnel, 0, sphere form factor): the specular albedo
    with Schlick's F is f0 norm + (1 - f0) fresnel.  N may be any size >= 2
    (64 for the published tables)."""
    arrays = []
    for name, t in (("ltc1", ltc1), ("ltc2", ltc2)):
        a = np.asarray(t, dtype=np.float64)
        if a.ndim == 1:
            n = math.isqrt(a.size // 4)
            if n * n * 4 != a.size:
                raise ValueError(f"{name}: a flat table must hold N * N * 4 values; got {a.size}")
            a = a.reshape(n, n, 4)
        if a.ndim != 3 or a.shape[0] != a.shape[1] or a.shape[2] != 4 or a.shape[0] < 2:
            raise ValueError(f"{name} must have shape (N, N, 4) with N >= 2 (or be flat); got {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name} must be finite")
        arrays.append(np.ascontiguousarray(a))
    if arrays[0].shape != arrays[1].shape:
        raise ValueError(f"ltc1 and ltc2 must have the same shape; got {arrays[0].shape} and {arrays[1].shape}")
    return LTCTable(arrays[0], arrays[1])


def _bilinear_published(table, roughness, nov):
    """Bilinear lookup of an (N, N, 4) table at uv = (r, sqrt(1 - n.v)) mapped to
    texel centres (three.js ``LTC_Uv``; texel coordinate p (N - 1)), with the
    GPU's linear filter and clamp to edge (:func:`pbrkit.core.filtering.texel_pair`,
    OpenGL 4.6 sec. 8.14.2)."""
    n = table.shape[0]
    x0, x1, ax = texel_pair(np.clip(roughness, 0.0, 1.0) * (n - 1), n, CLAMP_TO_EDGE)
    y0, y1, ay = texel_pair(np.sqrt(1.0 - np.clip(nov, 0.0, 1.0)) * (n - 1), n, CLAMP_TO_EDGE)
    ax = np.asarray(ax)[..., None]
    ay = np.asarray(ay)[..., None]
    return ((table[y0, x0] * (1.0 - ax) + table[y0, x1] * ax) * (1.0 - ay)
            + (table[y1, x0] * (1.0 - ax) + table[y1, x1] * ax) * ay)


@dual_use
def edge_vector_form_factor_xyz(ax, ay, az, bx, by, bz):
    """One edge's term of the vector form factor of a polygon projected on the
    unit sphere, as shaders compute it: cross(a, b) theta / (2 pi sin theta),
    theta = acos(a . b), with theta / sin theta / (2 pi) replaced by the
    rational fit of Hill and Heitz, "Real-Time Area Lighting: a Journey from
    Research to Production" (SIGGRAPH 2016 course "Advances in Real-Time
    Rendering"; ltc_code's ``IntegrateEdgeVec``, three.js's
    ``LTC_EdgeVectorFormFactor``): v = (0.8543985 + (0.4965155 + 0.0145206
    |x|) |x|) / (3.4175940 + (4.1616724 + |x|) |x|) for x = a . b > 0, and
    0.5 / sqrt(max(1 - x^2, 1e-7)) - v otherwise (theta / sin theta for the
    obtuse angle from the acute one).  Unit vectors a, b by components; returns
    the vector's components."""
    x = ax * bx + ay * by + az * bz
    y = np.abs(x)
    v = (0.8543985 + (0.4965155 + 0.0145206 * y) * y) / (3.4175940 + (4.1616724 + y) * y)
    t = select(x > 0.0, v, 0.5 / np.sqrt(np.maximum(1.0 - x * x, 1e-7)) - v)
    return (ay * bz - az * by) * t, (az * bx - ax * bz) * t, (ax * by - ay * bx) * t


def edge_vector_form_factor(v1, v2):
    """:func:`edge_vector_form_factor_xyz` for unit vectors (..., 3) -> (..., 3)."""
    return np.stack(edge_vector_form_factor_xyz(v1[..., 0], v1[..., 1], v1[..., 2], v2[..., 0], v2[..., 1],
                                                v2[..., 2]), axis=-1)


@dual_use
def clipped_sphere_form_factor_xyz(fx, fy, fz):
    """Form factor of a horizon-clipped polygon approximated from its vector form
    factor f by that of a sphere with the same form factor and direction (Hill and
    Heitz 2016, "a Journey from Research to Production", p. 102; three.js
    ``LTC_ClippedSphereFormFactor``): max((|f|^2 + f.z) / (|f| + 1), 0)."""
    length = np.sqrt(fx * fx + fy * fy + fz * fz)
    return np.maximum((length * length + fz) / (length + 1.0), 0.0)


def clipped_sphere_form_factor(f):
    """:func:`clipped_sphere_form_factor_xyz` of vector form factors (..., 3) -> (...)."""
    return clipped_sphere_form_factor_xyz(f[..., 0], f[..., 1], f[..., 2])


def ltc_shader_rect(ltc1, ltc2, nov, roughness, corners, f0=1.0):
    """The specular radiance a shader computes for a unit-radiance rectangular
    light with LTC tables in the published layout: three.js's
    ``RE_Direct_RectArea_Physical`` and ``LTC_Evaluate``
    (``lights_physical_pars_fragment.glsl.js``, r187), the method of Heitz et
    al. 2016 (sec. 3-4) with the shortcuts of Hill and Heitz 2016:

    1. uv = (r, sqrt(1 - n.v)) mapped to texel centres, bilinear lookups of
       both tables (:func:`ltc_table_from_published_layout`);
    2. M^-1 = [[t1.x, 0, t1.z], [0, 1, 0], [t1.y, 0, t1.w]];
    3. the light's corners in the view's frame (T1, T2, n) with
       T1 = normalize(v - n (n.v)) (+x of the local frame; also at n.v = 1,
       where a GPU would divide 0 by 0) and T2 = -n x T1 (three.js's
       handedness, "negated from paper", matched by its corner winding), then
       M^-1 applied and the corners projected on the unit sphere;
    4. the vector form factor, the sum of :func:`edge_vector_form_factor` over
       the four edges, and the horizon-clipped form factor from it by
       :func:`clipped_sphere_form_factor`;
    5. times Hill's Fresnel split f0 t2.x + (1 - f0) t2.y (f90 = 1).

    A shading point behind the light's plane gets 0 (``LTC_Evaluate``'s
    back-side test).  ``ltc1`` / ``ltc2``: arrays or an :class:`LTCTable`
    (pass ``ltc2=None`` then).  ``nov``, ``roughness`` (...) and ``corners``
    (..., 4, 3) broadcast as in :func:`~pbrkit.ltc.reference.ggx_rect_integrals`; ``f0`` broadcasts
    too.  Computed in float64 (a GPU uses float32: differences ~1e-6
    relative).  Returns (...)."""
    table = ltc1 if isinstance(ltc1, LTCTable) else ltc_table_from_published_layout(ltc1, ltc2)
    nov, roughness, corners, shape = check_lights(nov, roughness, corners)
    t1 = _bilinear_published(table.ltc1, roughness, nov)
    t2 = _bilinear_published(table.ltc2, roughness, nov)
    fresnel = f0 * t2[..., 0] + (1.0 - f0) * t2[..., 1]
    return ltc_shader_form_factor(t1, corners) * fresnel


def ltc_exact_rect(ltc1, ltc2, nov, roughness, corners, f0=1.0):
    """pbrkit's own evaluation of a table in the published layout: the lookups of
    :func:`ltc_shader_rect` (bilinear, texel centres, the Fresnel split), but the
    LTC's integral clipped at the true horizon (:func:`exact_rect_form_factor`)
    instead of the shaders' sphere approximation; one-sided.  What a table fitted
    with ``clipping="exact"`` (:func:`pbrkit.ltc.fit.fit_table`) is for."""
    table = ltc1 if isinstance(ltc1, LTCTable) else ltc_table_from_published_layout(ltc1, ltc2)
    nov, roughness, corners, shape = check_lights(nov, roughness, corners)
    t1 = _bilinear_published(table.ltc1, roughness, nov)
    t2 = _bilinear_published(table.ltc2, roughness, nov)
    fresnel = f0 * t2[..., 0] + (1.0 - f0) * t2[..., 1]
    return _rect_form_factors(t1, corners, True) * fresnel


def ltc_fresnel_rect(ltc1, ltc2, fresnel_ltc1, nov, roughness, corners, f0=1.0):
    """pbrkit's Fresnel-aware LTC: Schlick's F = f0 + (1 - f0) Fc, Fc = (1 - v.h)^5,
    splits the lobe f F cos into f0 f cos + (1 - f0) f Fc cos, two lobes of
    different shapes (the second leans further to grazing), each with its own LTC:
    ``ltc1`` fitted for f (F = 1) and ``fresnel_ltc1`` for f Fc (``pbrkit ltc
    --fit-f0 0``), both evaluated with the exact horizon clipping
    (:func:`exact_rect_form_factor`) and scaled by their albedos, the norm and the
    fresnel column of ``ltc2`` (Hill's split, Heitz et al. 2016 sec. 4 and Hill and
    Heitz 2016, used here per lobe):
    f0 norm FF(M_1) + (1 - f0) fresnel FF(M_Fc).  The same layout and lookups as
    :func:`ltc_exact_rect`; one more table lookup and polygon integral per light."""
    table = ltc1 if isinstance(ltc1, LTCTable) else ltc_table_from_published_layout(ltc1, ltc2)
    fresnel = ltc_table_from_published_layout(fresnel_ltc1, table.ltc2)
    nov, roughness, corners, shape = check_lights(nov, roughness, corners)
    t1 = _bilinear_published(table.ltc1, roughness, nov)
    tc = _bilinear_published(fresnel.ltc1, roughness, nov)
    t2 = _bilinear_published(table.ltc2, roughness, nov)
    return (f0 * t2[..., 0] * _rect_form_factors(t1, corners, True)
            + (1.0 - f0) * t2[..., 1] * _rect_form_factors(tc, corners, True))


@dual_use
def shader_rect_form_factor(x, y, z, w, corners):
    """Steps 2-4 of :func:`ltc_shader_rect` for one rectangle ``corners`` (4, 3)
    under the ``ltc_1`` texel (x, y, z, w), i.e. M^-1 = [[x, 0, z], [0, 1, 0], [y, 0,
    w]], given directly (no table lookup): the corners in the shader's frame
    (T1, T2, N) = (+x, -y, +z), M^-1 applied and projected on the unit sphere, the
    edge terms by Hill and Heitz's rational fit (:func:`edge_vector_form_factor_xyz`)
    and the horizon clipping by the sphere approximation
    (:func:`clipped_sphere_form_factor_xyz`); 0 behind the light."""
    qx = np.empty(4)
    qy = np.empty(4)
    qz = np.empty(4)
    for c in range(4):
        px = corners[c, 0]
        py = -corners[c, 1]
        pz = corners[c, 2]
        ux = x * px + z * pz
        uz = y * px + w * pz
        length = math.sqrt(ux * ux + py * py + uz * uz)
        qx[c] = ux / length
        qy[c] = py / length
        qz[c] = uz / length
    fx = 0.0
    fy = 0.0
    fz = 0.0
    for c in range(4):
        d = (c + 1) % 4
        ex, ey, ez = edge_vector_form_factor_xyz(qx[c], qy[c], qz[c], qx[d], qy[d], qz[d])
        fx += ex
        fy += ey
        fz += ez
    if not _lit_side(corners):
        return 0.0
    return clipped_sphere_form_factor_xyz(fx, fy, fz)


@dual_use
def exact_rect_form_factor(x, y, z, w, corners):
    """The LTC's integral over one rectangle ``corners`` (4, 3) under M^-1 = [[x, 0,
    z], [0, 1, 0], [y, 0, w]] clipped at the true horizon (Heitz et al. 2016, sec.
    5.2, ``ClipQuadToHorizon``; :func:`pbrkit.ltc.polygon.transformed_polygon_form_factor`),
    signed by det M^-1 so that the light's own winding decides its side, and 0 on
    the unlit side."""
    m = np.zeros((3, 3))
    m[0, 0] = x
    m[0, 2] = z
    m[1, 1] = 1.0
    m[2, 0] = y
    m[2, 2] = w
    sign = 1.0 if x * w - z * y >= 0.0 else -1.0
    return max(0.0, sign * transformed_polygon_form_factor(m, corners))


@dual_use
def _lit_side(corners):
    """Whether the shading point (the origin) is on the lit side of the rectangle
    ``corners`` (4, 3): the side cross(c1 - c0, c3 - c0) points to (three.js
    ``LTC_Evaluate``'s back-side test)."""
    e1x = corners[1, 0] - corners[0, 0]
    e1y = corners[1, 1] - corners[0, 1]
    e1z = corners[1, 2] - corners[0, 2]
    e2x = corners[3, 0] - corners[0, 0]
    e2y = corners[3, 1] - corners[0, 1]
    e2z = corners[3, 2] - corners[0, 2]
    nx = e1y * e2z - e1z * e2y
    ny = e1z * e2x - e1x * e2z
    nz = e1x * e2y - e1y * e2x
    return -(nx * corners[0, 0] + ny * corners[0, 1] + nz * corners[0, 2]) >= 0.0


@row_kernel(1)
def _rect_form_factor_kernel(start, stop, texels, corners, exact, out):
    for k in range(start, stop):
        t = texels[k]
        if exact:
            out[k] = exact_rect_form_factor(t[0], t[1], t[2], t[3], corners[k])
        else:
            out[k] = shader_rect_form_factor(t[0], t[1], t[2], t[3], corners[k])


def _rect_form_factors(texel, corners, exact):
    """:func:`exact_rect_form_factor` or :func:`shader_rect_form_factor` of texels
    (..., 4) and rectangles (..., 4, 3), broadcast together -> (...)."""
    corners = np.asarray(corners, dtype=np.float64)
    texel = np.asarray(texel, dtype=np.float64)
    shape = np.broadcast_shapes(texel.shape[:-1], corners.shape[:-2])
    t = np.ascontiguousarray(np.broadcast_to(texel, shape + (4,)).reshape(-1, 4))
    c = np.ascontiguousarray(np.broadcast_to(corners, shape + (4, 3)).reshape(-1, 4, 3))
    out = np.empty(c.shape[0])
    _rect_form_factor_kernel(t, c, bool(exact), out)
    return out.reshape(shape)


def ltc_shader_form_factor(texel, corners):
    """Steps 2-4 of :func:`ltc_shader_rect` for ``ltc_1`` texel values ``texel``
    (..., 4) given directly (no table lookup) and rectangles ``corners`` (..., 4,
    3): :func:`shader_rect_form_factor` of each.  What a table fit for shaders
    (:mod:`pbrkit.ltc.fit`) must match."""
    return _rect_form_factors(texel, corners, False)
