"""``pbrkit bake`` on the command line: success, and every error path exits
non-zero with a one-line message and leaves no output directory behind."""

from __future__ import annotations

import json
import struct

import numpy as np
import pytest
from typer.testing import CliRunner

from pbrkit.cli import app
from pbrkit.io.hdr import hdr_bytes
from pbrkit.io.pfm import pfm_bytes, write_pfm

SMALL = ["--size", "16", "--min-size", "4", "--irradiance-size", "4", "--lut-size", "4"]


def sky(h=16):
    img = np.full((h, 2 * h, 3), 0.5, np.float32)
    img[: h // 2] += 0.5
    return img


def run(*args):
    return CliRunner().invoke(app, ["bake", *map(str, args)])


def assert_failed_cleanly(result, out, *fragments):
    assert result.exit_code == 1, result.output
    message = result.stderr.strip()
    assert message.startswith("pbrkit: error:") and "Traceback" not in result.output, result.output
    for fragment in fragments:
        assert fragment in message, message
    assert not out.exists()
    assert not [p for p in out.parent.iterdir() if p.name.startswith(f".{out.name}.")]


@pytest.fixture
def env(tmp_path):
    path = tmp_path / "sky.pfm"
    write_pfm(path, sky())
    return path


def test_bake_writes_the_directory(env, tmp_path):
    out = tmp_path / "nested" / "out"
    result = run(env, "-o", out, *SMALL)
    assert result.exit_code == 0, result.output
    assert "wrote" in result.stdout and "times (s)" in result.stdout
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["options"]["size"] == 16 and manifest["outputs"]["specular"]["levels"] == 3
    assert (out / "faces" / "specular_m2_nz.exr").is_file()


def test_quiet_prints_nothing(env, tmp_path):
    result = run(env, "-o", tmp_path / "o", *SMALL, "--quiet")
    assert result.exit_code == 0 and result.stdout == ""


def test_missing_file(tmp_path):
    out = tmp_path / "o"
    assert_failed_cleanly(run(tmp_path / "nope.hdr", "-o", out, *SMALL), out, "nope.hdr")


def test_truncated_hdr(tmp_path):
    path = tmp_path / "cut.hdr"
    data = hdr_bytes(sky(32), rle=True)
    path.write_bytes(data[: len(data) // 2])
    out = tmp_path / "o"
    assert_failed_cleanly(run(path, "-o", out, *SMALL), out, "cut.hdr")


def test_wrong_aspect_ratio(tmp_path):
    path = tmp_path / "odd.pfm"
    write_pfm(path, np.ones((10, 35, 3), np.float32))
    out = tmp_path / "o"
    assert_failed_cleanly(run(path, "-o", out, *SMALL), out, "odd.pfm", "35x10")


def _pfm_with(tmp_path, name, values):
    img = sky()
    data = bytearray(pfm_bytes(img))
    header = len(data) - img.size * 4
    for k, v in enumerate(values):  # rows are stored bottom to top; any sample will do
        struct.pack_into("<f", data, header + 4 * (37 * k + 5), v)
    path = tmp_path / name
    path.write_bytes(bytes(data))
    return path


def test_non_finite_pixels_are_reported_and_fixable(tmp_path):
    path = _pfm_with(tmp_path, "nan.pfm", [float("nan"), float("inf"), float("-inf")])
    out = tmp_path / "o"
    assert_failed_cleanly(run(path, "-o", out, *SMALL), out, "3 non-finite")
    result = run(path, "-o", out, *SMALL, "--fix-nonfinite")
    assert result.exit_code == 0, result.output
    notes = json.loads((out / "manifest.json").read_text())["input"]["notes"]
    assert any("3 non-finite" in n for n in notes)
    assert json.loads((out / "manifest.json").read_text())["options"]["fix_nonfinite"] is True


def test_negative_pixels_are_clamped_with_a_warning(tmp_path):
    path = _pfm_with(tmp_path, "neg.pfm", [-0.5, -2.0])
    out = tmp_path / "o"
    result = run(path, "-o", out, *SMALL)
    assert result.exit_code == 0, result.output
    assert "warning" in result.stderr and "2 negative" in result.stderr
    assert any("2 negative" in n for n in json.loads((out / "manifest.json").read_text())["input"]["notes"])


@pytest.mark.parametrize("args, fragment", [
    (["--size", "0"], "size"),
    (["--size", "3"], "power of two"),
    (["--size", "48"], "power of two"),
    (["--size", "100000"], "4096"),
    (["--size", "16", "--min-size", "16"], "min size"),
    (["--size", "32", "--irradiance-size", "0"], "irradiance size"),
    (["--size", "32", "--lut-size", "1"], "LUT size"),
    (["--size", "32", "--format", "rgb9e5"], "format"),
    (["--size", "32", "--method", "magic"], "method"),
])
def test_absurd_options(env, tmp_path, args, fragment):
    out = tmp_path / "o"
    assert_failed_cleanly(run(env, "-o", out, *args), out, fragment)


def test_wrong_number_of_files(env, tmp_path):
    out = tmp_path / "o"
    assert_failed_cleanly(run(env, env, "-o", out, *SMALL), out, "six face files")


def test_existing_output_directory(env, tmp_path):
    out = tmp_path / "o"
    out.mkdir()
    (out / "mine.txt").write_text("keep me")
    result = run(env, "-o", out, *SMALL)
    assert result.exit_code == 1 and "not empty" in result.stderr and "--force" in result.stderr
    assert [p.name for p in out.iterdir()] == ["mine.txt"]
    result = run(env, "-o", out, *SMALL, "--force", "--quiet")
    assert result.exit_code == 0, result.output
    assert not (out / "mine.txt").exists() and (out / "manifest.json").is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o", "sky.pfm"]
    file_out = tmp_path / "file"
    file_out.write_text("x")
    result = run(env, "-o", file_out, *SMALL, "--force")
    assert result.exit_code == 1 and "not a directory" in result.stderr


def test_bake_with_two_maps_points_to_batch_bake(tmp_path):
    from typer.testing import CliRunner

    from pbrkit.cli import app
    from pbrkit.data import environment_path

    env = str(environment_path())
    r = CliRunner().invoke(app, ["bake", env, env, "-o", str(tmp_path / "b")])
    text = " ".join(r.output.split())
    assert r.exit_code != 0 and "got 2 (to bake several environments, one folder each: pbrkit batch bake" in text
    assert not (tmp_path / "b").exists()


def test_a_bake_finer_than_its_map_warns_once(tmp_path):
    """The bundled map is 512 x 256 (about 128 texels per cube face): --size 256 upsamples
    it, one warning line saying so (the bake is still written); --size 128 does not."""
    from typer.testing import CliRunner

    from pbrkit.cli import app
    from pbrkit.data import environment_path

    options = ["--min-size", "64", "--irradiance-size", "8", "--lut-size", "16"]
    r = CliRunner().invoke(app, ["bake", str(environment_path()), "-o", str(tmp_path / "up"), "--size", "256",
                                 *options, "-q"])
    text = " ".join(r.output.split())
    assert r.exit_code == 0, r.output
    assert text.count("pbrkit: warning: --size 256 is finer than the map (512 x 256: about 128 texels per cube "
                      "face): the specular chain upsamples it") == 1 and "--size 128 keeps its detail" in text
    r = CliRunner().invoke(app, ["bake", str(environment_path()), "-o", str(tmp_path / "ok"), "--size", "128",
                                 *options, "-q"])
    assert r.exit_code == 0 and "warning" not in r.output


def test_a_bake_of_an_rgba_map_warns_once_that_alpha_is_ignored(tmp_path):
    """An RGBA OpenEXR environment bakes from its RGB, with one warning line naming the
    file; the bake is written."""
    import OpenEXR
    from typer.testing import CliRunner

    from pbrkit.cli import app

    rgb = np.random.default_rng(2).random((32, 64, 3)).astype(np.float32) + 0.05
    channels = {c: np.ascontiguousarray(rgb[..., i]) for i, c in enumerate("RGB")}
    channels["A"] = np.ones((32, 64), np.float32)
    env = tmp_path / "rgba.exr"
    OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}, channels).write(str(env))
    r = CliRunner().invoke(app, ["bake", str(env), "-o", str(tmp_path / "b"), "--size", "16", "--min-size", "8",
                                 "--irradiance-size", "8", "--lut-size", "16", "-q"])
    text = " ".join(r.output.split())
    assert r.exit_code == 0, r.output
    assert text.count(f"pbrkit: warning: {env}: its alpha channel is ignored") == 1
    assert (tmp_path / "b" / "manifest.json").is_file()


def test_bake_with_a_target_lists_its_files_and_how_to_load_them(tmp_path):
    import json

    from typer.testing import CliRunner

    from pbrkit.cli import app
    from pbrkit.data import environment_path

    out = tmp_path / "b"
    r = CliRunner().invoke(app, ["bake", str(environment_path()), "-o", str(out), "--size", "32", "--min-size", "8",
                                 "--irradiance-size", "8", "--lut-size", "16", "--target", "three"])
    assert r.exit_code == 0, r.output
    entry = json.loads((out / "manifest.json").read_text())["targets"]["three"]
    listed = [line for line in r.stdout.splitlines() if line.startswith("three: ")]
    assert listed == ["three: " + ", ".join(f"{out}/{f}" for f in entry["files"].values())]
    assert all((out / f).is_file() for f in entry["files"].values())
    assert f"  load (paths relative to {out}/): {entry['load']}" in r.stdout.splitlines()
    assert entry["load_base"] and "'./three/pbrkit-three.js'" in entry["load"]


def test_bake_only_target_writes_the_engine_s_folder_and_the_manifest(tmp_path):
    """--only-target: the engine's folder and manifest.json, none of pbrkit's own files;
    without an engine, or with --target generic, refused before any work (no folder)."""
    import json

    from typer.testing import CliRunner

    from pbrkit.cli import app
    from pbrkit.data import environment_path

    small = ["--size", "32", "--min-size", "8", "--irradiance-size", "8", "--lut-size", "16", "-q"]
    out = tmp_path / "b"
    r = CliRunner().invoke(app, ["bake", str(environment_path()), "-o", str(out), *small, "--target", "three",
                                 "--only-target"])
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in out.iterdir()) == ["manifest.json", "three"]
    entry = json.loads((out / "manifest.json").read_text())["targets"]["three"]
    assert sorted(str(p.relative_to(out)) for p in (out / "three").iterdir()) == sorted(entry["files"].values())
    for bad, said in ((["--only-target"], "--only-target needs an engine"),
                      (["--only-target", "--target", "generic"], "--target generic writes pbrkit's own files")):
        r = CliRunner().invoke(app, ["bake", str(environment_path()), "-o", str(tmp_path / "x"), *small, *bad])
        assert r.exit_code == 1 and said in " ".join(r.output.split()) and not (tmp_path / "x").exists()
