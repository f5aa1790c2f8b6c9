"""The ``pbrkit batch bake|render`` command, registered on the ``pbrkit`` app by ``cli``."""


def register(app):
    """Add this module's command(s) to ``app`` (filled in by pbrkit batch bake|render (issue 14))."""
