"""The shading models as NumPy functions: UE4, Filament, Unity URP mobile, a
generic Cook-Torrance with every term by name, Disney's principled BRDF and
the glTF 2.0 metallic-roughness BRDF (Appendix B).

Every model is a function ``model(l, v, n, material, ...)`` of unit directions
in the last axis of arrays (l toward the light, v toward the eye, n the
normal; any broadcastable leading shapes) and a :class:`pbrkit.Material`
whose fields broadcast against those leading shapes.  It returns the BRDF
value f (RGB, shape (..., 3)) -- *not* f cos -- and 0 where l or v is below
the surface.  Perceptual roughness r maps to alpha = r^2 (clamped at
``ALPHA_MIN``) in every model; other remaps are stated per model.

Each model is declared once, in its module of :mod:`pbrkit.brdf.shading` (its
parameters and its composition of lobes), and reached through the dispatch
generated from the registry (:mod:`pbrkit.brdf.dispatch`); the functions here
pack their arguments and evaluate it in one compiled kernel over threads, the
same code the renderer runs.  :func:`sample` and :func:`pdf`
expose each model's sampling routine and its pdf (local frame) the same way.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..core.jit import dual_use, row_kernel
from ..core.vec import dot, half_vector, orthonormal_basis_xyz, shading_frame
from .bxdf import CODE_COLUMNS, cosines, into_turned, isotropic_cosines, local_cosines, out_of_turned, turned_frame
from .dispatch import bxdf_f, bxdf_pdf, lobe_probabilities, make_bxdf, sample_wi
from .lobes.clearcoat import coat_in_frame, coat_tilted
from .shading.registry import COLUMNS, LAYOUT, MODEL_TERMS, MODELS, SURFACE, TERM_NAMES, model
from .shading.registry import model_codes as _registry_codes

DISTRIBUTIONS = TERM_NAMES["distribution"]
MASKINGS = TERM_NAMES["masking"]
FRESNELS = TERM_NAMES["fresnel"]
DIFFUSES = TERM_NAMES["diffuse"]

__all__ = [
    "Cosines",
    "frame_cosines",
    "ue4",
    "filament",
    "urp_mobile",
    "cook_torrance",
    "disney",
    "gltf",
    "evaluate",
    "evaluate_rows",
    "parameter_rows",
    "model_codes",
    "sample",
    "pdf",
    "MODELS",
    "MODEL_TERMS",
    "DISTRIBUTIONS",
    "MASKINGS",
    "FRESNELS",
    "DIFFUSES",
]


class Cosines(NamedTuple):
    """Cosines of the shading frame (NumPy arrays); tangent-frame components are None without a tangent."""

    nol: np.ndarray
    nov: np.ndarray
    noh: np.ndarray
    voh: np.ndarray
    tol: np.ndarray | None = None
    bol: np.ndarray | None = None
    tov: np.ndarray | None = None
    bov: np.ndarray | None = None
    toh: np.ndarray | None = None
    boh: np.ndarray | None = None


def frame_cosines(l, v, n, t=None, tangent_frame=False):
    """Dot products n.l, n.v, n.h, v.h (= l.h), and with ``tangent_frame`` the
    tangent-frame components (t from ``t`` or :func:`pbrkit.core.vec.orthonormal_basis`),
    as NumPy arrays (for analysis; the models use :func:`pbrkit.brdf.bxdf.cosines`)."""
    l = np.asarray(l, dtype=float)
    v = np.asarray(v, dtype=float)
    n = np.asarray(n, dtype=float)
    h = half_vector(l, v)
    cos = dict(nol=dot(n, l), nov=dot(n, v), noh=dot(n, h), voh=np.maximum(dot(v, h), 0.0))
    if tangent_frame:
        t, b, n = shading_frame(n, t)
        cos.update(tol=dot(t, l), bol=dot(b, l), tov=dot(t, v), bov=dot(b, v), toh=dot(t, h), boh=dot(b, h))
    return Cosines(**cos)


# ------------------------------------------------------------------ packing


def model_codes(model_name, distribution="ggx", masking="height-correlated", fresnel="schlick", diffuse="lambert",
                material=None):
    """The integer codes (1, :data:`pbrkit.brdf.bxdf.CODE_COLUMNS`) of a model and its
    terms by name; a fixed model's own terms replace the ones given
    (:func:`pbrkit.brdf.shading.registry.model_codes`); the model's extended form
    when ``material`` (a :class:`pbrkit.Material`) uses one of its extensions."""
    values = None
    if material is not None:
        values = {p.name: getattr(material, p.name, None) for p in model(model_name).extensions}
    codes = _registry_codes(model_name, distribution, masking, fresnel, diffuse, values)
    return np.asarray([codes], dtype=np.int64).reshape(1, CODE_COLUMNS)


def _check_for_model(name, material, terms):
    """The model's own ranges (a narrower one than Material's, e.g. Disney's
    anisotropy) and its cross-parameter rules, as one-line ``ValueError`` s."""
    m = model(name)
    for p in m.numbers:
        value = getattr(material, p.name)
        if value is not None:
            p.check(value, f"{name}: Material.{p.name}")
    for key, value in terms.items():
        choice = m.choices.get(key)
        if choice is not None:
            choice.check(value, f"{key} of {name}")
    if m.check is not None:
        values = {p.name: getattr(material, p.name) for p in m.numbers}
        values.update({k: v for k, v in terms.items() if k in m.choices})
        values["anisotropy"] = 0.0  # here an isotropic lobe (Blinn-Phong) ignores the anisotropy
        m.check(values, f"{name}: ")


#: The parameters the NumPy kernels read from the material's row (the other three,
#: base colour, metallic and roughness, come per element as the renderer's textures).
_ROW_FIELDS = tuple(p.name for p in LAYOUT.parameters
                    if p.name not in ("base_color", "metallic", "roughness") and p not in SURFACE)


class _Packed(NamedTuple):
    """A material packed for the kernels: a table of parameter rows (M, LAYOUT.size),
    the row of each element (N,), and the per-element base colour (N, 3), metallic
    and roughness (N,), as the renderer passes textured values."""

    table: np.ndarray
    index: np.ndarray
    base: np.ndarray
    metallic: np.ndarray
    roughness: np.ndarray


def _field_shape(material, name):
    value = getattr(material, name)
    if value is None:
        return ()
    shape = np.shape(value)
    return shape[:-1] if LAYOUT.by_name[name].channels == 3 else shape


def parameter_rows(material, rows_shape=()):
    """Parameter rows (prod(rows_shape), LAYOUT.size) in the packed layout of
    :data:`pbrkit.brdf.shading.registry.LAYOUT` for a material broadcast to
    ``rows_shape``: every parameter of the material (the complex IOR as zeros when
    absent).  Base colour, metallic, roughness, emission and sidedness are left 0:
    the NumPy kernels take the first three per element, and the renderer
    (:func:`pbrkit.rendering.materials.material_tables`) fills them."""
    return LAYOUT.row({name: getattr(material, name) for name in _ROW_FIELDS}, rows_shape)


def _pack(material, shape, coat_normal=None):
    """:class:`_Packed` of a material broadcast to ``shape``: one table row when every
    parameter other than base colour, metallic and roughness is a scalar (and no
    ``coat_normal`` (..., 3) is given: the clear coat's own normal, the rows'
    ``coat_normal``), else a row per element."""
    count = int(np.prod(shape))
    per_element = coat_normal is not None or any(len(_field_shape(material, name)) for name in _ROW_FIELDS)
    rows_shape = shape if per_element else ()
    table = parameter_rows(material, rows_shape)
    if coat_normal is not None:
        c = _rows(coat_normal, shape)
        length = np.linalg.norm(c, axis=1)
        if not np.all(np.isfinite(c)) or np.any(np.abs(length - 1.0) > 1e-6):
            raise ValueError("coat_normal must be unit vectors (..., 3)")
        table[:, COLUMNS.coat_normal:COLUMNS.coat_normal + 3] = c
    # the table row of element i is index[i], or row 0 for every element when index has one entry
    index = np.arange(count, dtype=np.int64) if table.shape[0] > 1 else np.zeros(1, dtype=np.int64)

    def per(value):
        value = np.asarray(value, dtype=np.float64)
        if value.shape != shape:
            value = np.broadcast_to(value, shape)
        return np.require(value.reshape(-1), dtype=np.float64, requirements=["C", "W"])

    return _Packed(table, index, _rows(material.base_color, shape), per(material.metallic), per(material.roughness))


def _material_shape(material):
    fields = [material.base_color.shape[:-1]] + [_field_shape(material, name) for name in
                                                 ("metallic", "roughness") + _ROW_FIELDS]
    return np.broadcast_shapes(*fields)


def _rows(x, shape):
    # A writable C-contiguous float64 (N, 3) array, so each kernel is compiled for one signature only
    # (copied only when it has to be broadcast or converted).
    x = np.asarray(x, dtype=np.float64)
    if x.shape != shape + (3,):
        x = np.broadcast_to(x, shape + (3,))
    return np.require(x.reshape(-1, 3), dtype=np.float64, requirements=["C", "W"])


@dual_use
def _frame(n, t, i, has_tangent):
    nx, ny, nz = n[i, 0], n[i, 1], n[i, 2]
    if has_tangent:
        d = t[i, 0] * nx + t[i, 1] * ny + t[i, 2] * nz
        tx = t[i, 0] - d * nx
        ty = t[i, 1] - d * ny
        tz = t[i, 2] - d * nz
        length = np.sqrt(tx * tx + ty * ty + tz * tz)
        tx /= length
        ty /= length
        tz /= length
        return (tx, ty, tz), (ny * tz - nz * ty, nz * tx - nx * tz, nx * ty - ny * tx)
    return orthonormal_basis_xyz(nx, ny, nz)


@row_kernel(6)
def _evaluate_kernel(start, stop, codes, table, index, base, metallic, roughness, l, v, n, t, has_tangent, out):
    per_element = index.shape[0] > 1
    for i in range(start, stop):
        row = index[i] if per_element else 0
        b = make_bxdf(codes, 0, table, row, roughness[i], metallic[i], base[i, 0], base[i, 1], base[i, 2])
        if b.anisotropic or coat_tilted(b):  # a tangent frame: the anisotropic lobe's, the coat normal's
            (tx, ty, tz), (bx, by, bz) = _frame(n, t, i, has_tangent)
            (tx, ty, tz), (bx, by, bz) = turned_frame(n[i, 0], n[i, 1], n[i, 2], tx, ty, tz, bx, by, bz, b.rotation)
            b = coat_in_frame(b, n[i, 0], n[i, 1], n[i, 2], (tx, ty, tz), (bx, by, bz))
            c = cosines(n[i, 0], n[i, 1], n[i, 2], tx, ty, tz, bx, by, bz, v[i, 0], v[i, 1], v[i, 2], l[i, 0],
                        l[i, 1], l[i, 2])
        else:  # isotropic lobes need no tangent frame
            c = isotropic_cosines(n[i, 0], n[i, 1], n[i, 2], v[i, 0], v[i, 1], v[i, 2], l[i, 0], l[i, 1], l[i, 2])
        f = bxdf_f(b, c, 1.0, 1.0, 1.0)
        out[i, 0] = f[0]
        out[i, 1] = f[1]
        out[i, 2] = f[2]


def evaluate_rows(codes, params, l, v, n, t=None):
    """The BRDF value f (N, 3) of packed materials (a code row ``codes`` and
    parameter rows ``params`` (N, LAYOUT.size), the layout of
    :data:`pbrkit.brdf.shading.registry.LAYOUT`, e.g. from
    :func:`pbrkit.rendering.materials.material_tables`)
    for unit directions (N, 3)."""
    l, v, n = (np.asarray(x, dtype=np.float64).reshape(-1, 3) for x in (l, v, n))
    shape = (l.shape[0],)
    params = np.ascontiguousarray(np.asarray(params, dtype=np.float64).reshape(-1, LAYOUT.size))
    index = np.arange(shape[0]) if params.shape[0] > 1 else np.zeros(1, dtype=np.int64)
    params = np.require(np.broadcast_to(params, (max(params.shape[0], 1), LAYOUT.size)), dtype=np.float64,
                        requirements=["C", "W"])
    out = np.empty((l.shape[0], 3))
    n_rows = _rows(n, shape)
    t_rows = n_rows if t is None else _rows(t, shape)
    rows = index if params.shape[0] > 1 else np.zeros(shape[0], dtype=np.int64)
    base = _rows(params[rows, COLUMNS.base_color:COLUMNS.base_color + 3], shape)
    metallic = np.ascontiguousarray(params[rows, COLUMNS.metallic])
    roughness = np.ascontiguousarray(params[rows, COLUMNS.roughness])
    codes = np.ascontiguousarray(np.asarray(codes, dtype=np.int64).reshape(1, CODE_COLUMNS))
    _evaluate_kernel(codes, params, index.astype(np.int64), base, metallic, roughness,
                     _rows(l, shape), _rows(v, shape), n_rows, t_rows, t is not None, out)
    return out


def evaluate(model, l, v, n, material, t=None, coat_normal=None, **terms):
    """The BRDF value f (..., 3) of ``model`` (a name of
    :data:`pbrkit.brdf.shading.registry.MODELS`; ``terms`` choose cook_torrance's
    ``distribution``, ``masking``, ``fresnel`` and ``diffuse``, and
    filament's ``diffuse``) for unit directions l, v, n (..., 3) and tangent
    ``t`` (default: :func:`pbrkit.core.vec.orthonormal_basis`); ``coat_normal``
    (..., 3, unit): the ``gltf`` clear coat's own normal (KHR_materials_clearcoat's
    clearcoatNormal; default: n).  Values outside the model's own ranges, or a
    combination it does not have, raise ``ValueError``."""
    codes = model_codes(model, material=material, **terms)
    _check_for_model(model, material, terms)
    l, v, n = (np.asarray(x, dtype=np.float64) for x in (l, v, n))
    shapes = [l.shape[:-1], v.shape[:-1], n.shape[:-1], _material_shape(material)]
    if t is not None:
        t = np.asarray(t, dtype=np.float64)
        shapes.append(t.shape[:-1])
    if coat_normal is not None:
        coat_normal = np.asarray(coat_normal, dtype=np.float64)
        shapes.append(coat_normal.shape[:-1])
    shape = np.broadcast_shapes(*shapes)
    out = np.empty((int(np.prod(shape)), 3))
    n_rows = _rows(n, shape)
    t_rows = n_rows if t is None else _rows(t, shape)
    pk = _pack(material, shape, coat_normal)
    _evaluate_kernel(codes, pk.table, pk.index, pk.base, pk.metallic, pk.roughness, _rows(l, shape), _rows(v, shape),
                     n_rows, t_rows, t is not None, out)
    return out.reshape(shape + (3,))


# ------------------------------------------------------------------ the models


def ue4(l, v, n, material):
    """UE4 shading model (Karis 2013): Lambert diffuse + GGX + Schlick-GGX with
    k = (r + 1)^2 / 8 + the spherical-Gaussian Schlick Fresnel, metallic
    workflow with dielectric f0 = 0.16 reflectance^2 (0.08 specular in UE4 terms)."""
    return evaluate("ue4", l, v, n, material)


def filament(l, v, n, material, diffuse: str = "lambert", t=None):
    """Filament's standard model (Filament documentation, sec. 4): Lambert or
    Burley diffuse, GGX (anisotropic when ``material.anisotropy`` != 0, with the
    tangent ``t`` or a built frame), height-correlated Smith-GGX visibility and
    Schlick Fresnel with f0 = 0.16 reflectance^2 (1 - metallic) + base metallic
    and f90 = saturate(50 * 0.33 * sum(f0)) (Filament's specular occlusion)."""
    return evaluate("filament", l, v, n, material, t=t, diffuse=diffuse)


def urp_mobile(l, v, n, material):
    """Unity URP mobile BRDF: diffuse = base (0.96 (1 - metallic)), specular colour
    lerp(0.04, base, metallic) (URP ``kDielectricSpec``), specular term
    :func:`pbrkit.brdf.shading.urp_mobile.urp_specular`, alpha = r^2 (URP
    ``PerceptualRoughnessToRoughness``).

    Unity's punctual lights are pi times brighter than radiometric ones, so the
    returned BRDF is (diffuse + specular_color * term) / pi.  The dielectric f0
    is URP's fixed 0.04 (``material.reflectance`` is not used).
    """
    return evaluate("urp_mobile", l, v, n, material)


def gltf(l, v, n, material):
    """The glTF 2.0 metallic-roughness BRDF exactly as the glTF 2.0 specification's
    Appendix B defines it: mix(fresnel_mix(ior = 1.5, diffuse_brdf(base_color),
    specular_brdf(alpha)), conductor_fresnel(f0 = base_color,
    specular_brdf(alpha)), metallic), i.e.

        f = (1 - metallic)(1 - F_0.04(v.h)) base_color / pi + D V F_f0(v.h),
        f0 = mix(0.04, base_color, metallic),

    with D GGX, V the separable Smith-GGX visibility G1(l) G1(v) / (4 n.l n.v)
    (Appendix B.3.2), Schlick's F of v.h, alpha = r^2 (B.2.2), and the
    dielectric f0 0.04 of IOR 1.5 (``material.reflectance`` is not used).
    :func:`pbrkit.brdf.shading.gltf.gltf_fresnel_mix_weight` is the diffuse weight.
    ``material.sheen_color`` / ``sheen_roughness`` layer KHR_materials_sheen's Charlie
    sheen on top, sheenColor f_sheen + f sheen_albedo_scaling (the extension's README,
    "Albedo-scaling technique"; :data:`pbrkit.brdf.shading.gltf.SHEEN_COMPOSITION`).
    """
    return evaluate("gltf", l, v, n, material)


def cook_torrance(l, v, n, material, distribution="ggx", masking="height-correlated",
                  fresnel="schlick", diffuse="lambert", t=None):
    """Cook & Torrance 1982 microfacet BRDF f = D G F / (4 n.l n.v) (+ diffuse),
    with each term chosen by name:

    - ``distribution``: ``ggx``, ``beckmann`` (both anisotropic when
      ``material.anisotropy`` != 0), ``blinn-phong`` (exponent
      2 / alpha^2 - 2 from the Beckmann alpha, Walter et al. 2007 eq. 30).
    - ``masking``: exact Smith ``height-correlated`` or ``separable`` for the
      chosen D (Blinn-Phong uses Beckmann's Lambda); ``schlick-ggx`` (k =
      alpha / 2), ``schlick-ggx-ue4`` (k = (r + 1)^2 / 8), ``kelemen``, or
      ``implicit`` (G = n.l n.v).
    - ``fresnel``: ``schlick``, ``schlick-pow4``, ``ue4-sg`` (f0 from the
      metallic workflow), ``exact-conductor`` (material.eta, material.k),
      ``exact-dielectric`` (IOR from f0 = 0.16 reflectance^2, metallic ignored),
      or ``none`` (F = 1).
    - ``diffuse``: ``lambert``, ``burley`` or ``none``, weighted by
      base_color (1 - metallic).
    """
    return evaluate("cook_torrance", l, v, n, material, t=t, distribution=distribution, masking=masking,
                    fresnel=fresnel, diffuse=diffuse)


def disney(l, v, n, material, t=None):
    """Disney's principled BRDF (Burley 2012, "Physically-Based Shading at Disney",
    sec. 5 and Appendix B; the BRDF Explorer's ``disney.brdf``).

    f = (1 - metallic) [base (mix(Burley, subsurface, s)) + sheen] + D_s F_s V_s + clearcoat:

    - diffuse: :func:`pbrkit.brdf.diffuse.burley` mixed with
      :func:`pbrkit.brdf.diffuse.burley_subsurface` by ``material.subsurface``;
    - sheen: (1 - l.h)^5 sheen mix(1, C_tint, sheen_tint), with
      C_tint = base / luminance(base) (luminance 0.3 R + 0.6 G + 0.1 B);
    - specular: anisotropic GGX with alpha = r^2 and Burley's aspect
      (:func:`pbrkit.microfacet.roughness.anisotropic_alphas_burley`, anisotropy in
      [0, 1]), separable exact Smith G (the BRDF Explorer's version, without the
      2012 notes' alpha_g "hotness" remap), Schlick Fresnel from
      C_spec0 = mix(0.08 specular mix(1, C_tint, specular_tint), base, metallic)
      where 0.08 specular = 0.16 reflectance^2 (``material.dielectric_f0``);
    - clear coat: 0.25 clearcoat D_GTR1(alpha = mix(0.1, 0.001, gloss)) times
      Schlick F with f0 = 0.04 times separable Smith V with alpha = 0.25.
    """
    return evaluate("disney", l, v, n, material, t=t)


# ------------------------------------------------------ sampling and pdf


@dual_use(inline=True)
def _local_coat(b):
    # a coat normal given in the local frame, in the frame turned by b.rotation (into_turned)
    (tx, ty, tz), (bx, by, bz) = turned_frame(0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, b.rotation)
    return coat_in_frame(b, 0.0, 0.0, 1.0, (tx, ty, tz), (bx, by, bz))


@row_kernel(6)
def _sample_kernel(start, stop, codes, table, index, base, metallic, roughness, wo, u, out_wi, out_pdf, out_weight):
    per_element = index.shape[0] > 1
    for i in range(start, stop):
        row = index[i] if per_element else 0
        b = _local_coat(make_bxdf(codes, 0, table, row, roughness[i], metallic[i], base[i, 0], base[i, 1], base[i, 2]))
        for a in range(3):
            out_wi[i, a] = 0.0
            out_weight[i, a] = 0.0
        out_pdf[i] = 0.0
        if wo[i, 2] <= 0.0:
            continue
        p_spec, p_coat = lobe_probabilities(b, wo[i, 2])
        wox, woy = into_turned(b, wo[i, 0], wo[i, 1])  # the frame of a turned anisotropy direction
        x, y, z = sample_wi(b, wox, woy, wo[i, 2], u[i, 0], u[i, 1], u[i, 2], p_spec, p_coat)
        length = np.sqrt(x * x + y * y + z * z)
        if length <= 0.0:
            continue
        x /= length
        y /= length
        z /= length
        if z <= 0.0:
            continue
        c = local_cosines(wox, woy, wo[i, 2], x, y, z)
        x, y = out_of_turned(b, x, y)
        pdf_ = bxdf_pdf(b, c, p_spec, p_coat)
        if pdf_ <= 0.0:
            continue
        f = bxdf_f(b, c, 1.0, 1.0, 1.0)
        out_wi[i, 0] = x
        out_wi[i, 1] = y
        out_wi[i, 2] = z
        out_pdf[i] = pdf_
        for a in range(3):
            out_weight[i, a] = f[a] * z / pdf_


@row_kernel(6)
def _pdf_kernel(start, stop, codes, table, index, base, metallic, roughness, wo, wi, out):
    per_element = index.shape[0] > 1
    for i in range(start, stop):
        row = index[i] if per_element else 0
        b = _local_coat(make_bxdf(codes, 0, table, row, roughness[i], metallic[i], base[i, 0], base[i, 1], base[i, 2]))
        out[i] = 0.0
        if wo[i, 2] <= 0.0 or wi[i, 2] <= 0.0:
            continue
        p_spec, p_coat = lobe_probabilities(b, wo[i, 2])
        wox, woy = into_turned(b, wo[i, 0], wo[i, 1])
        wix, wiy = into_turned(b, wi[i, 0], wi[i, 1])
        out[i] = bxdf_pdf(b, local_cosines(wox, woy, wo[i, 2], wix, wiy, wi[i, 2]), p_spec, p_coat)


def _local_setup(model, material, wo, other, terms, coat_normal):
    codes = model_codes(model, material=material, **terms)
    _check_for_model(model, material, terms)
    wo = np.asarray(wo, dtype=np.float64)
    other = np.asarray(other, dtype=np.float64)
    shapes = [wo.shape[:-1], other.shape[:-1], _material_shape(material)]
    if coat_normal is not None:
        coat_normal = np.asarray(coat_normal, dtype=np.float64)
        shapes.append(coat_normal.shape[:-1])
    shape = np.broadcast_shapes(*shapes)
    return codes, shape, _pack(material, shape, coat_normal), _rows(wo, shape)


def sample(model, material, wo, u, coat_normal=None, **terms):
    """Sample the light direction of ``model`` for the local view ``wo`` (..., 3)
    (normal +z, tangent +x, unit) with uniform numbers ``u`` (..., 3) in
    [0, 1): u[..., 0] picks the lobe (:func:`pbrkit.brdf.dispatch.lobe_probabilities`),
    u[..., 1:] place the direction (:func:`pbrkit.brdf.dispatch.sample_wi`).
    Returns (wi (..., 3), pdf (...), weight f cos / pdf (..., 3)); a failed
    sample (the direction below the horizon, or wo.z <= 0) has wi = 0,
    pdf = 0 and weight 0.  ``coat_normal`` (..., 3, unit, local): the ``gltf`` clear
    coat's own normal (default +z)."""
    codes, shape, pk, wo_rows = _local_setup(model, material, wo, np.asarray(u)[..., :3], terms, coat_normal)
    u = np.asarray(u, dtype=np.float64)
    if u.shape[-1] != 3 or np.any((u < 0.0) | (u > 1.0)) or not np.all(np.isfinite(u)):
        raise ValueError("u must have 3 components in [0, 1] in its last axis")
    count = wo_rows.shape[0]
    wi = np.empty((count, 3))
    pdf_ = np.empty(count)
    weight = np.empty((count, 3))
    _sample_kernel(codes, *pk, wo_rows, _rows(u, shape), wi, pdf_, weight)
    return wi.reshape(shape + (3,)), pdf_.reshape(shape), weight.reshape(shape + (3,))


def pdf(model, material, wo, wi, coat_normal=None, **terms):
    """Solid-angle pdf (...) with which :func:`sample` draws the local light
    direction ``wi`` for the view ``wo`` (both (..., 3), unit, normal +z); 0
    below the horizon; ``coat_normal`` as :func:`sample`'s."""
    codes, shape, pk, wo_rows = _local_setup(model, material, wo, wi, terms, coat_normal)
    out = np.empty(wo_rows.shape[0])
    _pdf_kernel(codes, *pk, wo_rows, _rows(wi, shape), out)
    return out.reshape(shape)
