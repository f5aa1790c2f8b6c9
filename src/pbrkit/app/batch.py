"""Batch bakes and renders on Dask (``pbrkit batch bake|render``, issue 14).

A batch runs one task per input on a Dask cluster (:mod:`pbrkit.app.scheduler`):
a ``LocalCluster`` of worker processes on this machine, or the workers of a
``distributed`` scheduler the user started (``--scheduler tcp://HOST:PORT``;
the inputs and the output folder must then be on a file system the workers
share, under the same paths).  Each task (:mod:`pbrkit.app.batch_tasks`,
:func:`~pbrkit.app.batch_tasks.run_task`) calls the very
functions ``pbrkit bake`` and ``pbrkit render`` call --
:func:`pbrkit.ibl.bake.bake` with :func:`pbrkit.io.bake_files.write_bake`, or
:func:`pbrkit.rendering.sources.resolve_scene` with
:func:`pbrkit.rendering.run.render_scene` -- so an input's folder holds the same
bytes as the single command's output.

The rules (the README's ``pbrkit batch`` section states them for users):

- **Names** (:func:`output_names`): input ``DIR/sky.hdr`` goes to ``OUT/sky/``.
  Inputs of one batch whose stems are equal (compared case-insensitively, as
  on macOS and Windows file systems), and a stem equal to ``index.html`` or
  ``batch.json``, get ``<stem>-<8 hex digits>``: the start of the SHA-256 of
  the input's absolute path, so the name depends only on the input, never on
  the order of the inputs.
- **One folder per input, written atomically**: the task writes into a hidden
  temporary folder beside ``OUT/<name>/`` and renames it into place
  (:func:`pbrkit.core.atomic.atomic_directory`), so an interrupted task or a
  killed worker leaves no partial folder; the temporaries a killed worker
  leaves behind (``OUT/.<name>.XXXXXXXX.partial``) are removed when the batch
  ends (:func:`remove_stale_temporaries`).
- **Resume record**, committed inside the folder by the same rename: for a
  bake its ``manifest.json`` (the pbrkit version, the input's file name and
  SHA-256, the options, the engine targets; ``bake_state``), for a render
  ``OUT/<name>/batch.json`` (the same, with the SHA-256 of every file the
  scene reads; ``render_state``).  An input whose folder records the same
  is skipped (``--force`` redoes it); a folder recording something else (the
  input changed, other options, another pbrkit version, a file missing) is
  redone and replaced; a folder that is not a pbrkit output is left alone and
  the input fails, unless ``--force``.
- **Isolation**: a task returns its outcome instead of raising: a bad input
  fails alone with its one-line error (``InputError`` and the other
  ``ValueError`` / ``OSError`` messages, as ``pbrkit bake`` prints them).
- **Fault tolerance**: a worker that dies mid-task has its task re-run on
  another worker by the scheduler (Dask's ``distributed.scheduler.allowed-
  failures``, 3 by default; after that the input fails with ``KilledWorker``).
  The re-run finds no folder (the rename never happened) or a complete one.
- **Workers**: a ``LocalCluster``'s workers are forked from this process with
  the tasks' modules already imported, where that is safe (Linux, Numba's
  thread pool not started here: ``pbrkit.app.scheduler._fork_is_safe``),
  else spawned (Dask's default); each runs one task at a time with
  ``--threads`` Numba threads.
- **Numba's cache** (:mod:`pbrkit.core.jit`): the workers of a
  ``LocalCluster`` share this process's ``$PBRKIT_CACHE_DIR`` (or its
  default).  When the workers find no compiled kernels there, the first input
  runs alone and the others start once it has filled the cache
  (``cache_is_cold``), so no worker compiles what another one compiled.
  Numba writes each cache file to a temporary name and renames it
  (``os.replace``), so concurrent readers never see a torn file; but its
  index of a kernel's signatures is read, extended and rewritten without a
  lock, so two processes saving *different* signatures of one kernel at the
  same instant race on it (an entry lost, or two entries given one data
  file); after the warm-up above the workers load what the first input
  compiled and compile only what other inputs need anew (another pixel
  type), so that race is rare (workers saving the same signature write the
  same entry).

The batch writes ``OUT/batch.json`` (every input's outcome, time and size) and
``OUT/index.html`` (:func:`gallery_html`), a page that opens from the file
system without a server.
"""

from __future__ import annotations

import contextlib
import hashlib
import html
import json
import os
import re
import shutil
import time
from collections import Counter
from pathlib import Path
from urllib.parse import quote

from .batch_tasks import (  # noqa: F401 - the tasks' names, as before they had their module
    RECORD_FORMAT,
    RECORD_NAME,
    _read_json,
    bake_state,
    folder_bytes,
    render_record,
    render_state,
    run_task,
)
from .scheduler import (  # noqa: F401 - the cluster's names, as before they had their module
    DEFAULT_SCHEDULER_TIMEOUT,
    cache_is_cold,
    cache_state,
    dask_client,
    default_workers,
)

__all__ = [
    "KINDS",
    "BAKE_SUFFIXES",
    "SCENE_SUFFIXES",
    "RESERVED_NAMES",
    "expand_inputs",
    "output_names",
    "bake_jobs_options",
    "render_jobs_options",
    "check_bake_options",
    "run_task",
    "bake_state",
    "render_state",
    "cache_is_cold",
    "dask_client",
    "run_batch",
    "gallery_html",
    "remove_stale_temporaries",
]

KINDS = ("bake", "render")
#: Environment files a folder given as input contributes to a bake batch (HDR formats only: the
#: .png / .jpg previews that sit beside HDRIs in asset libraries are baked only when named or globbed).
BAKE_SUFFIXES = (".hdr", ".pic", ".rgbe", ".exr", ".pfm")
#: Files a glob contributes to a bake batch (:data:`BAKE_SUFFIXES` and the LDR formats pbrkit reads).
BAKE_GLOB_SUFFIXES = BAKE_SUFFIXES + (".png", ".jpg", ".jpeg")
#: Scene files a folder or a glob contributes to a render batch.
SCENE_SUFFIXES = (".toml", ".json")
#: Names of the batch's own files in OUT, which no input's folder may take.
RESERVED_NAMES = ("index.html", "batch.json")
SUMMARY_FORMAT = "pbrkit batch summary"
#: Most paths one glob may match (a pattern such as ``/**`` names every path on the machine).
MAX_GLOB_PATHS = 100_000
_GLOB_CHARS = re.compile(r"[*?\[]")
_STEM_MAX = 200  # leaves room for "-<hash>" and the atomic temporaries' ".<name>.XXXXXXXX.partial" in NAME_MAX


# ==================================================================== inputs


def _is_glob(text):
    return bool(_GLOB_CHARS.search(text))


def _folder_inputs(folder, suffixes):
    return sorted(p for p in folder.iterdir() if p.is_file() and p.suffix.lower() in suffixes)


def _expand_one(text, kind, base, builtins):
    """The inputs one INPUT argument (or list-file line) stands for; ValueError
    for a path that does not exist, a glob that matches nothing, a folder
    without inputs."""
    from glob import iglob

    from ..core.errors import InputError

    if kind == "render" and text in builtins:
        return [text]
    path = Path(text).expanduser()
    if not path.is_absolute():
        path = base / path
    if path.is_dir():
        suffixes = BAKE_SUFFIXES if kind == "bake" else SCENE_SUFFIXES
        found = _folder_inputs(path, suffixes)
        if not found:
            raise InputError(f"no {' / '.join(suffixes)} files in the folder", text)
        return found
    if path.exists():
        return [path]
    if _is_glob(text):
        suffixes = BAKE_GLOB_SUFFIXES if kind == "bake" else SCENE_SUFFIXES
        matches, found = [], []
        for match in iglob(str(path), recursive=True):  # bounded: a pattern such as /** names every path
            if len(found) == MAX_GLOB_PATHS:
                raise InputError(f"the pattern matches more than {MAX_GLOB_PATHS:,} paths; narrow it", text)
            found.append(match)
        for match in sorted(found):
            m = Path(match)
            if m.is_dir():
                matches += _folder_inputs(m, BAKE_SUFFIXES if kind == "bake" else SCENE_SUFFIXES)
            elif m.suffix.lower() in suffixes:
                matches.append(m)
        if not matches:
            raise InputError(f"the pattern matches no {' / '.join(suffixes)} file", text)
        return matches
    hint = f" (built-in scenes: {', '.join(builtins)})" if kind == "render" else ""
    raise InputError(f"no such file or directory{hint}", text)


#: What a ``--list`` file holds, for its error messages.
LIST_FORMAT = ("a --list file: UTF-8 text, one input (a file, folder or glob, relative to the list's folder) "
               "a line, blank lines and # comments skipped")


def list_file_entries(path):
    """The entries of a ``--list`` file, as (line number, text): one input (file,
    folder or glob) a line; blank lines and lines starting with ``#`` are skipped.
    The file is read as untrusted input (:func:`pbrkit.core.inputs.read_text`: a
    regular file, at most :data:`pbrkit.core.inputs.MAX_TEXT_BYTES`, UTF-8); a line
    that cannot be a path (a NUL character) is refused by its number, never quoted."""
    from ..core.errors import InputError
    from ..core.inputs import read_text

    text = read_text(path, expected=LIST_FORMAT)
    entries = []
    for number, line in enumerate(text.split("\n"), 1):
        entry = line.strip()
        if not entry or entry.startswith("#"):
            continue
        if "\x00" in entry:
            raise InputError(f"line {number}: a NUL character; expected {LIST_FORMAT}", path)
        entries.append((number, entry))
    return entries


def _expand_listed(path, number, entry, kind, builtins):
    """:func:`_expand_one` for line ``number`` of the list file ``path``: its errors
    name the list file and the line, not the line's text (the file may be any file)."""
    from ..core.errors import InputError, one_line

    base = Path(path).expanduser().absolute().parent
    try:
        return _expand_one(entry, kind, base, builtins)
    except InputError as exc:
        problem = exc.problem
    except (OSError, ValueError, RuntimeError) as exc:  # a name too long, a folder that cannot be listed, ...
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else type(exc).__name__
        problem = f"not a usable path ({one_line(reason)})"  # strerror only: the exception names the path
    raise InputError(f"line {number}: {problem}; expected {LIST_FORMAT}", path)


def expand_inputs(arguments, list_files=(), kind="bake"):
    """The inputs of a batch, in the order given, each once.

    ``arguments``: files, folders (their files with :data:`BAKE_SUFFIXES` or
    :data:`SCENE_SUFFIXES`, sorted; not recursive) and globs (``**`` recurses;
    quote them for the shell), relative to the working directory; for
    renders also the built-in scene names.  ``list_files``: text files with
    one such entry a line, relative to the list file's folder
    (:func:`list_file_entries`; an error names the list file and the line
    number, not the line).  Returns
    absolute :class:`~pathlib.Path` objects (built-in scene names stay
    strings).  A missing path, a glob without matches, a folder without
    inputs or no input at all raise a one-line ValueError before anything
    starts."""
    builtins = ()
    if kind == "render":
        from ..rendering.scene import BUILTIN_SCENES as builtins
    expansions = [lambda a=str(a): _expand_one(a, kind, Path.cwd(), builtins) for a in arguments or ()]
    for lf in list_files or ():  # every list file read before any input is looked for
        expansions += [lambda lf=lf, n=n, e=e: _expand_listed(lf, n, e, kind, builtins)
                       for n, e in list_file_entries(lf)]
    seen, inputs = set(), []
    for expand in expansions:
        for item in expand():
            key = item if isinstance(item, str) else os.path.realpath(item)
            if key not in seen:
                seen.add(key)
                inputs.append(item if isinstance(item, str) else Path(os.path.abspath(item)))
    if not inputs:
        raise ValueError("no inputs: give files, folders or globs (or --list FILE)")
    return inputs


def _path_tag(item):
    """The 8 hex digits that tell inputs with the same stem apart: the start of
    the SHA-256 of the input's absolute path (of ``builtin:<name>`` for a
    built-in scene)."""
    text = f"builtin:{item}" if isinstance(item, str) else os.path.abspath(item)
    return hashlib.sha256(text.encode("utf-8", "surrogateescape")).hexdigest()


def output_names(inputs):
    """The folder name of each input under OUT (module doc): the stem, or
    ``<stem>-<8 hex>`` for stems that occur more than once in the batch
    (case-insensitively) or that equal one of :data:`RESERVED_NAMES`."""
    stems = [(item if isinstance(item, str) else Path(item).stem)[:_STEM_MAX] for item in inputs]
    counts = Counter(s.casefold() for s in stems)
    reserved = {r.casefold() for r in RESERVED_NAMES}
    names = []
    for item, stem in zip(inputs, stems):
        clash = counts[stem.casefold()] > 1 or stem.casefold() in reserved or not stem.strip(".")
        names.append(f"{stem}-{_path_tag(item)[:8]}" if clash else stem)
    taken = Counter(n.casefold() for n in names)
    for k, (item, name) in enumerate(zip(inputs, names)):  # a suffixed name equal to another input's stem
        if taken[name.casefold()] > 1:
            names[k] = f"{stems[k]}-{_path_tag(item)[:16]}"
    return names


# =================================================================== options


def bake_jobs_options(size=256, min_size=16, irradiance_size=32, lut_size=128, fmt="rgba16f", method="spectral",
                      sh_window=None, layout=None, fix_nonfinite=False):
    """The canonical options of a bake batch, under the keys the bake's
    manifest records them (``manifest["options"]``, :func:`pbrkit.ibl.bake.bake`)."""
    return {"size": size, "min_size": min_size, "irradiance_size": irradiance_size, "lut_size": lut_size,
            "format": fmt, "method": method, "sh_window": sh_window, "layout": layout,
            "fix_nonfinite": bool(fix_nonfinite)}


class _Checked(Exception):
    """Raised by :func:`check_bake_options`' ``started`` callback: the bake checked its options."""


def check_bake_options(options, targets):
    """Refuse bad bake options with the one-line errors of ``pbrkit bake``, before
    any cluster starts: :func:`pbrkit.ibl.bake.bake` itself checks them (sizes,
    format, method, SH window, the engine chains and their method), and is
    stopped by its ``started`` callback before it loads anything."""
    from ..ibl.bake import bake
    from ..io.bake_files import chains_for, parse_targets

    targets = parse_targets(targets)
    if options["layout"] not in (None, "equirect", "hcross", "vcross"):
        raise ValueError(f"unknown layout {options['layout']!r}; use equirect, hcross or vcross")

    def stop(*_):
        raise _Checked()

    try:
        bake(None, options["size"], options["min_size"], options["irradiance_size"], options["lut_size"],
             specular_format=options["format"], method=options["method"], sh_window=options["sh_window"],
             fix_nonfinite=options["fix_nonfinite"], layout=options["layout"], chains=chains_for(targets),
             started=stop)
    except _Checked:
        pass
    return targets


def render_jobs_options(mode="realtime", spp=64, bounces=0, tonemap="aces", exposure=0.0, width=None, height=None,
                        env=None, seed=0, diffuse="sh", energy_compensation=False, engine="pbrkit", bake_size=256,
                        fix_nonfinite=False, occlusion=None, style=None, fmt="png", allow_roots=()):
    """The canonical options of a render batch (those of ``pbrkit render``, and the
    image format ``fmt``, png or exr), checked as ``pbrkit render`` checks them
    before it loads a scene; ``env`` (a file or bake folder) and the folders of
    ``allow_roots`` (``--allow-root``) become absolute."""
    from ..core import checks
    from ..core.color import TONEMAPS
    from ..rendering.run import MODES

    if fmt not in ("png", "exr"):
        raise ValueError(f"--format: unknown image format {fmt!r}; choose one of png, exr")
    if mode not in MODES:
        raise ValueError(f"unknown mode {mode!r}; choose one of {', '.join(MODES)}")
    if tonemap not in TONEMAPS:
        raise ValueError(f"unknown tone mapper {tonemap!r}; choose one of {', '.join(TONEMAPS)}")
    if mode != "realtime":
        checks.integer(spp, "--spp", 1, 1 << 20)
    if mode != "reference":
        checks.power_of_two(bake_size, "--bake-size", 2, 4096)
    checks.integer(bounces, "--bounces", 0, 64)
    for value, flag in ((width, "--width"), (height, "--height")):  # the flag typed, not the scene key
        if value is not None:
            checks.integer(value, flag, 1, 16384)
    if env is not None:
        if not Path(env).exists():
            raise ValueError(f"{env}: environment file not found")
        env = os.path.abspath(env)
    if style is not None:
        from ..npr.style import STYLE_PRESETS, resolve_style

        from ..rendering.run import check_style_flag

        if str(style) not in STYLE_PRESETS:
            style = os.path.abspath(style)
        check_style_flag(mode, resolve_style(style))
    from ..io.gltf_resources import allowed_root

    roots = [os.path.abspath(allowed_root(root, None, "--allow-root")) for root in allow_roots]
    return {"mode": mode, "spp": spp, "bounces": bounces, "tonemap": tonemap, "exposure": float(exposure),
            "width": width, "height": height, "env": env, "seed": seed, "diffuse": diffuse,
            "energy_compensation": bool(energy_compensation), "engine": engine, "bake_size": bake_size,
            "fix_nonfinite": bool(fix_nonfinite), "occlusion": occlusion, "style": style, "format": fmt,
            "allow_roots": roots}


# ===================================================================== batch


class _Silent:
    """The progress of a batch run without one: nothing is shown."""

    def note(self, text):
        pass

    def start(self):
        pass

    def finished(self, outcome):
        pass


def remove_stale_temporaries(out, names):
    """Remove the hidden temporary folders (``.<name>.XXXXXXXX.partial`` and
    ``.old``, :func:`pbrkit.core.atomic.atomic_directory`) that killed tasks left
    in ``out`` for ``names``; call it only when no task of the batch runs.
    Returns the names removed."""
    out = Path(out)
    if not out.is_dir():
        return []
    patterns = [re.compile(r"\." + re.escape(n[:96]) + r"\.[A-Za-z0-9_]{8}\.(partial|old)\Z") for n in names]
    removed = []
    for entry in out.iterdir():
        if entry.name.startswith(".") and any(p.match(entry.name) for p in patterns):
            shutil.rmtree(entry, ignore_errors=True)
            removed.append(entry.name)
    return sorted(removed)


def _make_jobs(kind, inputs, names, out, options, targets, force, numba_threads=None):
    jobs = []
    for item, name in zip(inputs, names):
        jobs.append({"kind": kind, "input": str(item), "display": str(item), "name": name,
                     "builtin": isinstance(item, str),
                     "out": str(Path(out).absolute() / name), "options": options, "targets": list(targets),
                     "force": bool(force), "numba_threads": numba_threads})
    return jobs


def _killed_outcome(job, exc):
    from ..core.errors import one_line

    text = one_line(exc) or type(exc).__name__
    if type(exc).__name__ == "KilledWorker":
        text = ("the workers running this input died repeatedly (Dask's KilledWorker; out of memory?): "
                + text)
    return {"name": job["name"], "input": job["display"], "status": "failed", "error": text, "notes": [],
            "warnings": [], "seconds": 0.0, "bytes": 0, "worker": None}


def run_batch(kind, inputs, out, options, targets=("generic",), *, force=False, scheduler=None, workers=None,
              threads=None, dashboard=True, progress=None, scheduler_timeout=DEFAULT_SCHEDULER_TIMEOUT):
    """Run a batch (module doc) and write ``out/batch.json`` and ``out/index.html``.

    ``kind`` ``"bake"`` or ``"render"``; ``inputs`` from :func:`expand_inputs`;
    ``options`` from :func:`bake_jobs_options` / :func:`render_jobs_options`;
    ``targets`` the bake's engine targets.  ``progress`` a
    :class:`pbrkit.cli.console.BatchProgress` (or None: silent).  ``scheduler``: a ``--scheduler`` address,
    which has ``scheduler_timeout`` seconds to answer
    (:func:`pbrkit.app.scheduler.connect_scheduler`).  Returns the summary (what batch.json
    holds): per input, in input order, its outcome (:func:`run_task`)."""
    from .. import __version__
    from ..core.atomic import atomic_group

    if kind not in KINDS:
        raise ValueError(f"unknown batch kind {kind!r}")
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"{out}: exists and is not a directory")
    names = output_names(inputs)
    local = scheduler is None
    jobs = _make_jobs(kind, inputs, names, out, options, targets, force,
                      (1 if threads is None else int(threads)) if local else None)
    progress = progress or _Silent()
    outcomes = [None] * len(jobs)
    summary = None
    info = {}
    t0 = time.perf_counter()
    interrupted = False
    finished_all = False
    try:
        with dask_client(scheduler, workers, threads, kind, dashboard, scheduler_timeout) as (client, description):
            info["cluster"] = description
            progress.note(description)
            if dashboard or scheduler is not None:
                with contextlib.suppress(Exception):
                    info["dashboard"] = client.dashboard_link
                    progress.note(f"dashboard {client.dashboard_link}")
            info["workers"] = len(client.scheduler_info().get("workers", {}))
            futures = {}
            warm_up = len(jobs) > 1 and cache_is_cold(client, kind)
            progress.start()
            t_submit = time.perf_counter()
            info["start_seconds"] = t_submit - t0
            try:
                from distributed import as_completed

                token = os.urandom(4).hex()

                def submit(k):
                    f = client.submit(run_task, jobs[k], key=f"pbrkit-{kind}-{k}-{jobs[k]['name']}-{token}",
                                      pure=False, retries=0)
                    futures[f] = k
                    return f

                if warm_up:  # one input at a time until one is baked or rendered (skipped and failed ones
                    # compile nothing), then all the others
                    progress.note("no compiled kernels in the Numba cache yet: the first input runs alone "
                                  "and the others load what it compiles")
                    queue = as_completed([submit(0)])
                    rest = list(range(1, len(jobs)))
                else:
                    queue = as_completed([submit(k) for k in range(len(jobs))])
                    rest = []
                for f in queue:
                    k = futures[f]
                    try:
                        outcomes[k] = f.result()
                    except Exception as exc:  # the scheduler gave up on it (KilledWorker) or a cancelled task
                        outcomes[k] = _killed_outcome(jobs[k], exc)
                    progress.finished(outcomes[k])
                    if rest:
                        release = rest if outcomes[k]["status"] == "done" else rest[:1]
                        rest = rest[len(release):]
                        for j in release:
                            queue.add(submit(j))
                finished_all = True
                info["tasks_seconds"] = time.perf_counter() - t_submit
            except KeyboardInterrupt:
                interrupted = True
                with contextlib.suppress(Exception):
                    client.cancel(list(futures))
                raise
    except KeyboardInterrupt:
        interrupted = True
        raise
    finally:
        if finished_all or (interrupted and local):  # no task of this batch can still be writing
            info["removed_temporaries"] = remove_stale_temporaries(out, names)
        if any(o is not None for o in outcomes) or finished_all:
            for k, job in enumerate(jobs):
                if outcomes[k] is None:
                    outcomes[k] = {"name": job["name"], "input": job["display"], "status": "not run",
                                   "error": "the batch was interrupted before this input's result came back "
                                            "(a re-run skips it if its folder was completed)",
                                   "notes": [], "warnings": [], "seconds": 0.0, "bytes": 0, "worker": None}
            _carry_earlier_times(out / "batch.json", outcomes)
            summary = _summary(kind, out, options, targets, outcomes, info, time.perf_counter() - t0,
                               __version__, interrupted)
            with atomic_group([out / "batch.json", out / "index.html"]) as (json_tmp, html_tmp):
                json_tmp.write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
                html_tmp.write_text(gallery_html(summary), encoding="utf-8")
    return summary


def _carry_earlier_times(path, outcomes):
    """Give each skipped input the time of the run that made its folder, from the
    previous ``batch.json`` (``earlier_seconds``), for the gallery."""
    previous = _read_json(path)
    if previous is None or previous.get("format") != SUMMARY_FORMAT:
        return
    earlier = {}
    for o in previous.get("inputs") or []:
        if isinstance(o, dict) and o.get("status") == "done":
            earlier[o.get("name")] = o.get("seconds")
        elif isinstance(o, dict) and o.get("status") == "skipped" and o.get("earlier_seconds") is not None:
            earlier[o.get("name")] = o.get("earlier_seconds")
    for o in outcomes:
        if o["status"] == "skipped" and isinstance(earlier.get(o["name"]), (int, float)):
            o["earlier_seconds"] = float(earlier[o["name"]])


def _summary(kind, out, options, targets, outcomes, info, wall, version, interrupted):
    counts = Counter(o["status"] for o in outcomes)
    shown = dict(options)
    summary = {
        "format": SUMMARY_FORMAT,
        "pbrkit_version": version,
        "command": f"batch {kind}",
        "out": str(out),
        "options": shown,
        "counts": {s: counts.get(s, 0) for s in ("done", "skipped", "failed", "not run")},
        "wall_seconds": wall,
        "interrupted": interrupted,
        "inputs": outcomes,
    }
    if kind == "bake":
        summary["targets"] = list(targets)
    summary.update(info)
    return summary


# =================================================================== gallery


def _size_text(n):
    for unit in ("B", "kB", "MB", "GB"):
        if n < 1000 or unit == "GB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1000.0
    return f"{n:.1f} GB"


_PAGE_STYLE = """
body { font: 14px/1.4 system-ui, -apple-system, "Segoe UI", sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.3em; }
table { border-collapse: collapse; }
th, td { padding: 6px 10px; border-bottom: 1px solid #ddd; text-align: left; vertical-align: top; }
td.num { text-align: right; white-space: nowrap; }
img { max-height: 120px; max-width: 480px; display: block; }
.failed td { background: #fff0f0; }
.status-failed { color: #b00020; font-weight: 600; }
.status-skipped { color: #666; }
.error { color: #b00020; font-family: ui-monospace, monospace; font-size: 12px; }
.note { color: #666; font-size: 12px; }
code { font-size: 12px; }
"""


def gallery_html(summary):
    """``OUT/index.html``: every input's preview (a bake's ``preview.png``, a
    render's image or, for EXR, its thumbnail) by relative path, with its
    status, time, size and error line; self-contained (no script, no
    server)."""
    e = html.escape
    counts = summary["counts"]
    head = (f"{len(summary['inputs'])} inputs: {counts['done']} done, {counts['skipped']} skipped, "
            f"{counts['failed']} failed" + (f", {counts['not run']} not run (interrupted)" if counts["not run"] else "")
            + f"; {summary['wall_seconds']:.1f} s on {summary.get('cluster', 'no cluster')}")
    options = ", ".join(f"{k}={v}" for k, v in summary["options"].items() if v is not None)
    if summary.get("targets"):
        options += ", targets=" + ",".join(summary["targets"])
    rows = []
    for o in summary["inputs"]:
        link = quote(o["name"]) + "/"
        preview = o.get("preview")
        cell = ""
        if preview and o["status"] in ("done", "skipped"):
            cell = (f'<a href="{e(link)}"><img src="{e(link + quote(preview))}" alt="{e(o["name"])}" '
                    f'loading="lazy"></a>')
        time_text = f"{o['seconds']:.2f} s" if o["status"] == "done" else ""
        if o["status"] == "skipped" and o.get("earlier_seconds") is not None:
            time_text = f"{o['earlier_seconds']:.2f} s (earlier)"
        size_text = _size_text(o["bytes"]) if o.get("bytes") else ""
        detail = [f"<code>{e(str(o['input']))}</code>"]
        if o.get("error"):
            detail.append(f'<div class="error">{e(o["error"])}</div>')
        for text in list(o.get("notes") or []) + [f"warning: {w}" for w in o.get("warnings") or []]:
            detail.append(f'<div class="note">{e(text)}</div>')
        name_cell = f'<a href="{e(link)}">{e(o["name"])}</a>' if o["status"] in ("done", "skipped") else e(o["name"])
        rows.append(f'<tr class="{e(o["status"].replace(" ", "-"))}"><td>{name_cell}</td>'
                    f'<td class="status-{e(o["status"].replace(" ", "-"))}">{e(o["status"])}</td>'
                    f'<td class="num">{time_text}</td><td class="num">{size_text}</td><td>{cell}</td>'
                    f'<td>{"".join(detail)}</td></tr>')
    title = f"pbrkit {summary['command']}: {summary['out']}"
    return (f'<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n<title>{e(title)}</title>\n'
            f"<style>{_PAGE_STYLE}</style>\n</head>\n<body>\n<h1>{e(title)}</h1>\n<p>{e(head)}</p>\n"
            f"<p class=\"note\">pbrkit {e(summary['pbrkit_version'])}; options: {e(options)}</p>\n"
            "<table>\n<thead><tr><th>name</th><th>status</th><th>time</th><th>size</th><th>preview</th>"
            "<th>input</th></tr></thead>\n<tbody>\n" + "\n".join(rows) + "\n</tbody>\n</table>\n</body>\n</html>\n")
