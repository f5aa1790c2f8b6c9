"""glTF 2.0 meshes, materials, textures and tangents, cast with Embree.

Synthetic files built here check the specification's rules exactly; the Khronos
sample models in ../shared/data/models check real files (skipped without them)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from gltf_scenes import quad_scene, write_quad_glb
from skips import needs_shared_data

from pbrkit.core.color import srgb_to_linear
from pbrkit.core.errors import InputError
from pbrkit.rendering.geometry import Geometry
from pbrkit.rendering.gltf import load_gltf
from pbrkit.rendering.scene import (
    Camera,
    EnvironmentSpec,
    GltfObject,
    MaterialSpec,
    Plane,
    Scene,
)
from pbrkit.rendering.tangents import mikktspace_tangents
from pbrkit.rendering.textures import Texture

MODELS = Path(__file__).resolve().parents[3] / "shared" / "data" / "models"
needs_models = needs_shared_data("models/NormalTangentTest.glb")


# ------------------------------------------------------------------ loading


def test_node_hierarchy_transforms_and_lights(tmp_path):
    light = {"type": "spot", "intensity": 7.0, "color": [1.0, 0.5, 0.5], "range": 9.0,
             "spot": {"innerConeAngle": 0.1, "outerConeAngle": 0.4}}
    path = write_quad_glb(tmp_path / "q.glb", light=light)
    asset = load_gltf(path)
    (mesh,) = asset.meshes
    # parent translation (0, 0, -1) times child scale 2: corners at (+-1, +-1, -1)
    np.testing.assert_allclose(mesh.positions, [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1]], atol=1e-6)
    np.testing.assert_allclose(mesh.normals, np.tile([0, 0, 1], (4, 1)), atol=1e-7)
    (lt,) = asset.lights
    # a node rotated by -90 degrees about X: its -Z axis points down (-Y)
    assert lt.type == "spot" and lt.intensity == 7.0 and lt.range == 9.0 and lt.outer_cone_angle == 0.4
    np.testing.assert_allclose(lt.position, [0, 3, 0], atol=1e-7)
    np.testing.assert_allclose(lt.direction, [0, -1, 0], atol=1e-7)
    # an extra object transform composes on top (T R S of the scene file)
    moved = load_gltf(path, GltfObject(str(path), translation=(5, 0, 0)).matrix())
    np.testing.assert_allclose(moved.meshes[0].positions[:, 0], mesh.positions[:, 0] + 5.0, atol=1e-6)


def _mapped_normal_at_centre(path):
    scene = quad_scene(path)
    geometry = Geometry(scene)
    origin = np.array([[0.0, 0.0, 5.0]])
    d = np.array([[0.0, 0.0, -1.0]])
    return geometry.surface(geometry.intersect(origin, d), origin, d).n[0], geometry


@pytest.mark.parametrize("mirror", [False, True])
def test_normal_maps_stay_attached_to_the_surface_under_mirroring(tmp_path, mirror):
    """A normal texel tilted toward tangent-space +X (increasing u) and +Y (image up).
    The quad's texture runs left to right and top to bottom; mirroring the node in x
    (negative determinant: clockwise winding, glTF 2.0 sec. 3.7.2.1) mirrors the
    texture with it, so the mapped normal must tilt toward -x but still up."""
    texel = np.array([[[200, 200, 200]]], dtype=np.uint8)
    tangent_space = texel[0, 0] / 255.0 * 2.0 - 1.0
    path = write_quad_glb(tmp_path / "n.glb", normal_texture=texel,
                          node_matrix=np.diag([-2.0 if mirror else 2.0, 2.0, 2.0, 1.0]))
    n, geometry = _mapped_normal_at_centre(path)
    (mesh,) = geometry.meshes
    if mirror:
        np.testing.assert_allclose(mesh.positions[:, 0], [1, -1, -1, 1], atol=1e-6)
    expected = tangent_space * [-1.0 if mirror else 1.0, 1.0, 1.0]
    np.testing.assert_allclose(n, expected / np.linalg.norm(expected), atol=3e-3)
    assert np.all(mesh.tangents[:, 3] == (-1.0 if mirror else 1.0))


def test_textures_are_sampled_at_texel_centres_with_the_glTF_colour_spaces(tmp_path):
    colour = np.array([[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [128, 128, 128]]], dtype=np.uint8)
    mr = np.array([[[0, 64, 255], [0, 128, 0]], [[0, 192, 128], [0, 255, 64]]], dtype=np.uint8)
    path = write_quad_glb(tmp_path / "t.glb", texture=colour, mr_texture=mr,
                          sampler={"magFilter": 9728, "wrapS": 33071, "wrapT": 33071},
                          material_extras={"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}})
    scene = quad_scene(path)
    geometry = Geometry(scene)
    # rays through the centres of the four quadrants of the quad (world x, y = +-0.5 at z = -1)
    targets = np.array([[-0.5, 0.5, -1], [0.5, 0.5, -1], [-0.5, -0.5, -1], [0.5, -0.5, -1]], dtype=float)
    origins = np.tile(scene.camera.position, (4, 1))
    dirs = targets - origins
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    hits = geometry.intersect(origins, dirs)
    assert np.all(hits.hit)
    surface = geometry.surface(hits, origins, dirs)
    np.testing.assert_allclose(surface.p, targets, atol=1e-5)
    # image row 0 is v = 0, the top of the quad (+Y): texels (0,0), (0,1), (1,0), (1,1)
    texels = colour.reshape(4, 3) / 255.0
    expected = srgb_to_linear(texels) * np.array([1.0, 0.5, 1.0])  # baseColorTexture is sRGB, times the factor
    np.testing.assert_allclose(surface.base_color, expected, atol=1e-6)
    m = mr.reshape(4, 3) / 255.0  # linear: G = roughness, B = metallic, times the factors
    np.testing.assert_allclose(surface.roughness, m[:, 1] * 0.8, atol=1e-6)
    np.testing.assert_allclose(surface.metallic, m[:, 2] * 0.5, atol=1e-6)
    np.testing.assert_allclose(surface.emissive, np.tile([0.8, 0.4, 0.0], (4, 1)), atol=1e-12)
    np.testing.assert_allclose(surface.n, np.tile([0, 0, 1], (4, 1)), atol=1e-9)


def test_texture_wrap_modes_and_bilinear_filtering():
    texels = np.zeros((1, 4, 4), dtype=np.float32)
    texels[0, :, 0] = [0.0, 1.0, 2.0, 3.0]
    uv = np.array([[1.125, 0.5], [-0.125, 0.5], [0.25, 0.5], [1.375, 0.5]])
    repeat = Texture(texels, 10497, 10497, 9728).sample(uv)[:, 0]
    clamp = Texture(texels, 33071, 33071, 9728).sample(uv)[:, 0]
    mirror = Texture(texels, 33648, 33648, 9728).sample(uv)[:, 0]
    np.testing.assert_allclose(repeat, [0, 3, 1, 1])
    np.testing.assert_allclose(clamp, [3, 0, 1, 3])
    np.testing.assert_allclose(mirror, [3, 0, 1, 2])
    # bilinear between texel centres: u = 0.25 is halfway between texel 0 (0.125) and 1 (0.375)
    np.testing.assert_allclose(Texture(texels, 33071, 33071).sample(np.array([[0.25, 0.5], [0.0, 0.5]]))[:, 0],
                               [0.5, 0.0])
    np.testing.assert_allclose(Texture(texels).sample(np.array([[0.0, 0.5]]))[:, 0], [1.5])  # repeat: 3 and 0


def test_mikktspace_tangents_follow_the_glTF_image_up_convention():
    positions = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
    normals = np.tile([0.0, 0.0, 1.0], (4, 1))
    tri = np.array([[0, 1, 2], [0, 2, 3]])
    # glTF UVs: v grows downward in the image, so the image's "up" (+Y of a normal map) is world +Y here
    uv = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], dtype=float)
    t = mikktspace_tangents(positions, normals, uv, tri)
    np.testing.assert_allclose(t[:, :3], np.tile([1, 0, 0], (4, 1)), atol=1e-12)
    assert np.all(t[:, 3] == 1.0)  # B = w (N x T) = +Y = image up
    # mirrored in u: T = -X, and B = w (N x T) must still be +Y, so w = -1
    t2 = mikktspace_tangents(positions, normals, uv * [-1.0, 1.0] + [1.0, 0.0], tri)
    np.testing.assert_allclose(t2[:, :3], np.tile([-1, 0, 0], (4, 1)), atol=1e-12)
    assert np.all(t2[:, 3] == -1.0)
    np.testing.assert_allclose(np.cross(normals, t2[:, :3]) * t2[:, 3:], np.tile([0, 1, 0], (4, 1)), atol=1e-12)


def test_mikktspace_on_a_uv_sphere_matches_the_longitude_direction():
    # latitude-longitude sphere: u = phi / (2 pi) grows eastward, so T = d p / d phi (normalised)
    n_lat, n_lon = 12, 24
    theta = np.linspace(0.2, np.pi - 0.2, n_lat)
    phi = np.linspace(0.0, 2 * np.pi, n_lon + 1)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    p = np.stack([np.sin(th) * np.cos(ph), np.cos(th), -np.sin(th) * np.sin(ph)], axis=-1).reshape(-1, 3)
    uv = np.stack([ph / (2 * np.pi), th / np.pi], axis=-1).reshape(-1, 2)
    idx = np.arange(n_lat * (n_lon + 1)).reshape(n_lat, n_lon + 1)
    a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, 1:], idx[1:, :-1]
    tri = np.concatenate([np.stack([a, d, c], -1).reshape(-1, 3), np.stack([a, c, b], -1).reshape(-1, 3)])
    t = mikktspace_tangents(p, p, uv, tri)
    east = np.stack([-np.sin(ph), np.zeros_like(ph), -np.cos(ph)], axis=-1).reshape(-1, 3)
    np.testing.assert_allclose(np.sum(t[:, :3] * east, axis=1), 1.0, atol=2e-2)
    np.testing.assert_allclose(np.sum(t[:, :3] * p, axis=1), 0.0, atol=1e-12)
    assert np.all(t[:, 3] == 1.0)


def test_embree_hits_agree_with_the_analytic_plane(tmp_path):
    path = write_quad_glb(tmp_path / "p.glb")
    mesh_scene = quad_scene(path)
    plane_scene = Scene(camera=mesh_scene.camera, environment=mesh_scene.environment,
                        materials={"default": MaterialSpec()},
                        objects=(Plane(point=(0, 0, -1), normal=(0, 0, 1)),))
    rng = np.random.default_rng(1)
    targets = np.concatenate([rng.uniform(-0.95, 0.95, size=(500, 2)), -np.ones((500, 1))], axis=1)
    origins = rng.normal(size=(500, 3)) * 0.5 + [0, 0, 4]
    dirs = targets - origins
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    a = Geometry(mesh_scene).intersect(origins, dirs)
    b = Geometry(plane_scene).intersect(origins, dirs)
    assert np.all(a.hit) and np.all(b.hit)
    np.testing.assert_allclose(a.t, b.t, rtol=1e-5)
    assert np.all(Geometry(mesh_scene).occluded(origins, dirs))
    assert not np.any(Geometry(mesh_scene).occluded(origins, dirs, tmax=a.t * 0.99))


@pytest.mark.parametrize("change, fragment", [
    (dict(extensions_required=("KHR_draco_mesh_compression",)), "unsupported glTF extension"),
])
def test_gltf_errors_name_the_file(tmp_path, change, fragment):
    path = write_quad_glb(tmp_path / "bad.glb", **change)
    with pytest.raises(InputError) as info:
        load_gltf(path)
    assert str(info.value).startswith(str(path)) and fragment in str(info.value)
    (tmp_path / "junk.glb").write_bytes(b"glTF\x02\x00\x00\x00garbage")
    with pytest.raises(InputError, match="junk.glb"):
        load_gltf(tmp_path / "junk.glb")


# ------------------------------------------------------------ sample models


@needs_models
def test_normal_tangent_test_bumps_tilt_outward():
    """Khronos NormalTangentTest: the normal-mapped tiles show bumps, so the mapped
    normals tilt away from each bump's centre: dn_x/dx > 0 and dn_y/dy > 0 on
    average.  A flipped green channel or handedness would give dn_y/dy < 0."""
    scene = Scene(camera=Camera(position=(0.0, 0.0, 3.0), look_at=(0.0, 0.0, 0.0), fov=45.0, width=160,
                                height=160),
                  environment=EnvironmentSpec(color=(0.0, 0.0, 0.0)),
                  objects=(GltfObject(str(MODELS / "NormalTangentTest.glb")),))
    geometry = Geometry(scene)
    cam = scene.camera
    dirs = cam.ray_directions()[:, :, 0].reshape(-1, 3)
    origins = np.tile(cam.position, (dirs.shape[0], 1))
    hits = geometry.intersect(origins, dirs)
    rows = np.flatnonzero(hits.hit)
    s = geometry.surface(hits, origins, dirs, rows)
    n = np.zeros((160 * 160, 3))
    flat = np.zeros(160 * 160, dtype=bool)
    n[rows] = s.n
    flat[rows] = (np.abs(s.ng[:, 2]) > 0.999) & (np.linalg.norm(s.n - s.ng, axis=1) > 0.05)
    n = n.reshape(160, 160, 3)
    flat = flat.reshape(160, 160)
    both_x = flat[:, 1:] & flat[:, :-1]
    both_y = flat[1:, :] & flat[:-1, :]
    dnx_dx = (n[:, 1:, 0] - n[:, :-1, 0])[both_x]
    dny_dy = -(n[1:, :, 1] - n[:-1, :, 1])[both_y]  # image rows go down, world +Y up
    assert both_x.sum() > 500 and both_y.sum() > 500
    assert dnx_dx.mean() > 0.01 and dny_dy.mean() > 0.01


@needs_models
def test_metal_rough_spheres_materials_and_both_render_modes():
    from pbrkit.rendering.realtime import render_realtime
    from pbrkit.rendering.reference import render_reference

    asset = load_gltf(MODELS / "MetalRoughSpheresNoTextures.glb")
    metallic = sorted({round(m.spec.metallic, 3) for m in asset.materials})
    roughness = sorted({round(m.spec.roughness, 3) for m in asset.materials})
    assert len(metallic) >= 7 and len(roughness) >= 7 and metallic[0] == 0.0 and roughness[-1] == 1.0
    # the file is in millimetre-sized units (about 7.4e-3 across): scale it up 1000 times and centre it
    lo = np.min([m.positions.min(axis=0) for m in asset.meshes], axis=0)
    hi = np.max([m.positions.max(axis=0) for m in asset.meshes], axis=0)
    centre = tuple(-500.0 * (lo + hi))
    scene = Scene(camera=Camera(position=(0.0, 0.0, 15.0), look_at=(0.0, 0.0, 0.0), fov=40.0, width=40, height=40),
                  environment=EnvironmentSpec(),
                  objects=(GltfObject(str(MODELS / "MetalRoughSpheresNoTextures.glb"), translation=centre,
                                      scale=1000.0),))
    rt = render_realtime(scene, bake_size=32)
    ref = render_reference(scene, spp=4, occlusion=False)
    assert rt.mask.mean() > 0.2 and np.all(np.isfinite(rt.image)) and np.all(np.isfinite(ref.image))
    assert ref.stats["engine"].startswith("wavefront")


@needs_models
def test_damaged_helmet_textures_emission_and_bounces():
    from pbrkit.rendering.realtime import render_realtime
    from pbrkit.rendering.reference import render_reference

    helmet = MODELS / "DamagedHelmet.glb"
    scene = Scene(camera=Camera(position=(0.0, 0.0, 3.0), look_at=(0.0, 0.0, 0.0), fov=45.0, width=24, height=24),
                  environment=EnvironmentSpec(color=(0.0, 0.0, 0.0)), objects=(GltfObject(str(helmet)),))
    rt = render_realtime(scene, bake_size=16)
    ref = render_reference(scene, spp=2, bounces=1)
    # black environment, no lights: only the emissive texture shines, identically in both modes at the hits
    sel = rt.mask & ref.mask
    assert rt.image[sel].max() > 0.05
    direct = ref.image[sel]
    np.testing.assert_array_less(rt.image[sel] - 1e-9, direct + 1e-9)  # bounces only add light
    geometry = Geometry(scene)
    assert any(m.emissive_texture is not None and m.normal_texture is not None for m in geometry.materials)
    assert all(m.tangents is not None for m in geometry.meshes)  # generated: the file has no TANGENT


# ------------------------------------------------------------------ alpha modes

_UNLIT = {"KHR_materials_unlit": {}}
_NEAREST_CLAMP = {"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}
_SKY = (0.2, 0.3, 0.4)


def _alpha_scene(path, supersample=1):
    cam = Camera(position=(0.0, 0.0, 5.0), look_at=(0.0, 0.0, -1.0), fov=16.0, width=8, height=8,
                 supersample=supersample)
    return Scene(camera=cam, environment=EnvironmentSpec(color=_SKY), objects=(GltfObject(str(path)),))


def _modes():
    from pbrkit.rendering.realtime import render_realtime
    from pbrkit.rendering.reference import render_reference

    return {"realtime": lambda scene: render_realtime(scene, bake_size=8),
            "reference": lambda scene: render_reference(scene, spp=256, seed=1)}


@pytest.mark.parametrize("mode", ["realtime", "reference"])
def test_alpha_mask_cuts_out_where_the_texture_alpha_is_below_the_cutoff(tmp_path, mode):
    """alphaMode MASK (glTF 2.0, "Alpha Coverage"): an unlit quad (KHR_materials_unlit:
    it shows its base colour (1, 0.5, 1)) whose base colour texture is transparent on
    its left half (alpha 0, nearest filtering) and 60 % opaque on its right: with
    alphaCutoff 0.5 the left half shows the sky behind, exactly, and the right half the
    quad; with cutoff 0.7 the whole quad is gone; OPAQUE ignores alpha."""
    texture = np.zeros((2, 2, 4), dtype=np.uint8)
    texture[..., :3] = 255
    texture[:, 1, 3] = 153  # 0.6
    render = _modes()[mode]
    images = {}
    for name, alpha in (("mask", {"alphaMode": "MASK"}), ("strict", {"alphaMode": "MASK", "alphaCutoff": 0.7}),
                        ("opaque", None)):
        path = write_quad_glb(tmp_path / f"{name}.glb", texture=texture, sampler=_NEAREST_CLAMP,
                              material_extras=_UNLIT, alpha=alpha)
        images[name] = render(_alpha_scene(path)).image
    quad = np.array([1.0, 0.5, 1.0])
    left, right = images["mask"][:, :3], images["mask"][:, 5:]
    np.testing.assert_allclose(left, np.broadcast_to(_SKY, left.shape), rtol=1e-6)
    np.testing.assert_allclose(right, np.broadcast_to(quad, right.shape), rtol=1e-6)
    np.testing.assert_allclose(images["strict"], np.broadcast_to(_SKY, images["strict"].shape), rtol=1e-6)
    np.testing.assert_allclose(images["opaque"], np.broadcast_to(quad, images["opaque"].shape), rtol=1e-6)


@pytest.mark.parametrize("mode", ["realtime", "reference"])
def test_alpha_blend_is_coverage_over_what_lies_behind(tmp_path, mode):
    """alphaMode BLEND: the unlit quad at baseColorFactor alpha 0.3 covers 30 % of the rays
    (hashed from each ray): the ground truth is 0.3 quad + 0.7 sky within its own
    standard error per pixel (5 sigma) and overall; real time, 16 sub-pixel rays a pixel,
    is that blend over the image within 5 sigma of its 1024 rays; the same bytes twice."""
    path = write_quad_glb(tmp_path / "blend.glb", material_extras=_UNLIT, alpha={"alphaMode": "BLEND"},
                          base_alpha=0.3)
    scene = _alpha_scene(path, supersample=4 if mode == "realtime" else 1)
    result = _modes()[mode](scene)
    expected = 0.3 * np.array([1.0, 0.5, 1.0]) + 0.7 * np.array(_SKY)
    spread = np.abs(np.array([1.0, 0.5, 1.0]) - _SKY)  # one ray's deviation scale
    if mode == "reference":
        assert np.all(np.abs(result.image - expected) <= 5.0 * result.stderr + 1e-12)
        rays = 256 * 64
    else:
        rays = 16 * 64
    sigma = np.sqrt(0.3 * 0.7 / rays) * spread
    assert np.all(np.abs(result.image.reshape(-1, 3).mean(axis=0) - expected) <= 5.0 * sigma)
    assert np.ptp(result.image[..., 0]) > 0.0  # the coverage differs from pixel to pixel
    np.testing.assert_array_equal(_modes()[mode](scene).image, result.image)


@pytest.mark.parametrize("mode", ["realtime", "reference"])
def test_a_cutout_lets_light_through_to_the_shadow_side(tmp_path, mode):
    """Shadow rays pass the cutouts too: a sun straight above a floor, a MASK quad laid
    flat between them (x in [-0.5, 0.5], z in [-1.5, -0.5]) transparent where x < 0: the
    floor under that half is lit as without the quad, under the other half not at all
    (a black sky: the sun alone lights it; the quad emits nothing; the camera looks under
    the quad)."""
    from pbrkit.rendering.scene import Light

    texture = np.zeros((2, 2, 4), dtype=np.uint8)
    texture[..., :3] = 255
    texture[:, 1, 3] = 255
    flat = np.array([[1, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]], dtype=float)  # (x, y, 0) -> (x, 0, -y)
    path = write_quad_glb(tmp_path / "mask.glb", texture=texture, sampler=_NEAREST_CLAMP,
                          alpha={"alphaMode": "MASK"}, node_matrix=flat, emissive=(0.0, 0.0, 0.0))
    cam = Camera(position=(3.0, -0.6, -1.0), look_at=(0.0, -1.0, -1.0), fov=40.0, width=24, height=24)
    floor = MaterialSpec(name="floor", metallic=0.0, roughness=1.0, base_color=(0.5, 0.5, 0.5))
    sun = Light(type="directional", direction=(0.0, -1.0, 0.0), intensity=2.0)
    ground = Plane(point=(0.0, -1.0, 0.0), normal=(0.0, 1.0, 0.0), material="floor")

    def scene(objects):
        return Scene(camera=cam, environment=EnvironmentSpec(color=(0.0, 0.0, 0.0)),
                     materials={"default": MaterialSpec(), "floor": floor}, lights=(sun,), objects=objects)

    render = _modes()[mode]
    with_quad = render(scene((GltfObject(str(path)), ground))).image.reshape(-1, 3)
    without = render(scene((ground,))).image.reshape(-1, 3)
    d = cam.ray_directions()[:, :, 0].reshape(-1, 3)
    t = (-1.0 - cam.position[1]) / d[:, 1]
    p = np.asarray(cam.position) + t[:, None] * d
    under = (p[:, 2] > -1.45) & (p[:, 2] < -0.55) & (t > 0)
    lit = under & (p[:, 0] > -0.45) & (p[:, 0] < -0.05)
    dark = under & (p[:, 0] > 0.05) & (p[:, 0] < 0.45)
    assert lit.sum() > 5 and dark.sum() > 5 and np.all(without[lit | dark] > 0.01)
    np.testing.assert_allclose(with_quad[lit], without[lit], rtol=1e-9)
    assert np.all(with_quad[dark] == 0.0)


def test_vertex_colours_multiply_the_base_colour(tmp_path):
    """COLOR_0 (glTF 2.0, "Meshes": VEC3 / VEC4, float or normalised unsigned bytes) times
    the base colour at each hit, interpolated like the other attributes: an unlit quad
    (its base colour as emission) whose corners are coloured shows, at the centre of
    each triangle's corner pixels, the factor times the corner's colour; a VEC4 colour's
    alpha multiplies the base colour's alpha (a MASK cutout where it falls below the
    cutoff); a colour above 1 is refused."""
    import pygltflib as g

    from pbrkit.core.errors import InputError
    from pbrkit.rendering.geometry import Geometry
    from pbrkit.rendering.primary import _primary

    def quad(path, colors, ctype, normalized=False, alpha=None):
        path = write_quad_glb(path, material_extras=_UNLIT, alpha=alpha)
        gltf = g.GLTF2().load(str(path))
        blob = gltf.binary_blob()
        data = np.asarray(colors, dtype=np.float32 if ctype == g.FLOAT else np.uint8)
        offset = len(blob) + (-len(blob) % 4)
        blob = blob + b"\0" * (offset - len(blob)) + data.tobytes()
        gltf.bufferViews.append(g.BufferView(buffer=0, byteOffset=offset, byteLength=data.nbytes))
        gltf.accessors.append(g.Accessor(bufferView=len(gltf.bufferViews) - 1, componentType=ctype, count=4,
                                         type=g.VEC4 if data.shape[1] == 4 else g.VEC3, normalized=normalized))
        gltf.meshes[0].primitives[0].attributes.COLOR_0 = len(gltf.accessors) - 1
        gltf.buffers[0].byteLength = len(blob)
        gltf.set_binary_blob(blob)
        gltf.save_binary(str(path))
        return path

    colors = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]]
    for name, path in (("float", quad(tmp_path / "f.glb", colors, g.FLOAT)),
                       ("ubyte", quad(tmp_path / "u.glb", np.c_[np.asarray(colors) * 255, [255] * 4],
                                      g.UNSIGNED_BYTE, normalized=True))):
        scene = quad_scene(path, 2, 2, fov=10.0)  # the quad fills the view; 4 pixels
        geometry = Geometry(scene)
        prim = _primary(scene, geometry)
        s = prim.surface
        # unlit: the base colour (1, 0.5, 1) shows as emission, times the interpolated colour
        shown = s.emissive / np.array([1.0, 0.5, 1.0])
        assert shown.shape == (4, 3) and np.all(shown >= -1e-12) and np.all(shown <= 1.0 + 1e-12), name
        assert np.ptp(shown, axis=0).min() > 0.2, name  # the four pixels see different colours
        # the colour at each hit is the corners' colours mixed by the hit's barycentrics: the quad
        # maps (x, y) in [-1, 1]^2 to uv bilinearly; here from the corners' colours at each hit's
        # position (red at (-1, -1), green at (1, -1), blue at (1, 1), white at (-1, 1)), triangle
        # (0, 1, 2) below the diagonal y = x, (0, 2, 3) above
        x, y = s.p[:, 0], s.p[:, 1]
        corner = np.asarray(colors, dtype=np.float64)
        u, w = (x + 1.0) / 2.0, (y + 1.0) / 2.0
        below = y <= x
        expected = np.where(below[:, None], (1 - u)[:, None] * corner[0] + (u - w)[:, None] * corner[1]
                            + w[:, None] * corner[2], (1 - w)[:, None] * corner[0] + (w - u)[:, None] * corner[3]
                            + u[:, None] * corner[2])
        np.testing.assert_allclose(shown, expected, atol=2e-6)
    # a VEC4 colour's alpha multiplies the base colour's under alphaMode MASK: alpha 0.2 at the
    # bottom corners, 0.9 at the top ones, linear in y over the quad, cut below 0.5 (y < -1/7)
    from pbrkit.rendering.gltf import load_gltf

    cut = quad(tmp_path / "a.glb", np.c_[colors, [0.2, 0.2, 0.9, 0.9]], g.FLOAT, alpha={"alphaMode": "MASK"})
    assert not load_gltf(cut).notes
    scene = quad_scene(cut, 16, 16, fov=30.0)
    prim = _primary(scene, Geometry(scene))
    origin = np.asarray(scene.camera.position)
    t = (-1.0 - origin[2]) / prim.dirs[:, 2]  # the quad's plane z = -1
    x, y = (origin[None, :2] + t[:, None] * prim.dirs[:, :2]).T
    alpha_y = 0.2 + 0.7 * (y + 1.0) / 2.0
    inside = (np.abs(x) < 0.999) & (np.abs(y) < 0.999) & (np.abs(alpha_y - 0.5) > 1e-3)
    assert inside.sum() > 50 and (alpha_y[inside] < 0.5).any() and (alpha_y[inside] >= 0.5).any()
    np.testing.assert_array_equal(prim.hit[inside], alpha_y[inside] >= 0.5)
    bad = quad(tmp_path / "b.glb", [[2.0, 0.0, 0.0]] * 4, g.FLOAT)
    with pytest.raises(InputError, match=r"COLOR_0 has values outside \[0, 1\]"):
        load_gltf(bad)
