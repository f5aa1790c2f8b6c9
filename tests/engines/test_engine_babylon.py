"""Proof inside Babylon.js (npm ``babylonjs`` 9.35.0, headless Chromium, WebGL2 via
SwiftShader): pbrkit's ``.env`` (:mod:`pbrkit.io.babylon_env`) and RGBA16F DDS
(:func:`pbrkit.io.dds.write_dds`) load through Babylon's own public
``CubeTexture.CreateFromPrefilteredData`` in a ``useRightHandedSystem`` scene, and
what Babylon holds is what the files say (page: ``engines/pages/babylon.html``).

The cube chain is direction-coded: level m is a known smooth function f_m of the
direction (a different mix of x, y, z and quadratic terms per level, values from
0.08 to 180 so RGBD's divisor is exercised), evaluated at texel centres with the
OpenGL cube table written out here (CONVENTIONS.md "Cube maps"), independently of
pbrkit's own cube code.  One page run reads back, for both files:

* every texel of every face and level of Babylon's WebGL cube texture;
* ``textureLod`` of that texture at every texel-centre direction (GL's own
  direction -> texel mapping), nearest filtering;
* ``texture.sphericalPolynomial`` and ``lodGenerationScale``;
* the centre pixel of a mirror PBR sphere seen from +x, -x, +z, -z.
"""

import base64

import numpy as np
import pytest
from engine_pages import needs_engines, run_page

from pbrkit.ibl.sh import babylon_polynomial, project_cube
from pbrkit.io.babylon_env import (
    POLYNOMIAL_TERMS,
    rgbd_decode,
    rgbd_encode,
    write_babylon_env,
)
from pbrkit.io.dds import read_dds, write_dds

pytestmark = needs_engines()

N = 16
LOD_SCALE = 0.75  # not Babylon's default 0.8, so reading it back means something


def face_directions(n):
    """Unit directions (6, n, n, 3) of texel centres, OpenGL 4.6 table 8.19."""
    c = (np.arange(n) + 0.5) / n * 2 - 1
    tc, sc = np.meshgrid(c, c, indexing="ij")  # [row t, column s]
    one = np.ones_like(sc)
    faces = [(one, -tc, -sc), (-one, -tc, sc), (sc, one, tc), (sc, -one, -tc), (sc, -tc, one), (-sc, -tc, -one)]
    d = np.stack([np.stack(f, axis=-1) for f in faces])
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def coded(m, d):
    """Level m's colour for directions d (..., 3): known, smooth, different per level."""
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    if m == 0:  # linear + quadratic: every band of the SH is non-zero
        r = 3 + 1.5 * x + 0.6 * x * y + 0.4 * (x * x - y * y)
        g = 3 + 1.5 * y + 0.6 * y * z + 0.3 * z * z
        b = 3 + 1.5 * z + 0.6 * z * x
        return np.stack([r, g, b], axis=-1)
    scale = [None, 0.4, 20.0, 100.0, 1.2][m]
    perm = [None, (1, 2, 0), (2, 0, 1), (1, 0, 2), (2, 1, 0)][m]
    sign = [None, (1, -1, 1), (-1, 1, 1), (1, 1, -1), (-1, -1, 1)][m]
    return scale * (1 + 0.8 * d[..., list(perm)] * np.array(sign))


def run_babylon_page(data, query, timeout=120):
    """harness.mjs on pages/babylon.html: the report's "result" (fails the test
    with the page's error otherwise)."""
    return run_page("babylon.html", data=data, query=query, timeout=timeout)["result"]


def floats(b64):
    return np.frombuffer(base64.b64decode(b64), dtype="<f4")


def texel_levels(flat, n=N):
    """The page's texels (level-major, face-minor, rows as read: row 0 = t = 0) as (6, n, n, 4) arrays."""
    out, pos = [], 0
    while n >= 1:
        size = 6 * n * n * 4
        out.append(flat[pos:pos + size].reshape(6, n, n, 4))
        pos += size
        n //= 2
    assert pos == flat.size
    return out


@pytest.fixture(scope="module")
def babylon(tmp_path_factory):
    folder = tmp_path_factory.mktemp("babylon")
    sizes = [N >> m for m in range(N.bit_length())]
    dirs = [face_directions(n) for n in sizes]
    levels = [coded(m, d) for m, d in enumerate(dirs)]
    polynomial = babylon_polynomial(project_cube(levels[0]))  # any 9 terms will do; these are plausible
    write_babylon_env(folder / "cube.env", levels, polynomial, lod_generation_scale=LOD_SCALE)
    write_dds(folder / "cube.dds", levels, "R16G16B16A16_FLOAT", cube=True)
    samples = np.concatenate([np.concatenate([d.reshape(-1, 3), np.full((d[..., 0].size, 1), float(m))], axis=1)
                              for m, d in enumerate(dirs)]).astype("<f4")
    samples.tofile(folder / "dirs.bin")
    result = run_babylon_page(folder, "env=/data/cube.env&dds=/data/cube.dds&dirs=/data/dirs.bin&exposure=0.125")
    return {"folder": folder, "levels": levels, "dirs": dirs, "polynomial": polynomial, "result": result}


def test_scene_and_textures(babylon):
    r = babylon["result"]
    assert r["version"] == "9.35.0" and r["useRightHandedSystem"] is True
    for kind in ("env", "dds"):
        t = r[kind]
        assert t["isCube"] is True and t["size"] == N and t["invertZ"] is False


def test_dds_texels_equal_the_file_exactly(babylon):
    _, file_levels = read_dds(babylon["folder"] / "cube.dds")
    got = texel_levels(floats(babylon["result"]["dds"]["texels"]))
    for m, (a, b) in enumerate(zip(file_levels, got)):
        assert np.array_equal(b[..., :3], a[..., :3]), f"level {m}: max diff {np.abs(b[..., :3] - a[..., :3]).max()}"
    # and upside down they would not be
    assert not np.array_equal(got[0][..., :3], file_levels[0][:, ::-1, :, :3])


def test_env_texels_equal_the_rgbd_decode_and_rows_are_upside_down_in_the_file(babylon):
    got = texel_levels(floats(babylon["result"]["env"]["texels"]))
    worst_decode = worst_source = 0.0
    for m, (src, b) in enumerate(zip(babylon["levels"], got)):
        q = rgbd_encode(src)
        decoded = rgbd_decode(q).astype(np.float64)
        b = b[..., :3].astype(np.float64)
        # Babylon decodes the RGBD PNGs in a shader into a half-float cube: half rounding
        diff = np.abs(b - decoded)
        assert np.all(diff <= 2.0 ** -10 * decoded + 1e-6), f"level {m}: {diff.max()}"
        worst_decode = max(worst_decode, float(np.max(diff / (decoded + 1e-6))))
        # against the source values: within RGBD's 8-bit quantisation (+ half rounding)
        bound = 1.1 / q[..., 3:].astype(np.float64) + 2.0 ** -10 * src
        assert np.all(np.abs(b - src) <= bound), f"level {m}"
        worst_source = max(worst_source, float(np.max(np.abs(b - src) / bound)))
        if m < 4:  # the other row order would be far off (row 0 = t = 0 in Babylon's texture)
            flipped = np.abs(b - src[:, ::-1])
            assert np.max(flipped / bound) > 10
    print(f"env: max rel diff to the RGBD decode {worst_decode:.2e}; max |diff| / quantisation bound {worst_source:.2f}")


@pytest.mark.parametrize("kind", ["env", "dds"])
def test_sampling_by_direction_gives_the_coded_values(babylon, kind):
    """textureLod(cube, d, m) in Babylon's texture = f_m(d): faces, rows, columns
    and levels are where GL's cube table (and CONVENTIONS.md) put them."""
    got = floats(babylon["result"][kind]["samples"]).reshape(-1, 4)[:, :3].astype(np.float64)
    expect = np.concatenate([coded(m, d).reshape(-1, 3) for m, d in enumerate(babylon["dirs"])])
    if kind == "dds":
        bound = 2.0 ** -11 * expect * 1.0001
    else:
        bound = 1.1 / rgbd_encode(expect)[:, 3:].astype(np.float64) + 2.0 ** -10 * expect
    err = np.abs(got - expect)
    assert np.all(err <= bound), f"{kind}: worst |diff| / bound {np.max(err / bound):.2f}"
    print(f"{kind}: samples max rel diff {np.max(err / expect):.2e}")


def test_env_polynomial_and_lod_scale_are_what_was_written(babylon):
    env = babylon["result"]["env"]
    assert env["lodGenerationScale"] == LOD_SCALE
    for t in POLYNOMIAL_TERMS:
        assert env["polynomial"][t] == [float(v) for v in babylon["polynomial"][t]], t  # exact (JSON round trip)


def test_dds_polynomial_babylon_computes_matches_pbrkit(babylon):
    """Babylon computes a DDS's polynomial from its level-0 faces
    (CubeMapToSphericalPolynomialTools); pbrkit's babylon_polynomial of the file's
    faces gives the same numbers: same frame (no z flip in the SH tool), same scale."""
    _, file_levels = read_dds(babylon["folder"] / "cube.dds")
    ours = babylon_polynomial(project_cube(file_levels[0][..., :3]))
    theirs = babylon["result"]["dds"]["polynomial"]
    assert babylon["result"]["dds"]["lodGenerationScale"] == 0.8  # a DDS carries none: Babylon's default
    for t in POLYNOMIAL_TERMS:
        assert np.allclose(theirs[t], ours[t], rtol=1e-9, atol=1e-9), t
    assert abs(ours["xy"][0]) > 0.02 and abs(ours["z"][2]) > 0.5  # the terms compared are not trivially 0


def check_views(render, z_negated):
    render = {k: np.array(v[:3], dtype=float) for k, v in render.items()}
    for view, channel, brighter in (("+x", 0, True), ("-x", 0, False),
                                    ("+z", 2, not z_negated), ("-z", 2, z_negated)):
        rgb = render[view]
        others = np.delete(rgb, channel)
        if brighter:
            assert np.all(rgb[channel] > others + 20), (view, rgb)
        else:
            assert np.all(rgb[channel] < others - 20), (view, rgb)


@pytest.mark.parametrize("kind", ["env", "dds"])
def test_right_handed_scene_samples_the_cube_with_z_negated(babylon, kind):
    """Mirror sphere, centre pixel: the world reflection direction is the camera's
    direction from the sphere.  Level 0 is brightest in red toward +x and in blue
    toward +z; Babylon (useRightHandedSystem, invertZ false) shows +x where world +x
    is but -z where world +z is: it samples C(x, y, -z).  So a bake for a
    right-handed scene stores C(b) = L(b.x, b.y, -b.z)."""
    check_views(babylon["result"][kind]["render"], z_negated=True)


def test_left_handed_scene_samples_the_cube_as_is(babylon):
    """The same views in a left-handed scene (Babylon's default): no z flip."""
    check_views(babylon["result"]["dds"]["renderLeftHanded"], z_negated=False)
