"""What every Smith microfacet distribution shares: masking G1 from Lambda, the
two masking-shadowing forms G2, and the visibility V = G2 / (4 n.l n.v).

Smith's model (Smith 1967) as derived in Heitz 2014, "Understanding the
Masking-Shadowing Function in Microfacet-Based BRDFs", JCGT 3(2) (cited below
as Heitz 2014): a distribution's masking is fixed by its Lambda function (the
Lambda of GGX in :mod:`pbrkit.microfacet.ggx`, of Beckmann in
:mod:`pbrkit.microfacet.beckmann`), and G1 = 1 / (1 + Lambda) (:func:`g1_smith`).
Arguments are cosines with the normal (``nov = n.v``, ``nol = n.l``) or the
Lambda values themselves; no roughness enters here (the Lambda functions take
the distribution's alpha, not perceptual roughness; see
:mod:`pbrkit.microfacet.roughness`).

Direction cosines at or below zero give G = 0 (back-facing directions are
masked); cosines are clamped to :data:`COS_MIN` internally so no NaN or Inf
appears.
"""

from __future__ import annotations

import math

import numpy as np
from numba import types
from numba.extending import overload

from ..core.jit import dual_use, select

__all__ = [
    "COS_MIN",
    "erf",
    "g1_smith",
    "visible_normal_pdf",
    "g2_separable",
    "g2_height_correlated",
    "visibility",
]

#: Cosines are clamped to at least this value inside the masking terms.
COS_MIN = 1e-8


def erf(x):
    """Error function: elementwise on arrays from Python (SciPy's ``scipy.special.erf``,
    imported on first use), ``math.erf`` on scalars inside Numba kernels (the
    overload below).  Not a Numba ufunc: building one at import cost every
    command about 0.3 s."""
    from scipy.special import erf as _erf

    return _erf(x)


@overload(erf)
def _erf_numba(x):
    if isinstance(x, types.Float):
        return lambda x: math.erf(x)
    return None


@dual_use
def _tan2(cos_theta):
    """tan^2 theta from cos theta, the cosine clamped to [COS_MIN, 1] (the argument
    of every isotropic Lambda)."""
    c = np.minimum(np.maximum(cos_theta, COS_MIN), 1.0)
    c2 = c * c
    return (1.0 - c2) / c2


@dual_use
def g1_smith(lambda_v):
    """Smith masking G1 = 1 / (1 + Lambda) (Heitz 2014, eq. 43)."""
    return 1.0 / (1.0 + lambda_v)


@dual_use
def visible_normal_pdf(lambda_v, voh, d, cos_v):
    """The distribution of visible normals D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z
    (Heitz & d'Eon 2014; Heitz 2014, eq. 16; Heitz 2018, eq. 3), the pdf of a
    visible-normal sampler w.r.t. the solid angle of h, from the Smith Lambda(wo)
    of the distribution, wo.h, D(h) and wo.z (clamped at :data:`COS_MIN`, the clamp
    Lambda uses, so a grazing view gives the finite limit)."""
    return g1_smith(lambda_v) * np.maximum(voh, 0.0) * d / np.maximum(cos_v, COS_MIN)


@dual_use
def g2_separable(lambda_l, lambda_v):
    """Separable masking-shadowing G2 = G1(l) G1(v) (Heitz 2014, eq. 98)."""
    return g1_smith(lambda_l) * g1_smith(lambda_v)


@dual_use
def g2_height_correlated(lambda_l, lambda_v):
    """Height-correlated masking-shadowing G2 = 1 / (1 + Lambda(l) + Lambda(v)) (Heitz 2014, eq. 99)."""
    return 1.0 / (1.0 + lambda_l + lambda_v)


@dual_use
def visibility(g2, nol, nov):
    """V = G2 / (4 n.l n.v), the form real-time models use (Karis 2013; Filament sec. 4.4.2)."""
    denominator = 4.0 * np.maximum(nol, COS_MIN) * np.maximum(nov, COS_MIN)
    return select((nol > 0.0) & (nov > 0.0), g2 / denominator, 0.0)
