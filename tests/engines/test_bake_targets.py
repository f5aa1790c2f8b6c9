"""Engine targets of a bake (``pbrkit bake --target``, issue 10, first step): the
Khronos glTF Sample Viewer's inputs derived from the generic bake, checked against
the generic files and an independent relation of the tables."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from typer.testing import CliRunner

from pbrkit.cli import app
from pbrkit.core.errors import InputError
from pbrkit.engines import ENGINES, LOAD_BASE
from pbrkit.ibl.bake import bake
from pbrkit.io.bake_files import TARGETS, chains_for, load_bake, load_target_chain, parse_targets, write_bake
from pbrkit.io.ktx2 import read_ktx2
from pbrkit.io.pfm import write_pfm

SMALL = ["--size", "16", "--min-size", "4", "--irradiance-size", "8", "--lut-size", "16"]


def _sky(h=16):
    img = np.full((h, 2 * h, 3), 0.5, np.float32)
    img[: h // 2] += np.linspace(0.2, 1.5, 2 * h, dtype=np.float32)[None, :, None]
    return img


@pytest.fixture(scope="module")
def baked(tmp_path_factory):
    root = tmp_path_factory.mktemp("targets")
    env = root / "sky.pfm"
    write_pfm(env, _sky())
    runner = CliRunner()
    generic = root / "generic"
    both = root / "both"
    for out, extra in ((generic, []), (both, ["--target", "generic,khronos"])):
        result = runner.invoke(app, ["bake", str(env), "-o", str(out), *SMALL, *extra, "-q"])
        assert result.exit_code == 0, result.output
    return generic, both


def test_parse_targets():
    assert parse_targets(None) == ("generic",)
    assert parse_targets(["khronos"]) == ("generic", "khronos")  # the generic files are always written
    assert parse_targets(["khronos,generic", "generic"]) == ("generic", "khronos")
    assert parse_targets(["three", "babylon,filament"]) == ("generic", "filament", "babylon", "three")
    assert parse_targets(["all"]) == TARGETS
    with pytest.raises(ValueError, match="unknown target 'unreal'"):
        parse_targets(["generic,unreal"])


def test_generic_files_are_unchanged_by_a_target(baked):
    generic, both = baked
    for name in ("specular.ktx2", "specular.dds", "irradiance.ktx2", "brdf_lut.npy", "faces/specular_m1_px.exr"):
        assert (generic / name).read_bytes() == (both / name).read_bytes(), name
    assert not (generic / "khronos").exists()
    assert "targets" not in json.loads((generic / "manifest.json").read_text())


def test_khronos_files_follow_the_sample_viewer_conventions(baked):
    _, both = baked
    entry = json.loads((both / "manifest.json").read_text())["targets"]["khronos"]
    files = {k: both / v for k, v in entry["files"].items()}
    # the specular chain is the generic one (same layout, lod = r (M - 1))
    _, spec_k, _ = read_ktx2(files["specular"])
    _, spec_g, _ = read_ktx2(both / "specular.ktx2")
    assert len(spec_k) == len(spec_g) == 3
    for a, b in zip(spec_k, spec_g):
        np.testing.assert_array_equal(a, b)
    # the Lambertian cube is radiance E / pi: the generic irradiance divided by pi, to half-float rounding
    _, (lam,), _ = read_ktx2(files["lambertian"])
    _, (irr,), _ = read_ktx2(both / "irradiance.ktx2")
    np.testing.assert_allclose(lam[..., :3] * np.pi, irr[..., :3], rtol=2e-3)
    # the LUT is (A, B) with albedo F0 A + B of the height-correlated lobe: A + B = DFG2 and B = DFG1 of the
    # generic table (another integral of the same lobe), to half-float rounding
    _, (lut,), _ = read_ktx2(files["lut"])
    dfg = np.load(both / "brdf_lut.npy")
    np.testing.assert_allclose(lut[..., 0] + lut[..., 1], dfg[..., 1], atol=2e-3)
    np.testing.assert_allclose(lut[..., 1], dfg[..., 0], atol=1e-3)
    assert json.loads(files["lut_description"].read_text())["visibility"] == "height-correlated"


def test_generic_bake_records_the_sheen_chain_and_table(baked):
    """The manifest names each sheen file, its layout and level curve; the chain has the
    specular chain's level count at sheen roughness m / (M - 1) and halving sizes."""
    generic, _ = baked
    manifest = json.loads((generic / "manifest.json").read_text())
    outputs = manifest["outputs"]
    sheen, table = outputs["sheen"], outputs["sheen_lut"]
    levels = outputs["specular"]["levels"]
    assert sheen["ktx2"]["path"] == "sheen.ktx2" and sheen["dds"]["path"] == "sheen.dds"
    assert sheen["levels"] == levels and sheen["level_curve"] == "linear"
    assert sheen["sheen_roughness"] == pytest.approx([m / (levels - 1) for m in range(levels)])
    assert "r = m / (M - 1)" in sheen["sheen_roughness_of_level"]
    assert [e["size"] for e in sheen["level_info"]] == [sheen["size"] >> m for m in range(levels)]
    _, chain, kv = read_ktx2(generic / sheen["ktx2"]["path"])
    assert len(chain) == levels and chain[0].shape == (6, sheen["size"], sheen["size"], 4)
    assert json.loads(kv["pbrkit.bake"])["sheen_roughness"] == sheen["sheen_roughness"]
    assert table["npy"]["path"] == "sheen_lut.npy" and table["ktx2"]["path"] == "sheen_lut.ktx2"
    assert table["description"]["channels"] == ["E_sheen", "E_ashikhmin"]
    assert table["description"]["axes"]["column i"] == "n.v = (i + 0.5) / N"
    lut = np.load(generic / "sheen_lut.npy")
    assert lut.shape == (16, 16, 2) and lut.dtype == np.float32
    assert json.loads((generic / "sheen_lut.npy.json").read_text())["kind"] == "sheen"


def test_khronos_sheen_files(baked):
    """charlie.ktx2 is the generic sheen chain byte for byte; lut_charlie holds E_sheen in
    blue (what getIBLRadianceCharlie reads) and lut_sheen_E in red (albedoSheenScalingLUT),
    both the generic table's E_sheen to half-float rounding."""
    _, both = baked
    entry = json.loads((both / "manifest.json").read_text())["targets"]["khronos"]
    files = {k: both / v for k, v in entry["files"].items()}
    assert files["sheen"].read_bytes() == (both / "sheen.ktx2").read_bytes()
    _, (charlie,), _ = read_ktx2(files["sheen_lut"])
    _, (sheen_e,), _ = read_ktx2(files["sheen_e_lut"])
    e = np.load(both / "sheen_lut.npy")[..., 0]
    assert charlie.shape == (16, 16, 4) and sheen_e.shape == (16, 16, 2)
    np.testing.assert_allclose(charlie[..., 2], e, rtol=1e-3, atol=1e-4)
    np.testing.assert_allclose(sheen_e[..., 0], e, rtol=1e-3, atol=1e-4)
    assert not charlie[..., :2].any() and np.all(charlie[..., 3] == 1.0) and not sheen_e[..., 1].any()
    conventions = entry["conventions"]
    assert ".b" in conventions["sheen_lut"] and ".r" in conventions["sheen_e_lut"]
    assert "u_MipCount" in conventions["sheen"]


def test_khronos_module_binds_the_sheen_files(baked):
    """pbrkit-khronos.js fetches the three sheen files and binds them as sheenEnvMap,
    sheenLUT and sheenELUT, black only when a file is absent."""
    _, both = baked
    js = (both / "khronos" / "pbrkit-khronos.js").read_text()
    for name in ("charlie.ktx2", "lut_charlie.ktx2", "lut_sheen_E.ktx2"):
        assert name in js
    assert 'add("sheenEnvMap", sheen ? uploadPbrkitKTX2(gl, sheen) : blank(gl, true, 4), true);' in js
    assert 'add("sheenLUT", sheenLut ? uploadPbrkitKTX2(gl, sheenLut) : blank(gl, false, 4), false);' in js
    assert 'add("sheenELUT", sheenE ? uploadPbrkitKTX2(gl, sheenE) : blank(gl, false, 4), false);' in js
    assert "response.status === 404" in js and "u_MipCount" in js


def test_unknown_target_is_refused_cleanly(tmp_path):
    env = tmp_path / "sky.pfm"
    write_pfm(env, _sky())
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["bake", str(env), "-o", str(out), *SMALL, "--target", "unreal"])
    assert result.exit_code == 1
    assert result.stderr.strip().startswith("pbrkit: error:") and "unknown target 'unreal'" in result.stderr
    assert not out.exists()


# ------------------------------------------------- engines' files alone, load lines


@pytest.fixture(scope="module")
def every_target(tmp_path_factory):
    """One bake written with every target beside the generic files, and once per
    engine with that engine's files alone (``only_targets``)."""
    root = tmp_path_factory.mktemp("every")
    write_pfm(root / "sky.pfm", _sky())
    b = bake(root / "sky.pfm", size=16, min_size=4, irradiance_size=8, lut_size=16, chains=chains_for(["all"]))
    full = write_bake(b, root / "full", targets=["all"])
    only = {name: write_bake(b, root / f"only-{name}", targets=[name], only_targets=True) for name in ENGINES}
    return b, full, only


def _files(root):
    return {p.relative_to(root).as_posix() for p in root.rglob("*") if p.is_file()}


def _flat(files):
    """The paths of a manifest entry's ``files`` (a dict of paths)."""
    return [v for value in files.values() for v in (_flat(value) if isinstance(value, dict) else [value])]


@pytest.mark.parametrize("name", list(ENGINES))
def test_only_targets_writes_the_engines_files_and_the_manifest_alone(every_target, name):
    _, full, only = every_target
    folder = only[name]
    engine_files = {f for f in _files(full) if f.startswith(f"{name}/")}
    assert _files(folder) == engine_files | {"manifest.json"}  # no generic file, no other engine's
    for f in engine_files:  # the same bytes as beside the generic files: nothing reads those
        assert (folder / f).read_bytes() == (full / f).read_bytes(), f
    manifest = json.loads((folder / "manifest.json").read_text())
    assert manifest["only_targets"] is True and list(manifest["targets"]) == [name]
    assert manifest["targets"][name] == json.loads((full / "manifest.json").read_text())["targets"][name]
    for f in _flat(manifest["targets"][name]["files"]):
        assert (folder / f).is_file(), f
    with pytest.raises(InputError, match="engine-only bake") as info:
        load_bake(folder)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("name", [n for n, e in ENGINES.items() if e.chain_file])
def test_an_engine_only_bake_gives_the_engine_its_chain(every_target, name):
    """What ``render --engine`` reads from a bake folder (the engine's chain file, at
    its own levels, mirrored back) is there without the generic files, and is the
    bake's chain of the engine's curve."""
    b, full, only = every_target
    chain = load_target_chain(only[name], name)
    expected = b.chains[ENGINES[name].curve]
    np.testing.assert_allclose(chain.roughness, expected.roughness, atol=1e-12)
    for got, want in zip(chain.levels, expected.levels):
        np.testing.assert_allclose(got, want, rtol=0.07, atol=1e-3)  # R11G11B10 / float16 / RGBA16F texels


def test_an_engine_only_khronos_bake_holds_the_generic_chains(every_target):
    """The Sample Viewer samples pbrkit's own chain: the khronos folder holds the
    generic specular.ktx2 and sheen.ktx2, byte for byte, when they are not written."""
    _, full, only = every_target
    folder = only["khronos"] / "khronos"
    assert (folder / "specular.ktx2").read_bytes() == (full / "specular.ktx2").read_bytes()
    assert (folder / "charlie.ktx2").read_bytes() == (full / "sheen.ktx2").read_bytes()


def _load_paths(load):
    """The quoted paths of a load line (strings with a slash: files and folders)."""
    return [p for p in re.findall(r"'([^'\s]+)'", load) if "/" in p]


def test_load_lines_name_paths_relative_to_the_bake_folder(every_target):
    """Every target's load line states its base, the bake folder, and every path in it
    is there relative to that folder, inside the engine's own subfolder (the ES module
    import and the fetched textures alike), with and without the generic files."""
    _, full, only = every_target
    for root in (full, *only.values()):
        targets = json.loads((root / "manifest.json").read_text())["targets"]
        for name, entry in targets.items():
            assert entry["load_base"] == LOAD_BASE and "bake folder" in LOAD_BASE
            paths = _load_paths(entry["load"])
            assert paths, name
            for p in paths:
                relative = p[2:] if p.startswith("./") else p
                assert relative.startswith(f"{name}/"), (name, p)
                assert (root / relative).is_dir() if p.endswith("/") else (root / relative).is_file(), (name, p)
    assert "'./three/pbrkit-three.js'" in json.loads((full / "manifest.json").read_text())["targets"]["three"]["load"]


def test_an_engine_only_bake_without_an_engine_writes_nothing(every_target, tmp_path):
    b, _, _ = every_target
    for targets in (["generic"], [], ["generic,three"]):
        with pytest.raises(ValueError) as info:
            write_bake(b, tmp_path / "out", targets=targets, only_targets=True)
        assert "\n" not in str(info.value) and "engine" in str(info.value)
        assert not (tmp_path / "out").exists()
