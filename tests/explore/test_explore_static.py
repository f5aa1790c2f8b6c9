"""``pbrkit explore --static -o DIR``: every view as a valid PNG and SVG, the same
bytes twice; bad options and bad MERL files are refused with one line and no
output; the command's choices are the library's; ``pbrkit --help`` stays light."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from pbrkit.cli import explore as explore_cli
from pbrkit.cli import app
from pbrkit.explore.static import VIEW_NAMES


def invoke(*args):
    return CliRunner().invoke(app, ["explore", *[str(a) for a in args]])


def assert_refused(result, *fragments, absent=()):
    assert result.exit_code == 1, result.output
    assert isinstance(result.exception, SystemExit), repr(result.exception)
    assert "Traceback" not in result.output
    assert result.stdout == ""
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("pbrkit: error: "), lines
    for fragment in fragments:
        assert fragment in lines[0], lines[0]
    for path in absent:
        assert not Path(path).exists()
        assert not list(Path(path).parent.glob(f".{Path(path).name}*"))  # no hidden temporary left


def check_outputs(out, names):
    files = sorted(p.name for p in Path(out).iterdir())
    assert files == sorted([f"{n}.png" for n in names] + [f"{n}.svg" for n in names] + ["explore.json"])
    for n in names:
        with Image.open(out / f"{n}.png") as im:
            im.verify()
        with Image.open(out / f"{n}.png") as im:
            assert im.format == "PNG" and im.size[0] >= 300 and im.size[1] >= 300
            assert np.asarray(im.convert("L")).std() > 5  # something is drawn
        root = ET.parse(out / f"{n}.svg").getroot()
        assert root.tag.endswith("svg")
        assert len(list(root.iter())) > 50
    return json.loads((out / "explore.json").read_text())


def test_static_writes_every_view_twice_the_same(tmp_path):
    args = ["--static", "--model", "disney", "--roughness", "0.3", "--sheen", "0.4", "--compare", "filament",
            "--theta-v", "50", "-q"]
    first = invoke(*args, "-o", tmp_path / "a")
    assert first.exit_code == 0, first.output
    assert first.stdout == "" and first.stderr == ""  # --quiet
    record = check_outputs(tmp_path / "a", VIEW_NAMES)
    assert record["first"]["model"] == "disney" and record["first"]["sheen"] == 0.4
    assert record["second"]["model"] == "filament" and "sheen" not in record["second"]
    assert record["angles_degrees"]["theta_v"] == 50.0
    assert record["first"]["roughness_remap"] == "alpha = roughness^2"
    second = invoke(*args, "-o", tmp_path / "b")
    assert second.exit_code == 0, second.output
    for p in (tmp_path / "a").iterdir():
        assert p.read_bytes() == (tmp_path / "b" / p.name).read_bytes(), p.name


def test_static_without_a_second_brdf_has_no_compare(tmp_path):
    result = invoke("--static", "--model", "cook_torrance", "--distribution", "beckmann", "--masking", "separable",
                    "--fresnel", "exact-conductor", "--conductor", "copper", "-o", tmp_path / "out")
    assert result.exit_code == 0, result.output
    assert "wrote" in result.stdout
    assert [line for line in result.stderr.splitlines() if line.startswith("pbrkit explore: ")]  # progress
    record = check_outputs(tmp_path / "out", [n for n in VIEW_NAMES if n != "compare"])
    assert record["first"]["fresnel"] == "exact-conductor" and record["second"] is None


@pytest.fixture(scope="module")
def merl_files(tmp_path_factory):
    from pbrkit.explore.views import model_brdf
    from pbrkit.measured.merl import merl_bytes, merl_table

    root = tmp_path_factory.mktemp("merl")
    brdf = model_brdf("cook_torrance", (0.6, 0.3, 0.2), 0.0, 0.3)
    data = merl_bytes(merl_table(lambda l, v, n: brdf.evaluate(l, v, n)))
    (root / "ggx.binary").write_bytes(data)
    (root / "truncated.binary").write_bytes(data[: len(data) // 3])
    wrong = np.asarray([90, 90, 90], dtype="<i4").tobytes() + data[12:]
    (root / "wrong.binary").write_bytes(wrong)
    return root


def test_static_with_a_merl_file_and_its_fit(merl_files, tmp_path):
    result = invoke("--static", "--merl", merl_files / "ggx.binary", "--fit", "ggx", "-o", tmp_path / "out")
    assert result.exit_code == 0, result.output
    assert "pbrkit: warning" not in result.stderr
    record = check_outputs(tmp_path / "out", VIEW_NAMES)
    fit = record["fit"]
    assert fit["measured"] == "ggx" and fit["model"] == "ggx"
    assert fit["error"]["relative_l2"] < 1e-3 and abs(fit["parameters"]["roughness"] - 0.3) < 1e-3
    assert record["second"]["name"] == "ggx"
    assert "fit ggx to ggx" in result.stdout


@pytest.mark.parametrize("name, fragment", [("truncated.binary", "truncated MERL BRDF file"),
                                            ("wrong.binary", "header dimensions 90 x 90 x 90"),
                                            ("missing.binary", "file not found")])
def test_bad_merl_files_are_refused_with_one_line(merl_files, tmp_path, name, fragment):
    out = tmp_path / "out"
    result = invoke("--static", "--merl", merl_files / name, "-o", out)
    assert_refused(result, f"{merl_files / name}: ", fragment, absent=[out])


@pytest.mark.parametrize("args, fragments", [
    (["--static"], ["--static needs -o DIR"]),
    (["-o", "OUT"], ["-o/--out is for --static"]),
    (["--static", "-o", "OUT", "--roughness", "1.5"], ["--roughness", "[0, 1]"]),
    (["--static", "-o", "OUT", "--base-color", "1,0.5"], ["--base-color", "R,G,B"]),
    (["--static", "-o", "OUT", "--base-color", "1,0.5,2"], ["--base-color", "[0, 1]"]),
    (["--static", "-o", "OUT", "--model", "gltf", "--sheen", "0.5"], ["--sheen", "'gltf' has no sheen", "disney"]),
    (["--static", "-o", "OUT", "--model", "ue4", "--masking", "separable"], ["--masking", "cook_torrance"]),
    (["--static", "-o", "OUT", "--model", "phong"], ["--model", "unknown model 'phong'", "gltf"]),
    (["--static", "-o", "OUT", "--theta-v", "95"], ["--theta-v", "[0, 89]"]),
    (["--static", "-o", "OUT", "--fit", "ggx"], ["--fit needs --merl"]),
    (["--port", "70000"], ["--port"]),
    (["--static", "-o", "OUT", "--model", "cook_torrance", "--fresnel", "exact-conductor"],
     ["exact-conductor", "needs eta and k (or conductor)"]),
])
def test_bad_options_are_refused_with_one_line(tmp_path, args, fragments):
    out = tmp_path / "OUT"
    result = invoke(*[str(out) if a == "OUT" else a for a in args])
    assert_refused(result, *fragments, absent=[out])


def test_static_refuses_a_non_empty_folder_without_force(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("x")
    assert_refused(invoke("--static", "-o", out), "not empty", "--force")
    assert (out / "keep.txt").read_text() == "x"


def test_the_choices_are_the_librarys():
    from pbrkit.brdf import models as bxdf
    from pbrkit.brdf.fresnel import CONDUCTORS
    from pbrkit.explore.views import COMPENSATIONS, MODEL_PARAMETERS
    from pbrkit.measured.fit import FIT_MODELS, FIT_WEIGHTINGS

    assert explore_cli.EXPLORE_MODELS == bxdf.MODELS
    assert explore_cli.EXPLORE_DISTRIBUTIONS == bxdf.DISTRIBUTIONS
    assert explore_cli.EXPLORE_MASKINGS == bxdf.MASKINGS
    assert explore_cli.EXPLORE_FRESNELS == bxdf.FRESNELS
    assert explore_cli.EXPLORE_DIFFUSES == bxdf.DIFFUSES
    assert explore_cli.EXPLORE_CONDUCTORS == tuple(sorted(CONDUCTORS))
    assert explore_cli.EXPLORE_FIT_MODELS == FIT_MODELS
    assert explore_cli.EXPLORE_FIT_WEIGHTINGS == FIT_WEIGHTINGS
    assert explore_cli.EXPLORE_COMPENSATIONS == COMPENSATIONS
    assert set(explore_cli.EXPLORE_PARAMETERS.values()) == set().union(*MODEL_PARAMETERS.values())
    help_text = CliRunner().invoke(app, ["explore", "--help"], env={"COLUMNS": "200"}).stdout
    for choices in (bxdf.MODELS, bxdf.FRESNELS):
        assert "[" + "|".join(choices) + "]" in help_text


def test_help_is_light_and_has_no_python_types():
    code = ("import sys\nfrom pbrkit.cli import app\n"
            "for args in (['--help'], ['explore', '--help']):\n"
            "    try:\n        app(args, prog_name='pbrkit')\n    except SystemExit as exc:\n"
            "        assert exc.code in (0, None)\n"
            "print('HEAVY', sorted(m for m in ('panel', 'bokeh', 'matplotlib', 'numba', 'numpy', "
            "'pbrkit.explore.views') if m in sys.modules), file=sys.stderr)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "COLUMNS": "300"})
    assert done.returncode == 0, done.stderr
    assert "HEAVY []" in done.stderr, done.stderr
    assert "pbrkit explore" in done.stdout or "explore" in done.stdout
    assert not re.search(r"<(bool|str|int|float|Path|path|list\[[^>]*\])>", done.stdout)
