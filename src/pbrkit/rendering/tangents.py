"""Tangent frames for normal mapping.

Tangents, when a primitive has a normal texture but no TANGENT attribute,
are generated the way MikkTSpace does (Mikkelsen, "Simulation of Wrinkled
Surfaces Revisited", MSc thesis, 2008; the reference implementation
``mikktspace.c``): per face corner the texture-space derivative dp/du is
projected into the tangent plane of the vertex normal and normalised,
weighted by the corner's angle and averaged over the corners that share a
vertex *and* the orientation (handedness) of their texture mapping; the
sign w makes B = w (N x T) point along dp/dv' with v' = 1 - v, the
convention glTF normal maps use (+Y is up in the image, and glTF's v
grows downward).  The bitangent is rebuilt per pixel from the
interpolated N and T, as MikkTSpace requires.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "mikktspace_tangents",
]

def mikktspace_tangents(positions, normals, uv, triangles):
    """Per-vertex tangents (V, 4) (xyz unit, w = +-1) for a triangle mesh, the way
    MikkTSpace builds them (module docstring): corner tangents dp/du projected into
    the vertex normal's tangent plane, normalised, angle-weighted and averaged over
    the corners sharing a vertex and a texture orientation; w = +1 when
    (T, N x T, N) agrees with dp/dv' for v' = 1 - v (glTF's image-up axis).
    Vertices used with both orientations take the majority one (MikkTSpace would
    split them; glTF stores one tangent per vertex)."""
    p = np.asarray(positions, dtype=float)
    n = np.asarray(normals, dtype=float)
    uv = np.asarray(uv, dtype=float)
    tri = np.asarray(triangles, dtype=np.int64)
    v_count = p.shape[0]
    corners = tri.reshape(-1)
    p0, p1, p2 = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
    # v' = 1 - v: texture "up" is +v'
    s0, s1, s2 = uv[tri[:, 0], 0], uv[tri[:, 1], 0], uv[tri[:, 2], 0]
    t0, t1, t2 = 1.0 - uv[tri[:, 0], 1], 1.0 - uv[tri[:, 1], 1], 1.0 - uv[tri[:, 2], 1]
    e1 = p1 - p0
    e2 = p2 - p0
    ds1, ds2 = s1 - s0, s2 - s0
    dt1, dt2 = t1 - t0, t2 - t0
    det = ds1 * dt2 - ds2 * dt1
    orient = np.where(det >= 0.0, 1.0, -1.0)
    # dp/du and dp/dv' scaled by det (MikkTSpace keeps only directions and the sign)
    vos = (e1 * dt2[:, None] - e2 * dt1[:, None]) * orient[:, None]
    # corner angles
    angles = np.empty((tri.shape[0], 3))
    pts = (p0, p1, p2)
    for c in range(3):
        a = pts[(c + 1) % 3] - pts[c]
        b = pts[(c + 2) % 3] - pts[c]
        cosang = np.sum(a * b, axis=1) / np.maximum(np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1), 1e-300)
        angles[:, c] = np.arccos(np.clip(cosang, -1.0, 1.0))
    nc = n[corners]
    tc = np.repeat(vos, 3, axis=0)
    tc = tc - np.sum(tc * nc, axis=1, keepdims=True) * nc
    length = np.linalg.norm(tc, axis=1, keepdims=True)
    good = (length[:, 0] > 1e-20) & (np.repeat(np.abs(det), 3) > 1e-20)
    tc = np.where(good[:, None], tc / np.maximum(length, 1e-300), 0.0)
    weight = angles.reshape(-1) * good
    oc = np.repeat(orient, 3)
    acc_pos = np.zeros((v_count, 3))
    acc_neg = np.zeros((v_count, 3))
    w_pos = np.zeros(v_count)
    w_neg = np.zeros(v_count)
    pos_mask = oc > 0
    np.add.at(acc_pos, corners[pos_mask], tc[pos_mask] * weight[pos_mask, None])
    np.add.at(acc_neg, corners[~pos_mask], tc[~pos_mask] * weight[~pos_mask, None])
    np.add.at(w_pos, corners[pos_mask], weight[pos_mask])
    np.add.at(w_neg, corners[~pos_mask], weight[~pos_mask])
    use_pos = w_pos >= w_neg
    t = np.where(use_pos[:, None], acc_pos, acc_neg)
    sign = np.where(use_pos, 1.0, -1.0)
    length = np.linalg.norm(t, axis=1, keepdims=True)
    # fallback for vertices without a usable UV mapping: any vector orthogonal to n
    fallback = np.cross(n, np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]]))
    t = np.where(length > 1e-20, t / np.maximum(length, 1e-300), fallback / np.maximum(
        np.linalg.norm(fallback, axis=1, keepdims=True), 1e-300))
    return np.concatenate([t, sign[:, None]], axis=1)


