"""``pbrkit explore`` serves its app on the loopback address only; the page loads
in headless Chromium (puppeteer-core, tests/support/explore_browser.mjs) with no console
errors, and moving a slider changes the plotted data, which the server computes;
Ctrl-C stops the server cleanly."""

from __future__ import annotations

import json
import os
import queue
import re
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from pathlib import Path

import pytest
from engine_pages import NODE, engines_missing

HERE = Path(__file__).resolve().parent
BROWSER = HERE.parent / "support" / "explore_browser.mjs"
START_TIMEOUT = 300  # seconds: a cold Numba cache compiles the models, the bake and the renderer first


@pytest.fixture(scope="module")
def server():
    """``pbrkit explore --no-browser --port 0`` in a subprocess: (process, URL, port)."""
    proc = subprocess.Popen([sys.executable, "-m", "pbrkit", "explore", "--no-browser", "--port", "0"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=dict(os.environ))
    lines = queue.Queue()
    threading.Thread(target=lambda: [lines.put(line) for line in proc.stdout], daemon=True).start()
    url = None
    deadline = time.monotonic() + START_TIMEOUT
    while url is None and time.monotonic() < deadline and proc.poll() is None:
        try:
            line = lines.get(timeout=1.0)
        except queue.Empty:
            continue
        match = re.search(r"serving (http://127\.0\.0\.1:(\d+)/)", line)
        if match:
            url, port = match.group(1), int(match.group(2))
    if url is None:
        proc.kill()
        pytest.fail(f"pbrkit explore printed no URL (exit {proc.poll()}): {proc.stderr.read()[-2000:]}")
    yield proc, url, port
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def listening_addresses(pid, port):
    """The local addresses on which process ``pid`` listens on ``port`` (psutil, a dependency of dask)."""
    import psutil

    process = psutil.Process(pid)
    connections = getattr(process, "net_connections", None) or process.connections
    return sorted({c.laddr.ip for c in connections(kind="inet") if c.status == psutil.CONN_LISTEN
                   and c.laddr.port == port})


def other_address():
    """A non-loopback IPv4 address of this machine, or None (no packet is sent)."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        try:
            s.connect(("192.0.2.1", 9))  # TEST-NET-1: connect() on UDP only picks the route
            address = s.getsockname()[0]
        except OSError:
            return None
    return None if address.startswith("127.") else address


def test_served_on_the_loopback_address_only(server):
    proc, url, port = server
    assert listening_addresses(proc.pid, port) == ["127.0.0.1"]
    address = other_address()
    if address is not None:
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
            s.settimeout(5)
            with pytest.raises(OSError):
                s.connect((address, port))
    with urllib.request.urlopen(url, timeout=60) as response:
        assert response.status == 200
        page = response.read().decode("utf-8")
    assert "<title>pbrkit explore</title>" in page
    assert "bokeh" in page.lower()
    external = [u for u in re.findall(r'(?:src|href)="([^"]+)"', page) if u.startswith(("http:", "https:", "//"))]
    assert external == []  # BokehJS and Panel's files come from the local server: it works offline


@pytest.mark.skipif(engines_missing() is not None, reason=engines_missing() or "")
def test_page_loads_without_errors_and_a_slider_changes_the_plot(server):
    proc, url, port = server
    command = [NODE, str(BROWSER), url, "--timeout", "90", "--slider", "roughness",
               "--value", "0.85", "--source", "incidence_a"]
    from skips import CHROMIUM

    run = subprocess.run(command, capture_output=True, text=True, timeout=240, env=dict(os.environ, CHROMIUM=CHROMIUM))
    lines = [line for line in run.stdout.splitlines() if line.startswith("{")]
    assert lines, f"no report (exit {run.returncode}): {run.stderr[-2000:]}"
    report = json.loads(lines[-1])
    assert report["rendered"], report["errors"]
    assert report["errors"] == [], report["errors"]
    assert report["slider"] == {"type": "Slider", "title": "roughness", "old": 0.5, "value": 0.85}
    assert report["changed"] and report["before"] != report["after"]
    assert len(report["before"]) == len(report["after"]) == 181
    # rougher: a lower, wider peak in the plane of incidence (the server's new numbers)
    assert max(report["after"]) < max(report["before"])
    assert run.returncode == 0


def test_ctrl_c_stops_the_server_cleanly(server):
    proc, url, port = server
    proc.send_signal(signal.SIGINT)
    assert proc.wait(timeout=30) == 0
    assert "pbrkit explore: stopped" in proc.stderr.read()
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.settimeout(2)
        with pytest.raises(OSError):
            s.connect(("127.0.0.1", port))


# ------------------------------------------------------------------ the app in this process (no browser)


def test_the_app_plots_the_models_values_and_follows_its_widgets():
    import math

    import numpy as np
    import panel as pn

    from pbrkit.brdf import models
    from pbrkit.explore import views as V
    from pbrkit.explore.app import Explorer

    e = Explorer(model="ue4", roughness=0.4, second="filament", theta_v=math.radians(30.0))
    root = e.layout.get_root()  # what Jupyter and the server render: Bokeh models, no server needed
    assert isinstance(e.layout, pn.viewable.Viewable) and root is not None

    def plotted(name):
        data = e.sources[name].data
        return np.asarray(data["x"], dtype=float), np.asarray(data["y"], dtype=float)

    def expected(model, roughness, theta_v):
        material = V.model_brdf(model, (0.8, 0.8, 0.8), 0.0, roughness).material
        p = V.incidence_plane(V.model_brdf(model, roughness=roughness), theta_v)  # the view's directions
        f = getattr(models, model)(p["l"], np.broadcast_to(p["v"], p["l"].shape), np.array([0.0, 0.0, 1.0]),
                                   material)
        value = (f * p["l"][:, 2:3]) @ np.array([0.2126, 0.7152, 0.0722])
        return value * np.sin(p["theta_l"]), value * np.cos(p["theta_l"])

    for k, model in (("a", "ue4"), ("b", "filament")):
        np.testing.assert_allclose(plotted(f"incidence_{k}"), expected(model, 0.4, math.radians(30.0)), rtol=1e-12)
    e.params["roughness"].value = 0.7
    e.theta_v.value = 55.0
    for k, model in (("a", "ue4"), ("b", "filament")):
        np.testing.assert_allclose(plotted(f"incidence_{k}"), expected(model, 0.7, math.radians(55.0)), rtol=1e-12)
    albedo = e.sources["albedo_a"].data
    np.testing.assert_allclose(albedo["y"], V.directional_albedo(V.model_brdf("ue4", roughness=0.7))["value"])
    e.model.value = "disney"  # Disney's parameters become available, UE4's reflectance stays
    assert not e.params["sheen"].disabled and e.distribution.disabled
    e.model.value = "cook_torrance"
    assert not e.distribution.disabled
    e.fresnel.value = "exact-conductor"  # no conductor chosen: the status says so, the plots stay
    assert "exact-conductor" in e.status.object and "error" in e.status.object
    e.conductor.value = "gold"
    assert e._a.spec.eta is not None and e.status.object == ""
    assert max(e.timings.values()) < 5.0


def test_the_app_loads_a_merl_file_and_fits_it(tmp_path):
    import numpy as np

    from pbrkit.explore import views as V
    from pbrkit.explore.app import Explorer
    from pbrkit.measured.merl import merl_table, write_merl

    model = V.model_brdf("cook_torrance", (0.5, 0.4, 0.3), 0.0, 0.35)
    write_merl(tmp_path / "synthetic.binary", merl_table(lambda l, v, n: model.evaluate(l, v, n)))
    e = Explorer(model="gltf", merl=tmp_path / "synthetic.binary", second="measured")
    assert e.measured.name == "synthetic" and "loaded" in e.status.object
    assert len(e.sources["incidence_b"].data["x"]) == 181 and len(e.sources["difference"].data["x"]) == 181
    assert e.sources["terms_d_b"].data["x"] == []  # a measured BRDF has no terms
    e.merl_path.value = str(tmp_path / "missing.binary")
    e._load_merl()
    assert "missing.binary: file not found" in e.status.object and e.measured is not None
    e._fit()
    assert e.second.value == "fit" and "rms_log" in e.status.object
    assert e._b is e.fitted and abs(e.fitted.result.parameters["roughness"] - 0.35) < 1e-3
    assert np.all(np.isfinite(e.sources["sphere_difference"].data["image"][0]))


def test_the_gltf_extensions_have_controls_that_change_the_plots():
    """KHR_materials parameters of the gltf model are sliders (colours: one per channel,
    finite ends), enabled for gltf only where the model declares them, and moving one
    redraws the plots with the model's values."""
    import numpy as np

    from pbrkit.brdf import models
    from pbrkit.explore import views as V
    from pbrkit.explore.app import Explorer

    e = Explorer(model="gltf", base_color=(0.3, 0.05, 0.05), roughness=0.5, sheen_color=(0.2, 0.2, 0.2))
    assert [w.value for w in e.colours["sheen_color"]] == [0.2, 0.2, 0.2]
    assert e.params["ior"].start == 1.0 and e.params["ior"].end == 3.0 and e.params["ior"].value == 1.5
    assert e.colours["specular_color"][0].end == 2.0
    for name in ("clearcoat", "clearcoat_roughness", "sheen_roughness", "specular", "ior"):
        assert not e.params[name].disabled, name
    assert not e.colours["sheen_color"][0].disabled and not e.colours["specular_color"][2].disabled

    def peak():
        return float(np.max(np.asarray(e.sources["incidence_a"].data["y"], dtype=float)))

    before = peak()
    e.params["clearcoat"].value = 1.0
    e.params["clearcoat_roughness"].value = 0.05
    assert e._a.spec.clearcoat == 1.0 and peak() > 1.2 * before
    e.params["ior"].value = 2.4
    for w, x in zip(e.colours["specular_color"], (1.0, 0.5, 0.2)):
        w.value = x
    assert e._a.spec.ior == 2.4 and tuple(e._a.spec.specular_color) == (1.0, 0.5, 0.2)
    p = V.incidence_plane(e._a, np.radians(e.theta_v.value))
    f = models.gltf(p["l"], np.broadcast_to(p["v"], p["l"].shape), np.array([0.0, 0.0, 1.0]), e._a.material)
    value = (f * p["l"][:, 2:3]) @ np.array([0.2126, 0.7152, 0.0722])
    np.testing.assert_allclose(e.sources["incidence_a"].data["y"], value * np.cos(p["theta_l"]), rtol=1e-12)
    e.model.value = "ue4"  # no KHR_materials: their controls are disabled and not applied
    assert e.colours["sheen_color"][0].disabled and e.params["ior"].disabled and e.status.object == ""
