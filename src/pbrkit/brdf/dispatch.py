"""One dispatch on the model code, generated from the registry
(:mod:`pbrkit.brdf.shading.registry`): the compiled functions the kernels call
for a BxDF of any model.  Each is ``if model == 0: return <model 0's> ...``,
generated, never typed; a kernel that fixes the model (a BxDF whose code is a
constant, :func:`specialised`) keeps that model's branch only, so its
per-sample code has no model branches.  The generated text is each function's
``__source__``.

- :func:`make_bxdf` (the model's setup), :func:`bxdf_f` (the value f, RGB, not
  f cos; zero unless n.l > 0 and n.v > 0), :func:`lobe_probabilities`,
  :func:`sample_wi` and :func:`bxdf_pdf` (the composition's mixture,
  :func:`pbrkit.brdf.operators.compose`);
- the main specular lobe's pieces, for the tables, the explorer and the real-time
  split sum: :func:`specular_lobe` (D V), :func:`specular_distribution` (D),
  :func:`specular_visibility` (V), :func:`bxdf_fresnel` (F, RGB),
  :func:`split_sum_f0` (RGB), :func:`split_sum_f90`, :func:`fresnel_constant`;
- the real-time treatment of the model's other lobes (:class:`pbrkit.brdf.shading.model.RealTime`):
  :func:`ibl_has_diffuse`, :func:`ibl_diffuse_weight`, :func:`ibl_coat_roughness`,
  :func:`ibl_sheen_roughness`, :func:`ibl_base_scale`, :func:`ibl_khronos_extensions`,
  :func:`ibl_base_scale`, :func:`ibl_has_extras`, :func:`ibl_extras`.
"""

from __future__ import annotations

from typing import NamedTuple

from ..core.codegen import generate, if_chain
from ..core.jit import dual_use, rebind
from .bxdf import BxDF
from .lobes.microfacet import always, never
from .shading.registry import COLUMNS, COMPILED, EXTENDED_CODES

__all__ = ["make_bxdf", "emission_coat", "bxdf_f", "lobe_probabilities", "sample_wi", "bxdf_pdf", "specular_lobe",
           "specular_distribution", "specular_visibility", "bxdf_fresnel", "split_sum_f0", "split_sum_f90",
           "fresnel_constant", "ibl_has_diffuse", "ibl_diffuse_weight", "ibl_coat_roughness", "ibl_sheen_roughness",
           "ibl_base_scale", "ibl_khronos_extensions", "ibl_has_extras", "ibl_transmission",
           "ibl_extras",
           "specialised", "SOURCES", "Sampling", "sampling", "SAMPLING_BY_MODEL", "family", "restricted",
           "core_substitute"]

#: The generated source of every dispatch, by name.
SOURCES = {}


#: Each dispatch over every compiled model, by name, and how to generate it again over
#: other models (:func:`family`).
_FULL = {}
_SPECS = {}


def _dispatch(name, arguments, call, selector="b.model", inline=True, head=(), namespace=None, models=COMPILED):
    """``def name(arguments): <head> if selector == i: return call(i) ...`` over the
    registered models (or just ``return call(0)`` for one model in ``models``);
    ``call(i, model)`` gives the expression and registers what it calls in the
    namespace ``ns``."""
    ns = dict(namespace or {})
    calls = [call(i, m, ns) for i, m in enumerate(models)]
    lines = [f"def {name}({', '.join(arguments)}):", *head] + if_chain(selector, calls)
    source = "\n".join(lines) + "\n"
    full = models is COMPILED
    if full:
        SOURCES[name] = source
    fn = generate(source, name, ns, inline=inline)
    if full:
        _FULL[name] = fn
        _SPECS[name] = (arguments, call, selector, inline, head, namespace)
    return fn


_FAMILIES = {}


def family(models):
    """Every dispatch of this module generated over ``models`` (a prefix of
    :data:`pbrkit.brdf.shading.registry.COMPILED`, so that a model's code is its
    index in both), by name; the module's own functions for all of them."""
    models = tuple(models)
    if models == COMPILED:
        return dict(_FULL)
    if models != COMPILED[:len(models)] or not models:
        raise ValueError("a family of the dispatch is a non-empty prefix of the compiled models")
    if models not in _FAMILIES:
        _FAMILIES[models] = {name: _dispatch(name, a, c, sel, inl, h, ns, models)
                             for name, (a, c, sel, inl, h, ns) in _SPECS.items()}
    return _FAMILIES[models]


_RESTRICTED = {}
#: Functions that only the extended forms need, and what a kernel for the cores alone
#: calls instead (:func:`core_substitute`), by ``id`` of the original.
_CORE_SUBSTITUTES = {}


def core_substitute(original, substitute):
    """Have kernels compiled for the registered models' cores alone (:func:`restricted`
    over models without an extended form) call ``substitute`` where they call
    ``original``: a function only an extension needs (the transmissive vertex of the
    ground truth, say), replaced by the opaque one or a constant, so that such kernels
    neither compile nor run its code.  Returns ``original``."""
    _CORE_SUBSTITUTES[id(original)] = (original, substitute)
    return original


def restricted(fn, models):
    """``fn`` (a kernel or compiled helper that calls this module's dispatch, directly or
    not) compiled with the dispatch over ``models`` only (:func:`family`), so that a
    kernel for scenes of those models carries no other model's code
    (:func:`pbrkit.core.jit.rebind`; copies named after the number of models, cached
    on disk as their own); without an extended form among ``models``, also with the
    :func:`core_substitute` s.  ``fn`` itself for every compiled model."""
    models = tuple(models)
    if models == COMPILED:
        return fn
    key = models, len(_CORE_SUBSTITUTES)
    if key not in _RESTRICTED:
        sub = family(models)
        replacements = {id(_FULL[name]): sub[name] for name in _FULL}
        if not any(code < len(models) for code in EXTENDED_CODES.values()):
            replacements.update({k: new for k, (_, new) in _CORE_SUBSTITUTES.items()})
        _RESTRICTED[key] = (replacements, {})
    replacements, memo = _RESTRICTED[key]
    return rebind(fn, replacements, f"models{len(models)}", memo)


def _put(ns, key, fn):
    ns[key] = fn
    return key


make_bxdf = _dispatch(
    "make_bxdf", ("codes", "row", "params", "q", "roughness", "metallic", "b0", "b1", "b2"),
    lambda i, m, ns: f"{_put(ns, f'setup{i}', m.setup)}(codes, row, params, q, COLUMNS, roughness, metallic, b0, b1, "
                     f"b2)", selector="codes[row, 0]", namespace={"COLUMNS": COLUMNS})
make_bxdf.__doc__ = """The :class:`pbrkit.brdf.bxdf.BxDF` of a material (row ``row`` of the code
table ``codes``, row ``q`` of the parameter table ``params``) with the base colour
(b0, b1, b2), metallic and perceptual roughness at the shading point (textures
applied): the model's setup.  Tables and row numbers rather than row views: a view
per call costs reference counting in the innermost loops."""

emission_coat = _dispatch(
    "emission_coat", ("codes", "row", "params", "q"),
    lambda i, m, ns: f"{_put(ns, f'coat{i}', m.emission_coat)}(params, q, COLUMNS)", selector="codes[row, 0]",
    namespace={"COLUMNS": COLUMNS})
emission_coat.__doc__ = """The weight of the coat over the emission of the material of code row ``row``
and parameter row ``q`` (:attr:`pbrkit.brdf.shading.model.Model.emission_coat`; 0 for
every model without one, so that a kernel for the cores alone folds it away)."""


class Sampling(NamedTuple):
    """The functions of the Monte Carlo estimator for the models of ``models``:
    ``bxdf_f(b, c, ec0, ec1, ec2)``, ``lobe_probabilities(b, nov)``,
    ``sample_wi(b, wox, woy, woz, u_lobe, u1, u2, p_spec, p_coat)``,
    ``bxdf_pdf(b, c, p_spec, p_coat)``."""

    bxdf_f: object
    lobe_probabilities: object
    sample_wi: object
    bxdf_pdf: object


def sampling(models=COMPILED, suffix=""):
    """:class:`Sampling` dispatching over ``models`` (one model: its own functions,
    without a branch, for a kernel compiled for that model alone)."""
    return Sampling(
        _dispatch(f"bxdf_f{suffix}", ("b", "c", "ec0", "ec1", "ec2"),
                  lambda i, m, ns: f"{_put(ns, f'value{i}', m.compiled.value)}(b, c, (ec0, ec1, ec2))",
                  head=("    if c.nol <= 0.0 or c.nov <= 0.0:", "        return 0.0, 0.0, 0.0"), inline=False,
                  models=models),
        _dispatch(f"lobe_probabilities{suffix}", ("b", "nov"),
                  lambda i, m, ns: f"{_put(ns, f'p{i}', m.compiled.probabilities)}(b, nov)", models=models),
        _dispatch(f"sample_wi{suffix}", ("b", "wox", "woy", "woz", "u_lobe", "u1", "u2", "p_spec", "p_coat"),
                  lambda i, m, ns: f"{_put(ns, f's{i}', m.compiled.sample)}(b, wox, woy, woz, u_lobe, u1, u2, p_spec, "
                                   "p_coat)", models=models),
        _dispatch(f"bxdf_pdf{suffix}", ("b", "c", "p_spec", "p_coat"),
                  lambda i, m, ns: f"{_put(ns, f'pdf{i}', m.compiled.pdf)}(b, c, p_spec, p_coat)", models=models))


bxdf_f, lobe_probabilities, sample_wi, bxdf_pdf = sampling()
#: Each compiled model's own :class:`Sampling` (no branch on the model), by model code.
SAMPLING_BY_MODEL = tuple(sampling((m,), f"_{i}_{m.name}") for i, m in enumerate(COMPILED))


def _part(attribute, arguments):
    return lambda i, m, ns: f"{_put(ns, f'{attribute}{i}', getattr(m.compiled.specular.parts, attribute))}" \
                            f"({', '.join(arguments)})"


specular_lobe = _dispatch("specular_lobe", ("b", "c"), _part("dv", ("b", "c")))
specular_distribution = _dispatch("specular_distribution", ("b", "c"), _part("d", ("b", "c")))
specular_visibility = _dispatch("specular_visibility", ("b", "c"), _part("v", ("b", "c")))
bxdf_fresnel = _dispatch("bxdf_fresnel", ("b", "voh"), _part("fresnel", ("b", "voh")))
split_sum_f0 = _dispatch("split_sum_f0", ("b",), _part("split_sum_f0", ("b",)))
split_sum_f90 = _dispatch("split_sum_f90", ("b",), _part("split_sum_f90", ("b",)))
fresnel_constant = _dispatch("fresnel_constant", ("b",), _part("constant", ("b",)))


def _has_diffuse(m):
    """Whether the model's diffuse lobe is present: a choice that can be "none" is
    present unless the BxDF's diffuse code is that."""
    choice = m.choices.get("diffuse")
    if not m.compiled.diffuse:
        return never
    if choice is None or "none" not in choice.choices:
        return always
    from .lobes.diffuse import DIFFUSES

    none = DIFFUSES.index("none")

    @dual_use(inline=True)
    def present(b):
        return b.diffuse != none

    return present


ibl_has_diffuse = _dispatch("ibl_has_diffuse", ("b",),
                            lambda i, m, ns: f"{_put(ns, f'h{i}', _has_diffuse(m))}(b)")
ibl_diffuse_weight = _dispatch(
    "ibl_diffuse_weight", ("b", "nov", "exact", "table"),
    lambda i, m, ns: f"{_put(ns, f'w{i}', m.realtime.diffuse_weight)}(b, nov, exact, table)")
ibl_coat_roughness = _dispatch("ibl_coat_roughness", ("b",),
                               lambda i, m, ns: f"{_put(ns, f'c{i}', m.realtime.coat_roughness)}(b)")
ibl_base_scale = _dispatch("ibl_base_scale", ("b", "nov", "coat_nov"),
                           lambda i, m, ns: f"{_put(ns, f's{i}', m.realtime.base_scale)}(b, nov, coat_nov)")
ibl_sheen_roughness = _dispatch("ibl_sheen_roughness", ("b",),
                                lambda i, m, ns: f"{_put(ns, f'r{i}', m.realtime.sheen_roughness)}(b)")
ibl_khronos_extensions = _dispatch(
    "ibl_khronos_extensions", ("b",),
    lambda i, m, ns: f"{_put(ns, f'k{i}', always if m.realtime.khronos_extensions else never)}(b)")
ibl_transmission = _dispatch("ibl_transmission", ("b",),
                             lambda i, m, ns: f"{_put(ns, f't{i}', m.realtime.transmission)}(b)")
ibl_has_extras = _dispatch("ibl_has_extras", ("b",),
                           lambda i, m, ns: f"{_put(ns, f'x{i}', always if m.realtime.extras else never)}(b)")


@dual_use(inline=True)
def _no_extras(b, nov, coat_nov, coat_dfg1, coat_dfg2, sheen_table, irradiance, coat_prefiltered, sheen_prefiltered, dfg1, dfg2,
               radiance):
    z = (0.0, 0.0, 0.0)
    return z, z


ibl_extras = _dispatch(
    "ibl_extras", ("b", "nov", "coat_nov", "coat_dfg1", "coat_dfg2", "sheen_table", "irradiance", "coat_prefiltered",
                   "sheen_prefiltered", "dfg1", "dfg2", "radiance"),
    lambda i, m, ns: f"{_put(ns, f'e{i}', m.realtime.extras or _no_extras)}(b, nov, coat_nov, coat_dfg1, "
                     "coat_dfg2, sheen_table, irradiance, coat_prefiltered, sheen_prefiltered, dfg1, dfg2, radiance)")


# ----------------------------------------------------------------- specialised


@dual_use(inline=True)
def specialised(b, codes):
    """``b`` with its code row replaced by the constant ``codes`` (which must be its
    own: one of :data:`pbrkit.brdf.shading.registry.VARIANTS`) and made isotropic (the
    kernels specialise isotropic materials only), so that the dispatch functions
    inlined after it fold to that model's composition with those terms."""
    return BxDF(codes[0], codes[1], codes[2], codes[3], codes[4], b.roughness, b.alpha, b.alpha, b.alpha, False, 0.0,
                b.metallic, b.base, b.diffuse_color, b.f0, b.f90, b.eta, b.k, b.dielectric_f0, b.specular_color,
                b.extra)
