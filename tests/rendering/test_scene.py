"""Scene files, built-in scenes, the camera convention and punctual lights."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from pbrkit.core.errors import InputError
from pbrkit.rendering.lights import (
    Light,
    falloff_khr,
    falloff_ue4,
    spot_attenuation,
    window_ue4,
)
from pbrkit.rendering.scene import (
    Camera,
    EnvironmentSpec,
    GltfObject,
    MaterialSpec,
    Sphere,
    builtin_scene,
    load_scene,
    scene_from_dict,
    trs_matrix,
)
from pbrkit.rendering.sources import resolve_scene

SCENE_TOML = """
[camera]
position = [1.0, 2.0, 6.0]
look_at = [0.0, 0.5, 0.0]
fov = 35.0
width = 40
height = 30
supersample = 2

[environment]
color = [0.5, 0.25, 1.0]
intensity = 2.0
rotation = 30.0

[materials.gold]
model = "cook_torrance"
conductor = "gold"
roughness = 0.3
fresnel = "exact-conductor"

[materials.paint]
base_color = [0.8, 0.1, 0.1]
roughness = 0.6
masking = "separable"

[[objects]]
type = "sphere"
center = [0.0, 1.0, 0.0]
radius = 1.0
material = "gold"

[[objects]]
type = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 2.0, 0.0]
material = "paint"

[[lights]]
type = "spot"
position = [0.0, 4.0, 0.0]
direction = [0.0, -1.0, 0.0]
intensity = 50.0
range = 10.0
inner_cone_angle = 0.2
outer_cone_angle = 0.5
"""


# ------------------------------------------------------------------ camera


def test_camera_rays_pass_through_pixel_centres_row_zero_top():
    # An independent construction for a camera at the origin looking down -Z with +Y up:
    # pixel (i, j) centre at x = (2 (j + 0.5) / W - 1) t a, y = (1 - 2 (i + 0.5) / H) t on the plane z = -1.
    cam = Camera(position=(0, 0, 0), look_at=(0, 0, -1), up=(0, 1, 0), fov=50.0, width=8, height=6)
    d = cam.ray_directions()[:, :, 0]
    t = math.tan(math.radians(25.0))
    i, j = np.meshgrid(np.arange(6), np.arange(8), indexing="ij")
    expected = np.stack([(2 * (j + 0.5) / 8 - 1) * t * 8 / 6, (1 - 2 * (i + 0.5) / 6) * t, -np.ones((6, 8))], axis=-1)
    expected /= np.linalg.norm(expected, axis=-1, keepdims=True)
    np.testing.assert_allclose(d, expected, atol=1e-14)
    assert d[0, 0, 1] > 0 and d[-1, 0, 1] < 0  # row 0 is the top
    assert d[0, 0, 0] < 0 and d[0, -1, 0] > 0  # column 0 is the left
    # the corner ray reaches the image edge at half the field of view (rows, cols = 0, 0)
    corner = cam.ray_directions(np.array([0.0]), np.array([0.0]))[0]
    assert corner[1] / -corner[2] == pytest.approx(t)
    assert corner[0] / -corner[2] == pytest.approx(-t * 8 / 6)


def test_camera_project_inverts_rays_and_supersampling_grid():
    cam = Camera(position=(1, 2, 3), look_at=(0, 0, 0), up=(0, 1, 0), fov=40.0, width=10, height=7, supersample=3)
    d = cam.ray_directions()
    assert d.shape == (7, 10, 9, 3)
    rows, cols = cam.project(np.asarray(cam.position) + 2.5 * d)
    off = cam.subpixel_offsets()
    np.testing.assert_allclose(rows, np.broadcast_to(np.arange(7)[:, None, None] + off[None, None, :, 0], rows.shape),
                               atol=1e-9)
    np.testing.assert_allclose(cols, np.broadcast_to(np.arange(10)[None, :, None] + off[None, None, :, 1], cols.shape),
                               atol=1e-9)
    np.testing.assert_allclose(np.sort(np.unique(off[:, 0])), [1 / 6, 0.5, 5 / 6])


@pytest.mark.parametrize("kwargs, message", [
    (dict(fov=0.0), "fov"), (dict(fov=180.0), "fov"), (dict(width=0), "width"), (dict(height=1.5), "height"),
    (dict(supersample=17), "supersample"), (dict(look_at=(0, 0, 5)), "look_at"), (dict(up=(0, 0, 2)), "parallel"),
    (dict(position=(0, np.nan, 0)), "position"),
])
def test_camera_validation(kwargs, message):
    base = dict(position=(0, 0, 5), look_at=(0, 0, 0), up=(0, 1, 0))
    base.update(kwargs)
    with pytest.raises(ValueError, match=message):
        Camera(**base)


# ------------------------------------------------------------------ files


def test_toml_and_json_scene_files_agree(tmp_path):
    import tomllib

    toml_path = tmp_path / "s.toml"
    toml_path.write_text(SCENE_TOML)
    json_path = tmp_path / "s.json"
    json_path.write_text(json.dumps(tomllib.loads(SCENE_TOML)))
    a, b = load_scene(toml_path), load_scene(json_path)
    assert a.camera == b.camera and a.lights == b.lights and a.objects == b.objects
    assert a.camera.supersample == 2 and a.camera.width == 40
    assert a.environment.color == (0.5, 0.25, 1.0) and a.environment.intensity == 2.0
    gold = a.materials["gold"]
    assert gold.metallic == 1.0 and gold.eta is not None and gold.fresnel == "exact-conductor"
    assert a.materials["paint"].masking == "separable"
    assert a.objects[1].normal == pytest.approx((0.0, 1.0, 0.0))  # normalised
    spot = a.lights[0]
    assert spot.type == "spot" and spot.range == 10.0 and spot.outer_cone_angle == 0.5


def test_relative_paths_resolve_against_the_scene_folder(tmp_path):
    sub = tmp_path / "scenes"
    sub.mkdir()
    (tmp_path / "env.hdr").write_bytes(b"placeholder")
    (sub / "s.toml").write_text('[environment]\nfile = "../env.hdr"\n[[objects]]\ntype = "sphere"\n')
    scene = load_scene(sub / "s.toml")
    assert scene.environment.file == str(sub / "../env.hdr")


@pytest.mark.parametrize("text, fragment", [
    ("[camera]\nfov = -3\n[[objects]]\ntype = 'sphere'\n", "camera.fov"),
    ("[camera]\nzoom = 2\n[[objects]]\ntype = 'sphere'\n", "unknown key 'zoom'"),
    ("[[objects]]\ntype = 'cube'\n", "unknown type 'cube'"),
    ("[[objects]]\ntype = 'sphere'\nradius = -1\n", "radius"),
    ("[[objects]]\ntype = 'sphere'\nmaterial = 'nope'\n", "material 'nope'"),
    ("[materials.a]\nroughness = 2\n[[objects]]\ntype = 'sphere'\n", "roughness"),
    ("[materials.a]\nmodel = 'phong'\n[[objects]]\ntype = 'sphere'\n", "unknown model"),
    ("[materials.a]\nmodel = 'ue4'\nmasking = 'separable'\n[[objects]]\ntype = 'sphere'\n", "cook_torrance"),
    ("[materials.a]\nmodel = 'cook_torrance'\nfresnel = 'exact-conductor'\n[[objects]]\ntype = 'sphere'\n",
     "eta and k"),
    ("[materials.a]\nfresnel = 'exact-conductor'\n[[objects]]\ntype = 'sphere'\n", "model 'gltf' fixes it"),
    ("[environment]\nfile = 'missing.hdr'\n[[objects]]\ntype = 'sphere'\n", "does not exist"),
    ("[environment]\ncolor = [1, 1, 1]\nbake = 'x'\n[[objects]]\ntype = 'sphere'\n", "does not exist"),
    ("[[objects]]\ntype = 'gltf'\nfile = 'missing.glb'\n", "does not exist"),
    ("[[lights]]\ntype = 'spot'\ninner_cone_angle = 1.0\nouter_cone_angle = 0.5\n[[objects]]\ntype = 'sphere'\n",
     "cone"),
    ("[[lights]]\ntype = 'area'\n[[objects]]\ntype = 'sphere'\n", "unknown light type"),
    ("[camera]\nwidth = 10\n", "no objects"),
    ("[camera\nwidth = 10\n", "invalid TOML"),
])
def test_scene_file_errors_are_one_line_and_name_the_file(tmp_path, text, fragment):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(InputError) as info:
        load_scene(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(str(path))
    assert fragment in message


def test_scene_suffix_and_missing_file(tmp_path):
    with pytest.raises(InputError, match="toml or .json"):
        load_scene(tmp_path / "scene.yaml")
    with pytest.raises(InputError, match="no such scene file"):
        resolve_scene(tmp_path / "absent.toml")


def test_material_models_fix_their_terms():
    ue4 = MaterialSpec(model="ue4")
    assert (ue4.masking, ue4.fresnel) == ("schlick-ggx-ue4", "ue4-sg")
    assert MaterialSpec(model="filament", diffuse="burley").diffuse == "burley"
    with pytest.raises(ValueError, match="fixes it: lambert"):
        MaterialSpec(model="ue4", diffuse="burley")
    gold = MaterialSpec(conductor="gold")
    from pbrkit.brdf.fresnel import f_conductor

    eta, k = np.array(gold.eta), np.array(gold.k)
    np.testing.assert_allclose(gold.base_color, np.minimum(f_conductor(1.0, eta, k), 1.0))


def test_gltf_object_transform_is_t_r_s():
    # rotation by 90 degrees about +Y (quaternion (0, sin 45, 0, cos 45)): +X -> -Z
    obj = GltfObject(file="x.glb", translation=(1, 2, 3), rotation=(0, math.sin(math.pi / 4), 0,
                                                                   math.cos(math.pi / 4)), scale=2.0)
    m = obj.matrix()
    np.testing.assert_allclose(m @ [1, 0, 0, 1], [1, 2, 1, 1], atol=1e-12)
    np.testing.assert_allclose(trs_matrix((0, 0, 0), (0, 0, 0, 1), (1, 2, 3)), np.diag([1, 2, 3, 1]))
    with pytest.raises(ValueError, match="unit quaternion"):
        GltfObject(file="x.glb", rotation=(0, 0, 0, 2))


def test_builtin_sphere_grid_layout():
    scene = builtin_scene("spheres", 64, 64)
    assert len(scene.objects) == 49
    cam = scene.camera
    centres = np.array([o.center for o in scene.objects])
    rows, cols = cam.project(centres)
    rough = np.array([scene.materials[o.material].roughness for o in scene.objects])
    metal = np.array([scene.materials[o.material].metallic for o in scene.objects])
    # roughness grows left to right within each row, metallic top to bottom within each column
    for m in np.unique(metal):
        same = metal == m
        assert np.all(np.diff(rough[same][np.argsort(cols[same])]) > 0)
        assert np.ptp(rows[same]) < 1e-9
    for r in np.unique(rough):
        same = rough == r
        assert np.all(np.diff(metal[same][np.argsort(rows[same])]) > 0)
    assert np.unique(metal).size == 7 and np.unique(rough).size == 7
    radius_px = 1.0 / (cam.position[2] * math.tan(math.radians(cam.fov / 2))) * 32
    assert np.all((cols - radius_px > 0) & (cols + radius_px < 64) & (rows - radius_px > 0) & (rows + radius_px < 64))
    assert builtin_scene("sphere").objects == (Sphere(center=(0, 0, 0), radius=1.0, material="ball"),)
    with pytest.raises(ValueError, match="built-in"):
        builtin_scene("cornell")


def test_scene_from_dict_accepts_in_memory_environments():
    env = EnvironmentSpec(equirect=np.ones((4, 8, 3)))
    scene = scene_from_dict({"objects": [{"type": "sphere"}]})
    assert scene.environment.file is None
    with pytest.raises(ValueError, match="only one"):
        EnvironmentSpec(color=(1, 1, 1), equirect=np.ones((4, 8, 3)))
    with pytest.raises(ValueError, match="H, 2H, 3"):
        EnvironmentSpec(equirect=np.ones((4, 4, 3)))
    assert env.equirect.shape == (4, 8, 3)


# ------------------------------------------------------------------ lights


def test_khr_window_and_falloffs():
    d = np.array([0.5, 1.0, 2.0, 3.0, 4.0, 5.0])
    # KHR_lights_punctual: clamp(1 - (d / range)^4, 0, 1)^2 / d^2
    expected = np.clip(1 - (d / 4.0) ** 4, 0, 1) ** 2 / d**2
    np.testing.assert_allclose(falloff_khr(d, 4.0), expected)
    np.testing.assert_allclose(falloff_khr(d, 0.0), 1 / d**2)  # no range: plain inverse square
    # Karis 2013 eq. 9: saturate(1 - (d / r)^4)^2 / (d^2 + 1)
    np.testing.assert_allclose(falloff_ue4(d, 4.0), np.clip(1 - (d / 4.0) ** 4, 0, 1) ** 2 / (d**2 + 1))
    assert window_ue4(4.0, 4.0) == 0.0 and window_ue4(0.0, 4.0) == 1.0


def test_spot_attenuation_matches_the_khr_cone():
    inner, outer = 0.2, 0.5
    ci, co = math.cos(inner), math.cos(outer)
    assert spot_attenuation(math.cos(0.1), ci, co) == 1.0
    assert spot_attenuation(math.cos(0.6), ci, co) == 0.0
    mid = math.cos(0.35)
    assert spot_attenuation(mid, ci, co) == pytest.approx(((mid - co) / (ci - co)) ** 2)


def test_light_validation():
    with pytest.raises(ValueError, match="intensity"):
        Light(type="point", intensity=-1.0)
    with pytest.raises(ValueError, match="direction"):
        Light(type="directional", direction=(0, 0, 0))
    with pytest.raises(ValueError, match="range"):
        Light(type="point", range=0.0)
    assert Light(type="directional", direction=(0, -2, 0)).direction == (0.0, -1.0, 0.0)
