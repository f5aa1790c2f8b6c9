"""Every bad input is refused cleanly, and the command line says what it does.

A refusal is: a non-zero exit status, exactly one ``pbrkit: error:`` line that
names the file the user asked for (never a temporary name), no traceback, no
other output (stdout empty; on stderr at most the plain progress lines that
came before a failure found mid-run; nothing written on the process's file
descriptors by native code), and nothing left behind: no output, no hidden
temporary file or ``.partial`` folder.

Also here: :func:`pbrkit.core.atomic.atomic_group` and the race check of
:func:`~pbrkit.core.atomic.atomic_directory`, the help (choices, no Python
types, no heavy import), progress lines and --quiet, SIGTERM during a bake and
two bakes racing for one folder.
"""

from __future__ import annotations

import errno
import json
import os
import re
import signal
import stat
import struct
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from pbrkit.cli import console
from pbrkit.cli import app
from pbrkit.core import atomic
from pbrkit.core.atomic import atomic_directory, atomic_group, atomic_path
from pbrkit.core.errors import InputError, OutputError
from pbrkit.io.exr import exr_bytes
from pbrkit.io.pfm import write_pfm

SMALL = ["--size", "16", "--min-size", "4", "--irradiance-size", "8", "--lut-size", "16"]
RENDER_SMALL = ["--width", "8", "--height", "8", "--bake-size", "8"]
PROGRESS = re.compile(r"^pbrkit [a-z]+: .+ \(\d+/\d+\)$")


# ------------------------------------------------------------------ helpers


def sky(h=8):
    img = np.full((h, 2 * h, 3), 0.5, np.float32)
    img[: h // 2] += 0.5
    return img


@pytest.fixture
def env(tmp_path):
    path = tmp_path / "sky.pfm"
    write_pfm(path, sky())
    return path


def listing(root):
    """Every path under ``root`` (hidden ones included), relative."""
    return sorted(str(p.relative_to(root)) for p in Path(root).rglob("*"))


def invoke(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def assert_refused(result, root, before, name, *fragments, capfd=None, alone=True):
    """The refusal contract (module doc).  ``alone``: stderr holds the error line
    and nothing else (the failure came before any progress line was due)."""
    assert result.exit_code not in (0, None), result.output
    assert isinstance(result.exception, SystemExit), repr(result.exception)  # not an uncaught exception
    assert "Traceback" not in result.output
    assert result.stdout == "", result.stdout
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    errors = [line for line in lines if line.startswith("pbrkit: error:")]
    assert len(errors) == 1, result.stderr
    others = [line for line in lines if line not in errors]
    assert (not others) if alone else all(PROGRESS.match(line) for line in others), result.stderr
    assert lines[-1] == errors[0]
    message = errors[0]
    assert str(name) in message, message
    assert not re.search(r"/\.[^/ ]+\.[a-z0-9_]{6,}", message), message  # no temporary name
    for fragment in fragments:
        assert fragment in message, message
    assert listing(root) == before, "left behind: " + ", ".join(sorted(set(listing(root)) - set(before)))
    if capfd is not None:
        captured = capfd.readouterr()
        assert captured.out == "" and captured.err == "", captured  # native code printed nothing
    return message


def exr_with_window(x1, y1, h=4, w=8):
    """A valid little EXR whose header claims the data window (0, 0) - (x1, y1)."""
    data = exr_bytes(np.ones((h, w, 3), np.float32))
    key = b"dataWindow\x00box2i\x00"
    i = data.index(key) + len(key) + 4
    return data[:i] + struct.pack("<4i", 0, 0, x1, y1) + data[i + 16:]


def fill_disk(monkeypatch, names=None):
    """Temporary files pbrkit.core.atomic creates are links to /dev/full, so that
    writing them fails with ENOSPC as on a full disk (folders stay real): every
    one, or with ``names`` only those of outputs with these file names (the disk
    fills up part-way through a command)."""
    dev = Path("/dev/full")
    if not dev.exists() or not stat.S_ISCHR(dev.stat().st_mode):
        pytest.skip("no /dev/full")
    real = atomic.tempfile

    class FullDiskTempfile:
        mkdtemp = staticmethod(real.mkdtemp)

        @staticmethod
        def mkstemp(*args, **kwargs):
            fd, name = real.mkstemp(*args, **kwargs)
            if names is not None and not any(Path(name).name.startswith(f".{n}.") for n in names):
                return fd, name
            os.close(fd)
            os.unlink(name)
            os.symlink(dev, name)
            return os.open(name, os.O_WRONLY), name

    real_chmod = os.chmod

    def chmod(path, mode, *args, **kwargs):  # never change /dev/full through a link
        assert not os.path.islink(path), f"{path}: a write to a full disk succeeded"
        return real_chmod(path, mode, *args, **kwargs)

    monkeypatch.setattr(atomic, "tempfile", FullDiskTempfile)
    monkeypatch.setattr(os, "chmod", chmod)


@pytest.fixture
def full_disk(monkeypatch):
    """Every temporary file pbrkit.core.atomic creates is a link to /dev/full (:func:`fill_disk`)."""
    fill_disk(monkeypatch)


# ============================================================ image files


def test_truncated_exr_is_refused_without_openexr_noise(tmp_path, capfd):
    data = exr_bytes(np.random.default_rng(0).random((64, 128, 3)).astype(np.float32))
    path = tmp_path / "cut.exr"
    path.write_bytes(data[: len(data) // 2])
    capfd.readouterr()
    before = listing(tmp_path)
    assert_refused(invoke("bake", path, "-o", tmp_path / "o", *SMALL), tmp_path, before, path,
                   "corrupt or truncated OpenEXR", capfd=capfd)


@pytest.mark.parametrize("x1, y1, figure", [
    (99999, 49999, "100000x50000"),     # beyond the per-side limit
    (30000, 15000, "chunk table"),      # within it; the file is far too short for it
    (-5, 3, "OpenEXR"),                 # inverted window
])
def test_absurd_exr_data_window_is_refused(tmp_path, capfd, x1, y1, figure):
    path = tmp_path / "window.exr"
    path.write_bytes(exr_with_window(x1, y1))
    capfd.readouterr()
    before = listing(tmp_path)
    assert_refused(invoke("bake", path, "-o", tmp_path / "o", *SMALL), tmp_path, before, path, figure,
                   capfd=capfd)


def test_image_size_limit_counts_pixels(tmp_path):
    from pbrkit.io.image_checks import MAX_PIXELS, MAX_SIDE, _check_size

    _check_size("a.exr", MAX_SIDE // 2, MAX_SIDE)
    with pytest.raises(InputError, match=r"a\.exr: image size 32768x32768 .* exceeds the limit of"):
        _check_size("a.exr", MAX_SIDE, MAX_SIDE)
    assert MAX_PIXELS == 32768 * 16384


# ============================================================ full disk


def test_every_writer_names_the_requested_file_on_a_full_disk(tmp_path, full_disk):
    from pbrkit.io.images import write_image

    for name in ("a.exr", "b.hdr", "c.pfm", "d.png", "deep/e.exr"):
        with pytest.raises(OSError) as caught:
            write_image(tmp_path / name, sky())
        assert isinstance(caught.value, OutputError) and caught.value.errno == errno.ENOSPC
        assert str(caught.value) == f"{tmp_path / name}: cannot write: [Errno 28] No space left on device"
    assert listing(tmp_path) == []


@pytest.mark.parametrize("suffix", [".npy", ".exr", ".h"])
def test_lut_on_a_full_disk(tmp_path, full_disk, suffix):
    out = tmp_path / f"t{suffix}"
    assert_refused(invoke("lut", "-o", out, "--size", "8"), tmp_path, [], out, "[Errno 28] No space left on device",
                   alone=False)


def test_bake_on_a_full_disk_names_the_file_in_the_output_folder(tmp_path, env, full_disk):
    out = tmp_path / "out"
    message = assert_refused(invoke("bake", env, "-o", out, *SMALL), tmp_path, listing(tmp_path),
                             out / "specular.ktx2", "[Errno 28]", alone=False)
    assert ".partial" not in message


def test_render_on_a_full_disk(tmp_path, env, full_disk):
    for name in ("r.png", "r.exr"):
        out = tmp_path / name
        assert_refused(invoke("render", "sphere", "-o", out, "--env", env, *RENDER_SMALL), tmp_path, ["sky.pfm"],
                       out, "[Errno 28]", alone=False)


def test_output_under_a_file_is_refused(tmp_path):
    (tmp_path / "file").write_text("x")
    out = tmp_path / "file" / "sub" / "t.npy"
    assert_refused(invoke("lut", "-o", out, "--size", "8"), tmp_path, ["file"], out, "not a directory",
                   alone=False)


# ============================================================ bake folders


def _bake_dir(tmp_path, env):
    out = tmp_path / "bake"
    result = invoke("bake", env, "-o", out, *SMALL, "-q")
    assert result.exit_code == 0, result.output
    return out


def _edit_manifest(out, edit):
    manifest = json.loads((out / "manifest.json").read_text())
    edit(manifest)
    (out / "manifest.json").write_text(json.dumps(manifest))


@pytest.mark.parametrize("edit, fragment", [
    (lambda m: m.pop("outputs"), "missing 'outputs'"),
    (lambda m: m["outputs"]["specular"].pop("levels"), "missing 'outputs.specular.levels'"),
    (lambda m: m["outputs"].update(specular=[1, 2]), "'outputs.specular' must be a JSON object"),
    (lambda m: m["outputs"]["irradiance"].update(size="big"), "'outputs.irradiance.size' must be a positive"),
    (lambda m: m.pop("sh"), "missing 'sh'"),
    (lambda m: m.update(sh=[[0, 0, 0]]), "'sh' must be 9 rows"),
    (lambda m: m["outputs"]["specular"].update(roughness=[0.0]), "'outputs.specular.roughness' must be"),
])
def test_bad_bake_manifest(tmp_path, env, edit, fragment):
    from pbrkit.io.bake_files import load_bake

    out = _bake_dir(tmp_path, env)
    _edit_manifest(out, edit)
    with pytest.raises(InputError, match=re.escape(f"{out / 'manifest.json'}: {fragment}")):
        load_bake(out)
    before = listing(tmp_path)
    result = invoke("render", "sphere", "-o", tmp_path / "r.png", "--env", out, *RENDER_SMALL)
    assert_refused(result, tmp_path, before, out / "manifest.json", fragment)
    scene = tmp_path / "scene.toml"
    scene.write_text('[environment]\nbake = "bake"\n[[objects]]\ntype = "sphere"\n')
    before = listing(tmp_path)
    result = invoke("render", scene, "-o", tmp_path / "r.png", *RENDER_SMALL)
    assert_refused(result, tmp_path, before, "manifest.json", fragment)


def test_render_env_takes_a_bake_folder(tmp_path, env):
    out = _bake_dir(tmp_path, env)
    result = invoke("render", "sphere", "-o", tmp_path / "r.png", "--env", out, *RENDER_SMALL, "-q")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "r.png").is_file()
    (tmp_path / "empty").mkdir()
    for missing, fragment in (("nothing-here", "not found"), ("empty", "no manifest.json")):
        before = listing(tmp_path)
        assert_refused(invoke("render", "sphere", "-o", tmp_path / "x.png", "--env", tmp_path / missing),
                       tmp_path, before, tmp_path / missing, fragment)


# ============================================================ options


@pytest.mark.parametrize("args, fragment", [
    (["render", "sphere", "-o", "{d}/r.png", "--exposure", "2000"], "--exposure"),
    (["render", "sphere", "-o", "{d}/r.png", "--exposure", "-64.5"], "[-64, 64]"),
    (["render", "sphere", "-o", "{d}/r.png", "--exposure", "nan"], "finite"),
    (["render", "sphere", "-o", "{d}/r.png", "--exposure", "inf"], "finite"),
    (["render", "sphere", "-o", "{d}/r.png", "--seed", "-1"], "2^64 - 1"),
    (["render", "sphere", "-o", "{d}/r.png", "--seed", str(2 ** 64)], "18446744073709551615"),
    (["furnace", "-o", "{d}/f", "--seed", "-5"], "--seed"),
    (["demo", "-o", "{d}/d", "--seed", str(10 ** 30)], "--seed"),
    (["render", "sphere", "-o", "{d}/r.png", "--mode", "fast"], "unknown mode 'fast'"),
    (["render", "sphere", "-o", "{d}/r.png", "--diffuse", "sg"], "sh, cube"),
    (["lut", "-o", "{d}/t.npy", "--visibility", "smith"], "unknown visibility"),
    (["bake", "{d}/sky.pfm", "-o", "{d}/o", "--layout", "cross"], "equirect, hcross, vcross"),
    (["furnace", "-o", "{d}/f", "--lobe", "ggx/smith"], "unknown lobe"),
    (["render", "sphere", "-o", "{d}/r.png", "--spp", "lots"], "--spp"),
    (["render", "sphere", "-o", "{d}/r.png", "--mode", "reference", "--spp", str(10 ** 12)], "--spp"),
    (["render", "sphere", "-o", "{d}/r.png", "--width", str(10 ** 30)], "--width"),
    (["render", "sphere", "-o", "{d}/r.png", "--bake-size", "48"], "--bake-size"),
    (["render", "sphere", "-o", "{d}/r.png", "--env", "{d}/missing.hdr"], "missing.hdr: environment file not found"),
    (["lut", "-o", "{d}/t.npy", "--size", str(10 ** 30)], "--size"),
    (["bake", "{d}/sky.pfm", "-o", "{d}/o", "--size", str(10 ** 30)], "size"),
    (["bake", "{d}/sky.pfm"], "Missing option"),
    (["lut", "-o", "{d}/t.npy", "--no-such-option"], "No such option"),
])
def test_bad_options_are_refused_in_one_line(tmp_path, env, args, fragment):
    before = listing(tmp_path)
    assert_refused(invoke(*[a.format(d=tmp_path) for a in args]), tmp_path, before, "", fragment)


def test_largest_seed_is_accepted(tmp_path, env):
    out = tmp_path / "r.exr"
    result = invoke("render", "sphere", "-o", out, "--env", env, "--mode", "reference", "--spp", "1", "--width", "4",
                    "--height", "4", "--seed", str(2 ** 64 - 1), "-q")
    assert result.exit_code == 0, result.output
    assert out.is_file() and (tmp_path / "r.stderr.exr").is_file()


# ============================================================ non-finite pixels


def _pfm_with_nans(tmp_path, name, fraction):
    img = sky(8)
    flat = img.reshape(-1)
    flat[: int(round(fraction * flat.size))] = np.nan
    path = tmp_path / name
    path.write_bytes(f"PF\n{img.shape[1]} {img.shape[0]}\n-1.0\n".encode() + img[::-1].astype("<f4").tobytes())
    return path


@pytest.mark.parametrize("fraction, fragment", [(1.0, "all 384 samples are non-finite"),
                                                 (0.75, "too few finite samples")])
def test_fix_nonfinite_refuses_images_with_too_little_to_fill_from(tmp_path, fraction, fragment):
    path = _pfm_with_nans(tmp_path, "nan.pfm", fraction)
    before = listing(tmp_path)
    message = assert_refused(invoke("bake", path, "-o", tmp_path / "o", *SMALL, "--fix-nonfinite"), tmp_path, before,
                             path, fragment)
    assert "--fix-nonfinite" in message


def test_nonfinite_messages_name_the_flag_and_render_takes_it(tmp_path):
    path = _pfm_with_nans(tmp_path, "few.pfm", 0.02)
    for command in (["bake", path, "-o", tmp_path / "o", *SMALL],
                    ["render", "sphere", "-o", tmp_path / "r.png", "--env", path, *RENDER_SMALL]):
        before = listing(tmp_path)
        message = assert_refused(invoke(*command), tmp_path, before, path, "non-finite")
        assert "--fix-nonfinite" in message and "pass fix_nonfinite=True" not in message
    result = invoke("render", "sphere", "-o", tmp_path / "r.png", "--env", path, *RENDER_SMALL, "--fix-nonfinite",
                    "-q")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "r.png").is_file()


# ============================================================ reports: committed together

FURNACE_SMALL = ["--mu-count", "4", "--roughness-count", "3", "--samples", "16", "--lobe", "ggx/height-correlated"]
DEMO_SMALL = ["--size", "32", "--spp", "2", "--bake-size", "32"]


def test_furnace_writes_all_of_its_files_or_none(tmp_path, monkeypatch):
    out = tmp_path / "f"
    fill_disk(monkeypatch, ["furnace.png"])  # the disk fills up at the last file, the figure
    assert_refused(invoke("furnace", "-o", out, *FURNACE_SMALL), tmp_path, [], out / "furnace.png",
                   "cannot write: [Errno 28] No space left on device", alone=False)
    # an earlier run's files stay as they were
    monkeypatch.undo()
    assert invoke("furnace", "-o", out, *FURNACE_SMALL, "-q").exit_code == 0
    old = {name: (out / name).read_bytes() for name in listing(out)}
    assert set(old) == {"furnace.csv", "furnace.npy", "furnace.json", "furnace.png"}
    fill_disk(monkeypatch, ["furnace.png"])
    assert_refused(invoke("furnace", "-o", out, *FURNACE_SMALL, "--seed", "1", "--force"), tmp_path,
                   listing(tmp_path), out / "furnace.png", "[Errno 28]", alone=False)
    assert {name: (out / name).read_bytes() for name in listing(out)} == old


@pytest.mark.parametrize("command, options", [("furnace", FURNACE_SMALL), ("approximations", ["--size", "4"])])
def test_report_commands_refuse_a_non_empty_folder_without_force(tmp_path, command, options):
    """As bake, ltc, shaders and hatching: an output folder with files in it is refused
    (one line naming it and --force) before any work; --force writes into it."""
    out = tmp_path / "o"
    out.mkdir()
    (out / "mine.txt").write_text("keep")
    r = invoke(command, "-o", out, *options, "-q")
    assert r.exit_code != 0 and "directory exists and is not empty (use --force" in r.output
    assert listing(out) == ["mine.txt"]
    assert invoke(command, "-o", out, *options, "-q", "--force").exit_code == 0
    assert (out / "mine.txt").read_text() == "keep" and len(listing(out)) > 1


def test_compensation_writes_all_of_its_files_or_none(tmp_path, monkeypatch):
    from pbrkit.app.report import compensation_report

    fill_disk(monkeypatch, ["compensation.png"])
    with pytest.raises(OutputError) as caught:
        compensation_report(tmp_path / "c", "kulla-conty", table_size=8)
    expected = f"{tmp_path / 'c' / 'compensation.png'}: cannot write: [Errno 28] No space left on device"
    assert str(caught.value) == expected
    assert listing(tmp_path) == []


def test_approximations_write_both_files_or_none(tmp_path, monkeypatch):
    out = tmp_path / "a"
    out.mkdir()
    fill_disk(monkeypatch, ["approximations.json"])  # the figure is written, then the disk is full
    assert_refused(invoke("approximations", "-o", out, "--size", "4"), tmp_path, ["a"],
                   out / "approximations.json", "[Errno 28]", alone=False)


def test_demo_commits_its_folder_as_a_whole(tmp_path, monkeypatch):
    out = tmp_path / "site"
    out.mkdir()
    (out / "index.html").write_text("an earlier demo")  # a previous demo's folder is replaced as a whole ...
    before = listing(tmp_path)
    fill_disk(monkeypatch, ["index.html"])  # ... and left as it was when the page, written last, fails
    assert_refused(invoke("demo", "-o", out, *DEMO_SMALL), tmp_path, before, out / "index.html",
                   "cannot write: [Errno 28] No space left on device", alone=False)
    assert (out / "index.html").read_text() == "an earlier demo"


def test_demo_refuses_a_folder_with_other_files_and_too_little_memory_up_front(tmp_path, monkeypatch):
    import pbrkit.rendering.budget as budget

    out = tmp_path / "site"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    assert_refused(invoke("demo", "-o", out, *DEMO_SMALL), tmp_path, ["site", "site/notes.txt"], out,
                   "other than a previous demo's (notes.txt)")
    monkeypatch.setattr(budget, "available_memory", lambda: 1 << 20)
    assert_refused(invoke("demo", "-o", tmp_path / "new", *DEMO_SMALL), tmp_path, ["site", "site/notes.txt"],
                   "", "of memory", "has 1 MiB available")


@pytest.mark.parametrize("args, fragment", [
    (["demo", "-o", "{d}/d", "--bake-size", "16"], "--bake-size must be a power of two in [32, 2048]; got 16"),
    (["demo", "-o", "{d}/d", "--size", "8"], "--size must be an integer in [16, 4096]; got 8"),
    (["bake", "{d}/sky.pfm", "-o", "{d}/o", "--size", "3", "--min-size", "7"],
     "--size must be a power of two in [2, 4096]; got 3"),
    (["bake", "{d}/sky.pfm", "-o", "{d}/o", "--size", "16", "--min-size", "7"],
     "--min-size must be a power of two in [1, 4096]; got 7"),
    (["bake", "{d}/sky.pfm", "-o", "{d}/o", "--size", "16", "--min-size", "32"],
     "--min-size must be smaller than --size"),
])
def test_size_refusals_name_the_flags(tmp_path, env, args, fragment):
    before = listing(tmp_path)
    message = assert_refused(invoke(*[a.format(d=tmp_path) for a in args]), tmp_path, before, "", fragment)
    assert "bake_size" not in message and "min size must" not in message


# ============================================================ lut + sidecar


def test_lut_and_sidecar_are_committed_together(tmp_path, monkeypatch):
    out = tmp_path / "t.npy"
    (tmp_path / "t.npy.json").mkdir()  # the description cannot be written
    assert_refused(invoke("lut", "-o", out, "--size", "8"), tmp_path, ["t.npy.json"], "t.npy.json",
                   "Is a directory", alone=False)
    (tmp_path / "t.npy.json").rmdir()
    result = invoke("lut", "-o", out, "--size", "8", "-q")
    assert result.exit_code == 0, result.output
    old = out.read_bytes(), (tmp_path / "t.npy.json").read_bytes()
    real = Path.write_text

    def full(self, *args, **kwargs):  # the disk fills up when the description is written
        if self.name.endswith(".json"):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(self))
        return real(self, *args, **kwargs)

    monkeypatch.setattr(Path, "write_text", full)
    result = invoke("lut", "-o", out, "--size", "16", "--kind", "splitsum")
    assert_refused(result, tmp_path, ["t.npy", "t.npy.json"], "t.npy.json", "[Errno 28]", alone=False)
    assert (out.read_bytes(), (tmp_path / "t.npy.json").read_bytes()) == old  # the old pair, untouched


# ============================================================ atomic_group


def test_atomic_group_commits_all_files(tmp_path):
    a, b = tmp_path / "x" / "a.exr", tmp_path / "b.json"
    with atomic_group([a, b]) as (ta, tb):
        assert ta.parent == a.parent and ta.suffix == ".exr" and ta.name.startswith(".a.exr.")
        assert not a.exists() and not b.exists()
        ta.write_bytes(b"A")
        tb.write_text("B")
    assert a.read_bytes() == b"A" and b.read_text() == "B"
    assert listing(tmp_path) == ["b.json", "x", "x/a.exr"]
    assert stat.S_IMODE(a.stat().st_mode) == 0o666 & ~atomic.current_umask()


def test_atomic_group_writes_nothing_when_the_block_fails(tmp_path):
    keep = tmp_path / "b.json"
    keep.write_text("old")
    for error in (ValueError("bad"), KeyboardInterrupt()):
        with pytest.raises(type(error)):
            with atomic_group([tmp_path / "new" / "deeper" / "a.npy", keep]) as (ta, tb):
                ta.write_bytes(b"A")
                tb.write_text("new")
                raise error
        assert listing(tmp_path) == ["b.json"] and keep.read_text() == "old"


def test_atomic_group_undoes_renames_when_a_later_one_fails(tmp_path):
    first, second = tmp_path / "a.npy", tmp_path / "a.npy.json"
    first.write_text("old A")
    with pytest.raises(OutputError, match=re.escape(f"{second}: cannot write: [Errno 21] Is a directory")):
        with atomic_group([first, second]) as (ta, tb):
            second.mkdir()  # appears while writing: its rename fails after the first one's
            ta.write_text("new A")
            tb.write_text("new B")
    assert first.read_text() == "old A"
    assert listing(tmp_path) == ["a.npy", "a.npy.json"]
    second.rmdir()
    first.unlink()
    with pytest.raises(OutputError):
        with atomic_group([first, second]) as (ta, tb):
            second.mkdir()
            ta.write_text("new A")
    assert listing(tmp_path) == ["a.npy.json"]  # the new first file is gone again


def test_atomic_group_errors_name_the_requested_files(tmp_path, full_disk):
    from pbrkit.io.exr import write_exr

    a, b = tmp_path / "img.exr", tmp_path / "img.stderr.exr"
    with pytest.raises(OutputError, match=re.escape(f"{b}: cannot write: [Errno 28]")):
        with atomic_group([a, b]) as (ta, tb):
            write_exr(tb, np.ones((2, 2, 3), np.float32))  # a writer that is atomic itself
            write_exr(ta, np.ones((2, 2, 3), np.float32))
    assert listing(tmp_path) == []
    with pytest.raises(ValueError, match="twice"):
        with atomic_group([a, tmp_path / "." / "img.exr"]):
            pass


def test_atomic_group_with_atomic_writers(tmp_path):
    from pbrkit.io.exr import read_exr, write_exr

    a, b = tmp_path / "img.exr", tmp_path / "img.stderr.exr"
    with atomic_group([a, b]) as (ta, tb):
        write_exr(ta, np.full((2, 3, 3), 2.0, np.float32))
        write_exr(tb, np.full((2, 3, 3), 0.5, np.float32))
    assert read_exr(a)[0, 0, 0] == 2.0 and read_exr(b)[0, 0, 0] == 0.5
    assert listing(tmp_path) == ["img.exr", "img.stderr.exr"]


def test_atomic_path_removes_the_folders_it_created(tmp_path):
    with pytest.raises(RuntimeError):
        with atomic_path(tmp_path / "a" / "b" / "c.txt") as tmp:
            tmp.write_text("x")
            raise RuntimeError
    assert listing(tmp_path) == []


def test_atomic_directory_refuses_a_folder_filled_meanwhile(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    one, two = atomic_directory(out), atomic_directory(out)
    first, second = one.__enter__(), two.__enter__()  # both see an empty folder
    (first / "a.txt").write_text("first")
    (second / "b.txt").write_text("second")
    one.__exit__(None, None, None)  # the first one finishes while the second writes
    with pytest.raises(OutputError, match=re.escape(f"{out}: directory is no longer empty")):
        two.__exit__(None, None, None)
    assert listing(tmp_path) == ["out", "out/a.txt"]


def test_atomic_directory_errors_name_files_in_the_output(tmp_path, full_disk):
    out = tmp_path / "out"
    with pytest.raises(OutputError, match=re.escape(f"{out / 'faces' / 'f.exr'}: cannot write: [Errno 28]")):
        with atomic_directory(out) as tmp:
            (tmp / "faces").mkdir()
            atomic.write_bytes(tmp / "faces" / "f.exr", b"x")
    assert listing(tmp_path) == []


# ============================================================ interruptions and errors


def _raising(monkeypatch, error):
    import pbrkit.albedo.lut as lut

    def lookup_table(*args, **kwargs):
        raise error

    monkeypatch.setattr(lut, "lookup_table", lookup_table)  # what pbrkit lut calls


@pytest.mark.parametrize("error, code, fragment", [
    (KeyboardInterrupt(), 130, "interrupted"),
    (MemoryError(), 1, "out of memory"),
])
def test_interrupt_and_memory_errors_are_one_line(tmp_path, monkeypatch, error, code, fragment):
    _raising(monkeypatch, error)
    result = invoke("lut", "-o", tmp_path / "t.npy", "--size", "8")
    assert result.exit_code == code
    assert_refused(result, tmp_path, [], "", fragment, alone=False)


def test_openexr_errors_are_one_line(tmp_path, monkeypatch):
    import OpenEXR

    _raising(monkeypatch, OpenEXR.error("library says no"))
    assert_refused(invoke("lut", "-o", tmp_path / "t.npy", "--size", "8"), tmp_path, [], "", "library says no",
                   alone=False)


def test_programming_errors_are_not_swallowed(tmp_path, monkeypatch):
    _raising(monkeypatch, ZeroDivisionError("a bug"))
    result = invoke("lut", "-o", tmp_path / "t.npy", "--size", "8")
    assert isinstance(result.exception, ZeroDivisionError)


# ============================================================ help


def test_help_lists_the_choices_and_no_python_types():
    runner = CliRunner()
    expected = {
        "render": ["[realtime|reference|compare]", "[aces|khronos-neutral|agx|reinhard|none]", "[sh|cube]"],
        "lut": ["[splitsum|dfg]", "[schlick-ggx|separable|height-correlated]", "[float16|float32]"],
        "bake": ["[rgba16f|b10g11r11]", "[spectral|fis]", "[hanning|lanczos]", "[equirect|hcross|vcross]"],
        "furnace": ["[kulla-conty|filament]", "ggx/height-correlated", "urp_mobile"],
        "demo": [], "approximations": [],
    }
    for command, choices in expected.items():
        result = runner.invoke(app, [command, "--help"], env={"COLUMNS": "300"})
        assert result.exit_code == 0, result.output
        for choice in choices:
            assert choice in result.output, (command, choice)
        for line in result.output.splitlines():
            if command == "render" and ("--bounces" in line or "--occlusion" in line):
                continue  # the lead's options (their metavars are theirs to set)
            assert not re.search(r"<(bool|str|int|float|Path|path|list\[[^>]*\])>", line), (command, line)
        assert "[default: 0]" in result.output or command in ("lut", "bake", "approximations")


def test_choices_are_defined_once():
    """pbrkit.choices is the only definition: the library's tuples are its objects, the
    tables keyed by names have its names, and the command line offers them."""
    import importlib

    from pbrkit import choices
    from pbrkit.albedo.furnace import furnace_lobes
    from pbrkit.albedo.tables import VISIBILITIES
    from pbrkit.ibl.bake import SPECULAR_FORMATS

    from pbrkit.cli import ltc as ltc_cli
    from pbrkit.cli import options
    from pbrkit.cli import render as render_cli
    from pbrkit.cli import shaders as shaders_cli

    module = importlib.import_module
    assert module("pbrkit.rendering.run").MODES is choices.MODES is render_cli.MODES
    assert module("pbrkit.core.color").TONEMAPS is choices.TONEMAPS is render_cli.TONEMAPS
    assert module("pbrkit.rendering.realtime").ENGINES is choices.RENDER_ENGINES is render_cli.RENDER_ENGINES
    assert module("pbrkit.ltc.fit").CLIPPINGS is choices.LTC_CLIPPINGS is ltc_cli.LTC_CLIPPINGS
    assert module("pbrkit.ibl.bake").METHODS is choices.BAKE_METHODS is options.BAKE_METHODS
    assert module("pbrkit.shaders").TARGETS is choices.SHADER_TARGETS is shaders_cli.SHADER_TARGETS
    assert tuple(VISIBILITIES) == choices.VISIBILITIES and tuple(SPECULAR_FORMATS) == choices.BAKE_FORMATS
    assert tuple(furnace_lobes()) == choices.LOBES


def test_help_imports_neither_numba_nor_the_renderer():
    code = textwrap.dedent("""
        import sys
        from pbrkit.cli import app
        for args in (["--help"], ["render", "--help"], ["bake", "--help"], ["--version"]):
            try:
                app(args, prog_name="pbrkit")
            except SystemExit as exc:
                assert exc.code in (0, None), exc.code
        heavy = [m for m in ("numba", "numpy", "pbrkit.rendering", "pbrkit.brdf", "OpenEXR") if m in sys.modules]
        print("HEAVY", heavy, file=sys.stderr)
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "COLUMNS": "120"})
    assert done.returncode == 0, done.stderr
    assert "HEAVY []" in done.stderr, done.stderr
    assert "Usage: pbrkit" in done.stdout and re.search(r"^pbrkit \S+$", done.stdout, re.M), done.stdout


def test_python_m_pbrkit_runs_the_command_line():
    done = subprocess.run([sys.executable, "-m", "pbrkit", "--version"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and done.stdout.startswith("pbrkit "), done.stderr


# ============================================================ progress


def test_progress_lines_when_piped_and_silence_with_quiet(tmp_path, env):
    result = invoke("lut", "-o", tmp_path / "t.npy", "--size", "8")
    assert result.exit_code == 0, result.output
    assert result.stderr.splitlines() == ["pbrkit lut: integrate (1/2)", "pbrkit lut: write (2/2)"]
    result = invoke("lut", "-o", tmp_path / "q.npy", "--size", "8", "--quiet")
    assert result.exit_code == 0 and result.stdout == "" and result.stderr == ""
    result = invoke("bake", env, "-o", tmp_path / "b", *SMALL)
    # the 16 x 8 sky holds about 4 texels per face: --size 16 upsamples it, one warning line last
    *lines, warning = result.stderr.splitlines()
    assert warning.startswith("pbrkit: warning: --size 16 is finer than the map (16 x 8"), result.stderr
    assert result.exit_code == 0 and all(PROGRESS.match(line) for line in lines), result.stderr
    assert lines[0] == "pbrkit bake: load (1/19)" and lines[-1] == "pbrkit bake: write manifest (19/19)"
    result = invoke("render", "sphere", "-o", tmp_path / "r.png", "--env", env, *RENDER_SMALL)
    assert result.exit_code == 0, result.output
    assert [line for line in result.stderr.splitlines() if line.startswith("pbrkit render:")] == [
        "pbrkit render: load (1/4)", "pbrkit render: bake (2/4)", "pbrkit render: realtime (3/4)",
        "pbrkit render: write (4/4)"]
    result = invoke("render", "sphere", "-o", tmp_path / "s.png", "--env", env, *RENDER_SMALL, "-q")
    assert result.exit_code == 0 and result.stdout == "" and result.stderr == ""


def test_a_slow_first_stage_shows_its_line(monkeypatch, tmp_path):
    monkeypatch.setattr(console._Stages, "FIRST_LINE_DELAY", 0.0)
    import time

    import pbrkit.albedo.lut as lut

    real = lut.lookup_table

    def slow(*args, **kwargs):
        time.sleep(0.2)
        return real(*args, **kwargs)

    monkeypatch.setattr(lut, "lookup_table", slow)
    result = invoke("lut", "-o", tmp_path / "t.npy", "--size", "8")
    assert result.stderr.splitlines()[0] == "pbrkit lut: integrate (1/2)"


# ============================================================ signals and races

# The bake subprocesses below write their faces slowly (a sleep per file), so that a
# signal or a second bake lands while the output is being written.
_SLOW_BAKE = textwrap.dedent("""
    import sys, time
    import pbrkit.io.exr as exr
    real = exr.write_exr
    def slow(*args, **kwargs):
        time.sleep(0.03)
        return real(*args, **kwargs)
    exr.write_exr = slow
    from pbrkit.cli import app
    app(sys.argv[1:], prog_name="pbrkit")
""")


def _slow_bake(env, out, *extra):
    return subprocess.Popen([sys.executable, "-c", _SLOW_BAKE, "bake", str(env), "-o", str(out), *SMALL, *extra],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def test_sigterm_during_a_bake_leaves_nothing(tmp_path, env):
    out = tmp_path / "out"
    process = _slow_bake(env, out)
    for line in process.stderr:  # progress lines arrive as the stages start
        if line.startswith("pbrkit bake: write"):
            assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".partial")]
            process.send_signal(signal.SIGTERM)
            break
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 143, stderr
    assert stderr.strip().splitlines()[-1] == "pbrkit: error: terminated (SIGTERM)" and "Traceback" not in stderr
    assert stdout == ""
    assert listing(tmp_path) == ["sky.pfm"]


def test_two_bakes_into_one_empty_folder(tmp_path, env):
    out = tmp_path / "out"
    out.mkdir()
    processes = [_slow_bake(env, out, "-q") for _ in range(2)]
    results = [(p.wait(timeout=180), *p.communicate()) for p in processes]
    codes = sorted(code for code, _, _ in results)
    assert codes == [0, 1], results
    _, stdout, stderr = next(r for r in results if r[0] == 1)
    assert stdout == "" and len(stderr.strip().splitlines()) == 1, stderr
    assert stderr.startswith(f"pbrkit: error: {out}: ") and "empty" in stderr, stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "sky.pfm"]
    assert (out / "manifest.json").is_file() and not [p for p in out.rglob(".*")]
