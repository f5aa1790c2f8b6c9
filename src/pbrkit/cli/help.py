"""``pbrkit CMD --help`` laid out to be read at any width, 80 columns included.

Typer's table puts an option's names, its metavar and its help side by side,
and at 80 columns squeezes the first two: names cut short (``--energy-compe...``)
and choices broken mid-word (``[equirect|hcross|vcros`` / ``s]``).  Here each
option takes a line of its own, names then metavar, with its help wrapped at
word boundaries below it; a metavar that does not fit beside the names
continues on indented lines broken after a ``|``, so a choice is never split.
Then the command's example (its ``epilog``, one command line a line), printed
as it is.  Rich is imported only when a help page is printed.
"""

from __future__ import annotations

import re

__all__ = ["print_command_help", "fit_names", "EXAMPLE_HEADING"]

#: The heading above a command's example in its ``--help``.
EXAMPLE_HEADING = "Example:"
#: Columns the help of an option is indented by, under its names.
HELP_INDENT = 4


def fit_names(names, metavar, width, indent=HELP_INDENT):
    """The lines of an option's ``names`` (``-o, --out``) and ``metavar``, each at most
    ``width`` columns where the names and each choice fit: the metavar beside the
    names if it fits, else on lines of their own indented by ``indent``, broken only
    after a ``|`` (between two choices)."""
    if not metavar:
        return [names]
    if len(names) + 1 + len(metavar) <= width:
        return [f"{names} {metavar}"]
    lines, line = [names], " " * indent
    for piece in re.split(r"(?<=\|)", metavar):  # "[a|", "b|", "c]"
        if line.strip() and len(line) + len(piece) > width:
            lines.append(line)
            line = " " * indent
        line += piece
    lines.append(line)
    return lines


def _parts(param, ctx):
    """(names, metavar, help with its [default: ...] / [required]) of one parameter."""
    record = param.get_help_record(ctx)
    if record is None:
        return None
    head, text = record
    if param.param_type_name == "argument":
        name = param.metavar or param.name.upper()
        return name + ("..." if param.nargs != 1 and not name.endswith("...") else ""), "", text
    metavar = param.metavar or ""
    if metavar and head.endswith(" " + metavar):
        return head[:-len(metavar) - 1], metavar, text
    return head, "", text


def _split_extra(text):
    """(help, its ``[default: ...]`` / ``[required]`` suffix or "") of a help record."""
    body, sep, extra = (text or "").rpartition("  [")
    if sep and extra.startswith(("default:", "required", "env var:")) and extra.endswith("]"):
        return body, "[" + extra
    if (text or "").startswith("[") and text.startswith(("[default:", "[required", "[env var:")):
        return "", text
    return text or "", ""


def _paragraphs(text):
    """A docstring's paragraphs, each one line (blank lines separate them)."""
    import inspect

    text = inspect.cleandoc(text or "")
    return [" ".join(p.split()) for p in re.split(r"\n\s*\n", text) if p.strip()]


def print_command_help(command, ctx):
    """Print ``command``'s help (usage, description, arguments, options, example)
    on stdout with Typer's Rich console (its width: the terminal's, or COLUMNS)."""
    from rich.console import Group
    from rich.padding import Padding
    from rich.panel import Panel
    from rich.text import Text
    from typer.rich_utils import _get_rich_console

    console = _get_rich_console()
    inner = max(20, console.width - 4)  # a panel's border and padding take two columns a side
    usage = " ".join([ctx.command_path, *command.collect_usage_pieces(ctx)])
    console.print(Padding(Text.assemble(("Usage: ", "yellow"), usage), 1))
    for paragraph in _paragraphs(command.help):
        console.print(Padding(Text(paragraph), (0, 1, 1, 1)))
    panels = {"argument": [], "option": []}
    for param in command.get_params(ctx):
        if getattr(param, "hidden", False):
            continue
        parts = _parts(param, ctx)
        if parts is None:
            continue
        names, metavar, text = parts
        rows = panels.setdefault(param.param_type_name, [])
        head = Text("\n".join(fit_names(names, metavar, inner)), style="bold cyan", no_wrap=True, overflow="ignore")
        rows.append(head)
        text, extra = _split_extra(text)
        if extra:  # [default: 0] / [required] on a line of their own, never broken
            text = Text(text + "\n" if text else "").append(extra, style="dim")
        if text:
            rows.append(Padding(Text(text) if isinstance(text, str) else text, (0, 0, 0, HELP_INDENT)))
    for kind, title in (("argument", "Arguments"), ("option", "Options")):
        if panels.get(kind):
            console.print(Panel(Group(*panels[kind]), title=title, title_align="left", border_style="dim"))
    if command.epilog:
        lines = [line.strip() for line in command.epilog.strip().splitlines() if line.strip()]
        console.print(Padding(Text("\n".join([EXAMPLE_HEADING, *("  " + line for line in lines)]), no_wrap=True,
                                   overflow="ignore"), (1, 1, 0, 1)))
