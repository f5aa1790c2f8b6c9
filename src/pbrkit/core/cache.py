"""pbrkit's disk cache, without importing Numba: where it lives, the hash of the
sources that keys it, and memoised arrays.

The directory is ``$PBRKIT_CACHE_DIR`` if set, else ``$NUMBA_CACHE_DIR/pbrkit``,
else ``$XDG_CACHE_HOME/pbrkit`` (``~/.cache/pbrkit``), with a subdirectory
``numba-<version>-<hash>`` per version and sources (:func:`cache_directory`):
editing any pbrkit module starts a fresh cache.  It holds the compiled kernels
(:mod:`pbrkit.core.jit`) and, under ``results/``, arrays that are costly to
compute and depend only on their options and pbrkit's sources, such as the
lookup tables (:func:`memoised_array`), so that a second ``pbrkit lut`` with the
same options reads the table instead of importing Numba and integrating again.
``PBRKIT_NO_RESULT_CACHE=1`` (or ``memoised_array(..., enabled=False)``) turns
the result cache off.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import secrets
from pathlib import Path

import numpy as np

__all__ = ["source_hash", "cache_directory", "cached_kernels", "env_flag", "memoised_array"]

_PACKAGE_ROOT = Path(__file__).resolve().parent.parent


@functools.lru_cache(maxsize=4)
def source_hash(root=_PACKAGE_ROOT):
    """SHA-256 (hex) of every ``.py`` file under ``root`` (default: the package), in
    sorted path order (relative path and content both hashed)."""
    root = Path(root)
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(b"\0")
        digest.update(path.read_bytes())
        digest.update(b"\0")
    return digest.hexdigest()


@functools.lru_cache(maxsize=1)
def cache_directory():
    """Where pbrkit's compiled kernels and memoised results are cached (module docstring)."""
    base = os.environ.get("PBRKIT_CACHE_DIR")
    if not base and os.environ.get("NUMBA_CACHE_DIR"):
        base = os.path.join(os.environ["NUMBA_CACHE_DIR"], "pbrkit")
    if not base:
        base = os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.join(Path.home(), ".cache"), "pbrkit")
    from .. import __version__  # set before any submodule is imported

    return os.path.join(base, f"numba-{__version__}-{source_hash()[:16]}")


def cached_kernels(subpackage, name="*"):
    """Whether the kernel cache holds compiled kernels of ``subpackage`` (``rendering``,
    ``ibl``, ...: one cache folder per source folder, :mod:`pbrkit.core.jit`) whose
    index file matches ``name`` (``<module>.<function>-<line>``; default any)."""
    folder = Path(cache_directory()) / subpackage
    return folder.is_dir() and any(folder.glob(f"{name}.nbi"))


def env_flag(name):
    """Whether the environment variable ``name`` is set to anything but empty or ``0``."""
    return os.environ.get(name, "") not in ("", "0")


def _result_path(namespace, options):
    key = hashlib.sha256(json.dumps([namespace, options], sort_keys=True).encode()).hexdigest()[:32]
    return Path(cache_directory()) / "results" / f"{namespace}-{key}.npy"


def memoised_array(namespace, options, compute, check=None, enabled=True):
    """``compute()`` (an array), memoised on disk under ``namespace`` and the JSON-able
    ``options`` (with :func:`cache_directory`, which follows pbrkit's sources and
    version).  A cached file that cannot be read, or that ``check(array)`` rejects, is
    computed again and replaced.  Writing is atomic (a temporary name, then a rename)
    and best effort: a read-only or full cache directory only costs the computation.
    The result is the same bytes either way."""
    if not enabled or env_flag("PBRKIT_NO_RESULT_CACHE"):
        return compute()
    path = _result_path(namespace, options)
    try:
        array = np.load(path, allow_pickle=False)
        if check is None or check(array):
            return array
    except (OSError, ValueError, EOFError):
        pass
    array = compute()
    tmp = path.with_name(f".{path.name}.{secrets.token_hex(4)}.tmp")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(tmp, "wb") as f:
            np.save(f, np.ascontiguousarray(array), allow_pickle=False)
        os.replace(tmp, path)
    except OSError:
        try:
            tmp.unlink()
        except OSError:
            pass
    return array
