"""Irradiance cube maps by cosine convolution.

Irradiance E(n) = integral of L(l) max(0, n.l) dl (``CONVENTIONS.md``,
"Irradiance": E, not E / pi, so a constant radiance 1 gives pi; a Lambertian
surface reflects albedo / pi * E).  The cosine kernel is zonal, so by the
Funk-Hecke theorem E = pi times the convolution with the normalised kernel
max(0, cos theta) / pi, whose coefficients are lambda_l = A_l / pi with
A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4, ..., zero for odd l > 1
(Ramamoorthi & Hanrahan, "An Efficient Representation for Irradiance
Environment Maps", SIGGRAPH 2001, eqs. 8-9).  :func:`irradiance_spectral`
convolves the bounded part of an environment to the degree of its
coefficients (the same transform as the specular prefilter,
:mod:`pbrkit.ibl.prefilter`; the A_l decay like l^-5/2, so a degree in the
hundreds leaves an error far below 1e-4 of the bounded part's radiance) and
adds the sparse highlights exactly, each point of energy E_i contributing
E_i max(0, n.l_i).  :func:`irradiance_reference` is the brute-force sum over
every texel of a cube map with exact texel solid angles, for tests and
benchmarks.  No roughness remap is involved (the cosine lobe is
Lambertian).
"""

from __future__ import annotations

import math

import numpy as np

from .cubemap import _as_cube, cube_texel_directions, cube_texel_solid_angles
from .prefilter import LOBE_COSINE, merge_highlights, point_lobe_sum
from .sh import cosine_lobe_coefficients
from .spectral import convolve, sample_equirect, synthesise_equirect

__all__ = ["cosine_zonal_coefficients", "add_cosine_highlights", "irradiance_spectral", "irradiance_reference"]


def cosine_zonal_coefficients(lmax):
    """lambda_l = A_l / pi (l = 0..L) of the normalised clamped cosine
    max(0, cos theta) / pi, A_l in closed form (Ramamoorthi & Hanrahan 2001,
    eqs. 8-9; :func:`pbrkit.ibl.sh.cosine_lobe_coefficients`)."""
    return cosine_lobe_coefficients(lmax) / math.pi


def add_cosine_highlights(out, directions, points, energies):
    """Add the irradiance of point highlights E_i max(0, n.l_i) at unit
    ``directions`` (K, 3) to ``out`` (K, C) in place
    (:func:`pbrkit.ibl.prefilter.point_lobe_sum`)."""
    return point_lobe_sum(out, directions, points, energies, LOBE_COSINE)


def irradiance_spectral(coeffs, highlights, size, grid_factor=2.0):
    """Irradiance cube map (6, size, size, C) float32 (module doc) from the
    spherical-harmonic coefficients ``coeffs`` (L + 1, L + 1, C) of the
    bounded environment (:func:`pbrkit.ibl.spectral.analyse_equirect`) and its
    :class:`pbrkit.ibl.prefilter.Highlights` (merged per texel of a 2 size
    cube).  The series, cut at L' = min(L, 4 size) (|lambda_l| < 1e-5 beyond
    l = 128), is synthesised on an equirect grid of grid_factor * L' + 2
    rows and interpolated at the texel centres; negative
    ringing of the truncated series is clamped to 0.  Returns (cube, info)."""
    lmax = min(coeffs.shape[0] - 1, max(16, 4 * int(size)))
    height = int(grid_factor * lmax) + 2
    lam = cosine_zonal_coefficients(lmax)
    grid = synthesise_equirect(convolve(coeffs[: lmax + 1, : lmax + 1], lam), height)
    dirs = cube_texel_directions(size).reshape(-1, 3)
    values = sample_equirect(grid, dirs) * math.pi
    points, energies, merged = merge_highlights(highlights, 2 * size)
    add_cosine_highlights(values, dirs, points, energies)
    np.maximum(values, 0.0, out=values)
    info = dict(size=int(size), band_limit=int(lmax), grid_height=height, highlight_points=int(points.shape[0]),
                highlight_merge_size=int(merged))
    return values.reshape(6, size, size, -1).astype(np.float32), info


def irradiance_reference(cube, directions):
    """Brute-force irradiance sum_i L_i max(0, n.l_i) Omega_i over every
    texel i of ``cube`` (6, N, N, C) (centre directions, exact solid angles
    :func:`pbrkit.ibl.cubemap.cube_texel_solid_angles`) at unit ``directions``
    (..., 3) -> (..., C), by :func:`pbrkit.ibl.prefilter.point_lobe_sum`.
    O(directions x 6 N^2)."""
    c = _as_cube(cube).astype(np.float64)
    n = c.shape[1]
    d = np.asarray(directions, dtype=np.float64)
    shape = d.shape[:-1]
    flat = d.reshape(-1, 3)
    flat = np.ascontiguousarray(flat / np.linalg.norm(flat, axis=1, keepdims=True))
    src = np.ascontiguousarray((c * cube_texel_solid_angles(n)[..., None]).reshape(-1, c.shape[3]))
    out = np.zeros((flat.shape[0], c.shape[3]))
    point_lobe_sum(out, flat, cube_texel_directions(n).reshape(-1, 3), src, LOBE_COSINE)
    return out.reshape(shape + (c.shape[3],))
