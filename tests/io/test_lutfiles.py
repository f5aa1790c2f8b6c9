"""Lookup-table files: every format read back by an independent reader, and the CLI."""

import json

import numpy as np
import png
import pytest
from typer.testing import CliRunner

from pbrkit.albedo.lut import lookup_table
from pbrkit.cli import app
from pbrkit.io.ktx2 import read_ktx2
from pbrkit.io.lut_files import QuantisationWarning, parse_header, write_lut


@pytest.fixture(scope="module")
def table():
    return lookup_table("dfg", 16, cloth=False)


@pytest.fixture(scope="module")
def cloth_table():
    return lookup_table("dfg", 8, cloth=True)


def _sidecar(path):
    return json.loads(path.with_name(path.name + ".json").read_text())


def test_npy_round_trip(tmp_path, table):
    t, spec = table
    write_lut(tmp_path / "lut.npy", t, spec)
    back = np.load(tmp_path / "lut.npy")
    assert back.dtype == np.float32 and back.shape == (16, 16, 2)
    np.testing.assert_array_equal(back, t)
    d = _sidecar(tmp_path / "lut.npy")
    assert d["kind"] == "dfg" and d["size"] == [16, 16] and d["visibility"] == "height-correlated"
    assert d["channels"] == ["DFG1", "DFG2"] and "row j" in d["axes"]


def test_exr_round_trip(tmp_path, cloth_table):
    import OpenEXR

    t, spec = cloth_table
    write_lut(tmp_path / "lut.exr", t, spec)
    with OpenEXR.File(str(tmp_path / "lut.exr")) as f:
        rgb = f.channels()["RGB"].pixels
    assert rgb.dtype == np.float32
    np.testing.assert_array_equal(rgb, t)


def test_png_is_16_bit_linear_and_warns(tmp_path, table):
    t, spec = table
    with pytest.warns(QuantisationWarning):
        write_lut(tmp_path / "lut.png", t, spec)
    width, height, rows, info = png.Reader(filename=str(tmp_path / "lut.png")).asDirect()
    assert info["bitdepth"] == 16 and (width, height) == (16, 16)
    a = np.array([np.asarray(r) for r in rows], dtype=float).reshape(16, 16, 3) / 65535.0
    np.testing.assert_allclose(a[..., :2], t, atol=0.5 / 65535 + 1e-9)
    assert np.all(a[..., 2] == 0.0)


def test_header_parses_back_to_the_same_float16(tmp_path, table):
    t, spec = table
    write_lut(tmp_path / "lut.h", t, spec)
    text = (tmp_path / "lut.h").read_text()
    back = parse_header(text)
    np.testing.assert_array_equal(back.view(np.uint16), t.astype(np.float16).view(np.uint16))
    # Row 0 first: the first value is DFG1 at (n.v, r) = (0.5/16, 0.5/16), the smooth grazing texel.
    first = int(text.split("= {")[1].split(",")[0], 16)
    assert first == int(t[0, 0, 0].astype(np.float16).view(np.uint16))
    assert "#define PBRKIT_DFG_LUT_WIDTH 16" in text and "GL_RG16F" in text


@pytest.mark.parametrize("fmt,dtype", [("float16", np.float16), ("float32", np.float32)])
def test_ktx2_round_trip(tmp_path, table, fmt, dtype):
    t, spec = table
    write_lut(tmp_path / "lut.ktx2", t, spec, ktx2_format=fmt)
    header, levels, kv = read_ktx2(tmp_path / "lut.ktx2")
    assert header["vkFormat"] == (83 if fmt == "float16" else 103)
    assert header["faceCount"] == 1 and len(levels) == 1
    np.testing.assert_array_equal(levels[0].reshape(t.shape), t.astype(dtype).astype(np.float32))
    embedded = json.loads(kv["pbrkit.lut"].rstrip("\0"))
    assert embedded["kind"] == "dfg" and embedded["vk_format"] in ("R16G16_SFLOAT", "R32G32_SFLOAT")


def test_cli_writes_and_is_deterministic(tmp_path):
    runner = CliRunner()
    for k in range(2):
        result = runner.invoke(app, ["lut", "--kind", "splitsum", "--size", "16", "-o", str(tmp_path / f"a{k}.ktx2")])
        assert result.exit_code == 0, result.output
    assert (tmp_path / "a0.ktx2").read_bytes() == (tmp_path / "a1.ktx2").read_bytes()
    d = _sidecar(tmp_path / "a0.ktx2")
    assert d["kind"] == "splitsum" and d["visibility"] == "schlick-ggx" and d["channels"] == ["A", "B"]


@pytest.mark.parametrize("args", [
    ["--size", "0"],
    ["--size", "100000"],
    ["--kind", "nope"],
    ["--visibility", "nope"],
    ["--samples", "1"],
    ["--ktx2-format", "float8"],
])
def test_cli_rejects_bad_options_without_output(tmp_path, args):
    out = tmp_path / "lut.ktx2"
    result = CliRunner().invoke(app, ["lut", "-o", str(out), *args])
    assert result.exit_code == 1
    assert "error" in result.output
    assert list(tmp_path.iterdir()) == []


def test_cli_rejects_unknown_suffix(tmp_path):
    result = CliRunner().invoke(app, ["lut", "-o", str(tmp_path / "lut.txt")])
    assert result.exit_code == 1 and "unsupported table format" in result.output
    assert list(tmp_path.iterdir()) == []
