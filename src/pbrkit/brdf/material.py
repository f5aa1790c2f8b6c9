"""The material of the NumPy API, :class:`Material`, generated from the models'
parameter declarations (:data:`pbrkit.brdf.shading.registry.PARAMETERS`): one
field per parameter of any model, with its default, and its range checked on
construction (a ``ValueError`` naming the parameter; nothing is clamped
silently except alpha's documented minimum).  A model reads the fields it
declares and checks its own, possibly narrower, ranges when it evaluates
(Disney's anisotropy is Burley's aspect in [0, 1]).

Perceptual roughness r maps to alpha = max(r^2, ALPHA_MIN) in every model;
``reflectance`` is Filament's (dielectric f0 = 0.16 reflectance^2); UE4's
``Specular`` s (f0 = 0.08 s) converts with :meth:`Material.from_ue4`, a metal's
complex IOR with :meth:`Material.conductor`.  Every field broadcasts against
the directions' leading shape; RGB fields have 3 channels in their last axis.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..microfacet.roughness import alpha_from_roughness
from .fresnel import CONDUCTORS, f0_from_reflectance
from .shading.registry import PARAMETERS
from .parameters import Parameter

__all__ = ["Material", "FIELDS"]

#: The declarations of :class:`Material`'s fields, in order.
FIELDS = tuple(p for p in PARAMETERS if isinstance(p, Parameter))


def _default(p):
    if isinstance(p.default, tuple):
        value = np.asarray(p.default, dtype=float)
        return dataclasses.field(default_factory=lambda: value.copy())
    return dataclasses.field(default=p.default)


def _post_init(self):
    set_ = object.__setattr__
    for p in FIELDS:
        set_(self, p.name, p.check(getattr(self, p.name), f"Material.{p.name}"))
    if (self.eta is None) != (self.k is None):
        raise ValueError("Material.eta and Material.k must be given together")


def _conductor(cls, name, roughness=0.5, **kwargs):
    """A metal with the tabulated complex IOR of :data:`pbrkit.brdf.fresnel.CONDUCTORS`.

    base_color is set to the exact Fresnel f0 of that IOR so that the
    metallic-workflow models show the same metal.
    """
    from .fresnel import f0_conductor

    try:
        eta, k = CONDUCTORS[name]
    except KeyError:
        raise ValueError(f"unknown conductor {name!r}; known: {', '.join(sorted(CONDUCTORS))}") from None
    eta = np.asarray(eta)
    k = np.asarray(k)
    return cls(base_color=f0_conductor(eta, k), metallic=1.0, roughness=roughness, eta=eta, k=k, **kwargs)


def _from_ue4(cls, base_color, metallic=0.0, roughness=0.5, specular=0.5, **kwargs):
    """UE4 parameters: dielectric f0 = 0.08 specular (Karis 2013), mapped to reflectance."""
    specular = Parameter("specular", 0.5, 0.0, 1.0, "", "").check(specular, "Material.specular")
    return cls(base_color=base_color, metallic=metallic, roughness=roughness, reflectance=np.sqrt(0.5 * specular),
               **kwargs)


def _alpha(self):
    """alpha = max(r^2, ALPHA_MIN)."""
    return alpha_from_roughness(self.roughness)


def _dielectric_f0(self):
    """f0 of the non-metallic part, 0.16 reflectance^2."""
    return f0_from_reflectance(self.reflectance)


def _doc():
    lines = ["A material of any model, its fields generated from the models' parameter",
             "declarations (module docstring); every field broadcasts against the directions'",
             "leading shape.", "", "Fields (name, default, range, meaning):", ""]
    for p in FIELDS:
        default = "None" if p.default is None else p.default
        rgb = ", RGB" if p.channels == 3 else ""
        lines.append(f"- ``{p.name}`` = {default}, in {p.range_text}{rgb}: {p.doc}")
    return "\n".join(lines)


Material = dataclasses.make_dataclass(
    "Material",
    [(p.name, "np.ndarray | None" if p.optional else "np.ndarray", _default(p)) for p in FIELDS],
    frozen=True,
    namespace={"__post_init__": _post_init, "conductor": classmethod(_conductor),
               "from_ue4": classmethod(_from_ue4), "alpha": property(_alpha),
               "dielectric_f0": property(_dielectric_f0), "__doc__": _doc(), "__module__": __name__},
)
