"""Shared test helpers, and a report that keeps the ``slow`` marker meaningful.

Skip reasons are worded here, once: a test that needs the shared test data
beside the checkout (``../shared``) is marked ``@needs_shared_data("env/x.hdr")``
(or skips at run time with ``pytest.skip(shared_data_reason("env/x.hdr"))``), one
that needs headless Chromium ``@needs_chromium()``; every such skip then reads
the same way, e.g. ``needs ../shared/data/env/x.hdr (shared test data, present
in CI beside the checkout)``.

``-m 'not slow'`` is the quick run (pyproject.toml).

After a run, the terminal summary lists the tests that took over
UNMARKED_LIMIT seconds (setup + call + teardown) without ``@pytest.mark.slow``
-- candidates for the marker, since they make the quick run slow -- and those
marked slow that took under MARKED_MINIMUM.  It only reports (timings depend on
the machine, its load and Numba's cache), it never fails a run.
"""

import shutil
from pathlib import Path

import pytest

#: ``../shared`` beside the checkout: the project's contract and test data (present in CI).
SHARED = Path(__file__).resolve().parents[2] / "shared"
SHARED_DATA = SHARED / "data"
#: The headless browser of the demo-page test, or None.
CHROMIUM = shutil.which("chromium") or ("/usr/bin/chromium" if Path("/usr/bin/chromium").exists() else None)


def shared_reason(relative, what="shared test data"):
    """The one wording of a skip for a missing ``../shared/<relative>``."""
    return f"needs ../shared/{relative} ({what}, present in CI beside the checkout)"


def shared_data_reason(relative):
    """The skip reason for a missing ``../shared/data/<relative>``."""
    return shared_reason(f"data/{relative}")


def needs_shared(relative, what="shared test data"):
    """Skip marker: the test needs ``../shared/<relative>`` (file or folder)."""
    return pytest.mark.skipif(not (SHARED / relative).exists(), reason=shared_reason(relative, what))


def needs_shared_data(relative):
    """Skip marker: the test needs ``../shared/data/<relative>`` (file or folder)."""
    return pytest.mark.skipif(not (SHARED_DATA / relative).exists(), reason=shared_data_reason(relative))


def needs_chromium():
    """Skip marker: the test needs headless Chromium (``chromium`` on the PATH or /usr/bin/chromium)."""
    return pytest.mark.skipif(CHROMIUM is None, reason="needs chromium (headless browser for the demo page; "
                                                       "Debian: apt-get install chromium)")


UNMARKED_LIMIT = 5.0
MARKED_MINIMUM = 0.5

_durations = {}


def pytest_runtest_logreport(report):
    total, slow = _durations.get(report.nodeid, (0.0, False))
    _durations[report.nodeid] = (total + report.duration, slow or "slow" in report.keywords)


def pytest_terminal_summary(terminalreporter):
    unmarked = sorted(((t, n) for n, (t, slow) in _durations.items() if not slow and t > UNMARKED_LIMIT), reverse=True)
    marked = sorted((t, n) for n, (t, slow) in _durations.items() if slow and t < MARKED_MINIMUM)
    if unmarked:
        terminalreporter.write_sep("-", f"over {UNMARKED_LIMIT:g} s without @pytest.mark.slow")
        for t, n in unmarked:
            terminalreporter.write_line(f"{t:7.2f}s {n}")
    if marked:
        terminalreporter.write_sep("-", f"marked slow, under {MARKED_MINIMUM:g} s")
        for t, n in marked:
            terminalreporter.write_line(f"{t:7.2f}s {n}")
