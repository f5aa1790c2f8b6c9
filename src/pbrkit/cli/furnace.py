"""``pbrkit furnace``: the white-furnace albedo of every lobe (:mod:`pbrkit.app.report`).

The module imports Typer and the command line's own modules only; the command
imports its work in its body (``pbrkit --help`` stays light)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from ..choices import COMPENSATIONS, LOBES
from .console import _console, _Stages, user_errors
from .options import OUT_DIR, _choice, _choice_check, _flag, _quiet_option, _seed_option

#: ``pbrkit --help``'s line for the command (None: the docstring's first line).
SHORT_HELP = None
#: The example ``pbrkit furnace --help`` shows (tests/cli/test_cli_help.py parses it).
EXAMPLE = "pbrkit furnace -o furnace --lobe ggx/height-correlated --samples 64"


@user_errors
def furnace(
    out: Path = typer.Option(..., "-o", "--out", metavar="DIR", parser=OUT_DIR,
                             help="Output folder (must be absent or empty unless --force)."),
    mu_count: int = typer.Option(32, "--mu-count", metavar="N", help="Number of mu = n.v values (texel centres)."),
    roughness_count: int = typer.Option(11, "--roughness-count", metavar="N", help="Number of roughness values in [0, 1]."),
    samples: int = typer.Option(256, "--samples", metavar="N", help="Monte Carlo samples per (mu, roughness) cell."),
    seed: int = _seed_option("Seed of the Monte Carlo generator (lobe k uses seed + k)."),
    lobe: Optional[list[str]] = typer.Option(
        None, "--lobe", metavar="LOBE", callback=_choice_check("lobe", LOBES),
        help="Only this lobe (repeatable); default: all.  One of " + ", ".join(LOBES) + "."),
    compensation: Optional[str] = _choice(
        None, "--compensation", COMPENSATIONS, "compensation",
        "Also show multiple-scattering compensation (compensation.*)."),
    force: bool = _flag(False, ("--force",), "Write into a non-empty output folder."),
    quiet: bool = _quiet_option(),
):
    """White-furnace albedo E(mu) of every D x G combination and model (F = 1).

    Writes furnace.csv, furnace.npy, furnace.json and furnace.png to OUT; with
    --compensation also compensation.csv/.npy/.json/.png (white furnace of a
    compensated GGX surface, and gold and copper keeping their saturation).
    """
    import numpy as np

    from ..core import checks
    from ..core.atomic import check_output_directory
    from ..app.report import compensation_files, furnace_files, write_files

    check_output_directory(out, force)
    checks.integer(roughness_count, "--roughness-count", 2, 1024)
    checks.integer(mu_count, "--mu-count", 2, 4096)
    checks.integer(samples, "--samples", 2, 1 << 20)
    names = list(lobe or LOBES)
    with _Stages("furnace", quiet, len(names) + 1 + (compensation is not None)) as stages:
        stages.start(f"lobe {names[0]}")

        def finished(name):
            k = stages.number
            stages.start(f"lobe {names[k]}" if k < len(names) else "figures")

        summary, timings, files = furnace_files(n_mu=mu_count, roughness=np.linspace(0.0, 1.0, roughness_count),
                                                samples=samples, seed=seed, lobes=names, progress=finished)
        if compensation is not None:
            stages.start("compensation")
            comp, comp_files = compensation_files(compensation)
            files.update(comp_files)
        write_files(out, files)  # the furnace's and the compensation's files together: all or none
    if not quiet:
        from rich.console import Console
        from rich.table import Table

        table = Table(title="Single-scattering albedo with F = 1 (quadrature)")
        for col in ("lobe", "min E", "max E", "max |MC - quad|", "MC within 3 se", "quadrature s", "MC s"):
            table.add_column(col, justify="right" if col != "lobe" else "left")
        for name, s in summary["per_lobe"].items():
            table.add_row(name, f"{s['min_albedo']:.4f}", f"{s['max_albedo']:.4f}",
                          f"{s['max_abs_mc_minus_quadrature']:.2e}", f"{100 * s['fraction_within_3_stderr']:.0f}%",
                          f"{timings[name]['quadrature_s']:.2f}", f"{timings[name]['monte_carlo_s']:.2f}")
        Console(width=max(110, _console().width)).print(table)
        if compensation is not None:
            s = comp
            print(f"{compensation} compensation, F = 1 GGX: max |E - 1| = {s['max_abs_error_on_texel_grid']:.1e} "
                  f"on the {s['table_size']}^2 table's texel grid (without: energy loss up to "
                  f"{s['max_energy_loss_without_compensation']:.3f}); between texels (bilinear) max "
                  f"{s['between_texels']['max_abs_error']:.1e}, median {s['between_texels']['median_abs_error']:.1e}")
        print(f"wrote {out}: " + ", ".join(files))
