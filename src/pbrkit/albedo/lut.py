"""The lookup tables' description and their memoised computation, importable
without Numba: :class:`TableSpec` (what a table file holds), the default
quadrature :data:`DEFAULT_NODES`, and :func:`lookup_table`, which returns the
table integrated by :func:`pbrkit.albedo.tables.integrate_lookup_table`,
memoised on disk by :func:`pbrkit.core.cache.memoised_array` (keyed on the
options and pbrkit's sources): the second ``pbrkit lut`` with the same options
reads the table and never imports Numba.
"""

from __future__ import annotations

import numpy as np

from ..core import checks
from ..core.cache import memoised_array
from .table_spec import DEFAULT_NODES, TableSpec, default_visibility

__all__ = ["TableSpec", "DEFAULT_NODES", "lookup_table", "default_visibility", "splitsum_table", "dfg_table"]


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


def splitsum_table(size=128, visibility="schlick-ggx", nodes=DEFAULT_NODES):
    """UE4's (A, B) environment-BRDF table (Karis 2013); see :func:`lookup_table`."""
    return lookup_table("splitsum", size, visibility, False, nodes)[0]


def dfg_table(size=128, cloth=False, nodes=DEFAULT_NODES):
    """Filament's (DFG1, DFG2[, cloth]) table (Filament sec. 5.3.4.3 and 9.5); see :func:`lookup_table`."""
    return lookup_table("dfg", size, "height-correlated", cloth, nodes)[0]
