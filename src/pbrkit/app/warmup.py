"""The demo's parallel warm-up on a first run.

Numba compiles a kernel on the first call and caches it on disk
(:mod:`pbrkit.core.jit`); a process compiles on one core at a time (Numba's
compiler holds a lock), so on an empty cache ``pbrkit demo`` would spend most of
its first run compiling on one core.  When the cache holds none of the demo's
kernels and the machine has two or more cores, :meth:`WarmUp.start` launches a
second process (:func:`run_worker`, ``python -m pbrkit.app.warmup``) that
compiles the kernels of the demo's later steps (:data:`STEPS`: the ground
truth, the area-light scene, the styles, the glTF material extensions, the furnace
report) by running each of
them small (16^2 pixels, 2 samples), while the demo bakes and renders in real
time.  Each of those steps is claimed by whichever process reaches it first
(a marker file created exclusively, :meth:`WarmUp.claim`): the demo runs a
step it claimed at once, compiling its kernels itself, and waits for the
worker to finish a step the worker claimed (:meth:`WarmUp.wait`), then loads
its kernels from the cache.  The worker waits for the demo's bake and
real-time render (:meth:`WarmUp.signal`) before the styles and the glTF
extensions, which use their kernels.  So no kernel is compiled twice, and both cores compile.

The demo's results do not depend on it: the kernels are the same whoever
compiles them, and the worker writes only into its own temporary folder.  If
the worker fails or is slow to start, the demo compiles what it needs itself.
``PBRKIT_NO_WARM_UP=1`` turns it off.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

__all__ = ["STEPS", "WarmUp", "kernels_cached", "run_worker"]

#: The demo steps the worker runs small, in its order; the demo waits for each.
STEPS = ("reference", "area", "npr", "gltf", "furnace")
#: The demo steps after which the demo signals the worker (their kernels are cached).
SIGNALS = ("bake", "realtime")
#: How long the worker waits for a demo signal before giving up (seconds).
_PATIENCE = 900.0


def kernels_cached():
    """Whether Numba's cache already holds the demo's ground-truth kernel (then it holds
    the others too, or they are cheap to compile: no warm-up)."""
    from ..core.cache import cached_kernels

    return cached_kernels("rendering", "lanes._direct_kernel-*")


def _claim(folder, step, owner):
    """Claim ``step`` for ``owner`` (``demo`` or ``worker``): True if this call created
    ``<step>.claim``, False if the other process had."""
    try:
        fd = os.open(Path(folder) / f"{step}.claim", os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except FileExistsError:
        return False
    os.write(fd, owner.encode())
    os.close(fd)
    return True


class WarmUp:
    """The worker process and the folder of markers it and the demo share:
    ``<step>.claim`` (who runs a step of :data:`STEPS` first), ``<step>.done`` (the
    worker finished one), ``<step>.main`` (the demo finished a step of
    :data:`SIGNALS`)."""

    def __init__(self, process, folder):
        self.process = process
        self.folder = Path(folder)
        self.waited = 0.0

    @classmethod
    def start(cls, env_path):
        """Start the worker if the cache is cold, there are two or more cores and
        ``PBRKIT_NO_WARM_UP`` is not set; else return None."""
        from ..core.cache import env_flag

        if env_flag("PBRKIT_NO_WARM_UP") or (os.cpu_count() or 1) < 2:
            return None
        if kernels_cached():
            return None
        folder = tempfile.mkdtemp(prefix="pbrkit-warmup-")
        try:
            process = subprocess.Popen([sys.executable, "-m", "pbrkit.app.warmup", folder, str(env_path)],
                                       stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        except OSError:
            shutil.rmtree(folder, ignore_errors=True)
            return None
        return cls(process, folder)

    def signal(self, step):
        """Tell the worker that the demo finished ``step`` (:data:`SIGNALS`)."""
        (self.folder / f"{step}.main").touch()

    def claim(self, step):
        """Before the demo runs ``step`` (:data:`STEPS`): True if the demo claimed it
        (it compiles the step's kernels itself), False if the worker had."""
        return _claim(self.folder, step, "demo")

    def ready(self, step):
        """Before the demo runs ``step``: claim it, or wait for the worker that did."""
        if not self.claim(step):
            self.wait(step)

    def wait(self, step):
        """Wait until the worker finished ``step`` (:data:`STEPS`) or exited."""
        t = time.perf_counter()
        while not (self.folder / f"{step}.done").exists() and self.process.poll() is None:
            time.sleep(0.02)
        self.waited += time.perf_counter() - t

    def close(self):
        """Stop the worker if it still runs and remove the markers."""
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        shutil.rmtree(self.folder, ignore_errors=True)


_PARENT = os.getppid()


def _demo_gone(folder):
    """Whether the demo went away: its folder of markers is gone, or this process's
    parent changed (the demo was killed and this process was adopted)."""
    return not Path(folder).is_dir() or os.getppid() != _PARENT


def _wait_for_demo(folder, step):
    """Wait for the demo's ``<step>.main`` marker; False if it never comes (the demo
    stopped, :func:`_demo_gone`, or :data:`_PATIENCE` ran out)."""
    deadline = time.monotonic() + _PATIENCE
    while not (folder / f"{step}.main").exists():
        if _demo_gone(folder) or time.monotonic() > deadline:
            return False
        time.sleep(0.02)
    return True


def run_worker(folder, env_path):
    """Run the demo's :data:`STEPS` small (into ``folder/work``), each that the demo
    has not claimed first, writing ``folder/<step>.done`` after each; the styles
    wait for the demo's bake and real-time render first (:data:`SIGNALS`)."""
    import numpy as np

    from ..albedo.furnace import furnace_lobes
    from ..ibl.bake import bake as bake_environment
    from ..io.environment import load_environment
    from ..rendering.environment import EnvironmentLight
    from ..rendering.geometry import Geometry
    from ..rendering.reference import render_reference
    from ..rendering.scene import EnvironmentSpec, builtin_scene
    from .demo_sections import (DEMO_LEVELS, FURNACE_LOBES, area_light_comparison, gltf_extensions_comparison,
                                npr_gallery)
    from .report import furnace_report

    folder = Path(folder)
    if _demo_gone(folder):
        return
    work = folder / "work"
    work.mkdir(exist_ok=True)
    size = 16
    scene = builtin_scene("spheres", size, size, EnvironmentSpec(file=str(env_path)))
    geometry = Geometry(scene)
    env = EnvironmentLight(scene.environment)

    def demo_bake():  # after the demo's bake and real-time render (their kernels cached)
        if not all(_wait_for_demo(folder, step) for step in SIGNALS):
            raise RuntimeError("the demo stopped before its real-time render")
        if env.bake_data is None:
            env.bake_data = bake_environment(load_environment(env_path), size=1 << (DEMO_LEVELS - 1), min_size=1)
        return env.bake_data

    def styles():
        baked = demo_bake()
        npr_gallery(work, scene, env, baked, size)

    def gltf():
        baked = demo_bake()
        gltf_extensions_comparison(work, scene.environment, env, baked, 2 * size, 2, 0)

    def furnace():
        lobes = [name for name in FURNACE_LOBES if name in furnace_lobes()]
        furnace_report(work / "furnace", n_mu=2, roughness=np.linspace(0.0, 1.0, 2), samples=8, seed=0, lobes=lobes)

    runs = {"reference": lambda: render_reference(scene, spp=2, seed=0, geometry=geometry, env=env, occlusion=False),
            "area": lambda: area_light_comparison(work, size, 2, 0), "npr": styles, "gltf": gltf,
            "furnace": furnace}
    for step in STEPS:
        if _demo_gone(folder):
            return
        if _claim(folder, step, "worker"):
            runs[step]()
            (folder / f"{step}.done").touch()


if __name__ == "__main__":  # pragma: no cover - run as the worker process
    try:
        run_worker(Path(sys.argv[1]), Path(sys.argv[2]))
    except Exception:  # the demo compiles what the worker did not; it reports its own errors
        sys.exit(1)
