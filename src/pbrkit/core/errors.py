"""Exceptions for bad input.

:class:`InputError` is a :class:`ValueError` whose message is a single line
``"<file>: <problem>"`` (or just ``"<problem>"`` when no file is involved), so a
command-line front end can print it as it is.
"""

from __future__ import annotations

__all__ = ["InputError"]


class InputError(ValueError):
    """A file or array that cannot be used as input, with a one-line message.

    ``path`` is the offending file (or None) and ``problem`` the description;
    ``str(error)`` is ``"path: problem"``.  Line breaks in ``problem`` are
    folded into spaces so the message always fits on one line.
    """

    def __init__(self, problem, path=None):
        self.path = None if path is None else str(path)
        self.problem = " ".join(str(problem).split())
        super().__init__(self.problem if self.path is None else f"{self.path}: {self.problem}")

    def __reduce__(self):  # keep pickling (multiprocessing) working with two arguments
        return (type(self), (self.problem, self.path))
