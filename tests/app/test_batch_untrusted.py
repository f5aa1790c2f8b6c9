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

from pbrkit.app.batch import LIST_FORMAT, expand_inputs, list_file_entries
from pbrkit.app.batch_tasks import _gltf_references, _scene_references
from pbrkit.cli import app
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


# ================================================================ --list files


_DEVICE_SCRIPT = """
import resource, sys
resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))  # a regression fails with MemoryError, not the machine
from pbrkit.app.batch import expand_inputs
from pbrkit.app.batch_tasks import _read_json
from pbrkit.core.errors import InputError
assert _read_json(sys.argv[1]) is None
for path in sys.argv[1:]:
    try:
        expand_inputs(None, [path], "bake")
    except InputError as exc:
        print(exc)
    else:
        print("read", path)
"""


def test_a_device_as_list_file_is_refused_without_reading_it(tmp_path):
    link = tmp_path / "list.txt"
    link.symlink_to("/dev/zero")
    t0 = time.monotonic()
    done = subprocess.run([sys.executable, "-c", _DEVICE_SCRIPT, "/dev/zero", str(link)], capture_output=True,
                          text=True, timeout=60, env={**os.environ, "PYTHONPATH": str(Path(__file__).parents[2] / "src")})
    assert done.returncode == 0, done.stderr[-2000:]
    lines = done.stdout.splitlines()
    assert len(lines) == 2 and time.monotonic() - t0 < 30, done.stdout
    for line, name in zip(lines, ("/dev/zero", str(link))):
        assert line.startswith(f"{name}: is a character device, not a regular file; expected a --list file"), line


def test_a_list_file_is_never_quoted(tmp_path, hdr):
    """A file that is not a list (``/etc/passwd``'s layout): the error names the
    list file and line 1, not the line."""
    passwd = tmp_path / "passwd"
    passwd.write_text(f"root:x:0:0:{SECRET}:/root:/bin/bash\ndaemon:x:1:1::/usr/sbin:/usr/sbin/nologin\n")
    line = one_error_line(invoke("batch", "bake", hdr, "--list", passwd, "-o", tmp_path / "out", *SMALL))
    assert f"{passwd}: line 1: no such file or directory; expected {LIST_FORMAT}" in line, line
    assert SECRET not in line and "/bin/bash" not in line and "nologin" not in line
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("content, fragment", [
    (b"sky.hdr\n\n# comment\nmissing.hdr\n", "line 4: no such file or directory"),
    (b"sky.hdr\nnone-*.hdr\n", "line 2: the pattern matches no"),
    (b"sky.hdr\n" + f"x\x00{SECRET}\n".encode(), "line 2: a NUL character"),
    (b"sky.hdr\n" + f"{SECRET}".encode() * 800 + b"\n", "line 2: not a usable path (File name too long)"),
    (b"sky.hdr\n\xff\xfe" + SECRET.encode(), "is not UTF-8 text (byte 8 is not valid UTF-8)"),
])
def test_list_file_errors_name_the_line_not_its_text(hdr, content, fragment):
    listing = hdr.parent / "list.txt"
    listing.write_bytes(content)
    with pytest.raises(InputError) as caught:
        expand_inputs(None, [listing], "bake")
    message = str(caught.value)
    assert message.startswith(f"{listing}: ") and fragment in message and "\n" not in message, message
    assert SECRET not in message and LIST_FORMAT in message


def test_list_file_of_the_wrong_kind(tmp_path):
    with pytest.raises(InputError, match="file not found; expected a --list file"):
        list_file_entries(tmp_path / "missing.txt")
    with pytest.raises(InputError, match="is a folder, not a regular file; expected a --list file"):
        list_file_entries(tmp_path)


def test_a_good_list_file_is_read_relative_to_its_folder(tmp_path, hdr):
    (hdr.parent / "sub").mkdir()
    (hdr.parent / "sub" / "b.exr").write_bytes(b"")
    listing = hdr.parent / "list.txt"
    listing.write_text("# inputs\r\n  sky.hdr  \r\n\r\nsub\r\n*.hdr\r\n")  # CRLF, spaces, a comment, a repeat
    assert list_file_entries(listing) == [(2, "sky.hdr"), (4, "sub"), (5, "*.hdr")]
    assert expand_inputs(None, [listing], "bake") == [hdr, hdr.parent / "sub" / "b.exr"]


# A property: whatever a list file becomes, its parser answers with the inputs it names or one clean line.

_FILES = ("a.hdr", "b.exr", "sub/c.hdr", "sub/d.pfm")
_LIST = f"# {SECRET} inputs\na.hdr\n\nsub\n  *.hdr  \nsub/c.hdr\nb.exr\n".encode()
_ENTRIES = {"a.hdr": ["a.hdr"], "b.exr": ["b.exr"], "sub": ["sub/c.hdr", "sub/d.pfm"], "*.hdr": ["a.hdr"],
            "sub/c.hdr": ["sub/c.hdr"]}
_PIECES = [b"\x00", b"\n", b"\r\n", b"\r", b"#", b" ", b"\t", b".", b"..", b"/", b"\xff", b"\xc3", b"\xe2\x80\xa8",
           b"a", b"[", b"?", b"\\", SECRET.encode(), b"x" * 300]


@pytest.fixture(scope="module")
def list_folder(tmp_path_factory):
    root = tmp_path_factory.mktemp("lists")
    for name in _FILES:
        (root / name).parent.mkdir(exist_ok=True)
        (root / name).write_bytes(b"")
    return root


def _mutate(data, edits):
    data = bytearray(data)
    for op, where, piece, length in edits:
        k = where % (len(data) + 1)
        if op == "insert":
            data[k:k] = piece
        elif op == "delete":
            del data[k:k + length]
        elif op == "replace":
            data[k:k + length] = piece
        else:
            del data[k:]
    return bytes(data)


def _expected(data, root):
    """The inputs a mutated list must give when every entry is one of the original
    list's, else None (any clean outcome is right)."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        return None
    entries = [line.strip() for line in text.split("\n")]
    entries = [e for e in entries if e and not e.startswith("#")]
    if not entries or any(e not in _ENTRIES for e in entries):
        return None
    found = []
    for e in entries:
        found += [root / name for name in _ENTRIES[e] if root / name not in found]
    return found


_EDIT = st.tuples(st.sampled_from(["insert", "delete", "replace", "truncate"]), st.integers(0, 200),
                  st.sampled_from(_PIECES), st.integers(1, 12))


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(edits=st.lists(_EDIT, min_size=0, max_size=6))
def test_mutated_list_files_parse_or_fail_cleanly(list_folder, edits):
    data = _mutate(_LIST, edits)
    listing = list_folder / "list.txt"
    listing.write_bytes(data)
    try:
        found = expand_inputs(None, [listing], "bake")
    except InputError as exc:
        message = str(exc)
        assert "\n" not in message and "\r" not in message and SECRET not in message, message
        assert message.startswith(f"{listing}: ") and "expected a --list file" in message, message
        assert _expected(data, list_folder) is None, message
        return
    except ValueError as exc:  # only comments and blank lines
        assert str(exc).startswith("no inputs:"), exc
        return
    expected = _expected(data, list_folder)
    if expected is not None:
        assert found == expected
    assert found and all(p.is_absolute() and p.is_file() for p in found)


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


# ================================================================ glTF references


def _gltf(folder, *uris):
    import json

    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "model.gltf"
    path.write_text(json.dumps({"asset": {"version": "2.0"}, "buffers": [{"uri": u, "byteLength": 4} for u in uris],
                                "images": [{"uri": "data:image/png;base64,AAAA"}, {"bufferView": 0}]}))
    return path


def test_gltf_references_are_confined_to_its_folder(tmp_path):
    (tmp_path / "secret.bin").write_bytes(b"1234")
    (tmp_path / "m" / "tex").mkdir(parents=True)
    (tmp_path / "m" / "tex" / "a b.bin").write_bytes(b"1234")
    good = _gltf(tmp_path / "m", "tex/a%20b.bin", "tex/../tex/a b.bin")
    assert _gltf_references(good) == [(tmp_path / "m" / "tex" / "a b.bin").resolve()] * 2
    for uri in ("../secret.bin", "%2e%2e/secret.bin", str(tmp_path / "secret.bin"), "file:///etc/passwd",
                "http://example.org/x.bin"):
        gltf = _gltf(tmp_path / "m", "tex/a%20b.bin", uri)
        with pytest.raises(InputError) as caught:
            _gltf_references(gltf)
        message = str(caught.value)
        assert message.startswith(f"{gltf}: buffers[1].uri") and "\n" not in message, message
    outside = _gltf(tmp_path / "m", "../secret.bin")
    assert _gltf_references(outside, allowed_roots=[tmp_path]) == [(tmp_path / "secret.bin").resolve()]
    (tmp_path / "m" / "link.bin").symlink_to(tmp_path / "secret.bin")
    with pytest.raises(InputError, match="lies outside its own folder"):
        _gltf_references(_gltf(tmp_path / "m", "link.bin"))


def test_a_render_record_refuses_a_gltf_reaching_outside(tmp_path):
    from pbrkit.rendering.scene import GltfObject

    gltf = _gltf(tmp_path / "m", "../../../../../../../../etc/hostname")
    scene = SimpleNamespace(environment=SimpleNamespace(file=None, bake=None), objects=[GltfObject(file=str(gltf))])
    with pytest.raises(InputError, match=r"buffers\[0\]\.uri .* lies outside its own folder"):
        _scene_references(scene, None)
    garbage = tmp_path / "g" / "model.gltf"
    garbage.parent.mkdir()
    garbage.write_text("[" * 100000)  # JSON nested too deep: no references (the renderer refuses the file)
    scene.objects = [GltfObject(file=str(garbage))]
    assert [r[0] for r in _scene_references(scene, None)] == ["gltf"]


def test_batch_render_takes_allow_roots_as_pbrkit_render_does(tmp_path, monkeypatch):
    """--allow-root of a render batch: each folder made absolute in the job options (which
    reach command_scene and the record's references); a path that is not a folder is
    refused with one line naming the flag before any work."""
    from pbrkit.app.batch import render_jobs_options

    (tmp_path / "shared").mkdir()
    monkeypatch.chdir(tmp_path)
    assert render_jobs_options(allow_roots=["shared"])["allow_roots"] == [str(tmp_path / "shared")]
    assert render_jobs_options()["allow_roots"] == []
    with pytest.raises(ValueError, match="--allow-root .*missing.* is not a folder"):
        render_jobs_options(allow_roots=["missing"])
    result = invoke("batch", "render", "spheres", "-o", str(tmp_path / "out"), "--allow-root", "missing")
    assert result.exit_code != 0
    assert "--allow-root" in one_error_line(result) and not (tmp_path / "out").exists()


def test_batch_render_refuses_a_style_outside_real_time_before_any_work(tmp_path):
    """--style with --mode reference or compare is refused with the other options (as
    pbrkit render refuses it), not job by job; --style pbr (no style) passes."""
    from pbrkit.app.batch import render_jobs_options

    for mode in ("reference", "compare"):
        with pytest.raises(ValueError, match="--style toon .*applies to --mode realtime only"):
            render_jobs_options(mode=mode, style="toon")
        assert render_jobs_options(mode=mode, style="pbr")["style"] == "pbr"
    assert render_jobs_options(style="toon")["style"] == "toon"
    result = invoke("batch", "render", "spheres", "-o", str(tmp_path / "out"), "--mode", "reference", "--style",
                    "toon")
    assert "--style" in one_error_line(result) and not (tmp_path / "out").exists()


def test_a_glob_is_bounded_by_the_paths_it_may_match(tmp_path, monkeypatch):
    """A pattern (on the command line or in a --list file) that matches more than
    MAX_GLOB_PATHS paths is refused naming the pattern, without collecting them all
    (``/**`` would name every path of the machine)."""
    from pbrkit.app import batch

    for i in range(6):
        (tmp_path / f"m{i}.hdr").write_bytes(b"")
    monkeypatch.setattr(batch, "MAX_GLOB_PATHS", 5)
    with pytest.raises(InputError, match=r"the pattern matches more than 5 paths; narrow it"):
        expand_inputs([str(tmp_path / "*.hdr")], [], "bake")
    monkeypatch.setattr(batch, "MAX_GLOB_PATHS", 6)
    assert [p.name for p in expand_inputs([str(tmp_path / "*.hdr")], [], "bake")] == [f"m{i}.hdr" for i in range(6)]
