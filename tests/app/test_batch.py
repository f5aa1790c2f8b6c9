"""``pbrkit batch bake|render`` (issue 14) on real Dask clusters.

Two clusters: the command's own ``LocalCluster`` of 2 worker processes
(``--workers 2``), and a ``distributed`` scheduler with 2 worker processes
started here on 127.0.0.1 the way a user starts one (``dask scheduler``,
``dask worker``), which the other tests reach with ``--scheduler``.  The
outputs are compared byte for byte with what the single commands write:
``pbrkit bake`` run as separate processes, ``pbrkit render`` in this process.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from pbrkit.app.batch import expand_inputs, output_names
from pbrkit.cli import app
from pbrkit.data import environment_path

SMALL = ["--size", "16", "--min-size", "4", "--irradiance-size", "4", "--lut-size", "4"]
BATCH_FILES = {"index.html", "batch.json"}


def tree(folder):
    """{relative path: bytes} of every file under ``folder``."""
    folder = Path(folder)
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def path_tag(path):
    return hashlib.sha256(os.path.abspath(path).encode()).hexdigest()[:8]


def batch(*args):
    return CliRunner().invoke(app, ["batch", *map(str, args)])


def summary_of(out):
    return json.loads((Path(out) / "batch.json").read_text())


def status_of(out):
    return {o["name"]: o["status"] for o in summary_of(out)["inputs"]}


def no_temporaries(out):
    return not [p.name for p in Path(out).iterdir() if p.name.startswith(".")]


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """Copies of the bundled environment: two with the same stem in different
    folders, one other, and a truncated (corrupt) one."""
    root = tmp_path_factory.mktemp("inputs")
    data = environment_path().read_bytes()
    files = {"a": root / "a" / "sky.hdr", "b": root / "b" / "sky.hdr", "other": root / "other.hdr"}
    for path in files.values():
        path.parent.mkdir(exist_ok=True)
        path.write_bytes(data)
    files["bad"] = root / "bad.hdr"
    files["bad"].write_bytes(data[: len(data) // 3])
    return files


@pytest.fixture(scope="module")
def scheduler(tmp_path_factory):
    """A distributed scheduler on 127.0.0.1 and 2 worker processes (1 thread, 1
    Numba thread each), started as a user would start them; yields (address,
    a client of it)."""
    from distributed import Client

    root = tmp_path_factory.mktemp("cluster")
    file = root / "scheduler.json"
    env = dict(os.environ, NUMBA_NUM_THREADS="1")
    log = open(root / "cluster.log", "wb")
    procs = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                               "--port", "0", "--no-dashboard", "--scheduler-file", str(file)],
                              stdout=log, stderr=log, env=env)]
    client = None
    try:
        deadline = time.monotonic() + 60
        while not file.exists() or not file.read_text().strip():
            assert time.monotonic() < deadline and procs[0].poll() is None, "the scheduler did not start"
            time.sleep(0.1)
        address = json.loads(file.read_text())["address"]
        procs.append(subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nworkers",
                                       "2", "--nthreads", "1", "--no-dashboard", "--memory-limit", "0"],
                                      stdout=log, stderr=log, env=env))
        client = Client(address, timeout=60)
        client.wait_for_workers(2, timeout=60)
        yield address, client
    finally:
        if client is not None:
            try:
                client.shutdown()  # the scheduler and its workers close (faster than SIGTERM's graceful stop)
            except Exception:
                client.close()
        for p in reversed(procs):
            if p.poll() is None:
                try:
                    p.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    p.terminate()
        for p in reversed(procs):
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
        log.close()


def separate_bakes(paths, out, *options):
    """``pbrkit bake`` for each path, as separate processes (run side by side)."""
    procs = [subprocess.Popen([sys.executable, "-m", "pbrkit", "bake", str(p), "-o", str(out / f"ref{k}"), "-q",
                               *options], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
             for k, p in enumerate(paths)]
    for p in procs:
        stdout, stderr = p.communicate(timeout=300)
        assert p.returncode == 0, stderr.decode()
    return [tree(out / f"ref{k}") for k in range(len(paths))]


# ----------------------------------------------------------------- inputs


def test_names_are_stems_and_same_stems_get_their_path_hash(tmp_path):
    for rel in ("a/sky.hdr", "b/Sky.exr", "x/index.html.hdr", "x/studio.hdr", "x/studio-0.pfm", "x/notes.txt",
                "x/thumb.jpg"):
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_bytes(b"x")
    listing = tmp_path / "list.txt"
    listing.write_text("# my library\nx\n\na/*.hdr\nx/studio.hdr\n")
    found = expand_inputs([str(tmp_path / "b" / "Sky.exr")], [listing], "bake")
    # folders give their HDR files (not .txt, not the .jpg preview), sorted; a file named twice counts once
    assert [p.relative_to(tmp_path).as_posix() for p in found] == [
        "b/Sky.exr", "x/index.html.hdr", "x/studio-0.pfm", "x/studio.hdr", "a/sky.hdr"]
    names = output_names(found)
    assert names == [f"Sky-{path_tag(found[0])}", f"index.html-{path_tag(found[1])}", "studio-0", "studio",
                     f"sky-{path_tag(found[4])}"]
    assert output_names(list(reversed(found))) == list(reversed(names))  # the order changes no name
    assert output_names(["spheres", "area"]) == ["spheres", "area"]
    with pytest.raises(ValueError, match="matches no"):
        expand_inputs([str(tmp_path / "nothing" / "*.hdr")], (), "bake")
    with pytest.raises(ValueError, match="no such file or directory"):
        expand_inputs([str(tmp_path / "missing.hdr")], (), "bake")
    with pytest.raises(ValueError, match="no .toml / .json files"):
        expand_inputs([str(tmp_path / "x")], (), "render")


@pytest.mark.parametrize("args, fragment", [
    (["--size", "100"], "--size must be a power of two"),
    (["--target", "unreal"], "unknown target 'unreal'"),
    (["--target", "filament", "--method", "fis"], "need --method spectral"),
    (["--workers", "0"], "--workers must be an integer"),
    (["--scheduler", "localhost"], "expected an address such as tcp://HOST:PORT"),
    (["--scheduler", "tcp://127.0.0.1:1", "--workers", "2"], "--workers, --threads and --no-dashboard set up"),
    (["{missing}"], "no such file or directory"),
])
def test_bad_options_are_refused_before_any_cluster_starts(inputs, tmp_path, args, fragment):
    out = tmp_path / "out"
    args = [a.replace("{missing}", str(tmp_path / "missing.hdr")) for a in args]
    t0 = time.perf_counter()
    result = batch("bake", inputs["other"], "-o", out, *SMALL, *args)
    assert result.exit_code == 1, result.output
    line = result.stderr.strip()
    assert line.startswith("pbrkit: error:") and fragment in line and "\n" not in line, result.output
    assert not out.exists() and time.perf_counter() - t0 < 5.0


def test_help_lists_the_choices_and_imports_neither_dask_nor_numba():
    code = ("import sys\nfrom pbrkit.cli import app\n"
            "for args in (['batch', '--help'], ['batch', 'bake', '--help'], ['batch', 'render', '--help']):\n"
            "    try:\n        app(args, prog_name='pbrkit')\n    except SystemExit as exc:\n"
            "        assert exc.code in (0, None)\n"
            "print('HEAVY', [m for m in ('numba', 'numpy', 'dask', 'distributed', 'pbrkit.rendering') "
            "if m in sys.modules], file=sys.stderr)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "COLUMNS": "300"})
    assert done.returncode == 0 and "HEAVY []" in done.stderr, done.stderr
    for choice in ("[rgba16f|b10g11r11]", "[spectral|fis]", "[generic|filament|khronos|babylon|three|all]",
                   "[png|exr]", "[realtime|reference|compare]", "--scheduler", "--workers", "--list"):
        assert choice in done.stdout, choice
    assert not re.search(r"<(bool|str|int|float|Path|path|list\[[^>]*\])>", done.stdout)


# -------------------------------------------------------------- LocalCluster


def test_batch_of_three_equals_three_separate_bakes(inputs, tmp_path):
    """The command's own LocalCluster of 2 workers: same bytes as `pbrkit bake`,
    same-stem inputs told apart by their path hash, the gallery and the summary."""
    paths = [inputs["a"], inputs["b"], inputs["other"]]
    out = tmp_path / "out"
    run = subprocess.run([sys.executable, "-m", "pbrkit", "batch", "bake", *map(str, paths), "-o", str(out),
                          *SMALL, "--workers", "2"], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "dashboard http" in run.stderr and "LocalCluster: 2 workers x 1 Numba thread" in run.stderr
    assert re.search(r"other done in [\d.]+ s \(\d/3, 0 failed, ETA", run.stderr), run.stderr
    assert "3 inputs: 3 done, 0 skipped, 0 failed" in run.stdout
    names = [f"sky-{path_tag(inputs['a'])}", f"sky-{path_tag(inputs['b'])}", "other"]
    assert {p.name for p in out.iterdir()} == set(names) | BATCH_FILES
    references = separate_bakes(paths, tmp_path, *SMALL)
    for name, reference in zip(names, references):
        assert tree(out / name) == reference, name
    summary = summary_of(out)
    assert summary["counts"] == {"done": 3, "skipped": 0, "failed": 0, "not run": 0}
    assert len({o["pid"] for o in summary["inputs"]}) == 2  # both workers baked
    page = (out / "index.html").read_text()
    for name in names:
        assert f'src="{name}/preview.png"' in page and (out / name / "preview.png").is_file()


# ------------------------------------------------- a scheduler started here


def test_corrupt_input_fails_alone(inputs, scheduler, tmp_path):
    from pbrkit.io.png import write_png

    address, _ = scheduler
    ldr = tmp_path / "ldr.png"  # bakes, with the LDR warning pbrkit bake prints
    write_png(ldr, np.full((8, 16, 3), 0.5))
    out = tmp_path / "out"
    result = batch("bake", inputs["other"], inputs["bad"], inputs["a"], ldr, "-o", out, *SMALL,
                   "--scheduler", address)
    assert result.exit_code == 1, result.output
    assert result.stderr.strip().splitlines()[-1] == (
        f"pbrkit: error: 1 of 4 inputs failed: bad (errors in {out / 'batch.json'})")
    assert f"failed: bad: {inputs['bad']}: truncated" in result.stdout
    assert f"scheduler {address} (2 workers)" in result.stdout
    assert status_of(out) == {"other": "done", "bad": "failed", "sky": "done", "ldr": "done"}
    assert {p.name for p in out.iterdir()} == {"other", "sky", "ldr"} | BATCH_FILES  # no folder for the bad one
    outcomes = {o["name"]: o for o in summary_of(out)["inputs"]}
    assert outcomes["bad"]["error"].startswith(f"{inputs['bad']}: truncated RGBE pixel data")
    assert outcomes["bad"]["error"] in (out / "index.html").read_text()
    assert outcomes["ldr"]["warnings"] == [f"{ldr}: low-dynamic-range PNG input, sRGB-decoded; highlights are "
                                           "clipped at 1.0, so lighting from it is too dim and flat (use .hdr or "
                                           ".exr)"]


def test_rerun_skips_finished_inputs_and_force_redoes_them(inputs, scheduler, tmp_path):
    address, _ = scheduler
    out = tmp_path / "out"
    paths = [inputs["other"], inputs["a"]]
    assert batch("bake", *paths, "-o", out, *SMALL, "--scheduler", address).exit_code == 0
    first = {name: (out / name / "manifest.json").stat().st_ino for name in ("other", "sky")}
    again = batch("bake", *paths, "-o", out, *SMALL, "--scheduler", address)
    assert again.exit_code == 0 and "2 inputs: 0 done, 2 skipped, 0 failed" in again.stdout
    assert {name: (out / name / "manifest.json").stat().st_ino for name in first} == first  # untouched
    before = {name: tree(out / name) for name in first}
    (out / "sky" / "sheen.ktx2").unlink()  # a bake missing one of its outputs is stale: redone
    redo = batch("bake", *paths, "-o", out, *SMALL, "--scheduler", address)
    assert redo.exit_code == 0 and status_of(out) == {"other": "skipped", "sky": "done"}
    assert any("incomplete (no sheen.ktx2)" in n for i in summary_of(out)["inputs"] for n in i["notes"])
    forced = batch("bake", *paths, "-o", out, *SMALL, "--scheduler", address, "--force")
    assert forced.exit_code == 0 and status_of(out) == {"other": "done", "sky": "done"}
    assert all((out / name / "manifest.json").stat().st_ino != ino for name, ino in first.items())
    assert {name: tree(out / name) for name in first} == before  # redone: the same bytes
    # other options: redone and replaced, not skipped
    changed = batch("bake", *paths, "-o", out, *SMALL[:-1], "8", "--scheduler", address)
    assert changed.exit_code == 0 and status_of(out) == {"other": "done", "sky": "done"}
    assert json.loads((out / "sky" / "manifest.json").read_text())["options"]["lut_size"] == 8
    note = summary_of(out)["inputs"][0]["notes"][0]
    assert note.startswith("replaced:") and "lut_size 4 -> 8" in note
    # a folder that is not a bake is not replaced without --force
    shutil.rmtree(out / "other")
    (out / "other").mkdir()
    (out / "other" / "mine.txt").write_text("keep me")
    kept = batch("bake", *paths, "-o", out, *SMALL[:-1], "8", "--scheduler", address)
    assert kept.exit_code == 1 and (out / "other" / "mine.txt").read_text() == "keep me"
    assert status_of(out) == {"other": "failed", "sky": "skipped"} and no_temporaries(out)


def test_render_batch_equals_pbrkit_render(scheduler, tmp_path):
    address, _ = scheduler
    scene = tmp_path / "scenes" / "ball.toml"
    scene.parent.mkdir()
    scene.write_text('[materials.red]\nbase_color = [0.8, 0.1, 0.1]\nroughness = 0.4\n\n'
                     '[[objects]]\ntype = "sphere"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = "red"\n')
    options = ["--width", "12", "--height", "8", "--bake-size", "8"]
    out = tmp_path / "out"
    result = batch("render", "sphere", scene.parent, "-o", out, *options, "--scheduler", address)
    assert result.exit_code == 0, result.output
    for name, source in (("sphere", "sphere"), ("ball", scene)):
        single = tmp_path / f"{name}.png"
        assert CliRunner().invoke(app, ["render", str(source), "-o", str(single), *options, "-q"]).exit_code == 0
        assert (out / name / f"{name}.png").read_bytes() == single.read_bytes()
        assert f'src="{name}/{name}.png"' in (out / "index.html").read_text()
    record = json.loads((out / "ball" / "batch.json").read_text())
    assert record["scene"] == {"name": "ball.toml", "sha256": hashlib.sha256(scene.read_bytes()).hexdigest()}
    assert batch("render", "sphere", scene, "-o", out, *options, "--scheduler", address).exit_code == 0
    assert status_of(out) == {"sphere": "skipped", "ball": "skipped"}
    scene.write_text(scene.read_text().replace("0.4", "0.6"))  # the scene changed: rendered again
    assert batch("render", "sphere", scene, "-o", out, *options, "--scheduler", address).exit_code == 0
    assert status_of(out) == {"sphere": "skipped", "ball": "done"}


def test_a_worker_killed_mid_task_loses_and_corrupts_nothing(inputs, scheduler, tmp_path):
    """The test ends a worker process while it writes a bake; the scheduler runs
    that task again on a worker, and every folder is complete and identical to
    a sequential bake; the killed task's temporary folder is removed."""
    address, client = scheduler
    data = inputs["other"].read_bytes()
    paths = []
    for k in range(4):
        paths.append(tmp_path / "in" / f"k{k}.hdr")
        paths[-1].parent.mkdir(exist_ok=True)
        paths[-1].write_bytes(data)
    options = ["--size", "64", "--irradiance-size", "8", "--lut-size", "16"]
    out = tmp_path / "out"
    out.mkdir()
    pids = client.run(os.getpid)
    run = subprocess.Popen([sys.executable, "-m", "pbrkit", "batch", "bake", *map(str, paths), "-o", str(out),
                            *options, "--scheduler", address], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           text=True)
    killed = partial = None
    deadline = time.monotonic() + 240
    while killed is None and run.poll() is None and time.monotonic() < deadline:
        partial = next((p.name for p in out.iterdir() if p.name.endswith(".partial")), None)
        if partial is None:
            time.sleep(0.002)
            continue
        name = partial[1:].split(".")[0]
        for worker, keys in client.processing().items():
            if any(f"-{name}-" in str(key) for key in keys) and worker in pids:
                os.kill(pids[worker], signal.SIGKILL)
                killed = name
                break
    left_behind = (out / partial).exists() if killed else False
    stdout, stderr = run.communicate(timeout=300)
    assert killed is not None, f"no worker was killed mid-write\n{stderr}"
    assert left_behind  # the killed worker was writing: its temporary folder stayed behind ...
    assert run.returncode == 0, stderr
    summary = summary_of(out)
    assert partial in summary["removed_temporaries"]  # ... until the batch removed it
    assert summary["counts"]["done"] == 4
    assert {p.name for p in out.iterdir()} == {f"k{k}" for k in range(4)} | BATCH_FILES
    reference = separate_bakes(paths[:1], tmp_path, *options)[0]
    assert tree(out / "k0") == reference
    for k in range(1, 4):  # the same bytes, but for the input's file name in the manifest
        manifest = reference["manifest.json"].replace(b'"k0.hdr"', b'"k%d.hdr"' % k)
        expected = dict(reference, **{"manifest.json": manifest})
        assert tree(out / f"k{k}") == expected


def test_an_interrupted_batch_leaves_no_partial_folder(inputs, tmp_path):
    """SIGTERM to the command while its LocalCluster bakes: exit status 143, the
    summary says which inputs were not run, and every folder in OUT is complete."""
    paths = []
    for k in range(4):
        paths.append(tmp_path / "in" / f"t{k}.hdr")
        paths[-1].parent.mkdir(exist_ok=True)
        paths[-1].write_bytes(inputs["other"].read_bytes())
    options = ["--size", "64", "--irradiance-size", "8", "--lut-size", "16"]
    out = tmp_path / "out"
    run = subprocess.Popen([sys.executable, "-m", "pbrkit", "batch", "bake", *map(str, paths), "-o", str(out),
                            *options, "--workers", "2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines = []
    for line in run.stderr:  # the first finished input, then SIGTERM
        lines.append(line)
        if " done in " in line:
            run.send_signal(signal.SIGTERM)
            break
    stdout, rest = run.communicate(timeout=120)
    assert run.returncode == 143, "".join(lines) + rest
    assert rest.strip().splitlines()[-1] == "pbrkit: error: terminated (SIGTERM)"
    summary = summary_of(out)
    assert summary["interrupted"] and summary["counts"]["done"] >= 1 and summary["counts"]["not run"] >= 1
    assert no_temporaries(out)
    reference = separate_bakes(paths[:1], tmp_path, *options)[0]
    for folder in (p for p in out.iterdir() if p.is_dir()):
        k = int(folder.name[1:])
        manifest = reference["manifest.json"].replace(b'"t0.hdr"', b'"t%d.hdr"' % k)
        expected = dict(reference, **{"manifest.json": manifest})
        assert tree(folder) == expected, folder.name


@pytest.mark.parametrize("args, fragment", [
    (["--width", "0"], "--width must be an integer in [1, 16384]; got 0"),
    (["--height", "100000"], "--height must be an integer in [1, 16384]; got 100000"),
])
def test_batch_render_names_the_size_flags_as_typed(tmp_path, args, fragment):
    out = tmp_path / "out"
    result = batch("render", "spheres", "-o", out, *args)
    assert result.exit_code == 1, result.output
    line = result.stderr.strip()
    assert line.startswith("pbrkit: error:") and fragment in line and "\n" not in line, result.output
    assert not out.exists()
