"""The ``pbrkit`` commands' building blocks: the command and group classes
(:class:`_Command`: no Python types in ``--help``, its help laid out for 80
columns by :mod:`pbrkit.cli.help`; :class:`_Group`: usage errors as one line),
and the option factories every command uses: choices (:func:`_choice`), flags,
seeds, exposure, ``--quiet``, the ``-o/--out`` parsers (:data:`OUT_DIR`,
:data:`OUT_FILE`) and the options ``pbrkit bake`` and ``pbrkit batch bake``
share (:data:`BAKE_OPTIONS`).  The choices come from :mod:`pbrkit.choices`, their
only definition; this module imports neither NumPy nor the library's work."""

from __future__ import annotations

import sys
from pathlib import Path

import typer
from typer.core import TyperCommand, TyperGroup

try:  # typer >= 0.2x vendors its own click
    from typer import _click as _click
except ImportError:  # pragma: no cover - a typer built on click itself
    import click as _click

from ..choices import BAKE_FORMATS, BAKE_METHODS, BAKE_TARGETS, SH_WINDOWS
from .console import _say

SEED_MAX = 2 ** 64 - 1  # the renderer's counter-based generator takes a uint64; NumPy's default_rng any int >= 0
EXPOSURE_LIMIT = 64.0   # |EV|: 2^64 is far beyond any useful exposure and still finite in float32 arithmetic


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

    def collect_usage_pieces(self, ctx):
        """``[OPTIONS] ENV...``: arguments by their metavar (not ``{ENV}...``)."""
        pieces = [self.options_metavar] if self.options_metavar else []
        for param in self.get_params(ctx):
            if param.param_type_name == "argument":
                name = (param.metavar or param.name.upper()) + ("..." if param.nargs != 1 else "")
                pieces.append(name if param.required else f"[{name}]")
        return pieces

    def format_help(self, ctx, formatter):
        from .help import print_command_help

        print_command_help(self, ctx)


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


#: ``--target``'s metavar in ``pbrkit bake`` and ``pbrkit batch bake``: the targets
#: (:data:`pbrkit.choices.BAKE_TARGETS`) and ``all``.
TARGET_METAVAR = "[" + "|".join((*BAKE_TARGETS, "all")) + "]"

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
