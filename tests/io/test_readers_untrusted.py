"""The file readers take their input as untrusted (the "Untrusted input" issue).

Every reader (images, environments, texture containers, the bake's files, LTC
tables, MERL BRDFs): opens only regular files (a device such as /dev/zero, a
named pipe or a folder is refused at once, also behind a symbolic link); never
quotes the file in a message (a ``/etc/passwd``-like file, bare or behind each
format's own signature, is refused without any of its text); refuses a header
declaring an absurd size, or more than the file can hold, before allocating
(the peak traced by :mod:`tracemalloc` stays small); and the command line
refuses such files with one ``pbrkit: error:`` line and a non-zero exit.
The property-based (fuzzing) half is tests/io/test_readers_fuzz.py.
"""

from __future__ import annotations

import json
import os
import struct
import tracemalloc
import zlib

import numpy as np
import pytest
from typer.testing import CliRunner

import pbrkit.core.inputs
from pbrkit.cli import app
from pbrkit.core.errors import InputError
from pbrkit.io.babylon_env import ENV_MAGIC, read_babylon_env
from pbrkit.io.bake_files import load_bake
from pbrkit.io.dds import dds_bytes, read_dds
from pbrkit.io.environment import load_environment
from pbrkit.io.exr import exr_bytes, read_exr
from pbrkit.io.hdr import read_hdr
from pbrkit.io.images import read_image
from pbrkit.io.ktx1 import KTX1_IDENTIFIER, ktx1_bytes, read_ktx1
from pbrkit.io.ktx2 import KTX2_IDENTIFIER, ktx2_bytes, read_ktx2
from pbrkit.io.ltc_files import read_ltc_npy
from pbrkit.io.npy_files import read_npy
from pbrkit.io.pfm import read_pfm
from pbrkit.io.png import PNG_SIGNATURE, png_chunk, read_ldr
from pbrkit.measured.merl import read_merl

SECRET = b"root:x:0:0:SECRET-LINE:/root:/bin/bash\ndaemon:x:1:1:SECRET-TWO:/usr/sbin\n"

#: name -> (reader, suffix)
READERS = {
    "image": (read_image, ".hdr"),
    "hdr": (read_hdr, ".hdr"),
    "pfm": (read_pfm, ".pfm"),
    "exr": (read_exr, ".exr"),
    "ldr": (read_ldr, ".png"),
    "environment": (load_environment, ".hdr"),
    "ktx1": (read_ktx1, ".ktx"),
    "ktx2": (read_ktx2, ".ktx2"),
    "dds": (read_dds, ".dds"),
    "babylon_env": (read_babylon_env, ".env"),
    "npy": (read_npy, ".npy"),
    "ltc": (read_ltc_npy, ".npy"),
    "merl": (read_merl, ".binary"),
}


def refusal(read, path):
    """The InputError ``read(path)`` raises, checked: one line naming ``path``."""
    with pytest.raises(InputError) as info:
        read(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{path}: "), message
    return message


def assert_quotes_nothing(message, secret=SECRET):
    """No 5-byte run of ``secret`` appears in ``message`` (whatever its encoding)."""
    text = secret.decode("latin-1")
    for i in range(len(text) - 4):
        piece = text[i:i + 5]
        if piece.strip() and piece not in ("/bin/", ":/usr"):
            assert piece not in message, (piece, message)
    assert "SECRET" not in message and "\\x" not in message and "b'" not in message, message


# ------------------------------------------------------------------ special files


@pytest.mark.parametrize("name", sorted(READERS))
def test_devices_pipes_and_folders_are_refused_also_behind_a_link(tmp_path, name):
    read, suffix = READERS[name]
    link = tmp_path / f"zero{suffix}"
    link.symlink_to("/dev/zero")
    fifo = tmp_path / f"pipe{suffix}"
    os.mkfifo(fifo)  # opening it would block: it must be refused before
    folder = tmp_path / f"folder{suffix}"
    folder.mkdir()
    for path, kind in (("/dev/zero", "character device"), (link, "character device"), (fifo, "named pipe"),
                       (folder, "folder")):
        message = refusal(read, path)
        assert f"is a {kind}, not a regular file; expected" in message, message
    message = refusal(read, tmp_path / f"absent{suffix}")
    assert "not found" in message or "no such" in message, message


def test_a_bake_folder_with_a_device_for_a_manifest_or_table(tmp_path):
    (tmp_path / "manifest.json").symlink_to("/dev/zero")
    with pytest.raises(InputError, match=f"^{tmp_path / 'manifest.json'}: is a character device, not a regular"):
        load_bake(tmp_path)


# ------------------------------------------------------------------ secrets


def _with_magic():
    """Files that pass each format's signature and then hold the secret text."""
    ktx1 = KTX1_IDENTIFIER + struct.pack("<13I", 0x04030201, 0x140B, 2, 0x1908, 0x881A, 0x1908, 1, 1, 0, 0, 1, 1,
                                         len(SECRET) + (-len(SECRET) % 4)) + SECRET
    npy_header = b"{'descr': '" + SECRET[:20] + b"', 'fortran_order': False, 'shape': (2,), }"
    return {
        "hdr": [b"#?RADIANCE\nFORMAT=" + SECRET + b"\n-Y 2 +X 2\n", b"#?RADIANCE\n\n" + SECRET,
                b"#?RADIANCE\nEXPOSURE=" + SECRET + b"\n-Y 1 +X 1\n"],
        "pfm": [b"PF\n" + SECRET, b"Pf " + SECRET],
        "exr": [b"\x76\x2f\x31\x01\x02\x00\x00\x00" + SECRET,
                b"\x76\x2f\x31\x01\x02\x00\x00\x00" + SECRET.replace(b"\n", b"\x00") + b"box2i\x00\x10\x00\x00\x00"],
        "ldr": [PNG_SIGNATURE + SECRET, PNG_SIGNATURE + png_chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 2, 0, 0, 0))
                + png_chunk(b"IDAT", SECRET) + png_chunk(b"IEND", b""),
                b"\xff\xd8\xff\xe0" + SECRET],
        "ktx1": [KTX1_IDENTIFIER + SECRET, ktx1],
        "ktx2": [KTX2_IDENTIFIER + SECRET * 2],
        "dds": [b"DDS " + SECRET * 3],
        "babylon_env": [ENV_MAGIC + SECRET + b"\x00", ENV_MAGIC + b'{"version": "' + SECRET[:30] + b'"}\x00',
                        ENV_MAGIC + b'{"version": 2, "width": 1, "imageType": "' + SECRET[:20] + b'"}\x00',
                        ENV_MAGIC + SECRET.replace(b"root", b"\xff\xfe\xfd\xfc") + b"\x00"],
        "npy": [b"\x93NUMPY\x01\x00" + struct.pack("<H", len(npy_header)) + npy_header,
                b"\x93NUMPY\x01\x00" + SECRET],
        "merl": [SECRET * 3],
    }


@pytest.mark.parametrize("name", sorted(READERS))
def test_messages_never_quote_the_file(tmp_path, name):
    read, suffix = READERS[name]
    contents = [SECRET] + _with_magic().get({"image": "hdr", "environment": "hdr", "ltc": "npy"}.get(name, name), [])
    for i, data in enumerate(contents):
        path = tmp_path / f"passwd{i}{suffix}"
        path.write_bytes(data)
        assert_quotes_nothing(refusal(read, path).removeprefix(f"{path}: "))


def test_notes_of_a_radiance_header_quote_nothing(tmp_path):
    from pbrkit.io.images import read_image_with_notes

    path = tmp_path / "exposed.hdr"
    path.write_bytes(b"#?RADIANCE\nEXPOSURE=" + SECRET[:20] + b"\n\n-Y 1 +X 1\n\x80\x80\x80\x80")
    img, _, notes = read_image_with_notes(path)
    assert img.shape == (1, 1, 3) and "EXPOSURE= not applied" in " ".join(notes)
    assert_quotes_nothing(" ".join(notes))


# ------------------------------------------------------------------ absurd sizes


def _peak_of(fn):
    """(result or the exception, peak traced bytes) of ``fn()``."""
    tracemalloc.start()
    try:
        try:
            result = fn()
        except InputError as exc:
            result = exc
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    return result, peak


def _ktx2_declaring(width, height):
    data = bytearray(ktx2_bytes([np.ones((4, 4, 4), np.float32)], "R16G16B16A16_SFLOAT"))
    struct.pack_into("<2I", data, 20, width, height)
    n = (width * height * 8) & (2**64 - 1)
    struct.pack_into("<2Q", data, 80 + 8, n, n)  # level 0's byteLength and uncompressedByteLength, as declared
    return bytes(data)


def _dds_declaring(width, height):
    data = bytearray(dds_bytes([np.ones((4, 4, 4), np.float32)], "R16G16B16A16_FLOAT"))
    struct.pack_into("<3I", data, 12, height, width, width * 8)
    return bytes(data)


def _ktx1_declaring(width, height):
    data = bytearray(ktx1_bytes([np.ones((4, 4, 4), np.float32)], "RGBA16F"))
    struct.pack_into("<2I", data, 12 + 24, width, height)
    struct.pack_into("<I", data, 64, (width * height * 8) & 0xFFFFFFFF)
    return bytes(data)


def _png16_declaring(width, height):
    ihdr = struct.pack(">IIBBBBB", width, height, 16, 2, 0, 0, 0)
    return (PNG_SIGNATURE + png_chunk(b"IHDR", ihdr) + png_chunk(b"IDAT", zlib.compress(b"\x00" * 4000))
            + png_chunk(b"IEND", b""))


def _png8_declaring(width, height):
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (PNG_SIGNATURE + png_chunk(b"IHDR", ihdr) + png_chunk(b"IDAT", zlib.compress(b"\x00" * 4000))
            + png_chunk(b"IEND", b""))


def _exr_declaring(width, height):
    data = exr_bytes(np.ones((4, 8, 3), np.float32))
    key = b"dataWindow\x00box2i\x00"
    i = data.index(key) + len(key) + 4
    return data[:i] + struct.pack("<4i", 0, 0, width - 1, height - 1) + data[i + 16:]


def _npy_declaring(shape):
    header = repr({"descr": "<f4", "fortran_order": False, "shape": shape}).encode()
    header += b" " * (-(len(header) + 11) % 64) + b"\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header + b"\x00" * 64


def _env_declaring(width):
    levels = width.bit_length()
    manifest = {"version": 2, "width": width, "imageType": "image/png",
                "specular": {"mipmaps": [{"length": 10, "position": 0}] * (6 * levels)}}
    return ENV_MAGIC + json.dumps(manifest).encode() + b"\x00" + b"\x00" * 64


ABSURD = [
    # (reader, suffix, bytes, a fragment of the refusal)
    (read_hdr, ".hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 60000 +X 60000\n", "32768-pixel limit"),
    (read_hdr, ".hdr", b"#?RADIANCE\n\n-Y 16000 +X 32000\n" + b"\x01" * 4000, "need at least 192000 bytes"),
    (read_pfm, ".pfm", b"PF\n60000 60000\n-1.0\n" + b"\x00" * 64, "32768-pixel limit"),
    (read_pfm, ".pfm", b"PF\n32000 16000\n-1.0\n" + b"\x00" * 64, "truncated PFM data"),
    (read_exr, ".exr", _exr_declaring(60000, 60000), "32768-pixel limit"),
    (read_exr, ".exr", _exr_declaring(32000, 16000), "chunk table"),
    (read_ldr, ".png", _png16_declaring(60000, 60000), "32768-pixel limit"),
    (read_ldr, ".png", _png16_declaring(32000, 16000), "truncated PNG image data"),
    (read_ldr, ".png", _png8_declaring(60000, 60000), ""),
    (read_ktx2, ".ktx2", _ktx2_declaring(60000, 60000), "extends past the end of the file"),
    (read_ktx2, ".ktx2", _ktx2_declaring(0xFFFFFFFF, 0xFFFFFFFF), "byteLength"),
    (read_dds, ".dds", _dds_declaring(60000, 60000), "expected 28800000148"),
    (read_ktx1, ".ktx", _ktx1_declaring(60000, 60000), "imageSize"),
    (read_npy, ".npy", _npy_declaring((60000, 60000, 2)), "28800000000 bytes of data"),
    (read_babylon_env, ".env", _env_declaring(1 << 15), "after the manifest (truncated or corrupt)"),
    (read_babylon_env, ".env", _env_declaring(1 << 40), "more than 65536"),
]


@pytest.mark.parametrize("read, suffix, data, fragment", ABSURD)
def test_absurd_declared_sizes_are_refused_before_allocating(tmp_path, read, suffix, data, fragment):
    path = tmp_path / f"absurd{suffix}"
    path.write_bytes(data)
    result, peak = _peak_of(lambda: read(path))
    assert isinstance(result, InputError), result
    assert fragment in str(result), str(result)
    assert peak < 4 * len(data) + (1 << 20), f"{peak} bytes traced before the refusal"


def _big_flat_hdr(height, width):
    """A legitimate Radiance file of one colour: each scanline one flat pixel, then
    old-style run markers (Radiance ``freadcolrs``) for the rest: about 12 bytes a line."""
    rest, markers, shift = width - 1, b"", 0
    while rest:
        markers += bytes([1, 1, 1, rest >> shift & 255])
        rest -= (rest >> shift & 255) << shift
        shift += 8
    line = b"\x80\x80\x80\x81" + markers
    return b"#?RADIANCE\n\n" + f"-Y {height} +X {width}\n".encode() + line * height


def test_what_a_file_can_hold_legitimately_is_checked_against_the_memory(tmp_path, monkeypatch):
    small = tmp_path / "small.hdr"
    small.write_bytes(_big_flat_hdr(4, 300))
    img = read_hdr(small)
    assert img.shape == (4, 300, 3) and np.all(img == img[0, 0]) and img[0, 0, 0] == pytest.approx(1.0, rel=0.01)
    path = tmp_path / "big.hdr"
    path.write_bytes(_big_flat_hdr(16000, 32000))  # 192 KB for 512 M pixels
    monkeypatch.setattr(pbrkit.core.inputs, "available_memory", lambda: 64 << 20)
    result, peak = _peak_of(lambda: read_hdr(path))
    assert isinstance(result, InputError) and "would need about 21 GiB of memory" in str(result), result
    assert "64 MiB available" in str(result) and peak < (2 << 20)
    pfm = tmp_path / "big.pfm"
    pfm.write_bytes(b"Pf\n2048 2048\n-1.0\n" + b"\x00" * (4 * 2048 * 2048))
    monkeypatch.setattr(pbrkit.core.inputs, "available_memory", lambda: 20 << 20)
    assert "would need about 32 MiB" in refusal(read_pfm, pfm)  # 16 MiB of file, float copies beside it
    monkeypatch.setattr(pbrkit.core.inputs, "available_memory", lambda: 8 << 20)
    assert "reading the file (16 MiB) would need" in refusal(read_pfm, pfm)


def test_a_merl_file_must_have_the_length_its_header_declares(tmp_path):
    header = struct.pack("<3i", 90, 90, 180)
    path = tmp_path / "short.binary"
    path.write_bytes(header + b"\x00" * 800)
    result, peak = _peak_of(lambda: read_merl(path))
    assert "truncated MERL BRDF file: 812 bytes, expected the 34992012 its header declares" in str(result)
    assert peak < 1 << 20
    path.write_bytes(struct.pack("<3i", 90, 90, 181) + b"\x00" * (3 * 90 * 90 * 181 * 8))
    assert "header dimensions 90 x 90 x 181 (the file's length agrees); pbrkit reads" in refusal(read_merl, path)
    path.write_bytes(struct.pack("<3i", 60000, 60000, 60000) + b"\x00" * 800)
    assert "60000 x 60000 x 60000 (5184000000000012 bytes, the file has 812)" in refusal(read_merl, path)


# ------------------------------------------------------------------ the command line


def _cli_refuses(*args):
    result = CliRunner().invoke(app, [str(a) for a in args])
    assert result.exit_code not in (0, None), result.output
    assert isinstance(result.exception, SystemExit), repr(result.exception)
    assert "Traceback" not in result.output and result.stdout == ""
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("pbrkit: error: "), result.stderr
    return lines[0]


def test_the_command_line_refuses_special_and_secret_files_in_one_line(tmp_path):
    link = tmp_path / "sky.hdr"
    link.symlink_to("/dev/zero")
    secret = tmp_path / "passwd.hdr"
    secret.write_bytes(SECRET)
    small = ["--size", "16", "--min-size", "4", "--irradiance-size", "8", "--lut-size", "16"]
    for path in ("/dev/zero", link):
        line = _cli_refuses("bake", path, "-o", tmp_path / "out", *small)
        assert f"{path}: is a character device, not a regular file" in line
    line = _cli_refuses("bake", secret, "-o", tmp_path / "out", *small)
    assert str(secret) in line
    assert_quotes_nothing(line.split(f"{secret}: ", 1)[1])
    merl = tmp_path / "gold.binary"
    merl.write_bytes(SECRET)
    for path in ("/dev/zero", merl):
        line = _cli_refuses("explore", "--merl", path, "--static", "-o", tmp_path / "views")
        assert str(path) in line
        assert_quotes_nothing(line.split(f"{path}: ", 1)[1])
    assert not (tmp_path / "out").exists() and not (tmp_path / "views").exists()
