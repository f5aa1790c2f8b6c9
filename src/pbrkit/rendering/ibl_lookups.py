"""Where and at what roughness each engine's real time looks the prefiltered chain
up (:mod:`pbrkit.rendering.realtime`): the mirror direction and Filament's bent normal
for anisotropic lobes, the Sample Viewer's bent normal of KHR_materials_anisotropy,
Filament's dominant direction, and three.js's roughness with its screen-space
term.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.jit import dual_use

__all__ = ["reflection_direction", "khr_anisotropic_reflection", "three_roughness", "specular_dominant_direction",
           "THREE_MIN_ROUGHNESS"]

#: three.js's smallest perceptual roughness (``lights_physical_fragment``).
THREE_MIN_ROUGHNESS = 0.045


@dual_use(inline=True)
def _anisotropic_normal(dx, dy, dz, vx, vy, vz):
    # the anisotropic normal (d x v) x d of a grain direction d (McAuley 2015): n bent
    # within the plane of d and v (unnormalised)
    ax = dy * vz - dz * vy
    ay = dz * vx - dx * vz
    az = dx * vy - dy * vx
    return ay * dz - az * dy, az * dx - ax * dz, ax * dy - ay * dx


@dual_use
def reflection_direction(nx, ny, nz, vx, vy, vz, t, bt, anisotropy, roughness):
    """The direction a shader looks up the prefiltered environment in: the mirror
    direction R = 2 (n.v) n - v about the normal, or for an anisotropic lobe
    about Filament's bent normal (Filament documentation, "Anisotropic
    specular" IBL, after McAuley 2015 and Revie 2011): with the anisotropy
    direction d = bitangent (anisotropy >= 0) or tangent, the anisotropic
    normal a = (d x v) x d and n' = normalize(mix(n, a, |anisotropy|
    saturate(5 r))), r perceptual roughness."""
    if anisotropy != 0.0:
        if anisotropy >= 0.0:
            dx, dy, dz = bt
        else:
            dx, dy, dz = t
        qx, qy, qz = _anisotropic_normal(dx, dy, dz, vx, vy, vz)
        bend = abs(anisotropy) * min(max(5.0 * roughness, 0.0), 1.0)
        nx = nx + (qx - nx) * bend
        ny = ny + (qy - ny) * bend
        nz = nz + (qz - nz) * bend
        length = math.sqrt(nx * nx + ny * ny + nz * nz)
        nx /= length
        ny /= length
        nz /= length
    nov = nx * vx + ny * vy + nz * vz
    return 2.0 * nov * nx - vx, 2.0 * nov * ny - vy, 2.0 * nov * nz - vz


@dual_use
def khr_anisotropic_reflection(nx, ny, nz, vx, vy, vz, bt, strength, roughness):
    """The direction the Khronos glTF Sample Viewer looks up the prefiltered
    environment in for KHR_materials_anisotropy (its ``getIBLRadianceAnisotropy``,
    after Filament's bent normal, McAuley 2015): with the anisotropy bitangent B
    (across the direction of increased roughness), the anisotropic normal
    a = (B x v) x B bent back towards n by the factor (1 - strength (1 - r))^4
    (r perceptual roughness: no bend at r = 1 or strength 0), n' =
    normalize(mix(a, n, factor)), and R = reflect(-v, n')."""
    qx, qy, qz = _anisotropic_normal(bt[0], bt[1], bt[2], vx, vy, vz)
    k = 1.0 - strength * (1.0 - roughness)
    k = k * k * k * k
    mx = qx + (nx - qx) * k
    my = qy + (ny - qy) * k
    mz = qz + (nz - qz) * k
    length = math.sqrt(mx * mx + my * my + mz * mz)
    if length > 0.0:
        mx /= length
        my /= length
        mz /= length
    else:
        mx, my, mz = nx, ny, nz
    d = mx * vx + my * vy + mz * vz
    return 2.0 * d * mx - vx, 2.0 * d * my - vy, 2.0 * d * mz - vz


def three_roughness(camera, rows, normals, roughness):
    """The perceptual roughness three.js r187 shades with (``lights_physical_fragment``):
    max(r, 0.045) plus its ``geometryRoughness``, the largest component of
    max(|dFdx n|, |dFdy n|) of the view-space normal, capped at 1.  The screen-space
    derivatives are taken as a GPU's coarse ones, one difference per pixel pair
    along each axis (rows and columns paired from the image's top; each sub-pixel
    position of a supersampled camera as its own image); a neighbour that misses
    the scene counts as no change.  ``rows``: the hit rays' indices, ``normals``
    their world normals (K, 3) before normal mapping (three's ``nonPerturbedNormal``:
    :attr:`pbrkit.rendering.geometry.Surface.n_unmapped`), ``roughness`` (K,)."""
    h, w, k2 = camera.height, camera.width, camera.supersample ** 2
    right, up, forward = camera.basis()
    view = np.stack([normals @ right, normals @ up, -(normals @ forward)], axis=-1)
    grid = np.full((h * w * k2, 3), np.nan)
    grid[rows] = view
    grid = grid.reshape(h, w, k2, 3)
    dx = np.zeros_like(grid)
    dy = np.zeros_like(grid)
    pairs = 2 * (w // 2)
    dx[:, 0:pairs:2] = grid[:, 1:pairs:2] - grid[:, 0:pairs:2]
    dx[:, 1:pairs:2] = dx[:, 0:pairs:2]
    pairs = 2 * (h // 2)
    dy[0:pairs:2] = grid[1:pairs:2] - grid[0:pairs:2]
    dy[1:pairs:2] = dy[0:pairs:2]
    g = np.nan_to_num(np.maximum(np.abs(dx), np.abs(dy)), nan=0.0).max(axis=-1).reshape(-1)[rows]
    return np.minimum(np.maximum(np.asarray(roughness, dtype=np.float64), THREE_MIN_ROUGHNESS) + g, 1.0)


def specular_dominant_direction(n, r, roughness):
    """Filament's lookup direction for the prefiltered chain, mix(R, n, alpha^2)
    with alpha = r^2 (``getSpecularDominantDirection``, called with Filament's
    ``pixel.roughness`` = alpha; after Lagarde & de Rousiers 2014, "Moving
    Frostbite to PBR", sec. 4.9.3, whose fitted lerp it simplifies): rough lobes
    are centred towards the normal.  ``n``, ``r`` (K, 3), ``roughness`` (K,)
    perceptual; unnormalised, as the shader leaves it (a cube lookup needs no
    unit vector)."""
    a = np.asarray(roughness, dtype=np.float64) ** 2
    w = (a * a)[:, None]
    return np.asarray(r) * (1.0 - w) + np.asarray(n) * w
