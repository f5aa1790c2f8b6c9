"""``pbrkit demo``: the bundled scene baked, rendered, compared and plotted into a
web page (:func:`pbrkit.app.demo.run_demo`).

The module imports Typer and the command line's own modules only; the command
imports its work in its body (``pbrkit --help`` stays light)."""

from __future__ import annotations

from pathlib import Path

import typer

from .console import _Stages, user_errors
from .options import OUT_DIR, _quiet_option, _seed_option

#: ``pbrkit --help``'s line for the command (None: the docstring's first line).
SHORT_HELP = "Bake, render, compare and plot the bundled scene into OUT/index.html."
#: The example ``pbrkit demo --help`` shows (tests/cli/test_cli_help.py parses it).
EXAMPLE = "pbrkit demo -o demo"


@user_errors
def demo(
    out: Path = typer.Option(..., "-o", "--out", metavar="DIR", parser=OUT_DIR,
                             help="Output folder (index.html and its images)."),
    size: int = typer.Option(384, "--size", metavar="PIXELS", help="Side of the sphere-grid images in pixels."),
    spp: int = typer.Option(192, "--spp", metavar="N",
                            help="Ground-truth samples per pixel (more than render's 64: the page shows the "
                                 "ground truth's noise beside the error)."),
    bake_size: int = typer.Option(128, "--bake-size", metavar="N",
                                  help="Size of the bake's specular cube (power of two >= 32; smaller than "
                                       "render's 256 to keep the demo quick)."),
    seed: int = _seed_option("Seed of the random numbers (ground truth and furnace)."),
    quiet: bool = _quiet_option(),
):
    """Bake the bundled environment, render the sphere grid and the area-light scene in
    real time and as ground truth, plot the furnace test and the lookup table, and
    write OUT/index.html."""
    from ..app.demo import run_demo

    steps = ("bake", "realtime", "furnace", "lut", "npr", "area", "reference", "images", "page")
    with _Stages("demo", quiet, len(steps)) as stages:
        stages.start(steps[0])

        def finished(name):
            k = steps.index(name) + 1 if name in steps else stages.number
            if k < len(steps):
                stages.start(steps[k], k + 1)

        summary = run_demo(out, size=size, spp=spp, bake_size=bake_size, seed=seed, progress=finished)
    if not quiet:
        e = summary["errors"]
        print(f"mean relative error {e['mean_relative_error']:.4f}, FLIP {e.get('flip', float('nan')):.4f}; "
              f"total {summary['timings_s']['total']:.1f} s")
        print(f"wrote {out / 'index.html'}")
