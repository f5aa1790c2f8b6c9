"""Mesh edges (pbrkit.npr.edges): welding, classification, silhouettes, and
drawing lines visible against a depth buffer."""

import math

import numpy as np
import pytest

from pbrkit.npr.edges import draw_lines, mesh_edges, silhouette_edges, weld_vertices
from pbrkit.rendering.scene import Camera


def cube24(size=1.0):
    """A cube as glTF stores it: 24 vertices (4 per face, corners duplicated), 12
    triangles, counter-clockwise seen from outside; faces in the order +X -X +Y -Y +Z -Z."""
    pos, idx = [], []
    for axis in range(3):
        for sign in (1.0, -1.0):
            n = np.zeros(3)
            n[axis] = sign
            u = np.zeros(3)
            u[(axis + 1) % 3] = 1.0
            v = np.cross(n, u)
            base = len(pos)
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                pos.append(0.5 * size * (n + a * u + b * v))
            idx += [[base, base + 1, base + 2], [base, base + 2, base + 3]]
    return np.array(pos), np.array(idx)


def uv_sphere(n_lon, n_lat, radius=1.0):
    """A UV sphere as exporters write it: (n_lat + 1) x (n_lon + 1) vertices (the seam
    column and the pole rows duplicated), two triangles per quad (those at the poles
    degenerate once welded)."""
    theta = np.linspace(0.0, np.pi, n_lat + 1)
    phi = np.linspace(0.0, 2.0 * np.pi, n_lon + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    pos = radius * np.stack([np.sin(t) * np.cos(p), np.cos(t), -np.sin(t) * np.sin(p)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n_lat), np.arange(n_lon), indexing="ij")
    w = n_lon + 1
    a, b, c, d = i * w + j, i * w + j + 1, (i + 1) * w + j + 1, (i + 1) * w + j
    idx = np.concatenate([np.stack([a, d, c], -1).reshape(-1, 3), np.stack([a, c, b], -1).reshape(-1, 3)])
    return pos, idx


def grid(nx, ny):
    """A flat nx x ny grid of quads in the z = 0 plane, (nx + 1) (ny + 1) vertices."""
    x, y = np.meshgrid(np.arange(nx + 1.0), np.arange(ny + 1.0), indexing="xy")
    pos = np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], -1)
    j, i = np.meshgrid(np.arange(nx), np.arange(ny), indexing="xy")
    a = i * (nx + 1) + j
    b, c, d = a + 1, a + nx + 2, a + nx + 1
    tris = np.stack([np.stack([a, b, c], -1), np.stack([a, c, d], -1)], axis=2).reshape(-1, 3)
    return pos, tris


def sphere_depth(cam, radius=1.0):
    """Ray distance t of a sphere at the origin (inf where missed)."""
    dirs = cam.ray_directions()[:, :, 0, :]
    o = np.asarray(cam.position)
    b = dirs @ o
    disc = b * b - (o @ o - radius * radius)
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    return np.where((disc >= 0) & (t > 0), t, np.inf)


def radial_profile(coverage, n_bins=64):
    h, w = coverage.shape
    ii, jj = np.mgrid[0:h, 0:w]
    dy, dx = ii + 0.5 - h / 2, jj + 0.5 - w / 2
    r = np.hypot(dy, dx)
    b = ((np.arctan2(dy, dx) + np.pi) / (2 * np.pi) * n_bins).astype(int) % n_bins
    return np.bincount(b.ravel(), (coverage * r).ravel(), n_bins) / np.bincount(b.ravel(), coverage.ravel(), n_bins)


# ----------------------------------------------------------------- classification


def test_cube_with_duplicated_corners_has_twelve_crease_edges():
    pos, idx = cube24()
    e = mesh_edges(pos, idx)
    assert len(e.positions) == 8 and e.remap.shape == (24,)
    assert len(e) == 18                                     # 12 cube edges + 6 face diagonals
    assert e.crease.sum() == 12 and e.boundary.sum() == 0 and e.non_manifold.sum() == 0
    assert e.consistent.all() and np.all(e.face_count == 2)
    lengths = np.linalg.norm(np.diff(e.segments(), axis=1)[:, 0], axis=1)
    np.testing.assert_allclose(lengths[e.crease], 1.0)      # the creases are the cube's edges
    np.testing.assert_allclose(lengths[~e.crease], math.sqrt(2.0))   # the diagonals are not
    np.testing.assert_allclose(e.dihedral_deg[e.crease], 90.0)
    np.testing.assert_allclose(e.dihedral_deg[~e.crease], 0.0, atol=1e-6)
    # without welding every edge would be a boundary: the weld is what makes it work
    unwelded = mesh_edges(pos + np.repeat(np.arange(6), 4)[:, None] * 10.0, idx)
    assert unwelded.boundary.sum() == 24


def test_smooth_uv_sphere_has_no_creases():
    pos, idx = uv_sphere(32, 16)
    e = mesh_edges(pos, idx, crease_angle_deg=30.0)
    assert len(e.positions) == 32 * 15 + 2
    assert e.crease.sum() == 0 and e.boundary.sum() == 0 and e.non_manifold.sum() == 0
    assert e.degenerate.sum() == 2 * 32                     # one per quad at each pole
    assert len(e) == len(e.positions) + (~e.degenerate).sum() - 2   # Euler: V - E + F = 2
    assert np.nanmax(e.dihedral_deg) < 12.0
    assert mesh_edges(pos, idx, crease_angle_deg=5.0).crease.sum() > 0


def test_open_meshes_boundary_edges():
    pos, idx = cube24()
    open_box = mesh_edges(pos, idx[np.r_[0:4, 6:12]])       # without the +Y face (triangles 4, 5)
    assert open_box.boundary.sum() == 4
    seg = open_box.segments(open_box.boundary)
    np.testing.assert_allclose(seg[..., 1], 0.5)            # the rim of the missing top
    assert open_box.crease.sum() == 8
    for nx, ny in ((1, 1), (5, 3), (8, 8)):
        pos, tris = grid(nx, ny)
        e = mesh_edges(pos, tris)
        assert e.boundary.sum() == 2 * (nx + ny)
        assert e.crease.sum() == 0 and len(e) == nx * (ny + 1) + ny * (nx + 1) + nx * ny


def test_material_edges_between_two_halves():
    nx, ny = 6, 4
    pos, tris = grid(nx, ny)
    centre_x = pos[tris].mean(axis=1)[:, 0]
    material = (centre_x > nx / 2).astype(np.int32)
    e = mesh_edges(pos, tris, material=material)
    assert e.material_edge.sum() == ny
    seg = e.segments(e.material_edge)
    np.testing.assert_allclose(seg[..., 0], nx / 2)         # the line x = 3 between the halves
    assert not (e.material_edge & e.boundary).any()
    assert mesh_edges(pos, tris).material_edge.sum() == 0


def test_non_manifold_and_inconsistent_winding():
    pos = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -1, 0], [0.5, 0, 1.0]])
    fan = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])        # three faces on the edge (0, 1)
    e = mesh_edges(pos, fan)
    assert e.non_manifold.sum() == 1 and tuple(e.vertices[e.non_manifold][0]) == (0, 1)
    assert e.face_count[e.non_manifold][0] == 3
    assert e.boundary.sum() == 6
    # a flat grid with one triangle wound the other way: no crease, and its edges are flagged
    gpos, tris = grid(3, 3)
    tris = tris.copy()
    tris[8] = tris[8, ::-1]                                 # in the middle quad
    g = mesh_edges(gpos, tris)
    assert g.crease.sum() == 0 and (~g.consistent[g.face_count == 2]).sum() == 3


def test_weld_tolerance_is_relative():
    pos, idx = cube24(size=1000.0)
    rng = np.random.default_rng(1)
    jitter = pos + rng.uniform(-1e-7, 1e-7, pos.shape) * 1000.0       # far below 1e-6 of the diagonal
    assert len(mesh_edges(jitter, idx).positions) == 8
    assert len(mesh_edges(pos + rng.uniform(-1e-3, 1e-3, pos.shape) * 1000.0, idx).positions) == 24
    welded, remap = weld_vertices(pos, 0.0)
    assert len(welded) == 8 and remap[0] == 0 and np.array_equal(welded[remap], pos)


# ------------------------------------------------------------------------ silhouettes


def test_sphere_silhouette_projects_onto_the_analytic_circle():
    size, distance, fov = 256, 4.0, 40.0
    cam = Camera(position=(0.0, 0.0, distance), look_at=(0.0, 0.0, 0.0), fov=fov, width=size, height=size)
    pos, idx = uv_sphere(64, 32)
    e = mesh_edges(pos, idx)
    sil = silhouette_edges(e, None, None, cam)
    assert 64 <= sil.sum() <= 160
    assert np.array_equal(sil, silhouette_edges(e, e.face_normals, e.face_centres, cam.position))

    def rho(r):
        return math.tan(math.asin(r / distance)) / math.tan(math.radians(fov) / 2) * size / 2

    # Polygonisation: the (convex, inscribed) mesh lies between the sphere and its
    # inscribed ball, whose radius is the nearest face plane's distance from the centre.
    kept = ~e.degenerate
    r_in = np.abs(np.einsum("ij,ij->i", e.face_normals[kept], e.face_centres[kept])).min()
    poly_error = rho(1.0) - rho(r_in)
    assert poly_error < 0.3                                  # 64 x 32: 0.23 pixel
    s = np.linspace(0, 1, 9)[:, None, None]
    seg = e.segments(sil)
    pts = seg[:, 0] + s * (seg[:, 1] - seg[:, 0])
    rows, cols = cam.project(pts)
    radius = np.hypot(rows - size / 2, cols - size / 2)
    assert radius.max() <= rho(1.0) + 1e-9 and radius.min() >= rho(r_in) - 1e-9
    # drawn with the sphere's depth buffer: visible all around, centred on the circle
    cov = draw_lines(seg, cam, sphere_depth(cam), width_px=2.0)
    profile = radial_profile(cov)
    assert np.all(profile > rho(r_in) - 1.0) and np.all(profile < rho(1.0) + 1.0), (profile.min(), profile.max())
    assert abs(cov.sum() / (2 * math.pi * rho(1.0)) - 2.0) < 0.1    # 2 pixels wide all around


def test_back_edges_of_a_sphere_are_hidden():
    size = 128
    cam = Camera(position=(0.0, 0.0, 4.0), look_at=(0.0, 0.0, 0.0), fov=40.0, width=size, height=size)
    pos, idx = uv_sphere(32, 16)
    e = mesh_edges(pos, idx)
    front = np.einsum("ij,ij->i", e.face_normals, np.asarray(cam.position) - e.face_centres) > 0
    two = e.face_count == 2
    back = two & ~front[e.edge_faces[:, 0]] & ~front[e.edge_faces[:, 1]]
    seen = two & front[e.edge_faces[:, 0]] & front[e.edge_faces[:, 1]]
    depth = sphere_depth(cam)
    ii, jj = np.mgrid[0:size, 0:size]
    disk = np.hypot(ii + 0.5 - size / 2, jj + 0.5 - size / 2) < 0.9 * 45.4
    assert draw_lines(e.segments(back), cam, None, 1.0)[disk].mean() > 0.1     # they are there...
    assert draw_lines(e.segments(back), cam, depth, 1.0)[disk].max() == 0.0    # ...behind the sphere
    assert draw_lines(e.segments(seen), cam, depth, 1.0)[disk].mean() > 0.1   # the front ones show


# --------------------------------------------------------------------------- drawing


def test_draw_lines_visibility_against_a_plane():
    cam = Camera(position=(0.0, 0.0, 5.0), look_at=(0.0, 0.0, 0.0), fov=40.0, width=96, height=64)
    dirs = cam.ray_directions()[:, :, 0, :]
    t_plane = 5.0 / -dirs[..., 2]                            # the plane z = 0, ray distance
    behind = np.array([[[-1.0, 0.2, -0.5], [1.0, -0.2, -0.5]]])
    front = behind + [0.0, 0.0, 1.0]
    on = behind + [0.0, 0.0, 0.5]                            # on the plane itself
    assert draw_lines(behind, cam, t_plane, 2.0).max() == 0.0
    assert draw_lines(behind, cam, None, 2.0).sum() > 50
    assert draw_lines(front, cam, t_plane, 2.0).sum() > 50
    np.testing.assert_array_equal(draw_lines(on, cam, t_plane, 2.0), draw_lines(on, cam, None, 2.0))
    # the view depth gives the same
    z_plane = t_plane * (dirs @ cam.basis()[2])
    np.testing.assert_array_equal(draw_lines(front, cam, z_plane, 2.0, depth_kind="view"),
                                  draw_lines(front, cam, t_plane, 2.0))
    # a segment piercing the plane: drawn up to where it goes behind
    pierce = np.array([[[-1.0, 0.0, 1.0], [1.0, 0.0, -1.0]]])
    c = draw_lines(pierce, cam, t_plane, 1.0)
    cols = np.nonzero(c.sum(axis=0))[0]
    mid_col = cam.project(np.zeros(3))[1]
    assert cols.min() < mid_col - 10 and abs(cols.max() + 0.5 - mid_col) <= 1.5


def test_constant_width_in_pixels():
    cam = Camera(position=(0.0, 0.0, 5.0), look_at=(0.0, 0.0, 0.0), fov=40.0, width=128, height=128)
    # horizontal, through pixel centres' row: the coverage across sums to 2
    horizontal = np.array([[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]])
    c = draw_lines(horizontal, cam, None, 2.0)
    assert c[:, 64].sum() == pytest.approx(2.0, abs=1e-9)
    # near or far, slanted in depth: the same width in pixels
    for seg in ([[-1.0, -1.0, 2.0], [1.0, 1.0, -20.0]], [[-1.0, 0.6, 0.0], [1.2, -0.5, 0.0]]):
        seg = np.array([seg])
        cov = draw_lines(seg, cam, None, 2.0)
        r, k = cam.project(seg[0])
        length = math.hypot(r[1] - r[0], k[1] - k[0])
        assert abs(cov.sum() - (2.0 * length + math.pi)) < 0.03 * cov.sum()   # band + two round caps
    for width in (1.0, 3.0, 4.5):
        assert draw_lines(horizontal, cam, None, width)[:, 64].sum() == pytest.approx(width, abs=1e-9)


def test_near_plane_clipping_and_colours():
    cam = Camera(position=(0.0, 0.0, 5.0), look_at=(0.0, 0.0, 0.0), fov=40.0, width=64, height=64)
    behind_camera = np.array([[[0.0, 0.0, 6.0], [0.5, 0.3, 9.0]]])
    assert draw_lines(behind_camera, cam, None, 2.0).max() == 0.0
    through = np.array([[[0.3, 0.1, 0.0], [0.3, 0.1, 10.0]]])      # from in front to behind the eye
    c = draw_lines(through, cam, None, 2.0)
    assert np.all(np.isfinite(c)) and c.max() == 1.0
    segs = np.array([[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [[0.0, -1.0, 0.0], [0.0, 1.0, 0.0]]])
    cov, rgb = draw_lines(segs, cam, None, 2.0, color=[[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    assert rgb.shape == (64, 64, 3)
    np.testing.assert_array_equal(rgb[32, 20], [1.0, 0.0, 0.0])
    np.testing.assert_array_equal(rgb[20, 32], [0.0, 0.0, 1.0])
    np.testing.assert_array_equal(rgb[cov == 0], 0.0)


def test_deterministic():
    cam = Camera(position=(0.3, 0.5, 4.0), look_at=(0.0, 0.0, 0.0), fov=40.0, width=96, height=96)
    pos, idx = uv_sphere(24, 12)
    e = mesh_edges(pos, idx)
    seg = e.segments(silhouette_edges(e, None, None, cam) | e.feature_edges())
    a = draw_lines(seg, cam, sphere_depth(cam), 1.5)
    b = draw_lines(seg.copy(), cam, sphere_depth(cam), 1.5)
    assert a.tobytes() == b.tobytes()
    e2 = mesh_edges(pos.copy(), idx.copy())
    assert np.array_equal(e.vertices, e2.vertices) and np.array_equal(e.face_list, e2.face_list)


@pytest.mark.parametrize("call, message", [
    (lambda: mesh_edges(np.zeros((3, 2)), [[0, 1, 2]]), "positions"),
    (lambda: mesh_edges(np.eye(3), [[0, 1, 3]]), "indices must be in"),
    (lambda: mesh_edges(np.eye(3), [[0.0, 1.0, 2.0]]), "integer"),
    (lambda: mesh_edges(np.eye(3), [[0, 1, 2]], material=[0, 1]), "material"),
    (lambda: mesh_edges(np.eye(3), [[0, 1, 2]], crease_angle_deg=200), "crease_angle_deg"),
    (lambda: silhouette_edges(None, eye=(0, 0, 1)), "MeshEdges"),
    (lambda: draw_lines(np.zeros((1, 3, 3)), Camera(), None), "segments"),
    (lambda: draw_lines(np.zeros((1, 2, 3)), Camera(), np.ones((3, 3))), "depth"),
    (lambda: draw_lines(np.zeros((1, 2, 3)), Camera(), None, width_px=-1), "width_px"),
    (lambda: draw_lines(np.zeros((1, 2, 3)), Camera(), None, depth_kind="z"), "depth_kind"),
])
def test_bad_input_is_one_line(call, message):
    with pytest.raises(ValueError, match=message) as info:
        call()
    assert "\n" not in str(info.value)
