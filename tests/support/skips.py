"""Shared test helper: the skip reasons, worded once.

A test that needs the shared test data beside the checkout (``../shared``) is marked
``@needs_shared_data("env/x.hdr")`` (or skips at run time with
``pytest.skip(shared_data_reason("env/x.hdr"))``), one that needs headless Chromium
``@needs_chromium()``; every such skip then reads the same way, e.g. ``needs
../shared/data/env/x.hdr (shared test data, present in CI beside the checkout)``.
"""

import shutil
from pathlib import Path

import pytest

#: ``../shared`` beside the checkout: the project's contract and test data (present in CI).
SHARED = Path(__file__).resolve().parents[3] / "shared"
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
