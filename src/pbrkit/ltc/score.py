"""Scoring Linearly Transformed Cosine tables against ground truth: the
converged integral of a microfacet lobe (GGX by default, or Beckmann; a
Smith-family masking) over rectangular lights, the evaluation a shader does
with a table in the published layout, and the test set and statistics that
compare the two.

Heitz, Dupuy, Hill and Neubelt 2016, "Real-Time Polygonal-Light Shading with
Linearly Transformed Cosines" (ACM TOG 35(4), SIGGRAPH 2016; code and tables:
``selfshadow/ltc_code``) approximate the specular lobe of a view direction and
roughness by a clamped cosine D_o under a linear transform M, so that the
lobe's integral over a polygon P is the cosine's integral over M^-1 P, in
closed form, times the lobe's norm (its directional albedo).

Frame (``docs/CONVENTIONS.md``): every function here works in the *local
shading frame* of the shading point, which sits at the origin with normal
n = +z and view v = (sin theta_v, 0, cos theta_v) (so v is in the xz-plane
with t.v >= 0, mu = n.v = cos theta_v).  A rectangular light is given by its
four corners ``(..., 4, 3)`` in that frame, in three.js's order
(``RE_Direct_RectArea_Physical``: centre + w - h, centre - w - h,
centre - w + h, centre + w + h for half-width w and half-height h):
counter-clockwise as seen from the lit side, which is the side
cross(c1 - c0, c3 - c0) points to.  Lights are one-sided (``CONVENTIONS.md``,
Area lights): a shading point behind the light's plane receives nothing, in
the reference as in the shader.  Radiance is 1 and the quantity is the
reflected radiance L_o = integral over the light of f_r(v, l) (n.l) dl.

- :func:`lobe_rect_integrals` / :func:`lobe_rect_reference`: that integral for
  the lobe of ``distribution`` (:data:`LTC_DISTRIBUTIONS`: GGX or Beckmann,
  alpha = r^2 for both) and ``masking`` (:data:`MASKINGS_FOR`: height-correlated
  or separable Smith, or for GGX Schlick-GGX) with Schlick F, the lobe
  evaluated by :mod:`pbrkit.brdf.dispatch`'s own ``specular_lobe`` (one code path
  for every lobe), by adaptive cubature in the light's plane, clipped at the
  horizon; converged to 1e-6 relative by its own estimate and tested against
  Monte Carlo and a composite Gauss-Legendre rule.  :func:`ggx_rect_integrals`
  / :func:`ggx_rect_reference` are the default lobe's, GGX with
  height-correlated Smith.  :func:`lobe_split_integrals` /
  :func:`directional_albedo`: the same lobe's converged albedo.
- :func:`ltc_shader_rect`: what three.js's ``LTC_Evaluate`` computes with a
  table in the published layout (:func:`ltc_table_from_published_layout`).
- :func:`random_rect_lights`: the test set; :func:`score_table`: relative and
  albedo-normalised errors and their summary; :func:`published_table`: the
  published tables as three.js ships them, read from its npm package at run
  time (never bundled: the data is ltc_code's, MIT licensed, in three's
  ``RectAreaLightTexturesLib.js``).
"""

from __future__ import annotations

import heapq
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..albedo.tables import VISIBILITIES, specular_integrals
from ..brdf.bxdf import isotropic_cosines
from ..brdf.dispatch import make_bxdf, specular_lobe
from ..core.inputs import check_regular, read_bytes, read_text
from ..brdf.fresnel import f_schlick
from ..brdf.models import model_codes
from ..brdf.shading.registry import LAYOUT
from ..core.filtering import CLAMP_TO_EDGE, texel_pair
from ..core.jit import dual_use, kernel, row_kernel, select
from ..core.quadrature import gauss_legendre_01
from ..microfacet.roughness import alpha_from_roughness
from .polygon import transformed_polygon_form_factor

#: The packed parameter row's length (a constant for the compiled kernels).
_PARAMETER_COLUMNS = LAYOUT.size

__all__ = [
    "LUT_SIZE",
    "REFERENCE_TOLERANCE",
    "RELATIVE_THRESHOLD",
    "TEST_SET",
    "LTCTable",
    "RectLights",
    "LTCScore",
    "LTC_DISTRIBUTIONS",
    "LTC_MASKINGS",
    "MASKINGS_FOR",
    "lobe_codes",
    "lobe_name",
    "rect_corners",
    "lobe_rect_integrals",
    "lobe_rect_reference",
    "ggx_rect_integrals",
    "ggx_rect_reference",
    "ALBEDO_NODES",
    "TABLE_NODES",
    "lobe_split_integrals",
    "ltc_table_from_published_layout",
    "ltc_shader_rect",
    "ltc_shader_form_factor",
    "ltc_exact_rect",
    "ltc_fresnel_rect",
    "shader_rect_form_factor",
    "exact_rect_form_factor",
    "rect_lights_towards",
    "edge_vector_form_factor",
    "edge_vector_form_factor_xyz",
    "clipped_sphere_form_factor",
    "clipped_sphere_form_factor_xyz",
    "random_rect_lights",
    "directional_albedo",
    "score_table",
    "published_table",
    "published_table_path",
]

#: Side of the published tables (texels per axis).
LUT_SIZE = 64

#: Relative accuracy the reference cubature is run to by default (its own,
#: conservative error estimate; the tests check it against 4x tighter runs and
#: against Monte Carlo).
REFERENCE_TOLERANCE = 1e-6

#: Lights whose reference radiance is below this fraction of the directional
#: albedo E(mu, r) (same Fresnel) are left out of the *relative* errors (their
#: relative error measures nothing a viewer sees); the albedo-normalised
#: errors include every light.
RELATIVE_THRESHOLD = 1e-3


# --------------------------------------------------------------------- lobes

#: The microfacet distributions LTC tables are fitted and scored for (``pbrkit ltc
#: --distribution``; :data:`pbrkit.brdf.models.DISTRIBUTIONS` of ``cook_torrance``),
#: both with alpha = r^2 (:func:`pbrkit.microfacet.roughness.alpha_from_roughness`).
#: Blinn-Phong is left out: pbrkit pairs it with Beckmann's Smith Lambda (an
#: approximation, no Smith masking of its own), and a Blinn-Phong lobe of
#: exponent 2 / alpha^2 - 2 is Beckmann's to within that approximation.
LTC_DISTRIBUTIONS = ("ggx", "beckmann")
#: The Smith-family masking-shadowing terms of ``cook_torrance``
#: (:data:`pbrkit.brdf.models.MASKINGS`, ``pbrkit ltc --masking``):
#: exact Smith G2 height-correlated (Heitz 2014, eq. 99) or separable (eq. 98)
#: with the distribution's own Lambda, and Schlick's approximation of the
#: separable Smith-GGX G1 with k = alpha / 2 (Karis 2013, IBL) or UE4's
#: direct-light k = (r + 1)^2 / 8.  Left out: ``kelemen`` (Kelemen and
#: Szirmay-Kalos 2001: 1 / (v.h)^2 approximates Cook-Torrance's V-cavity G, not a
#: Smith term, and does not depend on roughness) and ``implicit`` (G = n.l n.v:
#: no masking at all).
LTC_MASKINGS = ("height-correlated", "separable", "schlick-ggx", "schlick-ggx-ue4")
#: The maskings each distribution takes: Schlick-GGX's k fits GGX's Smith G1, not
#: Beckmann's, so Beckmann takes the exact Smith terms only.
MASKINGS_FOR = {"ggx": LTC_MASKINGS, "beckmann": ("height-correlated", "separable")}


def lobe_codes(distribution="ggx", masking="height-correlated"):
    """The integer code row (1, :data:`pbrkit.brdf.bxdf.CODE_COLUMNS`) of the
    Fresnel-free specular lobe the LTC machinery integrates: ``cook_torrance``
    with ``distribution`` and ``masking``, Fresnel and diffuse "none"
    (:func:`pbrkit.brdf.models.model_codes`).  A ValueError of one line names
    the option (``--distribution`` / ``--masking``) and the choices for a
    distribution or masking outside :data:`LTC_DISTRIBUTIONS` /
    :data:`MASKINGS_FOR`."""
    if distribution not in LTC_DISTRIBUTIONS:
        raise ValueError(f"--distribution: unknown distribution {distribution!r}; choose one of "
                         f"{', '.join(LTC_DISTRIBUTIONS)}")
    allowed = MASKINGS_FOR[distribution]
    if masking not in allowed:
        if masking in LTC_MASKINGS:
            raise ValueError(f"--masking: {masking} is Schlick's approximation of GGX's Smith masking, not "
                             f"{distribution}'s; with --distribution {distribution} choose one of {', '.join(allowed)}")
        raise ValueError(f"--masking: unknown masking {masking!r}; choose one of {', '.join(allowed)}"
                         + ("" if distribution == "ggx" else f" (with --distribution {distribution})"))
    return model_codes("cook_torrance", distribution, masking, fresnel="none", diffuse="none")


def lobe_name(distribution="ggx", masking="height-correlated"):
    """A one-line description of the lobe, for reports and file metadata."""
    lobe_codes(distribution, masking)
    d = {"ggx": "GGX", "beckmann": "Beckmann"}[distribution]
    g = {"height-correlated": "height-correlated Smith G2", "separable": "separable Smith G2",
         "schlick-ggx": "Schlick-GGX G2 (k = alpha / 2)",
         "schlick-ggx-ue4": "Schlick-GGX G2 (UE4 direct, k = (r + 1)^2 / 8)"}[masking]
    return f"{d} D, {g}, alpha = r^2"


@dual_use
def _lobe_of(codes, roughness):
    """The :class:`pbrkit.brdf.bxdf.BxDF` of the lobe of code row ``codes``
    (:func:`lobe_codes`) at perceptual roughness ``roughness``
    (:func:`pbrkit.brdf.dispatch.make_bxdf`: alpha = max(r^2, 1e-3), isotropic,
    white, metallic)."""
    params = np.zeros((1, _PARAMETER_COLUMNS))
    return make_bxdf(codes, 0, params, 0, roughness, 1.0, 1.0, 1.0, 1.0)


# ------------------------------------------------------------------ geometry


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


def _check_lights(nov, roughness, corners):
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


# ------------------------------------------------------- reference cubature


@dual_use
def _lobe_per_area(x, y, ox, oy, oz, ux, uy, uz, wx, wy, wz, delta, nov, sin_v, lobe):
    """(f (n.l) dl/dA, the same times Fc = (1 - v.h)^5) at the point
    o + x u + y w of the light's plane (distance ``delta`` from the origin):
    f = D V of the Fresnel-free specular lobe ``lobe``, a
    :class:`pbrkit.brdf.bxdf.BxDF` of ``cook_torrance`` with the chosen
    distribution and masking codes (:func:`_lobe_of`), evaluated by the models'
    own composition (:func:`pbrkit.brdf.dispatch.specular_lobe`), and
    dl = delta / |p|^3 dA (the area-to-solid-angle Jacobian cos theta' / d^2,
    e.g. Pharr, Jakob and Humphreys 2023, pbrt-v4 sec. 4.2.3)."""
    px = ox + x * ux + y * wx
    py = oy + x * uy + y * wy
    pz = oz + x * uz + y * wz
    d2 = px * px + py * py + pz * pz
    d = math.sqrt(d2)
    lz = pz / d
    if lz <= 0.0:
        return 0.0, 0.0
    c = isotropic_cosines(0.0, 0.0, 1.0, sin_v, 0.0, nov, px / d, py / d, lz)
    g = specular_lobe(lobe, c) * c.nol * delta / (d2 * d)
    return g, g * f_schlick(c.voh, 0.0, 1.0)


@dual_use
def _triangle_rule(ax, ay, bx, by, cx, cy, geo, nov, sin_v, lobe, gx, gw):
    """Collapsed (Duffy) tensor Gauss-Legendre rule on the triangle (A, B, C):
    P = A + xi (B - A) + xi eta (C - B), dA = 2 area xi dxi deta; the nodes
    cluster at A (where the fan puts the lobe's peak)."""
    area2 = abs((bx - ax) * (cy - ay) - (by - ay) * (cx - ax))
    s0 = 0.0
    s1 = 0.0
    n = gx.shape[0]
    for i in range(n):
        xi = gx[i]
        px = ax + xi * (bx - ax)
        py = ay + xi * (by - ay)
        qx = xi * (cx - bx)
        qy = xi * (cy - by)
        for j in range(n):
            eta = gx[j]
            g0, g1 = _lobe_per_area(px + eta * qx, py + eta * qy, geo[0], geo[1], geo[2], geo[3], geo[4], geo[5],
                                    geo[6], geo[7], geo[8], geo[9], nov, sin_v, lobe)
            wt = gw[i] * gw[j] * xi
            s0 += wt * g0
            s1 += wt * g1
    return s0 * area2, s1 * area2


@dual_use
def _children(t):
    """The four midpoint children of triangle t = (ax, ay, bx, by, cx, cy); the
    first keeps vertex A first."""
    ax, ay, bx, by, cx, cy = t[0], t[1], t[2], t[3], t[4], t[5]
    abx, aby = 0.5 * (ax + bx), 0.5 * (ay + by)
    bcx, bcy = 0.5 * (bx + cx), 0.5 * (by + cy)
    cax, cay = 0.5 * (cx + ax), 0.5 * (cy + ay)
    out = np.empty((4, 6))
    out[0, :] = (ax, ay, abx, aby, cax, cay)
    out[1, :] = (abx, aby, bx, by, bcx, bcy)
    out[2, :] = (cax, cay, bcx, bcy, cx, cy)
    out[3, :] = (bcx, bcy, cax, cay, abx, aby)
    return out


@dual_use
def _assess(t, geo, nov, sin_v, lobe, gx, gw):
    """(integral over t by its four children (two channels), error estimate
    |rule(t) - sum of rule(children)| of channel 0)."""
    p0, _ = _triangle_rule(t[0], t[1], t[2], t[3], t[4], t[5], geo, nov, sin_v, lobe, gx, gw)
    ch = _children(t)
    s0 = 0.0
    s1 = 0.0
    for k in range(4):
        a, b = _triangle_rule(ch[k, 0], ch[k, 1], ch[k, 2], ch[k, 3], ch[k, 4], ch[k, 5], geo, nov, sin_v, lobe,
                              gx, gw)
        s0 += a
        s1 += b
    return s0, s1, abs(p0 - s0)


#: Largest angle (radians) between the directions to two vertices of a triangle
#: of the initial subdivision.
_MAX_ANGLE = 0.3


@dual_use
def _angular_size(t, geo):
    """Largest angle between the directions from the origin to the vertices of
    triangle t (plane coordinates; ``geo`` = (o, u, w, delta))."""
    d = np.empty((3, 3))
    for k in range(3):
        x = t[2 * k]
        y = t[2 * k + 1]
        px = geo[0] + x * geo[3] + y * geo[6]
        py = geo[1] + x * geo[4] + y * geo[7]
        pz = geo[2] + x * geo[5] + y * geo[8]
        n = math.sqrt(px * px + py * py + pz * pz)
        d[k, 0] = px / n
        d[k, 1] = py / n
        d[k, 2] = pz / n
    smallest = 1.0
    for a in range(3):
        b = (a + 1) % 3
        smallest = min(smallest, d[a, 0] * d[b, 0] + d[a, 1] * d[b, 1] + d[a, 2] * d[b, 2])
    return math.acos(max(-1.0, min(1.0, smallest)))


#: The reflected lobe's width, in the plane of incidence, is about 2 alpha (radians)
#: about the mirror direction r, for GGX as for Beckmann (across it 2 alpha n.v: the
#: collapsed rule's nodes, clustered at the fan centre, and the adaptive refinement
#: resolve that).  The fan's triangles at a centre on the peak are split until they
#: span at most _PEAK_SIZE widths ...
_PEAK_SIZE = 2.0
#: ... and a peak outside the light but within _PEAK_REACH widths of its edge is taken
#: as on it (beyond, a Beckmann lobe is below e^-25 of its peak, and GGX's tail is
#: smooth on the triangles' scale).
_PEAK_REACH = 5.0


@kernel
def _rect_integral(corners, nov, roughness, codes, tol, max_triangles, gx, gw, out):
    """out = (integral of f (n.l) dl, integral of f Fc (n.l) dl, error estimate,
    triangles) over one light (module doc; :func:`lobe_rect_integrals`) for the
    lobe of perceptual roughness ``roughness`` and the code row ``codes`` (1,
    CODE_COLUMNS) (:func:`lobe_codes`)."""
    out[:] = 0.0
    lobe = _lobe_of(codes, roughness)
    c0 = corners[0]
    e1 = corners[1] - c0
    e3 = corners[3] - c0
    nl = np.cross(e1, e3)
    nn = math.sqrt(nl[0] * nl[0] + nl[1] * nl[1] + nl[2] * nl[2])
    if nn <= 0.0:
        return
    nl = nl / nn
    # one-sided: the origin must be on the lit side (nl . (0 - c0) > 0)
    delta = -(nl[0] * c0[0] + nl[1] * c0[1] + nl[2] * c0[2])
    if delta <= 0.0:
        return
    o = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3])
    u = e1 / math.sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2])
    w = np.cross(nl, u)
    geo = np.array([o[0], o[1], o[2], u[0], u[1], u[2], w[0], w[1], w[2], delta])
    # the light as a polygon in (x, y) plane coordinates, clipped to z > 0
    # (Sutherland-Hodgman against z(x, y) = o.z + x u.z + y w.z)
    poly = np.empty((8, 2))
    m = 0
    for k in range(4):
        ck = corners[k] - o
        kn = corners[(k + 1) % 4] - o
        xk = ck[0] * u[0] + ck[1] * u[1] + ck[2] * u[2]
        yk = ck[0] * w[0] + ck[1] * w[1] + ck[2] * w[2]
        xn = kn[0] * u[0] + kn[1] * u[1] + kn[2] * u[2]
        yn = kn[0] * w[0] + kn[1] * w[1] + kn[2] * w[2]
        zk = o[2] + xk * u[2] + yk * w[2]
        zn = o[2] + xn * u[2] + yn * w[2]
        if zk > 0.0:
            poly[m, 0] = xk
            poly[m, 1] = yk
            m += 1
        if (zk > 0.0) != (zn > 0.0):
            s = zk / (zk - zn)
            poly[m, 0] = xk + s * (xn - xk)
            poly[m, 1] = yk + s * (yn - yk)
            m += 1
    if m < 3:
        return
    # fan centre: where the mirror direction meets the light, if inside, else the closest
    # point of its edges if that is on the lobe's peak, else the centroid
    sin_v = math.sqrt(max(0.0, 1.0 - nov * nov))
    width = 2.0 * lobe.alpha  # the reflected lobe's angular width (module constants _PEAK_*)
    peak = False
    fx = 0.0
    fy = 0.0
    for k in range(m):
        fx += poly[k, 0] / m
        fy += poly[k, 1] / m
    rdn = -sin_v * nl[0] + nov * nl[2]
    if rdn < 0.0:  # the mirror ray meets the plane in front (nl points to the origin)
        s = -delta / rdn
        qx = -s * sin_v - o[0]
        qy = -o[1]
        qz = s * nov - o[2]
        px = qx * u[0] + qy * u[1] + qz * u[2]
        py = qx * w[0] + qy * w[1] + qz * w[2]
        inside = True
        orient = 0.0
        for k in range(m):
            ax, ay = poly[k, 0], poly[k, 1]
            bx, by = poly[(k + 1) % m, 0], poly[(k + 1) % m, 1]
            cr = (bx - ax) * (py - ay) - (by - ay) * (px - ax)
            if orient == 0.0:
                orient = 1.0 if cr > 0.0 else -1.0
            if cr * orient <= 1e-12 * ((bx - ax) ** 2 + (by - ay) ** 2):
                inside = False
        if inside:
            fx = px
            fy = py
            peak = True
        else:
            # the mirror direction misses the light: if the closest point of its boundary is
            # within _PEAK_REACH widths of it, the lobe's peak is at the edge; centre the fan there
            best = math.inf
            cx = fx
            cy = fy
            for k in range(m):
                ax, ay = poly[k, 0], poly[k, 1]
                ex, ey = poly[(k + 1) % m, 0] - ax, poly[(k + 1) % m, 1] - ay
                e2 = ex * ex + ey * ey
                f = 0.0 if e2 <= 0.0 else min(1.0, max(0.0, ((px - ax) * ex + (py - ay) * ey) / e2))
                d2 = (ax + f * ex - px) ** 2 + (ay + f * ey - py) ** 2
                if d2 < best:
                    best = d2
                    cx = ax + f * ex
                    cy = ay + f * ey
            dx = o[0] + cx * u[0] + cy * w[0]
            dy = o[1] + cx * u[1] + cy * w[1]
            dz = o[2] + cx * u[2] + cy * w[2]
            cos_r = (nov * dz - sin_v * dx) / math.sqrt(dx * dx + dy * dy + dz * dz)
            if math.acos(max(-1.0, min(1.0, cos_r))) <= _PEAK_REACH * width:
                fx = cx
                fy = cy
                peak = True
    # fan triangles from the centre, split until each spans at most _MAX_ANGLE as seen
    # from the shading point (so no feature of the integrand on the sphere is hidden
    # between the nodes of a huge triangle) and, when the centre is on the lobe's peak,
    # those at the centre (child 0 keeps it first) until they span at most _PEAK_SIZE
    # of the lobe's widths: a lobe much narrower than a triangle can fall between the
    # nodes of its rule and of its children's, and the error estimate would miss it
    # (Beckmann's lobe has no tail to give it away); then adaptively
    tris = np.empty((max_triangles, 6))
    vals = np.zeros((max_triangles, 2))
    errs = np.zeros(max_triangles)
    stack = np.empty((max_triangles, 6))
    top = 0
    for k in range(m):
        stack[top, :] = (fx, fy, poly[k, 0], poly[k, 1], poly[(k + 1) % m, 0], poly[(k + 1) % m, 1])
        top += 1
    count = 0
    while top > 0:
        top -= 1
        t = stack[top].copy()
        size = _angular_size(t, geo)
        at_peak = peak and t[0] == fx and t[1] == fy and size > _PEAK_SIZE * width
        if (size > _MAX_ANGLE or at_peak) and top + 4 <= max_triangles and count + top + 4 <= max_triangles:
            ch = _children(t)
            for k in range(4):
                stack[top, :] = ch[k]
                top += 1
        else:
            tris[count, :] = t
            count += 1
    heap = [(0.0, 0)]
    heap.pop()
    total0 = 0.0
    total1 = 0.0
    err_total = 0.0
    for i in range(count):
        a, b, e = _assess(tris[i], geo, nov, sin_v, lobe, gx, gw)
        vals[i, 0] = a
        vals[i, 1] = b
        errs[i] = e
        total0 += a
        total1 += b
        err_total += e
        heapq.heappush(heap, (-e, i))
    while count + 3 <= max_triangles and err_total > tol * abs(total0):
        _, i = heapq.heappop(heap)
        ch = _children(tris[i])
        total0 -= vals[i, 0]
        total1 -= vals[i, 1]
        err_total -= errs[i]
        for k in range(4):
            slot = i
            if k > 0:
                slot = count
                count += 1
            tris[slot, :] = ch[k]
            a, b, e = _assess(ch[k], geo, nov, sin_v, lobe, gx, gw)
            vals[slot, 0] = a
            vals[slot, 1] = b
            errs[slot] = e
            total0 += a
            total1 += b
            err_total += e
            heapq.heappush(heap, (-e, slot))
    out[0] = vals[:count, 0].sum()
    out[1] = vals[:count, 1].sum()
    out[2] = errs[:count].sum()
    out[3] = count


#: Gauss-Legendre points per axis of the collapsed triangle rule.
_RULE_POINTS = 5


@row_kernel(0)
def _rect_integrals(start, stop, corners, nov, roughness, codes, tol, max_triangles, gx, gw, out):
    """:func:`_rect_integral` of every light, in parallel."""
    for k in range(start, stop):
        one = np.zeros(4)
        _rect_integral(corners[k], nov[k], roughness[k], codes, tol, max_triangles, gx, gw, one)
        for c in range(4):
            out[k, c] = one[c]


def lobe_rect_integrals(nov, roughness, corners, distribution="ggx", masking="height-correlated",
                        tol=REFERENCE_TOLERANCE, max_triangles=40000, return_error=False):
    """(norm, fresnel) = (integral of f (n.l) dl, integral of f Fc (n.l) dl) over
    each rectangular light (unit radiance), f = D G2 / (4 n.l n.v) the
    Fresnel-free microfacet lobe of ``distribution`` (GGX, Walter et al. 2007, or
    Beckmann) and the Smith-family ``masking`` G2 (:data:`LTC_MASKINGS`;
    :func:`lobe_codes`), alpha = r^2 for both distributions
    (:func:`~pbrkit.microfacet.roughness.alpha_from_roughness`, at least 1e-3),
    evaluated by :func:`pbrkit.brdf.dispatch.specular_lobe` of a ``cook_torrance``
    BxDF (:func:`pbrkit.brdf.dispatch.make_bxdf`), Fc = (1 - v.h)^5, so that with
    Schlick's F (Schlick 1994) the radiance is f0 norm + (1 - f0) fresnel (the
    split of ltc_code's second table).

    ``nov`` (...), ``roughness`` (...) and ``corners`` (..., 4, 3) broadcast
    over the lights, in the local shading frame of the module doc.  Only the
    part of the light above the horizon (n.l > 0) counts, and nothing if the
    origin is behind the light (one-sided).

    Method: the integral is taken over the light's plane with the
    area-to-solid-angle Jacobian dl = delta / |p|^3 dA (delta the plane's
    distance), over the rectangle clipped to z > 0 (Sutherland-Hodgman), split
    into a fan of triangles about the point where the mirror direction meets
    the light (else the closest point of its edges when that is within 5 lobe
    widths, 2 alpha, of the mirror direction, else the centroid) so that the
    lobe's peak is a vertex, split until no triangle spans more than 0.3 rad as
    seen from the shading point and those at a centre on the peak no more than
    two lobe widths (a lobe without a tail, Beckmann's, could otherwise fall
    between the nodes of a triangle and of its children, unseen by the error
    estimate); then globally adaptive cubature: a 5 x 5 collapsed
    Gauss-Legendre rule per triangle (degree 9), the error of a triangle
    estimated as |rule(T) - sum of rule(children)|, and the triangle with
    the largest estimate split into four until the summed estimate is below
    ``tol`` times the integral (or ``max_triangles`` are used).  The estimate
    is conservative (it bounds the error of the parents, the sum of the
    children is returned): at the default tol = 1e-6 the result agrees with a
    run at tol = 1e-9 to 1e-6 (tested; typically 1e-8), with Monte Carlo within its
    standard error for GGX and with a composite Gauss-Legendre rule over the
    rectangle for Beckmann and separable Smith (``tests/test_ltc_score.py``), so
    the reference is converged to 1e-4 relative with a wide margin.

    Returns (..., 2); with ``return_error`` also the summed error estimate
    (...) of channel 0 and the triangle count (...).
    """
    codes = lobe_codes(distribution, masking)
    nov, roughness, corners, shape = _check_lights(nov, roughness, corners)
    gx, gw = gauss_legendre_01(_RULE_POINTS)
    flat_c = np.ascontiguousarray(corners.reshape(-1, 4, 3))
    flat_mu = np.ascontiguousarray(nov.reshape(-1), dtype=np.float64)
    flat_r = np.ascontiguousarray(roughness.reshape(-1), dtype=np.float64)
    result = np.zeros((flat_c.shape[0], 4))
    _rect_integrals(flat_c, flat_mu, flat_r, codes, float(tol), int(max_triangles), gx, gw, result)
    values = result[:, :2].reshape(shape + (2,))
    if return_error:
        return values, result[:, 2].reshape(shape), result[:, 3].astype(np.int64).reshape(shape)
    return values


def lobe_rect_reference(nov, roughness, corners, f0=1.0, distribution="ggx", masking="height-correlated",
                        tol=REFERENCE_TOLERANCE):
    """The reflected radiance of a unit-radiance rectangular light off the
    specular lobe of ``distribution`` and ``masking`` with Schlick's F of ``f0``
    (1: F = 1): f0 norm + (1 - f0) fresnel of :func:`lobe_rect_integrals` (its
    arguments and accuracy)."""
    pair = lobe_rect_integrals(nov, roughness, corners, distribution, masking, tol=tol)
    return f0 * pair[..., 0] + (1.0 - f0) * pair[..., 1]


def ggx_rect_integrals(nov, roughness, corners, tol=REFERENCE_TOLERANCE, max_triangles=40000, return_error=False):
    """:func:`lobe_rect_integrals` of the default lobe: GGX (alpha = r^2) with
    height-correlated Smith G2 (Heitz 2014, eq. 99)."""
    return lobe_rect_integrals(nov, roughness, corners, "ggx", "height-correlated", tol=tol,
                               max_triangles=max_triangles, return_error=return_error)


def ggx_rect_reference(nov, roughness, corners, f0=1.0, tol=REFERENCE_TOLERANCE):
    """:func:`lobe_rect_reference` of GGX with height-correlated Smith."""
    return lobe_rect_reference(nov, roughness, corners, f0, "ggx", "height-correlated", tol=tol)


#: Gauss-Legendre nodes (theta_h, phi) of :func:`lobe_split_integrals`'s half-vector
#: quadrature (:func:`pbrkit.albedo.furnace.albedo_quadrature`): converged to about
#: 1e-9 relative for Beckmann and UE4's Schlick-GGX from n.v = 1 to 8.7e-4 (the
#: fit's grazing row) and alpha from 1e-3 to 1, against 256 x 96 nodes.
ALBEDO_NODES = (96, 48)
#: Nodes of :func:`pbrkit.albedo.tables.specular_integrals` (theta, grazing theta,
#: phi) for the GGX lobes it has: converged to 3e-8 relative over the same range
#: (its default (12, 24, 6), for lookup tables, is good to ~5e-5).
TABLE_NODES = (48, 96, 24)


def _furnace_lobe(distribution, masking):
    """``brdf(l, v, n, r)`` of :func:`pbrkit.albedo.furnace.albedo_quadrature` with two
    channels, f (1 - Fc) and f Fc, Fc = (1 - v.h)^5: ``cook_torrance`` (NumPy API,
    :func:`pbrkit.brdf.models.cook_torrance`) with Schlick's F for a white metal
    (F = 1) minus that for a black one (F = Fc), and the latter."""
    from ..brdf.material import Material
    from ..brdf.models import cook_torrance

    def brdf(l, v, n, roughness):
        def lobe(base):
            material = Material(base_color=np.full(3, base), metallic=1.0, roughness=roughness)
            return cook_torrance(l, v, n, material, distribution=distribution, masking=masking, fresnel="schlick",
                                 diffuse="none")[..., 0]

        fc = lobe(0.0)
        return np.stack([lobe(1.0) - fc, fc], axis=-1)

    return brdf


def lobe_split_integrals(nov, roughness, distribution="ggx", masking="height-correlated"):
    """(A, B) = (integral of f (1 - Fc) (n.l) dl, integral of f Fc (n.l) dl) over the
    hemisphere, the split integrals of the directional albedo f0 A + B with
    Schlick's F (Karis 2013), for the lobe of :func:`lobe_rect_integrals` (the
    same alpha = max(r^2, 1e-3)), per (n.v, r) pair (...) -> (..., 2), by
    converged quadrature over the half vector:

    - where :func:`pbrkit.albedo.tables.specular_integrals` has the lobe (GGX
      with height-correlated, separable or Schlick-GGX (k = alpha / 2) masking),
      that, with :data:`TABLE_NODES` and at roughness sqrt(max(r^2, 1e-3)) (the
      tables themselves do not clamp alpha);
    - otherwise (Beckmann; UE4's k = (r + 1)^2 / 8),
      :func:`pbrkit.albedo.furnace.albedo_quadrature` of the ``cook_torrance``
      lobe (:func:`pbrkit.brdf.models.cook_torrance`; nodes :data:`ALBEDO_NODES`).

    Both agree with the sum of :func:`lobe_rect_integrals` over the six faces of
    a cube about the shading point (tested) wherever that cubature converges."""
    lobe_codes(distribution, masking)  # checks the pair
    nov, roughness = np.broadcast_arrays(np.asarray(nov, dtype=float), np.asarray(roughness, dtype=float))
    out = np.empty(nov.shape + (2,))
    flat_out = out.reshape(-1, 2)
    flat_mu = nov.reshape(-1)
    flat_r = roughness.reshape(-1)
    if distribution == "ggx" and masking in VISIBILITIES:
        r_alpha = np.sqrt(alpha_from_roughness(flat_r))  # table_alpha(r_alpha) = alpha_from_roughness(r)
        for r in np.unique(r_alpha):
            at = np.flatnonzero(r_alpha == r)
            flat_out[at] = specular_integrals(flat_mu[at], [r], masking, nodes=TABLE_NODES)[0]
        return out
    from ..albedo.furnace import albedo_quadrature

    brdf = _furnace_lobe(distribution, masking)
    for r in np.unique(flat_r):
        at = np.flatnonzero(flat_r == r)
        flat_out[at] = albedo_quadrature(brdf, flat_mu[at], [r], *ALBEDO_NODES)[:, 0]
    return out


# --------------------------------------------------- the shader's evaluation


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
    (..., 4, 3) broadcast as in :func:`ggx_rect_integrals`; ``f0`` broadcasts
    too.  Computed in float64 (a GPU uses float32: differences ~1e-6
    relative).  Returns (...)."""
    table = ltc1 if isinstance(ltc1, LTCTable) else ltc_table_from_published_layout(ltc1, ltc2)
    nov, roughness, corners, shape = _check_lights(nov, roughness, corners)
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
    nov, roughness, corners, shape = _check_lights(nov, roughness, corners)
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
    nov, roughness, corners, shape = _check_lights(nov, roughness, corners)
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


# ------------------------------------------------------------------ test set


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


# ------------------------------------------------------------------- scoring


def directional_albedo(nov, roughness, f0=1.0, distribution="ggx", masking="height-correlated"):
    """The specular directional albedo E(n.v, r) = f0 A + B of the lobe of
    ``distribution`` and ``masking`` (default GGX with height-correlated Smith)
    and Schlick F (:func:`lobe_split_integrals`, converged quadrature), per
    (n.v, r) pair (...)."""
    ab = lobe_split_integrals(nov, roughness, distribution, masking)
    return f0 * ab[..., 0] + ab[..., 1]


@dataclass
class LTCScore:
    """Per-light results of :func:`score_table` and their summary."""

    reference: np.ndarray
    ltc: np.ndarray
    albedo: np.ndarray
    relative: np.ndarray  # |ltc - ref| / ref, NaN where ref <= threshold * albedo
    absolute_over_albedo: np.ndarray  # |ltc - ref| / albedo, every light
    summary: dict = field(default_factory=dict)


def _summary(rel, abs_alb, ref, ltc, used):
    r = rel[used]
    return {
        "lights": int(rel.size),
        "scored": int(used.sum()),
        "relative_median": float(np.median(r)) if r.size else float("nan"),
        "relative_mean": float(np.mean(r)) if r.size else float("nan"),
        "relative_p95": float(np.percentile(r, 95)) if r.size else float("nan"),
        "relative_max": float(np.max(r)) if r.size else float("nan"),
        "ltc_zero_share": float(np.mean(ltc[used] <= 0.0)) if r.size else float("nan"),
        "abs_over_albedo_mean": float(np.mean(abs_alb)),
        "abs_over_albedo_median": float(np.median(abs_alb)),
        "abs_over_albedo_p95": float(np.percentile(abs_alb, 95)),
        "abs_over_albedo_max": float(np.max(abs_alb)),
    }


def score_table(ltc1, ltc2, lights, f0=1.0, reference=None, threshold=RELATIVE_THRESHOLD, evaluation="shader",
                distribution="ggx", masking="height-correlated", fresnel_ltc1=None):
    """Score LTC tables in the published layout on ``lights`` (:class:`RectLights`)
    with Schlick's F of ``f0`` (1: F = 1): the shader's radiance
    (:func:`ltc_shader_rect`) against the converged reference of the lobe of
    ``distribution`` and ``masking`` (:func:`lobe_rect_reference`; pass
    ``reference`` (K,) to reuse one, computed for the same lobe).

    Per light: the relative error |ltc - ref| / ref, over the lights whose
    reference exceeds ``threshold`` times the directional albedo
    E(n.v, r) of the same lobe and f0 (:func:`directional_albedo`; NaN elsewhere), and
    the absolute error over that albedo, |ltc - ref| / E, over every light.
    ``summary``: the count scored, median, mean, 95th percentile and maximum
    of the relative errors (percentiles by linear interpolation, NumPy's
    default), the share of scored lights where the LTC is 0, and the mean,
    median, 95th percentile and maximum of the absolute errors over the
    albedo.  ``evaluation``: ``shader`` (:func:`ltc_shader_rect`, what engines run)
    or ``exact`` (:func:`ltc_exact_rect`); with ``fresnel_ltc1`` (the matrices of
    the f Fc lobe) ``exact`` is the Fresnel-aware :func:`ltc_fresnel_rect`.
    Returns :class:`LTCScore`."""
    table = ltc1 if isinstance(ltc1, LTCTable) else ltc_table_from_published_layout(ltc1, ltc2)
    lobe_codes(distribution, masking)
    if reference is None:
        reference = lobe_rect_reference(lights.nov, lights.roughness, lights.corners, f0, distribution, masking)
    reference = np.asarray(reference, dtype=float)
    if fresnel_ltc1 is not None:
        if evaluation != "exact":
            raise ValueError("the Fresnel-aware LTC is evaluated with the exact clipping (evaluation='exact')")
        ltc = ltc_fresnel_rect(table, None, fresnel_ltc1, lights.nov, lights.roughness, lights.corners, f0=f0)
    else:
        evaluate = ltc_exact_rect if evaluation == "exact" else ltc_shader_rect
        ltc = evaluate(table, None, lights.nov, lights.roughness, lights.corners, f0=f0)
    albedo = directional_albedo(lights.nov, lights.roughness, f0, distribution, masking)
    used = reference > threshold * albedo
    diff = np.abs(ltc - reference)
    rel = np.where(used, diff / np.where(used, reference, 1.0), np.nan)
    abs_alb = diff / albedo
    return LTCScore(reference, ltc, albedo, rel, abs_alb, _summary(rel, abs_alb, reference, ltc, used))


# --------------------------------------------------------- published tables


#: Where :func:`published_table` looks for three.js's npm package, relative to
#: the repository root (the pinned engines of ``tests/engines``) and to the
#: working directory.
#: Largest JavaScript file searched for the published tables (three.js's are about 80 KiB).
_MAX_JS_BYTES = 16 << 20
_THREE_FILES = ("examples/jsm/lights/RectAreaLightTexturesLib.js", "examples/jsm/lights/RectAreaLightUniformsLib.js")
_REPOSITORY = Path(__file__).resolve().parents[min(3, len(Path(__file__).resolve().parents) - 1)]


def published_table_path(path=None):
    """The three.js file that holds ``LTC_MAT_1`` / ``LTC_MAT_2``: ``path`` (that
    file, the ``three`` package folder or a ``node_modules`` folder), else the
    first found of ``tests/engines/node_modules/three`` in the repository
    (``npm ci --prefix tests/engines``) and ``node_modules/three`` in the
    working directory.  three r150+ keeps the arrays in
    ``RectAreaLightTexturesLib.js``, older releases in
    ``RectAreaLightUniformsLib.js``.  Raises FileNotFoundError naming where it
    looked."""
    if path is not None:
        p = Path(path)
        if p.exists() and not p.is_dir():
            check_regular(p, "three.js's LTC data (a JavaScript file, or the three package's folder)")
        candidates = [p] if p.is_file() else [p / "three", p]
    else:
        candidates = [_REPOSITORY / "tests/engines/node_modules/three", Path.cwd() / "node_modules/three"]
    looked = []
    for base in candidates:
        files = [base] if base.is_file() else [base / f for f in _THREE_FILES]
        for f in files:
            looked.append(str(f))
            if f.is_file() and "LTC_MAT_1" in read_bytes(f, _MAX_JS_BYTES, "a JavaScript file").decode(
                    "utf-8", errors="replace"):
                return f
    raise FileNotFoundError("the published LTC tables (three.js's LTC_MAT_1 / LTC_MAT_2) were not found; install "
                            "three (npm ci --prefix tests/engines) or pass its path; looked in: " + ", ".join(looked))


def published_table(path=None):
    """The LTC tables of Heitz, Dupuy, Hill and Neubelt 2016 (``ltc_code``
    ``fit/results/ltc.js``) as three.js ships them: ``LTC_MAT_1`` and
    ``LTC_MAT_2`` read from its npm package at run time
    (:func:`published_table_path`; MIT licensed, not bundled with pbrkit), as
    two float32 arrays (64, 64, 4) indexed [t, a, c], the order three
    uploads them in (a ``DataTexture`` 64 wide: row t, column a).  Values
    are rounded to float32 as three's ``Float32Array`` does."""
    f = published_table_path(path)
    text = read_text(f, _MAX_JS_BYTES, "three.js's LTC data (a JavaScript file with LTC_MAT_1 and LTC_MAT_2)")
    out = []
    for name in ("LTC_MAT_1", "LTC_MAT_2"):
        match = re.search(name + r"\s*=\s*\[([^\]]*)\]", text)
        if match is None:
            raise ValueError(f"{f}: no {name} array")
        try:
            values = np.array([float(x.replace(" ", "")) for x in match.group(1).split(",") if x.strip()],
                              dtype=np.float64)
        except ValueError:
            raise ValueError(f"{f}: {name} holds something other than numbers") from None
        if values.size != LUT_SIZE * LUT_SIZE * 4:
            raise ValueError(f"{f}: {name} has {values.size} values, expected {LUT_SIZE * LUT_SIZE * 4}")
        out.append(values.astype(np.float32).reshape(LUT_SIZE, LUT_SIZE, 4))
    return out[0], out[1]
