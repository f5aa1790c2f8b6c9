"""The engine table (:mod:`pbrkit.engines`): its names are the choices' own, each
engine's pinned version is the one the in-engine tests install (the lock file) and
the notes cite, its level curve is its shader's lod formula (written out here from
the engines' shaders, docs/engine-targets.md), and targets parse as ``--target``
and ``--only-target`` take them."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from pbrkit import engines
from pbrkit.choices import BAKE_TARGETS, RENDER_ENGINES
from pbrkit.engines import ENGINES, chains_for, engine, parse_targets

REPOSITORY = Path(__file__).resolve().parents[2]
PACKAGE_JSON = REPOSITORY / "tests" / "engines" / "package.json"
LOCK = REPOSITORY / "tests" / "engines" / "package-lock.json"
NOTES = REPOSITORY / "docs" / "engine-targets.md"


def test_the_table_holds_the_choices_names():
    assert tuple(ENGINES) == tuple(n for n in RENDER_ENGINES if n != "pbrkit")
    assert set(ENGINES) == set(BAKE_TARGETS) - {"generic"}
    assert engines.TARGETS is BAKE_TARGETS
    for name, e in ENGINES.items():
        assert e.name == name and RENDER_ENGINES[e.code] == name
        assert engine(name) is e
        assert getattr(engines, name).ENGINE is e  # the module declares it


def test_an_unknown_engine_is_one_line_naming_the_choices():
    with pytest.raises(ValueError) as info:
        engine("unreal")
    message = str(info.value)
    assert "\n" not in message and "'unreal'" in message
    assert "filament, khronos, three, babylon" in message
    with pytest.raises(ValueError, match="choose one of"):
        engine(None)


@pytest.mark.parametrize("name", list(ENGINES))
def test_pinned_version_is_the_one_the_engine_tests_install(name):
    e = ENGINES[name]
    assert json.loads(PACKAGE_JSON.read_text())["dependencies"][e.npm] == e.version
    if LOCK.exists():
        lock = json.loads(LOCK.read_text())
        assert lock["packages"][f"node_modules/{e.npm}"]["version"] == e.version
    if NOTES.exists():  # the notes' table of the sources read
        rows = [line for line in NOTES.read_text().splitlines() if line.startswith("|") and f"`{e.npm}`"
                in line.replace("@babylonjs/core", "babylonjs")]
        assert rows and all(e.version in row for row in rows), (name, rows)


@pytest.mark.parametrize("roughness", [0.0, 0.05, 0.3, 0.5, 0.8, 1.0])
def test_level_curves_are_the_shaders_lod(roughness):
    """Filament's and three's lod = (M - 1) r (2 - r) (perceptualRoughnessToLod,
    envmap_common_pars_fragment), the Sample Viewer's r (M - 1), Babylon's
    0.8 log2(N (r^2 + 0.0005)) clamped at 0."""
    levels, size = 7, 64
    expected = {
        "filament": (levels - 1) * roughness * (2 - roughness),
        "three": (levels - 1) * roughness * (2 - roughness),
        "khronos": roughness * (levels - 1),
        "babylon": max(0.0, 0.8 * math.log2(size * (roughness ** 2 + 0.0005))),
    }
    for name, e in ENGINES.items():
        assert e.lod(roughness, levels, size) == pytest.approx(expected[name], abs=1e-12), name
    lods = ENGINES["three"].lod(np.array([0.0, 0.5, 1.0]), levels, size)
    np.testing.assert_allclose(lods, [0.0, 4.5, 6.0])


def test_each_engine_samples_its_curves_chain():
    assert {n: e.extra_chain for n, e in ENGINES.items()} == {
        "filament": "filament", "khronos": None, "three": "filament", "babylon": "babylon"}
    assert chains_for(["khronos"]) == ()
    assert chains_for(["three"]) == ("filament",)
    assert chains_for(["all"]) == ("filament", "babylon")
    # the engines whose chain is their own keep it in their folder, mirrored as their lookups
    assert {n: (e.chain_file, e.mirror) for n, e in ENGINES.items()} == {
        "filament": ("filament/ibl.ktx", None), "khronos": (None, None),
        "three": ("three/specular.ktx2", "x"), "babylon": ("babylon/specular.dds", "z")}


def test_shading_of_a_white_metal_in_a_white_furnace_is_energy_conserving():
    """f0 = 1 under constant radiance L = 1 (E = pi): each engine's own
    multiple-scattering term returns 1 whatever (A, B) the table gives."""
    for a, b in ((0.9, 0.05), (0.6, 0.1), (0.3, 0.2)):
        for name in ("khronos", "three", "babylon"):
            value = ENGINES[name].shading(1.0, 1.0, 0.5, 0.7, a, b, 1.0, math.pi)
            assert value == pytest.approx(1.0, abs=1e-12 if name != "babylon" else 1e-6), (name, a, b)
    # Filament's diffuse weight is (1 - E) / pi
    assert ENGINES["filament"].shading(0.25) == pytest.approx(0.75 / math.pi)


def test_parse_targets_with_and_without_the_generic_files():
    assert parse_targets(["three"]) == ("generic", "three")
    assert parse_targets(["three"], only_targets=True) == ("three",)
    assert parse_targets(["babylon,three", "filament"], only_targets=True) == ("filament", "babylon", "three")
    assert parse_targets(["all"], only_targets=True) == tuple(t for t in BAKE_TARGETS if t != "generic")
    # what parse_targets returns parses to itself (write_bake parses its targets again)
    for only in (False, True):
        once = parse_targets(["all"], only_targets=only)
        assert parse_targets(once, only_targets=only) == once
    for values, match in (([], "needs an engine"), (None, "needs an engine"),
                          (["generic,three"], "name engines only"), (["unreal"], "unknown target 'unreal'")):
        with pytest.raises(ValueError, match=match) as info:
            parse_targets(values, only_targets=True)
        assert "\n" not in str(info.value)


def test_render_engine_looks_the_table_up():
    from pbrkit.rendering.realtime import ENGINES as RENDER_CHOICES
    from pbrkit.rendering.realtime import render_engine

    assert render_engine("pbrkit") is None
    for name in ENGINES:
        assert render_engine(name) is ENGINES[name]
    with pytest.raises(ValueError, match="use one of pbrkit, filament, khronos, three, babylon") as info:
        render_engine("unreal")
    assert "\n" not in str(info.value) and RENDER_CHOICES is RENDER_ENGINES
