"""``pbrkit render``: a scene in real time, as ground truth, or both
(:func:`pbrkit.rendering.run.render_scene`).

The module imports Typer and the command line's own modules only; the command
imports its work in its body (``pbrkit --help`` stays light)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from ..choices import DIFFUSE_MODES, MODES, RENDER_ENGINES, TONEMAPS
from .console import _err, _Stages, user_errors
from .options import EXPOSURE_LIMIT, OUT_FILE, _check_exposure, _choice, _flag, _quiet_option, _seed_option

#: ``pbrkit --help``'s line for the command (None: the docstring's first line).
SHORT_HELP = "Render a scene in real time, as Monte Carlo ground truth, or both (compare)."
#: The example ``pbrkit render --help`` shows (tests/cli/test_cli_help.py parses it).
EXAMPLE = "pbrkit render spheres -o spheres.png --mode compare --spp 16"


@user_errors
def render(
    scene: str = typer.Argument(..., metavar="SCENE",
                                help="Scene file (.toml or .json), a glTF file (.gltf or .glb: framed under "
                                     "the bundled environment) or a built-in scene: spheres, sphere, area."),
    out: Path = typer.Option(..., "-o", "--out", metavar="FILE", parser=OUT_FILE,
                             help="Output image: .exr (linear float32) or .png (tone-mapped, sRGB)."),
    mode: str = _choice("realtime", "--mode", MODES, "mode",
                        "realtime (split-sum IBL), reference (Monte Carlo ground truth) or compare (both)."),
    spp: int = typer.Option(64, "--spp", metavar="N", help="Ground-truth samples per pixel."),
    bounces: int = typer.Option(0, "--bounces", metavar="N",
                                help="Ground-truth bounces after the first hit (0: direct light; more turns "
                                     "occlusion on unless --no-occlusion, which then is refused)."),
    tonemap_name: str = _choice("aces", "--tonemap", TONEMAPS, "tone mapper", "Tone mapper of .png output."),
    exposure: float = typer.Option(0.0, "--exposure", metavar="EV", callback=_check_exposure,
                                   help=f"Exposure in EV applied before tone mapping (.png), within "
                                        f"+-{EXPOSURE_LIMIT:g}."),
    width: Optional[int] = typer.Option(None, "--width", metavar="PIXELS",
                                        help="Image width (overrides the scene's camera)."),
    height: Optional[int] = typer.Option(None, "--height", metavar="PIXELS",
                                         help="Image height (overrides the scene's camera)."),
    env: Optional[Path] = typer.Option(None, "--env", metavar="FILE|DIR",
                                       help="Environment map, or a bake folder (pbrkit bake), replacing the "
                                            "scene's."),
    seed: int = _seed_option("Seed of the ground truth's random numbers."),
    diffuse: str = _choice("sh", "--diffuse", DIFFUSE_MODES, "diffuse mode",
                           "Real-time diffuse IBL: sh (9 coefficients) or cube (irradiance cube)."),
    energy_compensation: bool = _flag(False, ("--energy-compensation/--no-energy-compensation",),
                                      "Real time: Filament's multiple-scattering compensation."),
    engine: str = _choice("pbrkit", "--engine", RENDER_ENGINES, "engine",
                          "Real time: whose IBL evaluation to follow: pbrkit's, or an engine's with its own "
                          "target's chain (a bake folder needs that --target)."),
    bake_size: int = typer.Option(256, "--bake-size", metavar="N",
                                  help="Real time: size of the bake's specular cube (power of two)."),
    fix_nonfinite: bool = _flag(False, ("--fix-nonfinite",),
                                "Replace NaN/Inf pixels of the environment map by the mean of their finite "
                                "neighbours (as bake --fix-nonfinite); without it they are refused."),
    occlusion: Optional[bool] = typer.Option(
        None, "--occlusion/--no-occlusion", show_default=False, metavar="",
        help="Ground truth: objects occlude one another's environment light.  Default: on for reference "
             "(the scene's ground truth), off for compare (like for like: real-time IBL has no occlusion, "
             "so compare's error measures the approximations only)."),
    style: Optional[str] = typer.Option(
        None, "--style", metavar="NAME|FILE",
        help="Real time in a non-photorealistic style: a preset (pbr, toon, toon-per-light, mtoon, hatching, "
             "outline) or a .toml / .json file with a [style] table (pbrkit.npr.style); replaces the scene's "
             "[style]."),
    allow_root: Optional[list[Path]] = typer.Option(
        None, "--allow-root", metavar="DIR",
        help="A folder besides a glTF model's own whose files its buffer and image URIs may name "
             "(repeatable; the scene key allow_roots)."),
    quiet: bool = _quiet_option(),
):
    """Render a scene in real time (split-sum IBL, punctual lights, LTC area lights), as Monte Carlo
    ground truth, or both side by side with an error heat map (compare)."""
    from rich.markup import escape

    from ..core import checks
    from ..rendering.run import STAGES, output_suffix_ok, render_scene
    from ..rendering.sources import command_scene

    output_suffix_ok(out)
    if mode != "realtime":
        checks.integer(spp, "--spp", 1, 1 << 20)
    if mode != "reference":
        checks.power_of_two(bake_size, "--bake-size", 2, 4096)
    for value, flag in ((width, "--width"), (height, "--height")):  # the flag typed, not the scene key
        if value is not None:
            checks.integer(value, flag, 1, 16384)
    style_obj = None
    if style is not None:  # before the scene loads: a style outside real time is refused at once
        from ..npr.style import resolve_style
        from ..rendering.run import check_style_flag

        style_obj = resolve_style(style)
        check_style_flag(mode, style_obj)
    scene_obj = command_scene(scene, width, height, env, fix_nonfinite, allow_root or ())
    with _Stages("render", quiet, len(STAGES[mode])) as stages:
        summary = render_scene(scene_obj, out, mode=mode, spp=spp, bounces=bounces, seed=seed,
                               tonemap_name=tonemap_name, exposure=exposure, diffuse=diffuse,
                               energy_compensation=energy_compensation, bake_size=bake_size, occlusion=occlusion,
                               progress=stages.start, engine=engine, style=style_obj)
    if quiet:
        return
    for note in summary["notes"]:
        _err.print(f"[yellow]pbrkit: note:[/] {escape(str(note))}", highlight=False, soft_wrap=True)
    if "realtime" in summary:
        print(f"real time: {summary['realtime']['timings']['total']:.3f} s")
    if "reference" in summary:
        r = summary["reference"]
        print(f"ground truth: {r['spp']} spp, {r['surface_paths']} paths on surfaces in "
              f"{r['timings']['sampling']:.3f} s ({r['paths_per_second'] / 1e6:.2f} M paths/s)")
    from ..rendering.run import comparison_lines

    for line in comparison_lines(summary):
        print(line)
    print("wrote " + ", ".join(summary["outputs"]))
