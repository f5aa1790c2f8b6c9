"""``pbrkit hatching``: a tonal art map for hatching (:func:`pbrkit.npr.hatching.tonal_art_map`).

The module imports Typer and the command line's own modules only; the command
imports its work in its body (``pbrkit --help`` stays light)."""

from __future__ import annotations

from pathlib import Path

import typer

from .console import _Stages, user_errors
from .options import OUT_DIR, _flag, _quiet_option, _seed_option

#: ``pbrkit --help``'s line for the command (None: the docstring's first line).
SHORT_HELP = "Write a tonal art map for hatching (Praun et al. 2001) as images."
#: The example ``pbrkit hatching --help`` shows (tests/cli/test_cli_help.py parses it).
EXAMPLE = "pbrkit hatching -o tam --tones 6 --size 256"


@user_errors
def hatching(
    out: Path = typer.Option(..., "-o", "--out", metavar="DIR", parser=OUT_DIR,
                             help="Output folder (absent or empty unless --force)."),
    tones: int = typer.Option(6, "--tones", metavar="N", help="Tones, light to dark (2-16)."),
    size: int = typer.Option(256, "--size", metavar="N", help="Side of the finest level (a power of two)."),
    seed: int = _seed_option("Seed of the strokes' placement; the same seed gives the same bytes."),
    force: bool = _flag(False, ("--force",), "Replace a non-empty output folder."),
    quiet: bool = _quiet_option(),
):
    """Generate a tonal art map (pbrkit.npr.hatching): every tone's mip chain as 8-bit
    PNG (tone{k}_mip{l}.png; each darker tone holds the strokes of the lighter ones,
    each level keeps the stroke width in pixels), RGB atlases of three tones, a
    preview and manifest.json, for use as hatching textures in an engine."""
    from ..core import checks
    from ..npr.hatching import tonal_art_map, write_tam

    checks.integer(tones, "--tones", 2, 16)
    checks.power_of_two(size, "--size", 8, 4096)
    with _Stages("hatching", quiet, 2) as stages:
        stages.start("strokes")
        tam = tonal_art_map(tones=tones, size=size, seed=seed)
        stages.start("write", 2)
        write_tam(out, tam, force=force)
    if not quiet:
        print(f"wrote {out}: {tones} tones, levels {', '.join(str(n) for n in tam.sizes)}")
