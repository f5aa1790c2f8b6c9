"""glTF's alpha modes on triangle meshes (glTF 2.0, "Alpha Coverage", the material's
``alphaMode`` and ``alphaCutoff``), for every ray either render mode casts
(:meth:`pbrkit.rendering.geometry.Geometry.intersect` and ``occluded``).

The alpha of a surface point is baseColorFactor's alpha times the alpha channel of
the baseColorTexture (linear), at the hit's texture coordinates (the texture's own
sampler and ``KHR_texture_transform``), times a VEC4 COLOR_0's alpha interpolated
over the triangle (glTF 2.0, "Meshes": COLOR_0 "acts as an additional linear
multiplier to base color", its alpha included):

- ``OPAQUE``: alpha is ignored (the rendered output is fully opaque);
- ``MASK``: a point whose alpha is below ``alphaCutoff`` (default 0.5) is not there,
  "fully transparent": a ray passes through it, to whatever lies behind, and so does
  a shadow ray (cutouts);
- ``BLEND``: coverage.  A ray meets the surface with probability alpha and passes
  through it otherwise (stochastic transparency, Enderton et al. 2010, "Stochastic
  Transparency"; the decision hashed from the ray, as hashed alpha testing, Wyman and
  McGuire 2017, "Hashed Alpha Testing", does from the fragment).  Its expectation is
  the specification's blending, alpha times the surface over (1 - alpha) times what is
  behind: exact in the ground truth (a Monte Carlo estimate over paths, shadows
  included), and over a pixel's sub-pixel rays in real time (alpha to coverage:
  ``--supersample`` sets how finely).  The hash of the ray's origin, direction and the
  layer crossed (SplitMix64's finaliser, Steele et al. 2014) gives the same bytes for
  the same scene.

A ray crosses at most :data:`LAYERS` surfaces that let it through (then it stops at
the next one).
"""

from __future__ import annotations

import numpy as np

from .primitives import KIND_TRIANGLE

__all__ = ["MODES", "LAYERS", "coverage_tables", "ray_uniform", "see_through", "pass_through"]

#: The alpha modes, in code order.
MODES = ("OPAQUE", "MASK", "BLEND")
#: The most surfaces a ray passes through.
LAYERS = 64
_MASK, _BLEND = 1, 2


def coverage_tables(materials):
    """(mode code, cutoff, alpha factor) per :class:`pbrkit.rendering.textures.SurfaceMaterial`,
    or None when every material is opaque."""
    modes = np.array([MODES.index(m.alpha_mode) for m in materials], dtype=np.int64)
    if not np.any(modes):
        return None
    return (modes, np.array([m.alpha_cutoff for m in materials], dtype=np.float64),
            np.array([m.alpha for m in materials], dtype=np.float64))


def _mix64(x):
    # SplitMix64's finaliser (Steele, Lea and Flood 2014): a bijection that mixes every bit
    x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return x ^ (x >> np.uint64(31))


def ray_uniform(origins, dirs, layer):
    """A number in [0, 1) per ray (N,), a hash of the bits of its origin and direction
    (N, 3) and the ``layer`` it crosses."""
    bits = np.ascontiguousarray(np.concatenate([origins, dirs], axis=1), dtype=np.float64).view(np.uint64)
    h = _mix64(np.full(bits.shape[0], layer, dtype=np.uint64) + np.uint64(0x9E3779B97F4A7C15))
    with np.errstate(over="ignore"):
        for c in range(bits.shape[1]):
            h = _mix64(h ^ bits[:, c])
    return (h >> np.uint64(11)).astype(np.float64) * (1.0 / 9007199254740992.0)


def _vertex_alpha(geometry, hits, rows, alpha):
    """``alpha`` (rows,) times COLOR_0's alpha interpolated at the hits ``rows`` on meshes
    that have one."""
    for gi in np.unique(hits.index[rows]):
        mesh = geometry.meshes[gi]
        if mesh.alphas is None:
            continue
        at = np.flatnonzero(hits.index[rows] == gi)
        tri = mesh.indices[hits.prim[rows[at]]]
        w1 = hits.b1[rows[at]]
        w2 = hits.b2[rows[at]]
        alpha[at] *= (1.0 - w1 - w2) * mesh.alphas[tri[:, 0]] + w1 * mesh.alphas[tri[:, 1]] + w2 * mesh.alphas[tri[:, 2]]
    return alpha


def _alpha(geometry, tables, hits, rows, material):
    """alpha (rows,) at the triangle hits ``rows`` of materials ``material``."""
    alpha = _vertex_alpha(geometry, hits, rows, tables[2][material].copy())
    for mi in np.unique(material):
        m = geometry.materials[mi]
        ref = m.alpha_texture
        if ref is None:
            continue
        sel = np.flatnonzero(material == mi)
        r = rows[sel]
        uv = np.empty((sel.size, 2))
        for gi in np.unique(hits.index[r]):
            at = np.flatnonzero(hits.index[r] == gi)
            mesh = geometry.meshes[gi]
            if ref.texcoord >= len(mesh.texcoords):
                raise ValueError(f"material {m.spec.name!r} uses TEXCOORD_{ref.texcoord}, which its mesh lacks")
            tri = mesh.indices[hits.prim[r[at]]]
            w1 = hits.b1[r[at]][:, None]
            w2 = hits.b2[r[at]][:, None]
            tc = mesh.texcoords[ref.texcoord]
            uv[at] = (1.0 - w1 - w2) * tc[tri[:, 0]] + w1 * tc[tri[:, 1]] + w2 * tc[tri[:, 2]]
        alpha[sel] *= m.textures[ref.texture].sample(ref.lookup_uv(uv))[:, 3]
    return alpha


def see_through(geometry, tables, hits, origins, dirs, rows, layer):
    """Which of the hits ``rows`` a ray passes through (module docstring)."""
    out = np.zeros(rows.size, dtype=bool)
    tri = np.flatnonzero(hits.kind[rows] == KIND_TRIANGLE)
    if tri.size == 0:
        return out
    r = rows[tri]
    material = np.array([geometry.meshes[g].material for g in hits.index[r]], dtype=np.int64)
    mode = tables[0][material]
    some = np.flatnonzero(mode != 0)
    if some.size == 0:
        return out
    r, material, mode = r[some], material[some], mode[some]
    alpha = _alpha(geometry, tables, hits, r, material)
    cut = alpha < tables[1][material]
    u = ray_uniform(origins[r], dirs[r], layer)
    out[tri[some]] = np.where(mode == _MASK, cut, u >= alpha)
    return out


def pass_through(geometry, tables, closest, hits, origins, dirs, tmax, salt=0):
    """``hits`` (the closest hits of rays o + t d, t < tmax) with every surface that the
    ray passes through (:func:`see_through`) replaced by the next one behind it, found
    by ``closest(origins, dirs, tmax)`` from just beyond it.  ``salt`` (an integer)
    draws other coverage decisions for the same rays (another Monte Carlo sample)."""
    origins = np.asarray(origins, dtype=np.float64)
    dirs = np.asarray(dirs, dtype=np.float64)
    n = origins.shape[0]
    far = None if tmax is None else np.broadcast_to(np.asarray(tmax, dtype=np.float64), (n,))
    eps = 1e-4 * geometry.scale
    pending = np.arange(n)
    for layer in range(LAYERS):
        if pending.size == 0:
            break
        through = pending[see_through(geometry, tables, hits, origins, dirs, pending, layer + LAYERS * salt)]
        if through.size == 0:
            break
        start = hits.t[through] + eps
        again = closest(origins[through] + start[:, None] * dirs[through], dirs[through],
                        None if far is None else np.maximum(far[through] - start, 0.0))
        hits.t[through] = start + again.t
        hits.kind[through] = again.kind
        hits.index[through] = again.index
        hits.prim[through] = again.prim
        hits.b1[through] = again.b1
        hits.b2[through] = again.b2
        pending = through
    return hits
