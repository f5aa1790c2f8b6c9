"""``pbrkit lut``: a split-sum or DFG lookup table (:func:`pbrkit.albedo.lut.lookup_table`).

The module imports Typer and the command line's own modules only; the command
imports its work in its body (``pbrkit --help`` stays light)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from ..choices import KTX2_FORMATS, LUT_KINDS, VISIBILITIES
from .console import _Stages, user_errors
from .options import OUT_FILE, _choice, _flag, _quiet_option

#: ``pbrkit --help``'s line for the command (None: the docstring's first line).
SHORT_HELP = None
#: The example ``pbrkit lut --help`` shows (tests/cli/test_cli_help.py parses it).
EXAMPLE = "pbrkit lut -o dfg.ktx2 --kind dfg --size 128"


@user_errors
def lut(
    out: Path = typer.Option(..., "-o", "--out", metavar="FILE", parser=OUT_FILE,
                             help="Output file: .npy, .exr, .png (16-bit), .h (C header, float16) or .ktx2; "
                                  "FILE.json beside it describes the table."),
    kind: str = _choice("dfg", "--kind", LUT_KINDS, "table kind",
                        "splitsum (UE4: A, B) or dfg (Filament: DFG1, DFG2)."),
    size: int = typer.Option(128, "--size", metavar="N", help="Table size N (N x N texels)."),
    cloth: bool = _flag(False, ("--cloth",), "Add the Charlie / Neubelt sheen albedo channel."),
    visibility: Optional[str] = _choice(
        None, "--visibility", VISIBILITIES, "visibility",
        "Masking-shadowing term; default: schlick-ggx for splitsum, height-correlated for dfg."),
    samples: Optional[int] = typer.Option(
        None, "--samples", metavar="N",
        help="Quadrature nodes per texel (theta x phi); default: the converged rule (144 nodes, 288 at grazing)."),
    ktx2_format: str = _choice("float16", "--ktx2-format", KTX2_FORMATS, "KTX2 format", "Texel type in .ktx2 output."),
    no_cache: bool = _flag(False, ("--no-cache",), "Integrate the table even if pbrkit's result cache holds it "
                                                   "(tables are memoised by options and pbrkit's sources)."),
    quiet: bool = _quiet_option(),
):
    """Split-sum (A, B) or DFG (DFG1, DFG2[, cloth]) lookup table with its JSON description."""
    from ..albedo.lut import DEFAULT_NODES, lookup_table
    from ..core import checks
    from ..io.lut_files import LUT_SUFFIXES, write_lut

    if out.suffix.lower() not in LUT_SUFFIXES:
        raise ValueError(f"{out}: unsupported table format {out.suffix!r}; use one of {', '.join(LUT_SUFFIXES)}")
    checks.integer(size, "--size", 2, 4096)
    nodes = DEFAULT_NODES
    if samples is not None:
        checks.integer(samples, "--samples", 8, 1 << 20)
        # Split the budget as the default rule does: 2 theta segments x n_theta x n_phi, n_phi = n_theta / 2.
        n_theta = max(2, int(round(samples ** 0.5)))
        nodes = (n_theta, 2 * n_theta, max(2, n_theta // 2))
    with _Stages("lut", quiet, 2) as stages:
        stages.start("integrate")
        table, spec = lookup_table(kind, size, visibility, cloth, nodes, cache=not no_cache)
        stages.start("write")
        written = write_lut(out, table, spec, ktx2_format)
    if not quiet:
        print(f"wrote {written[0]} ({kind}, {size} x {size}, {table.shape[2]} channels, "
              f"visibility {spec.visibility}) and {written[1].name}")
