"""The ``pbrkit explore`` command, registered on the ``pbrkit`` app by ``cli``."""


def register(app):
    """Add this module's command(s) to ``app`` (filled in by pbrkit explore (issue 13))."""
