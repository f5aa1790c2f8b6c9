"""Keeping native libraries quiet: what C/C++ code prints on the process's
standard output and error (OpenEXR's ``EXR_ERR_...`` lines and warnings)
bypasses Python's ``sys.stdout``/``sys.stderr``; :func:`captured_native_output`
redirects file descriptors 1 and 2 to a temporary file around such calls,
so that what the library said can become part of a one-line error instead of
noise before it.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import sys
import tempfile

__all__ = ["captured_native_output"]

_ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")
_LIMIT = 1 << 16


class Captured:
    """What was printed during the block: ``lines`` (non-empty, stripped, ANSI
    codes removed; filled in when the block ends)."""

    def __init__(self):
        self.lines = []

    def summary(self, default=""):
        """The most telling line: OpenEXR's "Exception raised ... - REASON" reason, else the last line."""
        for line in self.lines:
            if " - " in line and "exception" in line.lower():
                return line.rsplit(" - ", 1)[1].strip()
        return self.lines[-1] if self.lines else default


def _flush_c_stdio():
    try:
        import ctypes

        ctypes.CDLL(None).fflush(None)  # C stdio buffers (std::cout is synced with them)
    except Exception:  # pragma: no cover - no C library to call (unusual platforms)
        pass


def _flush_python():
    for stream in (sys.stdout, sys.stderr, sys.__stdout__, sys.__stderr__):
        with contextlib.suppress(Exception):
            stream.flush()


@contextlib.contextmanager
def captured_native_output():
    """Redirect file descriptors 1 and 2 to a temporary file while the block
    runs, and ``sys.stdout``/``sys.stderr`` to a buffer (libraries that print
    through Python, such as pybind11's ``py::print``, write there when the
    streams are not the process's own, e.g. under a test runner); yields a
    :class:`Captured` whose ``lines`` hold what was written once the block has
    ended (also when it raised).  Where the descriptors cannot be duplicated,
    only the Python-level streams are redirected."""
    captured = Captured()
    python_level = io.StringIO()  # what the library prints through Python (pybind11's py::print)
    _flush_python()
    try:
        saved = (os.dup(1), os.dup(2))
    except OSError:  # closed descriptors: only Python-level output to catch
        saved = None
    sink = tempfile.TemporaryFile() if saved is not None else None
    try:
        try:
            if saved is not None:
                os.dup2(sink.fileno(), 1)
                os.dup2(sink.fileno(), 2)
            with contextlib.redirect_stdout(python_level), contextlib.redirect_stderr(python_level):
                yield captured
        finally:
            text = python_level.getvalue()
            if saved is not None:
                _flush_python()
                _flush_c_stdio()
                os.dup2(saved[0], 1)
                os.dup2(saved[1], 2)
                sink.seek(0)
                text += sink.read(_LIMIT).decode("utf-8", errors="replace")
            captured.lines = [" ".join(_ANSI.sub("", line).split()) for line in text.splitlines()]
            captured.lines = [line for line in captured.lines if line]
    finally:
        if saved is not None:
            os.close(saved[0])
            os.close(saved[1])
            sink.close()
