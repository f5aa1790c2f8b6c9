"""The sheen lookup tables of ``KHR_materials_sheen`` image-based lighting, in the
layout of the split-sum tables (``CONVENTIONS.md``: an (N, N, C) float32 array
indexed [j, i, c], column i at n.v = (i + 0.5) / N, row j at sheen roughness
r = (j + 0.5) / N, row 0 smooth):

- the Charlie DFG value, what the Khronos glTF IBL Sampler writes as ``lut_charlie``
  (its ``LUT`` for the ``charlie`` distribution, blue channel) and the Sample Viewer
  multiplies the Charlie-prefiltered radiance by (``getIBLRadianceCharlie``:
  ``texture(u_CharlieLUT, vec2(NdotV, sheenRoughness)).b``): the directional albedo
  of the white sheen BRDF, integral of D_C V (n.l) dl over the upper hemisphere,
  with no Fresnel;
- E_sheen, the same albedo with the specification's visibility, what the Sample
  Viewer's ``lut_sheen_E`` holds and its albedo scaling reads
  (``albedoSheenScalingLUT``: ``texture(u_SheenELUT, vec2(NdotV,
  sheenRoughness)).r``; KHR_materials_sheen, "Albedo-scaling technique").

Both are :func:`pbrkit.albedo.tables.sheen_albedo`, the half-vector quadrature of
the lookup tables for the Charlie lobe (D cancels against the Charlie CDF map),
with KHR_materials_sheen's visibility (:func:`pbrkit.microfacet.charlie.v_charlie`)
or the Ashikhmin-Premoze one that the IBL Sampler's ``lut_charlie`` uses
(``V_Ashikhmin``; Filament's cloth term); alpha = sheenRoughness^2.  With
:data:`SHEEN_NODES` it agrees with :func:`pbrkit.brdf.lobes.sheen.sheen_albedo`
(the converged quadrature behind the bundled 33 x 33 E table) to 7e-5.
The bake's Charlie DFG uses the
specification's visibility by default, so that the image-based sheen has the
albedo that the albedo scaling removes from the base (see :data:`VISIBILITIES`);
the IBL Sampler's table is available as ``visibility="ashikhmin"``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core import checks
from ..core.cache import memoised_array

__all__ = ["VISIBILITIES", "SHEEN_NODES", "SheenTableSpec", "sheen_albedo_texels", "sheen_lut", "charlie_lut",
           "sheen_e_lut"]

#: The visibility of the Charlie DFG table -> what it is.
VISIBILITIES = {
    "sheen": "KHR_materials_sheen's sheen visibility G2 / (4 n.l n.v), G2 of Estevez and Kulla's fitted "
             "Lambda (pbrkit.microfacet.charlie.v_charlie)",
    "ashikhmin": "Ashikhmin-Premoze 1 / (4 (n.l + n.v - n.l n.v)) (pbrkit.microfacet.charlie.v_ashikhmin), "
                 "as the Khronos glTF IBL Sampler's lut_charlie (V_Ashikhmin)",
}
#: Gauss-Legendre nodes of the tables (theta per segment, theta in the grazing columns, phi):
#: within 7e-5 of :func:`pbrkit.brdf.lobes.sheen.sheen_albedo`'s converged quadrature
#: (1e-4) on a 32 x 32 grid, at a twentieth of its cost.
SHEEN_NODES = (16, 32, 8)
_AXES = {"column i": "n.v = (i + 0.5) / N",
         "row j": "sheen roughness r = (j + 0.5) / N (row 0 = smooth)"}


def _texel_centres(n):
    return (np.arange(n) + 0.5) / n


def sheen_albedo_texels(size, visibility="sheen", cache=True):
    """The (size, size) float32 directional albedo of the white sheen BRDF D_C V at the
    texel centres (rows sheen roughness, columns n.v; module doc), by
    :func:`pbrkit.albedo.tables.sheen_albedo` (the half-vector quadrature of the
    lookup tables, :data:`SHEEN_NODES`), memoised on disk
    (:func:`pbrkit.core.cache.memoised_array`) unless ``cache`` is false.
    ``visibility``: ``"sheen"`` (KHR_materials_sheen's,
    :func:`pbrkit.microfacet.charlie.v_charlie`) or ``"ashikhmin"``
    (:func:`pbrkit.microfacet.charlie.v_ashikhmin`, the IBL Sampler's); alpha =
    sheenRoughness^2 in both (Estevez and Kulla 2017)."""
    size = checks.integer(size, "table size", 2, 4096)
    if visibility not in VISIBILITIES:
        raise ValueError(f"unknown sheen visibility {visibility!r}; use one of {', '.join(VISIBILITIES)}")
    axis = _texel_centres(size)

    def compute():
        from .tables import sheen_albedo

        kind = "sheen" if visibility == "sheen" else "neubelt"
        return sheen_albedo(axis, axis, SHEEN_NODES, kind).astype(np.float32)

    def check(table):
        return table.dtype == np.float32 and table.shape == (size, size) and bool(np.isfinite(table).all())

    return memoised_array("sheen_albedo_texels", {"size": size, "visibility": visibility}, compute, check,
                          enabled=cache)


_CHANNELS = {"sheen": ["E_sheen", "E_ashikhmin"], "charlie": ["0", "0", "DFG_charlie"], "sheen_e": ["E_sheen", "0"]}
_MEANING = {
    "sheen": "the directional albedo of the white sheen BRDF D_Charlie V (no Fresnel) with KHR_materials_sheen's "
             "visibility (E_sheen: the factor of the Charlie-prefiltered radiance and the E of the albedo scaling "
             "1 - max3(sheenColor) E), then with the Ashikhmin-Premoze visibility (the Khronos glTF IBL Sampler's "
             "lut_charlie)",
    "charlie": "the directional albedo of the white sheen BRDF D_Charlie V (no Fresnel): the factor of the "
               "Charlie-prefiltered radiance (Khronos glTF IBL Sampler lut_charlie; the Sample Viewer reads .b)",
    "sheen_e": "E_sheen(n.v, sheenRoughness), the albedo of the white sheen BRDF for KHR_materials_sheen's albedo "
               "scaling 1 - max3(sheenColor) E (Sample Viewer lut_sheen_E, read as .r)",
}


@dataclass(frozen=True)
class SheenTableSpec:
    """What a sheen table file holds (:func:`pbrkit.io.lut_files.write_lut` writes its
    :meth:`description` beside it): ``kind`` ``"sheen"`` (pbrkit's generic pair
    (E_sheen, E_ashikhmin), :func:`sheen_lut`), ``"charlie"`` (the Charlie DFG in the
    blue channel, :func:`charlie_lut`) or ``"sheen_e"`` (E_sheen in the red channel,
    :func:`sheen_e_lut`); ``visibility`` that of the Charlie DFG."""

    kind: str
    size: int
    visibility: str
    cloth: bool = False

    def description(self):
        return {
            "format": "pbrkit lookup table",
            "kind": self.kind,
            "size": [self.size, self.size],
            "channels": list(_CHANNELS[self.kind]),
            "meaning": _MEANING[self.kind],
            "distribution": "Charlie (Estevez & Kulla 2017, eq. 2), alpha = sheenRoughness^2",
            "visibility": self.visibility if self.kind != "sheen" else "sheen, then ashikhmin",
            "visibility_formulas": dict(VISIBILITIES),
            "layout": "array (N, N, C) indexed [j, i, c]; row-major, row 0 first",
            "axes": dict(_AXES),
            "integration": {"method": "pbrkit.albedo.tables.sheen_albedo: Gauss-Legendre over the half "
                                      "vector (Charlie CDF map, analytic horizon limits)",
                            "theta_nodes_per_segment": SHEEN_NODES[0],
                            "theta_nodes_per_segment_grazing_nv_below_0.0625": SHEEN_NODES[1],
                            "phi_nodes": SHEEN_NODES[2]},
            "sampling": "sample at texel centres: uv = (n.v, sheen roughness); bilinear, clamp to edge",
        }


def sheen_lut(size, cache=True):
    """pbrkit's generic sheen table: (size, size, 2) float32 (E_sheen, E_ashikhmin),
    :func:`sheen_albedo_texels` with each visibility (module doc), and its
    :class:`SheenTableSpec`."""
    table = np.stack([sheen_albedo_texels(size, "sheen", cache), sheen_albedo_texels(size, "ashikhmin", cache)],
                     axis=-1)
    return table, SheenTableSpec("sheen", int(table.shape[0]), "sheen")


def charlie_lut(size, visibility="sheen", cache=True):
    """The Charlie DFG table as the IBL Sampler's ``lut_charlie`` lays it out: (size,
    size, 3) float32 (0, 0, DFG) (the Sample Viewer reads the blue channel), DFG =
    :func:`sheen_albedo_texels` with ``visibility``; and its :class:`SheenTableSpec`."""
    e = sheen_albedo_texels(size, visibility, cache)
    table = np.zeros(e.shape + (3,), np.float32)
    table[..., 2] = e
    return table, SheenTableSpec("charlie", int(e.shape[0]), visibility)


def sheen_e_lut(size, cache=True):
    """The E_sheen table as the Sample Viewer's ``lut_sheen_E`` is read: (size, size, 2)
    float32 (E, 0) (it reads the red channel), E = :func:`sheen_albedo_texels` with the
    specification's visibility; and its :class:`SheenTableSpec`."""
    e = sheen_albedo_texels(size, "sheen", cache)
    table = np.zeros(e.shape + (2,), np.float32)
    table[..., 0] = e
    return table, SheenTableSpec("sheen_e", int(e.shape[0]), "sheen")
