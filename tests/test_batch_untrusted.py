"""``pbrkit batch`` and every ``-o/--out`` take their inputs as untrusted.

- ``--list`` files are read with :func:`pbrkit.core.inputs.read_text`: a device
  (``/dev/zero``, also behind a link) is refused at once, and an error names the
  list file, the line number and the list format, never a line's text (a file
  such as ``/etc/passwd`` given as a list file is not echoed); a property test
  feeds random mutations of a valid list file to the parser.
- ``--scheduler``: the address is checked before anything starts, and a server
  that is not a Dask scheduler (silent, HTTP, random bytes, a closed port, a Dask
  worker) is one line naming ``--scheduler`` within ``--scheduler-timeout``.
- ``-o/--out``: an empty path and an existing path of the wrong kind are refused
  as the command line is read, by every command that has the option.
- The external files of a glTF recorded for a render batch are confined to its
  folder, as the renderer confines them.
"""

from __future__ import annotations

import asyncio
import os
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path
from types import SimpleNamespace

import pytest
import typer
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from pbrkit.app.cli import app
from pbrkit.app.scheduler import (
    SchedulerUnreachable,
    check_scheduler_address,
    check_scheduler_timeout,
    probe_scheduler,
)
from pbrkit.core.errors import InputError

SECRET = "SECRET-7f3a"
SMALL = ["--size", "16", "--min-size", "4", "--irradiance-size", "4", "--lut-size", "4"]


def invoke(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def one_error_line(result):
    """The refusal contract: exit status 1, nothing on stdout, one ``pbrkit: error:``
    line on stderr and nothing else, no traceback.  Returns the line."""
    assert result.exit_code == 1, result.output
    assert isinstance(result.exception, SystemExit), repr(result.exception)
    assert result.stdout == "" and "Traceback" not in result.output, result.output
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("pbrkit: error: "), result.stderr
    return lines[0]


@pytest.fixture
def hdr(tmp_path):
    path = tmp_path / "in" / "sky.hdr"
    path.parent.mkdir()
    path.write_bytes(b"#?RADIANCE\n")  # never read: every test here is refused before a bake starts
    return path


# ================================================================ --scheduler


@pytest.mark.parametrize("address, fragment", [
    ("tcp://host:notaport", "the port must be a number in 1-65535; got 'notaport'"),
    ("tcp://host:0", "the port must be a number in 1-65535; got '0'"),
    ("tcp://host:65536", "got '65536'"),
    ("tcp://host", "no port"),
    ("tcp://:8786", "no host"),
    ("http://host:8786", "unknown scheme 'http'"),
    ("localhost:8786", "expected an address such as tcp://HOST:PORT"),
    ("tcp://::1:8786", "an IPv6 host goes in brackets"),
    ("tcp://[nothing]:8786", "is not an IPv6 address"),
    ("tcp://a b:8786", "is not a host name or IP address"),
    ("tcp://host:8786/path", "the port must be a number"),
])
def test_bad_scheduler_addresses_are_refused_before_anything_starts(tmp_path, hdr, address, fragment):
    t0 = time.monotonic()
    line = one_error_line(invoke("batch", "bake", hdr, "-o", tmp_path / "out", *SMALL, "--scheduler", address))
    assert line.startswith("pbrkit: error: --scheduler: ") and fragment in line, line
    assert "invalid literal" not in line and not (tmp_path / "out").exists() and time.monotonic() - t0 < 10


def test_good_scheduler_addresses():
    assert check_scheduler_address("tcp://10.0.0.5:8786") == "tcp://10.0.0.5:8786"
    assert check_scheduler_address("TLS://sched.example.org:08786") == "tls://sched.example.org:8786"
    assert check_scheduler_address("tcp://[::1]:8786") == "tcp://[::1]:8786"
    assert check_scheduler_address("ws://h:1") == "ws://h:1" and check_scheduler_address("inproc://h/1/2")
    assert check_scheduler_timeout("2.5") == 2.5
    for bad in (0, -1, "nan", "inf", 1e9, True, "x"):
        with pytest.raises(ValueError, match="--scheduler-timeout: expected seconds"):
            check_scheduler_timeout(bad)


@pytest.mark.parametrize("args, fragment", [
    (["--scheduler-timeout", "5"], "--scheduler-timeout is for --scheduler"),
    (["--scheduler", "tcp://127.0.0.1:1", "--scheduler-timeout", "0"], "--scheduler-timeout: expected seconds"),
    (["--scheduler", "tcp://127.0.0.1:1", "--scheduler-timeout", "nan"], "--scheduler-timeout: expected seconds"),
])
def test_scheduler_timeout_is_checked_with_the_other_options(tmp_path, hdr, args, fragment):
    line = one_error_line(invoke("batch", "bake", hdr, "-o", tmp_path / "out", *SMALL, *args))
    assert fragment in line, line


class _Server:
    """A throwaway TCP server on 127.0.0.1: ``silent`` accepts and never answers,
    ``http`` answers an HTTP response, ``random`` random bytes, ``close`` closes."""

    def __init__(self, mode):
        self.sock = socket.create_server(("127.0.0.1", 0))
        self.port = self.sock.getsockname()[1]
        self.mode, self.conns = mode, []
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self):
        while True:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            self.conns.append(conn)
            try:
                if self.mode == "http":
                    conn.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Type: text/html\r\nContent-Length: 11\r\n\r\n"
                                 + SECRET.encode())
                elif self.mode == "random":
                    conn.sendall(os.urandom(4096))
                elif self.mode == "close":
                    conn.close()
            except OSError:
                pass

    def close(self):
        self.sock.close()
        for conn in self.conns:
            conn.close()


def _closed_port():
    with socket.create_server(("127.0.0.1", 0)) as sock:
        return sock.getsockname()[1]


@pytest.mark.parametrize("mode, reason", [
    ("silent", "the server accepted the connection but sent no Dask handshake"),
    ("http", "the server's answer is not Dask's protocol: MemoryError"),
    ("random", "the server's answer is not Dask's protocol"),
    ("close", "the server closed the connection: not a Dask scheduler"),
    ("closed port", "connection refused"),
])
def test_no_dask_scheduler_is_one_line_within_the_timeout(tmp_path, hdr, capfd, mode, reason):
    server = None if mode == "closed port" else _Server(mode)
    port = _closed_port() if server is None else server.port
    address = f"tcp://127.0.0.1:{port}"
    try:
        t0 = time.monotonic()
        result = invoke("batch", "bake", hdr, "-o", tmp_path / "out", *SMALL, "--scheduler", address,
                        "--scheduler-timeout", "1")
        seconds = time.monotonic() - t0
    finally:
        if server is not None:
            server.close()
    line = one_error_line(result)
    assert line.startswith(f"pbrkit: error: --scheduler {address}: no Dask scheduler answered within 1 s "
                           f"({reason}") and line.endswith(")"), line
    assert SECRET not in line
    assert seconds < 20.0, seconds  # 1 s, and the bake option check's imports; not Dask's default of 30 s
    assert not (tmp_path / "out").exists()
    captured = capfd.readouterr()
    assert SECRET not in captured.err and "Traceback" not in captured.err, captured.err  # Dask's own loggers


def _fake_dask_server(kind):
    """A server speaking Dask's protocol whose identity is of ``kind``; (address, stop)."""
    from distributed.core import Server

    ready, box = threading.Event(), {}

    async def main():
        async def identity(comm=None, **kwargs):
            return {"type": kind}

        server = Server({"identity": identity})
        await server.listen("tcp://127.0.0.1:0")
        box.update(address=server.address, loop=asyncio.get_running_loop(), stop=asyncio.Event())
        ready.set()
        await box["stop"].wait()
        await server.close()

    thread = threading.Thread(target=lambda: asyncio.run(main()), daemon=True)
    thread.start()
    assert ready.wait(30)

    def stop():
        box["loop"].call_soon_threadsafe(box["stop"].set)
        thread.join(10)

    return box["address"], stop


@pytest.mark.parametrize("kind, reason", [
    ("Worker", "a Dask worker answers there, not a scheduler"),
    ("Nanny", "a Dask nanny answers there, not a scheduler"),
    ("Other", "the server's answer is not a Dask scheduler's identity"),
])
def test_a_dask_server_that_is_not_a_scheduler(kind, reason):
    address, stop = _fake_dask_server(kind)
    try:
        with pytest.raises(SchedulerUnreachable) as caught:
            probe_scheduler(address, 2)
    finally:
        stop()
    assert str(caught.value) == f"--scheduler {address}: no Dask scheduler answered within 2 s ({reason})"


def test_a_dask_scheduler_answers_the_probe():
    address, stop = _fake_dask_server("Scheduler")
    try:
        assert probe_scheduler(address, 2) == {"type": "Scheduler"}
    finally:
        stop()


# ================================================================ -o/--out


def _commands_with_out():
    """[(command words, metavar)] of every command of ``pbrkit`` that has -o/--out."""
    found = []

    def walk(command, words):
        for name, sub in sorted(getattr(command, "commands", {}).items()):
            walk(sub, words + [name])
        for param in getattr(command, "params", []):
            if "--out" in getattr(param, "opts", ()):
                found.append((words, param.metavar))

    walk(typer.main.get_command(app), [])
    return found


COMMANDS = _commands_with_out()


def test_every_output_option_is_found():
    names = {" ".join(words) for words, _ in COMMANDS}
    assert {"furnace", "lut", "render", "bake", "batch bake", "batch render", "explore"} <= names, names
    assert {metavar for _, metavar in COMMANDS} == {"DIR", "FILE"}


@pytest.mark.parametrize("words, metavar", COMMANDS, ids=[" ".join(w) for w, _ in COMMANDS])
def test_an_empty_output_path_is_refused_by_every_command(tmp_path, monkeypatch, words, metavar):
    monkeypatch.chdir(tmp_path)
    line = one_error_line(invoke(*words, "-o", ""))
    wanted = "a folder (DIR)" if metavar == "DIR" else "a file (FILE)"
    assert line.startswith(f"pbrkit: error: --out: empty path; expected {wanted}"), line
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("words, metavar", COMMANDS, ids=[" ".join(w) for w, _ in COMMANDS])
def test_an_output_of_the_wrong_kind_is_refused_by_every_command(tmp_path, monkeypatch, words, metavar):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "file").write_text("mine")
    (tmp_path / "folder").mkdir()
    wrong = {"DIR": ["file", "/dev/null"], "FILE": ["folder", "/dev/null"]}[metavar]
    for path in wrong + ["file/under/it"]:
        line = one_error_line(invoke(*words, "-o", path))
        assert line.startswith(f"pbrkit: error: --out: {path}: "), line
        assert "not a" in line or (metavar == "FILE" and "is a directory" in line), line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file", "folder"]
    assert (tmp_path / "file").read_text() == "mine" and not any((tmp_path / "folder").iterdir())
