"""Diffuse lobes: f = diffuse_color * factor, the factor one of
:mod:`pbrkit.brdf.diffuse` (Lambert's 1 / pi, Burley's retro-reflective factor
of the perceptual roughness r), and cook_torrance's choice among them by the
BxDF's ``diffuse`` code (:data:`DIFFUSE_TABLE`, with OpenPBR's energy-preserving
Oren-Nayar of :mod:`.eon`).

All are sampled by cosine-weighted directions; the albedo estimate is the
luminance of the non-metallic base colour, luminance(base) (1 - metallic).
"""

from __future__ import annotations

from ...core.jit import dual_use
from ..diffuse import burley, lambert
from ..terms import Table, choose
from . import COSINE, Lobe, diffuse_estimate, quadrature_albedo
from .eon import EON

__all__ = ["LAMBERT", "BURLEY", "NO_DIFFUSE", "DIFFUSE_TABLE", "DIFFUSES", "diffuse_choice"]


@dual_use(inline=True)
def _lambert_value(b, c, ec, w):
    k = lambert(c.nol) * w
    return b.diffuse_color[0] * k, b.diffuse_color[1] * k, b.diffuse_color[2] * k


@dual_use(inline=True)
def _lambert_albedo(b, nov):
    # the integral of cos / pi over the hemisphere is 1
    return b.diffuse_color


@dual_use(inline=True)
def _burley_value(b, c, ec, w):
    k = burley(c.nol, c.nov, c.voh, b.roughness) * w
    return b.diffuse_color[0] * k, b.diffuse_color[1] * k, b.diffuse_color[2] * k


@dual_use(inline=True)
def _zero_value(b, c, ec, w):
    return 0.0, 0.0, 0.0


@dual_use(inline=True)
def _zero_estimate(b, nov):
    return 0.0


@dual_use(inline=True)
def _zero_albedo(b, nov):
    return 0.0, 0.0, 0.0


#: Lambert 1760: diffuse_color / pi.
LAMBERT = Lobe("lambert", _lambert_value, COSINE, "diffuse", diffuse_estimate, _lambert_albedo)
#: Burley 2012, sec. 5.3: diffuse_color times :func:`pbrkit.brdf.diffuse.burley`.
BURLEY = Lobe("burley", _burley_value, COSINE, "diffuse", diffuse_estimate,
              quadrature_albedo(_burley_value))
#: No diffuse lobe (cook_torrance's and filament's ``diffuse = "none"``): its technique
#: stays in the mixture with a zero estimate, so it is never drawn.
NO_DIFFUSE = Lobe("none", _zero_value, COSINE, "diffuse", _zero_estimate, _zero_albedo)

#: The diffuse lobes a material chooses by name, in code order.
DIFFUSE_TABLE = Table("diffuse", (LAMBERT, BURLEY, NO_DIFFUSE, EON))
DIFFUSES = DIFFUSE_TABLE.names


def diffuse_choice(names=DIFFUSES):
    """The diffuse lobe chosen by the BxDF's ``diffuse`` code among :data:`DIFFUSE_TABLE`
    (``names`` are the model's choices, for its declaration; the code indexes the
    whole table)."""
    names = tuple(names)
    return Lobe("diffuse", choose(DIFFUSE_TABLE, "value", ("c", "ec", "w"), names=names, inline=False), COSINE,
                "diffuse",
                choose(DIFFUSE_TABLE, "estimate", ("nov",), names=names),
                choose(DIFFUSE_TABLE, "albedo", ("nov",), names=names))
