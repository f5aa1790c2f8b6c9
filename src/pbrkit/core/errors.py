"""Exceptions for bad input, failed output and interruptions.

:class:`InputError` is a :class:`ValueError` whose message is a single line
``"<file>: <problem>"`` (or just ``"<problem>"`` when no file is involved), so a
command-line front end can print it as it is.  :class:`OutputError` is its
counterpart for files that cannot be written: an :class:`OSError` (keeping
the ``errno``, e.g. ``ENOSPC``) whose message names the file the caller asked
for, never the temporary file it was being written to.  :class:`Terminated`
is what the command line raises on SIGTERM so that the same clean-up runs as
for Ctrl-C (:class:`KeyboardInterrupt`).
"""

from __future__ import annotations

import errno as _errno

__all__ = ["InputError", "OutputError", "Terminated", "one_line", "is_library_error"]


def one_line(text):
    """``text`` with every run of whitespace (line breaks included) folded into one space."""
    return " ".join(str(text).split())


def is_library_error(exc):
    """Whether ``exc`` is an exception of an image library (OpenEXR's) that means bad
    input or a failed write, not a bug: the command line and the batch tasks report
    it as one line, like a :class:`ValueError` or :class:`OSError`."""
    return type(exc).__module__.split(".")[0] in ("OpenEXR",)


class InputError(ValueError):
    """A file or array that cannot be used as input, with a one-line message.

    ``path`` is the offending file (or None) and ``problem`` the description;
    ``str(error)`` is ``"path: problem"``.  Line breaks in ``problem`` are
    folded into spaces so the message always fits on one line.
    """

    def __init__(self, problem, path=None):
        self.path = None if path is None else str(path)
        self.problem = one_line(problem)
        super().__init__(self.problem if self.path is None else f"{self.path}: {self.problem}")

    def __reduce__(self):  # keep pickling (multiprocessing) working with two arguments
        return (type(self), (self.problem, self.path))


class OutputError(OSError):
    """A file that could not be written, with a one-line message naming it.

    ``str(error)`` is ``"path: problem"``; ``errno`` is kept from the
    underlying :class:`OSError` (``errno.ENOSPC`` for a full disk).  Built by
    :meth:`from_os_error` as ``"out.exr: cannot write: [Errno 28] No space
    left on device"``."""

    def __init__(self, problem, path=None, errno=None):
        self.path = None if path is None else str(path)
        self.problem = one_line(problem)
        super().__init__(self.problem if self.path is None else f"{self.path}: {self.problem}")
        self.errno = errno

    def __reduce__(self):
        return (type(self), (self.problem, self.path, self.errno))

    @classmethod
    def from_os_error(cls, exc, path, action="cannot write"):
        """``path: cannot write: [Errno N] strerror`` from an :class:`OSError`
        (whose own file name, often a temporary one, is dropped)."""
        code = getattr(exc, "errno", None)
        reason = getattr(exc, "strerror", None) or one_line(exc) or type(exc).__name__
        if code is not None:
            reason = f"[Errno {code}] {reason}"
        return cls(f"{action}: {reason}", path, code)

    @classmethod
    def from_library_error(cls, exc, path, action="cannot write"):
        """The same for a library's own exception (e.g. OpenEXR's RuntimeError):
        ``ENOSPC`` is recognised in its message."""
        text = one_line(exc) or type(exc).__name__
        code = _errno.ENOSPC if "no space left" in text.lower() else None
        return cls(f"{action}: {text}", path, code)


class Terminated(KeyboardInterrupt):
    """SIGTERM arrived while a command ran (raised by the command line's signal
    handler; a :class:`KeyboardInterrupt`, so every clean-up path that handles
    Ctrl-C handles it too)."""
