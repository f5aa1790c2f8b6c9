"""The wavefront engine of the ground truth: scenes with triangle meshes (Embree) as
a loop over samples and bounces, each step on the whole wavefront of paths at once
(:func:`_vertex_batch`, then shadow rays, BxDF rays and what they meet), with the
per-vertex estimator of :mod:`pbrkit.rendering.vertex`: the numbers of the fused kernel
(:mod:`pbrkit.rendering.reference`) for the same scene (tested).
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np

from ..brdf.transmission import sigma_a, transmissive_material
from ..brdf.shading.registry import COLUMNS
from ..core.jit import row_kernel
from ..sampling.random import _path_key
from .estimator import area_emission, area_shadow_t
from .film import Film, shifted_add
from .materials import coat_normals, emission_seen, for_materials, per_hit_tables
from .primary import _background, _primary
from .primitives import KIND_NONE
from .punctual import NO_TANGENTS, punctual_radiance, surface_tangents, tangent_of
from .records import Materials, Points, area_arrays, environment_arrays
from .vertex import _env_miss, _transmissive_vertex, _transmits, _vertex

__all__ = []

#: Columns of the packed parameter row the kernels read.
_TRANSMISSION = COLUMNS.transmission


class VertexSamples(NamedTuple):
    """:func:`_vertex`'s results for a wavefront of path vertices, one row each."""

    light_dir: np.ndarray
    light_val: np.ndarray
    area_dir: np.ndarray
    area_dist: np.ndarray  # how far the shadow ray looks (area_shadow_t)
    area_val: np.ndarray
    bsdf_dir: np.ndarray
    bsdf_w: np.ndarray
    bsdf_pdf: np.ndarray


def _vertex_samples(count):
    """Empty :class:`VertexSamples` for ``count`` vertices."""
    vec = lambda: np.empty((count, 3))  # noqa: E731
    return VertexSamples(vec(), vec(), vec(), np.empty(count), vec(), vec(), vec(), np.empty(count))


@row_kernel(lambda seed, sample, bounce, strategy, media, pixel, *rest: pixel.shape[0])
def _vertex_batch(start, stop, seed, sample, bounce, strategy, media, pixel, points, materials, env, area, out):
    media = _transmits(media)
    p = points.p
    ng = points.ng
    n = points.n
    v = points.v
    mat = points.material
    rough = points.roughness
    metal = points.metallic
    base = points.base_color
    tan = points.tangent
    light_dir = out.light_dir
    light_val = out.light_val
    area_dir = out.area_dir
    area_dist = out.area_dist
    area_val = out.area_val
    bsdf_dir = out.bsdf_dir
    bsdf_w = out.bsdf_w
    bsdf_pdf = out.bsdf_pdf
    for i in range(start, stop):
        key = _path_key(seed, pixel[i], sample, bounce)
        if media and transmissive_material(materials.codes, materials.params, mat[i]):
            ldir, lval, adir, adist, aval, bdir, bw, pdf_b = _transmissive_vertex(
                key, strategy, materials, env, area, mat[i], p[i, 0], p[i, 1], p[i, 2], ng[i, 0], ng[i, 1], ng[i, 2],
                n[i, 0], n[i, 1], n[i, 2], v[i, 0], v[i, 1], v[i, 2], rough[i], metal[i], base[i, 0], base[i, 1],
                base[i, 2], tangent_of(tan, i))
        else:
            ldir, lval, adir, adist, aval, bdir, bw, pdf_b = _vertex(
                key, strategy, materials, env, area, mat[i], p[i, 0], p[i, 1], p[i, 2], ng[i, 0], ng[i, 1], ng[i, 2],
                n[i, 0], n[i, 1], n[i, 2], v[i, 0], v[i, 1], v[i, 2], rough[i], metal[i], base[i, 0], base[i, 1],
                base[i, 2], tangent_of(tan, i))
        for a in range(3):
            light_dir[i, a] = ldir[a]
            light_val[i, a] = lval[a]
            area_dir[i, a] = adir[a]
            area_val[i, a] = aval[a]
            bsdf_dir[i, a] = bdir[a]
            bsdf_w[i, a] = bw[a]
        area_dist[i] = area_shadow_t(adist)
        bsdf_pdf[i] = pdf_b


@row_kernel(4)
def _area_emission_batch(start, stop, strategy, pdf_b, area, index, p, d, t, radiance, out):
    for i in range(start, stop):
        le = area_emission(strategy, pdf_b[i], area, index[i], p[i, 0], p[i, 1], p[i, 2], d[i, 0], d[i, 1], d[i, 2],
                           t[i], radiance[i, 0], radiance[i, 1], radiance[i, 2])
        out[i, 0] = le[0]
        out[i, 1] = le[1]
        out[i, 2] = le[2]


@row_kernel(2)
def _miss_batch(start, stop, strategy, pdf_b, d, env, out):
    for i in range(start, stop):
        le = _env_miss(strategy, pdf_b[i], env, d[i, 0], d[i, 1], d[i, 2])
        out[i, 0] = le[0]
        out[i, 1] = le[1]
        out[i, 2] = le[2]


def _wavefront(geometry, env, prim, base_value, k2, n_pixels, spp, bounces, seed, strategy, occlusion, materials,
               scene=None):
    """Every sample of a scene with triangle meshes (Embree) as a loop over samples and
    bounces, each step on the whole wavefront of paths at once (:func:`_vertex_batch`,
    then shadow rays, BRDF rays and what they meet); returns the :class:`Film`.  In a
    scene with glTF BLEND surfaces each sample casts its primary rays again, so that
    their coverage (:mod:`pbrkit.rendering.alpha`) is drawn per sample."""
    envs = environment_arrays(env)
    area = area_arrays(geometry)
    has_area = len(geometry.area_lights) > 0
    # volume boundaries and their media's absorption (the fused kernel's media, per path)
    volume, sigma = _media_tables(materials)
    media = bool(volume.any())
    transmits = bool(np.any(materials.params[:, _TRANSMISSION] > 0.0))
    total_sum = np.zeros((n_pixels, 3))
    total_sq = np.zeros((n_pixels, 3))
    blend = scene is not None and geometry.blends
    prim_tables, prim_material, prim_origin = _hit_tables(materials, prim.surface) if prim.rows.size else \
        (materials, np.zeros(0, dtype=np.int64), None)
    ray_pixel = np.arange(prim.dirs.shape[0]) // k2
    ray_sub = np.arange(prim.dirs.shape[0]) % k2
    for j in range(spp):
        sub = j % k2
        if blend:  # this sample's primary rays (ray = pixel * k2 + sub), their coverage drawn anew
            ids = np.arange(sub, prim.dirs.shape[0], k2)
            pj = _primary(scene, geometry, salt=j + 1, rays=ids)
            x = _base_values(pj, geometry, env, materials)
            rows = ids[pj.rows]
            sj = pj.surface
            surf_tables, surf_mat, surf_origin = _hit_tables(materials, sj)
            surf_p, surf_ng, surf_n = sj.p, sj.ng, sj.n
            surf_r, surf_m, surf_b, surf_t = sj.roughness, sj.metallic, sj.base_color, surface_tangents(sj)
        else:
            x = base_value[sub::k2].copy()  # rays are pixel-major: ray = pixel * k2 + sub
            sel = np.flatnonzero(ray_sub[prim.rows] == sub)
            rows = prim.rows[sel]
            surf_p = prim.surface.p[sel]
            surf_ng = prim.surface.ng[sel]
            surf_n = prim.surface.n[sel]
            surf_tables, surf_mat, surf_origin = prim_tables, prim_material[sel], prim_origin
            surf_r = prim.surface.roughness[sel]
            surf_m = prim.surface.metallic[sel]
            surf_b = prim.surface.base_color[sel]
            surf_t = NO_TANGENTS if prim.surface.tangent is None else prim.surface.tangent[sel]
        v = -prim.dirs[rows]
        pix = ray_pixel[rows]
        through = np.ones((rows.size, 3))
        medium = np.full(rows.size, -1, dtype=np.int64)
        for bounce in range(bounces + 1):
            count = pix.size
            if count == 0:
                break
            vs = _vertex_samples(count)
            points = Points(*(np.ascontiguousarray(a) for a in (surf_p, surf_ng, surf_n, v, surf_mat, surf_r,
                                                                 surf_m, surf_b, surf_t)))
            for_materials(_vertex_batch, surf_tables.codes)(seed, j, bounce, strategy, transmits,
                                                            pix.astype(np.int64), points, surf_tables, envs, area, vs)
            ldir, lval, adir, adist, aval, bdir, bw, bpdf = vs
            for direction, value, tmax in ((ldir, lval, None), (adir, aval, adist)):
                lit = np.flatnonzero(np.any(value > 0.0, axis=1))
                if lit.size and occlusion:  # the objects and the area lights cast shadows
                    origins = geometry.offset_origins(surf_p[lit], surf_ng[lit], direction[lit])
                    far = None if tmax is None else tmax[lit]
                    blocked = geometry.occluded(origins, direction[lit], far)
                    if has_area:
                        blocked |= geometry.area_light_hits(origins, direction[lit], far)[1] >= 0
                    lit = lit[~blocked]
                np.add.at(x, pix[lit], through[lit] * value[lit])
            go = np.flatnonzero((bpdf > 0.0) & np.any(bw > 0.0, axis=1))
            if go.size == 0:
                break
            origins = geometry.offset_origins(surf_p[go], surf_ng[go], bdir[go])
            dirs = np.ascontiguousarray(bdir[go])
            through = through[go] * bw[go]
            pix = pix[go]
            hits = geometry.intersect(origins, dirs) if occlusion else None
            if media:  # the medium of this segment (by the side of the boundary it leaves to), its transmittance
                mat_go = surf_mat[go] if surf_origin is None else surf_origin[surf_mat[go]]  # scene materials
                entering = np.sum(surf_ng[go] * dirs, axis=1) < 0.0
                medium = np.where(volume[mat_go], np.where(entering, mat_go, -1), medium[go])
                inside = np.flatnonzero(medium >= 0)
                if inside.size:
                    length = np.full(go.size, np.inf) if hits is None else hits.t
                    s_in = sigma[medium[inside]]
                    with np.errstate(invalid="ignore", over="ignore"):
                        through[inside] *= np.where(s_in > 0.0, np.exp(-s_in * length[inside, None]), 1.0)
            escaped = np.ones(go.size, dtype=bool) if hits is None else ~hits.hit
            if has_area:  # an area light before the next surface (any, without occlusion)
                at, ai, radiance = geometry.area_light_hits(origins, dirs, None if hits is None else hits.t)
                seen = np.flatnonzero(ai >= 0)
                if seen.size:
                    le = np.empty((seen.size, 3))
                    _area_emission_batch(strategy, np.ascontiguousarray(bpdf[go][seen]), area, ai[seen],
                                         np.ascontiguousarray(surf_p[go][seen]), np.ascontiguousarray(dirs[seen]),
                                         at[seen], radiance[seen], le)
                    np.add.at(x, pix[seen], through[seen] * le)
                    if hits is not None:  # the light is opaque: those paths end on it
                        escaped[seen] = False
                        hits.kind[seen] = KIND_NONE
            miss = np.flatnonzero(escaped)
            if miss.size:
                le = np.empty((miss.size, 3))
                _miss_batch(strategy, np.ascontiguousarray(bpdf[go][miss]), np.ascontiguousarray(dirs[miss]), envs,
                            le)
                np.add.at(x, pix[miss], through[miss] * le)
            if hits is None:
                break
            hit = np.flatnonzero(hits.hit)
            if hit.size == 0:
                break
            surface = geometry.surface(hits, origins, dirs, hit)
            tables, hit_material, origin = _hit_tables(materials, surface)
            surface = replace(surface, material=hit_material, extension_values=None)
            seen = emission_seen(tables.codes, tables.params, surface.material,
                                 -np.einsum("ij,ij->i", coat_normals(tables.params, surface.material, surface.n),
                                            dirs[hit]), surface.emissive)
            np.add.at(x, pix[hit], through[hit] * seen)
            if bounce == bounces:
                break
            through = through[hit]
            pix = pix[hit]
            if media:
                medium = medium[hit]
            v = -dirs[hit]
            if geometry.lights:
                np.add.at(x, pix, through * punctual_radiance(geometry, surface, v, tables.codes, tables.params))
            surf_p, surf_ng, surf_n = surface.p, surface.ng, surface.n
            surf_mat, surf_r, surf_m, surf_b = surface.material, surface.roughness, surface.metallic, \
                surface.base_color
            surf_tables, surf_origin = tables, origin
            surf_t = surface_tangents(surface)
        if j == 0:
            shift = x.copy()
        total_sum, total_sq = shifted_add(shift, total_sum, total_sq, x, 1)
    return Film(shift, total_sum, total_sq)


def _hit_tables(materials, surface):
    """The kernels' :class:`pbrkit.rendering.records.Materials` for the hits of ``surface``
    (a row per hit whose extension textures change its parameters,
    :func:`pbrkit.rendering.materials.per_hit_tables`), each hit's row in them, and each
    row's scene material (None: ``materials`` itself, the rows the scene's)."""
    codes, params, material, origin = per_hit_tables(materials.codes, materials.params, surface)
    return (materials if origin is None else Materials(codes, params)), material, origin


def _media_tables(materials):
    """Per material row: whether it bounds a medium
    (:func:`pbrkit.brdf.transmission.volume_material`) and its absorption coefficient
    sigma_a (M, 3) (:func:`pbrkit.brdf.transmission.sigma_a`)."""
    codes, params = materials
    volume = (params[:, _TRANSMISSION] > 0.0) & (params[:, COLUMNS.thickness] > 0.0)
    sigma = np.zeros((codes.shape[0], 3))
    for m in range(codes.shape[0]):
        sigma[m] = sigma_a(params, m)
    return volume, sigma


def _base_values(prim, geometry, env, materials):
    """The deterministic part of each primary ray (rays, 3): the background where it
    misses, else the emission and the punctual lights at its hit."""
    base_value = np.zeros((prim.dirs.shape[0], 3))
    base_value[~prim.hit] = _background(prim, env)
    if prim.rows.size:
        tables, material, _ = _hit_tables(materials, prim.surface)
        s = replace(prim.surface, material=material, extension_values=None)
        v = -prim.dirs[prim.rows]
        nov = np.einsum("ij,ij->i", coat_normals(tables.params, s.material, s.n), v)
        base_value[prim.rows] = emission_seen(tables.codes, tables.params, s.material, nov, s.emissive) + \
            punctual_radiance(geometry, s, v, tables.codes, tables.params, None, True)
    return base_value
