"""Layering operators: a material as a composition of lobes (:mod:`pbrkit.brdf.lobes`),
as the glTF 2.0 specification (Appendix B and the ``KHR_materials_*``
extensions) and OpenPBR Surface define materials, and the one sampling
routine and pdf that follow from the composition.

Operators (each a :class:`Node` whose value is built from its operands'; ``w``
the weight an enclosing operator passes down, multiplied into each lobe's
factor):

- :func:`add` (a + b): Disney's sum of lobes (Burley 2012, App. B);
- :func:`weighted` (w(b, c) a): a lobe under a direction-dependent weight, e.g.
  the 1 - F(v.h) glTF gives its diffuse base;
- :func:`mix` ((1 - w) a + w b, w(b) a material parameter): glTF's
  ``mix(dielectric_brdf, metal_brdf, metallic)``, OpenPBR's ``mix``;
- :func:`fresnel_mix` ((1 - F(v.h)) base + F(v.h) layer, F Schlick's of an IOR):
  glTF's ``fresnel_mix(ior, base, layer)`` (Appendix B.3.4);
- :func:`fresnel_coat` ((1 - t) base + t layer, t = weight(b) F(n.v), F Schlick's
  of an IOR at the view's cosine): ``KHR_materials_clearcoat``'s
  ``fresnel_coat(normal, ior, weight, base, layer)``;
- :func:`layer` (top + (1 - E_top(n.v)) base, E_top the top's directional albedo,
  its largest channel): the albedo-scaled layering of ``KHR_materials_sheen``
  and OpenPBR's ``layer``, which keeps a white furnace at or below 1.

:func:`compose` turns a composition into the compiled functions of a model:
its value f, and the mixture that samples it.  Sampling draws one technique
(the lobes' :class:`pbrkit.brdf.lobes.Technique`; lobes that share one share its
samples) with probability proportional to the estimate of its weighted albedo
(each lobe's ``estimate`` at n.v times the estimate weights of the operators
above it), clamped so that the specular and the diffuse technique each keep at
least 0.1 while both are present and a coat takes at most 0.5:

    p_spec = clamp(w_s / (w_s + w_d), 0.1, 0.9) (1 if w_d <= 0, 0 if w_s <= 0),
    p_coat = clamp(w_c / (w_s + w_d + w_c), 0.1, 0.5) if w_c > 0, p_spec *= 1 - p_coat,

and the diffuse (cosine) technique takes the rest; the pdf is the mixture's,
p_spec pdf_spec + p_coat pdf_coat + (1 - p_spec - p_coat) pdf_diffuse.  The
floors keep a lobe the estimate underrates from being starved (its samples
carry the MIS weights' variance), the cap keeps a coat from starving the base.
The generated routines take the probabilities as ``(p_spec, p_coat)`` (0 for
a technique the model lacks).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..core.codegen import generate
from ..core.color import rec709_luminance
from ..core.jit import dual_use
from .fresnel import f0_from_ior, f_schlick
from .lobes import Lobe, broad_width, half_vector_albedo, lobe_width

__all__ = ["Node", "add", "weighted", "mix", "fresnel_mix", "fresnel_coat", "layer", "compose", "Composition"]


@dataclass(frozen=True, eq=False)
class Node:
    """A composition: ``value(b, c, ec, w)`` (RGB) and its leaves, each a
    (lobe, estimate weights) pair: the functions ``(b, nov)`` whose product scales
    that lobe's albedo estimate."""

    name: str
    value: object
    leaves: tuple = field(default=())


def _as_node(x):
    if isinstance(x, Node):
        return x
    if isinstance(x, Lobe):
        return Node(x.name, x.value, ((x, ()),))
    raise TypeError(f"not a lobe or a composition: {x!r}")


def _scaled(leaves, weight):
    return tuple((lobe, weights + ((weight,) if weight is not None else ())) for lobe, weights in leaves)


def add(a, b):
    """f = f_a + f_b (a sum of lobes; Burley 2012, App. B)."""
    a = _as_node(a)
    b = _as_node(b)
    fa, fb = a.value, b.value

    @dual_use(inline=True)
    def value(bx, c, ec, w):
        x = fa(bx, c, ec, w)
        y = fb(bx, c, ec, w)
        return x[0] + y[0], x[1] + y[1], x[2] + y[2]

    return Node(f"add({a.name}, {b.name})", value, a.leaves + b.leaves)


def weighted(weight, a, estimate_weight=None):
    """f = weight(b, c) f_a, a direction-dependent weight; ``estimate_weight(b, nov)``
    scales the lobe's albedo estimate (None: not at all, the weight being unknown
    before a direction is sampled)."""
    a = _as_node(a)
    fa = a.value

    @dual_use(inline=True)
    def value(bx, c, ec, w):
        return fa(bx, c, ec, w * weight(bx, c))

    return Node(f"weighted({a.name})", value, _scaled(a.leaves, estimate_weight))


def mix(a, b, weight):
    """f = (1 - w) f_a + w f_b with w = ``weight(b)`` a material parameter in [0, 1]
    (glTF 2.0 Appendix B ``mix``; OpenPBR's mix).  Estimates scale by 1 - w and w."""
    a = _as_node(a)
    b = _as_node(b)
    fa, fb = a.value, b.value

    @dual_use(inline=True)
    def value(bx, c, ec, w):
        m = weight(bx)
        x = fa(bx, c, ec, w * (1.0 - m))
        y = fb(bx, c, ec, w * m)
        return x[0] + y[0], x[1] + y[1], x[2] + y[2]

    @dual_use(inline=True)
    def weight_a(bx, nov):
        return 1.0 - weight(bx)

    @dual_use(inline=True)
    def weight_b(bx, nov):
        return weight(bx)

    return Node(f"mix({a.name}, {b.name})", value, _scaled(a.leaves, weight_a) + _scaled(b.leaves, weight_b))


def fresnel_mix(ior, base, layer_):
    """f = (1 - F(v.h)) f_base + F(v.h) f_layer, F Schlick's with f0 = ((ior - 1) /
    (ior + 1))^2 (glTF 2.0 Appendix B.3.4 ``fresnel_mix``; the layer is a specular
    lobe without Fresnel of its own).  Estimates scale by 1 - F(n.v) and F(n.v)."""
    base = _as_node(base)
    layer_ = _as_node(layer_)
    fb, fl = base.value, layer_.value
    f0 = f0_from_ior(ior)

    @dual_use(inline=True)
    def value(bx, c, ec, w):
        f = f_schlick(c.voh, f0, 1.0)
        x = fb(bx, c, ec, w * (1.0 - f))
        y = fl(bx, c, ec, w * f)
        return x[0] + y[0], x[1] + y[1], x[2] + y[2]

    @dual_use(inline=True)
    def weight_base(bx, nov):
        return 1.0 - f_schlick(nov, f0, 1.0)

    @dual_use(inline=True)
    def weight_layer(bx, nov):
        return f_schlick(nov, f0, 1.0)

    return Node(f"fresnel_mix({ior:g}, {base.name}, {layer_.name})", value,
                _scaled(base.leaves, weight_base) + _scaled(layer_.leaves, weight_layer))


@dual_use(inline=True)
def _shading_nov(bx, c):
    return c.nov


def fresnel_coat(ior, weight, base, layer_, normal_cosine=None):
    """f = (1 - t) f_base + t f_layer with t = weight(b) F(n_c.v), F = f0 + (1 - f0)(1 -
    |n_c.v|)^5, f0 = ((1 - ior) / (1 + ior))^2: ``KHR_materials_clearcoat``'s
    ``fresnel_coat(normal, ior, weight, base, layer)`` (its README, "Layering"; the
    Fresnel of the view's cosine to the coat's normal n_c, not of v.h, which keeps the
    layering energy conserving).  ``weight(b)`` is a material parameter in [0, 1]
    (clearcoatFactor); ``normal_cosine(b, c)`` gives n_c.v (None: the shading normal's
    n.v), the ``normal`` that "affects the top layer, but not the base".  Estimates
    scale by 1 - t(n.v) and t(n.v) at the shading normal's n.v."""
    base = _as_node(base)
    layer_ = _as_node(layer_)
    fb, fl = base.value, layer_.value
    f0 = f0_from_ior(ior)
    cosine = _shading_nov if normal_cosine is None else normal_cosine

    @dual_use(inline=True)
    def coat(bx, nov):
        return weight(bx) * f_schlick(nov, f0, 1.0)

    @dual_use(inline=True)
    def value(bx, c, ec, w):
        t = coat(bx, cosine(bx, c))
        x = fb(bx, c, ec, w * (1.0 - t))
        y = fl(bx, c, ec, w * t)
        return x[0] + y[0], x[1] + y[1], x[2] + y[2]

    @dual_use(inline=True)
    def weight_base(bx, nov):
        return 1.0 - coat(bx, nov)

    return Node(f"fresnel_coat({ior:g}, {base.name}, {layer_.name})", value,
                _scaled(base.leaves, weight_base) + _scaled(layer_.leaves, coat))


def layer(top, base):
    """f = f_top + (1 - E_top(n.v)) f_base with E_top the top lobe's directional albedo
    (its largest channel): albedo scaling (``KHR_materials_sheen``'s
    ``sheen_albedo_scaling``; OpenPBR's layer), so that energy the top reflects is
    not reflected again by the base.  ``top`` must be a lobe (its ``albedo``)."""
    if not isinstance(top, Lobe):
        raise TypeError("layer: the top must be a lobe (its directional albedo scales the base)")
    albedo = top.albedo
    top_n = _as_node(top)
    base = _as_node(base)
    ft, fb = top_n.value, base.value

    @dual_use(inline=True)
    def scale(bx, nov):
        e = albedo(bx, nov)
        return 1.0 - max(e[0], max(e[1], e[2]))

    @dual_use(inline=True)
    def value(bx, c, ec, w):
        x = ft(bx, c, ec, w)
        y = fb(bx, c, ec, w * scale(bx, c.nov))
        return x[0] + y[0], x[1] + y[1], x[2] + y[2]

    return Node(f"layer({top_n.name}, {base.name})", value, top_n.leaves + _scaled(base.leaves, scale))


# ------------------------------------------------------------------- compose


@dataclass(frozen=True, eq=False)
class Composition:
    """The compiled functions of a composed material: ``value(b, c, ec)`` (RGB f),
    ``probabilities(b, nov) -> (p_spec, p_coat)``, ``sample(b, wox, woy, woz,
    u_lobe, u1, u2, p_spec, p_coat)`` (a local light direction), ``pdf(b, c,
    p_spec, p_coat)``, ``albedo(b, nov)`` (RGB directional albedo by quadrature
    over the half vector, :func:`pbrkit.brdf.lobes.half_vector_albedo`); ``specular``,
    ``coat``: the lobes
    of those roles (or None), ``lobes``: every lobe; ``source``: the generated
    sampling code."""

    node: Node
    value: object
    probabilities: object
    sample: object
    pdf: object
    specular: Lobe | None
    coat: Lobe | None
    diffuse: tuple
    lobes: tuple
    source: str
    albedo: object


def _estimate_expression(entries, namespace):
    """Source of the sum of the estimates of ``entries`` (lobe, weights), each lobe's
    estimate times its weights, functions registered in ``namespace``."""
    terms = []
    for lobe, weights in entries:
        key = f"e{len(namespace)}"
        namespace[key] = lobe.estimate
        term = f"{key}(b, nov)"
        for wfn in weights:
            wkey = f"e{len(namespace)}"
            namespace[wkey] = wfn
            term = f"{term} * {wkey}(b, nov)"
        terms.append(term)
    return " + ".join(terms) if terms else "0.0"


def compose(composition):
    """The compiled :class:`Composition` of a lobe or operator tree (module docstring)."""
    node = _as_node(composition)
    fvalue = node.value
    sampled = [(lobe, weights) for lobe, weights in node.leaves if lobe.role is not None]
    by_role = {role: [e for e in sampled if e[0].role == role] for role in ("specular", "diffuse", "coat")}
    techniques = {role: {id(e[0].technique): e[0].technique for e in entries}
                  for role, entries in by_role.items()}
    for role in ("specular", "coat"):
        if len(techniques[role]) > 1 or len(by_role[role]) > 1:
            raise ValueError(f"{node.name}: at most one {role} lobe can be sampled")
    if len(techniques["diffuse"]) > 1:
        raise ValueError(f"{node.name}: the diffuse lobes must share one technique")
    riders = [lobe for lobe, _ in node.leaves if lobe.role is None and lobe.technique is not None]
    for lobe in riders:
        if not by_role["diffuse"] or lobe.technique is not by_role["diffuse"][0][0].technique:
            raise ValueError(f"{node.name}: lobe {lobe.name!r} rides on a technique nothing samples")

    ns = {"min": min, "max": max}
    spec = by_role["specular"][0][0] if by_role["specular"] else None
    coat = by_role["coat"][0][0] if by_role["coat"] else None
    diffuse = by_role["diffuse"]
    lines = ["def probabilities(b, nov):"]
    if spec is None:
        lines.append("    p_spec = 0.0")
    elif not diffuse:
        lines.append("    p_spec = 1.0")
    if spec is not None or coat is not None:
        lines.append(f"    ws = {_estimate_expression(by_role['specular'], ns)}")
    if diffuse:
        lines.append(f"    wd = {_estimate_expression(diffuse, ns)}")
    if spec is not None and diffuse:
        lines += ["    if wd <= 0.0:", "        p_spec = 1.0", "    elif ws <= 0.0:", "        p_spec = 0.0",
                  "    else:", "        p_spec = min(max(ws / (ws + wd), 0.1), 0.9)"]
    lines.append("    p_coat = 0.0")
    if coat is not None:
        total = "ws + wd + wc" if diffuse else "ws + wc"
        lines += [f"    wc = {_estimate_expression(by_role['coat'], ns)}", "    if wc > 0.0:",
                  f"        p_coat = min(max(wc / ({total}), 0.1), 0.5)", "        p_spec *= 1.0 - p_coat"]
    lines.append("    return p_spec, p_coat")
    probabilities_src = "\n".join(lines) + "\n"

    ns["ss"] = spec.technique.sample if spec is not None else None
    ns["ps"] = spec.technique.pdf if spec is not None else None
    ns["sc"] = coat.technique.sample if coat is not None else None
    ns["pc"] = coat.technique.pdf if coat is not None else None
    ns["sd"] = diffuse[0][0].technique.sample if diffuse else None
    ns["pd"] = diffuse[0][0].technique.pdf if diffuse else None
    lines = ["def sample(b, wox, woy, woz, u_lobe, u1, u2, p_spec, p_coat):"]
    order = [(n, s) for n, s in (("p_spec", spec), ("p_coat", coat)) if s is not None]
    last = "sd" if diffuse else ("ss" if spec is not None else "sc")
    bound = []
    for name, lobe in order:
        bound.append(name)
        fn = "ss" if lobe is spec else "sc"
        if fn == last:
            continue
        lines += [f"    if u_lobe < {' + '.join(bound) if len(bound) > 1 else bound[0]}:",
                  f"        return {fn}(b, wox, woy, woz, u1, u2)"]
    lines.append(f"    return {last}(b, wox, woy, woz, u1, u2)")
    sample_src = "\n".join(lines) + "\n"

    lines = ["def pdf(b, c, p_spec, p_coat):", "    pdf = 0.0"]
    if spec is not None:
        lines += ["    if p_spec > 0.0:", "        pdf += p_spec * ps(b, c)"]
    if coat is not None:
        lines += ["    if p_coat > 0.0:", "        pdf += p_coat * pc(b, c)"]
    if diffuse:
        lines += ["    if p_spec + p_coat < 1.0:", "        pdf += (1.0 - p_spec - p_coat) * pd(b, c)"]
    lines.append("    return pdf")
    pdf_src = "\n".join(lines) + "\n"

    @dual_use(inline="llvm")
    def value(b, c, ec):
        return fvalue(b, c, ec, 1.0)

    ns["rec709_luminance"] = rec709_luminance
    probabilities = generate(probabilities_src, "probabilities", ns, inline=False)
    sample = generate(sample_src, "sample", ns, inline=False)
    pdf = generate(pdf_src, "pdf", ns, inline=False)
    return Composition(node, value, probabilities, sample, pdf, spec, coat, tuple(lobe for lobe, _ in diffuse),
                       tuple(lobe for lobe, _ in node.leaves),
                       probabilities_src + "\n" + sample_src + "\n" + pdf_src,
                       _composition_albedo(value, lobe_width if spec is not None else broad_width))


def _composition_albedo(value, width):
    """A composition's directional albedo (RGB) by :func:`pbrkit.brdf.lobes.half_vector_albedo`
    of its whole value, with the half-vector nodes of its specular lobe's width (alpha 1
    without one).  For the tests and the explorer, not for the per-sample loops."""

    @dual_use(inline=True)
    def value4(b, c, ec, w):
        return value(b, c, ec)

    @dual_use(inline=True, cache=False)
    def albedo(b, nov):
        return half_vector_albedo(value4, width, b, nov)

    return albedo
