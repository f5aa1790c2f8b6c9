"""The demo's parallel warm-up (pbrkit.app.warmup): when it starts, the claims that
keep a step from being compiled by both processes, the demo's signals, a worker
that dies, and the worker's own run (each unclaimed step once, in order)."""

from __future__ import annotations

import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from pbrkit.app import warmup
from pbrkit.core import cache


def _fake(folder, code="import time; time.sleep(30)"):
    """A WarmUp over ``folder`` whose process runs ``code``."""
    process = subprocess.Popen([sys.executable, "-c", code])
    return warmup.WarmUp(process, folder)


def test_start_only_on_a_cold_cache_with_two_cores(tmp_path, monkeypatch):
    monkeypatch.setenv("PBRKIT_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("PBRKIT_NO_WARM_UP", raising=False)
    cache.cache_directory.cache_clear()
    try:
        started = []
        monkeypatch.setattr(warmup.subprocess, "Popen", lambda *a, **k: started.append(a[0]) or object())
        monkeypatch.setattr(warmup.os, "cpu_count", lambda: 1)
        assert warmup.WarmUp.start("env.hdr") is None and not started  # one core: nothing to gain
        monkeypatch.setattr(warmup.os, "cpu_count", lambda: 2)
        monkeypatch.setenv("PBRKIT_NO_WARM_UP", "1")
        assert warmup.WarmUp.start("env.hdr") is None and not started
        monkeypatch.delenv("PBRKIT_NO_WARM_UP")
        warm = warmup.WarmUp.start("env.hdr")  # cold cache, two cores: the worker starts
        assert warm is not None and started[0][1:3] == ["-m", "pbrkit.app.warmup"]
        assert started[0][-1] == "env.hdr" and Path(started[0][-2]) == warm.folder
        warm.folder.rmdir()
        # the ground-truth kernel in the cache: warm, no worker
        index = Path(cache.cache_directory()) / "rendering" / "lanes._direct_kernel-581.py311.nbi"
        index.parent.mkdir(parents=True)
        index.write_bytes(b"")
        assert warmup.kernels_cached() and warmup.WarmUp.start("env.hdr") is None and len(started) == 1
    finally:
        cache.cache_directory.cache_clear()


def test_claims_wait_and_signals(tmp_path):
    warm = _fake(tmp_path)
    try:
        assert warm.claim("furnace")  # the demo got there first: it runs the step itself
        assert not warmup._claim(tmp_path, "furnace", "worker")
        assert warmup._claim(tmp_path, "reference", "worker")  # the worker's: the demo waits for it
        threading.Timer(0.3, lambda: (tmp_path / "reference.done").touch()).start()
        t = time.perf_counter()
        warm.ready("reference")
        assert 0.2 < time.perf_counter() - t < 10 and warm.waited > 0.2
        warm.signal("bake")
        assert (tmp_path / "bake.main").exists()
        assert (tmp_path / "furnace.claim").read_text() == "demo"
    finally:
        warm.close()
    assert not tmp_path.exists() and warm.process.poll() is not None  # stopped and cleaned up


def test_a_worker_that_dies_does_not_hang_the_demo(tmp_path):
    warm = _fake(tmp_path, "import sys; sys.exit(3)")
    try:
        assert warmup._claim(tmp_path, "npr", "worker")
        warm.ready("npr")  # never done: returns when the process has exited
        assert warm.process.poll() == 3
    finally:
        warm.close()


def test_worker_runs_each_unclaimed_step_after_the_demos_signals(tmp_path):
    """run_worker in-process: the steps the demo claimed are skipped, the others run
    small and are marked done in order, and the styles wait for the demo's signals."""
    from pbrkit.data import environment_path

    folder = tmp_path / "sync"
    folder.mkdir()
    assert warmup._claim(folder, "furnace", "demo")
    done = []
    early = []

    def watch():
        while len(done) < len(warmup.STEPS) - 1 and folder.is_dir():
            for step in warmup.STEPS:
                if (folder / f"{step}.done").exists() and step not in done:
                    done.append(step)
            if "reference" in done and not (folder / "bake.main").exists():
                time.sleep(0.5)  # the styles must not start before the demo's signals
                early.append((folder / "npr.done").exists())
                for step in warmup.SIGNALS:
                    (folder / f"{step}.main").touch()
            time.sleep(0.01)

    watcher = threading.Thread(target=watch)
    watcher.start()
    warmup.run_worker(folder, environment_path())
    watcher.join(60)
    assert done == [step for step in warmup.STEPS if step != "furnace"] and early == [False]
    assert not (folder / "furnace.done").exists() and (folder / "furnace.claim").read_text() == "demo"
    assert (folder / "work" / "npr_toon.png").exists() and (folder / "work" / "area_reference.png").exists()
    assert (folder / "work" / "gltf_realtime.png").exists()


@pytest.mark.parametrize("steps", [("bake", "realtime")])
def test_worker_gives_up_without_the_demos_signals(tmp_path, monkeypatch, steps):
    monkeypatch.setattr(warmup, "_PATIENCE", 0.2)
    assert warmup._wait_for_demo(tmp_path, steps[0]) is False
    (tmp_path / f"{steps[1]}.main").touch()
    assert warmup._wait_for_demo(tmp_path, steps[1]) is True


def test_worker_stops_when_the_demo_is_gone(tmp_path, monkeypatch):
    """A demo killed outright (no clean-up) leaves the worker adopted by another parent,
    or its folder removed: the worker stops instead of waiting."""
    assert not warmup._demo_gone(tmp_path)
    monkeypatch.setattr(warmup, "_PARENT", -1)
    assert warmup._demo_gone(tmp_path) and warmup._wait_for_demo(tmp_path, "bake") is False
    monkeypatch.setattr(warmup, "_PARENT", warmup.os.getppid())
    assert warmup._demo_gone(tmp_path / "missing")
    warmup.run_worker(tmp_path / "missing", "unused.hdr")  # returns at once: nothing claimed
    assert not (tmp_path / "missing").exists()
