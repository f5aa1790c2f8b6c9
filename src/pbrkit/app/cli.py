"""The ``pbrkit`` command line (Typer + Rich).

What a user sees:

- every refusal is one line on stderr, ``pbrkit: error: <file>: <problem>``,
  exit status 1 (bad options included), nothing on stdout and no output
  left behind; Ctrl-C gives ``pbrkit: error: interrupted`` (130) and SIGTERM
  ``pbrkit: error: terminated (SIGTERM)`` (143), after the same clean-up;
- progress by stage on stderr: a Rich bar on a terminal, one plain line per
  stage (``pbrkit render: reference (3/4)``) when stderr is not a terminal,
  nothing with ``--quiet``;
- ``--help`` lists the choices of every option with a fixed set of values
  (``[realtime|reference|compare]``) and answers without importing NumPy or
  Numba: the commands import what they need in their bodies.
"""

from __future__ import annotations

import contextlib
import functools
import signal
import sys
import warnings
from pathlib import Path
from typing import Optional

import typer
from typer.core import TyperCommand, TyperGroup

try:  # typer >= 0.2x vendors its own click
    from typer import _click as _click
except ImportError:  # pragma: no cover - a typer built on click itself
    import click as _click

# The choices of the options with a fixed set of values: pbrkit.choices, their only
# definition (it imports nothing, so `pbrkit --help` stays light).
from ..choices import (BAKE_FORMATS, BAKE_METHODS, COMPENSATIONS, DIFFUSE_MODES, KTX2_FORMATS, LAYOUTS, LOBES,
                       LTC_CLIPPINGS, LUT_KINDS, MODES, RENDER_ENGINES, SH_WINDOWS, SHADER_TARGETS, TONEMAPS,
                       VISIBILITIES)

SEED_MAX = 2 ** 64 - 1  # the renderer's counter-based generator takes a uint64; NumPy's default_rng any int >= 0
EXPOSURE_LIMIT = 64.0   # |EV|: 2^64 is far beyond any useful exposure and still finite in float32 arithmetic

# ----------------------------------------------------------------- errors


def _one_line(text):
    return " ".join(str(text).split())


def _isatty(stream):
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):
        return False


def _console():
    from rich.console import Console

    return Console(stderr=True, soft_wrap=True, highlight=False)


class _StderrConsole:
    """``_err``: a Rich console on stderr, created when first used (``pbrkit --help``
    does not import Rich's console)."""

    def __getattr__(self, name):
        return getattr(_console(), name)


_err = _StderrConsole()


def _say(kind, message, style):
    """One line ``pbrkit: <kind>: <message>`` on stderr (coloured on a terminal)."""
    from rich.text import Text

    _console().print(Text.assemble((f"pbrkit: {kind}:", style), " ", _one_line(message)))


def _is_library_error(exc):
    """Exceptions of the image libraries that mean bad input or a failed write, not a bug."""
    return type(exc).__module__.split(".")[0] in ("OpenEXR",)


@contextlib.contextmanager
def _interruptible():
    """SIGTERM raises :class:`pbrkit.core.errors.Terminated` (a KeyboardInterrupt) and
    SIGINT KeyboardInterrupt, once each, while a command runs, so that the clean-up
    of partial output runs for both; a second signal during the clean-up is ignored."""
    from ..core.errors import Terminated

    def on_signal(signum, frame):
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, signal.SIG_IGN)
        raise Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()

    try:
        previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    except (ValueError, OSError):  # not the main thread: leave the handlers alone
        yield
        return
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def user_errors(fn):
    """Turn expected failures into one line ``pbrkit: error: ...`` on stderr and an
    exit status: bad input, bad options and I/O (ValueError, OSError, OpenEXR's
    errors; 1), running out of memory (1), Ctrl-C (``interrupted``, 130) and SIGTERM
    (``terminated (SIGTERM)``, 143).  Anything else is a bug and propagates with its
    traceback.  Warnings (UserWarning and its subclasses) are printed as
    ``pbrkit: warning: ...`` lines once the command has succeeded."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        from ..core.errors import Terminated

        code = None
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UserWarning)
            try:
                with _interruptible():
                    result = fn(*args, **kwargs)
            except Terminated:
                _say("error", "terminated (SIGTERM)", "bold red")
                code = 143
            except KeyboardInterrupt:
                _say("error", "interrupted", "bold red")
                code = 130
            except MemoryError as exc:
                _say("error", f"out of memory{f' ({exc})' if str(exc) else ''}; try smaller sizes", "bold red")
                code = 1
            except (ValueError, OSError) as exc:
                _say("error", exc, "bold red")
                code = 1
            except Exception as exc:
                if not _is_library_error(exc):
                    raise
                _say("error", exc, "bold red")
                code = 1
        if code is not None:
            raise typer.Exit(code)
        seen = set()
        for w in caught:
            text = _one_line(w.message)
            if issubclass(w.category, UserWarning) and not issubclass(w.category, DeprecationWarning) \
                    and text not in seen:
                seen.add(text)
                _say("warning", text, "yellow")
        return result

    return wrapper


# ------------------------------------------------------- commands and help


def _help_option_without_type(command, ctx, base):
    option = base.get_help_option(command, ctx)
    if option is not None and option.metavar is None:
        option.metavar = ""  # no "<bool>" beside -h/--help
    return option


class _Command(TyperCommand):
    """A command whose --help shows no Python type (``<bool>``, ``<list[Path]>``):
    options carry metavars, arguments their name and their help."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        for param in self.params:
            if param.param_type_name == "argument":
                param.display_type_rich = lambda ctx: None

    def get_help_option(self, ctx):
        return _help_option_without_type(self, ctx, TyperCommand)


class _Group(TyperGroup):
    """The ``pbrkit`` group: usage errors (unknown options, bad or missing values)
    become one line ``pbrkit: error: ...`` and exit status 1, like every other
    refusal."""

    def get_help_option(self, ctx):
        return _help_option_without_type(self, ctx, TyperGroup)

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        if not standalone_mode:
            return super().main(args=args, prog_name=prog_name, complete_var=complete_var,
                                standalone_mode=False, **extra)
        try:
            rv = super().main(args=args, prog_name=prog_name, complete_var=complete_var,
                              standalone_mode=False, **extra)
        except _click.exceptions.ClickException as exc:
            if type(exc).__name__ == "NoArgsIsHelpError":  # `pbrkit` alone: the help was shown
                sys.exit(exc.exit_code)
            message = exc.format_message()
            param = getattr(exc, "param", None)
            if isinstance(exc, _click.exceptions.BadParameter) and getattr(param, "opts", None) and exc.message \
                    and not isinstance(exc, _click.exceptions.MissingParameter):
                message = f"{max(param.opts, key=len)}: {exc.message}"
            ctx = getattr(exc, "ctx", None)
            if isinstance(exc, _click.exceptions.UsageError) and ctx is not None:
                message = f"{message} (see '{ctx.command_path} --help')"
            _say("error", message, "bold red")
            sys.exit(1)
        except typer.Abort:
            _say("error", "aborted", "bold red")
            sys.exit(1)
        sys.exit(rv if isinstance(rv, int) and not isinstance(rv, bool) else 0)


app = typer.Typer(
    cls=_Group,
    no_args_is_help=True,
    add_completion=False,
    context_settings={"help_option_names": ["-h", "--help"]},
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
    the same input, options and --seed (default 0 everywhere)."""


# ------------------------------------------------------------- options


def _choice_check(noun, choices):
    def check(value):
        values = value if isinstance(value, (list, tuple)) else [value]
        for v in values:
            if v is not None and v not in choices:
                raise typer.BadParameter(f"unknown {noun} {v!r}; choose one of {', '.join(choices)}")
        return value

    return check


def _choice(default, flag, choices, noun, help_text):
    """An option with a fixed set of values: --help shows ``[a|b|c]``; anything else
    is refused as ``--flag: unknown <noun> 'x'; choose one of a, b, c``."""
    return typer.Option(default, flag, metavar="[" + "|".join(choices) + "]", callback=_choice_check(noun, choices),
                        help=help_text)


def _check_seed(value):
    if value is not None and not 0 <= value <= SEED_MAX:
        raise typer.BadParameter(f"the seed must be an integer in [0, 2^64 - 1] = [0, {SEED_MAX}]; got {value}")
    return value


def _seed_option(help_text):
    return typer.Option(0, "--seed", metavar="SEED", callback=_check_seed,
                        help=f"{help_text} An integer in [0, 2^64 - 1]; the same seed gives the same bytes.")


def _check_exposure(value):
    import math

    if not math.isfinite(value) or abs(value) > EXPOSURE_LIMIT:
        raise typer.BadParameter(f"exposure must be a finite number of EV in [-{EXPOSURE_LIMIT:g}, "
                                 f"{EXPOSURE_LIMIT:g}]; got {value}")
    return value


def _quiet_option():
    return typer.Option(False, "--quiet", "-q", metavar="",
                        help="No progress and no summary (warnings and errors still print).")


def _flag(default, decls, help_text, **kwargs):
    return typer.Option(default, *decls, metavar="", help=help_text, **kwargs)


def _output_path(kind):
    """The ``parser`` of every ``-o/--out`` option (``kind``: ``"DIR"`` or ``"FILE"``,
    as its metavar): refused as the command line is read, before any work, are an
    empty path (``-o ""``), an existing file where a folder is wanted, an existing
    folder or device where a file is, and a path under a file (its nearest existing
    parent is not a folder).  Typer's errors name the option (``--out: empty path``)."""
    import os
    import stat

    wanted = "a folder (DIR)" if kind == "DIR" else "a file (FILE)"

    def parse(value):
        text = str(value)
        if not text.strip():
            raise typer.BadParameter(f"empty path; expected {wanted}")
        if "\x00" in text:
            raise typer.BadParameter(f"a path with a NUL character; expected {wanted}")
        path = Path(text)
        try:
            mode = os.stat(path).st_mode
        except (FileNotFoundError, NotADirectoryError):
            mode = None
        except OSError as exc:  # a name too long, a loop of links, no permission
            raise typer.BadParameter(f"{path}: cannot use it ({exc.strerror or type(exc).__name__}); "
                                     f"expected {wanted}") from None
        if mode is not None and kind == "DIR" and not stat.S_ISDIR(mode):
            raise typer.BadParameter(f"{path}: exists and is not a directory; expected {wanted}")
        if mode is not None and kind != "DIR" and not stat.S_ISREG(mode):
            what = "a directory" if stat.S_ISDIR(mode) else "not a regular file"
            raise typer.BadParameter(f"{path}: exists and is {what}; expected {wanted}")
        parent = path.absolute().parent
        while not parent.exists() and parent != parent.parent:
            parent = parent.parent
        if not parent.is_dir():
            raise typer.BadParameter(f"{path}: its parent {parent} is not a directory; expected {wanted}")
        return path

    parse.__name__ = kind.lower()
    return parse


#: The ``parser`` of the ``-o/--out`` options naming a folder, and a file (:func:`_output_path`).
OUT_DIR, OUT_FILE = _output_path("DIR"), _output_path("FILE")


# ------------------------------------------------------------- progress


class _Stages:
    """Progress of one command by stage, on stderr: a Rich bar on a terminal
    (transient: it disappears when the command ends), one plain line per stage
    otherwise (``pbrkit render: reference (3/4)``), nothing with ``quiet``.
    :meth:`start` is called as each stage starts.

    The first stage's line waits until that stage has run for
    :data:`FIRST_LINE_DELAY` seconds or the next one starts, and is dropped if
    the command fails before: bad input, found while loading it, is then
    refused with its one error line alone."""

    FIRST_LINE_DELAY = 1.0

    def __init__(self, command, quiet, total):
        self.command = command
        self.total = max(1, int(total))
        self.number = 0
        self.mode = "off" if quiet else ("bar" if _isatty(sys.stderr) else "lines")
        self._bar = None
        self._task = None
        self._pending = None
        self._timer = None
        self._lock = None
        self._fd = None

    def __enter__(self):
        if self.mode == "bar":
            from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

            self._bar = Progress(TextColumn(f"pbrkit {self.command}: " + "{task.description}"), BarColumn(),
                                 TextColumn("{task.completed}/{task.total}"), TimeElapsedColumn(),
                                 console=_console(), transient=True)
            self._bar.start()
            self._task = self._bar.add_task("starting", total=self.total)
        elif self.mode == "lines":
            import os
            import threading

            self._lock = threading.Lock()
            try:  # lines go to the real stderr even while a native library's output is captured
                self._fd = os.dup(sys.stderr.fileno())
            except (AttributeError, ValueError, OSError):  # not a file (e.g. a test runner's buffer)
                self._fd = None
        return self

    def __exit__(self, exc_type, exc, tb):
        if self._bar is not None:
            self._bar.stop()
        if self._lock is not None:
            if self._timer is not None:
                self._timer.cancel()
            with self._lock:
                if exc_type is None:
                    self._print_pending()
                self._pending = None
                if self._fd is not None:
                    import os

                    os.close(self._fd)
                    self._fd = None
        return False

    def _write(self, line):
        if self._fd is None:
            print(line, file=sys.stderr, flush=True)
            return
        import os

        with contextlib.suppress(Exception):
            sys.stderr.flush()
        with contextlib.suppress(OSError):
            os.write(self._fd, (line + "\n").encode("utf-8", errors="replace"))

    def _print_pending(self):
        if self._pending is not None:
            self._write(self._pending)
            self._pending = None

    def _timed_out(self):
        with self._lock:
            self._print_pending()

    def start(self, name, number=None, total=None):
        """Stage ``name`` starts: ``number`` (from 1; counted here if None) of ``total``."""
        first = self.number == 0
        self.number = self.number + 1 if number is None else int(number)
        if total is not None:
            self.total = int(total)
        self.total = max(self.total, self.number)
        if self.mode == "lines":
            import threading

            line = f"pbrkit {self.command}: {name} ({self.number}/{self.total})"
            with self._lock:
                self._print_pending()
                if first:
                    self._pending = line
                    self._timer = threading.Timer(self.FIRST_LINE_DELAY, self._timed_out)
                    self._timer.daemon = True
                    self._timer.start()
                else:
                    self._write(line)
        elif self._bar is not None:
            self._bar.update(self._task, description=str(name), completed=self.number - 1, total=self.total)


# ------------------------------------------------------------- commands


@app.command(cls=_Command)
@user_errors
def furnace(
    out: Path = typer.Option(..., "-o", "--out", metavar="DIR", parser=OUT_DIR,
                             help="Output folder (must be absent or empty unless --force)."),
    mu_count: int = typer.Option(32, "--mu", metavar="N", help="Number of mu = n.v values (texel centres)."),
    roughness_count: int = typer.Option(11, "--roughness", metavar="N", help="Number of roughness values in [0, 1]."),
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
    from .report import compensation_files, furnace_files, write_files

    check_output_directory(out, force)
    checks.integer(roughness_count, "--roughness", 2, 1024)
    checks.integer(mu_count, "--mu", 2, 4096)
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


@app.command(cls=_Command)
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


@app.command(cls=_Command, short_help="Error heat maps of real-time approximations as directional-albedo differences.")
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


@app.command(cls=_Command, short_help="Render a scene in real time, as Monte Carlo ground truth, or both (compare).")
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


@app.command(cls=_Command, short_help="Bake, render, compare and plot the bundled scene into OUT/index.html.")
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
    from .demo import run_demo

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


#: The options ``pbrkit bake`` and ``pbrkit batch bake`` share: factories giving each
#: command its own Typer option.
BAKE_OPTIONS = {
    "size": lambda: typer.Option(256, "--size", metavar="N", help="Specular cube size (power of two, <= 4096)."),
    "min_size": lambda: typer.Option(16, "--min-size", metavar="N",
                                     help="Size of the last (roughest) specular level."),
    "irradiance_size": lambda: typer.Option(32, "--irradiance-size", metavar="N", help="Irradiance cube size."),
    "lut_size": lambda: typer.Option(128, "--lut-size", metavar="N", help="DFG lookup-table size."),
    "format": lambda: _choice("rgba16f", "--format", BAKE_FORMATS, "format", "KTX2/DDS texel format."),
    "method": lambda: _choice("spectral", "--method", BAKE_METHODS, "method",
                              "spectral (exact SH-domain convolution) or fis (filtered importance sampling)."),
    "sh_window": lambda: _choice(None, "--sh-window", SH_WINDOWS, "SH window", "Window the stored SH (default: none)."),
    "fix_nonfinite": lambda: _flag(False, ("--fix-nonfinite",),
                                   "Replace NaN/Inf pixels by the mean of their finite neighbours (refused when more "
                                   "than half of an image is NaN/Inf); without it they are refused."),
}


def _print_targets(out):
    """Each engine target's files and how to load them, from the manifest ``out`` holds
    (its ``targets``: :mod:`pbrkit.io.engine_targets`)."""
    import json

    targets = json.loads((Path(out) / "manifest.json").read_text()).get("targets") or {}
    for name, entry in targets.items():
        files = [f"{out}/{f}" for f in _flat_files(entry.get("files", {}))]
        print(f"{name}: {', '.join(files)}")
        if entry.get("load"):
            print(f"  load: {entry['load']}")


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


@app.command(cls=_Command, short_help="Bake an HDR environment for split-sum IBL into a folder.")
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
        None, "--target", metavar="[generic|filament|khronos|babylon|three|all]",
        help="Also write the files of an engine, baked for its conventions, in OUT/<target>/ (repeatable, or a "
             "comma-separated list; generic, pbrkit's own files at the top of OUT, is always written; the "
             "manifest says how to load each)."),
    quiet: bool = _quiet_option(),
):
    """Bake an HDR environment for split-sum IBL: prefiltered specular chain, irradiance
    cube, SH9, DFG table, faces, preview and manifest.json in OUT."""
    from ..core.atomic import check_output_directory
    from ..ibl.bake import bake as bake_environment
    from ..io.bake_files import chains_for, parse_targets, write_bake, write_steps

    targets = parse_targets(target)

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
        write_bake(result, out, force=force, started=write_stage, targets=targets)
    _warn_upsampling(result, size)
    if not quiet:
        levels = ", ".join(f"{r:g}" for r in result.roughness)
        print(f"wrote {out}: specular {size}^2, {result.levels} levels (roughness {levels}), "
              f"irradiance {irradiance_size}^2, SH9, DFG table {lut_size}^2")
        _print_targets(out)
        print("times (s): " + ", ".join(f"{k} {v:.3f}" for k, v in result.timings.items())
              + f"; total {sum(result.timings.values()):.3f} + writing")


@app.command(cls=_Command, short_help="Fit LTC tables for polygonal area lights, in the layout engines load.")
@user_errors
def ltc(
    out: Path = typer.Option(..., "-o", "--out", metavar="DIR", parser=OUT_DIR,
                             help="Output folder (must be absent or empty unless --force)."),
    size: int = typer.Option(64, "--size", metavar="N",
                             help="Cells per side (64: the published layout engines load)."),
    polygons: int = typer.Option(64, "--polygons", metavar="K", help="Rectangular lights each cell is fitted on."),
    seed: int = _seed_option("Seed of the lights each cell is fitted on."),
    fit_f0: str = typer.Option("1", "--fit-f0", metavar="F0[,F0...]",
                               help="Normal reflectances the fit weighs (Schlick F): 1 = the lobe without Fresnel "
                                    "(as the published table); 1,0.04 also a dielectric's, better for dielectrics "
                                    "and worse at F = 1."),
    clipping: str = _choice("sphere", "--clipping", LTC_CLIPPINGS, "clipping",
                            "Horizon clipping the table is fitted for: sphere (the shaders' approximation, what "
                            "engines run: the drop-in table) or exact (pbrkit's own evaluation, "
                            "pbrkit.ltc.score.ltc_exact_rect; same layout)."),
    distribution: str = _choice("ggx", "--distribution", ("ggx", "beckmann"),  # pbrkit.ltc.score.LTC_DISTRIBUTIONS
                                "distribution",
                                "Microfacet distribution of the lobe the tables are fitted for: ggx or beckmann "
                                "(cook_torrance's; alpha = r^2 for both)."),
    masking: str = _choice("height-correlated", "--masking",
                           ("height-correlated", "separable", "schlick-ggx", "schlick-ggx-ue4"),  # LTC_MASKINGS
                           "masking",
                           "Smith masking-shadowing G2 of the lobe: height-correlated or separable (exact Smith, "
                           "the distribution's own Lambda), or with ggx only schlick-ggx (k = alpha / 2) or "
                           "schlick-ggx-ue4 (k = (r + 1)^2 / 8)."),
    fresnel: bool = _flag(False, ("--fresnel",),
                          "With --clipping exact: also fit the f Fc lobe's matrices (fresnel_ltc_1.*) for pbrkit's "
                          "Fresnel-aware LTC, f0 norm LTC_1 + (1 - f0) fresnel LTC_Fc "
                          "(pbrkit.ltc.score.ltc_fresnel_rect), far better for dielectrics; the table pbrkit "
                          "renders with is --clipping exact --fresnel."),
    report: bool = _flag(False, ("--report",),
                         "Also score pbrkit's table and the published one (read from npm three, or --published) "
                         "on the same test set, with per-cell error maps."),
    published: Optional[Path] = typer.Option(
        None, "--published", metavar="FILE",
        help="three.js's RectAreaLightTexturesLib.js (default: the pinned npm three of tests/engines, if present)."),
    force: bool = _flag(False, ("--force",), "Replace a non-empty output folder."),
    quiet: bool = _quiet_option(),
):
    """Fit Linearly Transformed Cosines tables (Heitz et al. 2016) for GGX with
    height-correlated Smith (or --distribution / --masking), for the polygon
    integrals a shader computes, and write them in the published layout: ltc_1 /
    ltc_2 as .npy, RGBA32F / RGBA16F .dds and .ktx2, and an ES module for three.js."""
    import numpy as np

    from ..core import checks
    from ..core.atomic import atomic_directory, check_output_directory
    from ..ltc.fit import fit_table
    from ..ltc.report import score_fit, write_fit
    from ..ltc.score import lobe_codes

    # flags that contradict each other or would change nothing: refused before any work
    if published is not None and not report:
        raise ValueError("--published: the published table is read only to score against with --report; "
                         "add --report, or drop --published")
    if fresnel and clipping != "exact":
        raise ValueError("--fresnel: the Fresnel-aware LTC is evaluated with the exact horizon clipping; "
                         "add --clipping exact")
    lobe_codes(distribution, masking)  # a pair the fit has no lobe for: one line naming the choices
    size = checks.integer(size, "--size", 2, 256)
    polygons = checks.integer(polygons, "--polygons", 4, 4096)
    try:
        f0s = tuple(float(x) for x in fit_f0.split(","))
    except ValueError:
        raise ValueError(f"--fit-f0: a comma-separated list of numbers in [0, 1], got {fit_f0[:60]!r}") from None
    if not all(0.0 <= f <= 1.0 for f in f0s):  # NaN fails too
        raise ValueError(f"--fit-f0: normal reflectances must be in [0, 1], got {fit_f0[:60]!r}")
    check_output_directory(out, force)
    table = None
    if report:
        from ..ltc.score import published_table

        try:
            table = published_table(published)
        except FileNotFoundError as exc:
            if published is not None:
                raise ValueError(f"{published}: not three.js's LTC tables ({exc})") from None
            print(f"pbrkit ltc: note: the published table is not installed ({exc}); the report scores pbrkit's "
                  "table alone", file=sys.stderr)
    with _Stages("ltc", quiet, 2 * size + 2 if fresnel else size + 2) as stages:
        stages.start(f"fit roughness column 1/{size}")

        def column(done, total):
            if done < total:
                stages.start(f"fit roughness column {done + 1}/{total}", done + 1)

        fit = fit_table(size, polygons, seed, progress=column, fit_f0=f0s, clipping=clipping,
                        distribution=distribution, masking=masking)
        second = None
        if fresnel:  # the f Fc lobe's matrices: pbrkit.ltc.score.ltc_fresnel_rect
            stages.start(f"fit the f Fc lobe, roughness column 1/{size}", size + 1)

            def fc_column(done, total):
                if done < total:
                    stages.start(f"fit the f Fc lobe, roughness column {done + 1}/{total}", size + done + 1)

            second = fit_table(size, polygons, seed, progress=fc_column, fit_f0=(0.0,), clipping="exact",
                               distribution=distribution, masking=masking)
        stages.start("score" if report else "write", stages.total - 1)
        scores = score_fit(fit, table, fresnel=second) if report else None
        stages.start("write", stages.total)
        with atomic_directory(out, force) as tmp:
            write_fit(tmp, fit, scores, fresnel=second)
    if not quiet:
        seconds = fit.seconds + (second.seconds if second is not None else 0.0)
        print(f"wrote {out}: {size} x {size} LTC tables ({distribution}, {masking}"
              f"{', Fresnel-aware' if second is not None else ''}) fitted in {seconds:.1f} s; "
              f"per-cell error median {np.median(fit.error):.3f}")
        if scores is not None:
            for name, by_f in scores["scores"].items():
                label = "f0=0.04" if "Fresnel" in name else "F=1"
                s = by_f[label]
                print(f"{name} ({label}): relative error median {100 * s['relative_median']:.1f}%, mean "
                      f"{100 * s['relative_mean']:.1f}%, p95 {100 * s['relative_p95']:.1f}%; "
                      f"abs. error / albedo {100 * s['abs_over_albedo_mean']:.2f}%")




@app.command(cls=_Command, short_help="Write a tonal art map for hatching (Praun et al. 2001) as images.")
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


@app.command(cls=_Command, short_help="Write shader functions that match pbrkit's models and bakes.")
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


# Commands with their own modules (each keeps `pbrkit --help` light: the module
# imports only Typer and this one, and its command imports its work in its body).
from . import batch_cli as _batch_cli  # noqa: E402
from . import explore_cli as _explore_cli  # noqa: E402

_explore_cli.register(app)
_batch_cli.register(app)


if __name__ == "__main__":  # pragma: no cover
    app(prog_name="pbrkit")
