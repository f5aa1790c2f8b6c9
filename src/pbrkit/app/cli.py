"""The ``pbrkit`` command line (Typer + Rich)."""

from __future__ import annotations

import functools
import sys
from pathlib import Path
from typing import Optional

import typer
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

from .. import __version__
from ..core import checks

app = typer.Typer(
    help="pbrkit: physically based shading for real-time rendering.",
    no_args_is_help=True,
    add_completion=False,
    context_settings={"help_option_names": ["-h", "--help"]},
)
_err = Console(stderr=True)


def _version_callback(value: bool):
    if value:
        print(f"pbrkit {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: bool = typer.Option(False, "--version", callback=_version_callback, is_eager=True,
                                 help="Print the version and exit."),
):
    """pbrkit: physically based shading for real-time rendering."""


def user_errors(fn):
    """Turn expected failures (bad input, bad options, I/O) into one-line errors and exit status 1."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except (ValueError, OSError) as exc:
            _err.print(f"[bold red]pbrkit: error:[/] {exc}", highlight=False, soft_wrap=True)
            raise typer.Exit(1) from None

    return wrapper


def progress_bar(quiet: bool, total: int, description: str):
    """A Rich progress bar on a terminal; silent with ``quiet`` or when stderr is not a terminal."""
    return Progress(
        TextColumn("[progress.description]{task.description}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total}"),
        TimeElapsedColumn(),
        console=_err,
        disable=quiet or not sys.stderr.isatty(),
        transient=False,
    )


@app.command()
@user_errors
def furnace(
    out: Path = typer.Option(..., "-o", "--out", help="Output folder."),
    mu_count: int = typer.Option(32, "--mu", help="Number of mu = n.v values (texel centres)."),
    roughness_count: int = typer.Option(11, "--roughness", help="Number of roughness values in [0, 1]."),
    samples: int = typer.Option(256, "--samples", help="Monte Carlo samples per (mu, roughness) cell."),
    seed: int = typer.Option(0, "--seed", help="Seed of the Monte Carlo generator."),
    lobe: Optional[list[str]] = typer.Option(None, "--lobe", help="Only these lobes (repeatable)."),
    compensation: Optional[str] = typer.Option(
        None, "--compensation",
        help="Also show multiple-scattering compensation: kulla-conty or filament (compensation.*)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar or summary."),
):
    """White-furnace albedo E(mu) of every D x G combination and model (F = 1).

    Writes furnace.csv, furnace.npy, furnace.json and furnace.png to OUT; with
    --compensation also compensation.csv/.npy/.json/.png (white furnace of a
    compensated GGX surface, and gold and copper keeping their saturation).
    """
    import numpy as np

    from ..albedo.furnace import furnace_lobes
    from .report import furnace_report

    checks.integer(roughness_count, "--roughness", 2, 1024)
    if compensation is not None and compensation not in ("kulla-conty", "filament"):
        raise ValueError(f"--compensation must be kulla-conty or filament; got {compensation!r}")
    names = lobe or list(furnace_lobes())
    with progress_bar(quiet, len(names), "furnace") as bar:
        task = bar.add_task("furnace", total=len(names))
        summary, timings = furnace_report(out, n_mu=mu_count, roughness=np.linspace(0.0, 1.0, roughness_count),
                                 samples=samples, seed=seed, lobes=names,
                                 progress=lambda name: bar.advance(task))
    if not quiet:
        from rich.table import Table

        table = Table(title="Single-scattering albedo with F = 1 (quadrature)")
        for col in ("lobe", "min E", "max E", "max |MC - quad|", "MC within 3 se", "quadrature s", "MC s"):
            table.add_column(col, justify="right" if col != "lobe" else "left")
        for name, s in summary["per_lobe"].items():
            table.add_row(name, f"{s['min_albedo']:.4f}", f"{s['max_albedo']:.4f}",
                          f"{s['max_abs_mc_minus_quadrature']:.2e}", f"{100 * s['fraction_within_3_stderr']:.0f}%",
                          f"{timings[name]['quadrature_s']:.2f}", f"{timings[name]['monte_carlo_s']:.2f}")
        Console(width=max(110, _err.width)).print(table)
        print(f"wrote {out}/furnace.csv, furnace.npy, furnace.json, furnace.png")
    if compensation is not None:
        from .report import compensation_report

        s = compensation_report(out, compensation)
        if not quiet:
            print(f"{compensation} compensation, F = 1 GGX: max |E - 1| = {s['max_abs_error_on_texel_grid']:.1e} "
                  f"on the {s['table_size']}^2 table's texel grid (without: energy loss up to "
                  f"{s['max_energy_loss_without_compensation']:.3f}); between texels (bilinear) max "
                  f"{s['between_texels']['max_abs_error']:.1e}, median {s['between_texels']['median_abs_error']:.1e}")
            print(f"wrote {out}/compensation.csv, compensation.npy, compensation.json, compensation.png")


@app.command()
@user_errors
def lut(
    out: Path = typer.Option(..., "-o", "--out",
                             help="Output file: .npy, .exr, .png (16-bit), .h (C header, float16) or .ktx2."),
    kind: str = typer.Option("dfg", "--kind", help="splitsum (UE4: A, B) or dfg (Filament: DFG1, DFG2)."),
    size: int = typer.Option(128, "--size", help="Table size N (N x N texels)."),
    cloth: bool = typer.Option(False, "--cloth", help="Add the Charlie / Neubelt sheen albedo channel."),
    visibility: Optional[str] = typer.Option(
        None, "--visibility",
        help="schlick-ggx (splitsum default), separable or height-correlated (dfg default)."),
    samples: Optional[int] = typer.Option(
        None, "--samples",
        help="Quadrature nodes per texel (theta x phi); default: the converged rule (144 nodes, 288 at grazing)."),
    ktx2_format: str = typer.Option("float16", "--ktx2-format", help="float16 or float32 texels in .ktx2."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing on success."),
):
    """Split-sum (A, B) or DFG (DFG1, DFG2[, cloth]) lookup table with its JSON description."""
    import warnings

    from ..albedo.tables import DEFAULT_NODES, lookup_table
    from ..io.lut_files import LUT_SUFFIXES, QuantisationWarning, write_lut

    if out.suffix.lower() not in LUT_SUFFIXES:
        raise ValueError(f"{out}: unsupported table format {out.suffix!r}; use one of {', '.join(LUT_SUFFIXES)}")
    nodes = DEFAULT_NODES
    if samples is not None:
        checks.integer(samples, "--samples", 8, 1 << 20)
        # Split the budget as the default rule does: 2 theta segments x n_theta x n_phi, n_phi = n_theta / 2.
        n_theta = max(2, int(round(samples ** 0.5)))
        nodes = (n_theta, 2 * n_theta, max(2, n_theta // 2))
    table, spec = lookup_table(kind, size, visibility, cloth, nodes)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", QuantisationWarning)
        written = write_lut(out, table, spec, ktx2_format)
    for w in caught:
        _err.print(f"[yellow]pbrkit: warning:[/] {w.message}", highlight=False, soft_wrap=True)
    if not quiet:
        print(f"wrote {written[0]} ({kind}, {size} x {size}, {table.shape[2]} channels, "
              f"visibility {spec.visibility}) and {written[1].name}")


@app.command()
@user_errors
def approximations(
    out: Path = typer.Option(..., "-o", "--out", help="Output folder."),
    size: int = typer.Option(32, "--size", help="Grid size N over (n.v, roughness)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing on success."),
):
    """Error heat maps of real-time approximations (Karis' fit, Fresnel and masking
    shortcuts, URP mobile, compensation) as directional-albedo differences."""
    from ..albedo.approximations import approximations_report

    checks.integer(size, "--size", 4, 256)
    summary = approximations_report(out, size)
    if not quiet:
        from rich.table import Table

        table = Table(title="Albedo error of real-time approximations")
        for col in ("comparison", "max |error|", "mean |error|", "at n.v", "at r"):
            table.add_column(col, justify="left" if col == "comparison" else "right")
        for name, s in summary["comparisons"].items():
            table.add_row(name, f"{s['max_abs_error']:.2e}", f"{s['mean_abs_error']:.2e}",
                          f"{s['at']['nv']:.3f}", f"{s['at']['roughness']:.3f}")
        Console(width=max(100, _err.width)).print(table)
        print(f"wrote {out}/approximations.png and approximations.json")


@app.command()
@user_errors
def render(
    scene: str = typer.Argument(..., help="Scene file (.toml or .json) or a built-in scene: spheres, sphere."),
    out: Path = typer.Option(..., "-o", "--out",
                             help="Output image: .exr (linear float32) or .png (tone-mapped, sRGB)."),
    mode: str = typer.Option("realtime", "--mode", help="realtime, reference (Monte Carlo) or compare (both)."),
    spp: int = typer.Option(64, "--spp", help="Ground-truth samples per pixel."),
    bounces: int = typer.Option(0, "--bounces", help="Ground-truth bounces after the first hit (0: direct light)."),
    tonemap_name: str = typer.Option("aces", "--tonemap", help="aces, khronos-neutral, agx, reinhard or none."),
    exposure: float = typer.Option(0.0, "--exposure", help="Exposure in EV applied before tone mapping (PNG)."),
    width: Optional[int] = typer.Option(None, "--width", help="Image width (overrides the scene's camera)."),
    height: Optional[int] = typer.Option(None, "--height", help="Image height (overrides the scene's camera)."),
    env: Optional[Path] = typer.Option(None, "--env", help="Environment map replacing the scene's."),
    seed: int = typer.Option(0, "--seed", help="Seed of the ground truth's random numbers."),
    diffuse: str = typer.Option("sh", "--diffuse", help="Real-time diffuse IBL: sh or cube (irradiance cube)."),
    energy_compensation: bool = typer.Option(False, "--energy-compensation/--no-energy-compensation",
                                             help="Real time: Filament's multiple-scattering compensation."),
    bake_size: int = typer.Option(256, "--bake-size", help="Real time: size of the bake's specular cube."),
    no_occlusion: bool = typer.Option(False, "--no-occlusion",
                                      help="Ground truth: objects do not occlude one another (as real-time IBL)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Print nothing on success."),
):
    """Render a scene in real time (split-sum IBL + punctual lights), as Monte Carlo
    ground truth, or both side by side with an error heat map (compare)."""
    from ..render.run import output_suffix_ok, render_scene
    from ..render.scene import EnvironmentSpec, resolve_scene

    output_suffix_ok(out)
    environment = None
    if env is not None:
        if not env.exists():
            raise ValueError(f"{env}: environment file not found")
        environment = EnvironmentSpec(file=str(env))
    scene_obj = resolve_scene(scene, width, height, environment)
    summary = render_scene(scene_obj, out, mode=mode, spp=spp, bounces=bounces, seed=seed, tonemap_name=tonemap_name,
                           exposure=exposure, diffuse=diffuse, energy_compensation=energy_compensation,
                           bake_size=bake_size, occlusion=not no_occlusion)
    if quiet:
        return
    for note in summary["notes"]:
        _err.print(f"[yellow]pbrkit: note:[/] {note}", highlight=False, soft_wrap=True)
    if "realtime" in summary:
        print(f"real time: {summary['realtime']['timings']['total']:.3f} s")
    if "reference" in summary:
        r = summary["reference"]
        print(f"ground truth: {r['spp']} spp, {r['surface_paths']} paths on surfaces in "
              f"{r['timings']['sampling']:.3f} s ({r['paths_per_second'] / 1e6:.2f} M paths/s)")
    if "errors" in summary:
        e = summary["errors"]
        print(f"real time vs ground truth: mean relative error {e['mean_relative_error']:.4f}, "
              f"max relative error {e['max_relative_error']:.4f}, FLIP {e['flip']:.4f} "
              f"(ground-truth noise {e.get('mean_relative_stderr', 0.0):.4f})")
    print("wrote " + ", ".join(summary["outputs"]))


@app.command()
@user_errors
def demo(
    out: Path = typer.Option(..., "-o", "--out", help="Output folder (index.html and its images)."),
    size: int = typer.Option(384, "--size", help="Side of the sphere-grid images in pixels."),
    spp: int = typer.Option(192, "--spp", help="Ground-truth samples per pixel."),
    bake_size: int = typer.Option(128, "--bake-size", help="Size of the bake's specular cube (power of two)."),
    seed: int = typer.Option(0, "--seed", help="Seed of the random numbers."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar or summary."),
):
    """Bake the bundled environment, render the sphere grid in real time and as ground
    truth, plot the furnace test and the lookup table, and write OUT/index.html."""
    from .demo import run_demo

    steps = ("bake", "realtime", "reference", "images", "furnace", "lut", "page")
    with progress_bar(quiet, len(steps), "demo") as bar:
        task = bar.add_task("demo", total=len(steps))
        summary = run_demo(out, size=size, spp=spp, bake_size=bake_size, seed=seed,
                           progress=lambda name: bar.advance(task))
    if not quiet:
        e = summary["errors"]
        print(f"mean relative error {e['mean_relative_error']:.4f}, FLIP {e.get('flip', float('nan')):.4f}; "
              f"total {summary['timings_s']['total']:.1f} s")
        print(f"wrote {out / 'index.html'}")


@app.command()
@user_errors
def bake(
    env: list[Path] = typer.Argument(..., help="Environment: one equirect (.hdr, .exr, .pfm, .png, .jpg) or cube-cross "
                                           "image, or six face files in the order +X -X +Y -Y +Z -Z."),
    out: Path = typer.Option(..., "-o", "--out", help="Output folder (must be absent or empty unless --force)."),
    size: int = typer.Option(256, "--size", help="Specular cube size (power of two, <= 4096)."),
    min_size: int = typer.Option(16, "--min-size", help="Size of the last (roughest) specular level."),
    irradiance_size: int = typer.Option(32, "--irradiance-size", help="Irradiance cube size."),
    lut_size: int = typer.Option(128, "--lut-size", help="DFG lookup-table size."),
    fmt: str = typer.Option("rgba16f", "--format", help="KTX2/DDS texel format: rgba16f or b10g11r11."),
    method: str = typer.Option("spectral", "--method",
                               help="spectral (exact SH-domain convolution) or fis (filtered importance sampling)."),
    sh_window: Optional[str] = typer.Option(None, "--sh-window", help="Window the stored SH: hanning or lanczos."),
    layout: Optional[str] = typer.Option(None, "--layout", help="Force equirect, hcross or vcross for one file."),
    fix_nonfinite: bool = typer.Option(False, "--fix-nonfinite",
                                       help="Replace NaN/Inf pixels by the mean of their finite neighbours."),
    force: bool = typer.Option(False, "--force", help="Replace a non-empty output folder."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar or summary."),
):
    """Bake an HDR environment for split-sum IBL: prefiltered specular chain, irradiance
    cube, SH9, DFG table, faces, preview and manifest.json in OUT."""
    import warnings

    from ..core.atomic import check_output_directory
    from ..ibl.bake import bake as bake_environment
    from ..io.bake_files import write_bake

    if len(env) not in (1, 6):
        raise ValueError(f"give one environment file or six face files, got {len(env)}")
    check_output_directory(out, force)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with progress_bar(quiet, 1, "bake") as bar:
            task = bar.add_task("bake", total=None)

            def step(name, done, total):
                bar.update(task, description=name, completed=done, total=total)

            result = bake_environment(env[0] if len(env) == 1 else env, size=size, min_size=min_size,
                                      irradiance_size=irradiance_size, lut_size=lut_size, specular_format=fmt,
                                      method=method, sh_window=sh_window, fix_nonfinite=fix_nonfinite,
                                      layout=layout, progress=step)
            write_bake(result, out, force=force, progress=step)
    for w in caught:
        _err.print(f"[yellow]pbrkit: warning:[/] {w.message}", highlight=False, soft_wrap=True)
    if not quiet:
        levels = ", ".join(f"{r:g}" for r in result.roughness)
        print(f"wrote {out}: specular {size}^2, {result.levels} levels (roughness {levels}), "
              f"irradiance {irradiance_size}^2, SH9, DFG table {lut_size}^2")
        print("times (s): " + ", ".join(f"{k} {v:.3f}" for k, v in result.timings.items())
              + f"; total {sum(result.timings.values()):.3f} + writing")


if __name__ == "__main__":  # pragma: no cover
    app()
