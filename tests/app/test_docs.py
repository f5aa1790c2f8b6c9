"""The documentation shipped with the package agrees with the project's contract
and with the code: the README's two commands, the API tour of the user guide, the
input rules' limits.  Every code block of the README, docs/index.md and
docs/guide/*.md is run by tests/app/test_docs_blocks.py."""

from pathlib import Path

from doc_pages import GUIDE, api_tour
from skips import needs_shared

ROOT = Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared" / "CONVENTIONS.md"


@needs_shared("CONVENTIONS.md", "the project's contract")
def test_conventions_copy_starts_with_the_contract():
    """docs/CONVENTIONS.md holds ../shared/CONVENTIONS.md verbatim, followed only by
    sections the project adds, each a level-2 heading marked as an addition (the
    contract's rule "This file and docs/CONVENTIONS.md")."""
    copy = (ROOT / "docs" / "CONVENTIONS.md").read_text()
    contract = SHARED.read_text()
    assert copy.startswith(contract), "docs/CONVENTIONS.md must start with ../shared/CONVENTIONS.md verbatim"
    additions = copy[len(contract):]
    for block in additions.split("\n## ")[1:]:
        heading = block.splitlines()[0]
        assert "addition" in heading.lower(), f"added section {heading!r} is not marked as an addition"
    assert not additions.strip() or additions.lstrip("\n").startswith("## "), \
        "text after the contract must be added sections (## headings)"


def test_readme_starts_with_the_two_commands():
    text = (ROOT / "README.md").read_text()
    block = text.split("```sh", 1)[1].split("```", 1)[0].strip().splitlines()
    assert block == ['pip install . && pbrkit demo -o demo', 'pip install -e ".[test]" && python -m pytest -q']
    ci = (ROOT / ".ci" / "run").read_text()
    assert 'python -m pip install -q -e ".[test]"' in ci and "python -m pytest -q" in ci


def test_api_tour_imports_and_the_top_level_names():
    """Every import line of the guide's API tour runs; the top level holds the tour's
    names and the subpackages, and nothing else (no import machinery, no hook)."""
    import importlib
    import sys

    import pbrkit

    block = api_tour()
    imports = [line.split("#")[0].strip() for line in block.splitlines()
               if line.startswith(("import ", "from "))]
    assert any("pbrkit.ibl" in line for line in imports)
    for line in imports:
        exec(line, {})
    assert pbrkit.models is importlib.import_module("pbrkit.brdf.models")
    assert pbrkit.bake is importlib.import_module("pbrkit.ibl").bake and callable(pbrkit.render)
    assert pbrkit.write_bake is importlib.import_module("pbrkit.io.bake_files").write_bake
    assert pbrkit.render is importlib.import_module("pbrkit.rendering.run").render
    names = set(dir(pbrkit))
    assert {"render", "Rendering", "bake", "load_scene", "scene_from_dict", "Material", "models"} <= names
    assert not names & {"importlib", "sys", "_AliasFinder"}
    assert not any(type(f).__module__.startswith("pbrkit") for f in sys.meta_path)


def test_api_tour_runs_as_written(tmp_path, monkeypatch):
    """The whole API tour runs, as a user would paste it, in an empty folder: every
    file it reads ships with pbrkit (the bundled environment), and it writes the
    files the paragraph after it names."""
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "__docs__"}
    exec(compile(api_tour(), "docs/guide/python.md (API tour)", "exec"), namespace)
    assert (tmp_path / "bake" / "manifest.json").is_file()
    assert (tmp_path / "spheres.png").is_file() and (tmp_path / "spheres.stderr.exr").is_file()
    assert (tmp_path / "plastic.binary").is_file()
    assert abs(namespace["fit"].parameters["roughness"] - 0.5) < 1e-4  # the MERL file's model, recovered
    b, r = namespace["b"], namespace["r"]
    assert b.levels == 4 and list(b.roughness) == [0.0, 1 / 3, 2 / 3, 1.0]
    assert 0.0 <= r.stats["errors"]["mean_relative_error"] < 1.0
    assert r.realtime.shape == r.reference.shape == (32, 32, 3) and r.error.shape == (32, 32)
    pdf_h, h, wo = namespace["pdf_h"], namespace["h"], namespace["wo"]
    assert pdf_h.shape == (1024,) and (pdf_h > 0).all() and h.shape == (1024, 3) and wo.shape == (3,)


def test_bundled_environment_is_public_and_described():
    """pbrkit.data.environment_path() is the bundled CC0 map the demo and scenes use,
    and pbrkit.data.ENVIRONMENT agrees with LICENSE-environment.md beside it."""
    from pbrkit.data import ENVIRONMENT, environment_licence_path, environment_path
    from pbrkit.io.images import read_image
    from pbrkit.rendering.scene import bundled_environment

    path = environment_path()
    assert path.name == "environment.hdr" and path.is_file()
    assert path.samefile(bundled_environment())
    assert read_image(path).shape == (ENVIRONMENT["resolution"][1], ENVIRONMENT["resolution"][0], 3)
    licence = environment_licence_path().read_text(encoding="utf-8")
    for key in ("name", "source_file", "author", "url", "licence_url"):
        assert ENVIRONMENT[key] in licence, key
    assert "CC0" in ENVIRONMENT["licence"] and "CC0" in licence


def test_package_data_is_declared():
    """The bundled environment and its licence are package data of pbrkit.data
    (pyproject.toml), so a wheel (not only an editable install) has them."""
    import tomllib

    data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    assert {"environment.hdr", "LICENSE-environment.md"} <= set(data["pbrkit.data"])
    assert (ROOT / "src" / "pbrkit" / "data" / "__init__.py").is_file()


def test_input_rules_state_the_limits_the_code_enforces():
    """The guide's input rules (docs/guide/input-rules.md, "Untrusted input") state the limits of pbrkit.core.inputs and
    the glTF reader, and the options it names exist on the commands."""
    from typer.main import get_command

    from pbrkit.cli import app
    from pbrkit.core.inputs import MAX_TEXT_BYTES, size_text
    from pbrkit.io.gltf_document import MAX_GLTF_BYTES

    text = " ".join((GUIDE / "input-rules.md").read_text().split("## Untrusted input", 1)[1].split("\n## ", 1)[0].split())
    assert MAX_GLTF_BYTES % (1 << 30) == 0
    assert f"at most {size_text(MAX_TEXT_BYTES)}, glTF files {MAX_GLTF_BYTES >> 30} GiB" in text
    render = get_command(app).commands["render"]
    assert "--allow-root" in {opt for p in render.params for opt in p.opts}
    assert "allow_roots" in text and "--allow-root" in text
