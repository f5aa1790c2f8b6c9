"""The shading models, one registration line each, and what is generated from
their declarations (:class:`pbrkit.brdf.shading.model.Model`): the model codes,
the terms each fixes, the packed parameter row (:data:`LAYOUT`), the union of
the parameters (:data:`PARAMETERS`, the fields of :class:`pbrkit.Material`),
and the term tuples the direct-lighting kernel specialises (:data:`VARIANTS`).

Adding a model: write its module (a :class:`~pbrkit.brdf.shading.model.Model`
named ``MODEL``) and add one line to :data:`REGISTERED` below.
"""

from __future__ import annotations

import math

from ..lobes.diffuse import DIFFUSES
from ..parameters import Choice, Layout, Parameter, markdown_table, union
from ..terms import DISTRIBUTIONS, FRESNELS, MASKINGS
from . import cook_torrance, disney, filament, gltf, ue4, urp_mobile

__all__ = ["REGISTERED", "MODELS", "COMPILED", "EXTENDED_CODES", "BY_NAME", "MODEL_TERMS", "PARAMETERS", "SURFACE", "LAYOUT", "COLUMNS",
           "VARIANTS", "TERM_NAMES", "model_codes", "model",
           "parameters_markdown"]

#: The models, in code order (a material's code row stores the index).
REGISTERED = (
    cook_torrance.MODEL,
    filament.MODEL,
    ue4.MODEL,
    urp_mobile.MODEL,
    disney.MODEL,
    gltf.MODEL,
)

#: Model names in code order (the scene files' ``model`` key).
MODELS = tuple(m.name for m in REGISTERED)
#: What the kernels compile, in code order: each registered model (its core where it
#: declares one, :attr:`pbrkit.brdf.shading.model.Model.core`: the code of a material
#: without extensions), then the extended forms of the models with a core.
COMPILED = tuple(m.core or m for m in REGISTERED) + tuple(m for m in REGISTERED if m.core is not None)
#: The code of each model's extended form, by name.
EXTENDED_CODES = {m.name: len(REGISTERED) + i for i, m in enumerate(m for m in REGISTERED if m.core is not None)}
BY_NAME = {m.name: m for m in REGISTERED}
#: The term name tuples of cook_torrance's choices, in code order.
TERM_NAMES = {"distribution": DISTRIBUTIONS, "masking": MASKINGS, "fresnel": FRESNELS, "diffuse": DIFFUSES}
#: The (distribution, masking, fresnel, diffuse) each model fixes; None: the material chooses.
MODEL_TERMS = {m.name: m.terms for m in REGISTERED if any(t is not None for t in m.terms)}
#: Every model's parameters, one declaration per name (the widest range).
PARAMETERS = union(p for m in REGISTERED for p in m.parameters)
#: Per-material values of the renderer beside the BRDF's, packed in the same row.
SURFACE = (Parameter("emissive", (0.0, 0.0, 0.0), 0.0, math.inf, "cd / m^2", "emitted radiance", channels=3),
           Parameter("double_sided", 1.0, 0.0, 1.0, "", "1: both sides shade (glTF doubleSided)"),
           Parameter("coat_normal", (0.0, 0.0, 0.0), -1.0, 1.0, "", "world-space normal of the clear coat at a "
                     "hit (KHR_materials_clearcoat's clearcoatNormalTexture, or the geometry's normal under a "
                     "base normal map); 0: the shading normal", channels=3))
#: The packed parameter row of the compiled kernels.
LAYOUT = Layout(PARAMETERS, SURFACE)
COLUMNS = LAYOUT.columns


def parameters_markdown():
    """The documentation's table of every model's parameters (``docs/materials.md``),
    generated from the declarations (:func:`pbrkit.brdf.parameters.markdown_table`)."""
    return markdown_table(REGISTERED)


def model(name):
    """The registered model ``name``, or ``ValueError`` naming the choices."""
    try:
        return BY_NAME[name]
    except KeyError:
        raise ValueError(f"unknown model {name!r}; choose one of {', '.join(MODELS)}") from None


def _term_codes(m, terms):
    codes = []
    for kind, fixed, given in zip(TERM_NAMES, m.terms, terms):
        name = fixed if fixed is not None else given
        codes.append(TERM_NAMES[kind].index(name))
    return tuple(codes)


def model_codes(name, distribution="ggx", masking="height-correlated", fresnel="schlick", diffuse="lambert",
                values=None):
    """The code row (model, distribution, masking, fresnel, diffuse) of a model and
    its terms by name; a model's fixed terms replace the ones given.  The model code
    is its extended form's (:data:`EXTENDED_CODES`) when the parameter ``values`` (a
    mapping by name) use one of its extensions
    (:meth:`pbrkit.brdf.shading.model.Model.uses_extensions`), else its core's."""
    m = model(name)
    given = (distribution, masking, fresnel, diffuse)
    for kind, value in zip(TERM_NAMES, given):
        if value not in TERM_NAMES[kind]:
            raise ValueError(f"unknown {kind} {value!r}; choose one of {', '.join(TERM_NAMES[kind])}")
    code = EXTENDED_CODES[name] if values is not None and m.uses_extensions(values) else MODELS.index(name)
    return (code,) + _term_codes(m, given)


#: The code rows the direct-lighting kernel compiles specialised, with whether the
#: model samples a coat (then its p_coat stays a variable).
VARIANTS = tuple((model_codes(m.name, *terms), (m.core or m).compiled.coat is not None) for m in REGISTERED
                 for terms in (m.core or m).variants)


def _check_declarations():
    for m in REGISTERED:
        for p in m.parameters:
            if isinstance(p, Choice) and p.name in TERM_NAMES:
                unknown = set(p.choices) - set(TERM_NAMES[p.name])
                if unknown:
                    raise ValueError(f"model {m.name!r}: {p.name} choices {sorted(unknown)} are not in the table")


_check_declarations()
