"""The BRDF of a scene material inside compiled kernels (material tables and :func:`brdf_value`).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ..brdf.diffuse import burley, lambert
from ..brdf.distributions import (
    alpha_from_roughness,
    d_beckmann,
    d_blinn_phong,
    d_ggx,
    phong_exponent_from_beckmann_alpha,
)
from ..brdf.fresnel import (
    f0_metallic,
    f90_filament,
    f_conductor,
    f_schlick,
    f_schlick_pow4,
    f_schlick_ue4_sg,
)
from ..brdf.masking import (
    g2_height_correlated,
    g2_kelemen,
    g2_schlick_ggx,
    g2_separable,
    k_schlick_from_alpha,
    k_ue4_direct,
    lambda_beckmann,
    lambda_ggx,
    visibility,
)
from ..brdf.models import (
    DIFFUSES,
    DISTRIBUTIONS,
    FRESNELS,
    MASKINGS,
    combine_lobes,
    filament_specular,
    ue4_specular,
    urp_specular,
)
from ..core.jit import dual_use, parallel_kernel
from .scene import SHADING_MODELS

__all__ = [
    "material_tables",
    "brdf_value",
    "brdf_values",
]

_INV_PI = 1.0 / math.pi


# material table columns (see material_tables)
_MI_MODEL, _MI_DIST, _MI_MASK, _MI_FRES, _MI_DIFF = range(5)
_MF_F0D, _MF_ETA, _MF_K, _MF_SPEC, _MF_BASE, _MF_METAL, _MF_ROUGH, _MF_EMIT, _MF_TWO_SIDED = 0, 1, 4, 7, 10, 13, 14, \
    15, 18
_MF_COLUMNS = 19


# ===================================================================== BRDF


def material_tables(materials):
    """Pack :class:`pbrkit.geometry.SurfaceMaterial` s for the kernels:
    ``(mat_i (M, 5) int64 [model, distribution, masking, fresnel, diffuse] as indices
    into SHADING_MODELS, DISTRIBUTIONS, MASKINGS, FRESNELS, DIFFUSES;
    mat_f (M, 19) float64 [dielectric f0, eta (3), k (3), specular colour (3),
    base colour (3), metallic, roughness, emissive (3), double-sided])``."""
    m = len(materials)
    mat_i = np.zeros((m, 5), dtype=np.int64)
    mat_f = np.zeros((m, _MF_COLUMNS), dtype=np.float64)
    for i, sm in enumerate(materials):
        s = sm.spec
        mat_i[i] = (SHADING_MODELS.index(s.model), DISTRIBUTIONS.index(s.distribution), MASKINGS.index(s.masking),
                    FRESNELS.index(s.fresnel), DIFFUSES.index(s.diffuse))
        mat_f[i, _MF_F0D] = 0.16 * s.reflectance ** 2
        if s.eta is not None:
            mat_f[i, _MF_ETA:_MF_ETA + 3] = s.eta
            mat_f[i, _MF_K:_MF_K + 3] = s.k
        mat_f[i, _MF_SPEC:_MF_SPEC + 3] = s.specular_color
        mat_f[i, _MF_BASE:_MF_BASE + 3] = s.base_color
        mat_f[i, _MF_METAL] = s.metallic
        mat_f[i, _MF_ROUGH] = s.roughness
        mat_f[i, _MF_EMIT:_MF_EMIT + 3] = s.emissive
        mat_f[i, _MF_TWO_SIDED] = 1.0 if s.double_sided else 0.0
    return mat_i, mat_f


@dual_use
def _specular_lobe(mi, m, nol, nov, noh, voh, roughness, alpha):
    """The Fresnel-free specular lobe D V of material m's model (module docstring)."""
    model = mi[m, _MI_MODEL]
    if model == 1:  # filament: GGX x height-correlated Smith (Filament sec. 4.4)
        return filament_specular(nol, nov, noh, alpha)
    if model == 2:  # ue4 (Karis 2013)
        return ue4_specular(nol, nov, noh, roughness)
    if model == 3:  # urp_mobile: URP's term carries pi (see pbrkit.models.urp_mobile)
        return urp_specular(noh, voh, alpha) * _INV_PI
    dist = mi[m, _MI_DIST]
    mask = mi[m, _MI_MASK]
    if dist == 0:
        d = d_ggx(noh, alpha)
    elif dist == 1:
        d = d_beckmann(noh, alpha)
    else:
        d = d_blinn_phong(noh, phong_exponent_from_beckmann_alpha(alpha))
    if mask <= 1:
        if dist == 0:
            lam_l = lambda_ggx(nol, alpha)
            lam_v = lambda_ggx(nov, alpha)
        else:
            lam_l = lambda_beckmann(nol, alpha)
            lam_v = lambda_beckmann(nov, alpha)
        if mask == 0:
            g2 = g2_height_correlated(lam_l, lam_v)
        else:
            g2 = g2_separable(lam_l, lam_v)
    elif mask == 2:
        g2 = g2_schlick_ggx(nol, nov, k_schlick_from_alpha(alpha))
    elif mask == 3:
        g2 = g2_schlick_ggx(nol, nov, k_ue4_direct(roughness))
    elif mask == 4:
        g2 = g2_kelemen(nol, nov, voh)
    else:
        g2 = max(nol, 0.0) * max(nov, 0.0)
    return d * visibility(g2, nol, nov)


@dual_use
def _fresnel(mi, mf, m, c, voh, f0, f90):
    """Fresnel of channel c for model m (cook_torrance by name; the fixed models' own)."""
    model = mi[m, _MI_MODEL]
    if model == 1:
        return f_schlick(voh, f0, f90)
    if model == 2:
        return f_schlick_ue4_sg(voh, f0)
    if model == 3:
        return f0
    fres = mi[m, _MI_FRES]
    if fres == 0:
        return f_schlick(voh, f0, 1.0)
    if fres == 1:
        return f_schlick_pow4(voh, f0, 1.0)
    if fres == 2:
        return f_schlick_ue4_sg(voh, f0)
    if fres == 3:
        return f_conductor(voh, mf[m, _MF_ETA + c], mf[m, _MF_K + c])
    if fres == 4:
        root = math.sqrt(mf[m, _MF_F0D])
        return f_conductor(voh, (1.0 + root) / max(1.0 - root, 1e-6), 0.0)
    return mf[m, _MF_SPEC + c]


@dual_use
def _f0_channel(mi, mf, m, base_c, metallic):
    """Normal-incidence specular colour of a channel in the model's metallic workflow."""
    if mi[m, _MI_MODEL] == 3:
        return f0_metallic(base_c, metallic, 0.04)
    return f0_metallic(base_c, metallic, mf[m, _MF_F0D])


@dual_use
def brdf_value(mi, mf, m, nol, nov, noh, voh, roughness, metallic, b0, b1, b2, ec0, ec1, ec2):
    """BRDF f (RGB tuple) of material m for the given cosines and textured
    parameters; ``ec`` multiplies the specular lobe (energy compensation, 1 = off).
    Zero unless n.l > 0 and n.v > 0 (:func:`pbrkit.models.combine_lobes`)."""
    if nol <= 0.0 or nov <= 0.0:
        return 0.0, 0.0, 0.0
    alpha = alpha_from_roughness(roughness)
    spec = _specular_lobe(mi, m, nol, nov, noh, voh, roughness, alpha)
    model = mi[m, _MI_MODEL]
    f00 = _f0_channel(mi, mf, m, b0, metallic)
    f01 = _f0_channel(mi, mf, m, b1, metallic)
    f02 = _f0_channel(mi, mf, m, b2, metallic)
    f90 = f90_filament(f00 + f01 + f02) if model == 1 else 1.0
    if model == 3:
        dfac = _INV_PI
        kd = 0.96 * (1.0 - metallic)
    else:
        diff = mi[m, _MI_DIFF]
        if model == 2 or diff == 0:
            dfac = lambert(nol)
        elif diff == 1:
            dfac = burley(nol, nov, voh, roughness)
        else:
            dfac = 0.0
        kd = 1.0 - metallic
    r0 = combine_lobes(nol, nov, b0 * kd, dfac, spec * ec0, _fresnel(mi, mf, m, 0, voh, f00, f90))
    r1 = combine_lobes(nol, nov, b1 * kd, dfac, spec * ec1, _fresnel(mi, mf, m, 1, voh, f01, f90))
    r2 = combine_lobes(nol, nov, b2 * kd, dfac, spec * ec2, _fresnel(mi, mf, m, 2, voh, f02, f90))
    return r0, r1, r2


@dual_use
def _cosines(nx, ny, nz, vx, vy, vz, lx, ly, lz):
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
    return nol, nov, noh, voh


@parallel_kernel
def _brdf_batch(mi, mf, mat, l, v, n, rough, metal, base, out):
    for i in numba.prange(l.shape[0]):
        nol, nov, noh, voh = _cosines(n[i, 0], n[i, 1], n[i, 2], v[i, 0], v[i, 1], v[i, 2], l[i, 0], l[i, 1],
                                      l[i, 2])
        r = brdf_value(mi, mf, mat[i], nol, nov, noh, voh, rough[i], metal[i], base[i, 0], base[i, 1], base[i, 2],
                       1.0, 1.0, 1.0)
        out[i, 0] = r[0]
        out[i, 1] = r[1]
        out[i, 2] = r[2]


def brdf_values(materials, l, v, n, material_index=0, roughness=None, metallic=None, base_color=None):
    """:func:`brdf_value` on arrays of unit directions (N, 3) from Python (for tests
    and tools); parameters default to the material's own."""
    mat_i, mat_f = material_tables(materials)
    l, v, n = (np.ascontiguousarray(np.asarray(x, dtype=np.float64).reshape(-1, 3)) for x in (l, v, n))
    count = l.shape[0]
    mat = np.ascontiguousarray(np.broadcast_to(material_index, (count,)), dtype=np.int64)
    spec = materials[int(mat[0])].spec if count else None

    def per(x, default, shape=()):
        value = default if x is None else x
        return np.ascontiguousarray(np.broadcast_to(np.asarray(value, dtype=np.float64), (count,) + shape))

    out = np.empty((count, 3))
    _brdf_batch(mat_i, mat_f, mat, l, v, n, per(roughness, spec.roughness if spec else 0.5),
                per(metallic, spec.metallic if spec else 0.0),
                per(base_color, spec.base_color if spec else (0.8, 0.8, 0.8), (3,)), out)
    return out

