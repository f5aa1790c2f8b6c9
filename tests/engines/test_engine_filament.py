"""Filament loads pbrkit's KTX1 files with its own public loaders (issue 10).

The test writes, with :mod:`pbrkit.io.ktx1`, an IBL cube (5 levels, 16 down to
1, each texel a smooth function of its direction that differs per level and per
channel, plus Filament's ``sh`` key) and a skybox cube, and opens
``tests/engines/pages/filament.html`` in headless Chromium (npm ``filament``
1.53.4, WebGL2 through SwiftShader).  The page loads the IBL with
``engine.createIblFromKtx1(buffer)`` and the skybox with
``engine.createSkyFromKtx1(buffer)`` and renders, with post-processing off,
into an RGBA32F render target that it reads back as floats:

* the skybox seen from the origin along each face axis with a 90 degree field of
  view and a 16 x 16 viewport, so that each pixel's ray passes through one texel
  centre of level 0 (skybox.mat samples lod 0): every texel of the file, in
  Filament's world frame;
* mirror-like quads (gltfio's ubershader material, base colour 1, metallic 1,
  roughness r_m = 1 - sqrt(1 - m / (M - 1))) facing the camera, read at the
  pixel where v = n = reflected direction: Filament samples its reflections
  texture at lod = (M - 1) r (2 - r) = m, at a direction through a texel centre
  of level m (with f0 = 1 its E = dfg.y and energy compensation 1 / dfg.y
  cancel), so each probe is one texel of level m, m = 1..4.  Level 0 cannot be
  reached this way (Filament clamps the perceptual roughness from below), so the
  page also loads the IBL file with ``createSkyFromKtx1`` and views it like the
  skybox: every level-0 texel of the IBL file.

The read-back must equal the file's texels (decoded by pbrkit's reader, which
the round-trip tests check against the format's rounding) to 1e-5 relative,
i.e. to float32 arithmetic in the shader, far inside half-float or
R11G11B10 rounding; and equal the un-rounded content to within that rounding.
Both formats go through both loaders (two runs, formats swapped).
"""

from __future__ import annotations

import json
import struct

import numpy as np
import pytest
from engine_pages import needs_engines, page_report, run_page

from pbrkit.ibl.cubemap import cube_texel_directions, direction_to_cube, face_direction
from pbrkit.io.ktx1 import filament_sh_text, ktx1_bytes, read_ktx1, write_ktx1

pytestmark = [needs_engines(), pytest.mark.slow]  # about 6 s per page run (SwiftShader)

N = 16  # level 0 size
M = 5  # levels 16, 8, 4, 2, 1
# Relative rounding of each format (half the spacing of representable values):
# float16 2^-11; R11F_G11F_B10F 2^-7 (11-bit) and 2^-6 (10-bit blue).
ROUNDING = {"RGBA16F": np.array([2.0**-11] * 3), "R11F_G11F_B10F": np.array([2.0**-7, 2.0**-7, 2.0**-6])}
SH = (np.arange(27, dtype=np.float64).reshape(9, 3) - 13.0) * np.array([0.0123, -0.0456, 0.0789])


def run_filament_page(data, timeout=120, expect_error=False):
    """``engine_pages.run_page("filament.html", data)``; with ``expect_error`` the
    report as the page left it (:func:`engine_pages.page_report`)."""
    if expect_error:
        return page_report("filament.html", data=data, timeout=timeout)
    return run_page("filament.html", data=data, timeout=timeout)


def ibl_content(d, m):
    """Radiance stored at direction d (..., 3) of level m: per channel a different
    affine function of the direction, shifted per level."""
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    return np.stack([0.55 + 0.35 * x - 0.05 * z + 0.07 * m,
                     0.50 + 0.30 * y + 0.10 * x + 0.11 * m,
                     0.45 + 0.25 * z - 0.10 * y + 0.13 * m], axis=-1)


def sky_content(d):
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    return np.stack([1.2 - 0.5 * y + 0.3 * z, 0.9 + 0.6 * x * z, 0.7 + 0.4 * x - 0.2 * y], axis=-1)


def roughness_for_level(m):
    """Filament's roughness of level m: the inverse of lod = (M - 1) r (2 - r)."""
    return 1.0 - np.sqrt(1.0 - m / (M - 1))


def probe_texels():
    """(level, face, row, column) of the probes: two texels per face and level."""
    out = []
    for m in range(1, M):
        n = N >> m
        for f in range(6):
            picks = {(0, n - 1), (n // 2, n // 3)} if n > 1 else {(0, 0)}
            out += [(m, f, i, j) for i, j in sorted(picks)]
    return out


def sky_views():
    """Camera (forward, up) per face: forward = face axis, up = the face's +t axis."""
    views = []
    for f in range(6):
        forward = np.array(face_direction(f, 0.0, 0.0), dtype=float)
        up = np.array(face_direction(f, 0.0, 1.0), dtype=float) - forward
        views.append({"forward": forward.tolist(), "up": up.tolist()})
    return views


def pixel_texels(forward, up):
    """(face, row, column) of level 0 under each pixel of an N x N view with a
    90 degree field of view, pixels as gl.readPixels returns them (row 0 at the
    bottom); asserts each pixel ray passes through a texel centre."""
    forward = np.asarray(forward, float)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    c = (np.arange(N) + 0.5) / N * 2.0 - 1.0  # tan(45 deg) = 1
    yy, xx = np.meshgrid(c, c, indexing="ij")  # [row from bottom, column]
    d = forward + xx[..., None] * right + yy[..., None] * true_up
    face, s, t = direction_to_cube(d)
    col, row = np.floor(s * N).astype(int), np.floor(t * N).astype(int)
    assert np.allclose(s * N - col, 0.5, atol=1e-9) and np.allclose(t * N - row, 0.5, atol=1e-9)
    return face, row, col


@pytest.fixture(scope="module", params=[("R11F_G11F_B10F", "RGBA16F"), ("RGBA16F", "R11F_G11F_B10F")],
                ids=["ibl_r11g11b10-sky_rgba16f", "ibl_rgba16f-sky_r11g11b10"])
def filament_run(request, tmp_path_factory):
    ibl_format, sky_format = request.param
    data = tmp_path_factory.mktemp("filament")
    ibl_levels = [ibl_content(cube_texel_directions(N >> m), m) for m in range(M)]
    sky_levels = [sky_content(cube_texel_directions(N))]
    write_ktx1(data / "ibl.ktx", ibl_levels, ibl_format, cube=True, key_values={"sh": filament_sh_text(SH)})
    write_ktx1(data / "sky.ktx", sky_levels, sky_format, cube=True)
    probes = []
    for m, f, i, j in probe_texels():
        probes.append({"dir": cube_texel_directions(N >> m)[f, i, j].tolist(),
                       "roughness": float(roughness_for_level(m))})
    views = sky_views()
    (data / "probe.json").write_text(json.dumps({"ibl": "ibl.ktx", "sky": "sky.ktx", "skySize": N,
                                                 "skyViews": views, "probes": probes}))
    report = run_filament_page(data)
    return {
        "ibl_format": ibl_format, "sky_format": sky_format, "report": report, "views": views,
        "ibl_exact": ibl_levels, "sky_exact": sky_levels,
        "ibl_file": read_ktx1(data / "ibl.ktx")[1], "sky_file": read_ktx1(data / "sky.ktx")[1],
    }


def _rgb(values):
    return np.asarray(values, dtype=np.float64)[..., :3]


def test_skybox_shows_every_level0_texel_of_the_file(filament_run):
    run = filament_run
    result = run["report"]["result"]
    assert result["skyLevels"] == 1
    worst = 0.0
    assert len(result["sky"]) == 6
    for view, image in zip(run["views"], result["sky"], strict=True):
        got = _rgb(np.asarray(image).reshape(N, N, 4))
        face, row, col = pixel_texels(view["forward"], view["up"])
        stored = run["sky_file"][0][face, row, col, :3]
        exact = run["sky_exact"][0][face, row, col]
        worst = max(worst, float(np.max(np.abs(got - stored) / stored)))
        np.testing.assert_allclose(got, stored, rtol=1e-5, atol=0)
        np.testing.assert_array_less(np.abs(got - exact), ROUNDING[run["sky_format"]] * exact * 1.0001)
    print(f"skybox ({run['sky_format']}): max relative difference to the file's texels {worst:.3g}")


def test_ibl_file_level0_seen_as_a_skybox(filament_run):
    run = filament_run
    worst = 0.0
    for view, image in zip(run["views"], run["report"]["result"]["iblSky"], strict=True):
        got = _rgb(np.asarray(image).reshape(N, N, 4))
        face, row, col = pixel_texels(view["forward"], view["up"])
        stored = run["ibl_file"][0][face, row, col, :3]
        exact = run["ibl_exact"][0][face, row, col]
        worst = max(worst, float(np.max(np.abs(got - stored) / stored)))
        np.testing.assert_allclose(got, stored, rtol=1e-5, atol=0)
        np.testing.assert_array_less(np.abs(got - exact), ROUNDING[run["ibl_format"]] * exact * 1.0001)
    print(f"IBL level 0 as a skybox ({run['ibl_format']}): max relative difference {worst:.3g}")


def test_reflections_levels_equal_the_file_texels(filament_run):
    run = filament_run
    result = run["report"]["result"]
    assert result["iblLevels"] == M
    got = _rgb(result["probes"])
    keys = probe_texels()
    stored = np.array([run["ibl_file"][m][f, i, j, :3] for m, f, i, j in keys])
    exact = np.array([run["ibl_exact"][m][f, i, j] for m, f, i, j in keys])
    worst = float(np.max(np.abs(got - stored) / stored))
    print(f"reflections ({run['ibl_format']}): {len(keys)} probes over levels 1..{M - 1}, "
          f"max relative difference to the file's texels {worst:.3g}")
    np.testing.assert_allclose(got, stored, rtol=1e-5, atol=0)
    np.testing.assert_array_less(np.abs(got - exact), ROUNDING[run["ibl_format"]] * exact * 1.0001)
    # A neighbouring level at the same directions would be far outside that
    # tolerance, so a wrong lod mapping or level order shows.
    dirs = np.array([cube_texel_directions(N >> m)[f, i, j] for m, f, i, j in keys])
    for shift in (-1, 1):
        wrong = ibl_content(dirs, np.array([k[0] for k in keys]) + shift)
        assert np.all(np.max(np.abs(got - wrong) / wrong, axis=-1) > 0.05)


def test_sh_key_reaches_ibl_shfloats(filament_run):
    shfloats = filament_run["report"]["result"]["shfloats"]
    assert len(shfloats) == 27
    np.testing.assert_array_equal(np.float32(shfloats), np.float32(SH).reshape(-1))


def test_console_warning_only_for_rgba16f_ibl(filament_run):
    report = filament_run["report"]
    warned = [line for line in report["console"] if "not an expected floating-point format" in line]
    if filament_run["ibl_format"] == "RGBA16F":
        assert len(warned) == 1 and "0x881a" in warned[0]
    else:
        assert warned == []
    assert report["errors"] == []
    assert not [line for line in report["console"] if line.startswith("error")]


def test_filament_aborts_on_the_spec_gltype_so_pbrkit_writes_cmgens(tmp_path):
    """Why glType is 0x8C3A: the same file with the spec's glType for packed
    R11G11B10 (0x8C3B UNSIGNED_INT_10F_11F_11F_REV) makes Filament 1.53.4's
    createIblFromKtx1 fail (Texture::setImage precondition, then a wasm abort)."""
    levels = [ibl_content(cube_texel_directions(N >> m), m) for m in range(M)]
    data = bytearray(ktx1_bytes(levels, "R11F_G11F_B10F", cube=True, key_values={"sh": filament_sh_text(SH)}))
    assert struct.unpack_from("<I", data, 16)[0] == 0x8C3A
    struct.pack_into("<I", data, 16, 0x8C3B)
    (tmp_path / "ibl.ktx").write_bytes(bytes(data))
    write_ktx1(tmp_path / "sky.ktx", [sky_content(cube_texel_directions(N))], "RGBA16F", cube=True)
    (tmp_path / "probe.json").write_text(json.dumps({"ibl": "ibl.ktx", "sky": "sky.ktx", "skySize": N,
                                                     "skyViews": [], "probes": []}))
    report = run_filament_page(tmp_path, expect_error=True)
    assert report["result"] is None
    assert "createIblFromKtx1" in (report["error"] or "")
    assert any("is not supported" in line for line in report["console"])
