"""Geometric edges of triangle meshes (boundary, non-manifold, crease, material
and silhouette edges) and their drawing as anti-aliased lines of constant
width in pixels, visible against a depth buffer.

Meshes: ``positions`` (V, 3), ``indices`` (F, 3) integers (counter-clockwise
front faces, as in glTF), optional per-face ``material`` ids (F,).  Vertices
that share a position are welded first (:func:`weld_vertices`; glTF meshes
duplicate vertices at UV seams and hard edges, which would otherwise cut the
mesh into pieces whose every edge is a boundary): vertices closer than
``weld_tolerance`` times the diagonal of the mesh's bounding box are one vertex
(all pairs within that distance, found with a k-d tree, and their connected
components).  Faces that lose a vertex to the weld (two corners welded
together) are left out.

Edges (:func:`mesh_edges`): the unique undirected edges (v0 < v1) of the
welded faces with every face adjacent to them, found by sorting (no loop over
faces), and classified (an edge may be in several classes):

- boundary: one adjacent face;
- non-manifold: more than two;
- crease: two adjacent faces whose normals make an angle above
  ``crease_angle_deg`` (the dihedral angle's supplement; the normal of a face
  whose winding disagrees with its neighbour's across the edge, i.e. which
  runs the edge the same way instead of the opposite way, is flipped first);
- material: adjacent faces of different materials.

Silhouettes (:func:`silhouette_edges`): the edges between a face turned to the
eye and one turned away, front-facing meaning n . (eye - c) > 0 with c a point
of the face (Markosian, Kowalski, Trychin, Bourdev, Goldstein and Hughes,
"Real-Time Nonphotorealistic Rendering", SIGGRAPH 1997, sec. 2; Gooch, Sloan,
Gooch, Shirley and Riesenfeld, "Interactive Technical Illustration", I3D 1999,
sec. 3.1), and the boundary edges.

Drawing (:func:`draw_lines`): with the camera's conventions
(:class:`pbrkit.rendering.scene.Camera`: right-handed, +Y up, looking along its
-Z, image row 0 at the top, the centre of pixel (i, j) at (i + 0.5, j + 0.5)),
segments are clipped to the near plane (view depth ``near``), projected, and
rasterised as bands of full width ``width_px`` pixels with the box-filtered
coverage of :func:`pbrkit.npr.outlines.line_coverage` (round caps; the
largest coverage where lines overlap).  Visibility: the depth buffer holds,
per pixel, the distance along the unit ray through the pixel centre to the
first surface (``depth_kind="ray"``: the ``t`` of a ray caster,
:meth:`~pbrkit.rendering.scene.Camera.ray_directions`) or the view depth along
the camera's -Z (``depth_kind="view"``); inf / NaN / <= 0 is the background.
A line pixel is drawn where the point of the segment nearest to it (its view
depth interpolated perspective-correctly: 1 / z is linear along the projected
segment) is not behind the scene by more than ``depth_bias`` (relative),
the scene's view depth being the largest of the 3 x 3 pixels around that
point's pixel: a silhouette lies on the rim of its surface, with the
background or the surface's own far side one pixel away, and a crease on
the surface itself, so both show, while a line behind a surface that covers
its neighbourhood does not.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage, sparse
from scipy.sparse import csgraph
from scipy.spatial import cKDTree

from .outlines import _rasterize

__all__ = [
    "MeshEdges",
    "weld_vertices",
    "mesh_edges",
    "silhouette_edges",
    "draw_lines",
    "DEPTH_KINDS",
]

DEPTH_KINDS = ("ray", "view")


# ------------------------------------------------------------------ input checks


def _positions(positions, name="positions"):
    p = np.asarray(positions)
    if p.ndim != 2 or p.shape[1] != 3 or not (np.issubdtype(p.dtype, np.floating) or np.issubdtype(p.dtype, np.integer)):
        raise ValueError(f"{name} must be a real (V, 3) array; got {p.dtype} {p.shape}")
    p = p.astype(np.float64)
    if not np.all(np.isfinite(p)):
        raise ValueError(f"{name} must be finite; got {int(np.sum(~np.all(np.isfinite(p), axis=1)))} bad vertices")
    return p


def _indices(indices, nv):
    f = np.asarray(indices)
    if f.ndim != 2 or f.shape[1] != 3 or not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"indices must be an integer (F, 3) array; got {f.dtype} {f.shape}")
    f = f.astype(np.int64)
    if f.size and (f.min() < 0 or f.max() >= nv):
        raise ValueError(f"indices must be in [0, {nv - 1}]; got values in [{f.min()}, {f.max()}]")
    return f


def _number(value, name, lo, hi):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not lo <= value <= hi:
        raise ValueError(f"{name} must be a number in [{lo:g}, {hi:g}]; got {value!r}")
    return float(value)


# ------------------------------------------------------------------------- weld


def weld_vertices(positions, tolerance=1e-6):
    """``(welded (V', 3), remap (V,))``: vertices within ``tolerance`` x the
    bounding-box diagonal of each other (and chains of such) become one, at the
    position of the first of them; ``remap`` gives each input vertex its welded
    index, numbered in order of first appearance (deterministic).
    ``tolerance = 0`` welds equal positions only."""
    p = _positions(positions)
    tol = _number(tolerance, "weld_tolerance", 0.0, 0.1)
    n = len(p)
    if n == 0:
        return p.copy(), np.zeros(0, dtype=np.int64)
    if tol == 0.0:
        _, first, label = np.unique(p, axis=0, return_index=True, return_inverse=True)
        label = label.ravel()
    else:
        radius = tol * float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))
        pairs = cKDTree(p).query_pairs(radius, output_type="ndarray") if radius > 0.0 else np.zeros((0, 2), int)
        if radius == 0.0:  # all vertices at one point (or one vertex)
            pairs = np.stack([np.zeros(n - 1, int), np.arange(1, n)], axis=1)
        graph = sparse.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        _, label = csgraph.connected_components(graph, directed=False)
        _, first = np.unique(label, return_index=True)
    # number the welded vertices in order of their first input vertex
    order = np.argsort(first, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    remap = rank[label]
    return p[np.sort(first)], remap.astype(np.int64)


# ------------------------------------------------------------------------ edges


@dataclass(frozen=True)
class MeshEdges:
    """The edges of a welded triangle mesh (module docstring).

    Vertices and faces: ``positions`` (V', 3) welded, ``remap`` (V,) input
    vertex -> welded vertex, ``faces`` (F, 3) welded indices (input face
    order), ``degenerate`` (F,) faces left out (a repeated welded vertex),
    ``face_normals`` (F, 3) unit (NaN for degenerate or zero-area faces),
    ``face_centres`` (F, 3), ``material`` (F,) or None.

    Edges, sorted by (v0, v1): ``vertices`` (E, 2) welded indices, v0 < v1;
    ``face_count`` (E,); all adjacent faces of edge e are
    ``face_list[face_offsets[e]:face_offsets[e + 1]]`` (in face order);
    ``edge_faces`` (E, 2) the first two (-1 where absent); ``consistent`` (E,)
    whether the first two run the edge in opposite directions;
    ``dihedral_deg`` (E,) the angle between the normals of the two faces of a
    two-face edge, in degrees (after flipping an inconsistent one; NaN for
    other edges); classes ``boundary``, ``non_manifold``, ``crease``,
    ``material_edge`` (E,) bool."""

    positions: np.ndarray
    remap: np.ndarray
    faces: np.ndarray
    degenerate: np.ndarray
    face_normals: np.ndarray
    face_centres: np.ndarray
    material: np.ndarray | None
    vertices: np.ndarray
    face_count: np.ndarray
    face_offsets: np.ndarray
    face_list: np.ndarray
    edge_faces: np.ndarray
    consistent: np.ndarray
    dihedral_deg: np.ndarray
    boundary: np.ndarray
    non_manifold: np.ndarray
    crease: np.ndarray
    material_edge: np.ndarray
    crease_angle_deg: float

    def __len__(self):
        return len(self.vertices)

    def segments(self, mask=None):
        """(M, 2, 3) end points of the edges selected by ``mask`` (bool (E,) or
        indices; all edges if None), for :func:`draw_lines`."""
        v = self.vertices if mask is None else self.vertices[np.asarray(mask)]
        return self.positions[v]

    def feature_edges(self):
        """(E,) bool: boundary, non-manifold, crease or material edges (those
        drawn whatever the view)."""
        return self.boundary | self.non_manifold | self.crease | self.material_edge


def mesh_edges(positions, indices, material=None, crease_angle_deg=30.0, weld_tolerance=1e-6):
    """The classified edges of a triangle mesh (module docstring) as a
    :class:`MeshEdges`.  ``positions`` (V, 3); ``indices`` (F, 3) integers;
    ``material`` (F,) integer ids or None; ``crease_angle_deg`` in [0, 180];
    ``weld_tolerance`` relative to the bounding-box diagonal
    (:func:`weld_vertices`)."""
    p0 = _positions(positions)
    f0 = _indices(indices, len(p0))
    crease = _number(crease_angle_deg, "crease_angle_deg", 0.0, 180.0)
    mat = None
    if material is not None:
        mat = np.asarray(material)
        if mat.shape != (len(f0),) or not np.issubdtype(mat.dtype, np.integer):
            raise ValueError(f"material must be an integer array of shape ({len(f0)},); got {mat.dtype} {mat.shape}")
        mat = mat.astype(np.int64)
    pos, remap = weld_vertices(p0, weld_tolerance)
    faces = remap[f0] if len(f0) else f0.copy()
    degenerate = (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 2] == faces[:, 0])
    a, b, c = pos[faces[:, 0]], pos[faces[:, 1]], pos[faces[:, 2]]
    cross = np.cross(b - a, c - a)
    length = np.linalg.norm(cross, axis=1)
    ok = ~degenerate & (length > 0.0)
    normals = np.full((len(faces), 3), np.nan)
    normals[ok] = cross[ok] / length[ok, None]
    centres = (a + b + c) / 3.0

    # Directed half-edges of the kept faces: (v_k, v_{k+1}) of face f.
    keep = np.flatnonzero(~degenerate)
    fk = faces[keep]
    start = fk.ravel()
    end = fk[:, [1, 2, 0]].ravel()
    face_of = np.repeat(keep, 3)
    lo, hi = np.minimum(start, end), np.maximum(start, end)
    key = lo * max(len(pos), 1) + hi
    order = np.lexsort((face_of, key))          # by edge, then by face: deterministic
    key, face_of, forward = key[order], face_of[order], (start < end)[order]
    lo, hi = lo[order], hi[order]
    first = np.flatnonzero(np.r_[True, key[1:] != key[:-1]]) if len(key) else np.zeros(0, dtype=np.int64)
    counts = np.diff(np.r_[first, len(key)]).astype(np.int64)
    offsets = np.r_[first, len(key)].astype(np.int64)
    verts = np.stack([lo[first], hi[first]], axis=1) if len(first) else np.zeros((0, 2), dtype=np.int64)
    two = counts >= 2
    edge_faces = np.full((len(first), 2), -1, dtype=np.int64)
    edge_faces[:, 0] = face_of[first]
    edge_faces[two, 1] = face_of[first[two] + 1]
    consistent = np.zeros(len(first), dtype=bool)
    consistent[two] = forward[first[two]] != forward[first[two] + 1]

    dihedral = np.full(len(first), np.nan)
    exactly_two = counts == 2
    if exactly_two.any():
        n0 = normals[edge_faces[exactly_two, 0]]
        n1 = normals[edge_faces[exactly_two, 1]] * np.where(consistent[exactly_two], 1.0, -1.0)[:, None]
        # the angle from the half chord |n0 - n1| / 2 = sin(angle / 2): accurate at small angles too
        half = 0.5 * np.linalg.norm(n0 - n1, axis=1)
        dihedral[exactly_two] = np.degrees(2.0 * np.arcsin(np.minimum(half, 1.0)))
    with np.errstate(invalid="ignore"):
        is_crease = exactly_two & (dihedral > crease)
    material_edge = np.zeros(len(first), dtype=bool)
    if mat is not None and len(first):
        m = mat[face_of]
        material_edge = two & (np.minimum.reduceat(m, first) != np.maximum.reduceat(m, first))
    return MeshEdges(
        positions=pos, remap=remap, faces=faces, degenerate=degenerate, face_normals=normals,
        face_centres=centres, material=mat, vertices=verts, face_count=counts, face_offsets=offsets,
        face_list=face_of, edge_faces=edge_faces, consistent=consistent, dihedral_deg=dihedral,
        boundary=counts == 1, non_manifold=counts > 2, crease=is_crease, material_edge=material_edge,
        crease_angle_deg=crease)


def silhouette_edges(edges, face_normals=None, face_points=None, eye=None, *, include_boundary=True):
    """(E,) bool: the silhouette edges of ``edges`` (a :class:`MeshEdges`) seen
    from ``eye`` (a point (3,) or a :class:`~pbrkit.rendering.scene.Camera`,
    whose position is used): edges between a front-facing and a back-facing
    face, face f front-facing when n_f . (eye - c_f) > 0 (Markosian et al.
    1997; Gooch et al. 1999), with n the ``face_normals`` (F, 3) and c the
    ``face_points`` (F, 3) (any point of each face; default: the edges' own
    normals and centres).  A two-face edge with inconsistent winding compares
    one face's facing flipped; a non-manifold edge is a silhouette when its
    faces do not all face the same way.  ``include_boundary``: boundary edges
    too (the outline of an open surface)."""
    if not isinstance(edges, MeshEdges):
        raise ValueError(f"edges must be a MeshEdges (from mesh_edges); got {type(edges).__name__}")
    if eye is None:
        raise ValueError("eye must be given: a point (3,) or a Camera")
    e = np.asarray(eye.position if hasattr(eye, "position") else eye, dtype=np.float64) \
        if not isinstance(eye, str) else None
    if e is None or e.shape != (3,) or not np.all(np.isfinite(e)):
        raise ValueError(f"eye must be 3 finite numbers or a Camera; got {eye!r}")
    nf = len(edges.faces)
    n = edges.face_normals if face_normals is None else np.asarray(face_normals, dtype=np.float64)
    c = edges.face_centres if face_points is None else np.asarray(face_points, dtype=np.float64)
    for name, a in (("face_normals", n), ("face_points", c)):
        if a.shape != (nf, 3):
            raise ValueError(f"{name} must have shape ({nf}, 3); got {a.shape}")
    with np.errstate(invalid="ignore"):
        front = np.einsum("ij,ij->i", n, e - c) > 0.0
    sil = np.zeros(len(edges), dtype=bool)
    if len(edges):
        f = front[edges.face_list]
        two = edges.face_count == 2
        f0 = front[edges.edge_faces[two, 0]]
        f1 = front[edges.edge_faces[two, 1]]
        sil[two] = np.where(edges.consistent[two], f0 != f1, f0 == f1)
        many = edges.face_count > 2
        mixed = np.minimum.reduceat(f, edges.face_offsets[:-1]) != np.maximum.reduceat(f, edges.face_offsets[:-1])
        sil[many] = mixed[many]
        if include_boundary:
            sil |= edges.boundary
    return sil


# ---------------------------------------------------------------------- drawing


def _camera(camera):
    for attr in ("basis", "position", "fov", "width", "height"):
        if not hasattr(camera, attr):
            raise ValueError(f"camera must be a pbrkit.rendering.scene.Camera; got {type(camera).__name__}")
    return camera


def _view_depth_buffer(depth, camera, kind):
    """The scene's view depth (H, W) (inf for the background) from the buffer."""
    h, w = camera.height, camera.width
    d = np.asarray(depth)
    if d.shape != (h, w) or not (np.issubdtype(d.dtype, np.floating) or np.issubdtype(d.dtype, np.integer)):
        raise ValueError(f"depth must be a real array of the camera's image size {(h, w)}; got {d.dtype} {d.shape}")
    d = d.astype(np.float64)
    if kind == "ray":
        # cos of the angle between the unit ray through the pixel centre and the view axis
        t = math.tan(math.radians(camera.fov) / 2.0)
        x = (2.0 * (np.arange(w) + 0.5) / w - 1.0) * t * (w / h)
        y = (1.0 - 2.0 * (np.arange(h) + 0.5) / h) * t
        d = d / np.sqrt(1.0 + x[None, :] ** 2 + y[:, None] ** 2)
    d = np.where(np.isfinite(d) & (d > 0.0), d, np.inf)
    return ndimage.maximum_filter(d, size=3, mode="nearest")


def draw_lines(segments, camera, depth=None, width_px=1.0, color=None, *, depth_kind="ray",
               depth_bias=0.01, near=None):
    """Draw 3D segments (M, 2, 3) (world space) seen by ``camera`` (a
    :class:`pbrkit.rendering.scene.Camera`) as anti-aliased lines of full width
    ``width_px`` pixels (module docstring).

    ``depth``: None (every line shows) or the scene's depth buffer
    (camera.height, camera.width): with ``depth_kind="ray"`` (default) the
    distance along the unit camera ray through each pixel centre to the first
    surface (``t`` of a ray caster), with ``"view"`` the view depth along the
    camera's -Z; inf / NaN / <= 0 is the background.  A line pixel is drawn
    where the segment's view depth there is at most (1 + ``depth_bias``) times
    the scene's (the largest over the 3 x 3 pixels around the segment point).
    ``near``: the near plane's view depth (default 1e-6 x the largest end
    point depth); segments are clipped to it and parts behind it dropped.

    Returns the coverage (H, W) float64 in [0, 1]; with ``color`` ((3,) or
    (M, 3), linear RGB) also the colour (H, W, 3) of the line of largest
    coverage at each pixel (0 where none), for
    :func:`pbrkit.npr.outlines.composite`."""
    cam = _camera(camera)
    seg = np.asarray(segments)
    if seg.ndim != 3 or seg.shape[1:] != (2, 3) or not (np.issubdtype(seg.dtype, np.floating)
                                                         or np.issubdtype(seg.dtype, np.integer)):
        raise ValueError(f"segments must be a real (M, 2, 3) array; got {seg.dtype} {seg.shape}")
    seg = seg.astype(np.float64)
    if not np.all(np.isfinite(seg)):
        raise ValueError("segments must be finite")
    width = _number(width_px, "width_px", 1e-6, 256.0)
    bias = _number(depth_bias, "depth_bias", 0.0, 1.0)
    if depth_kind not in DEPTH_KINDS:
        raise ValueError(f"depth_kind must be one of {', '.join(DEPTH_KINDS)}; got {depth_kind!r}")
    colors = None
    if color is not None:
        colors = np.asarray(color, dtype=np.float64)
        if colors.shape == (3,):
            colors = np.broadcast_to(colors, (len(seg), 3))
        if colors.shape != (len(seg), 3) or not np.all(np.isfinite(colors)):
            raise ValueError(f"color must be 3 finite numbers or ({len(seg)}, 3); got shape {np.shape(color)}")
    h, w = cam.height, cam.width
    zmax = None if depth is None else _view_depth_buffer(depth, cam, depth_kind)

    # view space: x right, y up, z along the viewing direction (the camera's -Z)
    right, up, forward = cam.basis()
    rel = seg - np.asarray(cam.position, dtype=np.float64)
    x, y, z = rel @ right, rel @ up, rel @ forward            # (M, 2) each
    if near is None:
        zfar = float(np.max(z)) if z.size else 0.0
        near = 1e-6 * zfar if zfar > 0.0 else 1.0
    near = _number(near, "near", 1e-300, math.inf)
    keep = np.max(z, axis=1) >= near
    x, y, z, index = x[keep], y[keep], z[keep], np.flatnonzero(keep)
    # clip to the near plane: move the end behind it onto it
    for k in (0, 1):
        o = 1 - k
        behind = z[:, k] < near
        if behind.any():
            s = (near - z[behind, o]) / (z[behind, k] - z[behind, o])
            for a in (x, y):
                a[behind, k] = a[behind, o] + s * (a[behind, k] - a[behind, o])
            z[behind, k] = near
    t = math.tan(math.radians(cam.fov) / 2.0)
    cols = (x / z / (t * (w / h)) + 1.0) * 0.5 * w
    rows = (1.0 - y / z / t) * 0.5 * h
    seg2 = np.stack([rows, cols], axis=-1)                   # (M', 2, 2)
    if zmax is None:
        cov, best = _rasterize(seg2, (h, w), width)
    else:
        cov, best = _rasterize(seg2, (h, w), width, 0.0, 1.0 / z, zmax, bias)
    if colors is None:
        return cov
    rgb = np.zeros((h, w, 3))
    drawn = best >= 0
    rgb[drawn] = colors[index[best[drawn]]]
    return cov, rgb
