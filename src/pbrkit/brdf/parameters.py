"""Material parameters, declared once (the parameter tables of Mitsuba 3's BSDF
plugins: name, default, range, unit and a one-line meaning).

A shading model declares the parameters it reads as a tuple of
:class:`Parameter` (numbers, scalar or RGB) and :class:`Choice` (a term chosen
by name, e.g. cook_torrance's ``distribution``).  Everything else is generated
from those declarations (:mod:`pbrkit.brdf.shading.registry`): the fields and
checks of :class:`pbrkit.Material`, the packed parameter row of the compiled
kernels (:class:`Layout`), the scene-file keys with their one-line errors
(:mod:`pbrkit.rendering.scene`), the explorer's controls and the documentation's
parameter table (:func:`markdown_table`).

Names follow the specification of the model that defines them
(``CONVENTIONS.md``, "Materials"): the glTF 2.0 core names in snake_case
(``base_color`` for ``baseColorFactor``), Filament's ``reflectance`` and
``anisotropy``, Disney's (Burley 2012) for its extras, glTF's
``KHR_materials_*`` property names without "Factor".  A name means one thing
in every model that declares it (``specular_color`` tints the specular
reflection: cook_torrance's constant F, glTF's KHR_materials_specular F0 colour;
``clearcoat`` weighs a clear coat); a model may narrow its range (Disney's
anisotropy is Burley's aspect in [0, 1]).
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass, replace

import math

import numpy as np

__all__ = [
    "Parameter",
    "Choice",
    "Layout",
    "BASE_COLOR",
    "METALLIC",
    "ROUGHNESS",
    "REFLECTANCE",
    "ANISOTROPY",
    "ETA",
    "K",
    "SPECULAR_COLOR",
    "TEXTURED",
    "narrowed",
    "union",
    "markdown_table",
    "is_default",
]


@dataclass(frozen=True)
class Parameter:
    """A number (``channels`` = 1) or an RGB triple (3) a model reads.  ``low``,
    ``high``: the closed range every value must lie in, ``also``: values allowed
    outside it (glTF's ior 0); ``optional``: None is allowed (and packed as zeros;
    e.g. the complex IOR, which only the exact conductor Fresnel reads)."""

    name: str
    default: float | tuple | None
    low: float
    high: float
    unit: str
    doc: str
    channels: int = 1
    optional: bool = False
    also: tuple = ()

    def check(self, value, where):
        """``value`` as a float64 array, or ``ValueError`` with one line that starts
        with ``where`` (e.g. ``"Material.sheen"``) and says what is wrong."""
        if value is None:
            if self.optional:
                return None
            raise ValueError(f"{where} must be given")
        array = np.asarray(value, dtype=float)
        if self.channels == 3 and (array.ndim == 0 or array.shape[-1] != 3):
            raise ValueError(f"{where} must have 3 channels (RGB) in its last axis; got shape {array.shape}")
        if array.size <= 3:  # one material's value: Python's arithmetic (each NumPy reduction costs microseconds)
            values = array.ravel().tolist()
            bad = sum(1 for x in values if not math.isfinite(x))
            if bad:
                raise ValueError(f"{where} has {bad} non-finite value(s)")
            outside = [x for x in values if (x < self.low or x > self.high) and x not in self.also]
            if outside:
                self._outside(where, len(outside), outside[0])
            return array
        bad = ~np.isfinite(array)
        if np.any(bad):
            raise ValueError(f"{where} has {int(bad.sum())} non-finite value(s)")
        out = (array < self.low) | (array > self.high)
        if self.also:  # (np.isin costs tens of microseconds: only where a declaration has such values)
            out &= ~np.isin(array, self.also)
        if np.any(out):
            self._outside(where, int(out.sum()), float(array[out].flat[0]))
        return array

    def _outside(self, where, count, example):
        also = "".join(f" or {x}" for x in self.also)
        raise ValueError(f"{where} must be in [{self.low}, {self.high}]{also}; {count} value(s) outside, "
                         f"e.g. {example!r}")

    @property
    def phrase(self):
        """What a scene file's value must be, for one-line errors: "a number in [0, 1]"."""
        span = f" in {self.range_text}"
        return f"a list of 3 numbers{span}" if self.channels == 3 else f"a number{span}"

    @property
    def range_text(self):
        return f"[{self.low:g}, {self.high:g}]" + "".join(f" or {x:g}" for x in self.also)


@dataclass(frozen=True)
class Choice:
    """A term chosen by name from a method table (``choices``, in code order: the
    compiled kernels receive the index)."""

    name: str
    choices: tuple
    default: str
    doc: str

    def check(self, value, where):
        if value not in self.choices:
            raise ValueError(f"unknown {where} {value!r}; choose one of {', '.join(self.choices)}")
        return value


def narrowed(parameter, **changes):
    """A copy of a shared declaration with some fields changed (a model's narrower
    range, its own default or meaning)."""
    return replace(parameter, **changes)


# ----------------------------------------------------------------- the shared ones

#: The metallic-roughness parameters of glTF 2.0 (Appendix B), Filament and UE4; the
#: renderer may texture these three per shading point (:data:`TEXTURED`).
BASE_COLOR = Parameter("base_color", (0.8, 0.8, 0.8), 0.0, 1.0, "linear Rec.709",
                       "diffuse albedo of the dielectric, f0 of the metal (glTF baseColorFactor)", channels=3)
METALLIC = Parameter("metallic", 0.0, 0.0, 1.0, "", "mix of the dielectric (0) and the metal (1)")
ROUGHNESS = Parameter("roughness", 0.5, 0.0, 1.0, "perceptual",
                      "perceptual roughness r; alpha = max(r^2, 1e-3)")
REFLECTANCE = Parameter("reflectance", 0.5, 0.0, 1.0, "",
                        "dielectric f0 = 0.16 reflectance^2 (Filament); 0.5 gives 0.04")
ANISOTROPY = Parameter("anisotropy", 0.0, -1.0, 1.0, "",
                       "alpha_t = alpha (1 + a), alpha_b = alpha (1 - a) along the tangent (Kulla & Conty 2017)")
ETA = Parameter("eta", None, 1e-6, 1e3, "", "real part of the complex IOR (exact conductor Fresnel)", channels=3,
                optional=True)
K = Parameter("k", None, 0.0, 1e3, "", "imaginary part of the complex IOR (exact conductor Fresnel)", channels=3,
              optional=True)
SPECULAR_COLOR = Parameter("specular_color", (1.0, 1.0, 1.0), 0.0, 1.0, "linear Rec.709",
                           "the constant F of fresnel = \"none\"", channels=3)

#: The parameters a renderer takes per shading point (textures) rather than from the
#: material's row: the base colour, metallic and roughness of glTF's textures.
TEXTURED = ("base_color", "metallic", "roughness")


def union(declarations):
    """One declaration per name over several models' tuples, in first-seen order,
    with the widest range (a model's narrower range is checked by that model);
    ``ValueError`` if two declarations of a name disagree on anything else."""
    out = {}
    for d in declarations:
        seen = out.get(d.name)
        if seen is None:
            out[d.name] = d
            continue
        if type(seen) is not type(d):
            raise ValueError(f"parameter {d.name!r} is declared both as a number and as a choice")
        if isinstance(d, Parameter):
            if (seen.channels, seen.optional) != (d.channels, d.optional):
                raise ValueError(f"parameter {d.name!r} is declared with different channels")
            out[d.name] = replace(seen, low=min(seen.low, d.low), high=max(seen.high, d.high))
        else:
            merged = seen.choices + tuple(c for c in d.choices if c not in seen.choices)
            out[d.name] = replace(seen, choices=merged)
    return tuple(out.values())


class Layout:
    """The packed parameter row of the compiled kernels: every numeric parameter of
    every model (:func:`union`) at fixed columns (RGB ones take three), then the
    renderer's per-material ``extra`` columns (emission, sidedness).  ``columns``
    is a named tuple of first columns (``layout.columns.sheen``) that compiled code
    reads as constants; ``size`` the row length."""

    def __init__(self, parameters, extra=()):
        self.parameters = tuple(p for p in parameters if isinstance(p, Parameter)) + tuple(extra)
        start = {}
        column = 0
        for p in self.parameters:
            start[p.name] = column
            column += p.channels
        self.size = column
        self.columns = namedtuple("Columns", list(start))(**start)
        self.by_name = {p.name: p for p in self.parameters}

    def row(self, values, rows_shape=()):
        """Rows (prod(rows_shape), size) from ``values`` (name -> value broadcastable to
        rows_shape (+ (3,)); missing names take their defaults, None packs zeros)."""
        count = int(np.prod(rows_shape))
        table = np.zeros((count, self.size))
        for p in self.parameters:
            value = values.get(p.name, p.default)
            if value is None:
                continue
            shape = rows_shape + ((3,) if p.channels == 3 else ())
            column = getattr(self.columns, p.name)
            array = np.asarray(value, dtype=np.float64)
            if not rows_shape and array.size == p.channels:  # one row (np.broadcast_to costs microseconds)
                table[0, column:column + p.channels] = array.ravel()
                continue
            table[:, column:column + p.channels] = np.broadcast_to(np.asarray(value, dtype=np.float64),
                                                                    shape).reshape(count, -1)
        return table


def _default_text(p):
    if isinstance(p, Choice):
        return f"`{p.default}`"
    if p.default is None:
        return "none"
    if isinstance(p.default, tuple):
        return "(" + ", ".join(f"{x:g}" for x in p.default) + ")"
    return f"{p.default:g}"


def markdown_table(models):
    """The documentation's table of every model's parameters (a Markdown table per
    model: key, default, range or choices, unit, meaning), generated from the
    declarations of ``models`` (objects with ``name`` and ``parameters``)."""
    lines = []
    for m in models:
        lines += [f"### `{m.name}`", "", f"{m.doc[0].upper()}{m.doc[1:]}.", "",
                  "| key | default | range | unit | meaning |", "|---|---|---|---|---|"]
        for p in m.parameters:
            if isinstance(p, Choice):
                span = ", ".join(f"`{c}`" for c in p.choices)
                unit = "name"
            else:
                span = p.range_text + (" (RGB)" if p.channels == 3 else "")
                unit = p.unit
            lines.append(f"| `{p.name}` | {_default_text(p)} | {span} | {unit} | {p.doc} |")
        lines.append("")
    return "\n".join(lines)


def is_default(parameter, value):
    """Whether ``value`` equals the declaration's default (RGB compared per channel)."""
    if parameter.default is None or value is None:
        return value is None and parameter.default is None
    if isinstance(parameter, Choice):
        return value == parameter.default
    return bool(np.all(np.asarray(value, dtype=float) == np.asarray(parameter.default, dtype=float)))

