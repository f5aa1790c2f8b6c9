"""pbrkit's Sample Viewer module (``src/pbrkit/js/pbrkit-khronos.js``) inside the
Khronos glTF Sample Viewer 1.1.0 (npm ``@khronosgroup/gltf-viewer``), in headless
Chromium (issue 10).

The test writes a khronos folder as ``pbrkit bake --target khronos`` lays it out
(``specular.ktx2``: a direction-coded RGBA16F cube chain, each level a different
smooth function of direction; ``lambertian.ktx2``: a direction-coded one-level cube;
``lut_ggx.ktx2``: pbrkit's own (A, B) split-sum table with height-correlated
visibility) and a sphere glTF.  ``pages/khronos.html`` loads the folder with the
shipped module into a real GltfView / GltfState, renders the sphere with the
viewer's renderer, and reads every texel of the textures ``state.environment``
holds back from the GPU.  Checked: the GPU texels equal the files' float16 texels;
the centre pixel of the sphere (n = v = +Z) is what the viewer's shader makes of
those textures: metal = the specular level r (M - 1) in direction +Z (or +X under
the viewer's default environmentRotation of 90 degrees), dielectric = Lambertian
and specular mixed by the (A, B) LUT's Fresnel term.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from engine_pages import ENGINES, bake_target, needs_engines, run_page

from pbrkit.albedo.lut import lookup_table
from pbrkit.ibl.cubemap import cube_texel_directions, sample_cube
from pbrkit.io.ktx2 import read_ktx2, write_ktx2
from pbrkit.io.lut_files import write_lut

pytestmark = needs_engines()

N, M = 32, 6  # specular level 0 size and level count (32 .. 1)
N_LAMBERT, N_LUT = 16, 32
METAL_LEVEL = 2  # the metal sphere's roughness is METAL_LEVEL / (M - 1)
RENDERS = [{"scene": 0, "rotation": 0}, {"scene": 0, "rotation": 90}, {"scene": 1, "rotation": 0}]

def run_engine_page(page, data, query):
    return run_page(page, data=data, query=query, timeout=120)


def specular_function(m, d):
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    return np.stack([0.45 + 0.35 * x + 0.08 * m, 0.5 + 0.3 * y - 0.05 * m,
                     0.4 + 0.3 * z + 0.02 * m * x * y, np.full_like(x, 1.0 + m)], axis=-1)


def lambertian_function(d):
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    return np.stack([0.05 + 0.04 * x, 0.06 + 0.04 * y, 0.04 + 0.03 * z, np.ones_like(x)], axis=-1)


def sphere_gltf(folder):
    """A unit sphere (poles on +-Z, so a vertex faces the camera), two materials
    (white metal at roughness METAL_LEVEL / (M - 1), white dielectric at roughness
    1), one scene each, and a camera at (0, 0, 4) looking along -Z."""
    rings, segments = 48, 96
    theta = np.linspace(0.0, np.pi, rings + 1)
    phi = np.linspace(0.0, 2 * np.pi, segments + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    pos = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1).reshape(-1, 3)
    pos = pos.astype(np.float32)
    idx = []
    for i in range(rings):
        for j in range(segments):
            a, b = i * (segments + 1) + j, (i + 1) * (segments + 1) + j
            idx += [a, b, a + 1, a + 1, b, b + 1]
    idx = np.asarray(idx, np.uint32)
    blob = pos.tobytes() + pos.tobytes() + idx.tobytes()
    (folder / "sphere.bin").write_bytes(blob)
    n = len(pos)
    gltf = {
        "asset": {"version": "2.0"},
        "buffers": [{"uri": "sphere.bin", "byteLength": len(blob)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 12 * n, "target": 34962},
                        {"buffer": 0, "byteOffset": 12 * n, "byteLength": 12 * n, "target": 34962},
                        {"buffer": 0, "byteOffset": 24 * n, "byteLength": 4 * len(idx), "target": 34963}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
                       "min": pos.min(0).tolist(), "max": pos.max(0).tolist()},
                      {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"},
                      {"bufferView": 2, "componentType": 5125, "count": len(idx), "type": "SCALAR"}],
        "materials": [
            {"name": "metal", "doubleSided": True, "pbrMetallicRoughness": {
                "baseColorFactor": [1, 1, 1, 1], "metallicFactor": 1.0, "roughnessFactor": METAL_LEVEL / (M - 1)}},
            {"name": "dielectric", "doubleSided": True, "pbrMetallicRoughness": {
                "baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0.0, "roughnessFactor": 1.0}},
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": k}]}
                   for k in range(2)],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.6, "aspectRatio": 1.0, "znear": 0.1,
                                                            "zfar": 100.0}}],
        "nodes": [{"camera": 0, "translation": [0, 0, 4]}, {"mesh": 0}, {"mesh": 1}],
        "scenes": [{"nodes": [0, 1]}, {"nodes": [0, 2]}],
        "scene": 0,
    }
    (folder / "sphere.gltf").write_text(json.dumps(gltf))


@pytest.fixture(scope="module")
def khronos(tmp_path_factory):
    data = tmp_path_factory.mktemp("khronos_engine")
    folder = data / "khronos"
    folder.mkdir()
    levels = [specular_function(m, cube_texel_directions(N >> m)).astype(np.float32) for m in range(M)]
    write_ktx2(folder / "specular.ktx2", levels, "R16G16B16A16_SFLOAT", cube=True)
    lam = [lambertian_function(cube_texel_directions(N_LAMBERT)).astype(np.float32)]
    write_ktx2(folder / "lambertian.ktx2", lam, "R16G16B16A16_SFLOAT", cube=True)
    table, spec = lookup_table("splitsum", N_LUT, visibility="height-correlated")
    write_lut(folder / "lut_ggx.ktx2", table, spec)
    sphere_gltf(data)
    query = "&".join(["folder=khronos/", "gltf=sphere.gltf", "renders=" + json.dumps(RENDERS)])
    report = run_engine_page("khronos.html", data, query)
    files = {name: read_ktx2(folder / f"{name}.ktx2")[1] for name in ("specular", "lambertian", "lut_ggx")}
    return report["result"], files


def test_environment_fields(khronos):
    result, _ = khronos
    assert result["mipCount"] == M and result["iblIntensityScale"] == 1.0
    assert result["pbrkit"]["specularSize"] == N and result["pbrkit"]["lambertianSize"] == N_LAMBERT
    assert result["pbrkit"]["lutSize"] == [N_LUT, N_LUT] and result["pbrkit"]["lutChannels"] == 2


def test_gpu_textures_equal_the_files(khronos):
    result, files = khronos
    spec = np.concatenate([lv.reshape(-1) for lv in files["specular"]])
    got = np.asarray(result["specular"])
    assert got.shape == spec.shape and np.abs(got - spec).max() == 0.0
    assert sorted(set(got[3::4])) == [1.0 + m for m in range(M)]  # every level, each its own
    lam = files["lambertian"][0].reshape(-1)
    got = np.asarray(result["lambertian"])
    assert got.shape == lam.shape and np.abs(got - lam).max() == 0.0
    lut = files["lut_ggx"][0]  # (N, N, 2): (A, B); an RG16F texture reads back as (A, B, 0, 1)
    got = np.asarray(result["lut"]).reshape(N_LUT, N_LUT, 4)
    assert np.abs(got[..., :2] - lut).max() == 0.0
    assert np.all(got[..., 2] == 0.0) and np.all(got[..., 3] == 1.0)


def _linear(rgba8):
    """The viewer's output (toneMap None: pow(c, 1/2.2), 8-bit) back to linear."""
    return (np.asarray(rgba8[:3], np.float64) / 255.0) ** 2.2


def _render(result, scene, rotation):
    (hit,) = [r for r in result["renders"] if r["scene"] == scene and r["rotation"] == rotation]
    return _linear(hit["centre"])


TOL = 0.008  # 8-bit output near 1 (2.2 x^(1.2/2.2) / 510 = 0.004) plus the sphere's tessellation
TOL_DARK = 0.003  # the same for the dim dielectric pixel (linear values below 0.1)


def test_metal_sphere_shows_the_specular_level_of_its_roughness(khronos):
    """White metal: the viewer's F0 A + B and multiple-scattering terms sum to 1 for
    F0 = 1, so the centre pixel is the specular cube at lod r (M - 1) = METAL_LEVEL,
    direction reflect(-v, n) = +Z rotated by environmentRotation about +Y."""
    result, files = khronos
    z, x = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
    for rotation, seen, other in ((0, z, x), (90, x, z)):
        got = _render(result, 0, rotation)
        want = sample_cube(files["specular"], seen, lod=float(METAL_LEVEL))[:3]
        wrong = sample_cube(files["specular"], other, lod=float(METAL_LEVEL))[:3]
        assert np.abs(got - want).max() < TOL, (rotation, got, want)
        assert np.abs(got - wrong).max() > 0.1
        # a neighbouring level would be off by more than the tolerance too
        off = sample_cube(files["specular"], seen, lod=float(METAL_LEVEL + 1))[:3]
        assert np.abs(got - off).max() > 2 * TOL


def test_dielectric_sphere_mixes_lambertian_and_specular_by_the_lut(khronos):
    """White dielectric (F0 0.04), roughness 1, n = v: the viewer's
    getIBLGGXFresnel with (A, B) at (n.v, r) = (1, 1) (the LUT's last texel) gives
    the weight fr of the specular sample; colour = mix(lambertian(n), specular, fr)."""
    result, files = khronos
    z = np.array([0.0, 0.0, 1.0])
    a, b = (float(v) for v in files["lut_ggx"][0][-1, -1])
    f0, specular_weight = 0.04, 1.0
    fss_ess = specular_weight * (f0 * a + b)
    ems = 1.0 - (a + b)
    f_avg = specular_weight * (f0 + (1.0 - f0) / 21.0)
    fr = fss_ess + ems * fss_ess * f_avg / (1.0 - f_avg * ems)
    lam = sample_cube(files["lambertian"], z)[:3]
    spec = sample_cube(files["specular"], z, lod=float(M - 1))[:3]
    want = lam * (1 - fr) + spec * fr
    got = _render(result, 1, 0)
    assert np.abs(got - want).max() < TOL_DARK, (got, want, fr)
    # The LUT's term shows (fr ~ 0.014 here: without it the pixel would be lambertian
    # alone), and the Lambertian cube is used as radiance (E / pi), not times pi.
    assert np.abs(got - lam).max() > 3 * TOL_DARK
    assert np.abs(got - (np.pi * lam * (1 - fr) + spec * fr)).max() > 0.05


@pytest.mark.slow  # a CLI bake (Numba compilation on a cold cache)
def test_a_real_khronos_bake_loads_with_the_module_it_ships(tmp_path):
    """``pbrkit bake --target khronos``: the module copied into the bake fills a
    GltfState from the bake's folder, and every texel the viewer's environment holds
    equals the files'."""
    out = bake_target(tmp_path, "khronos")
    shipped = out / "khronos" / "pbrkit-khronos.js"
    assert shipped.read_bytes() == (ENGINES.parents[1] / "src" / "pbrkit" / "js" / "pbrkit-khronos.js").read_bytes()
    result = run_engine_page("khronos.html", out, "module=/data/khronos/pbrkit-khronos.js&folder=khronos/")["result"]
    files = {name: read_ktx2(out / "khronos" / f"{name}.ktx2")[1] for name in ("specular", "lambertian", "lut_ggx")}
    assert result["mipCount"] == len(files["specular"])
    for key, name in (("specular", "specular"), ("lambertian", "lambertian")):
        expected = np.concatenate([lv.reshape(-1) for lv in files[name]])
        assert np.abs(np.asarray(result[key]) - expected).max() == 0.0, key
    lut = files["lut_ggx"][0]
    got = np.asarray(result["lut"]).reshape(lut.shape[0], lut.shape[1], 4)
    assert np.abs(got[..., :2] - lut).max() == 0.0
