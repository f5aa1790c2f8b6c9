"""Shared test helper: the pages of the user guide the documentation tests read."""

from pathlib import Path

#: docs/guide of the repository.
GUIDE = Path(__file__).resolve().parents[2] / "docs" / "guide"


def api_tour():
    """The ```python block under "## API tour" in docs/guide/python.md."""
    text = (GUIDE / "python.md").read_text()
    return text.split("## API tour", 1)[1].split("```python", 1)[1].split("```", 1)[0]
