"""The material at a shading point as the compiled kernels see it, and the
shading frame (the record pbrt-v4's BxDFs hold, Pharr, Jakob and Humphreys 2023,
ch. 9).

A material is packed for compiled code as a row of integer codes
(:data:`CODE_COLUMNS`: the model, and cook_torrance's distribution, masking,
Fresnel and diffuse, each an index into its method table) and a row of float
parameters (:class:`pbrkit.brdf.parameters.Layout`, generated from the models'
declarations).  A model's ``setup`` (:mod:`pbrkit.brdf.models`) turns the two
rows and the (possibly textured) base colour, metallic and roughness at a
shading point into a :class:`BxDF`, whose fields every lobe
(:mod:`pbrkit.brdf.lobes`) reads; the directions come as their cosines in the
shading frame (:class:`Cosines`, :func:`cosines`; normal n, tangent t,
bitangent b).  :mod:`pbrkit.brdf.dispatch` evaluates, samples and gives the
pdf of the BxDF of any model, through code generated from the model registry.

Perceptual roughness r maps to alpha = max(r^2, ALPHA_MIN) in every model
(:func:`pbrkit.microfacet.roughness.alpha_from_roughness`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ..core.jit import dual_use
from ..core.vec import orthonormal_basis_xyz
from .fresnel import f0_metallic

__all__ = [
    "C_MODEL", "C_DISTRIBUTION", "C_MASKING", "C_FRESNEL", "C_DIFFUSE", "CODE_COLUMNS", "EXTRA_SLOTS", "NO_EXTRA",
    "BxDF", "Cosines", "cosines", "isotropic_cosines", "local_cosines", "tangent_frame", "shading_frame", "turned_frame", "into_turned",
    "out_of_turned", "NO_TANGENT", "lobe_bxdf", "with_extra",
    "metallic_workflow",
]

#: Columns of a material's integer code row.
C_MODEL, C_DISTRIBUTION, C_MASKING, C_FRESNEL, C_DIFFUSE = range(5)
CODE_COLUMNS = 5
#: How many values of its own a model can keep in a BxDF (:attr:`BxDF.extra`).
EXTRA_SLOTS = 15
#: The ``extra`` of a model that keeps none.
NO_EXTRA = (0.0,) * EXTRA_SLOTS


class BxDF(NamedTuple):
    """A material at one shading point, ready to evaluate and sample (a model's
    ``setup``).  ``model`` and the term codes are the code row's; ``alpha_x``,
    ``alpha_y`` are along the tangent and bitangent (equal to ``alpha`` unless
    ``anisotropic``); ``rotation``: the angle (radians, counter-clockwise about the
    normal) from the frame's tangent to the direction of ``alpha_x`` (glTF's
    anisotropyRotation; 0 for the other models); ``f0`` is the metallic-workflow normal reflectance of the
    Schlick-type Fresnel terms and ``f90`` their grazing value; ``diffuse_color``
    already carries the model's metallic weighting; ``eta``, ``k``: the complex IOR
    of the exact conductor Fresnel; ``dielectric_f0``: the dielectric's f0;
    ``specular_color``: the specular colour, the constant F of ``fresnel = "none"``
    (glTF's extended model: its dielectric's F0 colour); ``extra``:
    :data:`EXTRA_SLOTS` values of the model's own lobes (Disney's sheen colour and
    clear coat, for instance), at slots the model's lobes name."""

    model: int
    distribution: int
    masking: int
    fresnel: int
    diffuse: int
    roughness: float
    alpha: float
    alpha_x: float
    alpha_y: float
    anisotropic: bool
    rotation: float
    metallic: float
    base: tuple
    diffuse_color: tuple
    f0: tuple
    f90: float
    eta: tuple
    k: tuple
    dielectric_f0: float
    specular_color: tuple
    extra: tuple


# ---------------------------------------------------------------- the frame


class Cosines(NamedTuple):
    """The light l, the view v and the half vector h = normalize(l + v) in the
    shading frame (n, t, b): n.l, n.v, n.h, v.h (clamped at 0) and the tangent
    components t.l, b.l, t.v, b.v, t.h, b.h (0 when no tangent frame is used)."""

    nol: float
    nov: float
    noh: float
    voh: float
    tol: float
    bol: float
    tov: float
    bov: float
    toh: float
    boh: float


@dual_use
def _half_vector_cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz):
    # h = normalize(l + v) (n where l = -v) and n.l, n.v, n.h, max(v.h, 0).
    hx = lx + vx
    hy = ly + vy
    hz = lz + vz
    hl = math.sqrt(hx * hx + hy * hy + hz * hz)
    if hl > 1e-12:
        hx /= hl
        hy /= hl
        hz /= hl
    else:
        hx, hy, hz = nx, ny, nz
    nol = nx * lx + ny * ly + nz * lz
    nov = nx * vx + ny * vy + nz * vz
    noh = nx * hx + ny * hy + nz * hz
    voh = max(vx * hx + vy * hy + vz * hz, 0.0)
    return hx, hy, hz, nol, nov, noh, voh


@dual_use
def cosines(nx, ny, nz, tx, ty, tz, bx, by, bz, vx, vy, vz, lx, ly, lz):
    """:class:`Cosines` of world directions l and v (unit) in the frame with
    normal n, tangent t and bitangent b (unit, right-handed).  h = normalize(l +
    v); where l = -v, h = n (never NaN)."""
    hx, hy, hz, nol, nov, noh, voh = _half_vector_cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz)
    return Cosines(nol, nov, noh, voh, tx * lx + ty * ly + tz * lz, bx * lx + by * ly + bz * lz,
                   tx * vx + ty * vy + tz * vz, bx * vx + by * vy + bz * vz, tx * hx + ty * hy + tz * hz,
                   bx * hx + by * hy + bz * hz)


@dual_use
def isotropic_cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz):
    """:class:`Cosines` without the tangent components (zero): all an isotropic
    lobe uses."""
    _, _, _, nol, nov, noh, voh = _half_vector_cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz)
    return Cosines(nol, nov, noh, voh, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@dual_use
def local_cosines(wox, woy, woz, wix, wiy, wiz):
    """:class:`Cosines` of directions given in the local frame (normal +z, tangent +x)."""
    return cosines(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, wox, woy, woz, wix, wiy, wiz)


@dual_use
def tangent_frame(nx, ny, nz, anisotropic):
    """Tangent and bitangent of the shading frame at unit normal n.  For
    isotropic materials any frame will do: Duff et al.'s branchless basis
    (:func:`pbrkit.core.vec.orthonormal_basis_xyz`).  Anisotropic materials
    need a frame that varies smoothly over the surface: the tangent follows
    the parallels about +Y, t = normalize(n x Y) (on a sphere the direction of
    increasing longitude phi = atan2(z, x), as a parametric sphere's dp/dphi),
    with Duff's basis where n is within 1e-6 of +-Y."""
    if anisotropic:
        tx = -nz
        tz = nx
        length = math.sqrt(tx * tx + tz * tz)
        if length > 1e-6:
            tx /= length
            tz /= length
            # b = n x t
            return (tx, 0.0, tz), (ny * tz, nz * tx - nx * tz, -ny * tx)
    return orthonormal_basis_xyz(nx, ny, nz)


#: The tangent of a point that has none (a hit on an analytic shape): a zero vector,
#: handedness +1 (:func:`shading_frame` then takes :func:`tangent_frame`'s).
NO_TANGENT = (0.0, 0.0, 0.0, 1.0)


@dual_use(inline=True)
def shading_frame(nx, ny, nz, b, tangent):
    """The tangent and bitangent of BxDF ``b`` at unit normal n.  Isotropic: any
    frame (:func:`tangent_frame`).  Anisotropic: the surface's tangent ``tangent``
    (x, y, z, w: a glTF TANGENT, w the handedness of B = w (n x T), glTF 2.0
    specification, "Meshes") made orthogonal to n, or where it is zero
    (:data:`NO_TANGENT`) :func:`tangent_frame`'s, turned by ``b.rotation`` in the
    (T, B) plane: t = cos(rotation) T + sin(rotation) B, bitangent n x t
    (KHR_materials_anisotropy's README, "Implementation": anisotropicT =
    normalize(TBN (cos, sin, 0)), anisotropicB = normalize(cross(n, anisotropicT)))."""
    if not b.anisotropic:
        return tangent_frame(nx, ny, nz, False)
    tx, ty, tz, tw = tangent
    d = tx * nx + ty * ny + tz * nz
    tx -= d * nx
    ty -= d * ny
    tz -= d * nz
    length = math.sqrt(tx * tx + ty * ty + tz * tz)
    if length > 1e-12:
        tx /= length
        ty /= length
        tz /= length
        w = -1.0 if tw < 0.0 else 1.0
        bx, by, bz = w * (ny * tz - nz * ty), w * (nz * tx - nx * tz), w * (nx * ty - ny * tx)
    else:
        (tx, ty, tz), (bx, by, bz) = tangent_frame(nx, ny, nz, True)
    return turned_frame(nx, ny, nz, tx, ty, tz, bx, by, bz, b.rotation)


@dual_use(inline=True)
def turned_frame(nx, ny, nz, tx, ty, tz, bx, by, bz, rotation):
    """The frame (t, n x t) at unit normal n whose tangent is T turned by ``rotation``
    towards B: t = cos(rotation) T + sin(rotation) B (KHR_materials_anisotropy's
    anisotropyRotation, counter-clockwise in the (T, B) plane)."""
    if rotation != 0.0:
        c = math.cos(rotation)
        s = math.sin(rotation)
        tx, ty, tz = c * tx + s * bx, c * ty + s * by, c * tz + s * bz
    return (tx, ty, tz), (ny * tz - nz * ty, nz * tx - nx * tz, nx * ty - ny * tx)


@dual_use(inline=True)
def into_turned(b, x, y):
    """Local coordinates (x along the tangent, y along the bitangent, normal +z) of a
    direction in the frame of BxDF ``b``, its tangent turned by ``b.rotation``
    (:func:`turned_frame`); :func:`out_of_turned` is the inverse."""
    if b.rotation != 0.0:
        c = math.cos(b.rotation)
        s = math.sin(b.rotation)
        return c * x + s * y, c * y - s * x
    return x, y


@dual_use(inline=True)
def out_of_turned(b, x, y):
    """:func:`into_turned` undone: from the turned frame back to the local one."""
    if b.rotation != 0.0:
        c = math.cos(b.rotation)
        s = math.sin(b.rotation)
        return c * x - s * y, s * x + c * y
    return x, y




@dual_use(inline=True)
def with_extra(b, extra):
    """BxDF ``b`` with its :attr:`BxDF.extra` replaced (a NamedTuple's ``_replace``,
    which compiled code lacks)."""
    return BxDF(b.model, b.distribution, b.masking, b.fresnel, b.diffuse, b.roughness, b.alpha, b.alpha_x, b.alpha_y,
                b.anisotropic, b.rotation, b.metallic, b.base, b.diffuse_color, b.f0, b.f90, b.eta, b.k,
                b.dielectric_f0, b.specular_color, extra)


@dual_use(inline=True)
def metallic_workflow(codes, row, roughness, alpha, metallic, b0, b1, b2, dielectric_f0, kd):
    """The BxDF of an isotropic metallic-workflow model: f0 = mix(dielectric_f0, base,
    metallic) per channel (:func:`pbrkit.brdf.fresnel.f0_metallic`), diffuse colour
    base kd, f90 = 1, no complex IOR, constant colour or extra values."""
    z3 = (0.0, 0.0, 0.0)
    f0 = (f0_metallic(b0, metallic, dielectric_f0), f0_metallic(b1, metallic, dielectric_f0),
          f0_metallic(b2, metallic, dielectric_f0))
    return BxDF(codes[row, 0], codes[row, 1], codes[row, 2], codes[row, 3], codes[row, 4], roughness, alpha, alpha,
                alpha, False, 0.0, metallic, (b0, b1, b2), (b0 * kd, b1 * kd, b2 * kd), f0, 1.0, z3, z3, dielectric_f0, z3,
                NO_EXTRA)


@dual_use(inline=True)
def lobe_bxdf(alpha):
    """A BxDF that holds only an isotropic lobe of width alpha (perceptual roughness
    sqrt(alpha), white f0 and diffuse colour 0): what the lookup tables integrate the
    terms of (:mod:`pbrkit.albedo.tables`)."""
    z3 = (0.0, 0.0, 0.0)
    return BxDF(0, 0, 0, 0, 0, math.sqrt(alpha), alpha, alpha, alpha, False, 0.0, 1.0, z3, z3, z3, 1.0, z3, z3, 0.0, z3,
                NO_EXTRA)
