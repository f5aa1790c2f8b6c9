"""Primary rays: camera rays cast into the scene, their hits, and the
resolve of sub-pixel rays into an image.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .primitives import KIND_NONE

__all__ = [
    "RenderResult",
]

# ================================================================ results


@dataclass
class RenderResult:
    """An image (H, W, 3) float64 linear radiance, its per-pixel standard error
    (reference mode), the mask of pixels whose centre ray hit a surface, and stats."""

    image: np.ndarray
    mask: np.ndarray
    stderr: np.ndarray | None = None
    stats: dict = field(default_factory=dict)


@dataclass
class _Primary:
    """Primary hits of every (pixel, sub-pixel) ray."""

    dirs: np.ndarray        # (P * K, 3)
    hit: np.ndarray         # (P * K,) bool
    rows: np.ndarray        # indices of hit rays
    surface: object         # Surface of the hit rays
    origin: np.ndarray
    emitted: np.ndarray | None = None  # (P * K, 3) radiance of the area lights camera rays see first
    hits: object = None     # the Hits of every ray (t, kind, index: G-buffers for styles)


def _primary(scene, geometry, salt=0, rays=None):
    """The primary hits of the camera's rays (``rays``: the indices of a subset, in the
    order of :meth:`pbrkit.rendering.scene.Camera.ray_directions`; default all); ``salt``
    varies the coverage of glTF BLEND surfaces (:mod:`pbrkit.rendering.alpha`) from one
    Monte Carlo sample to the next."""
    cam = scene.camera
    dirs = cam.ray_directions().reshape(-1, 3)
    if rays is not None:
        dirs = dirs[rays]
    origins = np.broadcast_to(np.asarray(cam.position, dtype=np.float64), dirs.shape)
    hits = geometry.intersect(origins, dirs, salt=salt)
    emitted = None
    if len(geometry.area_lights):  # an area light in front of the surface hides it
        t, index, radiance = geometry.area_light_hits(origins, dirs, hits.t)
        seen = index >= 0
        hits.kind[seen] = KIND_NONE
        emitted = np.where(seen[:, None], radiance, np.nan)
    rows = np.flatnonzero(hits.hit)
    surface = geometry.surface(hits, origins, dirs, rows)
    return _Primary(dirs, hits.hit, rows, surface, np.asarray(cam.position, dtype=np.float64), emitted, hits)


def _background(prim, env):
    """Radiance of the camera rays that hit no surface: the environment's background,
    or the area light they see."""
    miss = ~prim.hit
    out = env.background(prim.dirs[miss])
    if prim.emitted is not None:
        light = prim.emitted[miss]
        seen = ~np.isnan(light[:, 0])
        out[seen] = light[seen]
    return out



def _resolve(scene, per_ray, hit):
    """Average the k^2 sub-pixel rays of each pixel -> (H, W, 3); mask: the pixel's rays all hit."""
    cam = scene.camera
    k2 = cam.supersample ** 2
    image = per_ray.reshape(cam.height, cam.width, k2, -1).mean(axis=2)
    mask = hit.reshape(cam.height, cam.width, k2).all(axis=2)
    return image, mask

