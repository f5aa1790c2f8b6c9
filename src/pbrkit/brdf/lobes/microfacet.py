"""Reflection from a microfacet distribution (Cook & Torrance 1982; Walter et al.
2007): f = D(h) V(l, v) F(v.h), V = G2 / (4 n.l n.v), with D, V and F the terms
of :mod:`pbrkit.brdf.terms` -- each fixed by the model, or chosen per material
by a code of the BxDF (a method :class:`~pbrkit.brdf.terms.Table`).

Roughness: the BxDF's alpha = max(r^2, 1e-3) (and its anisotropic alphas);
UE4's masking uses k = (r + 1)^2 / 8 of the perceptual r.  Sampled by GGX
visible normals of the same alphas (:data:`pbrkit.brdf.lobes.GGX_VISIBLE_NORMALS`);
the albedo estimate is Schlick's F at n.v with the lobe's f0 (the constant
colour for a constant F), luminance-weighted.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...core.color import rec709_luminance
from ...core.jit import dual_use
from ..terms import Distribution, Masking, Table, choose
from . import GGX_VISIBLE_NORMALS, Lobe, lobe_width, quadrature_albedo

__all__ = ["Microfacet", "microfacet", "always", "never"]


@dataclass(frozen=True, eq=False)
class Microfacet:
    """The pieces of a microfacet lobe, compiled: ``d(b, c)``, ``v(b, c)``, ``dv(b, c)``
    (D V, or the model's own combined term), ``fresnel(b, voh)`` (RGB),
    ``split_sum_f0(b)`` (RGB, the F0 of the real-time split sum), ``split_sum_f90(b)``
    (its F90, 1 unless the Fresnel term says), ``constant(b)``
    (whether F is the constant colour), and the term declarations themselves."""

    distribution: object
    masking: object
    fresnel_term: object
    d: object
    v: object
    dv: object
    fresnel: object
    split_sum_f0: object
    constant: object
    split_sum_f90: object = None

    def table_name(self, masking_name=None):
        """The DFG table whose visibility is this lobe's: its masking's, or for a
        chosen masking the one named ``masking_name``."""
        if isinstance(self.masking, Masking):
            return self.masking.table
        return self.masking[masking_name].table


def _fresnel_rgb(f):
    """F of the three channels, ``fresnel_rgb(b, voh)``, from ``f(b, f0, eta, k, s, voh)``
    of one: one compiled function."""

    @dual_use
    def fresnel_rgb(b, voh):
        return (f(b, b.f0[0], b.eta[0], b.k[0], b.specular_color[0], voh),
                f(b, b.f0[1], b.eta[1], b.k[1], b.specular_color[1], voh),
                f(b, b.f0[2], b.eta[2], b.k[2], b.specular_color[2], voh))

    return fresnel_rgb


def _chosen_distribution(table):
    """The distribution chosen by the BxDF's code: D and the Lambdas each one compiled
    function (called, not inlined at Numba's level, by every masking form that uses
    them: typing every distribution once, not once per use)."""
    return Distribution("chosen", choose(table, "d", ("c",), inline=False),
                        choose(table, "lambdas", ("c",), inline=False), True)


#: The microfacet lobes made so far, by their terms: one lobe (and one set of compiled
#: functions) per combination, shared by the models that use it.
_MADE = {}


def microfacet(distribution, masking, fresnel, dv=None, name="specular", role="specular"):
    """The microfacet :class:`~pbrkit.brdf.lobes.Lobe` of ``distribution``, ``masking``
    and ``fresnel`` (each a term of :mod:`pbrkit.brdf.terms` or a method table to
    choose from by the BxDF's code); ``dv(b, c)`` replaces D V in the value (a
    model's combined term, such as URP's), D and V still describing the lobe.

    Its pieces (D V, F, the albedo estimate, the split-sum F0) and every model's
    composed functions are compiled once each per process, as separate functions that
    every kernel shares (LLVM inlines them where they are called: D V always, as
    :func:`pbrkit.core.jit.jitable` with ``forceinline``, since a call per sample cost
    the punctual lights 5 %); the glue between them is inlined at Numba's level.  Inlining it all at Numba's level instead made
    every kernel type every model's whole composition again, which took about twice
    as long to compile."""
    key = (id(distribution), id(masking), id(fresnel), id(dv), name, role)
    if key not in _MADE:
        _MADE[key] = _microfacet(distribution, masking, fresnel, dv, name, role)
    return _MADE[key]


def _microfacet(distribution, masking, fresnel, dv, name, role):
    dist = _chosen_distribution(distribution) if isinstance(distribution, Table) else distribution
    d = dist.d
    if isinstance(masking, Table):
        v = choose(masking, "v", ("c",), wrap=lambda m: m.for_distribution(dist))
    else:
        v = masking.for_distribution(dist)
    if isinstance(fresnel, Table):  # each chosen per channel by one compiled function, called thrice
        fresnel_rgb = _fresnel_rgb(choose(fresnel, "f", ("f0", "eta", "k", "s", "voh"), inline=False))
        estimate = choose(fresnel, "estimate", ("f0", "s", "nov"), inline=False)
        f0_of = choose(fresnel, "split_sum_f0", ("f0", "eta", "k", "s"), inline=False)
        constant = choose(fresnel, "constant", (), wrap=lambda m: always if m.constant else never)
    else:
        estimate, f0_of = fresnel.estimate, fresnel.split_sum_f0
        fresnel_rgb = _fresnel_rgb(fresnel.f)
        constant = always if fresnel.constant else never

    if dv is None:
        @dual_use(inline="llvm")
        def dv(b, c):
            return d(b, c) * v(b, c)

    @dual_use
    def split_sum_f0(b):
        return (f0_of(b, b.f0[0], b.eta[0], b.k[0], b.specular_color[0]),
                f0_of(b, b.f0[1], b.eta[1], b.k[1], b.specular_color[1]),
                f0_of(b, b.f0[2], b.eta[2], b.k[2], b.specular_color[2]))

    @dual_use(inline=True)
    def value(b, c, ec, w):
        spec = dv(b, c)
        f0, f1, f2 = fresnel_rgb(b, c.voh)
        return f0 * ((spec * ec[0]) * w), f1 * ((spec * ec[1]) * w), f2 * ((spec * ec[2]) * w)

    @dual_use
    def lobe_estimate(b, nov):
        return rec709_luminance(estimate(b, b.f0[0], b.specular_color[0], nov),
                                estimate(b, b.f0[1], b.specular_color[1], nov),
                                estimate(b, b.f0[2], b.specular_color[2], nov))

    f90_of = None if isinstance(fresnel, Table) else fresnel.split_sum_f90
    split_sum_f90 = _one if f90_of is None else f90_of
    parts = Microfacet(distribution, masking, fresnel, d, v, dv, fresnel_rgb, split_sum_f0, constant, split_sum_f90)
    return Lobe(name, value, GGX_VISIBLE_NORMALS, role, lobe_estimate,
                quadrature_albedo(value, lobe_width), parts)


@dual_use(inline=True)
def _one(b):
    return 1.0


@dual_use(inline=True)
def always(b):
    """True whatever the BxDF (a flag of a fixed term)."""
    return True


@dual_use(inline=True)
def never(b):
    """False whatever the BxDF."""
    return False
