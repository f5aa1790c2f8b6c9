"""Atomic file output: write to a temporary file in the destination folder, then rename.

A failed or interrupted command therefore never leaves a partial file behind.
Outputs that belong together (a bake's files) are written into a temporary
directory that is renamed into place at the end (:func:`atomic_directory`).
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from pathlib import Path

__all__ = ["atomic_path", "atomic_directory", "check_output_directory", "current_umask", "write_bytes",
           "write_text"]


@contextlib.contextmanager
def atomic_path(path, suffix=None):
    """Yield a temporary path beside ``path``; on success it replaces ``path``.

    ``suffix`` defaults to the destination's suffix so libraries that choose
    the format by extension (matplotlib, imageio) keep working.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix if suffix is not None else path.suffix,
                               dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~current_umask())  # mkstemp creates 0600; give the usual permissions
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def current_umask():
    """The process's file-mode creation mask (read by setting and restoring it)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


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
    succeeded.  Any failure removes it and the parent directories this call
    created, so nothing remains.  An existing non-empty ``path`` is refused
    (ValueError, :func:`check_output_directory`, before anything is created)
    unless ``force``, which replaces it (the old directory is moved aside
    and removed after the rename)."""
    out = check_output_directory(path, force)
    parent = out.absolute().parent
    created = []
    probe = parent
    while not probe.exists():
        created.append(probe)
        probe = probe.parent
    parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".partial", dir=parent))
    try:
        os.chmod(tmp, 0o777 & ~current_umask())  # mkdtemp creates 0700; give the usual permissions
        yield tmp
        if out.exists() or out.is_symlink():
            old = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".old", dir=parent))
            os.rmdir(old)
            os.rename(out, old)
            os.rename(tmp, out)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.rename(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        for created_dir in created:  # deepest first
            with contextlib.suppress(OSError):
                created_dir.rmdir()
        raise


def write_bytes(path, data: bytes):
    """Atomically write ``data`` to ``path``."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def write_text(path, text: str):
    """Atomically write ``text`` (UTF-8) to ``path``."""
    write_bytes(path, text.encode("utf-8"))
