"""Image-space outlines (pbrkit.npr.outlines) on G-buffers rendered analytically
here: a sphere (ray-sphere intersection with the Camera's rays), two planes
meeting at 90 degrees, a single plane, and id images with straight edges."""

import math

import numpy as np
import pytest

from pbrkit.npr.outlines import (
    DEFAULT_THRESHOLDS,
    OPERATORS,
    composite,
    edge_strength,
    line_coverage,
    outline_mask,
)
from pbrkit.rendering.scene import Camera


def sphere_gbuffers(size=200, distance=4.0, radius=1.0, fov=40.0):
    """(camera, depth t, normal, object id, silhouette radius in pixels) of a sphere
    at the origin seen from (0, 0, distance): t along the unit rays of the pixel
    centres, inf where the ray misses."""
    cam = Camera(position=(0.0, 0.0, distance), look_at=(0.0, 0.0, 0.0), fov=fov, width=size, height=size)
    dirs = cam.ray_directions()[:, :, 0, :]
    o = np.asarray(cam.position)
    b = dirs @ o
    disc = b * b - (o @ o - radius * radius)
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    hit = (disc >= 0.0) & (t > 0.0)
    t = np.where(hit, t, np.inf)
    normal = np.where(hit[..., None], (o + np.where(hit, t, 0.0)[..., None] * dirs) / radius, 0.0)
    # the silhouette cone has half angle asin(r / d); on the image plane at unit distance its radius is tan of it
    rho = math.tan(math.asin(radius / distance)) / math.tan(math.radians(fov) / 2.0) * size / 2.0
    return cam, t, normal, hit.astype(np.int32), rho


def planes_gbuffers(cam, planes):
    """(depth t, normal, plane index) of the nearest of infinite planes (point, normal)."""
    dirs = cam.ray_directions()[:, :, 0, :]
    o = np.asarray(cam.position)
    best = np.full(dirs.shape[:2], np.inf)
    normal = np.zeros(dirs.shape)
    index = np.full(dirs.shape[:2], -1)
    for k, (point, n) in enumerate(planes):
        n = np.asarray(n, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = ((np.asarray(point, dtype=float) - o) @ n) / (dirs @ n)
        closer = (t > 0) & (t < best)
        best = np.where(closer, t, best)
        normal[closer] = n
        index[closer] = k
    return best, normal, index


def edge_point_positions(responses, thresholds=None):
    """Image positions (row, col) of the edge points (module docstring of outlines)."""
    e = responses.edges(thresholds)
    if responses.operator == "crack":
        i, j = np.nonzero(e[..., 0])
        k, m = np.nonzero(e[..., 1])
        return np.concatenate([np.stack([i + 0.5, j + 1.0], -1), np.stack([k + 1.0, m + 0.5], -1)])
    i, j = np.nonzero(e)
    off = 1.0 if responses.operator == "roberts" else 0.5
    return np.stack([i + off, j + off], -1)


def radial_profile(coverage, n_bins=64):
    """Coverage-weighted mean radius from the image centre in angular bins."""
    h, w = coverage.shape
    ii, jj = np.mgrid[0:h, 0:w]
    dy, dx = ii + 0.5 - h / 2, jj + 0.5 - w / 2
    r = np.hypot(dy, dx)
    b = ((np.arctan2(dy, dx) + np.pi) / (2 * np.pi) * n_bins).astype(int) % n_bins
    weight = np.bincount(b.ravel(), coverage.ravel(), n_bins)
    return np.bincount(b.ravel(), (coverage * r).ravel(), n_bins) / weight


# ---------------------------------------------------------------- the sphere silhouette


@pytest.mark.parametrize("operator", OPERATORS)
def test_sphere_silhouette_within_a_pixel(operator):
    cam, t, n, ids, rho = sphere_gbuffers()
    size = cam.width
    for buffers in ({"depth": t, "normal": n, "object_id": ids}, {"depth": t}, {"object_id": ids}):
        resp = edge_strength(**buffers, operator=operator)
        pts = edge_point_positions(resp)
        err = np.hypot(pts[:, 0] - size / 2, pts[:, 1] - size / 2) - rho
        # Sobel answers on a band up to sqrt(2) either side of a diagonal step (module docstring)
        limit = math.sqrt(2.0) if operator == "sobel" else 1.0
        assert np.abs(err).max() <= limit, (operator, list(buffers), err.min(), err.max())
        # the whole circle is found: edge points in every direction
        ang = np.arctan2(pts[:, 0] - size / 2, pts[:, 1] - size / 2)
        assert len(np.unique(((ang + np.pi) / (2 * np.pi) * 180).astype(int) % 180)) == 180
    # the outline's centre line follows the circle to a fraction of a pixel
    profile = radial_profile(outline_mask(t, n, ids, width_px=3.0, operator=operator))
    assert np.abs(profile - rho).max() < 0.3


def test_sphere_has_no_inner_edges():
    _, t, n, ids, rho = sphere_gbuffers()
    resp = edge_strength(t, n, ids)
    inside = np.isfinite(t)
    assert resp.normal.max() < 15.0                 # neighbouring normals on the sphere
    pts = edge_point_positions(resp)
    assert np.hypot(pts[:, 0] - 100, pts[:, 1] - 100).min() > rho - 1.0
    assert inside.sum() > 0.9 * math.pi * rho**2


@pytest.mark.parametrize("width", [0.5, 1.0, 2.0, 3.0, 4.5])
def test_outline_width(width):
    _, t, n, ids, rho = sphere_gbuffers()
    c = outline_mask(t, n, ids, width_px=width)
    # across the (vertical) silhouette on the row below the centre: the coverage sums to the width
    row = c[100, :100]
    assert abs(row.sum() - width) < 0.02, row[row > 0]
    # all around the circle: coverage = width x circumference, within the staircase's few per cent
    assert abs(c.sum() / (2 * math.pi * rho * width) - 1.0) < 0.1
    assert c.min() >= 0.0 and c.max() <= 1.0


def test_three_pixel_outline_is_three_pixels_wide_at_any_orientation():
    size = 128
    ii, jj = np.mgrid[0:size, 0:size]
    for slope in (0.0, 0.2, 0.37, 1.0, 2.5):
        ids = (jj + 0.5 - size / 2 > slope * (ii + 0.5 - size / 2)).astype(int)
        c = outline_mask(object_id=ids, width_px=3.0)
        window = c[24:-24, 24:-24]
        length = (size - 48) * math.hypot(1.0, slope) if slope <= 1 else (size - 48) * math.hypot(1.0, 1.0 / slope)
        assert abs(window.sum() / length - 3.0) < 0.15, (slope, window.sum() / length)


# --------------------------------------------------------- creases and planes


def test_normal_edge_where_two_planes_meet():
    cam = Camera(position=(0.0, 0.5, 2.0), look_at=(0.0, -0.6, -3.0), fov=60.0, width=160, height=120)
    floor_wall = [((0.0, -1.0, 0.0), (0.0, 1.0, 0.0)), ((0.0, 0.0, -3.0), (0.0, 0.0, 1.0))]
    t, n, _ = planes_gbuffers(cam, floor_wall)
    assert np.all(np.isfinite(t))                       # the planes fill the view
    for operator in OPERATORS:
        resp = edge_strength(t, n, np.zeros(t.shape, dtype=int), operator=operator)
        assert resp.depth.max() < 0.05          # a change of slope, not a step (Sobel's pairs span 2 pixels)
        pts = edge_point_positions(resp)
        rows, _ = cam.project(np.array([[0.0, -1.0, -3.0]]))
        assert len(pts) >= cam.width - 1                # one edge across the image
        assert np.abs(pts[:, 0] - rows[0]).max() <= 1.0, (operator, pts[:, 0].min(), pts[:, 0].max(), rows)
    c = outline_mask(t, n, width_px=2.0)
    assert abs(c[:, 80].sum() - 2.0) < 0.05


@pytest.mark.parametrize("operator", OPERATORS)
def test_no_edges_on_a_single_plane(operator):
    # a floor seen at grazing incidence (up to ~85 degrees) filling the view: no depth, normal or id edge
    cam = Camera(position=(0.0, 1.0, 0.0), look_at=(0.0, 0.0, -3.0), fov=30.0, width=96, height=96)
    t, n, index = planes_gbuffers(cam, [((0.0, 0.0, 0.0), (0.0, 1.0, 0.0))])
    assert np.all(np.isfinite(t))
    resp = edge_strength(t, n, index, operator=operator)
    assert not resp.edges().any()
    assert resp.depth.max() < 1e-3
    assert outline_mask(t, n, index, operator=operator).max() == 0.0
    # the same with the view depth
    z = t * (cam.ray_directions()[:, :, 0, :] @ cam.basis()[2])
    assert edge_strength(z, operator=operator).depth.max() < 1e-9


def test_thresholds():
    _, t, _, ids, _ = sphere_gbuffers(96)
    depth = np.where(np.isfinite(t), t, 6.0)            # a sphere in front of a wall: steps of about 1/3
    assert edge_strength(depth).edges().sum() == edge_strength(depth).edges(DEFAULT_THRESHOLDS).sum() > 0
    assert not edge_strength(depth).edges({"depth": 0.5}).any()
    assert edge_strength(depth).edges({"depth": 0.2}).any()
    assert outline_mask(depth, object_id=ids, thresholds={"depth": None, "object_id": None}).max() == 0.0
    assert outline_mask(depth, object_id=ids, thresholds={"depth": None}).max() >= 0.5


def test_depth_edges_are_scale_free():
    _, t, _, _, _ = sphere_gbuffers(96)
    plane = np.full_like(t, 6.0)
    depth = np.where(np.isfinite(t), t, plane)          # a sphere 2 in front of a wall: a relative step
    a = edge_strength(depth)
    b = edge_strength(depth * 1000.0)
    assert np.array_equal(a.edges(), b.edges()) and a.edges().any()
    np.testing.assert_allclose(a.depth, b.depth, rtol=1e-9, atol=1e-12)
    # the step relative to the farther depth: 1 - z_near / z_far
    step = a.depth[..., 0][a.depth[..., 0] > 0.02]
    assert 0.3 < np.median(step) < 0.45


# ------------------------------------------------------------- anti-aliasing, supersampling


def test_antialiased_coverage_on_a_diagonal_edge():
    size = 64
    ii, jj = np.mgrid[0:size, 0:size]
    ids = (jj - 20 > 0.37 * ii).astype(np.int64)
    c = outline_mask(object_id=ids, width_px=1.5)
    assert c.min() >= 0.0 and c.max() <= 1.0
    fractional = c[(c > 0.0) & (c < 1.0)]
    assert len(fractional) > size and len(np.unique(np.round(fractional, 6))) > 5
    hard = outline_mask(object_id=ids, width_px=1.5, antialias=False)
    assert set(np.unique(hard)) <= {0.0, 1.0} and hard.sum() > 0


def test_supersampled_gbuffers():
    k, size = 4, 64
    _, t, n, ids, rho = sphere_gbuffers(size * k)
    c = outline_mask(t, n, ids, width_px=2.0, supersample=k)
    assert c.shape == (size, size) and c.min() >= 0.0 and c.max() <= 1.0
    assert abs(c[size // 2, : size // 2].sum() - 2.0) < 0.1
    assert np.abs(radial_profile(c, 32) - rho / k).max() < 0.3
    assert len(np.unique(c)) > 8                         # graded coverage
    with pytest.raises(ValueError, match="samples per pixel"):
        outline_mask(t[:-1], width_px=2.0, supersample=k)


def test_deterministic():
    _, t, n, ids, _ = sphere_gbuffers(128)
    for kwargs in ({}, {"operator": "sobel"}, {"operator": "roberts", "width_px": 2.5}, {"supersample": 2}):
        a = outline_mask(t, n, ids, **kwargs)
        b = outline_mask(t.copy(), n.copy(), ids.copy(), **kwargs)
        assert a.tobytes() == b.tobytes()


# ------------------------------------------------------------------------ lines, blend


def test_line_coverage_width():
    shape = (64, 64)
    c = line_coverage(np.array([[[10.0, 5.3], [50.0, 40.7]]]), shape, width_px=2.0)
    length = math.hypot(40.0, 35.4)
    assert abs(c.sum() / length - 2.0) < 0.1        # round caps add pi w^2 / 4 / length
    h = line_coverage(np.array([[[20.5, 3.0], [20.5, 60.0]]]), shape, width_px=2.0)
    assert h[:, 30].sum() == pytest.approx(2.0) and h[20, 30] == 1.0 and h[19, 30] == h[21, 30] == 0.5
    assert line_coverage(np.zeros((0, 2, 2)), shape).max() == 0.0


def test_composite():
    img = np.full((2, 3, 3), 0.5)
    cov = np.array([[0.0, 0.25, 1.0], [1.0, 0.5, 0.0]])
    out = composite(img, cov, [1.0, 0.0, 0.0])
    np.testing.assert_allclose(out[0, 1], [0.625, 0.375, 0.375])
    np.testing.assert_allclose(out[0, 2], [1.0, 0.0, 0.0])
    np.testing.assert_allclose(out[1, 2], img[1, 2])
    with pytest.raises(ValueError, match="coverage must"):
        composite(img, cov[:1], 0.0)


@pytest.mark.parametrize("call, message", [
    (lambda: edge_strength(), "at least one"),
    (lambda: edge_strength(np.ones((4, 4)), operator="canny"), "operator must be one of"),
    (lambda: edge_strength(np.ones((4, 4)), np.ones((4, 5, 3))), "image size"),
    (lambda: edge_strength(object_id=np.ones((4, 4))), "integer"),
    (lambda: outline_mask(np.ones((4, 4)), width_px=0.0), "width_px"),
    (lambda: outline_mask(np.ones((4, 4)), thresholds={"colour": 1.0}), "unknown key"),
    (lambda: outline_mask(np.ones((4, 4)), thresholds={"depth": -1.0}), "thresholds"),
    (lambda: outline_mask(np.ones((4, 4)), supersample=1.5), "supersample"),
])
def test_bad_input_is_one_line(call, message):
    with pytest.raises(ValueError, match=message) as info:
        call()
    assert "\n" not in str(info.value)
