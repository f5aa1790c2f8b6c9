"""The files of an image-based-lighting bake (:mod:`pbrkit.ibl.bake`).

:func:`write_bake` writes a directory (into a temporary directory beside it,
renamed into place at the end, so a failure leaves nothing behind)::

    manifest.json                      what is below and every convention
    khronos/, filament/, three/, babylon/   with ``targets``: each engine's files
                                       (:mod:`pbrkit.engines`)
    specular.ktx2, specular.dds        cube map, all levels
    irradiance.ktx2, irradiance.dds    cube map, one level
    brdf_lut.ktx2, .npy, .exr          the DFG table (+ .json descriptions)
    sheen.ktx2, sheen.dds              the Charlie-prefiltered (sheen) cube map, all levels
    sheen_lut.ktx2, .npy               the sheen table (E_sheen, E_ashikhmin) (+ .json)
    faces/specular_m{m}_{px|nx|py|ny|pz|nz}.exr, faces/irradiance_{face}.exr
    preview.png                        every level as a tone-mapped cross

With ``only_targets`` it holds the engines' folders and the manifest alone
(``"only_targets": true``; :func:`load_bake` refuses such a folder: it has no
generic files).  :func:`load_bake` reads a whole bake back, as untrusted input: regular files only, the
manifest as bounded text (:func:`pbrkit.core.inputs.read_text`), the table with
:func:`pbrkit.io.npy_files.read_npy`, images and KTX2 files through their readers,
and messages that never quote the manifest.  Same input and options, same bytes:
nothing time- or machine-dependent is written.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from ..core.atomic import atomic_directory
from ..engines import ENGINES, TARGETS, chains_for, parse_targets, write_target
from ..engines.common import lut_spec
from .bake_chains import bake_formats, write_sheen_ktx2, write_specular_ktx2

__all__ = [
    "TARGETS",
    "parse_targets",
    "chains_for",
    "write_bake",
    "load_bake",
    "load_target_chain",
]

# ---------------------------------------------------------------------- write


def preview_strip(bake_result, *args, **kwargs):
    """:func:`pbrkit.ibl.bake.preview_strip` (imported when called)."""
    from ..ibl.bake import preview_strip as strip

    return strip(bake_result, *args, **kwargs)


def _face_path(kind, face, level=None):
    from ..ibl.bake import FACE_FILE_NAMES

    name = FACE_FILE_NAMES[face]
    return f"faces/specular_m{level}_{name}.exr" if kind == "specular" else f"faces/irradiance_{name}.exr"


#: The groups of files :func:`write_bake` writes, in order (its progress stages).
WRITE_STEPS = ("specular.ktx2", "specular.dds", "irradiance", "brdf_lut", "sheen", "faces", "preview", "manifest")


def write_steps(targets=("generic",)):
    """:data:`WRITE_STEPS` with a step per extra target before the manifest; the
    targets and the manifest alone when ``generic`` is not among ``targets``
    (:func:`pbrkit.engines.parse_targets` with ``only_targets``)."""
    extra = tuple(t for t in targets if t != "generic")
    generic = WRITE_STEPS[:-1] if "generic" in targets else ()
    return generic + extra + WRITE_STEPS[-1:]


def _write_all(root, b, progress, started=None, targets=("generic",)):
    steps = write_steps(targets)
    count = [0]

    def step(name):
        count[0] += 1
        if progress is not None:
            progress(f"write {name}", count[0], len(steps))
        if started is not None and count[0] < len(steps):
            started(f"write {steps[count[0]]}", count[0] + 1, len(steps))

    if started is not None:
        started(f"write {steps[0]}", 1, len(steps))

    if "generic" in targets:
        _write_generic(root, b, step)
    entries = {}
    for name in targets:
        if name != "generic":
            entries[name] = write_target(name, root, b)
            step(name)
    manifest = b.manifest
    if entries:
        manifest = dict(manifest, targets=entries)
    if "generic" not in targets:
        manifest = dict(manifest, only_targets=True)
    (root / "manifest.json").write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")
    step("manifest")


def _write_generic(root, b, step):
    """pbrkit's own files of ``b`` into ``root`` (module doc), ``step(name)`` after each group."""
    from .dds import write_dds
    from .exr import write_exr
    from .ktx2 import write_ktx2
    from .lut_files import write_lut
    from .png import write_png

    ktx_format, dds_format = bake_formats(b)
    write_specular_ktx2(root / "specular.ktx2", b)
    step("specular.ktx2")
    write_dds(root / "specular.dds", b.specular, dds_format, cube=True)
    step("specular.dds")
    key = {"pbrkit.bake": json.dumps({"content": "irradiance E(n), constant radiance 1 gives pi"})}
    write_ktx2(root / "irradiance.ktx2", [b.irradiance], ktx_format, cube=True, key_values=key)
    write_dds(root / "irradiance.dds", [b.irradiance], dds_format, cube=True)
    step("irradiance")
    spec = lut_spec(b)
    for suffix in (".ktx2", ".npy", ".exr"):
        write_lut(root / f"brdf_lut{suffix}", b.lut, spec)
    step("brdf_lut")
    if b.sheen:
        _write_sheen(root, b, dds_format)
    step("sheen")
    (root / "faces").mkdir()
    for m, level in enumerate(b.specular):
        for f in range(6):
            write_exr(root / _face_path("specular", f, m), level[f])
    for f in range(6):
        write_exr(root / _face_path("irradiance", f), b.irradiance[f])
    step("faces")
    write_png(root / "preview.png", preview_strip(b), bits=8, srgb=True)
    step("preview")


def _write_sheen(root, b, dds_format):
    """The sheen chain (KTX2 and DDS, as the specular chain) and the sheen table
    (:func:`pbrkit.albedo.sheen_tables.sheen_lut`) of ``b``."""
    from ..albedo.sheen_tables import SheenTableSpec
    from .dds import write_dds
    from .lut_files import write_lut

    write_sheen_ktx2(root / "sheen.ktx2", b)
    write_dds(root / "sheen.dds", b.sheen, dds_format, cube=True)
    spec = SheenTableSpec("sheen", int(b.sheen_lut.shape[0]), "sheen")
    for suffix in (".ktx2", ".npy"):
        write_lut(root / f"sheen_lut{suffix}", b.sheen_lut, spec)


def write_bake(bake_result, out_dir, force=False, progress=None, started=None, targets=("generic",),
               only_targets=False):
    """Write ``bake_result`` to the directory ``out_dir`` (module doc).

    The files are written into a temporary directory beside ``out_dir``,
    which is renamed to ``out_dir`` only when everything succeeded; any
    failure removes it (and any parent directories this call created), so
    no partial output remains (:func:`pbrkit.core.atomic.atomic_directory`).
    An existing non-empty ``out_dir`` is refused unless ``force``, which
    replaces it; when another process fills an empty ``out_dir`` meanwhile,
    this one fails instead of replacing its output.  ``progress(step, done,
    total)`` after each group of files (:func:`write_steps`), ``started(step,
    number, total)`` before each.  ``targets`` (:func:`parse_targets`) adds the
    files of other engines in subdirectories (their manifest entries under
    ``targets``); ``only_targets`` writes those and the manifest alone, not
    pbrkit's own files (``targets`` must then name an engine).  Returns the output
    path."""
    targets = parse_targets(targets, only_targets)
    with atomic_directory(out_dir, force) as tmp:
        _write_all(tmp, bake_result, progress, started, targets)
    return Path(out_dir)


# ----------------------------------------------------------------------- load


_MISSING = object()


def _entry(manifest, path, dotted, check=None, what=None):
    """``manifest[a][b]...`` for ``dotted`` = "a.b..."; a missing key, or a
    value that fails ``check``, raises :class:`InputError` naming ``path``
    (the manifest) and the key."""
    from ..core.errors import InputError

    value = manifest
    keys = dotted.split(".")
    for depth, key in enumerate(keys):
        if not isinstance(value, dict):
            raise InputError(f"{'.'.join(keys[:depth])!r} must be a JSON object; got {_kind(value)}", path)
        value = value.get(key, _MISSING)
        if value is _MISSING:
            raise InputError(f"missing {'.'.join(keys[:depth + 1])!r}", path)
    if check is not None:
        try:
            ok = check(value)
        except (TypeError, ValueError, OverflowError):
            ok = False
        if not ok:
            raise InputError(f"{dotted!r} must be {what}; got {_kind(value)}", path)
    return value


def _kind(value):
    """What a JSON value is, for a message that must not quote the manifest: 'a
    list of 3', 'a string', 'the number 7' (numbers are named, they are no text)."""
    if isinstance(value, bool) or value is None:
        return "true" if value is True else "false" if value is False else "null"
    if isinstance(value, (int, float)):
        return f"the number {value:.6g}" if isinstance(value, float) else f"the number {value}"
    if isinstance(value, (list, dict)):
        return f"{'a list' if isinstance(value, list) else 'an object'} of {len(value)}"
    return "a string" if isinstance(value, str) else type(value).__name__


def _positive_int(value):
    return isinstance(value, int) and not isinstance(value, bool) and 1 <= value <= 1 << 16


def _read_manifest(root):
    """(path, the JSON object) of ``root/manifest.json``; one-line
    :class:`~pbrkit.core.errors.InputError` naming it when it is missing,
    unreadable, not JSON or not an object."""
    from ..core.errors import InputError

    from ..core.inputs import read_text

    path = root / "manifest.json"
    if not os.path.lexists(path):
        raise InputError("not a bake directory (no manifest.json)", path)
    text = read_text(path, expected="a bake manifest (JSON)")  # a regular file of at most MAX_TEXT_BYTES
    try:
        manifest = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"manifest is not valid JSON ({exc.msg} at line {exc.lineno})", path) from None
    except (ValueError, RecursionError):
        raise InputError("manifest is not valid JSON (nested too deeply or a number too long)", path) from None
    if not isinstance(manifest, dict):
        raise InputError(f"manifest must be a JSON object; got {type(manifest).__name__}", path)
    return path, manifest


def load_bake(out_dir, prefer="exr"):
    """Read a directory written by :func:`write_bake` into a :class:`Bake`.

    ``prefer`` ``"exr"`` reads the float32 face files (exactly what was
    baked); ``"ktx2"`` reads specular.ktx2 / irradiance.ktx2 (float16 or
    B10G11R11, as written).  The SH come from the manifest and the table from
    brdf_lut.npy.  Missing or inconsistent files, and manifests without a key
    they need (``DIR/manifest.json: missing 'outputs'``), raise
    :class:`~pbrkit.core.errors.InputError` (a ValueError) naming the file."""
    from ..core.errors import InputError
    from ..ibl.bake import FORMAT, Bake
    from .images import read_image
    from .ktx2 import read_ktx2
    from .npy_files import read_npy

    root = Path(out_dir)
    if prefer not in ("exr", "ktx2"):
        raise ValueError(f"prefer must be 'exr' or 'ktx2', got {prefer!r}")
    if not root.is_dir():
        raise InputError("not a bake directory (no such directory)" if not root.exists()
                         else "not a bake directory (a file)", root)
    path, manifest = _read_manifest(root)
    if manifest.get("format") != FORMAT:
        raise InputError(f"not a pbrkit bake manifest ('format' is not {FORMAT!r})", path)
    if manifest.get("only_targets") is True:
        raise InputError("an engine-only bake (only_targets): it has no generic files to load; bake without "
                         "--only-target", path)
    levels = _entry(manifest, path, "outputs.specular.levels", _positive_int, "a positive integer")
    size = _entry(manifest, path, "outputs.specular.size", _positive_int, "a positive integer")
    irr_size = _entry(manifest, path, "outputs.irradiance.size", _positive_int, "a positive integer")
    roughness = _entry(manifest, path, "outputs.specular.roughness",
                       lambda r: np.asarray(r, dtype=np.float64).shape == (levels,)
                       and np.all(np.isfinite(np.asarray(r, dtype=np.float64))),
                       f"a list of {levels} finite numbers")
    sh = _entry(manifest, path, "sh", lambda v: np.asarray(v, dtype=np.float64).shape == (9, 3),
                "9 rows of 3 numbers (SH9, RGB)")
    if size >> (levels - 1) < 1:
        raise InputError(f"'outputs.specular.levels' {levels} is too many for size {size}", path)
    if prefer == "exr":
        specular = [np.stack([read_image(root / _face_path("specular", f, m)) for f in range(6)])
                    for m in range(levels)]
        irradiance = np.stack([read_image(root / _face_path("irradiance", f)) for f in range(6)])
    else:
        _, spec_levels, _ = read_ktx2(root / "specular.ktx2")
        _, irr_levels, _ = read_ktx2(root / "irradiance.ktx2")
        specular = [np.ascontiguousarray(level[..., :3]) for level in spec_levels]
        irradiance = np.ascontiguousarray(irr_levels[0][..., :3])
    if len(specular) != levels:
        raise InputError(f"specular chain has {len(specular)} levels, the manifest says {levels}", root)
    for m, level in enumerate(specular):
        n = size >> m
        if level.shape != (6, n, n, 3):
            raise InputError(f"specular level {m} has shape {level.shape}, expected {(6, n, n, 3)}", root)
    if irradiance.shape != (6, irr_size, irr_size, 3):
        raise InputError(f"irradiance has shape {irradiance.shape}, expected {(6, irr_size, irr_size, 3)}", root)
    lut_path = root / "brdf_lut.npy"
    if not os.path.lexists(lut_path):
        raise InputError("missing (the DFG table of the bake)", lut_path)
    lut = read_npy(lut_path, "the bake's DFG table (.npy, N x N x 2)")
    if lut.dtype.kind not in "fiu":
        raise InputError("not a numeric .npy array", lut_path)
    if lut.ndim != 3 or lut.shape[0] != lut.shape[1] or lut.shape[2] not in (2, 3) or lut.shape[0] < 2:
        raise InputError(f"table has shape {lut.shape}, expected (N, N, 2)", lut_path)
    sheen, sheen_roughness, sheen_table = _load_sheen(root, path, manifest)
    return Bake(specular=[np.asarray(s, dtype=np.float32) for s in specular],
                roughness=np.asarray(roughness, dtype=np.float64),
                irradiance=np.asarray(irradiance, dtype=np.float32), sh=np.asarray(sh, dtype=np.float64),
                lut=np.asarray(lut, dtype=np.float32), manifest=manifest, sheen=sheen,
                sheen_roughness=sheen_roughness, sheen_lut=sheen_table)


def _load_sheen(root, path, manifest):
    """The sheen chain (``sheen.ktx2``), its sheen roughness and table (``sheen_lut.npy``)
    of a bake whose manifest names them (``outputs.sheen``), else ([], None, None)
    (a bake written before pbrkit baked sheen).  Inconsistent files raise
    :class:`~pbrkit.core.errors.InputError`."""
    from ..core.errors import InputError
    from .ktx2 import read_ktx2
    from .npy_files import read_npy

    outputs = manifest.get("outputs")
    if not isinstance(outputs, dict) or "sheen" not in outputs:
        return [], None, None
    levels = _entry(manifest, path, "outputs.sheen.levels", _positive_int, "a positive integer")
    size = _entry(manifest, path, "outputs.sheen.size", _positive_int, "a positive integer")
    roughness = _entry(manifest, path, "outputs.sheen.sheen_roughness",
                       lambda r: np.asarray(r, dtype=np.float64).shape == (levels,)
                       and np.all(np.isfinite(np.asarray(r, dtype=np.float64))),
                       f"a list of {levels} finite numbers")
    _, chain, _ = read_ktx2(root / "sheen.ktx2")
    if len(chain) != levels:
        raise InputError(f"has {len(chain)} levels, the manifest says {levels}", root / "sheen.ktx2")
    for m, level in enumerate(chain):
        n = max(1, size >> m)
        if level.shape[:3] != (6, n, n):
            raise InputError(f"level {m} has shape {level.shape}, expected {(6, n, n)}", root / "sheen.ktx2")
    table_path = root / "sheen_lut.npy"
    if not os.path.lexists(table_path):
        raise InputError("missing (the sheen table of the bake)", table_path)
    table = read_npy(table_path, "the bake's sheen table (.npy, N x N x 2)")
    if table.dtype.kind not in "fiu" or table.ndim != 3 or table.shape[0] != table.shape[1] or table.shape[2] != 2:
        raise InputError(f"table has shape {table.shape}, expected (N, N, 2)", table_path)
    return ([np.ascontiguousarray(level[..., :3], dtype=np.float32) for level in chain],
            np.asarray(roughness, dtype=np.float64), np.asarray(table, dtype=np.float32))


def load_target_chain(out_dir, target):
    """The prefiltered chain of an engine target of a bake directory, as that
    engine reads it: a :class:`pbrkit.ibl.bake.Chain` with the texels of the
    target's file (:attr:`pbrkit.engines.Engine.chain_file`: ``filament``
    ``filament/ibl.ktx``, R11F_G11F_B10F; ``three`` ``three/specular.ktx2``; both at
    Filament's levels; ``babylon`` ``babylon/specular.dds``), mirrored back to
    pbrkit's frame where the target is mirrored (:attr:`~pbrkit.engines.Engine.mirror`),
    and the roughness of every level from the manifest.  For rendering as the engine
    does (:func:`pbrkit.rendering.realtime.render_realtime` ``engine``).  Missing or
    inconsistent files raise :class:`~pbrkit.core.errors.InputError`."""
    from ..core.errors import InputError
    from ..ibl.bake import Chain
    from ..ibl.cubemap import mirror_cube
    from .dds import read_dds
    from .ktx1 import read_ktx1
    from .ktx2 import read_ktx2

    chained = {name: e for name, e in ENGINES.items() if e.chain_file is not None}
    if target not in chained:
        raise ValueError(f"no chain reader for target {target!r} ({', '.join(chained)})")
    spec = chained[target]
    root = Path(out_dir)
    path, manifest = _read_manifest(root)
    if target not in (manifest.get("targets") or {}):
        raise InputError(f"the bake has no {target} target (bake it with --target {target})", path)
    roughness = _entry(manifest, path, f"targets.{target}.conventions.roughness",
                       lambda r: np.asarray(r, dtype=np.float64).ndim == 1 and len(r) >= 2,
                       f"a list of roughness values (bake with --target {target})")
    file = root / spec.chain_file
    read = {".ktx": read_ktx1, ".ktx2": read_ktx2, ".dds": read_dds}[file.suffix]
    levels = read(file)[1]
    if spec.mirror is not None:
        levels = [mirror_cube(level, spec.mirror) for level in levels]
    if len(levels) != len(roughness):
        raise InputError(f"has {len(levels)} levels, the manifest's roughness lists {len(roughness)}", file)
    return Chain(spec.curve, [np.ascontiguousarray(level[..., :3], dtype=np.float32) for level in levels],
                 np.asarray(roughness, dtype=np.float64), [])
