"""Scenes for ``pbrkit render``: the camera, the environment, materials,
objects and punctual lights, read from a TOML or JSON file or built in.

A scene file (TOML shown; JSON has the same structure).  Relative paths are
relative to the scene file's folder.  Every key is optional except
``objects``; unknown keys are errors::

    allow_roots = ["../shared-textures"]  # folders besides a glTF model's own that its
                                  # buffer and image URIs may name (also --allow-root)

    [camera]                      # pinhole camera, looks down its -Z
    position = [0.0, 0.0, 5.0]
    look_at = [0.0, 0.0, 0.0]
    up = [0.0, 1.0, 0.0]
    fov = 40.0                    # vertical field of view, degrees
    width = 512
    height = 512
    supersample = 1               # k: k x k rays per pixel (stratified), 1 = the pixel centre

    [environment]                 # one of file / bake / color; default: the bundled CC0 map
    file = "studio.hdr"           # equirect .hdr/.exr/.pfm, or a cube cross
    # bake = "bake_dir"           # a directory written by `pbrkit bake`
    # color = [1.0, 1.0, 1.0]     # constant radiance
    intensity = 1.0
    rotation = 0.0                # degrees about +Y (counter-clockwise seen from +Y)

    [materials.gold]              # every model's keys, ranges and defaults: docs/materials.md
    model = "gltf"                # gltf (default: glTF 2.0 Appendix B), cook_torrance, filament, ue4,
                                  # urp_mobile, disney
    base_color = [1.0, 0.78, 0.34]
    metallic = 1.0
    roughness = 0.3               # perceptual roughness, alpha = r^2
    emissive = [0.0, 0.0, 0.0]    # emitted radiance (cd / m^2); any model

    [materials.clay]
    model = "cook_torrance"       # chooses its terms by name:
    distribution = "ggx"          # ggx, beckmann, blinn-phong
    masking = "height-correlated" # height-correlated, separable, schlick-ggx, schlick-ggx-ue4, kelemen, implicit
    fresnel = "schlick"           # schlick, schlick-pow4, ue4-sg, exact-conductor, exact-dielectric, none
    diffuse = "eon"               # lambert, burley, none, eon (energy-preserving Oren-Nayar)
    base_color = [0.6, 0.35, 0.25]
    roughness = 0.8
    # conductor = "gold"          # a metal's complex IOR (eta, k) for exact-conductor

    [[objects]]
    type = "sphere"
    center = [0.0, 0.0, 0.0]
    radius = 1.0
    material = "gold"

    [[objects]]
    type = "plane"                # infinite plane
    point = [0.0, -1.0, 0.0]
    normal = [0.0, 1.0, 0.0]
    material = "gold"

    [[objects]]
    type = "gltf"                 # glTF 2.0 (.gltf or .glb), its own materials
    file = "model.glb"
    translation = [0.0, 0.0, 0.0]
    rotation = [0.0, 0.0, 0.0, 1.0]   # unit quaternion (x, y, z, w), as in glTF
    scale = 1.0                       # or [sx, sy, sz]

    [[lights]]                    # KHR_lights_punctual units: lux, candela
    type = "spot"                 # directional, point, spot
    position = [0.0, 4.0, 0.0]
    direction = [0.0, -1.0, 0.0]  # the direction the light travels
    color = [1.0, 1.0, 1.0]
    intensity = 50.0
    range = 20.0                  # optional
    inner_cone_angle = 0.2        # radians (spot)
    outer_cone_angle = 0.5
    falloff = "khr"               # khr (windowed 1/d^2) or ue4 (Karis 2013 eq. 9)

    [[lights]]                    # area lights (pbrkit.rendering.area_lights): rect, polygon, disk, sphere
    type = "rect"
    position = [0.0, 3.0, 0.0]    # centre (rect, disk, sphere)
    normal = [0.0, -1.0, 0.0]     # the side it emits to (rect, disk)
    up = [0.0, 0.0, 1.0]          # rect: direction of its height edge (optional)
    width = 2.0                   # rect
    height = 1.0                  # rect
    # radius = 0.5                # disk, sphere
    # vertices = [[...], ...]     # polygon: 3-32 points, planar, convex, counter-clockwise from the lit side
    two_sided = false             # rect, polygon, disk
    color = [1.0, 1.0, 1.0]
    intensity = 10.0
    unit = "radiance"             # radiance (cd / m^2) or power (lumens, Lambertian emitter)

    [style]                       # optional: non-photorealistic style (pbrkit.npr.style), real time only
    shading = "toon"              # pbr, toon, mtoon, hatching
    outline = "image"             # none, image, geometry, both

Camera conventions (``CONVENTIONS.md``, "Camera"): right-handed world, +Y up;
the camera looks along ``look_at - position`` (its -Z); image row 0 is the
top and column 0 the left; without supersampling the ray of pixel (row i,
column j) passes through the pixel centre (i + 0.5, j + 0.5) of the image
plane at unit distance whose half height is tan(fov / 2) (and half width
tan(fov / 2) * width / height).  With ``supersample = k`` the rays pass
through the centres of the k x k sub-pixels (an ordered grid).

Built-in scenes (:func:`builtin_scene`): ``spheres``, a 7 x 7 grid of
spheres with perceptual roughness 0, 1/6, ..., 1 across (left to right) and
metallic 0, 1/6, ..., 1 down (top to bottom), seen from far away with a
narrow field of view; ``sphere``, one material ball; and ``area``, five gold
spheres of perceptual roughness 0.1 to 0.9 on a grey floor under a 4 x 1 m rect
light (radiance 8 cd / m^2) in a dim constant environment (0.03 cd / m^2), the
area-light scene of the demo, at width x width / 2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..brdf.shading.registry import MODELS
from ..core import checks
from ..core.documents import FORMATS, parse_document
from ..core.errors import InputError
from ..core.inputs import describe, read_text
from ..io.gltf_resources import allowed_root
from .area_lights import AREA_LIGHT_TYPES, AreaLight
from .lights import LIGHT_TYPES, Light
from .material_spec import MaterialSpec
from .scene_checks import (  # noqa: F401 - MAX_* re-exported
    MAX_COORDINATE, MAX_INTENSITY, _AREA_LIGHT_KEYS, _AREA_LIGHT_VALUES, _CAMERA_KEYS, _CAMERA_VALUES,
    _ENV_KEYS, _ENV_VALUES, _LIGHT_KEYS, _LIGHT_VALUES, _MATERIAL_KEYS, _MATERIAL_VALUES, _OBJECT_KEYS,
    _OBJECT_VALUES, _SECTIONS, _STRING, _check_keys, _check_values, _name, _show)

__all__ = [
    "Camera",
    "EnvironmentSpec",
    "MaterialSpec",
    "Sphere",
    "Plane",
    "GltfObject",
    "Scene",
    "SHADING_MODELS",
    "BUILTIN_SCENES",
    "BUILTIN_SIZES",
    "load_scene",
    "scene_from_dict",
    "builtin_scene",
    "bundled_environment",
]

#: Shading models a scene material may name (those of :mod:`pbrkit.brdf.models`).
SHADING_MODELS = MODELS
BUILTIN_SCENES = ("spheres", "sphere", "area")
#: Each built-in scene's size (width, height) where neither is given.
BUILTIN_SIZES = {"spheres": (512, 512), "sphere": (512, 512), "area": (512, 256)}
#: What a scene file must be, for messages.
SCENE_EXPECTED = "a .toml or .json scene file (pbrkit.rendering.scene)"


# ---------------------------------------------------------------- camera


@dataclass(frozen=True)
class Camera:
    """Pinhole camera (module docstring)."""

    position: tuple = (0.0, 0.0, 5.0)
    look_at: tuple = (0.0, 0.0, 0.0)
    up: tuple = (0.0, 1.0, 0.0)
    fov: float = 40.0
    width: int = 512
    height: int = 512
    supersample: int = 1

    def __post_init__(self):
        set_ = object.__setattr__
        for name in ("position", "look_at", "up"):
            set_(self, name, tuple(float(x) for x in checks.vector(getattr(self, name), f"camera.{name}")))
        fov = float(self.fov)
        if not 0.0 < fov < 180.0:
            raise ValueError(f"camera.fov must be in (0, 180) degrees; got {self.fov!r}")
        set_(self, "fov", fov)
        for name, hi in (("width", 16384), ("height", 16384), ("supersample", 16)):
            set_(self, name, checks.integer(getattr(self, name), f"camera.{name}", 1, hi))
        forward = np.subtract(self.look_at, self.position)
        if np.linalg.norm(forward) == 0.0:
            raise ValueError("camera.look_at must differ from camera.position")
        if np.linalg.norm(np.cross(forward, self.up)) <= 1e-9 * np.linalg.norm(forward) * np.linalg.norm(self.up):
            raise ValueError("camera.up must not be parallel to the viewing direction (look_at - position)")

    def basis(self):
        """(right, true_up, forward) unit vectors: forward = the viewing direction
        (the camera's -Z), right = forward x up, true_up = right x forward."""
        forward = np.subtract(self.look_at, self.position).astype(float)
        forward /= np.linalg.norm(forward)
        right = np.cross(forward, self.up)
        right /= np.linalg.norm(right)
        return right, np.cross(right, forward), forward

    def subpixel_offsets(self):
        """(k^2, 2) offsets (row, column) inside a pixel of the k x k sub-pixel centres."""
        k = self.supersample
        c = (np.arange(k) + 0.5) / k
        rows, cols = np.meshgrid(c, c, indexing="ij")
        return np.stack([rows.ravel(), cols.ravel()], axis=-1)

    def ray_directions(self, rows=None, cols=None):
        """Unit ray directions: (H, W, k^2, 3) for the whole image, or for the given
        fractional image coordinates ``rows``, ``cols`` (any equal shapes; the pixel
        centre of (i, j) is (i + 0.5, j + 0.5)) an array of that shape + (3,)."""
        right, up, forward = self.basis()
        t = math.tan(math.radians(self.fov) / 2.0)
        aspect = self.width / self.height
        if rows is None:
            off = self.subpixel_offsets()
            rows = np.arange(self.height)[:, None, None] + off[None, None, :, 0]
            cols = np.arange(self.width)[None, :, None] + off[None, None, :, 1]
            rows, cols = np.broadcast_arrays(rows, cols)
        rows = np.asarray(rows, dtype=float)
        cols = np.asarray(cols, dtype=float)
        x = (2.0 * cols / self.width - 1.0) * t * aspect
        y = (1.0 - 2.0 * rows / self.height) * t
        d = forward + x[..., None] * right + y[..., None] * up
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    def project(self, points):
        """Fractional image coordinates (rows, cols) of world points (..., 3) (inverse of
        :meth:`ray_directions`); points behind the camera give NaN."""
        right, up, forward = self.basis()
        p = np.asarray(points, dtype=float) - np.asarray(self.position)
        z = p @ forward
        t = math.tan(math.radians(self.fov) / 2.0)
        aspect = self.width / self.height
        with np.errstate(divide="ignore", invalid="ignore"):
            x = (p @ right) / z / (t * aspect)
            y = (p @ up) / z / t
        cols = np.where(z > 0, (x + 1.0) * 0.5 * self.width, np.nan)
        rows = np.where(z > 0, (1.0 - y) * 0.5 * self.height, np.nan)
        return rows, cols


# ------------------------------------------------------------- environment


@dataclass(frozen=True)
class EnvironmentSpec:
    """Where the environment comes from: exactly one of ``file`` (an image),
    ``bake`` (a bake directory), ``color`` (constant radiance) or ``equirect``
    (an in-memory (H, 2H, 3) array); none of them means the bundled map.
    ``intensity`` multiplies the radiance; ``rotation`` (degrees) turns the
    environment about +Y: the radiance arriving from world direction d is the
    map's radiance at R_y(-rotation) d.  ``fix_nonfinite`` repairs NaN / Inf
    pixels of ``file`` (:func:`pbrkit.io.environment.load_environment`; the
    ``--fix-nonfinite`` flag) instead of refusing them."""

    file: str | None = None
    bake: str | None = None
    color: tuple | None = None
    equirect: np.ndarray | None = field(default=None, compare=False, repr=False)
    intensity: float = 1.0
    rotation: float = 0.0
    fix_nonfinite: bool = False

    def __post_init__(self):
        given = [k for k in ("file", "bake", "color", "equirect") if getattr(self, k) is not None]
        if len(given) > 1:
            raise ValueError(f"environment takes only one of file, bake, color; got {', '.join(given)}")
        if self.color is not None:
            c = np.asarray(self.color, dtype=float)
            if c.shape != (3,) or not np.all(np.isfinite(c)) or np.any(c < 0):
                raise ValueError(f"environment.color must be 3 finite non-negative numbers; got {self.color!r}")
            object.__setattr__(self, "color", tuple(float(x) for x in c))
        if self.equirect is not None:
            a = np.asarray(self.equirect)
            if a.ndim != 3 or a.shape[2] != 3 or a.shape[1] != 2 * a.shape[0]:
                raise ValueError(f"environment.equirect must have shape (H, 2H, 3); got {a.shape}")
        intensity = float(self.intensity)
        if not np.isfinite(intensity) or intensity < 0:
            raise ValueError(f"environment.intensity must be finite and >= 0; got {self.intensity!r}")
        rotation = float(self.rotation)
        if not np.isfinite(rotation):
            raise ValueError(f"environment.rotation must be finite; got {self.rotation!r}")
        object.__setattr__(self, "intensity", intensity)
        object.__setattr__(self, "rotation", rotation)


def bundled_environment():
    """Path of the CC0 environment map shipped with pbrkit (:func:`pbrkit.data.environment_path`)."""
    from ..data import environment_path

    return environment_path()


# --------------------------------------------------------------- materials
# MaterialSpec is generated from the models' declarations (pbrkit.rendering.material_spec).


# ----------------------------------------------------------------- objects


def _vector(what, value, n=3):
    return tuple(float(x) for x in checks.vector(value, what, n))


@dataclass(frozen=True)
class Sphere:
    center: tuple = (0.0, 0.0, 0.0)
    radius: float = 1.0
    material: str = "default"

    def __post_init__(self):
        object.__setattr__(self, "center", _vector("sphere center", self.center))
        r = float(self.radius)
        if not np.isfinite(r) or r <= 0.0:
            raise ValueError(f"sphere radius must be positive; got {self.radius!r}")
        object.__setattr__(self, "radius", r)


@dataclass(frozen=True)
class Plane:
    point: tuple = (0.0, 0.0, 0.0)
    normal: tuple = (0.0, 1.0, 0.0)
    material: str = "default"

    def __post_init__(self):
        object.__setattr__(self, "point", _vector("plane point", self.point))
        n = np.asarray(_vector("plane normal", self.normal))
        if np.linalg.norm(n) == 0.0:
            raise ValueError("plane normal must not be zero")
        object.__setattr__(self, "normal", tuple(n / np.linalg.norm(n)))


@dataclass(frozen=True)
class GltfObject:
    """A glTF 2.0 file placed with translation, rotation (unit quaternion x, y, z, w)
    and scale, applied as T R S to the file's scene (glTF's node transform order)."""

    file: str
    translation: tuple = (0.0, 0.0, 0.0)
    rotation: tuple = (0.0, 0.0, 0.0, 1.0)
    scale: tuple = (1.0, 1.0, 1.0)

    def __post_init__(self):
        object.__setattr__(self, "translation", _vector("gltf translation", self.translation))
        q = np.asarray(_vector("gltf rotation (quaternion x, y, z, w)", self.rotation, 4))
        if abs(np.linalg.norm(q) - 1.0) > 1e-3:
            raise ValueError(f"gltf rotation must be a unit quaternion (x, y, z, w); got {self.rotation!r}")
        object.__setattr__(self, "rotation", tuple(q / np.linalg.norm(q)))
        s = self.scale
        if np.ndim(s) == 0:
            s = (s, s, s)
        s = _vector("gltf scale", s)
        if any(x == 0.0 for x in s):
            raise ValueError("gltf scale must not be zero")
        object.__setattr__(self, "scale", s)

    def matrix(self):
        """4 x 4 matrix T R S (glTF 2.0 sec. 3.5.3)."""
        return trs_matrix(self.translation, self.rotation, self.scale)


def trs_matrix(translation, rotation, scale):
    """4 x 4 matrix T R S from translation, unit quaternion (x, y, z, w) and scale (glTF 2.0, sec. 3.5.3)."""
    x, y, z, w = rotation
    r = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])
    m = np.eye(4)
    m[:3, :3] = r * np.asarray(scale, dtype=float)[None, :]
    m[:3, 3] = translation
    return m


# ------------------------------------------------------------------- scene


@dataclass(frozen=True)
class Scene:
    """Everything a render needs; ``source`` names the file (or built-in) it came from."""

    camera: Camera = field(default_factory=Camera)
    environment: EnvironmentSpec = field(default_factory=EnvironmentSpec)
    materials: dict = field(default_factory=lambda: {"default": MaterialSpec()})
    objects: tuple = ()
    lights: tuple = ()
    area_lights: tuple = ()
    source: str = "<scene>"
    style: object = None  # a pbrkit.npr.style.Style, from [style]
    allow_roots: tuple = ()  # folders besides a glTF file's own whose files it may name (allow_roots)

    def __post_init__(self):
        if not self.objects:
            raise ValueError("scene has no objects")
        for obj in self.objects:
            if isinstance(obj, (Sphere, Plane)) and obj.material not in self.materials:
                defined = ", ".join(_name(m) for m in sorted(self.materials)[:20])
                raise ValueError(f"{type(obj).__name__.lower()} uses material {describe(obj.material)}, which is "
                                 f"not defined (defined: {defined or 'none'}"
                                 f"{', ...' if len(self.materials) > 20 else ''})")

    def with_camera(self, **changes):
        """A copy with some camera fields changed (e.g. width, height)."""
        return replace(self, camera=replace(self.camera, **changes))


def _resolve(base_dir, path, what):
    if not isinstance(path, str) or not path:
        raise ValueError(f"{what} must be a non-empty string path; got {path!r}")
    p = Path(path)
    if not p.is_absolute() and base_dir is not None:
        p = Path(base_dir) / p
    if not p.exists():
        raise ValueError(f"{what} {str(p)!r} does not exist")
    return str(p)


def scene_from_dict(data, base_dir=None, source="<scene>"):
    """Build and validate a :class:`Scene` from the parsed content of a scene file.
    Raises ``ValueError`` with a one-line message naming the problem (and the key)."""
    _check_keys("scene", data, _SECTIONS)
    return Scene(camera=_camera_from(data.get("camera", {})),
                 environment=_environment_from(data.get("environment", {}), base_dir),
                 materials=_materials_from(data.get("materials", {})),
                 objects=_objects_from(data.get("objects", []), base_dir),
                 **_lights_from(data.get("lights", [])), source=source,
                 style=_style_from(data["style"], base_dir) if "style" in data else None,
                 allow_roots=_allow_roots_from(data.get("allow_roots", []), base_dir))


def _allow_roots_from(items, base_dir):
    """The folders of the ``allow_roots`` key (relative to the scene file's folder): a
    glTF model may name files under them besides its own folder (:mod:`pbrkit.core.inputs`)."""
    if not isinstance(items, list) or not all(_STRING.ok(item) for item in items):
        raise ValueError(f"allow_roots must be a list of folder paths (non-empty strings), got {_show(items)}")
    return tuple(allowed_root(item, base_dir, f"allow_roots[{i}]") for i, item in enumerate(items))


def _style_from(table, base_dir):
    from ..npr.style import style_from_dict

    return style_from_dict(table, base_dir)


def _camera_from(table):
    _check_keys("camera", table, _CAMERA_KEYS)
    _check_values(table, _CAMERA_VALUES, lambda key: f"camera.{key}")
    return Camera(**table)


def _environment_from(table, base_dir):
    _check_keys("environment", table, _ENV_KEYS)
    _check_values(table, _ENV_VALUES, lambda key: f"environment.{key}")
    env = dict(table)
    for key in ("file", "bake"):
        if key in env:
            env[key] = _resolve(base_dir, env[key], f"environment.{key}")
    return EnvironmentSpec(**env)


def _materials_from(table):
    if not isinstance(table, dict):
        raise ValueError("materials must be a table of named materials")
    materials = {"default": MaterialSpec()}
    for name, spec in table.items():
        _check_keys(f"materials.{_name(name)}", spec, _MATERIAL_KEYS)
        _check_values(spec, _MATERIAL_VALUES, lambda key, name=name: f"material {describe(name)}: {key}")
        materials[name] = MaterialSpec(name=name, **spec)
    return materials


_OBJECT_TYPES = {"sphere": Sphere, "plane": Plane, "gltf": GltfObject}


def _objects_from(items, base_dir):
    if not isinstance(items, list):
        raise ValueError("objects must be an array of tables")
    return tuple(_object_from(obj, f"objects[{index}]", base_dir) for index, obj in enumerate(items))


def _object_from(obj, where, base_dir):
    if not isinstance(obj, dict) or "type" not in obj:
        raise ValueError(f"{where} needs a type ({', '.join(_OBJECT_KEYS)})")
    kind = obj["type"]
    if not isinstance(kind, str) or kind not in _OBJECT_KEYS:
        raise ValueError(f"{where}: unknown type {_show(kind)}; choose one of {', '.join(_OBJECT_KEYS)}")
    _check_keys(where, obj, _OBJECT_KEYS[kind])
    _check_values(obj, _OBJECT_VALUES, lambda key: f"{where} ({kind}): {key}")
    args = {k: v for k, v in obj.items() if k != "type"}
    if kind == "gltf":
        if "file" not in args:
            raise ValueError(f"{where} (gltf) needs a file")
        args["file"] = _resolve(base_dir, args["file"], f"{where} (gltf): file")
    try:
        return _OBJECT_TYPES[kind](**args)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: {exc}") from None


def _lights_from(items):
    """{"lights": punctual lights, "area_lights": area lights} of a scene file's ``lights``."""
    if not isinstance(items, list):
        raise ValueError("lights must be an array of tables")
    lights = []
    area = []
    types = LIGHT_TYPES + AREA_LIGHT_TYPES
    for index, light in enumerate(items):
        where = f"lights[{index}]"
        if not isinstance(light, dict) or "type" not in light:
            raise ValueError(f"{where} needs a type ({', '.join(types)})")
        kind = light["type"]
        if not _STRING.ok(kind):
            raise ValueError(f"{where}: type must be {_STRING.phrase}, got {_show(kind)}")
        if kind not in types:
            raise ValueError(f"{where}: unknown light type {_show(kind)}; choose one of {', '.join(types)}")
        area_light = kind in AREA_LIGHT_TYPES
        _check_keys(f"{where} ({kind})", light, _AREA_LIGHT_KEYS[kind] if area_light else _LIGHT_KEYS[kind])
        _check_values(light, _AREA_LIGHT_VALUES if area_light else _LIGHT_VALUES,
                      lambda key, where=where: f"{where}: {key}")
        try:
            (area if area_light else lights).append((AreaLight if area_light else Light)(**light))
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{where}: {exc}") from None
    return {"lights": tuple(lights), "area_lights": tuple(area)}


def load_scene(path):
    """Read a scene file (``.toml`` or ``.json``).  Problems raise
    :class:`pbrkit.core.errors.InputError` (a ``ValueError``) with one line naming the file."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".toml", ".json"):
        hint = (" (pbrkit.rendering.sources.resolve_scene frames a glTF file alone; a scene file places one: "
                "[[objects]] type = \"gltf\", file = ...)"
                if suffix in (".gltf", ".glb") else "")
        raise InputError(f"scene files must be .toml or .json; got {suffix or 'no suffix'!r}{hint}", path)
    # a regular file of bounded size (not /dev/zero, a pipe, or a link to one); errors
    # give the position, never the text (pbrkit.core.documents)
    text = read_text(path, expected=SCENE_EXPECTED)
    data = parse_document(text, FORMATS[suffix], path, SCENE_EXPECTED)
    try:
        return scene_from_dict(data, base_dir=path.parent, source=str(path))
    except (TypeError, ValueError) as exc:
        raise InputError(str(exc), path) from None


def builtin_scene(name, width=None, height=None, environment=None):
    """The built-in scene ``spheres``, ``sphere`` or ``area`` (module docstring).  ``environment``
    (an :class:`EnvironmentSpec`) replaces the bundled map."""
    if name not in BUILTIN_SCENES:
        raise ValueError(f"unknown built-in scene {name!r}; choose one of {', '.join(BUILTIN_SCENES)}")
    default_width, default_height = BUILTIN_SIZES[name]
    if name == "area":
        width = default_width if width is None else width
        return _area_scene(width, max(1, width // 2) if height is None else height, environment)
    environment = environment or EnvironmentSpec()
    width = default_width if width is None else width
    height = default_height if height is None else height
    if name == "sphere":
        camera = Camera(position=(0.0, 0.0, 4.5), look_at=(0.0, 0.0, 0.0), fov=32.0,
                        width=width, height=height)
        materials = {"default": MaterialSpec(), "ball": MaterialSpec(name="ball", base_color=(0.9, 0.6, 0.35),
                                                                     metallic=0.0, roughness=0.4)}
        return Scene(camera=camera, environment=environment, materials=materials,
                     objects=(Sphere(center=(0.0, 0.0, 0.0), radius=1.0, material="ball"),), source="sphere")
    n = 7
    spacing = 2.4
    materials = {"default": MaterialSpec()}
    objects = []
    for row in range(n):
        for col in range(n):
            name_ = f"m{row}_r{col}"
            materials[name_] = MaterialSpec(name=name_, base_color=(0.9, 0.6, 0.35), metallic=row / (n - 1),
                                            roughness=col / (n - 1))
            objects.append(Sphere(center=((col - (n - 1) / 2) * spacing, ((n - 1) / 2 - row) * spacing, 0.0),
                                  radius=1.0, material=name_))
    half = ((n - 1) / 2 * spacing + 1.0) * 1.06
    distance = 60.0
    camera = Camera(position=(0.0, 0.0, distance), look_at=(0.0, 0.0, 0.0),
                    fov=2.0 * math.degrees(math.atan(half / (distance - 1.0))),
                    width=width, height=height)
    return Scene(camera=camera, environment=environment, materials=materials, objects=tuple(objects),
                 source="spheres")


def _area_scene(width, height, environment=None):
    """The built-in ``area`` scene (module docstring)."""
    camera = Camera(position=(0.0, 2.0, 7.5), look_at=(0.0, 0.7, 0.0), fov=32.0, width=width, height=height)
    materials = {"default": MaterialSpec(),
                 "floor": MaterialSpec(name="floor", base_color=(0.5, 0.5, 0.5), metallic=0.0, roughness=0.6)}
    objects = [Plane(point=(0.0, 0.0, 0.0), normal=(0.0, 1.0, 0.0), material="floor")]
    for k, r in enumerate((0.1, 0.3, 0.5, 0.7, 0.9)):
        name = f"gold_r{k}"
        materials[name] = MaterialSpec(name=name, base_color=(1.0, 0.78, 0.34), metallic=1.0, roughness=r)
        objects.append(Sphere(center=(-2.6 + 1.3 * k, 0.55, 0.0), radius=0.55, material=name))
    light = AreaLight(type="rect", position=(0.0, 2.4, 1.4), normal=(0.0, -1.0, 0.25), width=4.0, height=1.0,
                      intensity=8.0)
    return Scene(camera=camera, environment=environment or EnvironmentSpec(color=(0.03, 0.03, 0.03)),
                 materials=materials, objects=tuple(objects), area_lights=(light,), source="area")
