"""What every ``pbrkit`` command shares on the terminal: the Rich console on
stderr, one-line errors and warnings (:func:`user_errors`), Ctrl-C and SIGTERM
handling, the progress of a command by stage (:class:`_Stages`) and of a batch
by input (:class:`BatchProgress`), and the check for an optional extra
(:func:`need_extra`).

What a user sees:

- every refusal is one line on stderr, ``pbrkit: error: <file>: <problem>``,
  exit status 1 (bad options included), nothing on stdout and no output
  left behind; Ctrl-C gives ``pbrkit: error: interrupted`` (130) and SIGTERM
  ``pbrkit: error: terminated (SIGTERM)`` (143), after the same clean-up;
- progress by stage on stderr: a Rich bar on a terminal, one plain line per
  stage (``pbrkit render: reference (3/4)``) when stderr is not a terminal,
  nothing with ``--quiet``.

This module imports Typer and :mod:`pbrkit.core.errors` only (``pbrkit --help``
stays light); Rich's console is created when first used.
"""

from __future__ import annotations

import contextlib
import functools
import signal
import sys
import time
import warnings

import typer

from ..core.errors import is_library_error as _is_library_error
from ..core.errors import one_line as _one_line

__all__ = ["user_errors", "need_extra", "BatchProgress"]


def _isatty(stream):
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):
        return False


def _console():
    from rich.console import Console

    return Console(stderr=True, soft_wrap=True, highlight=False)


class _StderrConsole:
    """``_err``: a Rich console on stderr, created when first used (``pbrkit --help``
    does not import Rich's console)."""

    def __getattr__(self, name):
        return getattr(_console(), name)


_err = _StderrConsole()


def _say(kind, message, style):
    """One line ``pbrkit: <kind>: <message>`` on stderr (coloured on a terminal)."""
    from rich.text import Text

    _console().print(Text.assemble((f"pbrkit: {kind}:", style), " ", _one_line(message)))


@contextlib.contextmanager
def _interruptible():
    """SIGTERM raises :class:`pbrkit.core.errors.Terminated` (a KeyboardInterrupt) and
    SIGINT KeyboardInterrupt, once each, while a command runs, so that the clean-up
    of partial output runs for both; a second signal during the clean-up is ignored."""
    from ..core.errors import Terminated

    def on_signal(signum, frame):
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, signal.SIG_IGN)
        raise Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()

    try:
        previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    except (ValueError, OSError):  # not the main thread: leave the handlers alone
        yield
        return
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def user_errors(fn):
    """Turn expected failures into one line ``pbrkit: error: ...`` on stderr and an
    exit status: bad input, bad options and I/O (ValueError, OSError, OpenEXR's
    errors; 1), running out of memory (1), Ctrl-C (``interrupted``, 130) and SIGTERM
    (``terminated (SIGTERM)``, 143).  Anything else is a bug and propagates with its
    traceback.  Warnings (UserWarning and its subclasses) are printed as
    ``pbrkit: warning: ...`` lines once the command has succeeded."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        from ..core.errors import Terminated

        code = None
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UserWarning)
            try:
                with _interruptible():
                    result = fn(*args, **kwargs)
            except Terminated:
                _say("error", "terminated (SIGTERM)", "bold red")
                code = 143
            except KeyboardInterrupt:
                _say("error", "interrupted", "bold red")
                code = 130
            except MemoryError as exc:
                _say("error", f"out of memory{f' ({exc})' if str(exc) else ''}; try smaller sizes", "bold red")
                code = 1
            except (ValueError, OSError) as exc:
                _say("error", exc, "bold red")
                code = 1
            except Exception as exc:
                if not _is_library_error(exc):
                    raise
                _say("error", exc, "bold red")
                code = 1
        if code is not None:
            raise typer.Exit(code)
        seen = set()
        for w in caught:
            text = _one_line(w.message)
            if issubclass(w.category, UserWarning) and not issubclass(w.category, DeprecationWarning) \
                    and text not in seen:
                seen.add(text)
                _say("warning", text, "yellow")
        return result

    return wrapper


#: The optional extras of ``pip install "pbrkit[...]"``: extra -> the modules it installs.
EXTRAS = {"explore": ("panel", "bokeh"), "batch": ("dask", "distributed")}


def need_extra(command, extra):
    """Refuse ``command`` (``"pbrkit explore"``) with one line naming the ``pip install`` to
    run when a module of the optional ``extra`` (:data:`EXTRAS`) is not installed; looks
    for the modules without importing them."""
    import importlib.util

    for name in EXTRAS[extra]:
        try:
            found = importlib.util.find_spec(name) is not None
        except (ImportError, ValueError):  # a broken or blocked installation
            found = False
        if not found:
            raise ValueError(f'{command} needs the {extra} extra: pip install "pbrkit[{extra}]"')


# ------------------------------------------------------------- progress


class _Stages:
    """Progress of one command by stage, on stderr: a Rich bar on a terminal
    (transient: it disappears when the command ends), one plain line per stage
    otherwise (``pbrkit render: reference (3/4)``), nothing with ``quiet``.
    :meth:`start` is called as each stage starts.

    The first stage's line waits until that stage has run for
    :data:`FIRST_LINE_DELAY` seconds or the next one starts, and is dropped if
    the command fails before: bad input, found while loading it, is then
    refused with its one error line alone."""

    FIRST_LINE_DELAY = 1.0

    def __init__(self, command, quiet, total):
        self.command = command
        self.total = max(1, int(total))
        self.number = 0
        self.mode = "off" if quiet else ("bar" if _isatty(sys.stderr) else "lines")
        self._bar = None
        self._task = None
        self._pending = None
        self._timer = None
        self._lock = None
        self._fd = None

    def __enter__(self):
        if self.mode == "bar":
            from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

            self._bar = Progress(TextColumn(f"pbrkit {self.command}: " + "{task.description}"), BarColumn(),
                                 TextColumn("{task.completed}/{task.total}"), TimeElapsedColumn(),
                                 console=_console(), transient=True)
            self._bar.start()
            self._task = self._bar.add_task("starting", total=self.total)
        elif self.mode == "lines":
            import os
            import threading

            self._lock = threading.Lock()
            try:  # lines go to the real stderr even while a native library's output is captured
                self._fd = os.dup(sys.stderr.fileno())
            except (AttributeError, ValueError, OSError):  # not a file (e.g. a test runner's buffer)
                self._fd = None
        return self

    def __exit__(self, exc_type, exc, tb):
        if self._bar is not None:
            self._bar.stop()
        if self._lock is not None:
            if self._timer is not None:
                self._timer.cancel()
            with self._lock:
                if exc_type is None:
                    self._print_pending()
                self._pending = None
                if self._fd is not None:
                    import os

                    os.close(self._fd)
                    self._fd = None
        return False

    def _write(self, line):
        if self._fd is None:
            print(line, file=sys.stderr, flush=True)
            return
        import os

        with contextlib.suppress(Exception):
            sys.stderr.flush()
        with contextlib.suppress(OSError):
            os.write(self._fd, (line + "\n").encode("utf-8", errors="replace"))

    def _print_pending(self):
        if self._pending is not None:
            self._write(self._pending)
            self._pending = None

    def _timed_out(self):
        with self._lock:
            self._print_pending()

    def start(self, name, number=None, total=None):
        """Stage ``name`` starts: ``number`` (from 1; counted here if None) of ``total``."""
        first = self.number == 0
        self.number = self.number + 1 if number is None else int(number)
        if total is not None:
            self.total = int(total)
        self.total = max(self.total, self.number)
        if self.mode == "lines":
            import threading

            line = f"pbrkit {self.command}: {name} ({self.number}/{self.total})"
            with self._lock:
                self._print_pending()
                if first:
                    self._pending = line
                    self._timer = threading.Timer(self.FIRST_LINE_DELAY, self._timed_out)
                    self._timer.daemon = True
                    self._timer.start()
                else:
                    self._write(line)
        elif self._bar is not None:
            self._bar.update(self._task, description=str(name), completed=self.number - 1, total=self.total)


class BatchProgress:
    """Progress of a batch on stderr: a Rich bar over the inputs (count, failures,
    elapsed time and ETA) on a terminal, one line per finished input otherwise
    (``pbrkit batch bake: sky done in 1.23 s (3/8, 0 failed, ETA 0:00:12)``),
    nothing with ``quiet``.  :meth:`note` prints a line (the cluster, the
    dashboard address) above the bar."""

    def __init__(self, command, total, quiet):
        self.command = command
        self.total = int(total)
        self.mode = "off" if quiet else ("bar" if _isatty(sys.stderr) else "lines")
        self.done = self.failed = 0
        self._bar = self._task = None
        self._t0 = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self._bar is not None:
            self._bar.stop()
        return False

    def note(self, text):
        if self.mode == "off":
            return
        from rich.markup import escape

        (self._bar.console if self._bar is not None else _console()).print(
            f"pbrkit {self.command}: {escape(str(text))}", highlight=False, soft_wrap=True)

    def start(self):
        """The tasks are submitted: the clock of the ETA starts."""
        self._t0 = time.perf_counter()
        if self.mode == "bar":
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )

            self._bar = Progress(TextColumn(f"pbrkit {self.command}"), BarColumn(), MofNCompleteColumn(),
                                 TextColumn("{task.fields[failed]} failed"), TimeElapsedColumn(),
                                 TextColumn("ETA"), TimeRemainingColumn(), console=_console(), transient=True)
            self._bar.start()
            self._task = self._bar.add_task("", total=self.total, failed=0)

    def _eta(self):
        finished = self.done
        if not finished or self._t0 is None:
            return "?"
        seconds = (time.perf_counter() - self._t0) / finished * (self.total - finished)
        return time.strftime("%H:%M:%S", time.gmtime(round(seconds)))

    def finished(self, outcome):
        self.done += 1
        self.failed += outcome["status"] == "failed"
        if self._bar is not None:
            self._bar.update(self._task, completed=self.done, failed=self.failed)
        elif self.mode == "lines":
            what = {"done": f"done in {outcome.get('seconds', 0.0):.2f} s", "skipped": "skipped (up to date)",
                    "failed": f"failed: {outcome.get('error')}"}[outcome["status"]]
            print(_one_line(f"pbrkit {self.command}: {outcome['name']} {what} ({self.done}/{self.total}, "
                            f"{self.failed} failed, ETA {self._eta()})"), file=sys.stderr, flush=True)
