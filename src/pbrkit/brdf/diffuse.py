"""Diffuse lobes and the weights that combine them with specular lobes.

Diffuse BRDFs return the factor that multiplies the diffuse colour, so
f_diffuse = diffuse_color * factor (the factor is 1 / pi for Lambert).
"""

from __future__ import annotations

import numpy as np

from ..core.jit import dual_use, select
from .fresnel import f_schlick, f_schlick_roughness

__all__ = ["lambert", "burley", "burley_subsurface", "kd_ibl"]

_INV_PI = 1.0 / np.pi


@dual_use
def lambert(nol):
    """Lambert's diffuse factor: 1 / pi for n.l > 0, else 0 (Lambert 1760)."""
    return select(nol > 0.0, _INV_PI, 0.0)


@dual_use
def burley(nol, nov, loh, roughness):
    """Disney / Burley diffuse factor (Burley 2012, sec. 5.3, eq. 3).

    f = (1 / pi) (1 + (F_D90 - 1)(1 - n.l)^5)(1 + (F_D90 - 1)(1 - n.v)^5) with
    F_D90 = 0.5 + 2 r cos^2 theta_d, theta_d the angle between l and h
    (cos theta_d = l.h), r perceptual roughness.  The (1 - cos)^5 terms are
    Schlick's (:func:`pbrkit.brdf.fresnel.f_schlick` with f0 = 1, f90 = F_D90).
    """
    fd90 = 0.5 + 2.0 * roughness * loh * loh
    return _INV_PI * f_schlick(nol, 1.0, fd90) * f_schlick(nov, 1.0, fd90)


@dual_use
def burley_subsurface(nol, nov, loh, roughness):
    """Disney's subsurface approximation factor (Burley 2012, sec. 5.3 and the BRDF
    Explorer's ``disney.brdf``), after Hanrahan & Krueger 1993:
    f = (1.25 / pi) (F_ss (1 / (n.l + n.v) - 0.5) + 0.5) with
    F_ss = (1 + (F_ss90 - 1)(1 - n.l)^5)(1 + (F_ss90 - 1)(1 - n.v)^5),
    F_ss90 = r (l.h)^2, r perceptual roughness.  Zero below the horizon.
    """
    fss90 = roughness * loh * loh
    fss = f_schlick(nol, 1.0, fss90) * f_schlick(nov, 1.0, fss90)
    cl = np.maximum(nol, 0.0)
    cv = np.maximum(nov, 0.0)
    value = 1.25 * _INV_PI * (fss * (1.0 / np.maximum(cl + cv, 1e-8) - 0.5) + 0.5)
    return select((nol > 0.0) & (nov > 0.0), value, 0.0)


@dual_use
def kd_ibl(nov, f0, roughness, metallic):
    """Diffuse weight for image-based lighting k_d = (1 - F*)(1 - metallic).

    F* is the roughness-aware Fresnel of :func:`pbrkit.brdf.fresnel.f_schlick_roughness`
    (seed 000; Lagarde 2011).  r is perceptual roughness.
    """
    return (1.0 - f_schlick_roughness(nov, f0, roughness)) * (1.0 - metallic)
