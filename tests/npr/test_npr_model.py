"""The demo's procedural model (pbrkit.app.demo_model), the binary glTF writer
(pbrkit.io.gltf_writer) and texture-space hatching (hatching_space = "texture")."""

from __future__ import annotations

import math

import numpy as np
import pygltflib
import pytest

from pbrkit.app.demo_model import (
    box,
    demo_model_primitives,
    torus_knot,
    torus_knot_curve,
)
from pbrkit.io.gltf_document import read_gltf_document, validate_gltf_document
from pbrkit.io.gltf_writer import GltfPrimitive, glb_bytes, write_glb
from pbrkit.npr.edges import mesh_edges
from pbrkit.npr.hatching import hatch
from pbrkit.npr.render import _tam, render_styled
from pbrkit.npr.style import Style
from pbrkit.rendering.environment import EnvironmentLight
from pbrkit.rendering.lights import Light
from pbrkit.rendering.scene import Camera, EnvironmentSpec, GltfObject, Scene

# ------------------------------------------------------------------ the writer


def _accessor(gltf, blob, index):
    acc = gltf.accessors[index]
    view = gltf.bufferViews[acc.bufferView]
    dtype = {5126: np.float32, 5125: np.uint32}[acc.componentType]
    width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[acc.type]
    start = view.byteOffset + (acc.byteOffset or 0)
    return np.frombuffer(blob, dtype=dtype, count=acc.count * width, offset=start).reshape(acc.count, width)


def test_glb_round_trips_through_an_independent_reader(tmp_path):
    prims = demo_model_primitives()
    path = tmp_path / "m.glb"
    write_glb(path, prims)
    gltf = pygltflib.GLTF2().load(str(path))  # pygltflib parses the container itself
    blob = gltf.binary_blob()
    assert gltf.asset.version == "2.0" and len(gltf.meshes[0].primitives) == len(prims)
    for prim, p in zip(gltf.meshes[0].primitives, prims):
        pos = _accessor(gltf, blob, prim.attributes.POSITION)
        np.testing.assert_allclose(pos, p.positions, rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(_accessor(gltf, blob, prim.attributes.NORMAL), p.normals, atol=1e-6)
        np.testing.assert_allclose(_accessor(gltf, blob, prim.attributes.TEXCOORD_0), p.texcoords, atol=1e-6)
        np.testing.assert_array_equal(_accessor(gltf, blob, prim.indices).reshape(-1, 3), p.indices)
        acc = gltf.accessors[prim.attributes.POSITION]
        np.testing.assert_allclose(acc.min, pos.min(axis=0)) and np.testing.assert_allclose(acc.max, pos.max(axis=0))
        material = gltf.materials[prim.material]
        assert material.name == p.name
        np.testing.assert_allclose(material.pbrMetallicRoughness.baseColorFactor[:3], p.base_color)
        assert material.pbrMetallicRoughness.roughnessFactor == pytest.approx(p.roughness)
    doc, _ = read_gltf_document(path)
    validate_gltf_document(doc)  # pbrkit's own checks of the specification pass too
    assert path.read_bytes() == glb_bytes(demo_model_primitives())  # same meshes, same bytes
    assert len(path.read_bytes()) % 4 == 0


@pytest.mark.parametrize("change, message", [
    ({"positions": np.zeros((2, 3))}, "positions"),
    ({"normals": np.zeros((4, 2))}, "normals"),
    ({"indices": np.array([[0, 1, 9]])}, "indices"),
    ({"indices": np.array([[0.0, 1.0, 2.0]])}, "indices"),
    ({"texcoords": np.zeros((3, 2))}, "texcoords"),
    ({"positions": np.array([[0, 0, 0], [1, 0, 0], [0, np.nan, 0], [1, 1, 0.0]])}, "finite"),
])
def test_bad_primitives_are_refused_and_nothing_is_written(tmp_path, change, message):
    args = {"positions": np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.0]]),
            "normals": np.tile([0.0, 0.0, 1.0], (4, 1)), "indices": np.array([[0, 1, 2], [1, 3, 2]])}
    args.update(change)
    with pytest.raises(ValueError, match=message):
        write_glb(tmp_path / "bad.glb", [GltfPrimitive(**args)])
    assert not list(tmp_path.iterdir())


# --------------------------------------------------------------- the model


def test_torus_knot_is_closed_smooth_and_faces_outward():
    p, n, uv, idx = torus_knot(segments=128, sides=16, tube=0.4)
    rings = p.reshape(129, 17, 3)
    np.testing.assert_allclose(rings[0], rings[-1], atol=1e-12)  # the tube closes on itself, no seam
    np.testing.assert_allclose(n.reshape(129, 17, 3)[0], n.reshape(129, 17, 3)[-1], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
    # every vertex lies at the tube radius from the knot's centre line (sampled finely)
    line = torus_knot_curve(np.linspace(0.0, 2.0 * math.pi, 20001))
    distance = np.min(np.linalg.norm(p[:, None, :] - line[None, ::4, :], axis=2), axis=1)
    assert np.all(np.abs(distance - 0.4) < 2e-3)
    # triangles wind counter-clockwise seen from outside: their normals agree with the vertex normals
    face = np.cross(p[idx[:, 1]] - p[idx[:, 0]], p[idx[:, 2]] - p[idx[:, 0]])
    assert np.all(np.sum(face * n[idx].mean(axis=1), axis=1) > 0.0)
    # no crease and no boundary: a smooth closed tube once the seam vertices are welded
    edges = mesh_edges(p, idx, crease_angle_deg=40.0)
    assert not edges.boundary.any() and not edges.crease.any()
    assert uv[:, 0].min() == 0.0 and uv[:, 0].max() == pytest.approx(8.0)


def test_box_has_twelve_creases_and_outward_faces():
    p, n, uv, idx = box((0.0, 0.0, 0.0), (2.0, 1.0, 3.0))
    edges = mesh_edges(p, idx, crease_angle_deg=40.0)
    assert int(edges.crease.sum()) == 12 and not edges.boundary.any()
    face = np.cross(p[idx[:, 1]] - p[idx[:, 0]], p[idx[:, 2]] - p[idx[:, 0]])
    assert np.all(np.sum(face * n[idx[:, 0]], axis=1) > 0.0)
    np.testing.assert_allclose(np.abs(p).max(axis=0), [1.0, 0.5, 1.5])


# ------------------------------------------------------- texture-space hatching


@pytest.fixture(scope="module")
def quad(tmp_path_factory):
    """A unit-radiance-scaled quad in the plane z = 0 whose texture coordinates are
    an affine map of its position, and the map."""
    a = np.array([[0.5, 0.3], [-0.2, 0.6]])
    offset = np.array([0.1, 0.4])
    corners = np.array([[-2.0, -2.0, 0.0], [2.0, -2.0, 0.0], [2.0, 2.0, 0.0], [-2.0, 2.0, 0.0]])
    uv = corners[:, :2] @ a.T + offset
    path = tmp_path_factory.mktemp("quad") / "quad.glb"
    write_glb(path, [GltfPrimitive(corners, np.tile([0.0, 0.0, 1.0], (4, 1)), np.array([[0, 1, 2], [0, 2, 3]]),
                                   texcoords=uv, base_color=(1.0, 1.0, 1.0), roughness=1.0)])
    return path, a, offset


def test_texture_space_hatching_samples_the_map_at_the_mesh_uvs(quad):
    path, a, offset = quad
    theta = math.acos(0.5)  # n.l = 0.5: tone 0.5 everywhere on the quad
    light = Light(type="directional", direction=(-math.sin(theta), 0.0, -math.cos(theta)), intensity=math.pi)
    size = 256
    scene = Scene(camera=Camera(position=(0.0, 0.0, 5.0), look_at=(0.0, 0.0, 0.0), fov=30.0, width=size,
                                height=size), environment=EnvironmentSpec(color=(0.0, 0.0, 0.0)),
                  objects=(GltfObject(file=str(path)),), lights=(light,))
    env = EnvironmentLight(scene.environment)
    scale = 0.05  # small: under one texel per pixel, so level 0 of the map
    style = Style(shading="hatching", specular=0.0, environment=False, hatching_space="texture",
                  hatching_scale=scale)
    result = render_styled(scene, style, env=env)
    # where each pixel's ray meets the plane, and the texture coordinates there (the affine map)
    d = scene.camera.ray_directions().reshape(-1, 3)
    p = np.array([0.0, 0.0, 5.0]) + (-5.0 / d[:, 2])[:, None] * d
    inside = np.all(np.abs(p[:, :2]) < 1.9, axis=1).reshape(size, size)
    uv = (p[:, :2] @ a.T + offset) * scale
    tam = _tam(style.hatching_tones)  # the renderer's map: tonal_art_map(tones, size=256, seed=0)
    assert tam.strokes.size and tam.sizes[0] == 256
    expected = hatch(np.full(uv.shape[0], 0.5), uv, tam, level=0.0).reshape(size, size)
    ink = result.image[..., 1]  # white paper lit at 1: radiance = ink
    assert np.abs(ink - expected)[inside].max() < 1e-4  # Embree's float32 barycentrics
    assert 0.2 < expected[inside].mean() < 0.9 and expected[inside].std() > 0.05  # strokes, not flat grey
    # object space (box-mapped world x, y) draws a different pattern on the same quad
    world = render_styled(scene, Style(shading="hatching", specular=0.0, environment=False, hatching_scale=scale),
                          env=env).image[..., 1]
    assert np.abs(world - ink)[inside].max() > 0.2


def test_hatching_space_is_checked():
    with pytest.raises(ValueError, match="hatching_space"):
        Style(hatching_space="screen")
