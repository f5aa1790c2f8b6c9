"""pbrkit's three.js module (``src/pbrkit/js/pbrkit-three.js``) inside three.js
0.187.0, in headless Chromium (issue 10).

A direction-coded RGBA16F cube chain (each level a different smooth function of
direction) is written with :func:`pbrkit.io.ktx2.write_ktx2`, loaded with the
shipped module on ``pages/three.html``, and

* every texel of every level of every face is read back from the WebGL texture
  three uploaded (sampled at texel centres, NEAREST, in a raw WebGL2 pass on
  three's own context) and compared with the file's float16 texels;
* three's own background and a MeshBasicMaterial mirror show which texel three
  samples for a world direction d: that of (-d.x, d.y, d.z), the x mirror the
  three bake is written with;
* MeshStandardMaterial on a constant-per-level chain shows which level three
  reads at roughness r: lod = (M - 1) r (2 - r), so level m of the three bake sits
  at r_m = 1 - sqrt(1 - m / (M - 1)).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from engine_pages import ENGINES, bake_target, needs_engines, run_page

from pbrkit.ibl.cubemap import cube_texel_directions
from pbrkit.io.ktx2 import read_ktx2, write_ktx2

pytestmark = needs_engines()

N, M = 16, 5  # face size of level 0, number of levels (16 .. 1)
DIRS = [(0.8, 0.3, 0.5), (-0.7, -0.2, 0.65), (0.6, 0.7, -0.4), (-0.9, 0.1, -0.3), (0.55, -0.6, -0.58)]

def run_engine_page(page, data, query):
    return run_page(page, data=data, query=query, timeout=120)


def level_function(m, d):
    """Level m of the direction-coded chain at unit directions d (..., 3): RGBA."""
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    return np.stack([0.5 + 0.4 * x + 0.05 * m, 0.5 + 0.3 * y - 0.04 * m,
                     0.6 + 0.35 * z + 0.03 * m * x * y, np.full_like(x, 1.0 + m)], axis=-1)


def mirror_x(d):
    return d * np.array([-1.0, 1.0, 1.0])


@pytest.fixture(scope="module")
def three_report(tmp_path_factory):
    data = tmp_path_factory.mktemp("three")
    levels = [level_function(m, cube_texel_directions(N >> m)).astype(np.float32) for m in range(M)]
    write_ktx2(data / "cube.ktx2", levels, "R16G16B16A16_SFLOAT", cube=True)
    # Constant per level: R = 1 + m, G = 1, B = 1 except 0 on the last level (see
    # test_standard_material_reads_level_m_at_filaments_roughness).
    const = [np.broadcast_to(np.array([1.0 + m, 1.0, 0.0 if m == M - 1 else 1.0, 1.0], np.float32),
                             (6, N >> m, N >> m, 4)) for m in range(M)]
    write_ktx2(data / "levels.ktx2", const, "R16G16B16A16_SFLOAT", cube=True)
    write_ktx2(data / "bad_2d.ktx2", [np.ones((16, 16, 4), np.float32)], "R16G16B16A16_SFLOAT")
    write_ktx2(data / "bad_rgba32.ktx2", [np.ones((6, 4, 4, 4), np.float32)], "R32G32B32A32_SFLOAT", cube=True)
    roughness = [1 - np.sqrt(1 - m / (M - 1)) for m in (1, 2)] + [0.3]
    query = "&".join([
        "cube=cube.ktx2", "levels=levels.ktx2", "bad=bad_2d.ktx2,bad_rgba32.ktx2",
        "dirs=" + json.dumps([list(np.array(d) / np.linalg.norm(d)) for d in DIRS]),
        "roughness=" + json.dumps(roughness),
    ])
    report = run_engine_page("three.html", data, query)
    return report["result"], read_ktx2(data / "cube.ktx2")[1], roughness


def test_module_builds_a_pmrem_free_half_float_cube(three_report):
    result, _, _ = three_report
    assert result["three"] == "187"
    t = result["texture"]
    assert t["isCubeTexture"] and t["isCompressedCubeTexture"] and t["isPMREMTexture"]
    assert t["format"] == t["constants"]["RGBAFormat"] and t["type"] == t["constants"]["HalfFloatType"]
    assert t["flipY"] is False and t["generateMipmaps"] is False
    assert t["minFilter"] == t["constants"]["LinearMipmapLinearFilter"]
    assert (t["levels"], t["size"]) == (M, N)
    assert result["gl"]["immutableLevels"] == M
    assert result["gl"]["minFilter"] == result["gl"]["LINEAR_MIPMAP_LINEAR"]


def test_module_rejects_what_it_cannot_load(three_report):
    rejected = three_report[0]["rejected"]
    assert rejected["bad_2d.ktx2"] is not None and "faceCount 1" in rejected["bad_2d.ktx2"]
    assert rejected["bad_rgba32.ktx2"] is not None and "vkFormat 109" in rejected["bad_rgba32.ktx2"]


def test_every_texel_on_the_gpu_equals_the_file(three_report):
    result, levels, _ = three_report
    texels = np.asarray(result["texels"], dtype=np.float64)
    expected = np.concatenate([lv.reshape(-1) for lv in levels]).astype(np.float64)
    assert texels.shape == expected.shape
    diff = np.abs(texels - expected)
    assert diff.max() == 0.0, f"max |GPU - file| = {diff.max()}"
    # The levels really differ (alpha codes the level), so a wrong level would show.
    assert sorted(set(texels[3::4])) == [1.0 + m for m in range(M)]


@pytest.mark.parametrize("kind", ["background", "basic"])
def test_three_samples_the_texel_of_minus_x(three_report, kind):
    """three shows, for world direction d, the texel of (-d.x, d.y, d.z): the three
    bake must be (and is) stored mirrored in x.  Background: d = view direction;
    MeshBasicMaterial mirror facing the camera: d = reflect(view, n) = -view."""
    result, _, _ = three_report
    dirs = np.array([np.array(d) / np.linalg.norm(d) for d in DIRS])
    sampled = dirs if kind == "background" else -dirs
    got = np.asarray(result[kind])[:, :3]
    as_mirrored = level_function(0, mirror_x(sampled))[:, :3]
    as_is = level_function(0, sampled)[:, :3]
    err_mirrored = np.abs(got - as_mirrored).max()
    err_as_is = np.abs(got - as_is).max()
    assert err_mirrored < 0.01, (kind, err_mirrored, got.tolist())
    assert err_as_is > 0.3, (kind, err_as_is)


def test_basic_material_ignores_a_pmrem_marked_cube(three_report):
    """three r187's MeshBasic/Lambert/Phong env-map chunk samples only non-PMREM
    cubes: with the module's texture (isPMREMTexture) the white plane stays white,
    which is why pbrkit-three.js offers ``{ pmrem: false }`` for those materials."""
    got = np.asarray(three_report[0]["basicPMREM"])[:, :3]
    assert np.array_equal(got, np.ones_like(got))


def test_standard_material_reads_level_m_at_filaments_roughness(three_report):
    """Metal (F0 = 1) plane facing the camera, environment constant per level:
    pixel = c(lod) SS + MS E(c_last) per channel, with SS, MS channel-independent.
    B (1 on every level but the last, 0 there) gives SS; G (1 everywhere) gives
    MS E(1); R (1 + m) then gives the lod three read."""
    result, _, roughness = three_report
    for r, (red, green, blue, _) in zip(roughness, result["standard"], strict=True):
        ss, ms = blue, green - blue
        lod = (red - M * ms) / ss - 1.0
        assert abs(lod - (M - 1) * r * (2 - r)) < 0.005, (r, lod)
    lods = [(red - M * (g - b)) / b - 1 for red, g, b, _ in result["standard"]]
    assert abs(lods[0] - 1) < 0.005 and abs(lods[1] - 2) < 0.005  # level m at r_m


@pytest.mark.slow  # a CLI bake (Numba compilation on a cold cache)
def test_a_real_three_bake_loads_with_the_module_it_ships(tmp_path):
    """``pbrkit bake --target three``: the module copied into the bake loads the
    bake's cube, and every texel three holds equals the file's."""
    out = bake_target(tmp_path, "three")
    shipped = out / "three" / "pbrkit-three.js"
    assert shipped.read_bytes() == (ENGINES.parents[1] / "src" / "pbrkit" / "js" / "pbrkit-three.js").read_bytes()
    result = run_engine_page("three.html", out, "module=/data/three/pbrkit-three.js&cube=three/specular.ktx2")["result"]
    levels = read_ktx2(out / "three" / "specular.ktx2")[1]
    assert result["texture"]["isPMREMTexture"] and result["texture"]["levels"] == len(levels)
    expected = np.concatenate([lv.reshape(-1) for lv in levels])
    assert np.abs(np.asarray(result["texels"]) - expected).max() == 0.0
