"""``python -m pbrkit``: the ``pbrkit`` command (:mod:`pbrkit.cli`)."""

from .cli import app

if __name__ == "__main__":  # pragma: no cover
    app(prog_name="pbrkit")
