"""The documentation shipped with the package agrees with the project's contract."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "CONVENTIONS.md"


@pytest.mark.skipif(not SHARED.exists(), reason=f"the shared contract is not beside the checkout ({SHARED})")
def test_conventions_copy_is_the_contract():
    assert (ROOT / "docs" / "CONVENTIONS.md").read_text() == SHARED.read_text()


def test_readme_starts_with_the_two_commands():
    text = (ROOT / "README.md").read_text()
    block = text.split("```sh", 1)[1].split("```", 1)[0].strip().splitlines()
    assert block == ['pip install . && pbrkit demo -o demo', 'pip install -e ".[test]" && python -m pytest -q']
    ci = (ROOT / ".ci" / "run").read_text()
    assert 'python -m pip install -q -e ".[test]"' in ci and "python -m pytest -q" in ci


def test_readme_api_tour_imports_and_the_old_dotted_names_work():
    """Every import line of the README's API tour runs, and the dotted module names of
    the first release still import the modules they now live in."""
    import importlib

    import pbrkit

    text = (ROOT / "README.md").read_text()
    block = text.split("## API tour", 1)[1].split("```python", 1)[1].split("```", 1)[0]
    imports = [line.split("#")[0].strip() for line in block.splitlines()
               if line.startswith(("import ", "from "))]
    assert any("pbrkit.ibl" in line for line in imports)
    for line in imports:
        exec(line, {})
    for old, new in (("pbrkit.models", "pbrkit.brdf.models"), ("pbrkit.tables", "pbrkit.albedo.tables"),
                     ("pbrkit.masking", "pbrkit.brdf.masking"), ("pbrkit.bake", "pbrkit.ibl")):
        assert importlib.import_module(old) is importlib.import_module(new)
    from pbrkit.bake import bake, level_of_roughness, load_bake, write_bake  # noqa: F401
    assert pbrkit.models.cook_torrance is importlib.import_module("pbrkit.brdf.models").cook_torrance
