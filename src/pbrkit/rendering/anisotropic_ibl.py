"""Image-based lighting of anisotropic lobes in real time by filtered importance
sampling (Krivanek & Colbert, "Real-time Shading with Filtered Importance
Sampling", EGSR 2008; GPU Gems 3, ch. 20): pbrkit's own treatment of
``KHR_materials_anisotropy`` under ``--engine pbrkit``.

The split sum looks the prefiltered environment up once, in one direction, at the
base roughness, and multiplies by the isotropic lobe's DFG: an anisotropic lobe is
neither (the lobe at strength 1 and roughness 0.3 keeps 0.53 of the light, where
the isotropic one keeps 0.99, and its reflection is stretched along the tangent,
not blurred round).  Here each pixel draws :data:`SAMPLES` fixed directions from
the lobe's own visible normals (Heitz 2018, the anisotropic GGX of the BxDF, in its
turned frame; a Hammersley set, the same for every pixel, so images repeat to the
byte and show no noise), and looks each up in the prefiltered chain at the level of
its footprint: the solid angle 1 / (K pdf(l)) of the sample, as the lobe of width
alpha_s = sqrt(Omega / (4 pi)) covers (a GGX lobe's reflected peak is 1 / (4 pi
alpha^2)), perceptual roughness sqrt(alpha_s).  The samples' weights are the
estimator's G2 / G1(v) (height-correlated Smith, KHR_materials_anisotropy's V), so

    prefiltered = sum L_k w_k / sum w_k,  DFG2 = mean w_k,  DFG1 = mean w_k (1 - v.h_k)^5

replace the lookup and the table's terms in the split sum's F0 DFG2 + (F90 - F0)
DFG1 (:mod:`pbrkit.rendering.realtime`), the Fresnel kept apart from the radiance as
there.  Measured against the ground truth in ``bench/anisotropy_rt.md``.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import row_kernel
from ..ibl.prefilter import level_of_roughness
from ..microfacet.ggx import d_ggx_anisotropic, lambda_ggx_anisotropic, warp_ggx_vndf_anisotropic
from .materials import for_materials, hit_bxdf
from .punctual import tangent_of

__all__ = ["SAMPLES", "hammersley", "anisotropic_ibl"]

#: Samples per pixel.
SAMPLES = 32


def hammersley(count):
    """The Hammersley set of ``count`` points in [0, 1)^2: ((k + 0.5) / count, the base-2
    radical inverse of k) (Hammersley & Handscomb 1964)."""
    k = np.arange(count, dtype=np.uint64)
    bits = np.zeros(count, dtype=np.float64)
    scale = 0.5
    for _ in range(32):
        bits += (k & np.uint64(1)).astype(np.float64) * scale
        k >>= np.uint64(1)
        scale *= 0.5
    return np.ascontiguousarray(np.stack([(np.arange(count) + 0.5) / count, bits], axis=-1))


@row_kernel(2)
def _fis_kernel(start, stop, mi, mf, rows, mat, n, v, rough, metal, base, tan, u, out_dir, out_roughness, out_w,
                out_fc):
    """Per pixel ``rows[j]`` and sample k: the world direction, the perceptual roughness of
    its footprint, its weight G2 / G1(v) and (1 - v.h)^5 (0 weight below the surface)."""
    count = u.shape[0]
    for j in range(start, stop):
        i = rows[j]
        b, t, bt = hit_bxdf(mi, mf, mat[i], rough[i], metal[i], base[i, 0], base[i, 1], base[i, 2], n[i, 0], n[i, 1],
                            n[i, 2], tangent_of(tan, i))
        wox = v[i, 0] * t[0] + v[i, 1] * t[1] + v[i, 2] * t[2]
        woy = v[i, 0] * bt[0] + v[i, 1] * bt[1] + v[i, 2] * bt[2]
        woz = max(v[i, 0] * n[i, 0] + v[i, 1] * n[i, 1] + v[i, 2] * n[i, 2], 1e-4)
        ax = b.alpha_x
        ay = b.alpha_y
        lam_v = lambda_ggx_anisotropic(woz, wox, woy, ax, ay)
        for k in range(count):
            hx, hy, hz = warp_ggx_vndf_anisotropic(u[k, 0], u[k, 1], wox, woy, woz, ax, ay)
            voh = wox * hx + woy * hy + woz * hz
            lx = 2.0 * voh * hx - wox
            ly = 2.0 * voh * hy - woy
            lz = 2.0 * voh * hz - woz
            out_dir[j, k, 0] = lx * t[0] + ly * bt[0] + lz * n[i, 0]
            out_dir[j, k, 1] = lx * t[1] + ly * bt[1] + lz * n[i, 1]
            out_dir[j, k, 2] = lx * t[2] + ly * bt[2] + lz * n[i, 2]
            if lz <= 0.0 or voh <= 0.0:
                out_w[j, k] = 0.0
                out_fc[j, k] = 0.0
                out_roughness[j, k] = 0.0
                continue
            lam_l = lambda_ggx_anisotropic(lz, lx, ly, ax, ay)
            out_w[j, k] = (1.0 + lam_v) / (1.0 + lam_v + lam_l)
            c = 1.0 - voh
            out_fc[j, k] = c * c * c * c * c
            # pdf(l) = G1(v) D(h) / (4 v.n) (visible normals, reflected)
            pdf = d_ggx_anisotropic(hz, hx, hy, ax, ay) / (4.0 * woz * (1.0 + lam_v))
            alpha_s = min(math.sqrt(1.0 / (count * pdf) / (4.0 * math.pi)), 1.0)
            out_roughness[j, k] = math.sqrt(alpha_s)


def anisotropic_ibl(mat_i, mat_f, rows, surface, v, tangents, sampler, to_env_frame, levels, intensity):
    """Filtered importance sampling (module docstring) of the pixels ``rows`` of
    ``surface`` (anisotropic materials), seen along ``v``: (prefiltered radiance
    (R, 3), DFG1 (R,), DFG2 (R,)) for the split sum of :mod:`pbrkit.rendering.realtime`.
    ``sampler(directions, lod)`` looks the chain of ``levels`` levels up in the
    environment's frame (``to_env_frame``)."""
    rows = np.ascontiguousarray(rows, dtype=np.int64)
    count = rows.size
    u = hammersley(SAMPLES)
    directions = np.empty((count, SAMPLES, 3))
    roughness = np.empty((count, SAMPLES))
    weight = np.empty((count, SAMPLES))
    fc = np.empty((count, SAMPLES))
    for_materials(_fis_kernel, mat_i)(mat_i, mat_f, rows, np.ascontiguousarray(surface.material),
                                      *(np.ascontiguousarray(x) for x in (surface.n, v, surface.roughness,
                                                                          surface.metallic, surface.base_color,
                                                                          tangents)),
                                      u, directions, roughness, weight, fc)
    lod = np.asarray(level_of_roughness(roughness.reshape(-1), levels), dtype=np.float64)
    radiance = sampler(to_env_frame(directions.reshape(-1, 3)), lod).reshape(count, SAMPLES, 3) * intensity
    total = weight.sum(axis=1)
    prefiltered = np.einsum("rk,rkc->rc", weight, radiance) / np.maximum(total, 1e-300)[:, None]
    return prefiltered, np.mean(weight * fc, axis=1), total / SAMPLES
