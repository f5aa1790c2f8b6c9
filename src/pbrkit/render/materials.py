"""Scene materials for the compiled kernels: each material as the integer code
row and float parameter row of the registry's layout
(:data:`pbrkit.brdf.shading.registry.LAYOUT`), and the BxDF and shading frame at
a hit point.
"""

from __future__ import annotations

import numpy as np

from ..brdf.bxdf import CODE_COLUMNS, cosines, isotropic_cosines, tangent_frame
from ..brdf.dispatch import make_bxdf
from ..brdf.material import FIELDS
from ..brdf.shading.registry import LAYOUT, model_codes
from ..core.jit import dual_use

__all__ = ["material_tables", "hit_bxdf", "hit_cosines"]


def material_tables(materials):
    """Pack :class:`pbrkit.render.textures.SurfaceMaterial` s for the kernels:
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
                      double_sided=1.0 if s.double_sided else 0.0)
        params[i] = LAYOUT.row(values)[0]
    return codes, params


@dual_use(inline=True)
def hit_bxdf(codes, params, m, roughness, metallic, b0, b1, b2, nx, ny, nz):
    """The BxDF of material ``m`` at a hit with the textured roughness, metallic and
    base colour, and the tangent and bitangent of its shading frame at normal n
    (:func:`pbrkit.brdf.bxdf.tangent_frame`)."""
    b = make_bxdf(codes, m, params, m, roughness, metallic, b0, b1, b2)
    t, bt = tangent_frame(nx, ny, nz, b.anisotropic)
    return b, t, bt


@dual_use(inline=True)
def hit_cosines(b, nx, ny, nz, t, bt, vx, vy, vz, lx, ly, lz):
    """:func:`pbrkit.brdf.bxdf.cosines` in the frame (n, t, bt) of a hit, without
    the tangent components for an isotropic BxDF ``b``."""
    if b.anisotropic:
        return cosines(nx, ny, nz, t[0], t[1], t[2], bt[0], bt[1], bt[2], vx, vy, vz, lx, ly, lz)
    return isotropic_cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz)
