"""``pbrkit explore`` against untrusted input (the bad-input corpus of the issue
"Untrusted input"):

- the local server answers only requests that name it by a loopback name and
  its port (``Host``), from a loopback origin when there is an ``Origin``: a DNS
  rebinding pair (``Host: evil.example:PORT``, ``Origin: http://evil.example:PORT``)
  gets 403 for the page, a static file and the websocket upgrade (no 101, no
  session token), while the same requests with a loopback ``Host`` get 200 / 101
  (pbrkit.explore.server);
- Bokeh, Tornado and Panel log nothing on the terminal while serving, pbrkit's
  own lines still show;
- a port in use is one line naming ``--port``, exit status 1;
- the material and fit errors name the flag, not the material ``'explore'``;
- ``--static`` writes strict JSON: a fit whose numbers overflow is refused with
  one line naming what, and NaN or Infinity never reaches ``explore.json``.
"""

from __future__ import annotations

import base64
import http.client
import json
import logging
import os
import queue
import re
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from pbrkit.cli import app
from pbrkit.explore import server as S

START_TIMEOUT = 300  # seconds: a cold Numba cache compiles the models first
TOKEN = re.compile(r'"token"\s*:\s*"([^"]+)"')


def invoke(*args):
    return CliRunner().invoke(app, ["explore", *[str(a) for a in args]])


def assert_refused(result, *fragments, absent=(), progress=False):
    """One ``pbrkit: error:`` line naming ``fragments``, exit status 1, no traceback,
    nothing on stdout, nothing written; with ``progress``, the progress lines of
    the stages that had started may come before it."""
    assert result.exit_code == 1, result.output
    assert isinstance(result.exception, SystemExit), repr(result.exception)
    assert "Traceback" not in result.output
    assert result.stdout == ""
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    if progress:
        assert all(line.startswith("pbrkit explore: ") for line in lines[:-1]), lines
        lines = lines[-1:]
    assert len(lines) == 1 and lines[0].startswith("pbrkit: error: "), lines
    assert "'explore'" not in lines[0]
    for fragment in fragments:
        assert fragment in lines[0], lines[0]
    for path in absent:
        assert not Path(path).exists()
        assert not list(Path(path).parent.glob(f".{Path(path).name}*"))


# ------------------------------------------------------------------ the Host / Origin rule


@pytest.mark.parametrize("headers, refused", [
    ({"Host": "127.0.0.1:8123"}, None),
    ({"Host": "localhost:8123"}, None),
    ({"Host": "[::1]:8123"}, "foreign Host"),  # not listened on (and Panel cannot parse it)
    ({"Host": "LocalHost:8123", "Origin": "http://LOCALHOST:8123"}, None),
    ({"Host": "127.0.0.1:8123", "Origin": "http://127.0.0.1:8123"}, None),
    ({"Host": "localhost:8123", "Origin": "http://127.0.0.1:8123"}, None),
    ({"Host": "evil.example:8123"}, "foreign Host"),
    ({"Host": "evil.example:8123", "Origin": "http://evil.example:8123"}, "foreign Host"),
    ({"Host": "evil.example", "Origin": "http://evil.example"}, "foreign Host"),  # the default port
    ({"Host": "evil.example:80"}, "foreign Host"),
    ({"Host": "127.0.0.1"}, "foreign Host"),  # not the served port
    ({"Host": "localhost:8124"}, "foreign Host"),
    ({"Host": "localhost.:8123"}, "foreign Host"),
    ({"Host": "127.0.0.1:8123,evil.example:8123"}, "foreign Host"),  # two Host headers, as Tornado joins them
    ({}, "foreign Host"),
    ({"Host": "127.0.0.1:8123", "Origin": "http://evil.example:8123"}, "foreign Origin"),
    ({"Host": "127.0.0.1:8123", "Origin": "null"}, "foreign Origin"),
    ({"Host": "127.0.0.1:8123", "Origin": "https://127.0.0.1:8123"}, "foreign Origin"),
    ({"Host": "127.0.0.1:8123", "Origin": "http://127.0.0.1:8124"}, "foreign Origin"),
])
def test_only_loopback_hosts_and_origins_pass(headers, refused):
    assert S.refusal(headers, 8123) == refused


def test_library_logs_are_off_while_serving_and_restored_after(caplog):
    own = logging.getLogger("pbrkit.explore.test")
    child = logging.getLogger("tornado.access")
    child.setLevel(logging.INFO)
    parent_before = logging.getLogger("tornado").level  # (other tests may have set it)
    try:
        with S.quiet_library_logs():
            for name in ("bokeh.server.views.ws", "tornado.access", "tornado.application", "panel.io.server",
                         "tornado.brand_new_child"):
                logging.getLogger(name).error("library chatter from %s", name)
            own.error("pbrkit's own line")
        assert child.level == logging.INFO
        assert logging.getLogger("tornado").level == parent_before
    finally:
        child.setLevel(logging.NOTSET)
    assert [r.getMessage() for r in caplog.records] == ["pbrkit's own line"]


# ------------------------------------------------------------------ a real server


@pytest.fixture(scope="module")
def served():
    """``pbrkit explore --no-browser --port 0`` in a subprocess: (process, port, stderr lines so far)."""
    proc = subprocess.Popen([sys.executable, "-m", "pbrkit", "explore", "--no-browser", "--port", "0"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=dict(os.environ))
    lines = queue.Queue()
    threading.Thread(target=lambda: [lines.put(line) for line in proc.stdout], daemon=True).start()
    port = None
    deadline = time.monotonic() + START_TIMEOUT
    while port is None and time.monotonic() < deadline and proc.poll() is None:
        try:
            line = lines.get(timeout=1.0)
        except queue.Empty:
            continue
        match = re.search(r"serving http://127\.0\.0\.1:(\d+)/", line)
        if match:
            port = int(match.group(1))
    if port is None:
        proc.kill()
        pytest.fail(f"pbrkit explore printed no URL (exit {proc.poll()}): {proc.stderr.read()[-2000:]}")
    yield proc, port
    if proc.poll() is None:
        proc.kill()
        proc.wait()


def request(port, path, host, origin=None, upgrade=False, protocol=None):
    """GET ``path`` from 127.0.0.1:``port`` with these ``Host`` (None: no Host header)
    and ``Origin`` headers, as a websocket upgrade with ``upgrade``: (status, body)."""
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=120)
    try:
        connection.putrequest("GET", path, skip_host=True, skip_accept_encoding=True)
        if host is not None:
            connection.putheader("Host", host)
        if origin is not None:
            connection.putheader("Origin", origin)
        if upgrade:
            connection.putheader("Upgrade", "websocket")
            connection.putheader("Connection", "Upgrade")
            connection.putheader("Sec-WebSocket-Key", base64.b64encode(os.urandom(16)).decode())
            connection.putheader("Sec-WebSocket-Version", "13")
            if protocol is not None:
                connection.putheader("Sec-WebSocket-Protocol", protocol)
        connection.endheaders()
        response = connection.getresponse()
        body = b"" if response.status == 101 else response.read()
        return response.status, body.decode("utf-8", "replace")
    finally:
        connection.close()


STATIC = "/static/js/bokeh.min.js"


@pytest.mark.parametrize("host, origin", [
    ("evil.example:{port}", "http://evil.example:{port}"),  # the DNS rebinding pair
    ("evil.example:{port}", None),
    ("evil.example", "http://evil.example"),  # on the default port
    ("evil.example:80", None),
    ("127.0.0.1:{port}", "http://evil.example:{port}"),  # a foreign page's websocket
    ("127.0.0.1", None),
    ("localhost:{other}", None),
])
def test_a_foreign_host_or_origin_gets_no_page_no_token_no_websocket(served, host, origin):
    proc, port = served
    host = host.format(port=port, other=port + 1)
    origin = None if origin is None else origin.format(port=port)
    for path, upgrade in (("/", False), (STATIC, False), ("/ws", True), ("/autoload.js", False),
                          ("/nonexistent", False)):
        status, body = request(port, path, host, origin, upgrade=upgrade, protocol="bokeh")
        assert status == 403, (path, host, origin, status)
        assert "token" not in body and "bokeh" not in body.lower() and len(body) < 200, (path, body[:200])
    assert request(port, "/", None)[0] in (400, 403)  # no Host at all


@pytest.mark.parametrize("host, origin", [
    ("127.0.0.1:{port}", None),
    ("localhost:{port}", "http://localhost:{port}"),
    ("LOCALHOST:{port}", "http://127.0.0.1:{port}"),
])
def test_a_loopback_host_gets_the_page_and_the_websocket(served, host, origin):
    """The same requests as above with a loopback Host pass: the refusals are the Host check's."""
    proc, port = served
    host = host.format(port=port)
    origin = None if origin is None else origin.format(port=port)
    status, page = request(port, "/", host, origin)
    assert status == 200 and "<title>pbrkit explore</title>" in page
    token = TOKEN.search(page).group(1)
    assert request(port, STATIC, host, origin)[0] == 200
    status, _ = request(port, "/ws", host, origin, upgrade=True, protocol=f"bokeh, {token}")
    assert status == 101


def test_serving_keeps_library_logs_off_the_terminal(served):
    """After the refused and the allowed requests above (a websocket without Bokeh's
    subprotocol too, which makes Bokeh raise), stderr holds pbrkit's lines only."""
    proc, port = served
    request(port, "/ws", f"127.0.0.1:{port}", upgrade=True)  # no 'bokeh' subprotocol: a ProtocolError inside
    request(port, "/ws", f"evil.example:{port}", f"http://evil.example:{port}", upgrade=True)
    proc.send_signal(signal.SIGINT)
    assert proc.wait(timeout=30) == 0
    lines = [line for line in proc.stderr.read().splitlines() if line.strip()]
    assert lines and all(line.startswith("pbrkit explore: ") for line in lines), lines
    assert lines[-1] == "pbrkit explore: stopped"


# ------------------------------------------------------------------ the port


@pytest.fixture
def busy_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        s.listen(1)
        yield s.getsockname()[1]


def test_a_port_in_use_is_one_line_naming_the_flag(busy_port):
    result = invoke("--no-browser", "--port", busy_port)
    assert_refused(result, f"--port {busy_port}: in use")


def test_serve_names_the_port_when_it_cannot_bind(busy_port):
    """The port taken between the CLI's check and the server's bind: the same error."""
    from pbrkit.explore.app import serve

    announced = []
    with pytest.raises(S.ListenError) as caught:
        serve(port=busy_port, open_browser=False, announce=announced.append)
    assert str(caught.value).startswith(f"--port {busy_port}: in use")
    assert isinstance(caught.value, OSError) and announced == []


# ------------------------------------------------------------------ errors name the flag


@pytest.mark.parametrize("args, fragments", [
    (["--model", "cook_torrance", "--fresnel", "exact-conductor"], ["--fresnel: ", "needs eta and k"]),
    (["--model", "disney", "--anisotropy", "-0.5"], ["--anisotropy: ", "[0, 1]", "disney"]),
    (["--model", "filament", "--diffuse", "eon"], ["--diffuse: ", "has no diffuse 'eon'"]),
    (["--model", "cook_torrance", "--distribution", "blinn-phong", "--anisotropy", "0.5"],
     ["--distribution: ", "isotropic"]),
    (["--no-fit-fresnel"], ["--no-fit-fresnel is for --fit"]),
    (["--fit-weighting", "cosine"], ["--fit-weighting is for --fit"]),
])
def test_material_and_fit_errors_name_the_flag(tmp_path, args, fragments):
    out = tmp_path / "out"
    assert_refused(invoke("--static", "-o", out, *args), *fragments, absent=[out])


def test_the_second_brdf_errors_name_compare():
    from pbrkit.cli.explore import _flagged

    error = _flagged(ValueError("material 'explore': sheen needs model 'disney'"), "ue4", compare=True)
    assert str(error) == "--compare ue4: sheen needs model 'disney'"
    error = _flagged(ValueError("material 'explore': something else"), "gltf")
    assert str(error) == "--model gltf: something else"


# ------------------------------------------------------------------ strict JSON


@pytest.fixture(scope="module")
def merl_files(tmp_path_factory):
    from pbrkit.explore.views import model_brdf
    from pbrkit.measured.merl import merl_bytes, merl_table

    root = tmp_path_factory.mktemp("merl")
    brdf = model_brdf("cook_torrance", (0.6, 0.3, 0.2), 0.0, 0.3)
    table = merl_table(lambda l, v, n: brdf.evaluate(l, v, n))
    (root / "ggx.binary").write_bytes(merl_bytes(table))
    (root / "huge.binary").write_bytes(merl_bytes(np.where(table >= 0, table * 1e300, table)))  # finite, too large
    return root


def test_a_fit_that_overflows_is_refused_naming_what(merl_files, tmp_path):
    out = tmp_path / "out"
    result = invoke("--static", "--merl", merl_files / "huge.binary", "--fit", "ggx", "-o", out)
    assert_refused(result, "--fit ggx: the fit to 'huge'", "is not finite", absent=[out], progress=True)


def test_disney_fit_without_fresnel_names_the_flag(merl_files, tmp_path):
    out = tmp_path / "out"
    result = invoke("--static", "--merl", merl_files / "ggx.binary", "--fit", "disney", "--no-fit-fresnel", "-o", out)
    assert_refused(result, "--no-fit-fresnel: only --fit ggx", absent=[out])


class _Overflowing:
    """A BRDF of 1e308 everywhere: finite values whose albedo overflows."""

    name = "overflowing"

    def evaluate(self, l, v, n=None):
        return np.full(np.broadcast_shapes(np.shape(l), np.shape(v)), 1e308)


def test_non_finite_summaries_are_refused_before_anything_is_written(tmp_path):
    from pbrkit.explore.static import check_finite, write_static
    from pbrkit.explore.views import model_brdf

    out = tmp_path / "out"
    with pytest.raises(ValueError, match=r"^explore\.json: second\.albedo_luminance\.\w+ is not finite \(inf\)"):
        write_static(out, model_brdf(), _Overflowing())
    assert not out.exists() and not list(tmp_path.glob(".out*"))
    with pytest.raises(ValueError, match=r"explore\.json: fit\.error\[1\] is not finite \(nan\)"):
        check_finite({"fit": {"error": [1.0, float("nan")]}})
    check_finite({"a": [1.0, {"b": 2}], "c": "text", "d": None})


def test_the_json_written_is_strict(tmp_path):
    out = tmp_path / "out"
    result = invoke("--static", "--model", "ue4", "-q", "-o", out)
    assert result.exit_code == 0, result.output
    text = (out / "explore.json").read_text()

    def refuse(constant):
        raise AssertionError(f"non-strict JSON constant {constant}")

    json.loads(text, parse_constant=refuse)
