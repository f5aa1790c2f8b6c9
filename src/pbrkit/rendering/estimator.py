"""The Monte Carlo estimator of the ground truth (:mod:`pbrkit.rendering.reference`),
written once as small scalar functions that every engine schedules: the fused
kernel and the wavefront loop call them one sample at a time
(:func:`pbrkit.rendering.vertex._vertex`), the lane kernel in loops over lanes
(:mod:`pbrkit.rendering.lanes`).  They take scalars, tuples and the material's
:class:`pbrkit.brdf.bxdf.BxDF`, never arrays, and are inlined where they are called
(Numba IR, ``dual_use(inline=True)``), so that a loop over lanes that calls them
keeps no call (nor reference counting) and LLVM vectorises it.  Each computes
everything first and picks its result with one branch at the end, which LLVM turns
into selects in such a loop; in between, a division may meet a zero pdf, so they
need NumPy's error model (inf or NaN, which the checks discard), as pbrkit's
kernels have (:mod:`pbrkit.core.jit`).  A scalar engine may skip a call whose
result it knows to be zero (a light sample below the surface).

Direct lighting at a shading point
----------------------------------

All vectors are unit vectors in world space at the shading point; n is the shading
normal, (t, b) its tangent frame, g the geometric normal, v towards the eye::

           l_L (light sample)      n       l_B (BSDF sample)
               .                   ^                .
                 .                 |              .
                   .               |            .       v
                     .             |          .      .
                       .           |        .     .
                         .         |      .    .
         ------------------------- o ----------------------- surface (g)

- a light sample l_L ~ p_L: from the environment's alias table over texels,
  p_L = func(i, j) / total per solid angle (:mod:`pbrkit.rendering.environment`), or
  a point on one of the A area lights, picked with probability 1 / A,
  p_L = p_area(l) / A (:mod:`pbrkit.rendering.area_lights`), with its radiance L(l_L);
- a BSDF sample l_B ~ p_B (:func:`pbrkit.brdf.bxdf.sample_wi` in the local frame,
  v_local = (v.t, v.b, v.n), then l = t l_x + b l_y + n l_z, normalised): with
  probability P_s the mirror image of v about a GGX visible normal h,
  l = 2 (v.h) h - v, with probability P_c about a GTR1 normal (Disney's clear
  coat), else cosine-weighted::

                  D_v(h)               D_c(h) <n.h>                  <n.l>
      p_B(l) = P_s --------  +  P_c  ------------  +  (1 - P_s - P_c) -----
                  4 <v.h>                4 <v.h>                        pi

  (:func:`pbrkit.brdf.bxdf.bxdf_pdf`; the 1 / (4 v.h) is the Jacobian of the
  reflection l = reflect(-v, h));
- each sample is weighted against the other strategy by the power heuristic
  (beta = 2; Veach 1997, sec. 9.2.4; :func:`power_heuristic`)::

                     p_L(l)^2                          p_B(l)^2
      w_L(l) = -------------------- ,      w_B(l) = --------------------
                p_L(l)^2 + p_B(l)^2                  p_B(l)^2 + p_L(l)^2

  and BSDF sampling alone (strategy ``brdf``) takes no light sample and w_B = 1.

A sample of the pixel is then, with V the visibility (the shadow rays, which the
engines trace) and L_e the emission and punctual lights, the deterministic part::

    +-------------------------------------------------------------------------------------------+
    |            f(v, l_L) L(l_L) <n.l_L>                f(v, l_B) <n.l_B>                      |
    |  x = L_e + ------------------------ w_L V(l_L)  +  ----------------- w_B L(l_B) V(l_B)    |
    |                    p_L(l_L)                            p_B(l_B)                           |
    +-------------------------------------------------------------------------------------------+

with f the BRDF (:func:`pbrkit.brdf.bxdf.bxdf_f`; not f cos) and L(l_B) what the
BSDF sample meets: the environment or an area light (their w_B needs p_L at l_B:
:func:`emission_weight`, :func:`area_emission`), or a surface, whose emission
(weight 1: no light sampling aims at it) and, with ``bounces`` > 0, whose own
sample x continue the path with the throughput f <n.l_B> / p_B.  Samples with
g.l <= 0, n.l <= 0 or a zero pdf contribute nothing.

- :func:`light_sample`: the second term without V (the environment's or an area
  light's sample);
- :func:`bsdf_sample`: l_B, the weight f <n.l_B> / p_B and p_B (:func:`bsdf_weight`
  after :func:`pbrkit.brdf.bxdf.sample_wi`, and :func:`view_in_frame`);
- :func:`emission_weight`, :func:`area_emission`: w_B where the BSDF sample meets a
  light.

Transmission (``KHR_materials_transmission``, ``KHR_materials_volume``)
-------------------------------------------------------------------------

A material that transmits (:func:`pbrkit.brdf.transmission.transmissive_material`) has a
BSDF on both sides of the surface; its vertices use :func:`transmissive_light_sample`
and :func:`transmissive_bsdf_sample` in place of the two above: the same estimator
with f the BSDF (:func:`pbrkit.brdf.transmission.transmissive_f`), |n.l| for <n.l>,
the mixture pdf of :func:`pbrkit.brdf.transmission.transmissive_pdf` (reflection and
transmission techniques) in the MIS weights, and l on either side of the surface
(a light sample from below is lit through it), so long as the geometric and the
shading normal put l on the same side (else nothing: no light leaks).  The normals
of a volume's boundary stay outward (the volume README: doubleSided has no effect
there), so the side of the view says whether a path enters or leaves.  A smooth
interface's refraction is a Dirac delta: its sample's pdf is
:data:`pbrkit.brdf.transmission.DELTA_PDF`, which gives it MIS weight 1 where it meets a
light (no light sample can reach it).  Rays leave from just off the surface on the
side they go to (:func:`ray_origin`), and the engines multiply the throughput of a
path segment inside a volume by its Beer-Lambert transmittance
(:func:`pbrkit.brdf.transmission.absorption`).

The pixel's estimate and standard error from its samples are
:mod:`pbrkit.rendering.film`'s.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ..brdf.dispatch import bxdf_f, bxdf_pdf, sample_wi
from ..brdf.transmission import transmissive_f, transmissive_pdf, transmissive_sample
from ..core.jit import dual_use
from .area_lights import area_light_pdf
from .materials import hit_cosines

__all__ = ["STRATEGIES", "STRATEGY_MIS", "STRATEGY_BSDF", "Shading", "power_heuristic", "light_sample",
           "view_in_frame", "bsdf_weight", "bsdf_sample", "emission_weight", "area_emission", "area_shadow_t",
           "transmissive_light_sample", "transmissive_bsdf_sample", "ray_origin"]

#: The sampling strategies of :func:`pbrkit.rendering.reference.render_reference`: both
#: light and BSDF samples combined by MIS, or BSDF sampling alone.
STRATEGIES = ("mis", "brdf")
STRATEGY_MIS = STRATEGIES.index("mis")
STRATEGY_BSDF = STRATEGIES.index("brdf")


class Shading(NamedTuple):
    """A shading point as the estimator sees it (world space, unit vectors): the shading
    normal ``n``, tangent ``t`` and bitangent ``bt`` of its frame
    (:func:`pbrkit.rendering.materials.hit_bxdf`), the geometric normal ``g`` and the
    direction ``v`` towards the eye, each an (x, y, z) tuple."""

    n: tuple
    t: tuple
    bt: tuple
    g: tuple
    v: tuple


@dual_use(inline=True)
def power_heuristic(pa, pb):
    """Veach 1997, sec. 9.2.4: w = pa^2 / (pa^2 + pb^2) (beta = 2), 0 where both are 0."""
    a = pa * pa
    b = pb * pb
    if a + b <= 0.0:
        return 0.0
    return a / (a + b)


@dual_use(inline=True)
def light_sample(b, s, p_spec, p_coat, lx, ly, lz, pdf_l, r0, r1, r2):
    """The contribution w_L f(v, l) L <n.l> / p_L of a light sample (module docstring),
    unshadowed: direction l (unit, world), its light-sampling pdf ``pdf_l`` (solid
    angle) and radiance (r0, r1, r2), for the BxDF ``b`` at :class:`Shading` ``s``
    sampled with lobe probabilities (p_spec, p_coat)
    (:func:`pbrkit.brdf.bxdf.lobe_probabilities`).  Zero unless pdf_l > 0, g.l > 0
    and n.l > 0: everything is computed first and one branch picks the result, which
    LLVM turns into selects in a loop over lanes."""
    n = s.n
    v = s.v
    g = s.g
    cs = hit_cosines(b, n[0], n[1], n[2], s.t, s.bt, v[0], v[1], v[2], lx, ly, lz)
    f = bxdf_f(b, cs, 1.0, 1.0, 1.0)
    pdf_b = bxdf_pdf(b, cs, p_spec, p_coat)
    w = power_heuristic(pdf_l, pdf_b) * cs.nol / pdf_l
    if (pdf_l > 0.0) & (g[0] * lx + g[1] * ly + g[2] * lz > 0.0) & (cs.nol > 0.0):
        return f[0] * r0 * w, f[1] * r1 * w, f[2] * r2 * w
    return 0.0, 0.0, 0.0


@dual_use(inline=True)
def view_in_frame(s):
    """(v.t, v.b, n.v): the view in the local frame of :class:`Shading` ``s``, as
    :func:`pbrkit.brdf.bxdf.sample_wi` takes it."""
    n = s.n
    t = s.t
    bt = s.bt
    vx, vy, vz = s.v
    nov = n[0] * vx + n[1] * vy + n[2] * vz
    wox = vx * t[0] + vy * t[1] + vz * t[2]
    woy = vx * bt[0] + vy * bt[1] + vz * bt[2]
    return wox, woy, nov


@dual_use(inline=True)
def bsdf_weight(b, s, p_spec, p_coat, llx, lly, llz):
    """The BSDF sample of the local direction (llx, lly, llz) that
    :func:`pbrkit.brdf.bxdf.sample_wi` drew with lobe probabilities (p_spec, p_coat):
    (direction l (world, normalised), weight f <n.l> / p_B (3), p_B).  Where the
    sample gives nothing (zero length, g.l <= 0, n.l <= 0 or p_B <= 0) the normal,
    a zero weight and a zero pdf.  Below the surface it returns before evaluating the
    BxDF (the scalar engines skip that work; in a loop over lanes both ways become
    selects, as in :func:`light_sample`)."""
    nx, ny, nz = s.n
    tx, ty, tz = s.t
    bx, by, bz = s.bt
    g = s.g
    v = s.v
    lx = llx * tx + lly * bx + llz * nx
    ly = llx * ty + lly * by + llz * ny
    lz = llx * tz + lly * bz + llz * nz
    norm = math.sqrt(lx * lx + ly * ly + lz * lz)
    lx /= norm
    ly /= norm
    lz /= norm
    if not ((norm > 0.0) & (g[0] * lx + g[1] * ly + g[2] * lz > 0.0)):  # nothing to evaluate
        return (nx, ny, nz), (0.0, 0.0, 0.0), 0.0
    cs = hit_cosines(b, nx, ny, nz, s.t, s.bt, v[0], v[1], v[2], lx, ly, lz)
    pdf_b = bxdf_pdf(b, cs, p_spec, p_coat)
    f = bxdf_f(b, cs, 1.0, 1.0, 1.0)
    k = cs.nol / pdf_b
    if (cs.nol > 0.0) & (pdf_b > 0.0):
        return (lx, ly, lz), (f[0] * k, f[1] * k, f[2] * k), pdf_b
    return (nx, ny, nz), (0.0, 0.0, 0.0), 0.0


@dual_use(inline=True)
def bsdf_sample(b, s, p_spec, p_coat, u_lobe, u1, u2):
    """A BSDF sample (module docstring) at :class:`Shading` ``s``: ``u_lobe`` picks the
    lobe with probabilities (p_spec, p_coat), (u1, u2) the direction in it
    (:func:`pbrkit.brdf.bxdf.sample_wi`); returns :func:`bsdf_weight`'s (direction,
    weight f <n.l> / p_B, p_B)."""
    wox, woy, nov = view_in_frame(s)
    llx, lly, llz = sample_wi(b, wox, woy, nov, u_lobe, u1, u2, p_spec, p_coat)
    return bsdf_weight(b, s, p_spec, p_coat, llx, lly, llz)


@dual_use(inline=True)
def emission_weight(strategy, pdf_b, pdf_light):
    """MIS weight w_B of a BSDF sample (pdf ``pdf_b``) that meets a light whose
    light-sampling pdf there is ``pdf_light`` (the environment's, or an area light's
    over the A lights): the power heuristic, or 1 for BSDF sampling alone."""
    w = 1.0
    if strategy == STRATEGY_MIS:
        w = power_heuristic(pdf_b, pdf_light)
    return w


@dual_use
def area_shadow_t(dist):
    """How far the shadow ray towards an area light's sample at distance ``dist`` looks
    for blockers (V(l_L) of the module docstring; short of the light itself)."""
    return dist * (1.0 - 1e-6)


@dual_use
def area_emission(strategy, pdf_b, area, li, px, py, pz, dx, dy, dz, t, r0, r1, r2):
    """Radiance (r0, r1, r2) of area light ``li`` of ``area``
    (:class:`pbrkit.rendering.records.AreaArrays`), met at distance t by the BSDF sample
    d (pdf ``pdf_b``) from p, times its MIS weight (:func:`emission_weight`; the light
    is sampled with probability 1 / A, then by
    :func:`pbrkit.rendering.area_lights.area_light_pdf`)."""
    pdf_a = 0.0
    if strategy == STRATEGY_MIS:
        pdf_a = area_light_pdf(area.codes, area.values, area.vertices, li, px, py, pz, dx, dy, dz,
                               t) / area.codes.shape[0]
    w = emission_weight(strategy, pdf_b, pdf_a)
    return r0 * w, r1 * w, r2 * w



@dual_use(inline=True)
def _local(s, x, y, z):
    t = s.t
    bt = s.bt
    n = s.n
    return x * t[0] + y * t[1] + z * t[2], x * bt[0] + y * bt[1] + z * bt[2], x * n[0] + y * n[1] + z * n[2]


@dual_use(inline=True)
def transmissive_light_sample(b, s, p_t, p_spec, p_coat, lx, ly, lz, pdf_l, r0, r1, r2):
    """:func:`light_sample` for a transmissive BxDF (module docstring): w_L f(v, l) L |n.l|
    / p_L with l on either side, the mixture pdf of
    :func:`pbrkit.brdf.transmission.transmissive_pdf` (probabilities (p_t, p_spec,
    p_coat) of :func:`pbrkit.brdf.transmission.transmissive_probabilities`) in the
    weight; zero unless pdf_l > 0 and l is on the same side of the geometric and the
    shading normal."""
    g = s.g
    v = s.v
    wox, woy, woz = _local(s, v[0], v[1], v[2])
    wix, wiy, wiz = _local(s, lx, ly, lz)
    f = transmissive_f(b, wox, woy, woz, wix, wiy, wiz)
    pdf_b = transmissive_pdf(b, wox, woy, woz, wix, wiy, wiz, p_t, p_spec, p_coat)
    w = power_heuristic(pdf_l, pdf_b) * abs(wiz) / pdf_l
    gl = g[0] * lx + g[1] * ly + g[2] * lz
    if (pdf_l > 0.0) & (gl * wiz > 0.0):
        return f[0] * r0 * w, f[1] * r1 * w, f[2] * r2 * w
    return 0.0, 0.0, 0.0


@dual_use(inline=True)
def transmissive_bsdf_sample(b, s, p_t, p_spec, p_coat, u_lobe, u1, u2):
    """:func:`bsdf_sample` for a transmissive BxDF: (direction l (world), weight
    f |n.l| / p_B (3), p_B) of :func:`pbrkit.brdf.transmission.transmissive_sample`, l
    on either side (:data:`pbrkit.brdf.transmission.DELTA_PDF` for a smooth interface's
    refraction); the normal, a zero weight and a zero pdf where the sample gives
    nothing (or the geometric and shading normals disagree on its side)."""
    nx, ny, nz = s.n
    tx, ty, tz = s.t
    bx, by, bz = s.bt
    g = s.g
    v = s.v
    wox, woy, woz = _local(s, v[0], v[1], v[2])
    llx, lly, llz, w, pdf_b = transmissive_sample(b, wox, woy, woz, u_lobe, u1, u2, p_t, p_spec, p_coat)
    lx = llx * tx + lly * bx + llz * nx
    ly = llx * ty + lly * by + llz * ny
    lz = llx * tz + lly * bz + llz * nz
    norm = math.sqrt(lx * lx + ly * ly + lz * lz)
    if (norm > 0.0) & (pdf_b > 0.0):
        lx /= norm
        ly /= norm
        lz /= norm
        if (g[0] * lx + g[1] * ly + g[2] * lz) * llz > 0.0:
            return (lx, ly, lz), w, pdf_b
    return (nx, ny, nz), (0.0, 0.0, 0.0), 0.0


@dual_use(inline=True)
def ray_origin(px, py, pz, gx, gy, gz, dx, dy, dz, eps):
    """Where a ray along d leaves the surface point p of geometric normal g: ``eps`` off
    the surface on the side d goes to (below it for a transmitted ray)."""
    k = eps if gx * dx + gy * dy + gz * dz >= 0.0 else -eps
    return px + k * gx, py + k * gy, pz + k * gz
