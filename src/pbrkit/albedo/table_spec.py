"""What a lookup table of :mod:`pbrkit.albedo` holds, importable without Numba
or the integrators: :class:`TableSpec` (the description written beside every
table file), the default quadrature :data:`DEFAULT_NODES` and each kind's
default visibility.  :mod:`pbrkit.albedo.tables` integrates tables of this
description and :mod:`pbrkit.albedo.lut` memoises them; both import this
module, neither imports the other at module level.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["TableSpec", "DEFAULT_NODES", "default_visibility"]

#: Default quadrature: theta nodes per segment (and in the grazing columns), phi nodes.
DEFAULT_NODES = (12, 24, 6)


def default_visibility(kind):
    """Karis' IBL visibility (Schlick-GGX, k = alpha / 2) for ``splitsum``, as UE4 uses;
    height-correlated Smith for ``dfg``, as Filament does."""
    return "schlick-ggx" if kind == "splitsum" else "height-correlated"


@dataclass(frozen=True)
class TableSpec:
    """What a lookup table holds; written beside (or into) every table file."""

    kind: str
    size: int
    visibility: str
    cloth: bool
    nodes: tuple

    def description(self):
        channels = ["A", "B"] if self.kind == "splitsum" else ["DFG1", "DFG2"]
        if self.cloth:
            channels.append("cloth_DV")
        meaning = (
            "specular albedo with Schlick Fresnel = F0 * A + B (Karis 2013)"
            if self.kind == "splitsum"
            else "albedo = lerp(DFG1, DFG2, F0) = DFG1 + F0 (DFG2 - DFG1); DFG2 = E(mu), F = 1 (Filament)"
        )
        return {
            "format": "pbrkit lookup table",
            "kind": self.kind,
            "size": [self.size, self.size],
            "channels": channels,
            "meaning": meaning,
            "cloth": (
                "integral of D_Charlie V_Neubelt (n.l) dl, alpha = r^2 (Estevez & Kulla 2017; Neubelt 2013)"
                if self.cloth else None
            ),
            "layout": "array (N, N, C) indexed [j, i, c]; row-major, row 0 first",
            "axes": {
                "column i": "n.v = (i + 0.5) / N",
                "row j": "perceptual roughness r = (j + 0.5) / N (row 0 = smooth)",
            },
            "distribution": "GGX, alpha = r^2 (unclamped; shading clamps alpha at 1e-3, the table does not)",
            "visibility": self.visibility,
            "integration": {
                "method": "deterministic Gauss-Legendre quadrature over the half vector "
                          "(GGX-CDF theta map, analytic horizon limits)",
                "theta_nodes_per_segment": self.nodes[0],
                "theta_nodes_per_segment_grazing_nv_below_0.0625": self.nodes[1],
                "phi_nodes": self.nodes[2],
                "sample_count": 2 * self.nodes[0] * self.nodes[2],
            },
            "sampling": "sample at texel centres: uv = (n.v, r); bilinear, clamp to edge",
        }
