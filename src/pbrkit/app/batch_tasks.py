"""The task of one input of a batch (``pbrkit batch bake|render``,
:mod:`pbrkit.app.batch`), as a Dask worker runs it: :func:`run_task` bakes or
renders the input into its folder with the functions ``pbrkit bake`` and
``pbrkit render`` call, unless the folder's record says it is up to date
(:func:`bake_state`, :func:`render_state`), and returns its outcome instead of
raising.

A render's record lists every file the render reads (:func:`render_record`),
a glTF's buffers and images included, confined to the glTF's folder as the
renderer confines them (:func:`_gltf_references`); records and manifests are
read bounded (:func:`_read_json`).
"""

from __future__ import annotations

import contextlib
import json
import os
import time
import traceback
import warnings
from pathlib import Path

__all__ = ["RECORD_NAME", "RECORD_FORMAT", "run_task", "bake_state", "render_state", "render_record",
           "folder_bytes"]

#: The per-input record of a render folder (a bake's record is its manifest.json).
RECORD_NAME = "batch.json"
RECORD_FORMAT = "pbrkit batch render record"


def _sha256(path):
    from ..ibl.bake import _sha256 as sha256

    return sha256(path)


def folder_bytes(path):
    """Total size in bytes of the files under ``path``."""
    total = 0
    for root, _, files in os.walk(path):
        for f in files:
            with contextlib.suppress(OSError):
                total += os.lstat(os.path.join(root, f)).st_size
    return total


def _read_json(path, limit=None):
    """The JSON object (a dict) in the file ``path``, or None: no such regular file,
    larger than ``limit`` bytes (default :data:`pbrkit.core.inputs.MAX_TEXT_BYTES`;
    :func:`pbrkit.core.inputs.read_text`), not UTF-8, not JSON (nested too deep
    included) or not an object."""
    from ..core.inputs import MAX_TEXT_BYTES, read_text

    try:
        value = json.loads(read_text(path, MAX_TEXT_BYTES if limit is None else limit, "a JSON file"))
    except (OSError, ValueError, RecursionError):  # InputError is a ValueError
        return None
    return value if isinstance(value, dict) else None


def _existing(out):
    """"absent" (no folder, or an empty one) or "present"; InputError for a file in the way."""
    from ..core.errors import InputError

    out = Path(out)
    if not (out.exists() or out.is_symlink()):
        return "absent"
    if not out.is_dir():
        raise InputError("exists and is not a directory", out)
    return "present" if any(out.iterdir()) else "absent"


#: Files every bake folder has (:mod:`pbrkit.io.bake_files`); one missing makes the folder stale.
_BAKE_FILES = ("specular.ktx2", "specular.dds", "irradiance.ktx2", "irradiance.dds", "brdf_lut.npy", "sheen.ktx2",
               "sheen.dds", "sheen_lut.npy", "preview.png")


def bake_state(out, input_name, sha256, options, targets):
    """What ``out`` holds for this bake: ``("absent", None)``, ``("match", None)``
    (its manifest records this pbrkit version, this input's name and SHA-256,
    these options and engine targets, and its files are there), ``("stale",
    reason)`` (a pbrkit bake of something else) or ``("foreign", reason)``
    (not a pbrkit bake)."""
    from .. import __version__
    from ..ibl.bake import FORMAT

    out = Path(out)
    if _existing(out) == "absent":
        return "absent", None
    manifest = _read_json(out / "manifest.json")
    if manifest is None or manifest.get("format") != FORMAT:
        return "foreign", "not a pbrkit bake (no pbrkit manifest.json)"
    differences = []
    if manifest.get("pbrkit_version") != __version__:
        differences.append(f"pbrkit {manifest.get('pbrkit_version')} -> {__version__}")
    if (manifest.get("input") or {}).get("files") != [{"name": input_name, "sha256": sha256}]:
        differences.append("the input changed (its name or SHA-256)")
    recorded = manifest.get("options") if isinstance(manifest.get("options"), dict) else {}
    for key, value in options.items():
        if key == "layout" and value is None:  # detected from the image, whose SHA-256 is compared
            continue
        if recorded.get(key) != value:
            differences.append(f"{key} {recorded.get(key)!r} -> {value!r}")
    recorded_targets = sorted(manifest.get("targets") or {})
    wanted = sorted(t for t in targets if t != "generic")
    if recorded_targets != wanted:
        differences.append(f"targets {recorded_targets} -> {wanted}")
    missing = [f for f in _BAKE_FILES + tuple(wanted) if not (out / f).exists()]
    if missing:
        differences.append(f"incomplete (no {missing[0]})")
    return ("stale", "; ".join(differences)) if differences else ("match", None)


def _outcome(status, **fields):
    return dict({"status": status, "error": None, "notes": [], "warnings": []}, **fields)


def _bake_job(job):
    from ..core.errors import InputError, OutputError
    from ..ibl.bake import bake
    from ..io.bake_files import chains_for, write_bake

    source = Path(job["input"])
    options, targets, out = job["options"], tuple(job["targets"]), Path(job["out"])
    if not source.is_file():
        raise InputError("no such file" if not source.exists() else "not a file", job["display"])
    sha = _sha256(source)
    state, reason = bake_state(out, source.name, sha, options, targets)
    if state == "match" and not job["force"]:
        return _outcome("skipped", notes=["already baked with these options"], preview="preview.png")
    if state == "foreign" and not job["force"]:
        raise InputError(f"{reason}; not replaced (use --force to replace it)", out)
    t0 = time.perf_counter()
    result = bake(str(source), size=options["size"], min_size=options["min_size"],
                  irradiance_size=options["irradiance_size"], lut_size=options["lut_size"],
                  specular_format=options["format"], method=options["method"], sh_window=options["sh_window"],
                  fix_nonfinite=options["fix_nonfinite"], layout=options["layout"], chains=chains_for(targets))
    t1 = time.perf_counter()
    try:
        write_bake(result, out, force=job["force"] or state != "absent", targets=targets)
    except OutputError as exc:  # filled meanwhile (another task for the same folder finished first)
        if state == "absent" and bake_state(out, source.name, sha, options, targets)[0] == "match":
            return _outcome("skipped", notes=["written meanwhile by another task"], preview="preview.png")
        raise exc
    notes = [f"replaced: {reason}"] if state == "stale" else ([f"replaced ({reason})"] if state == "foreign" else [])
    return _outcome("done", notes=notes, bake_s=t1 - t0, write_s=time.perf_counter() - t1,
                    preview="preview.png")


# ---------------------------------------------------------------- renders


#: The largest .gltf whose references a render record lists (the renderer's own bound,
#: ``pbrkit.io.gltf_document``: a .gltf may embed its buffers as data: URIs).
_GLTF_JSON_LIMIT = 2 << 30


def _gltf_references(path, allowed_roots=()):
    """The external files (buffers, images) a ``.gltf`` names by URI, each confined
    as the renderer confines them (:class:`pbrkit.core.inputs.Confinement`: under
    the glTF's own folder or one of ``allowed_roots``; ``data:`` URIs are inline);
    InputError naming the glTF and the URI's place for one that lies elsewhere."""
    from ..core.inputs import Confinement

    if Path(path).suffix.lower() != ".gltf":
        return []
    data = _read_json(path, _GLTF_JSON_LIMIT) or {}  # unreadable: the render fails on it with its own error
    confinement = Confinement(Path(path).parent, allowed_roots)
    found = []
    for key in ("buffers", "images"):
        entries = data.get(key)
        for k, entry in enumerate(entries if isinstance(entries, list) else []):
            uri = entry.get("uri") if isinstance(entry, dict) else None
            if isinstance(uri, str) and uri and not uri.startswith("data:"):
                found.append(confinement.resolve(uri, f"{key}[{k}].uri", path))
    return found


def _scene_references(scene, style, allowed_roots=()):
    """[role, file name, SHA-256 or None if missing] of every file the render
    reads besides the scene file: its environment image (or every file of its
    bake folder), its glTF files and their buffers and images (confined:
    :func:`_gltf_references` with ``allowed_roots``), a style file."""
    from ..rendering.scene import GltfObject

    files = []
    env = scene.environment
    if env.file is not None:
        files.append(("environment", Path(env.file)))
    if env.bake is not None:
        root = Path(env.bake)
        files += [("environment bake", p) for p in sorted(root.rglob("*")) if p.is_file()]
    for obj in scene.objects:
        if isinstance(obj, GltfObject):
            files.append(("gltf", Path(obj.file)))
            files += [("gltf resource", p) for p in _gltf_references(obj.file, allowed_roots)]
    if style is not None and Path(style).is_file():
        files.append(("style", Path(style)))
    return [[role, p.name, _sha256(p) if p.is_file() else None] for role, p in files]


def render_record(scene_input, scene, options, builtin=False, allowed_roots=()):
    """The record a render folder keeps in ``batch.json`` (module doc): what the
    render depends on, nothing time- or machine-dependent (file names, not
    paths).  ``allowed_roots``: the folders besides a glTF's own its files may
    lie in (:func:`_gltf_references`)."""
    from .. import __version__

    if builtin:
        source = {"builtin": scene_input}
    else:
        source = {"name": Path(scene_input).name, "sha256": _sha256(scene_input)}
    shown = dict(options)
    for key in ("env", "style"):
        if shown[key] is not None and os.path.isabs(shown[key]):
            shown[key] = Path(shown[key]).name
    return {"format": RECORD_FORMAT, "pbrkit_version": __version__, "scene": source,
            "references": _scene_references(scene, options["style"], allowed_roots), "options": shown}


def render_state(out, record):
    """As :func:`bake_state`, for a render folder and its ``batch.json`` record."""
    out = Path(out)
    if _existing(out) == "absent":
        return "absent", None
    stored = _read_json(out / RECORD_NAME)
    if stored is None or stored.get("format") != RECORD_FORMAT:
        return "foreign", f"not a pbrkit batch render (no {RECORD_NAME} record)"
    differences = [k for k in ("pbrkit_version", "scene", "references", "options") if stored.get(k) != record[k]]
    missing = [f for f in stored.get("outputs") or ["?"] if not (out / f).is_file()]
    if missing:
        differences.append(f"incomplete (no {missing[0]})")
    return ("stale", "differs in " + ", ".join(differences)) if differences else ("match", None)


def _thumbnail(image_path, thumb_path, options, width=512):
    """An 8-bit sRGB PNG of a linear EXR render for the gallery: tone-mapped as the
    PNG output is (:func:`pbrkit.core.color.tonemap`, the batch's --tonemap and
    --exposure), box-filtered by an integer factor to at most ``width`` pixels
    across."""
    import numpy as np

    from ..core.color import linear_to_srgb, tonemap
    from ..io.images import read_image
    from ..io.png import write_png

    image = np.asarray(read_image(image_path), dtype=np.float64)[..., :3]
    k = max(1, -(-image.shape[1] // width))
    h, w = image.shape[0] // k * k, image.shape[1] // k * k
    if k > 1 and h and w:
        image = image[:h, :w].reshape(h // k, k, w // k, k, 3).mean(axis=(1, 3))
    write_png(thumb_path, linear_to_srgb(tonemap(image, options["tonemap"], options["exposure"])), bits=8,
              srgb=False)


def _render_job(job):

    from ..core.atomic import atomic_directory
    from ..core.errors import InputError, OutputError
    from ..rendering.run import render_scene
    from ..rendering.sources import command_scene

    options, out, name = job["options"], Path(job["out"]), job["name"]
    scene_input = job["input"]
    scene = command_scene(scene_input, options["width"], options["height"], options["env"], options["fix_nonfinite"],
                          options.get("allow_roots", ()))
    style = None
    if options["style"] is not None:
        from ..npr.style import resolve_style

        style = resolve_style(options["style"])
    record = render_record(scene_input, scene, options, job.get("builtin", False),
                           getattr(scene, "allow_roots", ()))  # the scene key and --allow-root
    state, reason = render_state(out, record)
    image_name = f"{name}.{options['format']}"
    preview = "thumbnail.png" if options["format"] == "exr" else image_name
    if state == "match" and not job["force"]:
        return _outcome("skipped", notes=["already rendered with these options"], preview=preview)
    if state == "foreign" and not job["force"]:
        raise InputError(f"{reason}; not replaced (use --force to replace it)", out)
    t0 = time.perf_counter()
    try:
        with atomic_directory(out, job["force"] or state != "absent") as tmp:
            summary = render_scene(scene, tmp / image_name, mode=options["mode"], spp=options["spp"],
                                   bounces=options["bounces"], seed=options["seed"], tonemap_name=options["tonemap"],
                                   exposure=options["exposure"], diffuse=options["diffuse"],
                                   energy_compensation=options["energy_compensation"],
                                   bake_size=options["bake_size"], occlusion=options["occlusion"],
                                   engine=options["engine"], style=style)
            outputs = [Path(p).name for p in summary["outputs"]]
            if options["format"] == "exr":
                _thumbnail(tmp / image_name, tmp / preview, options)
                outputs.append(preview)
            record["outputs"] = sorted(outputs)
            (tmp / RECORD_NAME).write_text(json.dumps(record, indent=2, sort_keys=True) + "\n", encoding="utf-8")
    except OutputError:
        if state == "absent" and render_state(out, record)[0] == "match":
            return _outcome("skipped", notes=["written meanwhile by another task"], preview=preview)
        raise
    notes = [str(n) for n in summary.get("notes", [])]
    if state != "absent":
        notes.append(f"replaced: {reason}")
    extra = {}
    if "errors" in summary:
        e = summary["errors"]
        extra["errors"] = {k: float(e[k]) for k in ("rms_relative_error_noise_removed", "mean_relative_error",
                                                     "flip") if k in e}
    return _outcome("done", notes=notes, render_s=time.perf_counter() - t0, preview=preview, **extra)


def _worker_address():
    try:
        from distributed import get_worker

        return get_worker().address
    except (ImportError, ValueError):
        return None


def run_task(job):
    """Run one input's job (a dict: ``kind``, ``input``, ``display``, ``name``,
    ``out``, ``options``, ``targets``, ``force``) and return its outcome, a
    dict with ``status`` ``done`` / ``skipped`` / ``failed``, ``error`` (one
    line, as ``pbrkit bake`` / ``pbrkit render`` print it), ``seconds``,
    ``bytes`` (of the folder), ``warnings``, ``notes`` and ``worker``.  Never
    raises for a bad input: a batch's inputs fail alone.  Runs on a Dask
    worker (or in this process)."""
    from ..core.errors import is_library_error, one_line

    t0 = time.perf_counter()
    if job.get("numba_threads"):  # a LocalCluster's worker (forked workers keep this process's pool size)
        import numba

        numba.set_num_threads(min(int(job["numba_threads"]), numba.config.NUMBA_NUM_THREADS))
    base = {"name": job["name"], "input": job["display"], "worker": _worker_address(), "pid": os.getpid()}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UserWarning)
        try:
            outcome = (_bake_job if job["kind"] == "bake" else _render_job)(job)
        except MemoryError as exc:
            outcome = _outcome("failed", error=f"out of memory{f' ({exc})' if str(exc) else ''}; try smaller sizes")
        except (ValueError, OSError) as exc:
            outcome = _outcome("failed", error=one_line(exc))
        except Exception as exc:  # a bug, or a library's error: this input fails, the batch goes on
            if is_library_error(exc):
                outcome = _outcome("failed", error=one_line(exc))
            else:
                outcome = _outcome("failed", error=f"internal error: {type(exc).__name__}: {one_line(exc)}",
                                   traceback=traceback.format_exc())
    seen = []
    for w in caught:
        text = one_line(w.message)
        if issubclass(w.category, UserWarning) and not issubclass(w.category, DeprecationWarning) and text not in seen:
            seen.append(text)
    outcome["warnings"] = seen
    outcome["seconds"] = time.perf_counter() - t0
    outcome["bytes"] = folder_bytes(job["out"]) if outcome["status"] != "failed" else 0
    return dict(base, **outcome)
