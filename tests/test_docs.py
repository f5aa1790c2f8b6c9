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
