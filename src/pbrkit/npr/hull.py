"""The inverted hull outline in the ray caster: every object's shell, pushed out along
smoothed normals, seen only from inside (its back faces), drawn in the outline
colour where no object lies in front of it.

The method engines use for toon outlines (GAMES202's NPR lecture; VRM MToon 1.0,
"Outline": the outline pass draws the mesh's vertices moved along their normals
with front faces culled), cast here as rays: a camera ray that meets a back face
of an object's shell before it meets any object is an outline ray.  The push is
the outline width in pixels times the world size of a pixel at the vertex's
distance from the camera, so the outline keeps a constant width in pixels; or, for
MToon's ``worldCoordinates`` (``world``), the width itself in scene units, so the
outline narrows with distance.

- spheres: the shell of a sphere of radius r is the sphere of radius r + w, w =
  width x pixel size at the centre's distance; its back face is the far root of
  the ray's intersection with it;
- triangle meshes: vertices welded where glTF duplicates them
  (:func:`pbrkit.npr.edges.weld_vertices`), smoothed normals (the normalised sum of
  the face normals around each welded vertex, weighted by area), each vertex
  pushed by its own distance's pixel size; the shell is cast with Embree and a
  ray continues past the shell's front faces until it meets a back face or leaves;
- planes (infinite) have no hull.

Coverage is per camera ray, so ``supersample`` anti-aliases it.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["hull_pixel_size", "hull_rays", "smoothed_normals"]

#: Most shell front faces a ray passes through before its back face is looked for.
MAX_CROSSINGS = 8


def hull_pixel_size(camera):
    """World size of one pixel per unit of distance along the view: 2 tan(fov / 2) /
    height (the ``Camera`` convention: fov is vertical, pixel centres on the image
    plane at unit distance)."""
    return 2.0 * math.tan(math.radians(camera.fov) / 2.0) / camera.height


def smoothed_normals(positions, indices):
    """Unit vertex normals (V, 3): the area-weighted sum of the adjacent faces' normals
    over vertices welded by position (so the shell does not split at hard edges and
    UV seams); a vertex of only degenerate faces gets +Y."""
    from .edges import weld_vertices

    welded, remap = weld_vertices(positions)
    tri = remap[np.asarray(indices, dtype=np.int64)]
    p = welded[tri]
    face = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])  # length = twice the area: area weighting
    acc = np.zeros_like(welded)
    for c in range(3):
        np.add.at(acc, tri[:, c], face)
    length = np.linalg.norm(acc, axis=1, keepdims=True)
    unit = np.where(length > 0.0, acc / np.where(length > 0.0, length, 1.0), np.array([0.0, 1.0, 0.0]))
    return unit[remap]


def _sphere_hull(origin, dirs, t_object, spheres, width, pixel):
    """Rays (N,) that meet a sphere's shell (radius r + w) before any object; ``pixel``
    None: ``width`` is in scene units."""
    hit = np.zeros(dirs.shape[0], dtype=bool)
    for cx, cy, cz, r in spheres:
        c = np.array([cx, cy, cz])
        grow = width if pixel is None else width * pixel * float(np.linalg.norm(c - origin))
        f = origin - c
        b = dirs @ f
        disc = b * b - (f @ f - (r + grow) ** 2)
        ok = disc >= 0.0
        far = -b + np.sqrt(np.where(ok, disc, 0.0))  # the back face: the far root
        hit |= ok & (far > 0.0) & (far < t_object)
    return hit


def _mesh_hull(origin, dirs, t_object, meshes, width, pixel):
    """Rays (N,) that meet a back face of the meshes' shell before any object; ``pixel``
    None: ``width`` is in scene units."""
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh

    shell_p, shell_i = [], []
    offset = 0
    for mesh in meshes:
        n = smoothed_normals(mesh.positions, mesh.indices)
        grow = (np.full(mesh.positions.shape[0], float(width)) if pixel is None
                else width * pixel * np.linalg.norm(mesh.positions - origin, axis=1))
        shell_p.append(mesh.positions + n * grow[:, None])
        shell_i.append(np.asarray(mesh.indices, dtype=np.int64) + offset)
        offset += mesh.positions.shape[0]
    positions = np.concatenate(shell_p)
    indices = np.concatenate(shell_i)
    outward = np.concatenate([smoothed_normals(m.positions, m.indices) for m in meshes])
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene, positions.astype(np.float32), indices.astype(np.int32))
    p = positions[indices]
    face = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    # faces wound against the smoothed normals are turned to face outwards
    flip = np.sum(face * outward[indices].sum(axis=1), axis=1) < 0.0
    face[flip] = -face[flip]
    hit = np.zeros(dirs.shape[0], dtype=bool)
    active = np.arange(dirs.shape[0])
    start = np.zeros(dirs.shape[0])
    eps = 1e-5 * max(1.0, float(np.abs(positions).max()))
    for _ in range(MAX_CROSSINGS):
        if active.size == 0:
            break
        o = origin + (start[active] + eps)[:, None] * dirs[active]
        r = scene.run(o.astype(np.float32), dirs[active].astype(np.float32), output=1)
        prim = r["primID"].astype(np.int64)
        t = start[active] + eps + r["tfar"].astype(np.float64)
        met = (prim >= 0) & (t < t_object[active])
        back = met & (np.sum(face[np.maximum(prim, 0)] * dirs[active], axis=1) > 0.0)
        hit[active[back]] = True
        go = met & ~back  # a front face: continue behind it
        start[active[go]] = t[go]
        active = active[go]
    return hit


def hull_rays(scene, geometry, prim, width, world=False):
    """Per camera ray (P K,): True where the ray meets the inverted hull of a sphere or
    mesh (module docstring) before any object, ``width`` pixels wide (``world``: pushed
    out by ``width`` scene units)."""
    cam = scene.camera
    origin = np.asarray(cam.position, dtype=np.float64)
    dirs = np.ascontiguousarray(prim.dirs, dtype=np.float64)
    t_object = np.where(prim.hit, prim.hits.t, np.inf)
    pixel = None if world else hull_pixel_size(cam)
    hit = np.zeros(dirs.shape[0], dtype=bool)
    if len(geometry.spheres):
        hit |= _sphere_hull(origin, dirs, t_object, geometry.spheres, width, pixel)
    if geometry.meshes:
        hit |= _mesh_hull(origin, dirs, t_object, geometry.meshes, width, pixel)
    return hit
