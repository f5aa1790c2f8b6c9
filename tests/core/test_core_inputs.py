"""pbrkit.core.inputs: regular files only, bounded reads, confined paths, memory
checked before allocating, and messages that never quote a file."""

import os
import socket

import pytest

from pbrkit.core.errors import InputError
from pbrkit.core.inputs import (Confinement, check_allocation, check_regular, confined_path, describe, read_bytes,
                                read_text, size_text)


def test_special_files_are_refused_also_behind_a_link(tmp_path):
    link = tmp_path / "scene.toml"
    link.symlink_to("/dev/zero")
    for path in ("/dev/zero", link, tmp_path):
        with pytest.raises(InputError, match="not a regular file"):
            read_bytes(path, 1 << 20, "a scene file")
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="named pipe"):  # refused without opening (which would block)
        read_text(fifo)
    sock_path = tmp_path / "s"
    with socket.socket(socket.AF_UNIX) as s:
        s.bind(str(sock_path))
        with pytest.raises(InputError, match="socket"):
            check_regular(sock_path)
    with pytest.raises(InputError, match="file not found"):
        read_bytes(tmp_path / "missing", 10)


def test_reads_are_bounded_by_the_limit_with_both_figures(tmp_path):
    f = tmp_path / "big.json"
    f.write_bytes(b"x" * 3000)
    assert read_bytes(f, 3000) == b"x" * 3000
    with pytest.raises(InputError, match=r"2 KiB is more than the 1000 bytes that a style file may hold"):
        read_bytes(f, 1000, "a style file")


def test_errors_never_quote_the_file(tmp_path):
    secret = "root:x:0:0:SECRET-LINE\n"
    f = tmp_path / "passwd"
    f.write_bytes(secret.encode() + b"\xff\xfe")
    with pytest.raises(InputError) as err:
        read_text(f)
    assert "SECRET" not in str(err.value) and "byte 23" in str(err.value)
    assert describe("a\x1b[31mred\n") == "'a\\x1b[31mred\\n'"
    assert len(describe("x" * 500)) == 60


def test_paths_named_by_an_asset_stay_under_its_folder(tmp_path):
    asset = tmp_path / "model"
    (asset / "textures").mkdir(parents=True)
    (asset / "textures" / "a b.png").write_bytes(b"")
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    (outside / "x.bin").write_bytes(b"")
    (asset / "escape.bin").symlink_to(outside / "x.bin")
    c = Confinement(asset)
    assert c.resolve("textures/a%20b.png", "images[0].uri") == (asset / "textures" / "a b.png").resolve()
    assert c.resolve("textures/../textures/a b.png", "u") == (asset / "textures" / "a b.png").resolve()
    for uri in ("../elsewhere/x.bin", "%2e%2e/elsewhere/x.bin", "..%2Felsewhere%2Fx.bin", "escape.bin",
                "textures/../../elsewhere/x.bin"):
        with pytest.raises(InputError, match="lies outside its own folder; allow another folder with --allow-root"):
            confined_path(uri, c, "buffers[0].uri", asset / "m.gltf")
    for uri in ("/etc/passwd", f"file://{outside}/x.bin", "file:///etc/passwd", "C:\\Windows\\x", "%2Fetc%2Fpasswd"):
        with pytest.raises(InputError, match="absolute path or file: URI"):
            confined_path(uri, c, "buffers[0].uri", asset / "m.gltf")
    for uri in ("http://example.com/x.bin", "ftp:x"):
        with pytest.raises(InputError, match="only relative file paths and data: URIs"):
            confined_path(uri, c, "buffers[0].uri")
    allowed = Confinement(asset, [outside])
    assert allowed.resolve("../elsewhere/x.bin", "u") == (outside / "x.bin").resolve()
    assert allowed.resolve(str(outside / "x.bin"), "u") == (outside / "x.bin").resolve()
    assert allowed.resolve("escape.bin", "u") == (outside / "x.bin").resolve()
    with pytest.raises(InputError, match="lies outside its own folder or an allowed root"):
        allowed.resolve("/etc/passwd", "u")


def test_allocations_are_checked_against_the_memory_available():
    assert check_allocation(1000, "x", available=2000) == 1000
    with pytest.raises(InputError, match=r"accessors\[0\] would need about 1.5 GiB of memory; this machine has "
                                         r"100 MiB available; lower it"):
        check_allocation(3 << 29, "accessors[0]", "m.gltf", "lower it", available=100 << 20)
    assert size_text(80) == "80 bytes" and size_text(12 << 30) == "12 GiB"
