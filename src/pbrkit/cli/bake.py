"""``pbrkit bake``: an HDR environment baked for split-sum IBL
(:func:`pbrkit.ibl.bake.bake`, :func:`pbrkit.io.bake_files.write_bake`).

The module imports Typer and the command line's own modules only; the command
imports its work in its body (``pbrkit --help`` stays light)."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Optional

import typer

from ..choices import LAYOUTS
from .console import _Stages, user_errors
from .options import BAKE_OPTIONS, OUT_DIR, TARGET_METAVAR, _choice, _flag, _quiet_option

#: ``pbrkit --help``'s line for the command (None: the docstring's first line).
SHORT_HELP = "Bake an HDR environment for split-sum IBL into a folder."
#: The example ``pbrkit bake --help`` shows (tests/cli/test_cli_help.py parses it).
EXAMPLE = "pbrkit bake sky.hdr -o sky --size 256 --target three"


def _print_targets(out):
    """Each engine target's files and how to load them, from the manifest ``out`` holds
    (its ``targets``: :mod:`pbrkit.engines`; the load line's paths are relative to
    its ``load_base``, the bake folder)."""
    import json

    targets = json.loads((Path(out) / "manifest.json").read_text()).get("targets") or {}
    for name, entry in targets.items():
        files = [f"{out}/{f}" for f in _flat_files(entry.get("files", {}))]
        print(f"{name}: {', '.join(files)}")
        if entry.get("load"):
            print(f"  load (paths relative to {out}/): {entry['load']}")


def _flat_files(files):
    """The relative paths of a manifest's ``files`` (a dict of paths or of dicts of them)."""
    out = []
    for value in files.values():
        if isinstance(value, dict):
            out += _flat_files(value)
        elif isinstance(value, str):
            out.append(value)
        elif isinstance(value, list):
            out += [v for v in value if isinstance(v, str)]
    return out


def _warn_upsampling(result, size):
    """One ``pbrkit: warning:`` line where the bake's specular cube is finer than its map
    (an equirect W x H holds about W / 4 texels per cube face; a cube its face size)."""
    layout = result.manifest["input"]["layout"]
    width, height = result.manifest["input"]["resolution"]
    face = width // 4 if layout == "equirect" else width
    if size > face:
        megabytes = sum(level.nbytes for level in result.specular) / 1e6
        keep = 1 << max(0, int(face).bit_length() - 1)
        warnings.warn(f"--size {size} is finer than the map ({width} x {height}: about {face} texels per cube "
                      f"face): the specular chain upsamples it ({megabytes:.0f} MB); --size {keep} keeps its "
                      "detail", UserWarning, stacklevel=2)


@user_errors
def bake(
    env: list[Path] = typer.Argument(..., metavar="ENV",
                                     help="Environment: one equirect (.hdr, .exr, .pfm, .png, .jpg) or cube-cross "
                                          "image, or six face files in the order +X -X +Y -Y +Z -Z."),
    out: Path = typer.Option(..., "-o", "--out", metavar="DIR", parser=OUT_DIR,
                             help="Output folder (must be absent or empty unless --force)."),
    size: int = BAKE_OPTIONS["size"](),
    min_size: int = BAKE_OPTIONS["min_size"](),
    irradiance_size: int = BAKE_OPTIONS["irradiance_size"](),
    lut_size: int = BAKE_OPTIONS["lut_size"](),
    fmt: str = BAKE_OPTIONS["format"](),
    method: str = BAKE_OPTIONS["method"](),
    sh_window: Optional[str] = BAKE_OPTIONS["sh_window"](),
    layout: Optional[str] = _choice(None, "--layout", LAYOUTS, "layout",
                                    "Force the layout of a single file (default: by aspect ratio)."),
    fix_nonfinite: bool = BAKE_OPTIONS["fix_nonfinite"](),
    force: bool = _flag(False, ("--force",), "Replace a non-empty output folder."),
    target: Optional[list[str]] = typer.Option(
        None, "--target", metavar=TARGET_METAVAR,
        help="Also write the files of an engine, baked for its conventions, in OUT/<target>/ (repeatable, or a "
             "comma-separated list; generic, pbrkit's own files at the top of OUT, is always written; the "
             "manifest says how to load each)."),
    only_target: bool = _flag(False, ("--only-target",),
                              "Write only the --target engines' folders and manifest.json, not pbrkit's own "
                              "files (needs an engine; the bake then loads in those engines only)."),
    quiet: bool = _quiet_option(),
):
    """Bake an HDR environment for split-sum IBL: prefiltered specular chain, irradiance
    cube, SH9, DFG table, faces, preview and manifest.json in OUT."""
    from ..core.atomic import check_output_directory
    from ..ibl.bake import bake as bake_environment
    from ..io.bake_files import chains_for, parse_targets, write_bake, write_steps

    targets = parse_targets(target, only_targets=only_target)

    if len(env) not in (1, 6):
        raise ValueError(f"give one environment file or six face files, got {len(env)} (to bake several "
                         f"environments, one folder each: pbrkit batch bake {' '.join(str(e) for e in env[:2])} "
                         "... -o DIR)")
    check_output_directory(out, force)
    with _Stages("bake", quiet, 1) as stages:
        baking = [1]

        def bake_stage(name, number, total):
            baking[0] = total
            stages.start(name, number, total + len(write_steps(targets)))

        def write_stage(name, number, total):
            stages.start(name, baking[0] + number, baking[0] + total)

        result = bake_environment(env[0] if len(env) == 1 else env, size=size, min_size=min_size,
                                  irradiance_size=irradiance_size, lut_size=lut_size, specular_format=fmt,
                                  method=method, sh_window=sh_window, fix_nonfinite=fix_nonfinite,
                                  layout=layout, chains=chains_for(targets), started=bake_stage)
        write_bake(result, out, force=force, started=write_stage, targets=targets, only_targets=only_target)
    _warn_upsampling(result, size)
    if not quiet:
        levels = ", ".join(f"{r:g}" for r in result.roughness)
        print(f"wrote {out}: specular {size}^2, {result.levels} levels (roughness {levels}), "
              f"irradiance {irradiance_size}^2, SH9, DFG table {lut_size}^2")
        _print_targets(out)
        print("times (s): " + ", ".join(f"{k} {v:.3f}" for k, v in result.timings.items())
              + f"; total {sum(result.timings.values()):.3f} + writing")
