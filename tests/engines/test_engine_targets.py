"""Engine targets of a bake (issue 10): the level curves of Filament, three.js and
Babylon.js, the chains prefiltered for them (checked against brute-force
prefiltering), the mirrors that engines' cube lookups need (checked on
directions and on SH projections), and the files each target writes (read back
with pbrkit's readers and checked against the chains they come from).  The
engines themselves load the files in tests/engines/test_engine_*.py."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from pbrkit.cli import app
from pbrkit.ibl.bake import bake
from pbrkit.ibl.cubemap import cube_texel_directions, mirror_cube
from pbrkit.ibl.equirect import equirect_directions
from pbrkit.ibl.prefilter import (
    babylon_alpha_of_level,
    babylon_level_of_roughness,
    chain_roughness,
    filament_level_of_roughness,
    filament_roughness_of_level,
    prefilter_reference,
)
from pbrkit.ibl.sh import (
    babylon_polynomial,
    lambertian_sh_prescaled,
    mirror_sh,
    project_cube,
)
from pbrkit.io.babylon_env import read_babylon_env
from pbrkit.io.bake_files import chains_for
from pbrkit.io.dds import read_dds
from pbrkit.io.float_packing import to_float16
from pbrkit.io.ktx1 import read_ktx1
from pbrkit.io.ktx2 import read_ktx2
from pbrkit.io.pfm import write_pfm


def _smooth_sky(h=128):
    """Detail between the transform's band limit and the narrow lobes' (so the
    narrow levels' residual sampling matters), no highlight: the level-0 cube
    and the equirect then describe the same function closely."""
    d = equirect_directions(h)
    lum = 1.0 + 0.6 * np.sin(25 * d[..., 0]) * np.cos(19 * d[..., 1]) + 0.3 * (d[..., 2] > 0.3)
    return np.stack([lum, 0.8 * lum, 0.5 + 0 * lum], -1).astype(np.float32)


def test_filament_level_curve_inverts_its_lod():
    levels = 5
    m = np.arange(levels)
    r = filament_roughness_of_level(m, levels)
    np.testing.assert_allclose(r, [0, 1 - np.sqrt(0.75), 1 - np.sqrt(0.5), 0.5, 1], atol=1e-15)
    np.testing.assert_allclose(filament_level_of_roughness(r, levels), m, atol=1e-12)
    # its shader's lod is (M - 1) r (2 - r): lod 1 at r = 0.134, not at 0.25 as in the generic chain
    assert filament_level_of_roughness(0.25, levels) == pytest.approx(4 * 0.25 * 1.75)


def test_babylon_level_curve_inverts_its_lod():
    n = 256
    m = np.arange(1, 7)
    alpha = babylon_alpha_of_level(m, n)
    np.testing.assert_allclose(alpha, 2.0 ** (m / 0.8) / n)
    # Babylon's shader: lod = 0.8 log2(N alpha_G), alpha_G = r^2 + 0.0005
    r = np.sqrt(alpha - 0.0005)
    np.testing.assert_allclose(babylon_level_of_roughness(r, n), m, atol=1e-12)
    assert babylon_alpha_of_level(0, n) == 0.0 and babylon_alpha_of_level(8, n) == 1.0
    sizes, rough = chain_roughness("babylon", n, 16)
    assert sizes == [256, 128, 64, 32, 16, 8, 4, 2, 1] and rough[0] == 0 and rough[-1] == 1


def test_mirror_cube_moves_each_texel_to_the_mirrored_direction():
    d = cube_texel_directions(6)
    for k, axis in enumerate("xyz"):
        expected = d.copy()
        expected[..., k] *= -1
        np.testing.assert_allclose(mirror_cube(d, axis), expected, rtol=0, atol=1e-15)
        np.testing.assert_array_equal(mirror_cube(mirror_cube(d, axis), axis), d)
    with pytest.raises(ValueError, match="axis"):
        mirror_cube(d, "w")


def test_mirror_sh_is_the_projection_of_the_mirrored_cube():
    rng = np.random.default_rng(4)
    cube = rng.random((6, 8, 8, 3))
    for axis in "xyz":
        np.testing.assert_allclose(mirror_sh(project_cube(cube), axis), project_cube(mirror_cube(cube, axis)),
                                   atol=1e-12)


@pytest.fixture(scope="module")
def chained(tmp_path_factory):
    root = tmp_path_factory.mktemp("chains")
    write_pfm(root / "sky.pfm", _smooth_sky())
    return bake(root / "sky.pfm", size=64, min_size=4, chains=("filament", "babylon"))


@pytest.mark.parametrize("curve", ["filament", "babylon"])
def test_engine_chains_are_prefiltered_at_their_own_roughness(chained, curve):
    """Every level, the narrow ones (residual sampling around the transform) and
    the others (the transform alone), against brute-force prefiltering of the
    level-0 cube at the level's roughness."""
    chain = chained.chains[curve]
    level0 = chained.specular[0].astype(np.float64)
    sizes, rough = chain_roughness(curve, 64, 4)
    np.testing.assert_allclose(chain.roughness, rough)
    assert [lv.shape[1] for lv in chain.levels] == sizes
    methods = " ".join(e["method"] for e in chain.info)
    assert "filtered importance sampling" in methods and "no sampling" in methods  # both routes ran
    rng = np.random.default_rng(9)
    for m in range(1, len(sizes)):
        pick = rng.choice(6 * sizes[m] ** 2, size=min(6 * sizes[m] ** 2, 400), replace=False)
        ref = prefilter_reference(level0, cube_texel_directions(sizes[m]).reshape(-1, 3)[pick], rough[m])
        got = chain.levels[m].reshape(-1, 3)[pick]
        err = np.sqrt(np.sum((got - ref) ** 2) / np.sum(ref ** 2))
        assert err < 2e-3, (curve, m, err)


def test_a_linear_chain_would_be_the_generic_one(chained):
    """The generic chain is what prefilter_chain gives for the linear curve's levels
    that the transform resolves (one code path for both)."""
    from pbrkit.ibl.prefilter import roughness_of_level
    np.testing.assert_allclose(chained.roughness, roughness_of_level(np.arange(chained.levels), chained.levels))


SMALL = ["--size", "32", "--min-size", "4", "--irradiance-size", "8", "--lut-size", "16"]


@pytest.fixture(scope="module")
def all_targets(tmp_path_factory):
    root = tmp_path_factory.mktemp("all_targets")
    write_pfm(root / "sky.pfm", _smooth_sky(64))
    out = root / "bake"
    result = CliRunner().invoke(app, ["bake", str(root / "sky.pfm"), "-o", str(out), *SMALL, "--target", "all", "-q"])
    assert result.exit_code == 0, result.output
    manifest = json.loads((out / "manifest.json").read_text())
    b = bake(root / "sky.pfm", size=32, min_size=4, irradiance_size=8, lut_size=16, chains=chains_for(["all"]))
    return out, manifest, b


def test_every_target_has_files_conventions_and_a_load_call(all_targets):
    out, manifest, _ = all_targets
    assert set(manifest["targets"]) == {"filament", "khronos", "babylon", "three"}
    for name, entry in manifest["targets"].items():
        assert entry["load"] and entry["conventions"] and entry["engine"]
        for path in entry["files"].values():
            assert (out / path).is_file(), (name, path)


def test_filament_files(all_targets):
    out, manifest, b = all_targets
    chain = b.chains["filament"]
    info, levels, keys = read_ktx1(out / "filament" / "ibl.ktx")
    assert len(levels) == len(chain.levels) == 4
    assert info["glInternalFormat"] == 0x8C3A and info["glType"] == 0x8C3A  # as cmgen writes it
    for got, want in zip(levels, chain.levels):  # B10G11R11: 6 (5 for blue) mantissa bits
        np.testing.assert_allclose(got[..., :3], want, rtol=2 ** -6, atol=1e-6)
    numbers = keys["sh"].decode("ascii").split()
    assert len(numbers) == 27 and keys["sh"].count(b"\n") == 9
    np.testing.assert_allclose(np.array(numbers, float).reshape(9, 3), lambertian_sh_prescaled(b.sh), rtol=1e-6)
    _, sky, _ = read_ktx1(out / "filament" / "skybox.ktx")
    assert len(sky) == 1 and sky[0].shape[:3] == (6, 32, 32)


def test_three_files_are_the_filament_chain_mirrored_in_x(all_targets):
    out, manifest, b = all_targets
    chain = b.chains["filament"]
    _, levels, _ = read_ktx2(out / "three" / "specular.ktx2")
    for got, want in zip(levels, chain.levels):
        np.testing.assert_array_equal(got[..., :3], to_float16(mirror_cube(want, "x")).astype(np.float32))
    sh = json.loads((out / "three" / "sh.json").read_text())["coefficients"]
    np.testing.assert_allclose(np.reshape(sh, (9, 3)), b.sh)  # light probes are not mirrored
    assert (out / "three" / "pbrkit-three.js").read_text().startswith("//")


def test_babylon_files_are_its_chain_mirrored_in_z(all_targets):
    out, manifest, b = all_targets
    chain = b.chains["babylon"]
    assert [lv.shape[1] for lv in chain.levels] == [32, 16, 8, 4, 2, 1]
    _, dds_levels = read_dds(out / "babylon" / "specular.dds")
    for got, want in zip(dds_levels, chain.levels):
        np.testing.assert_array_equal(got[..., :3], to_float16(mirror_cube(want, "z")).astype(np.float32))
    env_manifest, env_levels, polynomial = read_babylon_env(out / "babylon" / "environment.env")
    assert env_manifest["specular"]["lodGenerationScale"] == 0.8
    for got, want in zip(env_levels, chain.levels):  # RGBD: 8 bits over the shared exponent
        want = mirror_cube(want, "z")
        np.testing.assert_allclose(got[..., :3], want, rtol=0.02, atol=2e-3 * float(want.max()))
    expected = babylon_polynomial(mirror_sh(b.sh, "z"))
    for term, value in expected.items():
        np.testing.assert_allclose(polynomial[term], value, rtol=1e-6, atol=1e-9)
