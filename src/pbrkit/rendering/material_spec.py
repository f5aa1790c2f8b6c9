"""A scene's material, :class:`MaterialSpec`, generated from the models'
declarations (:mod:`pbrkit.brdf.shading.registry`): its shading ``model``, one
field per parameter and term choice of any model (the keys of a scene file's
``[materials.<name>]`` table), and the renderer's own ``emissive``,
``double_sided`` and ``conductor`` (a metal of
:data:`pbrkit.brdf.fresnel.CONDUCTORS`: its eta and k, metallic 1 and the base
colour of its exact normal reflectance, as :meth:`pbrkit.Material.conductor`).

The checks, each a one-line ``ValueError`` naming the material and the key:
the model exists; every value is in its declared range (the model's own range
where it narrows the shared one); a parameter the model does not declare keeps
its default ("sheen needs model 'disney'"); a term the model fixes is not
chosen ("distribution can only be chosen with model 'cook_torrance'"); the
model's own cross-parameter rules (:attr:`pbrkit.brdf.shading.model.Model.check`).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..brdf.fresnel import CONDUCTORS, f0_conductor
from ..brdf.material import FIELDS, Material
from ..brdf.shading.registry import MODELS, PARAMETERS, REGISTERED, model
from ..brdf.parameters import Choice, is_default
from ..core.inputs import describe

__all__ = ["MaterialSpec", "NUMBERS", "CHOICES", "SURFACE_KEYS", "models_with"]

#: The numeric parameters of every model (the fields of :class:`pbrkit.Material`).
NUMBERS = FIELDS
#: The term choices of every model, with every name their tables hold.
CHOICES = tuple(p for p in PARAMETERS if isinstance(p, Choice))
#: The renderer's keys beside the models' parameters.
SURFACE_KEYS = ("model", "emissive", "double_sided", "conductor")


def models_with(name):
    """The models that declare parameter ``name``, as text: "'a', 'b' or 'c'"."""
    having = [f"{m.name!r}" for m in REGISTERED if m.declaration(name) is not None]
    return having[0] if len(having) == 1 else ", ".join(having[:-1]) + " or " + having[-1]


def _spec_default(p):
    if isinstance(p, Choice):
        return dataclasses.field(default=p.default)
    return dataclasses.field(default=p.default)


def _show(value):
    """A value for a message, short and escaped: true, null, 'red', [1, '1', 1]."""
    if isinstance(value, (bool, np.bool_)) or value is None:
        return "null" if value is None else str(bool(value)).lower()
    text = describe(value) if isinstance(value, str) else ascii(value)
    return text if len(text) <= 60 else text[:56] + " ..."


def _numeric(value):
    """Whether ``value`` (a number or an array of them) holds numbers only: not bools
    or strings, which ``numpy.asarray(..., dtype=float)`` would take as 1.0 or 0.5."""
    try:
        items = np.asarray(value, dtype=object).ravel()
    except (TypeError, ValueError):
        return False
    return all(isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, (bool, np.bool_))
               for x in items)


def _post_init(self):
    set_ = object.__setattr__
    where = f"material {describe(self.name)}: "
    if not isinstance(self.model, str) or self.model not in MODELS:
        raise ValueError(f"{where}unknown model {describe(self.model)}; choose one of {', '.join(MODELS)}")
    m = model(self.model)
    for choice in CHOICES:
        value = getattr(self, choice.name)
        if not isinstance(value, str) or value not in choice.choices:
            raise ValueError(f"{where}unknown {choice.name} {describe(value)}; choose one of "
                             f"{', '.join(choice.choices)}")
        own = m.choices.get(choice.name)
        if own is not None:
            if value not in own.choices:
                raise ValueError(f"{where}model {self.model!r} has no {choice.name} {value!r}; choose one of "
                                 f"{', '.join(own.choices)}")
            continue
        implied = m.terms[("distribution", "masking", "fresnel", "diffuse").index(choice.name)] \
            if choice.name in ("distribution", "masking", "fresnel", "diffuse") else None
        if value not in (choice.default, implied):
            fixed = f": {implied}" if implied is not None else ""
            raise ValueError(f"{where}{choice.name} can only be chosen with model {models_with(choice.name)} "
                             f"(model {self.model!r} fixes it{fixed})")
        if implied is not None:
            set_(self, choice.name, implied)
    for p in NUMBERS:
        if getattr(self, p.name) is not None and not _numeric(getattr(self, p.name)):
            raise ValueError(f"{where}{p.name} must be {'a list of 3 numbers' if p.channels == 3 else 'a number'}; "
                             f"got {_show(getattr(self, p.name))}")
        if m.declaration(p.name) is None and not is_default(p, getattr(self, p.name)):
            raise ValueError(f"{where}{p.name} needs model {models_with(p.name)}")
    if self.conductor is not None:
        if not isinstance(self.conductor, str) or self.conductor not in CONDUCTORS:
            raise ValueError(f"{where}unknown conductor {describe(self.conductor)}; known: "
                             f"{', '.join(sorted(CONDUCTORS))}")
        if self.eta is not None or self.k is not None:
            raise ValueError(f"{where}give either conductor or eta and k, not both")
        eta, k = (np.asarray(x) for x in CONDUCTORS[self.conductor])
        set_(self, "eta", tuple(eta))
        set_(self, "k", tuple(k))
        set_(self, "metallic", 1.0)
        set_(self, "base_color", tuple(f0_conductor(eta, k)))
    try:
        material = self.material()
    except ValueError as exc:
        raise ValueError(f"{where}{exc}") from None
    for p in m.numbers:  # the model's own ranges, where narrower than the shared ones
        value = getattr(material, p.name)
        if value is not None and np.any(((value < p.low) | (value > p.high)) & ~(np.isin(value, p.also) if p.also
                                                                                 else False)):
            raise ValueError(f"{where}{p.name} must be in {p.range_text} for model {self.model!r} ({p.doc})")
    for p in NUMBERS:  # normalised: floats and tuples of floats
        value = getattr(material, p.name)
        if value is not None:
            set_(self, p.name, tuple(float(x) for x in value) if p.channels == 3 else float(value))
    if m.check is not None:
        m.check({name: getattr(self, name) for name in (c.name for c in CHOICES)} |
                {p.name: getattr(self, p.name) for p in NUMBERS}, where)
    e = np.asarray(self.emissive, dtype=float) if _numeric(self.emissive) else np.full(3, np.nan)
    if e.shape != (3,) or not np.all(np.isfinite(e)) or np.any(e < 0):
        raise ValueError(f"{where}emissive must be 3 finite non-negative numbers; got {_show(self.emissive)}")
    set_(self, "emissive", tuple(float(x) for x in e))
    if not isinstance(self.double_sided, (bool, np.bool_)):
        raise ValueError(f"{where}double_sided must be true or false; got {_show(self.double_sided)}")
    set_(self, "double_sided", bool(self.double_sided))


def _material(self):
    """The :class:`pbrkit.Material` of these parameters (validates them)."""
    return Material(**{p.name: (None if getattr(self, p.name) is None else np.asarray(getattr(self, p.name),
                                                                                        dtype=float))
                       for p in NUMBERS})


def _doc():
    lines = ["A scene material (module docstring): its ``model``, every parameter and term of the models",
             "(:mod:`pbrkit.brdf.models`), and the renderer's ``emissive`` (radiance, cd / m^2),",
             "``double_sided`` and ``conductor``.", "", "Keys (name = default):", ""]
    for p in NUMBERS + CHOICES:
        lines.append(f"- ``{p.name}`` = {p.default!r}: {p.doc} (models {models_with(p.name)})")
    return "\n".join(lines)


MaterialSpec = dataclasses.make_dataclass(
    "MaterialSpec",
    [("name", "str", dataclasses.field(default="default")), ("model", "str", dataclasses.field(default="gltf"))]
    + [(p.name, "object", _spec_default(p)) for p in NUMBERS + CHOICES]
    + [("emissive", "tuple", dataclasses.field(default=(0.0, 0.0, 0.0))),
       ("double_sided", "bool", dataclasses.field(default=True)),
       ("conductor", "str | None", dataclasses.field(default=None))],
    frozen=True,
    namespace={"__post_init__": _post_init, "material": _material, "__doc__": _doc(), "__module__": __name__},
)
