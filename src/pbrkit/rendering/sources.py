"""The scene a name or a path stands for (``pbrkit render SCENE``, ``pbrkit.render(scene)``): a
built-in scene, a scene file, or a glTF file as a scene of its own (``pbrkit render model.glb``):
the model under the bundled environment (or the one given), seen from +Z (glTF's front:
"the front of a glTF asset faces +Z", glTF 2.0 specification, "Coordinate System and Units")
by a camera that frames its bounds, as the Khronos glTF Sample Viewer's default camera does.

Framing: the bounding sphere of the world-space vertices (centre: the centre of their
bounding box; radius: the largest distance of a vertex from it) fills :data:`FILL` of the
narrower of the two fields of view (the vertical ``fov`` of :data:`FOV` degrees, and the
horizontal one the aspect ratio gives), the camera looking at its centre.

Sizes: where only one of ``width`` and ``height`` is given, the other keeps the scene's
aspect ratio (a built-in scene's, a scene file's camera's, a glTF file's square).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from dataclasses import replace

from ..core.errors import InputError
from ..io.gltf_resources import allowed_root
from .scene import BUILTIN_SCENES, BUILTIN_SIZES, Camera, EnvironmentSpec, GltfObject, Scene, builtin_scene, load_scene

__all__ = ["GLTF_SUFFIXES", "FOV", "FILL", "frame_bounds", "gltf_scene", "keep_aspect", "resolve_scene",
           "command_scene"]

#: The suffixes of glTF files.
GLTF_SUFFIXES = (".gltf", ".glb")
#: The camera's vertical field of view (degrees) and the share of it the model fills.
FOV = 35.0
FILL = 0.9


def frame_bounds(points, width, height, fov=FOV, fill=FILL):
    """A :class:`Camera` on +Z of the bounding sphere of ``points`` (N, 3) that frames it
    (module docstring) at ``width`` x ``height`` pixels."""
    points = np.asarray(points, dtype=np.float64)
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = 0.5 * (lo + hi)
    radius = float(np.sqrt(((points - centre) ** 2).sum(axis=1).max()))
    if not radius > 0.0:
        radius = 1.0
    half_v = math.radians(fov) / 2.0
    half = min(half_v, math.atan(math.tan(half_v) * width / height))  # the narrower field of view
    distance = radius / math.sin(half * fill)
    position = centre + np.array([0.0, 0.0, distance])
    return Camera(position=tuple(position), look_at=tuple(centre), fov=fov, width=width, height=height)


def gltf_scene(path, width=None, height=None, environment=None):
    """The scene of a glTF file alone (module docstring): 512 x 512 unless ``width`` /
    ``height`` say otherwise (one of them keeps the square), ``environment`` (an
    :class:`EnvironmentSpec`) or the bundled map.  Problems of the file raise
    :class:`pbrkit.core.errors.InputError` naming it."""
    from .gltf import load_gltf

    path = Path(path)
    if not path.is_file():
        raise InputError("no such glTF file", path)
    asset = load_gltf(path)
    points = [m.positions for m in asset.meshes if len(m.positions)]
    if not points:
        raise InputError("the glTF file has no triangles to render", path)
    width, height = keep_aspect(512, 512, width, height)
    camera = frame_bounds(np.concatenate(points), width, height)
    return Scene(camera=camera, environment=environment or EnvironmentSpec(), objects=(GltfObject(str(path)),),
                 source=str(path))


def keep_aspect(default_width, default_height, width=None, height=None):
    """(width, height): the defaults where neither is given, and where one is, the other
    from the defaults' aspect ratio (at least 1 pixel)."""
    if width is None and height is None:
        return default_width, default_height
    if height is None:
        return int(width), max(1, round(int(width) * default_height / default_width))
    if width is None:
        return max(1, round(int(height) * default_width / default_height)), int(height)
    return int(width), int(height)


def command_scene(name_or_path, width=None, height=None, env=None, fix_nonfinite=False, allow_roots=()):
    """The scene ``pbrkit render`` and ``pbrkit batch render`` draw: :func:`resolve_scene`
    with ``env`` (an environment image file or a bake folder) replacing the scene's
    environment, ``fix_nonfinite`` repairing its NaN / Inf pixels, and ``allow_roots``
    (``--allow-root``) added to the scene's ``allow_roots``."""
    roots = []
    for root in allow_roots:
        try:
            roots.append(allowed_root(root, None, "--allow-root"))
        except ValueError as exc:
            raise InputError(str(exc)) from None
    environment = None
    if env is not None:
        env = Path(env)
        if not env.exists():
            raise InputError("environment file not found", env)
        environment = EnvironmentSpec(bake=str(env)) if env.is_dir() else EnvironmentSpec(file=str(env))
    scene = resolve_scene(name_or_path, width, height, environment)
    if fix_nonfinite:
        scene = replace(scene, environment=replace(scene.environment, fix_nonfinite=True))
    if roots:
        scene = replace(scene, allow_roots=scene.allow_roots + tuple(roots))
    return scene


def resolve_scene(name_or_path, width=None, height=None, environment=None):
    """A built-in scene by name, a scene file, or a glTF file (:func:`gltf_scene`);
    ``width``/``height`` override the camera's (one of them keeps the aspect ratio,
    :func:`keep_aspect`), ``environment`` (an :class:`EnvironmentSpec`) the scene's."""
    if str(name_or_path) in BUILTIN_SCENES:
        width, height = keep_aspect(*BUILTIN_SIZES[str(name_or_path)], width, height)
        return builtin_scene(str(name_or_path), width, height, environment)
    path = Path(name_or_path)
    if not path.exists():
        raise InputError(f"no such scene file (built-in scenes: {', '.join(BUILTIN_SCENES)})", path)
    if path.suffix.lower() in GLTF_SUFFIXES:
        return gltf_scene(path, width, height, environment)
    scene = load_scene(path)
    if width is not None or height is not None:
        width, height = keep_aspect(scene.camera.width, scene.camera.height, width, height)
    changes = {k: v for k, v in (("width", width), ("height", height)) if v is not None}
    if changes:
        try:
            scene = scene.with_camera(**changes)
        except ValueError as exc:
            raise InputError(str(exc), path) from None
    if environment is not None:
        scene = replace(scene, environment=environment)
    return scene
