"""The named terms of a microfacet lobe, as method tables with one dispatcher
each (the layout of colour-science's ``method=`` tables): the normal
distribution D (with its Smith Lambdas), the masking-shadowing form of the
visibility V = G2 / (4 n.l n.v), and the Fresnel factor F.

Each method is one published formula (its function's docstring cites it and
states its roughness remap); a table lists the methods in the order of their
codes, the integers a material's code row stores (``cook_torrance`` chooses
each term by name, :data:`DISTRIBUTIONS`, :data:`MASKINGS`, :data:`FRESNELS`).
:func:`choose` makes one compiled function of a table that picks the method by
a code field of the :class:`pbrkit.brdf.bxdf.BxDF`; a model with fixed terms
uses the methods themselves, so its compiled code has no branch on them.

Compiled signatures (``b`` a BxDF, ``c`` its :class:`pbrkit.brdf.bxdf.Cosines`):
D ``d(b, c)`` and ``lambdas(b, c) -> (Lambda(l), Lambda(v))`` (anisotropic when
``b.anisotropic``); V ``v(b, c)`` (a Smith form made for a distribution's
Lambdas by :meth:`Masking.for_distribution`); F ``f(b, f0, eta, k, s, voh)`` of
one channel (the metallic-workflow f0, the complex IOR, the constant colour s),
with ``estimate(b, f0, s, nov)`` (what the lobe's albedo estimate for sampling
uses) and ``split_sum_f0(b, f0, eta, k, s)`` (the F0 a real-time shader feeds
the split-sum table).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..core.codegen import generate, if_chain
from ..core.jit import dual_use
from ..microfacet.beckmann import d_beckmann, d_beckmann_anisotropic, lambda_beckmann, lambda_beckmann_anisotropic
from ..microfacet.blinn_phong import d_blinn_phong, phong_exponent_from_beckmann_alpha
from ..microfacet.ggx import d_ggx, d_ggx_anisotropic, lambda_ggx, lambda_ggx_anisotropic, v_smith_ggx_height_correlated
from ..microfacet.smith import g2_height_correlated, g2_separable, visibility
from .fresnel import f0_conductor, f_conductor, f_schlick, f_schlick_pow4, f_schlick_ue4_sg, ior_from_f0
from .masking import g2_kelemen, g2_schlick_ggx, k_schlick_from_alpha, k_ue4_direct

__all__ = [
    "Distribution",
    "Masking",
    "Fresnel",
    "Table",
    "choose",
    "GGX",
    "BECKMANN",
    "BLINN_PHONG",
    "DISTRIBUTION_TABLE",
    "MASKING_TABLE",
    "FRESNEL_TABLE",
    "DISTRIBUTIONS",
    "MASKINGS",
    "FRESNELS",
    "HEIGHT_CORRELATED",
    "SEPARABLE",
    "SCHLICK_GGX",
    "SCHLICK_GGX_UE4",
    "HEIGHT_CORRELATED_DIVISION_FREE",
    "SCHLICK",
    "SCHLICK_F90",
    "SCHLICK_SPECULAR",
    "SCHLICK_POW4",
    "UE4_SG",
    "EXACT_CONDUCTOR",
    "EXACT_DIELECTRIC",
    "CONSTANT",
    "CONSTANT_F0",
]


@dataclass(frozen=True)
class Distribution:
    """A microfacet distribution for a lobe: D and Smith's Lambdas of the BxDF's
    alphas; ``anisotropic``: whether it has an anisotropic form (the BxDF's setup
    makes the lobe isotropic otherwise)."""

    name: str
    d: object
    lambdas: object
    anisotropic: bool
    table: str = "height-correlated"


@dataclass(frozen=True)
class Masking:
    """A masking-shadowing form of V: ``smith`` forms (``g2`` of the distribution's
    Lambdas) are made per distribution (:meth:`for_distribution`); the others are
    one function ``v``.  ``table``: the DFG table whose visibility matches (the one
    the real-time split sum multiplies the prefiltered light by)."""

    name: str
    table: str
    g2: object = None
    v: object = None

    def for_distribution(self, distribution):
        if self.g2 is None:
            return self.v
        g2 = self.g2
        lambdas = distribution.lambdas

        @dual_use(inline=True)
        def smith_v(b, c):
            lam_l, lam_v = lambdas(b, c)
            return visibility(g2(lam_l, lam_v), c.nol, c.nov)

        return smith_v


@dataclass(frozen=True)
class Fresnel:
    """A Fresnel factor of one channel; ``constant``: F does not depend on v.h (the
    split sum then uses s DFG2 instead of DFG1 + F0 (DFG2 - DFG1));
    ``split_sum_f90(b)``: the F90 of the split sum, F90 DFG1 + F0 (DFG2 - DFG1)
    (None: 1)."""

    name: str
    f: object
    estimate: object
    split_sum_f0: object
    constant: bool = False
    split_sum_f90: object = None


@dataclass(frozen=True)
class Table:
    """Methods in code order, and the BxDF field holding the code."""

    field: str
    methods: tuple
    names: tuple = field(init=False)

    def __post_init__(self):
        object.__setattr__(self, "names", tuple(m.name for m in self.methods))

    def __getitem__(self, name):
        return self.methods[self.names.index(name)]


def choose(table, attribute, arguments, inline=True, wrap=None, names=None):
    """One compiled function ``(b, *arguments)`` that calls the method of ``table``
    chosen by ``b.<table.field>`` (its ``attribute``, or ``wrap(method)`` when given),
    among ``names`` (default: all; a code outside them takes the last).  Generated:
    ``if b.field == 0: return m0(b, ...) ...``."""
    codes = [table.names.index(n) for n in (table.names if names is None else names)]
    fns = [wrap(table.methods[i]) if wrap is not None else getattr(table.methods[i], attribute) for i in codes]
    args = ", ".join(("b",) + tuple(arguments))
    name = f"choose_{table.field}_{attribute}"
    lines = [f"def {name}({args}):"] + if_chain(f"b.{table.field}", [f"m{i}({args})" for i in range(len(fns))],
                                                 values=codes)
    return generate("\n".join(lines) + "\n", name, {f"m{i}": fn for i, fn in enumerate(fns)}, inline=inline)


# ---------------------------------------------------------------- distributions


@dual_use(inline=True)
def _d_ggx(b, c):
    if b.anisotropic:
        return d_ggx_anisotropic(c.noh, c.toh, c.boh, b.alpha_x, b.alpha_y)
    return d_ggx(c.noh, b.alpha)


@dual_use(inline=True)
def _lambdas_ggx(b, c):
    if b.anisotropic:
        return (lambda_ggx_anisotropic(c.nol, c.tol, c.bol, b.alpha_x, b.alpha_y),
                lambda_ggx_anisotropic(c.nov, c.tov, c.bov, b.alpha_x, b.alpha_y))
    return lambda_ggx(c.nol, b.alpha), lambda_ggx(c.nov, b.alpha)


@dual_use(inline=True)
def _d_beckmann(b, c):
    if b.anisotropic:
        return d_beckmann_anisotropic(c.noh, c.toh, c.boh, b.alpha_x, b.alpha_y)
    return d_beckmann(c.noh, b.alpha)


@dual_use(inline=True)
def _lambdas_beckmann(b, c):
    if b.anisotropic:
        return (lambda_beckmann_anisotropic(c.nol, c.tol, c.bol, b.alpha_x, b.alpha_y),
                lambda_beckmann_anisotropic(c.nov, c.tov, c.bov, b.alpha_x, b.alpha_y))
    return lambda_beckmann(c.nol, b.alpha), lambda_beckmann(c.nov, b.alpha)


@dual_use(inline=True)
def _d_blinn_phong(b, c):
    # exponent 2 / alpha^2 - 2 from the Beckmann alpha (Walter et al. 2007, eq. 30); isotropic
    return d_blinn_phong(c.noh, phong_exponent_from_beckmann_alpha(b.alpha))


@dual_use(inline=True)
def _lambdas_blinn_phong(b, c):
    # Smith's Lambda of the Beckmann distribution of the same alpha (Walter et al. 2007, eq. 30)
    return lambda_beckmann(c.nol, b.alpha), lambda_beckmann(c.nov, b.alpha)


GGX = Distribution("ggx", _d_ggx, _lambdas_ggx, True)
BECKMANN = Distribution("beckmann", _d_beckmann, _lambdas_beckmann, True)
BLINN_PHONG = Distribution("blinn-phong", _d_blinn_phong, _lambdas_blinn_phong, False)
DISTRIBUTION_TABLE = Table("distribution", (GGX, BECKMANN, BLINN_PHONG))

# --------------------------------------------------------------------- masking


@dual_use(inline=True)
def _v_schlick_ggx(b, c):
    return visibility(g2_schlick_ggx(c.nol, c.nov, k_schlick_from_alpha(b.alpha)), c.nol, c.nov)


@dual_use(inline=True)
def _v_schlick_ggx_ue4(b, c):
    return visibility(g2_schlick_ggx(c.nol, c.nov, k_ue4_direct(b.roughness)), c.nol, c.nov)


@dual_use(inline=True)
def _v_kelemen(b, c):
    return visibility(g2_kelemen(c.nol, c.nov, c.voh), c.nol, c.nov)


@dual_use(inline=True)
def _v_implicit(b, c):
    return visibility(max(c.nol, 0.0) * max(c.nov, 0.0), c.nol, c.nov)


@dual_use(inline=True)
def _v_height_correlated_division_free(b, c):
    if b.anisotropic:
        return visibility(g2_height_correlated(lambda_ggx_anisotropic(c.nol, c.tol, c.bol, b.alpha_x, b.alpha_y),
                                               lambda_ggx_anisotropic(c.nov, c.tov, c.bov, b.alpha_x, b.alpha_y)),
                          c.nol, c.nov)
    return v_smith_ggx_height_correlated(c.nol, c.nov, b.alpha)


HEIGHT_CORRELATED = Masking("height-correlated", "height-correlated", g2=g2_height_correlated)
SEPARABLE = Masking("separable", "separable", g2=g2_separable)
SCHLICK_GGX = Masking("schlick-ggx", "schlick-ggx", v=_v_schlick_ggx)
SCHLICK_GGX_UE4 = Masking("schlick-ggx-ue4", "schlick-ggx", v=_v_schlick_ggx_ue4)
KELEMEN = Masking("kelemen", "height-correlated", v=_v_kelemen)
IMPLICIT = Masking("implicit", "height-correlated", v=_v_implicit)
#: Filament's GGX visibility: the height-correlated Smith V in Lagarde & de Rousiers'
#: division-free form when isotropic, the exact anisotropic one otherwise.
HEIGHT_CORRELATED_DIVISION_FREE = Masking("height-correlated", "height-correlated",
                                          v=_v_height_correlated_division_free)
MASKING_TABLE = Table("masking", (HEIGHT_CORRELATED, SEPARABLE, SCHLICK_GGX, SCHLICK_GGX_UE4, KELEMEN, IMPLICIT))

# ---------------------------------------------------------------------- Fresnel


@dual_use(inline=True)
def _schlick_estimate(b, f0, s, nov):
    return f_schlick(nov, f0, 1.0)


@dual_use(inline=True)
def _constant_estimate(b, f0, s, nov):
    return s


@dual_use(inline=True)
def _f0_of_workflow(b, f0, eta, k, s):
    return f0


@dual_use(inline=True)
def _f_schlick(b, f0, eta, k, s, voh):
    return f_schlick(voh, f0, 1.0)


@dual_use(inline=True)
def _f_schlick_f90(b, f0, eta, k, s, voh):
    return f_schlick(voh, f0, b.f90)


@dual_use(inline=True)
def _f_schlick_pow4(b, f0, eta, k, s, voh):
    return f_schlick_pow4(voh, f0, 1.0)


@dual_use(inline=True)
def _f_ue4_sg(b, f0, eta, k, s, voh):
    return f_schlick_ue4_sg(voh, f0)


@dual_use(inline=True)
def _f_exact_conductor(b, f0, eta, k, s, voh):
    return f_conductor(voh, eta, k)


@dual_use(inline=True)
def _f0_exact_conductor(b, f0, eta, k, s):
    return f0_conductor(eta, k)


@dual_use(inline=True)
def _f_exact_dielectric(b, f0, eta, k, s, voh):
    return f_conductor(voh, ior_from_f0(b.dielectric_f0), 0.0)


@dual_use(inline=True)
def _f0_exact_dielectric(b, f0, eta, k, s):
    return b.dielectric_f0


@dual_use(inline=True)
def _f_constant(b, f0, eta, k, s, voh):
    return s


@dual_use(inline=True)
def _f0_constant(b, f0, eta, k, s):
    return s


@dual_use(inline=True)
def _f_constant_f0(b, f0, eta, k, s, voh):
    return f0


SCHLICK = Fresnel("schlick", _f_schlick, _schlick_estimate, _f0_of_workflow)
SCHLICK_POW4 = Fresnel("schlick-pow4", _f_schlick_pow4, _schlick_estimate, _f0_of_workflow)
UE4_SG = Fresnel("ue4-sg", _f_ue4_sg, _schlick_estimate, _f0_of_workflow)
EXACT_CONDUCTOR = Fresnel("exact-conductor", _f_exact_conductor, _schlick_estimate, _f0_exact_conductor)
EXACT_DIELECTRIC = Fresnel("exact-dielectric", _f_exact_dielectric, _schlick_estimate, _f0_exact_dielectric)
#: F = the constant colour s (``fresnel = "none"``: no Fresnel effect, s = 1 by default).
CONSTANT = Fresnel("none", _f_constant, _constant_estimate, _f0_constant, constant=True)
FRESNEL_TABLE = Table("fresnel", (SCHLICK, SCHLICK_POW4, UE4_SG, EXACT_CONDUCTOR, EXACT_DIELECTRIC, CONSTANT))
#: Filament's Schlick with its f90 (the BxDF's ``f90``, specular occlusion of f0 below 2 %).
SCHLICK_F90 = Fresnel("schlick", _f_schlick_f90, _schlick_estimate, _f0_of_workflow)
@dual_use(inline=True)
def _schlick_f90_estimate(b, f0, s, nov):
    return f_schlick(nov, f0, b.f90)


@dual_use(inline=True)
def _f90_of_bxdf(b):
    return b.f90


#: Schlick's F with the BxDF's f90 in the value, the sampling estimate and the split
#: sum: glTF's KHR_materials_specular, whose F90 mix(specular, 1, metallic) is below 1
#: when the specular factor is (its README, "Implementation": dielectric_f90 = specular).
SCHLICK_SPECULAR = Fresnel("schlick", _f_schlick_f90, _schlick_f90_estimate, _f0_of_workflow,
                           split_sum_f90=_f90_of_bxdf)
#: Unity URP's specular colour lerp(0.04, base, metallic) as F, no angular dependence
#: (its albedo estimate for sampling is Schlick's at n.v, as for the others).
CONSTANT_F0 = Fresnel("schlick", _f_constant_f0, _schlick_estimate, _f0_of_workflow)

#: Term names in code order (the scene files' and the NumPy API's choices).
DISTRIBUTIONS = DISTRIBUTION_TABLE.names
MASKINGS = MASKING_TABLE.names
FRESNELS = FRESNEL_TABLE.names
