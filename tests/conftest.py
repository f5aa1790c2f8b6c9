"""The suite's hooks: a report that keeps the ``slow`` marker meaningful.

Shared test helpers live in tests/support (on the path through pyproject.toml's
``[tool.pytest.ini_options] pythonpath``): the skip reasons in ``skips.py``
(``from skips import needs_shared_data``), the independent references and the
engine harness beside them.

``-m 'not slow'`` is the quick run (pyproject.toml).

After a run, the terminal summary lists the tests that took over
UNMARKED_LIMIT seconds (setup + call + teardown) without ``@pytest.mark.slow``
-- candidates for the marker, since they make the quick run slow -- and those
marked slow that took under MARKED_MINIMUM.  It only reports (timings depend on
the machine, its load and Numba's cache), it never fails a run.
"""

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
