"""``pbrkit approximations``: error heat maps of real-time approximations
(:func:`pbrkit.albedo.approximations.approximations_report`).

The module imports Typer and the command line's own modules only; the command
imports its work in its body (``pbrkit --help`` stays light)."""

from __future__ import annotations

from pathlib import Path

import typer

from .console import _console, _Stages, user_errors
from .options import OUT_DIR, _flag, _quiet_option

#: ``pbrkit --help``'s line for the command (None: the docstring's first line).
SHORT_HELP = "Error heat maps of real-time approximations as directional-albedo differences."
#: The example ``pbrkit approximations --help`` shows (tests/cli/test_cli_help.py parses it).
EXAMPLE = "pbrkit approximations -o approximations --size 32"


@user_errors
def approximations(
    out: Path = typer.Option(..., "-o", "--out", metavar="DIR", parser=OUT_DIR,
                             help="Output folder (must be absent or empty unless --force)."),
    size: int = typer.Option(32, "--size", metavar="N", help="Grid size N over (n.v, roughness)."),
    force: bool = _flag(False, ("--force",), "Write into a non-empty output folder."),
    quiet: bool = _quiet_option(),
):
    """Error heat maps of real-time approximations (Karis' fit, Fresnel and masking
    shortcuts, URP mobile, compensation) as directional-albedo differences."""
    from ..albedo.approximations import approximations_report
    from ..core import checks
    from ..core.atomic import check_output_directory

    check_output_directory(out, force)
    checks.integer(size, "--size", 4, 256)
    with _Stages("approximations", quiet, 1) as stages:
        stages.start("albedo differences and figure")
        summary = approximations_report(out, size)
    if not quiet:
        from rich.console import Console
        from rich.table import Table

        table = Table(title="Albedo error of real-time approximations")
        for col in ("comparison", "max |error|", "mean |error|", "at n.v", "at r"):
            table.add_column(col, justify="left" if col == "comparison" else "right")
        for name, s in summary["comparisons"].items():
            table.add_row(name, f"{s['max_abs_error']:.2e}", f"{s['mean_abs_error']:.2e}",
                          f"{s['at']['nv']:.3f}", f"{s['at']['roughness']:.3f}")
        Console(width=max(100, _console().width)).print(table)
        print(f"wrote {out}/approximations.png and approximations.json")
