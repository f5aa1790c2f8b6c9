"""Shared test helper: the unit sphere scene of the renderer tests, and its per-pixel hit
data computed independently of pbrkit's ray caster (a ray-sphere intersection written
here)."""

from __future__ import annotations

import numpy as np

from pbrkit.rendering.scene import Camera, MaterialSpec, Scene, Sphere


def sphere_scene(material, environment, size=16, fov=35.0, distance=4.0, lights=(), supersample=1):
    """A unit sphere of ``material`` at the origin seen from ``distance`` on +Z under
    ``environment`` and ``lights``: a ``size`` x ``size`` image."""
    cam = Camera(position=(0.0, 0.0, distance), look_at=(0.0, 0.0, 0.0), fov=fov, width=size, height=size,
                 supersample=supersample)
    materials = {"default": MaterialSpec(), "m": material}
    return Scene(camera=cam, environment=environment, materials=materials,
                 objects=(Sphere(center=(0.0, 0.0, 0.0), radius=1.0, material="m"),), lights=tuple(lights))


def pixel_geometry(scene):
    """Independent per-pixel hit data of a unit sphere at the origin: (mask, p = n, v)."""
    cam = scene.camera
    d = cam.ray_directions()[:, :, 0]
    o = np.asarray(cam.position)
    b = d @ o
    disc = b * b - (o @ o - 1.0)
    mask = disc > 0
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    p = o + t[..., None] * d
    return mask, p, -d
