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
