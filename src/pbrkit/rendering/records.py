"""The ground truth kernels' arguments as a few records (NamedTuples of arrays, which
Numba passes as one value each): the materials, the environment's radiance and
sampling tables, the analytic shapes, the punctual and area lights, and shading
points (the primary hits, or a wavefront's path vertices).  A kernel reads the
arrays out of its records once, outside its loops over lanes (reading a record's
field counts a reference to the array; in a loop that would be a call that keeps
LLVM from vectorising it)."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .lights import light_arrays

__all__ = ["Materials", "EnvArrays", "Shapes", "Lights", "AreaArrays", "Points", "environment_arrays",
           "analytic_shapes", "punctual_lights", "area_arrays"]


class Materials(NamedTuple):
    """The scene's materials (:func:`pbrkit.rendering.materials.material_tables`): code rows
    (M, CODE_COLUMNS) int64 and parameter rows (M, LAYOUT.size) of
    :mod:`pbrkit.brdf.bxdf`."""

    codes: np.ndarray
    params: np.ndarray


class EnvArrays(NamedTuple):
    """The environment light (:class:`pbrkit.rendering.environment.EnvironmentLight`): its
    radiance (H, W, 3), its sampling distribution (``func`` (H, W), its integral
    ``total``, the alias table (H W, 2), ``rows`` (H + 1) the cos theta of the rows'
    boundaries; :attr:`~pbrkit.rendering.environment.EnvironmentLight.distribution`) and
    its rotation about y (cos, sin)."""

    radiance: np.ndarray
    func: np.ndarray
    total: float
    alias: np.ndarray
    rows: np.ndarray
    cos: float
    sin: float


class Shapes(NamedTuple):
    """The analytic shapes of a :class:`pbrkit.rendering.geometry.Geometry`: spheres (S, 4),
    their BVH (:func:`pbrkit.rendering.primitives.build_sphere_bvh`), planes (P, 6), the
    material of each, and ``eps``, how far rays start off a surface."""

    spheres: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    skip: np.ndarray
    first: np.ndarray
    count: np.ndarray
    order: np.ndarray
    planes: np.ndarray
    sphere_material: np.ndarray
    plane_material: np.ndarray
    eps: float


class Lights(NamedTuple):
    """The punctual lights (:func:`pbrkit.rendering.lights.light_arrays`)."""

    codes: np.ndarray
    values: np.ndarray


class AreaArrays(NamedTuple):
    """The area lights (:class:`pbrkit.rendering.area_lights.AreaLights`): codes (A, 4),
    values (A, 16), polygon vertices (V, 3)."""

    codes: np.ndarray
    values: np.ndarray
    vertices: np.ndarray


class Points(NamedTuple):
    """Shading points, one row each: position, geometric and shading normals, the
    direction towards the eye (N, 3), the material (N,) int64 (-1: none, a ray that
    missed), the textured roughness and metallic (N,), base colour (N, 3) and the
    surface's tangent (N, 4) (:attr:`pbrkit.rendering.geometry.Surface.tangent`), or one row
    of NO_TANGENT for points without (:func:`pbrkit.rendering.punctual.tangent_of`)."""

    p: np.ndarray
    ng: np.ndarray
    n: np.ndarray
    v: np.ndarray
    material: np.ndarray
    roughness: np.ndarray
    metallic: np.ndarray
    base_color: np.ndarray
    tangent: np.ndarray


def environment_arrays(env):
    """:class:`EnvArrays` of an :class:`pbrkit.rendering.environment.EnvironmentLight`."""
    func, total, alias, rows = env.distribution
    return EnvArrays(env.radiance, func, total, alias, rows, env.cos, env.sin)


def analytic_shapes(geometry):
    """:class:`Shapes` of a :class:`pbrkit.rendering.geometry.Geometry`."""
    return Shapes(geometry.spheres, *geometry.bvh, geometry.planes, geometry.sphere_material,
                  geometry.plane_material, 1e-7 * geometry.scale)


def punctual_lights(geometry):
    """:class:`Lights` of a :class:`pbrkit.rendering.geometry.Geometry`."""
    return Lights(*light_arrays(geometry.lights))


def area_arrays(geometry):
    """:class:`AreaArrays` of a :class:`pbrkit.rendering.geometry.Geometry`."""
    return AreaArrays(*geometry.area_lights.arrays())
