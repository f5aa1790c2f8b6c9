"""The drop-in LTC table files (``pbrkit.io.ltc_files``, issue 11): the published
layout in every format, read back with pbrkit's readers, and the ES module checked
with three.js itself: fed three.js's own published tables, ``init(THREE)`` installs
textures identical to those of three.js's ``RectAreaLightUniformsLib``."""

from __future__ import annotations

import json
import os
import subprocess

import numpy as np
import pytest
from engine_pages import ENGINES, NODE, engines_missing

from pbrkit.io.dds import read_dds
from pbrkit.io.float_packing import to_float16
from pbrkit.io.ktx2 import read_ktx2
from pbrkit.io.ltc_files import LTC_FILES, read_ltc_npy, write_ltc_tables


def _tables(n=64, seed=3):
    rng = np.random.default_rng(seed)
    return (rng.normal(size=(n, n, 4)).astype(np.float32), rng.random((n, n, 4)).astype(np.float32))


def test_every_format_holds_the_table(tmp_path):
    ltc1, ltc2 = _tables()
    write_ltc_tables(tmp_path, ltc1, ltc2)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(LTC_FILES)
    for name, table in (("ltc_1", ltc1), ("ltc_2", ltc2)):
        np.testing.assert_array_equal(read_ltc_npy(tmp_path / f"{name}.npy"), table)
        header, (dds32,) = read_dds(tmp_path / f"{name}.rgba32f.dds")
        np.testing.assert_array_equal(dds32, table)
        _, (dds16,) = read_dds(tmp_path / f"{name}.rgba16f.dds")
        np.testing.assert_array_equal(dds16, to_float16(table).astype(np.float32))
        info, (k32,), _ = read_ktx2(tmp_path / f"{name}.rgba32f.ktx2")
        np.testing.assert_array_equal(k32, table)
        _, (k16,), _ = read_ktx2(tmp_path / f"{name}.rgba16f.ktx2")
        np.testing.assert_array_equal(k16, to_float16(table).astype(np.float32))
    # row 0 first in memory: the .npy's first row is the texture's first row
    raw = (tmp_path / "ltc_1.rgba32f.dds").read_bytes()
    np.testing.assert_array_equal(np.frombuffer(raw[-ltc1.nbytes:], "<f4").reshape(ltc1.shape), ltc1)


def test_bad_tables_and_files_are_refused(tmp_path):
    ltc1, ltc2 = _tables(8)
    with pytest.raises(ValueError, match="shape"):
        write_ltc_tables(tmp_path / "a", ltc1[..., :3], ltc2)
    bad = ltc2.copy()
    bad[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        write_ltc_tables(tmp_path / "b", ltc1, bad)
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()  # nothing written
    np.save(tmp_path / "x.npy", np.zeros((4, 4, 3)))
    with pytest.raises(ValueError, match=r"x\.npy.*shape"):
        read_ltc_npy(tmp_path / "x.npy")
    (tmp_path / "y.npy").write_bytes(b"not numpy")
    with pytest.raises(ValueError, match=r"y\.npy: not a \.npy file"):
        read_ltc_npy(tmp_path / "y.npy")


NODE_SCRIPT = """
import * as THREE from "three";
import { RectAreaLightTexturesLib } from "three/addons/lights/RectAreaLightTexturesLib.js";
import { readFileSync, writeFileSync } from "node:fs";
const [mode, folder] = process.argv.slice(2);
if (mode === "three") {
  RectAreaLightTexturesLib.init();
  const t = RectAreaLightTexturesLib;
  writeFileSync(folder + "/three.json", JSON.stringify({
    ltc1: Array.from(t.LTC_FLOAT_1.image.data), ltc2: Array.from(t.LTC_FLOAT_2.image.data),
    half1: Array.from(t.LTC_HALF_1.image.data), half2: Array.from(t.LTC_HALF_2.image.data)}));
} else {
  const m = await import(folder + "/ltc_tables.js");
  const u = m.init(THREE);
  const same = (a, b) => a.length === b.length && a.every((x, i) => Object.is(x, b[i]));
  const three = JSON.parse(readFileSync(folder + "/three.json", "utf8"));
  const result = {
    float1: same(Array.from(THREE.UniformsLib.LTC_FLOAT_1.image.data), three.ltc1),
    float2: same(Array.from(THREE.UniformsLib.LTC_FLOAT_2.image.data), three.ltc2),
    half1: same(Array.from(u.LTC_HALF_1.image.data), three.half1),
    half2: same(Array.from(u.LTC_HALF_2.image.data), three.half2),
    size: [u.LTC_FLOAT_1.image.width, u.LTC_FLOAT_1.image.height],
    types: [u.LTC_FLOAT_1.type === THREE.FloatType, u.LTC_HALF_1.type === THREE.HalfFloatType],
    filters: [u.LTC_FLOAT_1.magFilter === THREE.LinearFilter, u.LTC_FLOAT_1.minFilter === THREE.NearestFilter],
  };
  console.log(JSON.stringify(result));
}
"""


@pytest.mark.skipif(engines_missing() is not None, reason=engines_missing() or "")
def test_the_module_is_a_drop_in_for_three(tmp_path):
    script = ENGINES / f"ltc_module_check_{os.getpid()}.mjs"  # beside node_modules, so that "three" resolves
    script.write_text(NODE_SCRIPT)
    try:
        subprocess.run([NODE, str(script), "three", str(tmp_path)], check=True, capture_output=True, text=True,
                       timeout=120)
        three = json.loads((tmp_path / "three.json").read_text())
        ltc1 = np.asarray(three["ltc1"], np.float32).reshape(64, 64, 4)
        ltc2 = np.asarray(three["ltc2"], np.float32).reshape(64, 64, 4)
        write_ltc_tables(tmp_path, ltc1, ltc2, note="three.js's own table, for the test")
        proc = subprocess.run([NODE, str(script), "ours", str(tmp_path)], check=True, capture_output=True,
                              text=True, timeout=120)
    finally:
        script.unlink()
    result = json.loads(proc.stdout.strip().splitlines()[-1])
    assert result == {"float1": True, "float2": True, "half1": True, "half2": True, "size": [64, 64],
                      "types": [True, True], "filters": [True, True]}
