"""Scene materials for the compiled kernels: each material as the integer code
row and float parameter row of the registry's layout
(:data:`pbrkit.brdf.shading.registry.LAYOUT`), and the BxDF and shading frame at
a hit point.
"""

from __future__ import annotations

import numpy as np

from ..brdf.bxdf import CODE_COLUMNS, cosines, isotropic_cosines, shading_frame
from ..brdf.dispatch import make_bxdf, restricted
from ..brdf.lobes.clearcoat import coat_in_frame, coat_tilted, coated_emission
from ..brdf.material import FIELDS
from ..brdf.shading.gltf import GLTF_DIELECTRIC_F0
from ..brdf.shading.model import _uncoated
from ..brdf.shading.registry import COLUMNS, COMPILED, LAYOUT, REGISTERED, model_codes
from ..core.jit import dual_use

__all__ = ["material_tables", "per_hit_tables", "hit_bxdf", "hit_cosines", "coat_normals", "for_materials",
           "bounds_volume", "emission_seen",
           "COAT_F0"]

#: The f0 of the coat over the emission (KHR_materials_clearcoat: its fixed IOR 1.5).
COAT_F0 = GLTF_DIELECTRIC_F0


def bounds_volume(spec, material=None):
    """Whether a :class:`pbrkit.rendering.scene.MaterialSpec` bounds a medium: a ``gltf``
    material that transmits with a thickness above 0 (``KHR_materials_volume``).  Its
    normals are never turned to face the ray ("The doubleSided property has no effect
    on volume boundaries", the volume README, "Properties"): the side of the view says
    whether a path enters or leaves the medium."""
    if spec.model != "gltf":
        return False
    material = spec.material() if material is None else material
    return bool(np.any(np.asarray(getattr(material, "transmission", 0.0)) > 0.0)
                and np.any(np.asarray(getattr(material, "thickness", 0.0)) > 0.0))


def material_tables(materials):
    """Pack :class:`pbrkit.rendering.textures.SurfaceMaterial` s for the kernels:
    ``(codes (M, CODE_COLUMNS) int64, params (M, LAYOUT.size) float64)``: the model
    and its term choices as indices into their tables, and every parameter at its
    column of :data:`pbrkit.brdf.shading.registry.LAYOUT` (with emission and
    sidedness)."""
    m = len(materials)
    codes = np.zeros((m, CODE_COLUMNS), dtype=np.int64)
    params = np.zeros((m, LAYOUT.size), dtype=np.float64)
    for i, sm in enumerate(materials):
        s = sm.spec
        material = s.material()
        values = {p.name: getattr(material, p.name) for p in FIELDS}
        codes[i] = model_codes(s.model, s.distribution, s.masking, s.fresnel, s.diffuse, values)
        values.update(specular_color=s.specular_color, emissive=s.emissive,
                      double_sided=1.0 if s.double_sided and not bounds_volume(s, material) else 0.0)
        params[i] = LAYOUT.row(values)[0]
    return codes, params


def per_hit_tables(codes, params, surface):
    """The kernels' material tables for the hits of ``surface`` (a
    :class:`pbrkit.rendering.geometry.Surface`) whose KHR_materials extension textures
    change their parameters (:attr:`~pbrkit.rendering.geometry.Surface.extension_values`):
    (codes (M + K, C), params (M + K, P), each hit's row (N,), each row's scene material
    (M + K,)), a row per such hit after the M of ``codes`` and ``params`` (its
    material's, the textured columns replaced); the tables themselves, ``surface.material``
    and None without such hits."""
    if surface.extension_values is None:
        return codes, params, surface.material, None
    rows, values = surface.extension_values
    m = codes.shape[0]
    material = surface.material
    new_params = params[material[rows]].copy()
    for column, v in values.items():
        new_params[:, column] = v
    out = material.copy()
    out[rows] = m + np.arange(rows.size)
    return (np.concatenate([codes, codes[material[rows]]]), np.concatenate([params, new_params]), out,
            np.concatenate([np.arange(m), material[rows]]))


def coat_normals(params, material, n):
    """The clear coat's world-space normal at hits of rows ``material`` (N,) of the table
    ``params`` with shading normals ``n`` (N, 3): the row's ``coat_normal``
    (KHR_materials_clearcoat's clearcoatNormal, :func:`pbrkit.brdf.lobes.clearcoat.coat_in_frame`),
    or ``n`` where it is 0 (the coat has no normal of its own)."""
    table = params[:, COLUMNS.coat_normal:COLUMNS.coat_normal + 3]
    if not table.any():  # no row has one (a glance at the table, not a gather per hit)
        return n
    c = table[material]
    own = np.any(c != 0.0, axis=1)
    if not own.any():
        return n
    out = np.array(n, dtype=np.float64)
    out[own] = c[own] / np.linalg.norm(c[own], axis=1, keepdims=True)
    return out


def for_materials(fn, codes):
    """The kernel ``fn`` compiled for the models of the material code table ``codes``
    (:func:`material_tables`): the registered models' cores, and the extended forms
    only when a material uses one (:func:`pbrkit.brdf.dispatch.restricted` over the
    prefix of :data:`pbrkit.brdf.shading.registry.COMPILED` that holds every code).
    So a scene of materials without extensions runs kernels without the extensions'
    code, which LLVM would otherwise optimise beside theirs (it slowed the plain
    glTF material's lane kernel by 13-18 % with iridescence)."""
    top = int(codes[:, 0].max()) + 1 if codes.shape[0] else 0
    return restricted(fn, COMPILED[:max(len(REGISTERED), top)])


def emission_seen(codes, params, material, nov, emissive, f0=COAT_F0):
    """The emission ``emissive`` (N, 3) of hits of materials ``material`` (N,) seen at
    n.v ``nov`` (N,), darkened where the material's model puts a coat over it
    (:attr:`pbrkit.brdf.shading.model.Model.emission_coat`,
    :func:`pbrkit.brdf.lobes.clearcoat.coated_emission` with ``f0``, a number or per
    hit); ``emissive`` itself where no material has one."""
    out = emissive
    for code, m in enumerate(COMPILED):
        if m.emission_coat is _uncoated:
            continue
        rows = np.flatnonzero(codes[material, 0] == code)
        if rows.size == 0:
            continue
        if out is emissive:
            out = np.array(emissive, dtype=np.float64)
        f = f0 if np.ndim(f0) == 0 else np.asarray(f0)[rows]
        out[rows] *= coated_emission(m.emission_coat(params, material[rows], COLUMNS), f, nov[rows])[:, None]
    return out


@dual_use(inline=True)
def hit_bxdf(codes, params, m, roughness, metallic, b0, b1, b2, nx, ny, nz, tangent):
    """The BxDF of material ``m`` at a hit with the textured roughness, metallic and
    base colour, and the tangent and bitangent of its shading frame at normal n and
    the surface's tangent ``tangent`` (x, y, z, w; :data:`pbrkit.brdf.bxdf.NO_TANGENT`
    where it has none: :func:`pbrkit.brdf.bxdf.shading_frame`); a coat's own normal
    (the row's ``coat_normal``) in that frame's coordinates
    (:func:`pbrkit.brdf.lobes.clearcoat.coat_in_frame`)."""
    b = make_bxdf(codes, m, params, m, roughness, metallic, b0, b1, b2)
    t, bt = shading_frame(nx, ny, nz, b, tangent)
    return coat_in_frame(b, nx, ny, nz, t, bt), t, bt


@dual_use(inline=True)
def hit_cosines(b, nx, ny, nz, t, bt, vx, vy, vz, lx, ly, lz):
    """:func:`pbrkit.brdf.bxdf.cosines` in the frame (n, t, bt) of a hit, without
    the tangent components for an isotropic BxDF ``b`` whose coat (if any) has no
    normal of its own."""
    if b.anisotropic or coat_tilted(b):
        return cosines(nx, ny, nz, t[0], t[1], t[2], bt[0], bt[1], bt[2], vx, vy, vz, lx, ly, lz)
    return isotropic_cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz)
