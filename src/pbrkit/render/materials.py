"""Scene materials for the compiled kernels: each material as the integer code
row and float parameter row of :mod:`pbrkit.brdf.bxdf`, and the BxDF and
shading frame at a hit point.
"""

from __future__ import annotations

import numpy as np

from ..brdf.bxdf import (
    CODE_COLUMNS,
    DIFFUSES,
    DISTRIBUTIONS,
    FRESNELS,
    MASKINGS,
    MODELS,
    P_BASE_COLOR,
    P_DOUBLE_SIDED,
    P_EMISSIVE,
    P_METALLIC,
    P_ROUGHNESS,
    P_SPECULAR_COLOR,
    PARAM_COLUMNS,
    cosines,
    isotropic_cosines,
    make_bxdf,
    tangent_frame,
)
from ..brdf.models import parameter_rows
from ..core.jit import dual_use

__all__ = ["material_tables", "hit_bxdf", "hit_cosines"]


def material_tables(materials):
    """Pack :class:`pbrkit.render.textures.SurfaceMaterial` s for the kernels:
    ``(codes (M, CODE_COLUMNS) int64, params (M, PARAM_COLUMNS) float64)`` in the
    layout of :mod:`pbrkit.brdf.bxdf` (model, distribution, masking, Fresnel and
    diffuse as indices into their name tuples; dielectric f0 = 0.16
    reflectance^2, eta, k, specular colour, base colour, metallic, roughness,
    emissive, double-sided, anisotropy and Disney's extras)."""
    m = len(materials)
    codes = np.zeros((m, CODE_COLUMNS), dtype=np.int64)
    params = np.zeros((m, PARAM_COLUMNS), dtype=np.float64)
    for i, sm in enumerate(materials):
        s = sm.spec
        codes[i] = (MODELS.index(s.model), DISTRIBUTIONS.index(s.distribution), MASKINGS.index(s.masking),
                    FRESNELS.index(s.fresnel), DIFFUSES.index(s.diffuse))
        params[i] = parameter_rows(s.material())[0]
        params[i, P_SPECULAR_COLOR:P_SPECULAR_COLOR + 3] = s.specular_color
        params[i, P_BASE_COLOR:P_BASE_COLOR + 3] = s.base_color
        params[i, P_METALLIC] = s.metallic
        params[i, P_ROUGHNESS] = s.roughness
        params[i, P_EMISSIVE:P_EMISSIVE + 3] = s.emissive
        params[i, P_DOUBLE_SIDED] = 1.0 if s.double_sided else 0.0
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
