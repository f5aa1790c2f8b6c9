"""``pbrkit demo``: the page is self-contained, every image loads in a real browser
(headless Chromium) without console errors, and the numbers are there."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

CHROMIUM = shutil.which("chromium") or ("/usr/bin/chromium" if Path("/usr/bin/chromium").exists() else None)
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync", "--no-first-run"]


class _Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.images, self.links, self.scripts = [], [], 0

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "img":
            self.images.append(attrs.get("src"))
        elif tag == "a":
            self.links.append(attrs.get("href"))
        elif tag == "script":
            self.scripts += 1


@pytest.fixture(scope="module")
def demo_dir(tmp_path_factory):
    from typer.testing import CliRunner

    from pbrkit.app.cli import app

    out = tmp_path_factory.mktemp("demo") / "site"
    # the demo's CLI with small sizes (the defaults take ~20 s on 2 cores)
    result = CliRunner().invoke(app, ["demo", "-o", str(out), "--size", "56", "--spp", "8", "--bake-size", "32",
                                      "--quiet"])
    assert result.exit_code == 0, result.output
    return out


def test_page_is_self_contained_and_complete(demo_dir):
    page = (demo_dir / "index.html").read_text(encoding="utf-8")
    parser = _Links()
    parser.feed(page)
    assert parser.scripts == 0
    assert {"realtime.png", "reference.png", "error.png", "furnace/furnace.png", "lut.png",
            "bake/preview.png"} <= set(parser.images)
    for ref in parser.images + parser.links:
        assert ref and not re.match(r"^[a-z]+:", ref) and not ref.startswith("/"), ref  # relative links only
        assert (demo_dir / ref).exists(), ref
    summary = json.loads((demo_dir / "summary.json").read_text())
    errors = summary["errors"]
    for key in ("mean_relative_error", "max_relative_error", "flip", "mean_relative_stderr"):
        assert np.isfinite(errors[key]) and f"{errors[key]:.4g}" in page
    assert summary["reference"]["spp"] == 8 and str(summary["reference"]["paths"]) in page
    manifest = json.loads((demo_dir / "bake" / "manifest.json").read_text())
    assert manifest["format"] in page and "sha256" in page
    assert len(summary["per_sphere_signed_relative_error"]) == 7
    assert (demo_dir / "LICENSE-environment.md").read_text().count("CC0") >= 1


def test_images_have_the_requested_sizes(demo_dir):
    import imageio.v3 as iio

    for name in ("realtime.png", "reference.png", "error.png"):
        assert iio.imread(demo_dir / name).shape == (56, 56, 3)


@pytest.mark.skipif(CHROMIUM is None, reason="headless Chromium is not installed (Debian: apt-get install -y chromium)")
def test_page_loads_in_headless_chromium(demo_dir, tmp_path):
    # A copy of the page with a checker appended (the product page has no script): after
    # the load event it lists the images that failed to decode into the document title.
    page = (demo_dir / "index.html").read_text(encoding="utf-8")
    checker = """<script>
window.addEventListener("load", function () {
  var bad = [], imgs = document.images;
  for (var i = 0; i < imgs.length; i++) {
    if (!imgs[i].complete || imgs[i].naturalWidth === 0) bad.push(imgs[i].getAttribute("src"));
  }
  document.body.setAttribute("data-images", imgs.length);
  document.body.setAttribute("data-broken", bad.join(","));
  document.body.setAttribute("data-checked", "yes");
});
</script></body>"""
    check = demo_dir / "check.html"
    check.write_text(page.replace("</body>", checker), encoding="utf-8")
    try:
        profile = tmp_path / "profile"
        dom = subprocess.run([CHROMIUM, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", "--enable-logging=stderr",
                              "--v=0", "--virtual-time-budget=10000", "--dump-dom", check.as_uri()],
                             capture_output=True, text=True, timeout=120)
    finally:
        check.unlink()
    assert 'data-checked="yes"' in dom.stdout, dom.stderr[-2000:]
    images = int(re.search(r'data-images="(\d+)"', dom.stdout).group(1))
    broken = re.search(r'data-broken="([^"]*)"', dom.stdout).group(1)
    assert images >= 6 and broken == ""
    console = [line for line in dom.stderr.splitlines()
               if "CONSOLE" in line or "Failed to load resource" in line or "Uncaught" in line
               or "ERR_FILE_NOT_FOUND" in line]
    assert console == []
    # a screenshot of the real page, kept beside the demo output
    shot = demo_dir.parent / "screenshot.png"
    run = subprocess.run([CHROMIUM, *CHROMIUM_FLAGS, f"--user-data-dir={tmp_path / 'profile2'}",
                          "--enable-logging=stderr", "--v=0", "--window-size=1280,1800", "--hide-scrollbars",
                          f"--screenshot={shot}", (demo_dir / "index.html").as_uri()],
                         capture_output=True, text=True, timeout=120)
    assert shot.exists(), run.stderr[-2000:]
    import imageio.v3 as iio

    pixels = iio.imread(shot)
    assert pixels.shape[:2] == (1800, 1280) and pixels.std() > 10  # not a blank page
    assert not [line for line in run.stderr.splitlines() if "CONSOLE" in line or "Failed to load" in line]
