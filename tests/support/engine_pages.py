"""Run a page of ``tests/engines/pages`` in headless Chromium with the pinned
engines (``tests/engines/harness.mjs``, puppeteer-core) and return what it reports.

Tests that need it are marked ``@needs_engines()``: they skip, with one reason,
when node, Chromium or the npm packages (``npm ci --prefix tests/engines``, which
``.ci/run`` does) are missing.
"""

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest
from skips import CHROMIUM

ENGINES = Path(__file__).resolve().parents[1] / "engines"
NODE = shutil.which("node")


def engines_missing():
    """Why the engine pages cannot run here, or None."""
    if NODE is None:
        return "needs node (Debian: apt-get install nodejs npm)"
    if CHROMIUM is None:
        return "needs chromium (Debian: apt-get install chromium)"
    if not (ENGINES / "node_modules" / "puppeteer-core").is_dir():
        return "needs the pinned engines: npm ci --prefix tests/engines (as .ci/run does)"
    return None


def needs_engines():
    """Skip marker for tests that open engine pages."""
    reason = engines_missing()
    return pytest.mark.skipif(reason is not None, reason=reason or "")


def page_report(page, data=None, query="", screenshot=None, timeout=240, retries=1):
    """Open ``pages/<page>`` (``data`` served as ``/data``) and return the harness's
    JSON: {"result", "error", "console", "errors"}, whatever the page reported;
    ``retries`` more runs when the harness gives no report at all (a browser that
    failed to start on a loaded machine).  Fails the test when there is none."""
    command = [NODE, str(ENGINES / "harness.mjs"), page, "--timeout", str(timeout)]
    if data is not None:
        command += ["--data", str(Path(data).resolve())]
    if query:
        command += ["--query", query]
    if screenshot is not None:
        command += ["--screenshot", str(Path(screenshot).resolve())]
    env = dict(os.environ, CHROMIUM=CHROMIUM)
    for _attempt in range(1 + int(retries)):
        proc = subprocess.run(command, capture_output=True, text=True, timeout=timeout + 60, env=env, cwd=ENGINES)
        lines = [line for line in proc.stdout.splitlines() if line.startswith("{")]
        if lines:
            return json.loads(lines[-1])
    pytest.fail(f"{page}: no report (exit {proc.returncode}): {proc.stderr.strip()[-2000:]}")


def run_page(page, data=None, query="", screenshot=None, timeout=240):
    """:func:`page_report`, failing the test with the page's error and console
    unless the page reported a result and no error."""
    report = page_report(page, data, query, screenshot, timeout)
    if report.get("error") is not None or report.get("result") is None:
        pytest.fail(f"{page}: {report.get('error')}; errors {report.get('errors')}; "
                    f"console {report.get('console')[-20:]}")
    return report


SMALL_BAKE = ["--size", "16", "--min-size", "4", "--irradiance-size", "8", "--lut-size", "16"]


def bake_target(root, target):
    """``pbrkit bake --target TARGET`` (the CLI) of a small sky (a horizontal
    gradient above a constant ground) into ``root/out``; returns that folder."""
    import numpy as np
    from typer.testing import CliRunner

    from pbrkit.cli import app
    from pbrkit.io.pfm import write_pfm

    h = 16
    sky = np.full((h, 2 * h, 3), 0.5, np.float32)
    sky[: h // 2] += np.linspace(0.2, 1.5, 2 * h, dtype=np.float32)[None, :, None]
    write_pfm(root / "sky.pfm", sky)
    result = CliRunner().invoke(app, ["bake", str(root / "sky.pfm"), "-o", str(root / "out"), *SMALL_BAKE,
                                      "--target", target, "-q"])
    assert result.exit_code == 0, result.output
    return root / "out"
