"""Atomic file output: write to a temporary file in the destination folder, then rename.

A failed or interrupted command therefore never leaves a partial file behind.
Outputs that belong together are committed together: several files with
:func:`atomic_group` (an image and its standard-error map, a table and its
JSON description), a folder of files with :func:`atomic_directory` (a bake).

Failures while writing become one-line errors that name the file the caller
asked for, never the temporary it was being written to: an :class:`OSError`
(a full disk, a read-only folder, a directory in the way) raised inside the
block becomes :class:`pbrkit.core.errors.OutputError` ``"out.exr: cannot
write: [Errno 28] No space left on device"``, and temporary names in other
:class:`ValueError` / :class:`OSError` messages are replaced by the requested
ones.  Folders created for an output are removed again when it fails.
"""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
import shutil
import tempfile
from pathlib import Path

from .errors import InputError, OutputError

__all__ = ["atomic_path", "atomic_group", "atomic_directory", "check_output_directory", "current_umask",
           "write_bytes", "write_text", "write_files"]


# ------------------------------------------------------------------ helpers


def current_umask():
    """The process's file-mode creation mask (read by setting and restoring it)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _make_parent(path):
    """Create the folder of ``path`` (and its missing parents); return the
    folders created, deepest first, for :func:`_remove_dirs`."""
    parent = Path(path).absolute().parent
    created = []
    probe = parent
    while not (probe.exists() or probe.is_symlink()) and probe != probe.parent:
        created.append(probe)
        probe = probe.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        _remove_dirs(created)
        if isinstance(exc, FileExistsError) or exc.errno == errno.ENOTDIR:
            raise OutputError(f"cannot create its folder: {probe} is not a directory", path, exc.errno) from None
        raise OutputError.from_os_error(exc, path, "cannot create its folder") from None
    return created


def _remove_dirs(created):
    for folder in sorted(created, key=lambda p: len(p.parts), reverse=True):  # deepest first
        with contextlib.suppress(OSError):
            folder.rmdir()


def _temporary_prefix(path):
    return f".{Path(path).name[:96]}."  # stays within NAME_MAX with the random part and suffix


def _rename_map(mapping):
    """[(temporary, requested)] as strings, both as given and absolute, longest first."""
    pairs = {}
    for tmp, final in mapping.items():
        pairs[str(tmp)] = str(final)
        pairs.setdefault(str(Path(tmp).absolute()), str(Path(final).absolute()))
    return sorted(pairs.items(), key=lambda kv: len(kv[0]), reverse=True)


def _rename_text(text, pairs):
    for tmp, final in pairs:
        text = text.replace(tmp, final)
    return text


def _requested_errors(exc, mapping, default):
    """The exception to raise for ``exc``, raised while writing the temporaries
    of ``mapping`` (temporary -> requested path): temporary names replaced by
    the requested ones; a plain :class:`OSError` becomes an
    :class:`OutputError` naming the requested file (its own file name if that
    is one of ours, else ``default``).  Anything else is returned unchanged."""
    pairs = _rename_map(mapping)
    if isinstance(exc, (OutputError, InputError)):
        path = exc.path if exc.path is None else _rename_text(exc.path, pairs)
        problem = _rename_text(exc.problem, pairs)
        if path == exc.path and problem == exc.problem:
            return exc
        if isinstance(exc, OutputError):
            return type(exc)(problem, path, exc.errno)
        return type(exc)(problem, path)
    if isinstance(exc, OSError):
        name = getattr(exc, "filename", None)
        target = default
        if isinstance(name, (str, bytes, os.PathLike)):
            renamed = _rename_text(os.fsdecode(name), pairs)
            if renamed != os.fsdecode(name):
                target = renamed
        return OutputError.from_os_error(exc, target)
    if isinstance(exc, ValueError):
        text = str(exc)
        renamed = _rename_text(text, pairs)
        if renamed != text:
            return ValueError(renamed)
    return exc


def _reraise(exc, mapping, default):
    new = _requested_errors(exc, mapping, default)
    if new is exc:
        raise exc
    raise new from None


# ------------------------------------------------------------------ one file


@contextlib.contextmanager
def atomic_path(path, suffix=None):
    """Yield a temporary path beside ``path``; on success it replaces ``path``.

    ``suffix`` defaults to the destination's suffix so libraries that choose
    the format by extension (matplotlib, imageio) keep working.  On failure
    the temporary (and any folder created for ``path``) is removed and
    errors name ``path`` (module doc).
    """
    path = Path(path)
    created = _make_parent(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=_temporary_prefix(path),
                                   suffix=suffix if suffix is not None else path.suffix, dir=path.parent)
    except OSError as exc:
        _remove_dirs(created)
        raise OutputError.from_os_error(exc, path) from None
    os.close(fd)
    tmp = Path(tmp)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~current_umask())  # mkstemp creates 0600; give the usual permissions
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        _remove_dirs(created)
        _reraise(exc, {tmp: path}, path)


# ---------------------------------------------------------- several files


def _unique_beside(path, tag):
    return path.with_name(f"{_temporary_prefix(path)}{secrets.token_hex(6)}.{tag}")


def _set_aside(path):
    """Keep the current ``path`` (a file or link) under a hidden name beside it
    (a hard link where the file system allows, so ``path`` never disappears;
    else a rename); None if there is nothing to keep."""
    if not (path.exists() or path.is_symlink()) or (path.is_dir() and not path.is_symlink()):
        return None  # absent, or a folder (the rename will refuse it)
    while True:
        backup = _unique_beside(path, "old")
        try:
            os.link(path, backup, follow_symlinks=False)
            return backup
        except FileExistsError:
            continue
        except OSError:
            os.rename(path, backup)
            return backup


def _commit(temps, paths):
    """Rename every temporary onto its path; if one fails, undo those done
    (earlier contents restored, new files removed) and raise."""
    mode = 0o666 & ~current_umask()
    done = []  # (path, backup or None), renamed into place
    try:
        for tmp, path in zip(temps, paths):
            os.chmod(tmp, mode)
            backup = _set_aside(path)
            try:
                os.replace(tmp, path)
            except BaseException:
                if backup is not None:
                    os.replace(backup, path)
                raise
            done.append((path, backup))
    except BaseException:
        for path, backup in reversed(done):
            with contextlib.suppress(OSError):
                if backup is None:
                    os.unlink(path)
                else:
                    os.replace(backup, path)
        raise
    for _, backup in done:
        if backup is not None:
            with contextlib.suppress(OSError):
                os.unlink(backup)


@contextlib.contextmanager
def atomic_group(paths):
    """Write several files that belong together: all of them or none.

    Yields a list of temporary paths, one beside each of ``paths`` (in the
    same folder, with the same suffix, so writers that choose the format by
    suffix keep working); write each output to its temporary.  When the
    block succeeds every temporary is renamed onto its path; if the block
    fails or is interrupted (Ctrl-C, SIGTERM through the command line), or a
    rename fails, every temporary is removed, the files already renamed are
    put back as they were (new ones removed, replaced ones restored) and
    folders created for the outputs are removed, so either every path holds
    its new content or every path is as before.  Errors name the requested
    paths, not the temporaries (module doc)::

        with atomic_group([image_path, stderr_path]) as (image_tmp, stderr_tmp):
            write_exr(image_tmp, image)
            write_exr(stderr_tmp, stderr)

    The writers may themselves be atomic (:func:`atomic_path`, e.g.
    :func:`pbrkit.io.exr.write_exr`): they then write a temporary of the
    temporary, which costs nothing but a rename.  Readers see the files
    change one after the other (a rename per file), not in one instant.
    """
    paths = [Path(p) for p in paths]
    if len({str(p.absolute()) for p in paths}) != len(paths):
        raise ValueError(f"atomic_group: the same path is given twice in {[str(p) for p in paths]}")
    created, temps = [], []

    def clean():
        for tmp in temps:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        _remove_dirs(created)

    for path in paths:
        try:
            created += _make_parent(path)
            fd, tmp = tempfile.mkstemp(prefix=_temporary_prefix(path), suffix=path.suffix, dir=path.parent)
        except BaseException as exc:
            clean()
            _reraise(exc, {}, path)
        os.close(fd)
        temps.append(Path(tmp))
    try:
        yield list(temps)
        _commit(temps, paths)
    except BaseException as exc:
        clean()
        _reraise(exc, dict(zip(temps, paths)), paths[0])


# -------------------------------------------------------------- a folder


def check_output_directory(path, force=False):
    """``Path(path)`` if it is absent, an empty directory, or (with ``force``)
    any directory; else ValueError."""
    out = Path(path)
    if out.exists() or out.is_symlink():
        if not out.is_dir():
            raise ValueError(f"{out}: exists and is not a directory")
        if not force and any(out.iterdir()):
            raise ValueError(f"{out}: directory exists and is not empty (use --force to replace it)")
    return out


@contextlib.contextmanager
def atomic_directory(path, force=False):
    """Yield a temporary directory beside ``path``; on success it replaces ``path``.

    Outputs that belong together are committed together: the files are
    written into a temporary directory (``.{name}.*.partial``) in the
    destination's parent, which is renamed to ``path`` only when the body
    succeeded.  Any failure or interruption removes it and the parent
    directories this call created, so nothing remains; errors name files
    under ``path``, not under the temporary directory.

    An existing non-empty ``path`` is refused (ValueError,
    :func:`check_output_directory`, before anything is created) unless
    ``force``, which replaces it (the old directory is moved aside and
    removed after the rename).  Without ``force`` the check is repeated by
    the final rename itself, atomically: ``rename(2)`` replaces an absent or
    empty directory and fails on a non-empty one, so when two processes
    write the same empty ``path`` at once, the second fails
    (:class:`pbrkit.core.errors.OutputError`) instead of replacing the first
    one's output."""
    out = check_output_directory(path, force)
    created = _make_parent(out)
    parent = out.absolute().parent
    try:
        tmp = Path(tempfile.mkdtemp(prefix=_temporary_prefix(out), suffix=".partial", dir=parent))
    except OSError as exc:
        _remove_dirs(created)
        raise OutputError.from_os_error(exc, out) from None
    try:
        os.chmod(tmp, 0o777 & ~current_umask())  # mkdtemp creates 0700; give the usual permissions
        yield tmp
        if out.is_symlink() or (force and out.exists()):
            old = Path(tempfile.mkdtemp(prefix=_temporary_prefix(out), suffix=".old", dir=parent))
            os.rmdir(old)
            os.rename(out, old)
            try:
                os.rename(tmp, out)
            except BaseException:
                os.rename(old, out)
                raise
            shutil.rmtree(old, ignore_errors=True)
        else:
            try:
                os.rename(tmp, out)  # replaces an absent or empty directory, fails on anything else
            except OSError as exc:
                if exc.errno in (errno.ENOTEMPTY, errno.EEXIST):
                    raise OutputError("directory is no longer empty (written by another process meanwhile); "
                                      "nothing written", out, exc.errno) from None
                if exc.errno == errno.ENOTDIR:
                    raise OutputError("exists and is not a directory (created by another process meanwhile); "
                                      "nothing written", out, exc.errno) from None
                raise
    except BaseException as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        _remove_dirs(created)
        _reraise(exc, {tmp: out}, out)


# ------------------------------------------------------------- shortcuts


def write_bytes(path, data: bytes):
    """Atomically write ``data`` to ``path``."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def write_text(path, text: str):
    """Atomically write ``text`` (UTF-8) to ``path``."""
    write_bytes(path, text.encode("utf-8"))


def write_files(out_dir, files):
    """Write ``files`` ({name: bytes}, names relative to ``out_dir``) together:
    all of them or none (:func:`pbrkit.core.atomic.atomic_group`; the folder is
    created if needed and removed again on failure).  Returns the paths written."""
    out_dir = Path(out_dir)
    paths = [out_dir / name for name in files]
    with atomic_group(paths) as temps:
        for path, tmp, data in zip(paths, temps, files.values()):
            try:
                with open(tmp, "wb") as f:
                    f.write(data)
            except OSError as exc:  # a failed write() names no file: name the one asked for
                raise OutputError.from_os_error(exc, path) from None
    return paths
