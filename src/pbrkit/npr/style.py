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

Values are checked as they are read, each refusal one line naming the key: a
number is a number (not a bool or a string, which Python would convert), within
its range; a colour is a list of 3 non-negative numbers; ``tones`` and
``thresholds``, ``shadow_color`` and ``ramp`` are alternatives, refused together
(:data:`EXCLUSIVE`); a ``VRMC_materials_mtoon`` object's factors are in the
ranges of its schema (:data:`MTOON_RANGES`).  Style files and ramp images are
read only if they are regular files (:mod:`pbrkit.core.inputs`), and an error
never quotes a file (:func:`pbrkit.core.documents.parse_document`).  A style is
real-time shading: ``pbrkit render`` refuses one that changes the image in the
reference and compare modes (:func:`pbrkit.rendering.run.render_scene`).
"""

from __future__ import annotations

import json
import math
import tomllib
import warnings
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np

from ..core import checks
from ..core.errors import InputError
from ..core.inputs import check_regular, describe, read_text

__all__ = ["SHADINGS", "LIGHTINGS", "OUTLINES", "HATCHING_SPACES", "OUTLINE_WIDTH_MODES",
           "mtoon_style", "Style", "STYLE_PRESETS", "style_from_dict", "resolve_style"]

SHADINGS = ("pbr", "toon", "mtoon", "hatching")
LIGHTINGS = ("per_light", "summed")
OUTLINES = ("none", "image", "geometry", "both", "hull")
HATCHING_SPACES = ("object", "texture")
OUTLINE_WIDTH_MODES = ("pixels", "screen", "world")


def _is_real(value):
    """A finite real number: an int or float (NumPy's too), not a bool (Python counts
    ``True`` as 1), not NaN or Inf, not an integer beyond the float range."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _show(value):
    """A value taken from a style, as a short escaped quotation (never more than 60
    characters of a file): true, null, 'toon', (1, 2, 3)."""
    if isinstance(value, (bool, np.bool_)) or value is None:
        return json.dumps(None if value is None else bool(value))
    return describe(value) if isinstance(value, str) else describe(value).strip("'\"")


def _colour(value, name, hi=None):
    """``value`` as a tuple of 3 finite non-negative floats (at most ``hi``): a list or
    tuple of numbers, not strings or bools; else ValueError naming ``name``."""
    ok = isinstance(value, (list, tuple, np.ndarray)) and len(value) == 3 \
        and all(_is_real(x) and x >= 0.0 and (hi is None or x <= hi) for x in value)
    if not ok:
        what = "3 non-negative numbers" if hi is None else f"3 numbers in [0, {hi:g}]"
        raise ValueError(f"{name} must be a list of {what}; got {_show(value)}")
    return tuple(float(x) for x in value)


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
            if not isinstance(getattr(self, name), str) or getattr(self, name) not in choices:
                raise ValueError(f"style {name} must be one of {', '.join(choices)}; got {_show(getattr(self, name))}")
        set_(self, "tones", checks.integer(self.tones, "style tones", 2, 64))
        set_(self, "hatching_tones", checks.integer(self.hatching_tones, "style hatching_tones", 2, 16))
        if self.thresholds is not None:
            t = self.thresholds
            if not isinstance(t, (list, tuple, np.ndarray)) or not 1 <= len(t) <= 63 \
                    or not all(_is_real(x) and 0.0 <= x <= 1.0 for x in t) \
                    or any(b <= a for a, b in zip(t[:-1], t[1:])):
                raise ValueError("style thresholds must increase within [0, 1] (a list of 1 to 63 numbers); "
                                 f"got {_show(t)}")
            set_(self, "thresholds", tuple(float(x) for x in t))
        for name in ("shadow_color", "rim_color", "shade_color", "outline_color"):
            set_(self, name, _colour(getattr(self, name), f"style {name}"))
        bounds = {"softness": (0.0, 1.0), "specular": (0.0, 100.0), "specular_threshold": (0.0, 1.0),
                  "specular_softness": (0.0, 1.0), "rim_power": (0.0, 100.0), "rim_lift": (-1.0, 1.0),
                  "rim_mix": (0.0, 1.0), "shading_shift": (-1.0, 1.0), "shading_toony": (0.0, 0.999),
                  "gi_equalization": (0.0, 1.0), "outline_width": (0.0, 64.0), "outline_depth": (1e-6, 10.0),
                  "outline_normal": (0.1, 180.0), "hatching_scale": (1e-3, 1e3)}
        for name, (lo, hi) in bounds.items():
            v = getattr(self, name)
            if not _is_real(v) or not lo <= v <= hi:
                raise ValueError(f"style {name} must be a number in [{lo:g}, {hi:g}]; got {_show(v)}")
            set_(self, name, float(v))
        if not isinstance(self.environment, (bool, np.bool_)):
            raise ValueError(f"style environment must be true or false; got {_show(self.environment)}")
        set_(self, "environment", bool(self.environment))
        if self.ramp is not None and (not isinstance(self.ramp, (str, Path)) or str(self.ramp) == ""):
            raise ValueError(f"style ramp must be the path of an image file; got {_show(self.ramp)}")
        if self.outline_width_mode == "world" and self.outline not in ("hull", "none"):
            raise ValueError("style outline_width_mode 'world' needs outline 'hull' (lines of the image and the "
                             f"meshes have a width on screen); got outline {_show(self.outline)}")
        if self.outline_width_mode == "screen" and self.outline_width > 0.25:
            raise ValueError("style outline_width must be at most 0.25 (of the image height) with "
                             f"outline_width_mode 'screen'; got {_show(self.outline_width)}")
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
#: The ranges of VRMC_materials_mtoon 1.0's number properties, from the specification's
#: schema (VRMC_materials_mtoon.schema.json: minimum, maximum); its colour factors'
#: items are in [0, 1].  shadingShiftFactor and parametricRimLiftFactor have none
#: there: :class:`Style` bounds them.
MTOON_RANGES = {"shadingToonyFactor": (0.0, 1.0), "giEqualizationFactor": (0.0, 1.0),
                "rimLightingMixFactor": (0.0, 1.0), "parametricRimFresnelPowerFactor": (0.0, None),
                "outlineWidthFactor": (0.0, None)}
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
        raise ValueError(f"VRMC_materials_mtoon: unknown property {describe(unknown[0])}")
    args = {"shading": "mtoon", "shade_color": (0.0, 0.0, 0.0), "shading_shift": 0.0, "shading_toony": 0.9,
            "gi_equalization": 0.9, "rim_color": (0.0, 0.0, 0.0), "rim_power": 5.0, "rim_lift": 0.0,
            "rim_mix": 1.0, "outline_width": 0.0, "outline_color": (0.0, 0.0, 0.0), "specular": 0.0}
    for key, name in MTOON_KEYS.items():
        if key not in table:
            continue
        value = table[key]
        if name.endswith("_color"):
            args[name] = _colour(value, f"VRMC_materials_mtoon {key}", 1.0)
            continue
        lo, hi = MTOON_RANGES.get(key, (None, None))
        if not _is_real(value) or (lo is not None and value < lo) or (hi is not None and value > hi):
            bounds = f" in [{lo:g}, {hi:g}]" if hi is not None else (f" >= {lo:g}" if lo is not None else "")
            raise ValueError(f"VRMC_materials_mtoon {key} must be a number{bounds}; got {_show(value)}")
        args[name] = float(value)
    mode = table.get("outlineWidthMode", "none")
    modes = {"none": None, "worldCoordinates": "world", "screenCoordinates": "screen"}
    if not isinstance(mode, str) or mode not in modes:
        raise ValueError(f"VRMC_materials_mtoon outlineWidthMode must be one of {', '.join(modes)}; "
                         f"got {_show(mode)}")
    if modes[mode] is None or args["outline_width"] == 0.0:
        args["outline"] = "none"
    else:
        args.update(outline="hull", outline_width_mode=modes[mode])
    # 1 (the hardest step) is in the specification's range; the step's width 2 (1 - toony)
    # must stay positive, so it becomes 0.999 (Style.shading_toony).
    args["shading_toony"] = min(args["shading_toony"], 0.999)
    try:
        return Style(**args)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"VRMC_materials_mtoon: {exc}") from None


#: What a ramp file must be, for messages.
RAMP_EXPECTED = "a ramp image (.png, .jpg, .hdr, .exr or .pfm; its middle row, left = tone 0)"


def _load_ramp(path):
    """A ramp image's middle row as linear RGB (M, 3) (:func:`pbrkit.io.images.read_image`:
    8-bit images are sRGB-decoded).  Only a regular file is opened
    (:func:`pbrkit.core.inputs.check_regular`: not a pipe or a device); the
    reader's low-dynamic-range warning is not given (a ramp is a colour table,
    not lighting)."""
    from ..io.image_checks import LDRInputWarning
    from ..io.images import read_image

    check_regular(path, RAMP_EXPECTED)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", LDRInputWarning)
            image = np.asarray(read_image(path), dtype=np.float64)
    except (OSError, ValueError) as exc:
        problem = exc.problem if isinstance(exc, InputError) else type(exc).__name__
        raise ValueError(f"style ramp {path}: {problem}; expected {RAMP_EXPECTED}") from None
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


#: Keys of a style table that are alternatives: given together, the first would be ignored.
EXCLUSIVE = (("tones", "thresholds"), ("shadow_color", "ramp"))
#: What a style file must hold, for messages.
STYLE_EXPECTED = "a .toml / .json file with a [style] table (pbrkit.npr.style) or a VRMC_materials_mtoon object"


def style_from_dict(table, base_dir=None):
    """A :class:`Style` from a scene file's ``[style]`` table: unknown keys, bad
    values and alternatives given together (:data:`EXCLUSIVE`) raise ValueError
    naming the key; ``ramp`` is relative to ``base_dir``."""
    if not isinstance(table, dict):
        raise ValueError(f"style must be a table; got {type(table).__name__}")
    unknown = sorted(set(table) - _KEYS)
    if unknown:
        raise ValueError(f"style: unknown key {describe(unknown[0])}; allowed: {', '.join(sorted(_KEYS))}")
    for first, second in EXCLUSIVE:
        if first in table and second in table:
            raise ValueError(f"style: {first} and {second} are alternatives (with {second} the {first} would be "
                             f"ignored); give one of them")
    args = dict(table)
    for key in ("tones", "hatching_tones"):
        if key in args and (isinstance(args[key], bool) or not isinstance(args[key], int)):
            raise ValueError(f"style {key} must be an integer; got {_show(args[key])}")
    if "environment" in args and not isinstance(args["environment"], bool):
        raise ValueError(f"style environment must be true or false; got {_show(args['environment'])}")
    for key in ("shading", "lighting", "outline", "ramp", "hatching_space", "outline_width_mode"):
        if key in args and (not isinstance(args[key], str) or not args[key]):
            raise ValueError(f"style {key} must be a non-empty string; got {_show(args[key])}")
    if "ramp" in args:
        if "\x00" in args["ramp"]:
            raise ValueError("style ramp: a path with a NUL character; expected the path of an image file")
        p = Path(args["ramp"])
        args["ramp"] = str(p if p.is_absolute() or base_dir is None else Path(base_dir) / p)
    try:
        return Style(**args)
    except (TypeError, ValueError) as exc:
        raise ValueError(str(exc)) from None


def resolve_style(name_or_path, base=None):
    """A preset name (:data:`STYLE_PRESETS`) or a ``.toml`` / ``.json`` file holding a
    ``[style]`` table (or the table itself) or a glTF material's
    ``VRMC_materials_mtoon`` object; ``base`` (a :class:`Style`, e.g. the scene's) is
    what a file's keys change.  The file is read with
    :func:`pbrkit.core.inputs.read_text` (a regular file, bounded); no error quotes
    it (:func:`pbrkit.core.documents.parse_document`)."""
    from ..core.documents import FORMATS, parse_document

    text = str(name_or_path)
    if text in STYLE_PRESETS:
        return STYLE_PRESETS[text]
    path = Path(text)
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise InputError(f"no such style (presets: {', '.join(STYLE_PRESETS)}; or a .toml / .json file)", path)
    data = parse_document(read_text(path, expected=STYLE_EXPECTED), fmt, path, STYLE_EXPECTED)
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
        changes = {k: getattr(style, k) for k in table}
        for first, second in EXCLUSIVE:  # the file's choice replaces the base's alternative
            if first in table or second in table:
                changes.setdefault(second, getattr(style, second))
        if "ramp" in changes:
            changes["ramp_colors"] = style.ramp_colors
        try:
            style = replace(base, **changes)
        except ValueError as exc:
            raise InputError(str(exc), path) from None
    return style
