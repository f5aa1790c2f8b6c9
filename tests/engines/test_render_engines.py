"""``pbrkit render --engine``: the real-time IBL as Filament, the Khronos Sample Viewer
and three.js evaluate it.  Each engine's image of its own ``--target`` bake is
compared with these modes inside the engine (tests/engines/test_engine_render_*.py); the
tests here need no engine: properties of the published models that the
implementation must keep, and the pieces checked one by one."""

from __future__ import annotations

import json

import numpy as np
import pytest

from pbrkit.engines.three import multiple_scattering_fdez_aguera
from pbrkit.rendering.realtime import (
    ENGINES,
    render_realtime,
    specular_dominant_direction,
    three_roughness,
)
from pbrkit.rendering.scene import load_scene


def _scene(tmp_path, metallic, base, roughness, color=(1.0, 1.0, 1.0), size=16):
    scene = {"camera": {"width": size, "height": size, "position": [0, 0, 4], "fov": 30},
             "environment": {"color": list(color)},
             "materials": {"m": {"roughness": roughness, "base_color": list(base), "metallic": metallic}},
             "objects": [{"type": "sphere", "material": "m"}]}
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    return load_scene(path)


@pytest.mark.parametrize("engine", ["filament", "khronos", "three", "babylon"])
@pytest.mark.parametrize("roughness", [0.2, 0.6, 1.0])
def test_a_white_metal_in_a_white_furnace_reflects_everything(tmp_path, engine, roughness):
    """Each engine compensates the energy single scattering loses (Filament: 1 + f0
    (1/DFG2 - 1); the viewer and three.js: Fdez-Aguera's FmsEms), so a white metal
    (f0 = 1) under constant radiance 1 returns exactly 1; pbrkit's own split sum
    without compensation returns the single-scattering albedo DFG2 < 1."""
    scene = _scene(tmp_path, 1.0, (1.0, 1.0, 1.0), roughness)
    image = render_realtime(scene, bake_size=16, engine=engine)
    inner = image.mask
    np.testing.assert_allclose(image.image[inner], 1.0, atol=2e-3)
    plain = render_realtime(scene, bake_size=16).image[inner]
    assert plain.mean() < 1.0 - (0.003 if roughness < 0.5 else 0.05)


def test_fdez_aguera_terms():
    """FssEss + FmsEms is 1 for f0 = 1 (energy conserving) and FmsEms is 0 when the
    single-scattering lobe loses nothing (A + B = 1); for f0 = 0 and any table entry
    the multiple-scattering term is E_ms FssEss / (21 - E_ms) (F_avg = 1/21)."""
    a = np.array([0.3, 0.5, 0.9, 0.2])
    b = np.array([0.1, 0.2, 0.1, 0.05])
    ss, ms = multiple_scattering_fdez_aguera(1.0, a, b)
    np.testing.assert_allclose(ss + ms, 1.0, atol=1e-12)
    ss, ms = multiple_scattering_fdez_aguera(0.5, a, 1.0 - a)
    np.testing.assert_allclose(ms, 0.0, atol=1e-15)
    ss, ms = multiple_scattering_fdez_aguera(0.0, a, b)
    e_ms = 1.0 - (a + b)
    np.testing.assert_allclose(ms, e_ms * b / (21.0 - e_ms), rtol=1e-12)


def test_dominant_direction_moves_from_the_mirror_to_the_normal():
    n = np.array([[0.0, 0.0, 1.0]] * 3)
    r = np.array([[1.0, 0.0, 0.0]] * 3)
    d = specular_dominant_direction(n, r, np.array([0.0, 0.5, 1.0]))
    np.testing.assert_allclose(d[0], r[0])
    np.testing.assert_allclose(d[1], r[1] * (1 - 0.5 ** 4) + n[1] * 0.5 ** 4)  # mix weight alpha^2 = r^4
    np.testing.assert_allclose(d[2], n[2])


def test_three_roughness_adds_the_normals_screen_space_change(tmp_path):
    """three.js adds max |dn| over a pixel pair to max(r, 0.045): on a sphere that
    fills more of the image the normals change less per pixel, so the term shrinks
    (about as 1 / size); a constant normal adds nothing."""
    small, large = (_scene(tmp_path, 0.0, (0.5, 0.5, 0.5), 0.0, size=s) for s in (16, 64))
    extra = []
    for scene in (small, large):
        from pbrkit.rendering.geometry import Geometry
        from pbrkit.rendering.primary import _primary

        prim = _primary(scene, Geometry(scene))
        r = three_roughness(scene.camera, prim.rows, prim.surface.n, np.zeros(prim.rows.size))
        assert np.all(r >= 0.045) and np.all(r <= 1.0)
        extra.append(np.median(r) - 0.045)
    assert extra[0] > 2.5 * extra[1] > 0.0
    flat = three_roughness(small.camera, np.arange(16 * 16), np.tile([0.0, 0.0, 1.0], (256, 1)), np.full(256, 0.3))
    np.testing.assert_allclose(flat, 0.3)


def test_unknown_engine_is_refused(tmp_path):
    with pytest.raises(ValueError, match="unknown engine 'unity'"):
        render_realtime(_scene(tmp_path, 0.0, (0.5, 0.5, 0.5), 0.5), bake_size=16, engine="unity")
    assert ENGINES[0] == "pbrkit"


def test_engine_mode_on_a_bake_without_its_target_is_refused_cleanly(tmp_path):
    from typer.testing import CliRunner

    from pbrkit.cli import app
    from pbrkit.io.pfm import write_pfm

    write_pfm(tmp_path / "sky.pfm", np.full((16, 32, 3), 0.5, np.float32))
    bake_dir = tmp_path / "bake"
    runner = CliRunner()
    result = runner.invoke(app, ["bake", str(tmp_path / "sky.pfm"), "-o", str(bake_dir), "--size", "16",
                                 "--min-size", "4", "--irradiance-size", "4", "--lut-size", "8", "-q"])
    assert result.exit_code == 0, result.output
    for engine in ("filament", "three", "babylon"):
        out = tmp_path / f"{engine}.png"
        result = runner.invoke(app, ["render", "sphere", "-o", str(out), "--env", str(bake_dir), "--engine", engine,
                                     "--width", "8", "--height", "8", "-q"])
        assert result.exit_code == 1 and not out.exists()
        assert f"the bake has no {engine} target (bake it with --target {engine})" in result.stderr


def _normal_mapped_quad(tmp_path, mapped=True):
    """A unit quad facing +Z (TANGENT +X) with an 8 x 8 tangent-space normal texture of
    bumps tilted up to 35 degrees (or none), under a camera looking down -Z at it."""
    from pbrkit.io.gltf_writer import GltfPrimitive, GltfTexture, write_glb

    x = (np.arange(8) + 0.5) / 8 * 2 * np.pi
    tilt = 0.7 * np.stack(np.meshgrid(np.cos(x), np.sin(x), indexing="xy"), -1)
    texel = np.concatenate([tilt, np.ones((8, 8, 1))], -1)
    texel /= np.linalg.norm(texel, axis=-1, keepdims=True)
    quad = GltfPrimitive(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.0]]), np.tile([0.0, 0.0, 1.0], (4, 1)),
                         np.array([[0, 1, 2], [1, 3, 2]]), texcoords=np.array([[0, 1], [1, 1], [0, 0], [1, 0.0]]),
                         tangents=np.tile([1.0, 0.0, 0.0, 1.0], (4, 1)), roughness=0.3,
                         normal_texture={"index": 0} if mapped else None)
    write_glb(tmp_path / "quad.glb", [quad], textures=[GltfTexture(np.rint(255 * (0.5 * texel + 0.5)).astype(int))])
    scene = {"camera": {"width": 16, "height": 16, "position": [0.5, 0.5, 2.5], "look_at": [0.5, 0.5, 0.0],
                        "fov": 20}, "environment": {"color": [0.5, 0.5, 0.5]},
             "objects": [{"type": "gltf", "file": "quad.glb"}]}
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    return load_scene(tmp_path / "scene.json")


def test_three_roughness_takes_the_normal_before_normal_mapping(tmp_path):
    """three.js r187 takes ``geometryRoughness`` from the screen-space change of
    ``nonPerturbedNormal``, the normal before the normalMap (``lights_physical_fragment``):
    on a flat normal-mapped quad ``--engine three`` adds nothing to max(r, 0.045) (before,
    it took the mapped normals' change, which the bumps make large).  The surface keeps
    that normal (:attr:`~pbrkit.rendering.geometry.Surface.n_unmapped`) only where a material
    has a normalTexture."""
    from unittest import mock

    import pbrkit.rendering.realtime as realtime
    from pbrkit.rendering.geometry import Geometry
    from pbrkit.rendering.primary import _primary

    scene = _normal_mapped_quad(tmp_path)
    prim = _primary(scene, Geometry(scene))
    s = prim.surface
    np.testing.assert_allclose(s.n_unmapped, np.tile([0.0, 0.0, 1.0], (len(s.n), 1)), atol=1e-12)
    assert np.all(s.n[:, 2] < 0.999)  # mapped
    bumpy = three_roughness(scene.camera, prim.rows, s.n, s.roughness)
    assert np.median(bumpy - 0.3) > 0.05  # what the mapped normals' change would add
    seen = []

    def spy(camera, rows, normals, roughness):
        seen.append(normals)
        return three_roughness(camera, rows, normals, roughness)

    with mock.patch.object(realtime, "three_roughness", spy):
        render_realtime(scene, bake_size=16, engine="three")
    np.testing.assert_allclose(seen[0], s.n_unmapped, atol=1e-12)
    np.testing.assert_allclose(three_roughness(scene.camera, prim.rows, seen[0], s.roughness), 0.3, atol=1e-12)
    (tmp_path / "plain").mkdir()
    plain = _normal_mapped_quad(tmp_path / "plain", mapped=False)
    assert _primary(plain, Geometry(plain)).surface.n_unmapped is None
