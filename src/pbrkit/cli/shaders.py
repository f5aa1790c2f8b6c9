"""``pbrkit shaders``: shader functions matching pbrkit's models and bakes
(:func:`pbrkit.shaders.write_shaders`).

The module imports Typer and the command line's own modules only; the command
imports its work in its body (``pbrkit --help`` stays light)."""

from __future__ import annotations

from pathlib import Path

import typer

from ..choices import SHADER_TARGETS
from .console import user_errors
from .options import OUT_DIR, _choice, _flag, _quiet_option

#: ``pbrkit --help``'s line for the command (None: the docstring's first line).
SHORT_HELP = "Write shader functions that match pbrkit's models and bakes."
#: The example ``pbrkit shaders --help`` shows (tests/cli/test_cli_help.py parses it).
EXAMPLE = "pbrkit shaders -o shaders --target glsl"


@user_errors
def shaders(
    out: Path = typer.Option(..., "-o", "--out", metavar="DIR", parser=OUT_DIR,
                             help="Output folder (must be absent or empty unless --force)."),
    target: str = _choice("glsl", "--target", SHADER_TARGETS, "shader target",
                          "Shading language: glsl (GLSL ES 3.00 / WebGL2 and GLSL 3.30+)."),
    force: bool = _flag(False, ("--force",), "Replace a non-empty output folder."),
    quiet: bool = _quiet_option(),
):
    """Write shader functions for pbrkit's BRDF terms and models (D, G/V, F, diffuse;
    UE4, Filament, glTF), for sampling a pbrkit bake (lod from roughness, the DFG
    table lookup, SH irradiance), for LTC area lights, the NPR terms, and
    KHR_materials_sheen / KHR_materials_iridescence (Charlie D and V, the E_sheen
    lookup and albedo scaling, the sheen IBL, the thin-film Fresnel), with the
    bake's conventions built in, and manifest.json listing each function with its
    source and roughness remap."""
    from ..shaders import write_shaders

    names = write_shaders(out, target=target, force=force)
    if not quiet:
        print(f"wrote {out}: " + ", ".join(names))
