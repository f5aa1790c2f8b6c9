"""Multiple-scattering energy compensation, evaluated as a renderer would.

Single-scattering microfacet lobes lose the energy that would scatter more
than once (Kulla & Conty 2017, "Revisiting Physically Based Shading at
Imageworks", sec. 3; seed 002).  Two published fixes are evaluated here with
the tables a runtime would use (bilinear lookups in pbrkit's DFG table):

- ``kulla-conty``: add f_ms = (1 - E(mu_o))(1 - E(mu_i)) / (pi (1 - E_avg))
  times the colour factor F_avg E_avg / (1 - F_avg (1 - E_avg))
  (:func:`pbrkit.albedo.tables.kulla_conty_ms`, :func:`pbrkit.albedo.tables.kulla_conty_color`);
- ``filament``: scale the lobe by 1 + F0 (1 / DFG2 - 1) (Filament sec. 4.7.2,
  :func:`pbrkit.albedo.tables.filament_energy_compensation`).

The single-scattering albedo itself comes from the converged quadrature of
:func:`pbrkit.albedo.tables.specular_integrals` (GGX, height-correlated Smith), so the
white-furnace result measures exactly what a renderer would get.
"""

from __future__ import annotations

import functools

import numpy as np

from ..core.quadrature import gauss_legendre_01
from .lut import lookup_table
from .tables import (
    f_avg_schlick,
    filament_energy_compensation,
    kulla_conty_color,
    kulla_conty_ms,
    sample_table,
    specular_integrals,
)

__all__ = ["METHODS", "white_furnace_compensated", "compensated_albedo"]

METHODS = ("kulla-conty", "filament")


@functools.lru_cache(maxsize=4)
def _runtime_tables(table_size, n_mu=64):
    """The DFG table, and E_avg per roughness computed from the table as an engine bakes it.

    Cached: a report evaluates several methods and metals against the same table.
    The table is returned read-only so the cache cannot be altered by a caller.
    """
    table = lookup_table("dfg", table_size)[0]
    table.setflags(write=False)
    x, w = gauss_legendre_01(n_mu)

    def e_avg(roughness):
        e = sample_table(table, x[None, :], np.asarray(roughness, dtype=float)[:, None])[..., 1]
        return 2.0 * np.sum(e * x * w, axis=-1)

    return table, e_avg, (x, w)


def compensated_albedo(method, mu, roughness, f0=1.0, table_size=128, nodes=None):
    """Directional albedo (len(mu), len(r), C) of a Schlick-Fresnel GGX surface with
    compensation ``method`` (``none``, ``kulla-conty`` or ``filament``).

    ``f0`` is a scalar or an RGB triple.  The single-scattering part is
    F0 A + B with (A, B) of :func:`pbrkit.albedo.tables.specular_integrals`
    (height-correlated Smith; ``nodes`` as there).  The compensation reads
    E(mu) = DFG2 from a ``table_size`` DFG table by bilinear lookup, as a
    renderer does; at the table's texel centres the lookup is exact.
    Kulla-Conty uses F_avg of Schlick's Fresnel in closed form, (20 F0 + 1) / 21,
    and E_avg integrated from the same table.
    """
    if method not in ("none",) + METHODS:
        raise ValueError(f"unknown compensation {method!r}; choose none, {', '.join(METHODS)}")
    mu = np.atleast_1d(np.asarray(mu, dtype=float))
    roughness = np.atleast_1d(np.asarray(roughness, dtype=float))
    f0 = np.atleast_1d(np.asarray(f0, dtype=float))
    kwargs = {} if nodes is None else {"nodes": nodes}
    ab = specular_integrals(mu, roughness, "height-correlated", **kwargs).transpose(1, 0, 2)  # (mu, r, 2)
    single = f0 * ab[..., 0:1] + ab[..., 1:2]
    if method == "none":
        return single
    table, e_avg_of, (x, w) = _runtime_tables(table_size)
    e_o = sample_table(table, mu[:, None], roughness[None, :])[..., 1:2]  # (mu, r, 1)
    if method == "filament":
        return single * filament_energy_compensation(f0, e_o)
    e_avg = e_avg_of(roughness)[None, :, None]  # (1, r, 1)
    # integral over the hemisphere of f_ms (n.l) dl = 2 pi integral_0^1 f_ms(mu_o, mu_i) mu_i dmu_i
    e_i = sample_table(table, x[:, None], roughness[None, :])[..., 1].T[None, :, :]  # (1, r, n_mu)
    ms = 2.0 * np.pi * np.sum(w * x * kulla_conty_ms(e_o, e_i, e_avg), axis=-1)  # (mu, r)
    return single + kulla_conty_color(f_avg_schlick(f0), e_avg) * ms[..., None]


def white_furnace_compensated(method, mu, roughness, table_size=128, nodes=None):
    """Albedo (len(mu), len(r)) of the white (F = 1) GGX lobe with compensation; ideally 1."""
    return compensated_albedo(method, mu, roughness, 1.0, table_size, nodes)[..., 0]
