"""The ``pbrkit batch bake|render`` commands (the group :data:`batch_app`, added to
the ``pbrkit`` app by :mod:`pbrkit.cli`).

This module imports only Typer and the command line's own modules (``pbrkit
--help`` stays light); the work is in :mod:`pbrkit.app.batch`, imported by the
commands' bodies, which also import Dask: without the ``batch`` extra a command
says which ``pip install`` to run (:func:`pbrkit.cli.console.need_extra`).
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Optional

import typer

from ..choices import DIFFUSE_MODES, LAYOUTS, MODES, RENDER_ENGINES, TONEMAPS
from .console import BatchProgress, need_extra, user_errors
from .options import (BAKE_OPTIONS, EXPOSURE_LIMIT, OUT_DIR, TARGET_METAVAR, _check_exposure, _choice, _Command,
                      _flag, _Group, _quiet_option, _seed_option)

#: ``pbrkit --help``'s line for the group.
SHORT_HELP = "Bake or render many inputs on a Dask cluster (LocalCluster or --scheduler)."
#: The examples ``pbrkit batch bake --help`` and ``pbrkit batch render --help`` show.
EXAMPLE_BAKE = "pbrkit batch bake skies/ -o baked --size 128 --workers 2"
EXAMPLE_RENDER = "pbrkit batch render scenes/*.toml -o renders --mode compare"

IMAGE_FORMATS = ("png", "exr")

batch_app = typer.Typer(
    cls=_Group,
    no_args_is_help=True,
    add_completion=False,
    context_settings={"help_option_names": ["-h", "--help"]},
    epilog="Example:\n\n" + EXAMPLE_BAKE,
    help="Bake or render many inputs on a Dask cluster: a LocalCluster on this machine, or the workers of a "
         "distributed scheduler (--scheduler tcp://HOST:PORT).  One folder per input in OUT (OUT/<stem>/), "
         "skipped when it is up to date, OUT/index.html (a gallery) and OUT/batch.json (the summary).",
)


# ------------------------------------------------------------ shared options


def _list_option():
    return typer.Option(None, "--list", metavar="FILE",
                        help="A text file of inputs, one file, folder or glob a line (blank lines and # comments "
                             "skipped; relative to the file's folder); repeatable.")


def _out_option():
    return typer.Option(..., "-o", "--out", metavar="DIR", parser=OUT_DIR,
                        help="Output folder: OUT/<name>/ per input, OUT/index.html, OUT/batch.json.")


def _force_option():
    return _flag(False, ("--force",), "Redo every input, also those whose folder is up to date, and replace "
                                      "folders that are not pbrkit output.")


def _scheduler_option():
    return typer.Option(None, "--scheduler", metavar="ADDRESS",
                        help="Run on the workers of a running distributed scheduler (tcp://HOST:PORT, or tls://, "
                             "ws://, wss://; inputs and OUT on a file system the workers share).  Default: a "
                             "LocalCluster on this machine.")


def _scheduler_timeout_option():
    return typer.Option(None, "--scheduler-timeout", metavar="SECONDS",
                        help="With --scheduler: give up when no Dask scheduler has answered within this time "
                             "(default 30).")


def _workers_option():
    return typer.Option(None, "--workers", metavar="N",
                        help="LocalCluster worker processes, one task at a time each (default: the cores this "
                             "process may use).")


def _threads_option():
    return typer.Option(None, "--threads", metavar="N",
                        help="LocalCluster: Numba threads per worker for the parallel kernels (default 1; "
                             "workers x threads = cores measured fastest, see the README).")


def _dashboard_option():
    return _flag(True, ("--dashboard/--no-dashboard",),
                 "LocalCluster: serve Dask's dashboard (its address is printed; about 1 s of the start).")


def _cluster_checks(scheduler, workers, threads, dashboard=True, scheduler_timeout=None):
    """The cluster options checked together, before any work: the ``--scheduler``
    address (:func:`pbrkit.app.scheduler.check_scheduler_address`) and its timeout,
    or the LocalCluster's.  Returns (scheduler address, timeout in seconds)."""
    from ..core import checks
    from ..app.scheduler import DEFAULT_SCHEDULER_TIMEOUT, check_scheduler_address, check_scheduler_timeout

    if scheduler is None:
        if scheduler_timeout is not None:
            raise ValueError("--scheduler-timeout is for --scheduler (a LocalCluster starts on this machine)")
    elif workers is not None or threads is not None or not dashboard:
        raise ValueError("--workers, --threads and --no-dashboard set up a LocalCluster; with --scheduler "
                         "the workers and the dashboard are those started for that scheduler")
    if workers is not None:
        checks.integer(workers, "--workers", 1, 1024)
    if threads is not None:
        checks.integer(threads, "--threads", 1, 1024)
    timeout = DEFAULT_SCHEDULER_TIMEOUT if scheduler_timeout is None else check_scheduler_timeout(scheduler_timeout)
    return (None if scheduler is None else check_scheduler_address(scheduler)), timeout


def _finish(summary, out, quiet):
    """Print the summary (stdout) unless ``quiet``; a batch with failures ends
    with one error line and exit status 1."""
    from ..core.errors import one_line

    counts = summary["counts"]
    failed = [o for o in summary["inputs"] if o["status"] == "failed"]
    if not quiet:
        print(f"{len(summary['inputs'])} inputs: {counts['done']} done, {counts['skipped']} skipped, "
              f"{counts['failed']} failed in {summary['wall_seconds']:.1f} s ({summary.get('cluster', '')})")
        for o in failed:
            print(one_line(f"failed: {o['name']}: {o['error']}"))
        print(f"wrote {out / 'index.html'} and {out / 'batch.json'}")
    for o in summary["inputs"]:  # printed by user_errors as "pbrkit: warning: <name>: ..." lines
        for w in o.get("warnings") or []:
            warnings.warn(f"{o['name']}: {w}", UserWarning, stacklevel=1)
    if failed:
        names = ", ".join(o["name"] for o in failed[:5]) + (", ..." if len(failed) > 5 else "")
        raise ValueError(f"{len(failed)} of {len(summary['inputs'])} inputs failed: {names} "
                         f"(errors in {out / 'batch.json'})")


# ----------------------------------------------------------------- commands


@batch_app.command("bake", cls=_Command, short_help="Bake many environments, one folder each, on Dask.",
                   epilog=EXAMPLE_BAKE)
@user_errors
def batch_bake(
    inputs: Optional[list[str]] = typer.Argument(
        None, metavar="INPUTS",
        help="Environment files (each as pbrkit bake ENV), folders (their .hdr .exr .pfm files) and globs."),
    out: Path = _out_option(),
    list_file: Optional[list[Path]] = _list_option(),
    size: int = BAKE_OPTIONS["size"](),
    min_size: int = BAKE_OPTIONS["min_size"](),
    irradiance_size: int = BAKE_OPTIONS["irradiance_size"](),
    lut_size: int = BAKE_OPTIONS["lut_size"](),
    fmt: str = BAKE_OPTIONS["format"](),
    method: str = BAKE_OPTIONS["method"](),
    sh_window: Optional[str] = BAKE_OPTIONS["sh_window"](),
    layout: Optional[str] = _choice(None, "--layout", LAYOUTS, "layout",
                                    "Force the layout of every input (default: by aspect ratio)."),
    fix_nonfinite: bool = BAKE_OPTIONS["fix_nonfinite"](),
    target: Optional[list[str]] = typer.Option(
        None, "--target", metavar=TARGET_METAVAR,
        help="Also write the files of an engine in OUT/<name>/<target>/, as pbrkit bake --target (repeatable, "
             "or a comma-separated list)."),
    force: bool = _force_option(),
    scheduler: Optional[str] = _scheduler_option(),
    scheduler_timeout: Optional[float] = _scheduler_timeout_option(),
    workers: Optional[int] = _workers_option(),
    threads: Optional[int] = _threads_option(),
    dashboard: bool = _dashboard_option(),
    quiet: bool = _quiet_option(),
):
    """Bake every input as pbrkit bake does, into OUT/<name>/ (the same files, byte for byte), on a Dask
    LocalCluster or --scheduler's workers.  An input whose folder's manifest records the same input SHA-256,
    options and targets is skipped (--force redoes it); a bad input fails alone, and the batch then exits
    with status 1 naming it.  Writes OUT/index.html (every preview, time, size, status) and OUT/batch.json."""
    need_extra("pbrkit batch", "batch")
    from ..app.batch import bake_jobs_options, check_bake_options, expand_inputs, run_batch

    options = bake_jobs_options(size, min_size, irradiance_size, lut_size, fmt, method, sh_window, layout,
                                fix_nonfinite)
    targets = check_bake_options(options, target)
    scheduler, timeout = _cluster_checks(scheduler, workers, threads, dashboard, scheduler_timeout)
    found = expand_inputs(inputs, list_file, "bake")
    with BatchProgress("batch bake", len(found), quiet) as progress:
        summary = run_batch("bake", found, out, options, targets, force=force, scheduler=scheduler,
                            workers=workers, threads=threads, dashboard=dashboard, progress=progress,
                            scheduler_timeout=timeout)
    _finish(summary, out, quiet)


@batch_app.command("render", cls=_Command, short_help="Render many scenes, one folder each, on Dask.",
                   epilog=EXAMPLE_RENDER)
@user_errors
def batch_render(
    scenes: Optional[list[str]] = typer.Argument(
        None, metavar="SCENES",
        help="Scene files (.toml, .json), folders and globs of them, or built-in scenes (spheres, sphere, area)."),
    out: Path = _out_option(),
    list_file: Optional[list[Path]] = _list_option(),
    image_format: str = _choice("png", "--format", IMAGE_FORMATS, "image format",
                                "OUT/<name>/<name>.png (tone-mapped, sRGB) or .exr (linear float32, with a "
                                "thumbnail.png for the gallery)."),
    mode: str = _choice("realtime", "--mode", MODES, "mode",
                        "realtime (split-sum IBL), reference (Monte Carlo ground truth) or compare (both)."),
    spp: int = typer.Option(64, "--spp", metavar="N", help="Ground-truth samples per pixel."),
    bounces: int = typer.Option(0, "--bounces", metavar="N", help="Ground-truth bounces after the first hit."),
    tonemap_name: str = _choice("aces", "--tonemap", TONEMAPS, "tone mapper", "Tone mapper of .png output."),
    exposure: float = typer.Option(0.0, "--exposure", metavar="EV", callback=_check_exposure,
                                   help=f"Exposure in EV before tone mapping, within +-{EXPOSURE_LIMIT:g}."),
    width: Optional[int] = typer.Option(None, "--width", metavar="PIXELS", help="Image width (overrides cameras)."),
    height: Optional[int] = typer.Option(None, "--height", metavar="PIXELS",
                                         help="Image height (overrides cameras)."),
    env: Optional[Path] = typer.Option(None, "--env", metavar="FILE|DIR",
                                       help="Environment map, or a bake folder, replacing every scene's."),
    seed: int = _seed_option("Seed of the ground truth's random numbers."),
    diffuse: str = _choice("sh", "--diffuse", DIFFUSE_MODES, "diffuse mode",
                           "Real-time diffuse IBL: sh (9 coefficients) or cube (irradiance cube)."),
    energy_compensation: bool = _flag(False, ("--energy-compensation/--no-energy-compensation",),
                                      "Real time: Filament's multiple-scattering compensation."),
    engine: str = _choice("pbrkit", "--engine", RENDER_ENGINES, "engine",
                          "Real time: whose IBL evaluation to follow."),
    bake_size: int = typer.Option(256, "--bake-size", metavar="N",
                                  help="Real time: size of the bake's specular cube (power of two)."),
    fix_nonfinite: bool = _flag(False, ("--fix-nonfinite",),
                                "Replace NaN/Inf environment pixels by the mean of their finite neighbours."),
    occlusion: Optional[bool] = typer.Option(
        None, "--occlusion/--no-occlusion", show_default=False, metavar="",
        help="Ground truth: objects occlude one another's environment light (default as pbrkit render: on for "
             "reference, off for compare)."),
    style: Optional[str] = typer.Option(None, "--style", metavar="NAME|FILE",
                                        help="Real time in a non-photorealistic style (as pbrkit render --style)."),
    allow_root: Optional[list[Path]] = typer.Option(
        None, "--allow-root", metavar="DIR",
        help="A folder besides a glTF model's own that its buffer and image URIs may name (repeatable; as "
             "pbrkit render --allow-root)."),
    force: bool = _force_option(),
    scheduler: Optional[str] = _scheduler_option(),
    scheduler_timeout: Optional[float] = _scheduler_timeout_option(),
    workers: Optional[int] = _workers_option(),
    threads: Optional[int] = _threads_option(),
    dashboard: bool = _dashboard_option(),
    quiet: bool = _quiet_option(),
):
    """Render every scene as pbrkit render does, into OUT/<name>/<name>.png (or .exr; reference and compare
    also <name>.stderr.exr), on a Dask LocalCluster or --scheduler's workers.  A scene whose folder's
    batch.json records the same scene, referenced files (SHA-256), options and pbrkit version is skipped
    (--force redoes it); a bad scene fails alone, and the batch then exits with status 1 naming it.
    Writes OUT/index.html and OUT/batch.json."""
    need_extra("pbrkit batch", "batch")
    from ..app.batch import expand_inputs, render_jobs_options, run_batch

    options = render_jobs_options(mode, spp, bounces, tonemap_name, exposure, width, height,
                                  None if env is None else str(env), seed, diffuse, energy_compensation, engine,
                                  bake_size, fix_nonfinite, occlusion, style, image_format, allow_root or ())
    scheduler, timeout = _cluster_checks(scheduler, workers, threads, dashboard, scheduler_timeout)
    found = expand_inputs(scenes, list_file, "render")
    with BatchProgress("batch render", len(found), quiet) as progress:
        summary = run_batch("render", found, out, options, force=force, scheduler=scheduler, workers=workers,
                            threads=threads, dashboard=dashboard, progress=progress, scheduler_timeout=timeout)
    _finish(summary, out, quiet)
