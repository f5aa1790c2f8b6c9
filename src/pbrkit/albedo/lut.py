"""The lookup tables' description and their memoised computation, importable
without Numba: :class:`TableSpec` (what a table file holds), the default
quadrature :data:`DEFAULT_NODES`, and :func:`lookup_table`, which returns the
table integrated by :func:`pbrkit.albedo.tables.integrate_lookup_table`,
memoised on disk by :func:`pbrkit.core.cache.memoised_array` (keyed on the
options and pbrkit's sources): the second ``pbrkit lut`` with the same options
reads the table and never imports Numba.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core import checks
from ..core.cache import memoised_array

__all__ = ["TableSpec", "DEFAULT_NODES", "lookup_table", "default_visibility"]

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


def lookup_table(kind="dfg", size=128, visibility=None, cloth=False, nodes=DEFAULT_NODES, cache=True):
    """The (size, size, C) float32 table of ``kind`` ``splitsum`` or ``dfg`` and its
    :class:`TableSpec` (:func:`pbrkit.albedo.tables.integrate_lookup_table`), memoised
    on disk unless ``cache`` is false (module docstring).

    Defaults: ``splitsum`` uses Karis' IBL visibility (Schlick-GGX, k = alpha / 2)
    as UE4 does; ``dfg`` uses height-correlated Smith as Filament does.
    ``cloth`` appends the sheen albedo channel (:func:`pbrkit.albedo.tables.sheen_albedo`).
    """
    if kind not in ("splitsum", "dfg"):
        raise ValueError(f"unknown table kind {kind!r}; use 'splitsum' or 'dfg'")
    size = checks.integer(size, "table size", 2, 4096)
    visibility = visibility or default_visibility(kind)
    nodes = tuple(int(n) for n in nodes)
    spec = TableSpec(kind, int(size), visibility, bool(cloth), nodes)
    channels = 3 if cloth else 2

    def compute():
        from .tables import integrate_lookup_table

        return integrate_lookup_table(kind, size, visibility, cloth, nodes)[0]

    def check(table):
        return (table.dtype == np.float32 and table.shape == (spec.size, spec.size, channels)
                and bool(np.isfinite(table).all()))

    options = {"kind": kind, "size": spec.size, "visibility": visibility, "cloth": spec.cloth, "nodes": list(nodes)}
    return memoised_array("lookup_table", options, compute, check, enabled=cache), spec
