"""The ground truth LTC tables are scored and fitted against: the converged
integral of a microfacet lobe (GGX by default, or Beckmann; a Smith-family
masking) over rectangular lights, and the same lobe's directional albedo.

Heitz, Dupuy, Hill and Neubelt 2016, "Real-Time Polygonal-Light Shading with
Linearly Transformed Cosines" (ACM TOG 35(4), SIGGRAPH 2016; code and tables:
``selfshadow/ltc_code``) approximate the specular lobe of a view direction and
roughness by a clamped cosine D_o under a linear transform M, so that the
lobe's integral over a polygon P is the cosine's integral over M^-1 P, in
closed form, times the lobe's norm (its directional albedo).  This module
computes what that approximates, without it.  Frame and lights:
:mod:`pbrkit.ltc.lights`.

- :data:`LTC_DISTRIBUTIONS`, :data:`MASKINGS_FOR`, :func:`lobe_codes`: the lobes
  (GGX or Beckmann, alpha = r^2 for both; height-correlated or separable Smith,
  or for GGX Schlick-GGX);
- :func:`lobe_rect_integrals` / :func:`lobe_rect_reference`: the integral over
  a light of the lobe with Schlick F, evaluated by
  :mod:`pbrkit.brdf.dispatch`'s own ``specular_lobe`` (one code path for every
  lobe), by adaptive cubature in the light's plane, clipped at the horizon;
  converged to 1e-6 relative by its own estimate and tested against Monte Carlo
  and a composite Gauss-Legendre rule.  :func:`ggx_rect_integrals` /
  :func:`ggx_rect_reference` are the default lobe's, GGX with height-correlated
  Smith;
- :func:`lobe_split_integrals` / :func:`directional_albedo`: the same lobe's
  converged albedo.
"""

from __future__ import annotations

import heapq
import math

import numpy as np

from ..albedo.tables import VISIBILITIES, specular_integrals
from ..brdf.bxdf import isotropic_cosines
from ..brdf.dispatch import make_bxdf, specular_lobe
from ..brdf.fresnel import f_schlick
from ..brdf.models import model_codes
from ..brdf.shading.registry import LAYOUT
from ..core.jit import dual_use, kernel, row_kernel
from ..core.quadrature import gauss_legendre_01
from ..microfacet.roughness import alpha_from_roughness
from .lights import check_lights

#: The packed parameter row's length (a constant for the compiled kernels).
_PARAMETER_COLUMNS = LAYOUT.size

__all__ = ["REFERENCE_TOLERANCE", "LTC_DISTRIBUTIONS", "LTC_MASKINGS", "MASKINGS_FOR", "ALBEDO_NODES",
           "TABLE_NODES", "lobe_codes", "lobe_name", "lobe_rect_integrals", "lobe_rect_reference",
           "ggx_rect_integrals", "ggx_rect_reference", "lobe_split_integrals", "directional_albedo"]

#: Relative accuracy the reference cubature is run to by default (its own,
#: conservative error estimate; the tests check it against 4x tighter runs and
#: against Monte Carlo).
REFERENCE_TOLERANCE = 1e-6


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
    rectangle for Beckmann and separable Smith (``tests/ltc/test_ltc_reference.py``), so
    the reference is converged to 1e-4 relative with a wide margin.

    Returns (..., 2); with ``return_error`` also the summed error estimate
    (...) of channel 0 and the triangle count (...).
    """
    codes = lobe_codes(distribution, masking)
    nov, roughness, corners, shape = check_lights(nov, roughness, corners)
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


def directional_albedo(nov, roughness, f0=1.0, distribution="ggx", masking="height-correlated"):
    """The specular directional albedo E(n.v, r) = f0 A + B of the lobe of
    ``distribution`` and ``masking`` (default GGX with height-correlated Smith)
    and Schlick F (:func:`lobe_split_integrals`, converged quadrature), per
    (n.v, r) pair (...)."""
    ab = lobe_split_integrals(nov, roughness, distribution, masking)
    return f0 * ab[..., 0] + ab[..., 1]
