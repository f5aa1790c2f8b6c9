"""The ``pbrkit`` command line (Typer + Rich): :data:`app`.

One module per command (:mod:`~pbrkit.cli.furnace`, :mod:`~pbrkit.cli.lut`,
:mod:`~pbrkit.cli.approximations`, :mod:`~pbrkit.cli.render`,
:mod:`~pbrkit.cli.demo`, :mod:`~pbrkit.cli.bake`, :mod:`~pbrkit.cli.ltc`,
:mod:`~pbrkit.cli.hatching`, :mod:`~pbrkit.cli.shaders`,
:mod:`~pbrkit.cli.explore`, and the group :mod:`~pbrkit.cli.batch`), each
defining its command function, its ``SHORT_HELP`` and its ``EXAMPLE``; this
module registers them, in :data:`COMMANDS`' order and help panels.  Shared:
:mod:`~pbrkit.cli.console` (one-line errors, Ctrl-C and SIGTERM, progress),
:mod:`~pbrkit.cli.options` (the command classes, the option factories) and
:mod:`~pbrkit.cli.help` (``--help`` laid out for 80 columns).

``--help`` lists the choices of every option with a fixed set of values
(``[realtime|reference|compare]``) and answers without importing NumPy or
Numba: the commands import what they need in their bodies.  The library never
imports this package (tests/app/test_package_layout.py).
"""

from __future__ import annotations

import typer

from . import approximations, bake, batch, demo, explore, furnace, hatching, ltc, lut, render, shaders
from .options import _Command, _Group

__all__ = ["app", "COMMANDS"]

app = typer.Typer(
    cls=_Group,
    no_args_is_help=True,
    add_completion=False,
    context_settings={"help_option_names": ["-h", "--help"]},
    epilog="Example:\n\n" + render.EXAMPLE,
)


def _version_callback(value: bool):
    if value:
        from .. import __version__

        print(f"pbrkit {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: bool = typer.Option(False, "--version", callback=_version_callback, is_eager=True, metavar="",
                                 help="Print the version and exit."),
):
    """pbrkit: physically based shading for real-time rendering.

    Every command refuses bad input or options with one line on stderr
    (pbrkit: error: FILE: problem), exit status 1 and no output left behind;
    shows its progress by stage on stderr (a bar on a terminal, plain lines
    otherwise; -q/--quiet: none, and no summary); and gives the same bytes for
    the same input, options and --seed (default 0 everywhere).  pbrkit CMD
    --help shows a command's options and an example."""


#: The commands in the order ``pbrkit --help`` lists them: (module, name, help panel).
COMMANDS = (
    (render, "render", "Render and compare"),
    (demo, "demo", "Render and compare"),
    (bake, "bake", "Bake and tables"),
    (lut, "lut", "Bake and tables"),
    (ltc, "ltc", "Bake and tables"),
    (hatching, "hatching", "Bake and tables"),
    (shaders, "shaders", "Bake and tables"),
    (furnace, "furnace", "Reports"),
    (approximations, "approximations", "Reports"),
    (explore, "explore", "Batch and apps"),
)

for _module, _name, _panel in COMMANDS:
    app.command(_name, cls=_Command, short_help=_module.SHORT_HELP, epilog=_module.EXAMPLE,
                rich_help_panel=_panel)(getattr(_module, _name))
app.add_typer(batch.batch_app, name="batch", short_help=batch.SHORT_HELP, rich_help_panel="Batch and apps")
del _module, _name, _panel


if __name__ == "__main__":  # pragma: no cover
    app(prog_name="pbrkit")
