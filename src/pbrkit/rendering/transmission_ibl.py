"""Real-time KHR_materials_transmission and KHR_materials_volume: the light a
transmissive glTF material lets through, looked up in the prefiltered environment
(issue 25's "transmission through the roughness-filtered environment with volume
attenuation"), for :func:`pbrkit.rendering.realtime.render_realtime`.

As the Khronos Sample Viewer does (``ibl.glsl``, ``getIBLVolumeRefraction``,
``getVolumeTransmissionRay``, ``applyIorToRoughness``, ``applyVolumeAttenuation``):

- the transmission ray: thin-walled (thickness 0) straight on, along -v; through a
  volume, GLSL's refract(-v, n, 1 / ior) followed for ``thickness`` (the volume
  README's thickness, in scene units: no node scale), one refraction only;
- the roughness of the lookup: applyIorToRoughness, r' = r clamp(2 ior - 2, 0, 1)
  (an ior near 1 does not blur what it lets through);
- the volume's attenuation over that length: attenuationColor^(thickness /
  attenuationDistance) (:func:`pbrkit.brdf.transmission.absorption`);
- KHR_materials_dispersion: a lookup per colour channel, each along its own
  refraction (the README's "Implementation"): ``engine="khronos"`` at the viewer's
  IORs, ior -+ (ior - 1) 0.025 dispersion
  (:func:`pbrkit.brdf.transmission.sample_viewer_dispersion_iors`), pbrkit at the
  ground truth's, Cauchy's n(lambda) at the Fraunhofer lines
  (:func:`pbrkit.brdf.transmission.dispersion_iors`).

Where the viewer reads its transmission framebuffer (the opaque scene rendered
behind, mip-filtered) at the projection of the ray's exit point, pbrkit reads the
environment: with ``engine="pbrkit"`` along the transmission ray's direction, with
``engine="khronos"`` along the camera's ray through the exit point (what a
framebuffer of the background shows there), each at the GGX-prefiltered level of
r'.  That background is the viewer's ``cubemap.vert``: the unit cube [-1, 1]^3 with the
view's translation replaced by ``mat[3] = vec4(0.0, 0.0, 0.0, 0.1)``, so clip w =
-z_view + 0.1 and a pixel shows the cube's point on the ray from 0.1 behind the cube's
centre (along the camera's +Z) rather than the ray from the centre: near the view axis
the directions it shows lie 1.1 times as far from the axis
(:func:`sample_viewer_background_direction`, what ``engine="khronos"`` reads when the
camera's viewing direction is given).  Other objects behind a transmissive one are not
seen through it in real time (the ground truth traces them).  The weights (the material's (1 - metallic)
transmission baseColor and the Fresnel left to the base) are the kernels'
(:func:`pbrkit.brdf.shading.gltf.ibl_transmission`,
:func:`pbrkit.rendering.khronos_ibl.sample_viewer_extensions_ibl`).
"""

from __future__ import annotations

import numpy as np

from ..brdf.shading.registry import COLUMNS, EXTENDED_CODES
from ..brdf.transmission import absorption, dispersion_iors, sample_viewer_dispersion_iors
from ..core.jit import row_kernel
from ..ibl.prefilter import level_of_roughness

__all__ = ["refract", "ior_roughness", "transmission_direction", "sample_viewer_background_direction",
           "transmission_lookups"]

_TRANSMISSION, _THICKNESS, _IOR, _DISPERSION = (COLUMNS.transmission, COLUMNS.thickness, COLUMNS.ior,
                                               COLUMNS.dispersion)


def refract(i, n, eta):
    """GLSL's refract(I, N, eta) on arrays (..., 3) (The OpenGL Shading Language,
    "Geometric Functions"): k = 1 - eta^2 (1 - (N.I)^2); 0 where k < 0 (total
    internal reflection), else eta I - (eta N.I + sqrt k) N.  ``eta`` = n_1 / n_2."""
    eta = np.asarray(eta, dtype=np.float64)[..., None]
    cos = np.sum(n * i, axis=-1, keepdims=True)
    k = 1.0 - eta * eta * (1.0 - cos * cos)
    out = eta * i - (eta * cos + np.sqrt(np.maximum(k, 0.0))) * n
    return np.where(k < 0.0, 0.0, out)


def ior_roughness(r, ior):
    """The Sample Viewer's applyIorToRoughness: r clamp(2 ior - 2, 0, 1), the perceptual
    roughness at which the transmitted light is blurred."""
    return np.asarray(r) * np.clip(2.0 * np.asarray(ior) - 2.0, 0.0, 1.0)


def transmission_direction(n, v, ior, thickness):
    """The transmission ray's direction (..., 3) (module docstring): -v through a thin wall
    (``thickness`` 0), refract(-v, n, 1 / ior) into a volume (-v where that is total
    internal reflection, which a ray from outside never meets)."""
    bent = refract(-v, n, 1.0 / np.asarray(ior, dtype=np.float64))
    bent = np.where(np.sum(bent * bent, axis=-1, keepdims=True) > 0.0, bent, -v)
    return np.where((np.asarray(thickness) > 0.0)[..., None], bent, -v)


def sample_viewer_background_direction(d, forward):
    """The environment direction (..., 3) the Sample Viewer's background (``cubemap.vert``,
    module docstring) shows along the camera's world rays ``d`` (..., 3, unit), the camera
    looking along ``forward``: the point where the ray from e = -0.1 forward along d
    leaves the cube [-1, 1]^3, normalised."""
    d = np.asarray(d, dtype=np.float64)
    f = np.asarray(forward, dtype=np.float64)
    e = -0.1 * f / np.linalg.norm(f)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(np.abs(d) > 1e-12, (np.where(d > 0.0, 1.0, -1.0) - e) / d, np.inf).min(axis=-1)
    a = e + t[..., None] * d
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


@row_kernel(2)
def _attenuation(start, stop, params, material, length, out):
    for i in range(start, stop):
        a = absorption(params, material[i], length[i])
        out[i, 0] = a[0]
        out[i, 1] = a[1]
        out[i, 2] = a[2]


def transmission_lookups(codes, params, surface, v, camera_position, sampler, to_env_frame, levels, engine,
                         camera_forward=None):
    """The light transmitted through each hit (N, 3): the prefiltered environment along
    the transmission ray (module docstring) times the volume's attenuation, for the hits
    of extended glTF materials with transmission > 0; zeros elsewhere.  A single zero
    row where no hit transmits (the kernels then read none).  ``sampler(directions,
    lods)`` reads the chain of ``levels`` levels, ``to_env_frame`` maps world
    directions into the map's frame.  ``camera_forward``: the camera's viewing direction,
    with which ``engine="khronos"`` reads the viewer's background
    (:func:`sample_viewer_background_direction`); without it the camera's ray itself."""
    material = surface.material
    gltf = codes[material, 0] == EXTENDED_CODES["gltf"]
    rows = np.flatnonzero(gltf & (params[material, _TRANSMISSION] > 0.0))
    if rows.size == 0:
        return np.zeros((1, 3))
    m = material[rows]
    n = surface.n[rows]
    vv = v[rows]
    thickness = params[m, _THICKNESS]

    def lookup(ior):
        ior = np.maximum(ior, 1.0)  # KHR_materials_ior's 0 (f0 1) refracts as 1
        direction = transmission_direction(n, vv, ior, thickness)
        if engine == "khronos":  # the background a framebuffer shows at the exit point's projection
            exit_ = surface.p[rows] + direction * thickness[:, None]
            toward = exit_ - np.asarray(camera_position, dtype=np.float64)
            toward /= np.maximum(np.linalg.norm(toward, axis=-1, keepdims=True), 1e-300)
            direction = np.where((thickness > 0.0)[:, None], toward, -vv)
            if camera_forward is not None:
                direction = sample_viewer_background_direction(direction, camera_forward)
        lod = level_of_roughness(ior_roughness(surface.roughness[rows], ior), levels)
        return sampler(to_env_frame(np.ascontiguousarray(direction)), np.asarray(lod, dtype=np.float64))

    light = lookup(params[m, _IOR])
    dispersion = params[m, _DISPERSION]
    # KHR_materials_dispersion: a lookup per channel where it applies (pbrkit: the volumes, as the
    # ground truth; the viewer's getTransmissionSample: every dispersive material, its IORs
    # blurring thin walls too)
    dispersive = (dispersion > 0.0) & ((thickness > 0.0) | (engine == "khronos"))
    if np.any(dispersive):
        iors = (sample_viewer_dispersion_iors if engine == "khronos" else dispersion_iors)(params[m, _IOR],
                                                                                           dispersion)
        for c in range(3):
            light[:, c] = np.where(dispersive, lookup(iors[:, c])[:, c], light[:, c])
    att = np.empty((rows.size, 3))
    _attenuation(params, np.ascontiguousarray(m), np.ascontiguousarray(thickness, dtype=np.float64), att)
    out = np.zeros((material.size, 3))
    out[rows] = light * att
    return out
