"""Styles: what ``[style]`` in a scene file and ``pbrkit render --style`` ask for.

A style names a shading (``pbr``: the real-time path unchanged; ``toon``: bands;
``mtoon``: VRM MToon 1.0; ``hatching``: tonal art maps) and optional outlines,
with their parameters (:class:`Style`; every key optional)::

    [style]
    shading = "toon"              # pbr, toon, mtoon, hatching
    lighting = "summed"           # toon: per_light (bands per light) or summed (bands over the sum)
    tones = 3                     # toon: number of tones (thresholds at k / tones) ...
    # thresholds = [0.2, 0.6]     # ... or their n.l positions
    softness = 0.0                # width of each band's transition (0: hard)
    shadow_color = [0.35, 0.35, 0.45]   # colour of tone 0, times the base colour
    # ramp = "ramp.png"           # or a ramp image (its middle row, left = tone 0)
    specular = 0.5                # highlight strength (0: none)
    specular_threshold = 0.5      # of D(n.h) / D(1)
    specular_softness = 0.0
    rim_color = [0.0, 0.0, 0.0]   # parametric rim (MToon's formula), also for toon
    rim_power = 5.0
    rim_lift = 0.0
    rim_mix = 1.0                 # how much the lighting tints the rim
    environment = true            # banded SH irradiance and thresholded prefiltered specular
    # mtoon: shade_color = [0, 0, 0], shading_shift = 0.0, shading_toony = 0.9, gi_equalization = 0.9
    outline = "none"              # none, image (G-buffer edges), geometry (mesh edges), both, hull (inverted hull)
    outline_width = 1.5           # in the unit of outline_width_mode
    outline_width_mode = "pixels" # pixels; screen (a fraction of the image height); world (scene units, hull only)
    outline_color = [0.0, 0.0, 0.0]
    outline_depth = 0.02          # image: relative depth step that is an edge
    outline_normal = 40.0         # image: normal angle (degrees) that is an edge; geometry: crease angle
    hatching_tones = 6            # hatching: tones of the tonal art map
    hatching_scale = 1.0          # repeats of the map per unit (object space) or per UV unit (texture space)
    hatching_space = "object"     # object (world position, box-mapped) or texture (the mesh's TEXCOORD_0)
"""

from __future__ import annotations

import json
import tomllib
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

from ..core import checks
from ..core.errors import InputError

__all__ = ["SHADINGS", "LIGHTINGS", "OUTLINES", "HATCHING_SPACES", "OUTLINE_WIDTH_MODES",
           "mtoon_style", "Style", "STYLE_PRESETS", "style_from_dict", "resolve_style"]

SHADINGS = ("pbr", "toon", "mtoon", "hatching")
LIGHTINGS = ("per_light", "summed")
OUTLINES = ("none", "image", "geometry", "both", "hull")
HATCHING_SPACES = ("object", "texture")
OUTLINE_WIDTH_MODES = ("pixels", "screen", "world")


@dataclass(frozen=True)
class Style:
    """A rendering style (module docstring for the keys and their meaning)."""

    shading: str = "pbr"
    lighting: str = "summed"
    tones: int = 3
    thresholds: tuple | None = None
    softness: float = 0.0
    shadow_color: tuple = (0.35, 0.35, 0.45)
    ramp: str | None = None
    specular: float = 0.5
    specular_threshold: float = 0.5
    specular_softness: float = 0.0
    rim_color: tuple = (0.0, 0.0, 0.0)
    rim_power: float = 5.0
    rim_lift: float = 0.0
    rim_mix: float = 1.0
    environment: bool = True
    shade_color: tuple = (0.0, 0.0, 0.0)
    shading_shift: float = 0.0
    shading_toony: float = 0.9
    gi_equalization: float = 0.9
    outline: str = "none"
    outline_width: float = 1.5
    outline_width_mode: str = "pixels"
    outline_color: tuple = (0.0, 0.0, 0.0)
    outline_depth: float = 0.02
    outline_normal: float = 40.0
    hatching_tones: int = 6
    hatching_scale: float = 1.0
    hatching_space: str = "object"
    ramp_colors: object = field(default=None, compare=False, repr=False)  # (M, 3) linear, loaded from ``ramp``

    def __post_init__(self):
        set_ = object.__setattr__
        for name, choices in (("shading", SHADINGS), ("lighting", LIGHTINGS), ("outline", OUTLINES),
                              ("hatching_space", HATCHING_SPACES), ("outline_width_mode", OUTLINE_WIDTH_MODES)):
            if getattr(self, name) not in choices:
                raise ValueError(f"style {name} must be one of {', '.join(choices)}; got {getattr(self, name)!r}")
        set_(self, "tones", checks.integer(self.tones, "style tones", 2, 64))
        set_(self, "hatching_tones", checks.integer(self.hatching_tones, "style hatching_tones", 2, 16))
        if self.thresholds is not None:
            t = [float(x) for x in self.thresholds]
            if not t or any(not 0.0 <= x <= 1.0 for x in t) or any(b <= a for a, b in zip(t, t[1:])):
                raise ValueError(f"style thresholds must increase within [0, 1]; got {self.thresholds!r}")
            set_(self, "thresholds", tuple(t))
        for name in ("shadow_color", "rim_color", "shade_color", "outline_color"):
            c = checks.vector(getattr(self, name), f"style {name}")
            if (c < 0.0).any():
                raise ValueError(f"style {name} must be non-negative; got {getattr(self, name)!r}")
            set_(self, name, tuple(float(x) for x in c))
        bounds = {"softness": (0.0, 1.0), "specular": (0.0, 100.0), "specular_threshold": (0.0, 1.0),
                  "specular_softness": (0.0, 1.0), "rim_power": (0.0, 100.0), "rim_lift": (-1.0, 1.0),
                  "rim_mix": (0.0, 1.0), "shading_shift": (-1.0, 1.0), "shading_toony": (0.0, 0.999),
                  "gi_equalization": (0.0, 1.0), "outline_width": (0.0, 64.0), "outline_depth": (1e-6, 10.0),
                  "outline_normal": (0.1, 180.0), "hatching_scale": (1e-3, 1e3)}
        for name, (lo, hi) in bounds.items():
            v = getattr(self, name)
            if not checks.is_finite_number(v) or not lo <= v <= hi:
                raise ValueError(f"style {name} must be a number in [{lo:g}, {hi:g}]; got {v!r}")
            set_(self, name, float(v))
        set_(self, "environment", bool(self.environment))
        if self.outline_width_mode == "world" and self.outline not in ("hull", "none"):
            raise ValueError("style outline_width_mode 'world' needs outline 'hull' (lines of the image and the "
                             f"meshes have a width on screen); got outline {self.outline!r}")
        if self.outline_width_mode == "screen" and self.outline_width > 0.25:
            raise ValueError("style outline_width must be at most 0.25 (of the image height) with "
                             f"outline_width_mode 'screen'; got {self.outline_width!r}")
        if self.ramp is not None and self.ramp_colors is None:
            set_(self, "ramp_colors", _load_ramp(self.ramp))

    def outline_pixels(self, camera):
        """The outline width in pixels of ``camera``'s image for the ``pixels`` and
        ``screen`` modes (``world`` widths have none: see :func:`pbrkit.npr.hull.hull_rays`)."""
        if self.outline_width_mode == "screen":
            return self.outline_width * camera.height
        return self.outline_width

    @property
    def threshold_values(self):
        """The toon thresholds: given, or k / tones (:func:`pbrkit.npr.toon.default_thresholds`)."""
        import numpy as np

        from .toon import default_thresholds

        if self.thresholds is not None:
            return np.asarray(self.thresholds, dtype=np.float64)
        return default_thresholds(self.tones)


#: VRMC_materials_mtoon 1.0 properties and the :class:`Style` keys they set (the
#: specification's names, github.com/vrm-c/vrm-specification, VRMC_materials_mtoon-1.0).
MTOON_KEYS = {
    "shadeColorFactor": "shade_color", "shadingShiftFactor": "shading_shift",
    "shadingToonyFactor": "shading_toony", "giEqualizationFactor": "gi_equalization",
    "parametricRimColorFactor": "rim_color", "parametricRimFresnelPowerFactor": "rim_power",
    "parametricRimLiftFactor": "rim_lift", "rimLightingMixFactor": "rim_mix",
    "outlineWidthFactor": "outline_width", "outlineColorFactor": "outline_color",
}
#: Properties of VRMC_materials_mtoon 1.0 that pbrkit reads but does not render (textures,
#: UV animation, render order, matcap): accepted and ignored, as their absence is.
MTOON_IGNORED = {"specVersion", "transparentWithZWrite", "renderQueueOffsetNumber", "shadeMultiplyTexture",
                 "shadingShiftTexture", "matcapFactor", "matcapTexture", "rimMultiplyTexture",
                 "outlineWidthMultiplyTexture", "outlineLightingMixFactor", "uvAnimationMaskTexture",
                 "uvAnimationScrollXSpeedFactor", "uvAnimationScrollYSpeedFactor",
                 "uvAnimationRotationSpeedFactor", "extensions", "extras"}


def mtoon_style(table):
    """A ``mtoon`` :class:`Style` from a VRMC_materials_mtoon 1.0 object (the glTF
    material extension's JSON): the shading and rim factors as :data:`MTOON_KEYS`
    maps them, and the outline as MToon draws it, the inverted hull
    (``outlineWidthMode``: ``none``: no outline; ``worldCoordinates``: the
    ``outlineWidthFactor`` in metres (scene units); ``screenCoordinates``: the
    factor as a fraction of the screen height).  Omitted properties take the
    specification's defaults (outline ``none``); ValueError names a bad one."""
    if not isinstance(table, dict):
        raise ValueError("VRMC_materials_mtoon must be a JSON object")
    unknown = sorted(set(table) - set(MTOON_KEYS) - MTOON_IGNORED - {"outlineWidthMode"})
    if unknown:
        raise ValueError(f"VRMC_materials_mtoon: unknown property {unknown[0]!r}")
    args = {"shading": "mtoon", "shade_color": (0.0, 0.0, 0.0), "shading_shift": 0.0, "shading_toony": 0.9,
            "gi_equalization": 0.9, "rim_color": (0.0, 0.0, 0.0), "rim_power": 5.0, "rim_lift": 0.0,
            "rim_mix": 1.0, "outline_width": 0.0, "outline_color": (0.0, 0.0, 0.0), "specular": 0.0}
    for key, name in MTOON_KEYS.items():
        if key in table:
            value = table[key]
            if isinstance(value, bool) or not isinstance(value, (int, float, list)):
                raise ValueError(f"VRMC_materials_mtoon {key} must be a number or a list of numbers; got {value!r}")
            args[name] = tuple(value) if isinstance(value, list) else value
    mode = table.get("outlineWidthMode", "none")
    modes = {"none": None, "worldCoordinates": "world", "screenCoordinates": "screen"}
    if mode not in modes:
        raise ValueError(f"VRMC_materials_mtoon outlineWidthMode must be one of {', '.join(modes)}; got {mode!r}")
    if modes[mode] is None or args["outline_width"] == 0.0:
        args["outline"] = "none"
    else:
        args.update(outline="hull", outline_width_mode=modes[mode])
    args["shading_toony"] = min(float(args["shading_toony"]), 0.999)
    try:
        return Style(**args)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"VRMC_materials_mtoon: {exc}") from None


def _load_ramp(path):
    """A ramp image's middle row as linear RGB (M, 3) (:func:`pbrkit.io.images.read_image`:
    8-bit images are sRGB-decoded)."""
    import numpy as np

    from ..io.images import read_image

    try:
        image = np.asarray(read_image(path), dtype=np.float64)
    except (OSError, ValueError) as exc:
        raise ValueError(f"style ramp {path}: {exc}") from None
    if image.ndim == 2:
        image = image[..., None]
    row = image[image.shape[0] // 2, :, :3]
    if row.shape[-1] == 1:
        row = np.repeat(row, 3, axis=-1)
    if row.shape[0] < 1 or not np.all(np.isfinite(row)) or (row < 0).any():
        raise ValueError(f"style ramp {path}: needs finite, non-negative pixels")
    return np.ascontiguousarray(row)


#: ``--style`` presets.
STYLE_PRESETS = {
    "pbr": Style(),
    "toon": Style(shading="toon", outline="image", rim_color=(0.15, 0.15, 0.15)),
    "toon-per-light": Style(shading="toon", lighting="per_light", outline="image"),
    "mtoon": Style(shading="mtoon", shade_color=(0.45, 0.35, 0.45), outline="image", outline_width=2.0,
                   rim_color=(0.2, 0.2, 0.2)),
    "hatching": Style(shading="hatching", outline="image", specular=0.0),
    "outline": Style(outline="both"),
}

_KEYS = {f.name for f in fields(Style)} - {"ramp_colors"}


def style_from_dict(table, base_dir=None):
    """A :class:`Style` from a scene file's ``[style]`` table: unknown keys and bad
    values raise ValueError naming the key; ``ramp`` is relative to ``base_dir``."""
    if not isinstance(table, dict):
        raise ValueError("style must be a table")
    unknown = sorted(set(table) - _KEYS)
    if unknown:
        raise ValueError(f"style: unknown key {unknown[0]!r}; allowed: {', '.join(sorted(_KEYS))}")
    args = dict(table)
    for key in ("tones", "hatching_tones"):
        if key in args and (isinstance(args[key], bool) or not isinstance(args[key], int)):
            raise ValueError(f"style {key} must be an integer; got {args[key]!r}")
    if "environment" in args and not isinstance(args["environment"], bool):
        raise ValueError(f"style environment must be true or false; got {args['environment']!r}")
    for key in ("shading", "lighting", "outline", "ramp", "hatching_space", "outline_width_mode"):
        if key in args and not isinstance(args[key], str):
            raise ValueError(f"style {key} must be a string; got {args[key]!r}")
    if "ramp" in args:
        p = Path(args["ramp"])
        args["ramp"] = str(p if p.is_absolute() or base_dir is None else Path(base_dir) / p)
    try:
        return Style(**args)
    except (TypeError, ValueError) as exc:
        raise ValueError(str(exc)) from None


def resolve_style(name_or_path, base=None):
    """A preset name (:data:`STYLE_PRESETS`) or a ``.toml`` / ``.json`` file holding a
    ``[style]`` table (or the table itself); ``base`` (a :class:`Style`, e.g. the
    scene's) is what a file's keys change."""
    text = str(name_or_path)
    if text in STYLE_PRESETS:
        return STYLE_PRESETS[text]
    path = Path(text)
    if path.suffix.lower() not in (".toml", ".json"):
        raise InputError(f"no such style (presets: {', '.join(STYLE_PRESETS)}; or a .toml / .json file)", path)
    try:
        data = (tomllib.loads if path.suffix.lower() == ".toml" else json.loads)(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise InputError(f"cannot read the style: {exc}", path) from None
    if isinstance(data, dict) and "VRMC_materials_mtoon" in data:  # a glTF material's extension, as it is
        try:
            return mtoon_style(data["VRMC_materials_mtoon"])
        except ValueError as exc:
            raise InputError(str(exc), path) from None
    table = data.get("style", data) if isinstance(data, dict) else data
    try:
        style = style_from_dict(table, path.parent)
    except ValueError as exc:
        raise InputError(str(exc), path) from None
    if base is not None:
        style = replace(base, **{k: getattr(style, k) for k in table})
    return style
