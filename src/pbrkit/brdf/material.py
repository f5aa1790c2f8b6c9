"""The metallic-roughness material shared by every model.

Parameters follow glTF 2.0 / Filament / UE4 (Burley 2012's "principled"
parameterisation):

- ``base_color``: linear RGB (Rec.709 primaries), shape (..., 3), in [0, 1].
- ``metallic``: in [0, 1].
- ``roughness``: *perceptual* roughness r in [0, 1]; models use alpha = r^2,
  clamped at :data:`pbrkit.microfacet.roughness.ALPHA_MIN` (so r = 0 is a mirror-like
  but finite lobe, never NaN).
- ``reflectance``: dielectric specular in [0, 1], f0 = 0.16 reflectance^2
  (Filament); 0.5 gives f0 = 0.04.  UE4's ``Specular`` s maps to
  f0 = 0.08 s: use :meth:`Material.from_ue4`.
- ``anisotropy``: in [-1, 1], alpha_t = alpha (1 + a), alpha_b = alpha (1 - a)
  (Kulla & Conty 2017; Filament).  Needs a tangent where used.
- ``eta``, ``k``: optional complex index of refraction (RGB) for the exact
  conductor Fresnel of :func:`pbrkit.brdf.models.cook_torrance`.
- Disney principled extras (Burley 2012), used by :func:`pbrkit.brdf.models.disney`
  only, all in [0, 1]: ``subsurface``, ``specular_tint``, ``sheen``,
  ``sheen_tint`` (default 0.5), ``clearcoat``, ``clearcoat_gloss`` (default 1).

Values outside their ranges, non-finite values or a base colour without three
channels raise ``ValueError`` naming the parameter; nothing is clamped
silently except alpha's documented minimum.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..microfacet.roughness import alpha_from_roughness
from .fresnel import CONDUCTORS, f0_from_reflectance

__all__ = ["Material"]


def _checked(name, value, lo, hi, rgb=False):
    array = np.asarray(value, dtype=float)
    if rgb and (array.ndim == 0 or array.shape[-1] != 3):
        raise ValueError(f"Material.{name} must have 3 channels (RGB) in its last axis; got shape {array.shape}")
    bad = ~np.isfinite(array)
    if np.any(bad):
        raise ValueError(f"Material.{name} has {int(bad.sum())} non-finite value(s)")
    out = (array < lo) | (array > hi)
    if np.any(out):
        raise ValueError(
            f"Material.{name} must be in [{lo}, {hi}]; {int(out.sum())} value(s) outside, "
            f"e.g. {array[out].flat[0]!r}"
        )
    return array


@dataclass(frozen=True)
class Material:
    """Metallic-roughness material; every field broadcasts against the directions' leading shape."""

    base_color: np.ndarray = field(default_factory=lambda: np.array([0.8, 0.8, 0.8]))
    metallic: np.ndarray = 0.0
    roughness: np.ndarray = 0.5
    reflectance: np.ndarray = 0.5
    anisotropy: np.ndarray = 0.0
    eta: np.ndarray | None = None
    k: np.ndarray | None = None
    subsurface: np.ndarray = 0.0
    specular_tint: np.ndarray = 0.0
    sheen: np.ndarray = 0.0
    sheen_tint: np.ndarray = 0.5
    clearcoat: np.ndarray = 0.0
    clearcoat_gloss: np.ndarray = 1.0

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "base_color", _checked("base_color", self.base_color, 0.0, 1.0, rgb=True))
        set_(self, "metallic", _checked("metallic", self.metallic, 0.0, 1.0))
        set_(self, "roughness", _checked("roughness", self.roughness, 0.0, 1.0))
        set_(self, "reflectance", _checked("reflectance", self.reflectance, 0.0, 1.0))
        set_(self, "anisotropy", _checked("anisotropy", self.anisotropy, -1.0, 1.0))
        for name in ("subsurface", "specular_tint", "sheen", "sheen_tint", "clearcoat", "clearcoat_gloss"):
            set_(self, name, _checked(name, getattr(self, name), 0.0, 1.0))
        if (self.eta is None) != (self.k is None):
            raise ValueError("Material.eta and Material.k must be given together")
        if self.eta is not None:
            set_(self, "eta", _checked("eta", self.eta, 1e-6, 1e3, rgb=True))
            set_(self, "k", _checked("k", self.k, 0.0, 1e3, rgb=True))

    @classmethod
    def conductor(cls, name, roughness=0.5, **kwargs):
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
        return cls(base_color=f0_conductor(eta, k), metallic=1.0,
                   roughness=roughness, eta=eta, k=k, **kwargs)

    @classmethod
    def from_ue4(cls, base_color, metallic=0.0, roughness=0.5, specular=0.5, **kwargs):
        """UE4 parameters: dielectric f0 = 0.08 specular (Karis 2013), mapped to reflectance."""
        specular = _checked("specular", specular, 0.0, 1.0)
        return cls(base_color=base_color, metallic=metallic, roughness=roughness,
                   reflectance=np.sqrt(0.5 * specular), **kwargs)

    @property
    def alpha(self):
        """alpha = max(r^2, ALPHA_MIN)."""
        return alpha_from_roughness(self.roughness)

    @property
    def dielectric_f0(self):
        """f0 of the non-metallic part, 0.16 reflectance^2."""
        return f0_from_reflectance(self.reflectance)
