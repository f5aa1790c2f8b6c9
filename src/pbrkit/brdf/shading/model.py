"""What a shading model declares (:class:`Model`): its parameters, how the BxDF is
set up from them, its composition of lobes, and its real-time treatment.  One
module per model (:mod:`pbrkit.brdf.models`) holds one such declaration; the
registry (:mod:`pbrkit.brdf.shading.registry`) lists them, and everything else
is generated from it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...core.jit import dual_use
from ..operators import compose
from ..parameters import Choice, Parameter

__all__ = ["Model", "RealTime"]


@dual_use(inline=True)
def _one(b, nov, exact, table):
    return 1.0


@dual_use(inline=True)
def _no_coat(b):
    return -1.0


@dual_use(inline=True)
def _unscaled(b, nov, coat_nov):
    return 1.0


@dual_use(inline=True)
def _opaque(b):
    return 0.0


@dual_use(inline=True)
def _uncoated(params, q, columns):
    return 0.0


@dataclass(frozen=True, eq=False)
class RealTime:
    """A model's real-time image-based lighting beyond the split sum of its specular
    lobe (:mod:`pbrkit.rendering.realtime`): ``diffuse_weight(b, nov, exact, table)``,
    the weight on diffuse_color E(n) / pi (1 unless the diffuse lobe is weighted,
    glTF's 1 - F(v.h)); ``coat_roughness(b)``, the perceptual roughness of a second
    prefiltered lookup for a coat (-1: none); ``sheen_roughness(b)``, that of a third,
    in the sheen's (Charlie) chain (-1: none); ``extras(b, nov, coat_nov, coat_dfg1, coat_dfg2,
    sheen_table, irradiance, coat_prefiltered, sheen_prefiltered, dfg1, dfg2, radiance)``
    -> (specular RGB, diffuse RGB) added for the model's other lobes (``None``: there
    are none), with the DFG table at the coat's roughness, the RGB irradiance, coat and
    sheen lookups, and the base's DFG and RGB prefiltered radiance; ``coat_nov`` the
    view's cosine to the coat's own normal (the shading normal's n.v where it has none,
    :func:`pbrkit.brdf.lobes.clearcoat.coat_local_nov`), at which the coat's DFG lookups
    are made too;
    ``base_scale(b, nov, coat_nov)``, the factor on the specular and diffuse IBL terms before
    the extras are added (1: none; glTF's KHR_materials_sheen albedo scaling);
    ``khronos_extensions``: ``engine="khronos"`` evaluates the model's glTF material
    extensions as the Sample Viewer does (:mod:`pbrkit.rendering.khronos_ibl`);
    ``transmission(b)``, the weight on base colour x diffuse weight x the light
    transmitted through the surface (0: none; glTF's KHR_materials_transmission,
    :mod:`pbrkit.rendering.transmission_ibl`)."""

    diffuse_weight: object = _one
    coat_roughness: object = _no_coat
    sheen_roughness: object = _no_coat
    extras: object = None
    base_scale: object = _unscaled
    khronos_extensions: bool = False
    transmission: object = _opaque


@dataclass(frozen=True, eq=False)
class Model:
    """A shading model's declaration.

    - ``name``: its key in scene files and the NumPy API; ``doc``: one line.
    - ``parameters``: :class:`~pbrkit.brdf.parameters.Parameter` and
      :class:`~pbrkit.brdf.parameters.Choice` declarations, in the model's order.
    - ``setup(codes, row, params, q, columns, roughness, metallic, b0, b1, b2)``:
      the compiled :class:`~pbrkit.brdf.bxdf.BxDF` of code row ``row`` and parameter
      row ``q`` (columns by name in ``columns``) with the shading point's base colour,
      metallic and roughness.
    - ``composition``: its lobes and operators (:mod:`pbrkit.brdf.operators`).
    - ``terms``: the (distribution, masking, fresnel, diffuse) names it fixes, None
      for a term chosen per material (a :class:`~pbrkit.brdf.parameters.Choice`).
    - ``realtime``: :class:`RealTime`.
    - ``variants``: term tuples the direct-lighting kernel compiles specialised.
    - ``check(values, where)``: cross-parameter rules (one-line ``ValueError``).
    - ``emission_coat(params, q, columns)``: the weight of a coat that lies over the
      material's emission (0: none; glTF's KHR_materials_clearcoat: clearcoatFactor),
      which darkens it by :func:`pbrkit.brdf.lobes.clearcoat.coated_emission`.
    - ``core``: for a model with extensions (glTF's ``KHR_materials_*``), the
      :class:`Model` of a material that uses none of them (its parameters a prefix
      of this one's, its values on such a material equal to this one's).  The
      kernels compile both (:data:`pbrkit.brdf.shading.registry.COMPILED`) and a
      material's code row names the core unless it uses an extension
      (:meth:`uses_extensions`), so that a material without extensions runs the
      code it ran before the extensions existed, at the same speed.
    """

    name: str
    doc: str
    parameters: tuple
    setup: object
    composition: object
    terms: tuple
    realtime: RealTime = field(default_factory=RealTime)
    variants: tuple = ()
    check: object = None
    core: object = None
    emission_coat: object = _uncoated
    compiled: object = field(init=False)

    def __post_init__(self):
        object.__setattr__(self, "compiled", compose(self.composition))
        names = [p.name for p in self.parameters]
        if len(set(names)) != len(names):
            raise ValueError(f"model {self.name!r} declares a parameter twice")
        for p in self.parameters:
            if not isinstance(p, (Parameter, Choice)):
                raise TypeError(f"model {self.name!r}: {p!r} is not a parameter declaration")
        if self.core is not None and tuple(self.core.parameters) != tuple(self.parameters[:len(self.core.parameters)]):
            raise ValueError(f"model {self.name!r}: its core's parameters must begin its own")

    @property
    def extensions(self):
        """The parameters beyond the core's (none without a core)."""
        if self.core is None:
            return ()
        return tuple(self.parameters[len(self.core.parameters):])

    def uses_extensions(self, values):
        """Whether a material with parameter ``values`` (a mapping by name; scalars,
        tuples or arrays of per-element values; missing names are at their defaults)
        uses any of the extensions: a value of an extension parameter other than its
        default."""
        for p in self.extensions:
            value = values.get(p.name)
            if value is None:
                continue
            array = np.asarray(value, dtype=np.float64)
            default = p.default if isinstance(p.default, tuple) else (p.default,)
            if array.size <= 3:  # one material's value: Python's comparison (np.any costs microseconds)
                flat = array.ravel().tolist()
                if any(x != default[i % len(default)] for i, x in enumerate(flat)):
                    return True
            elif np.any(array != np.asarray(p.default)):
                return True
        return False

    @property
    def numbers(self):
        """The numeric parameters."""
        return tuple(p for p in self.parameters if isinstance(p, Parameter))

    @property
    def choices(self):
        """The term choices, by name."""
        return {p.name: p for p in self.parameters if isinstance(p, Choice)}

    def declaration(self, name):
        """The declaration of parameter ``name``, or None."""
        for p in self.parameters:
            if p.name == name:
                return p
        return None
