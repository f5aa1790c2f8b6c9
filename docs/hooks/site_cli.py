"""The command-line reference page (``reference/cli.md``), generated from the
``pbrkit`` command itself: the Typer app named by pyproject.toml's
``[project.scripts]`` entry point (``module:attr``), turned into its click command
tree by ``typer.main.get_command``, and walked with click's contexts.  Every
command (groups and their subcommands too) gets a section with its usage, its
help and a table of its arguments and options: every flag spelling, the value it
takes (a fixed set of values listed one by one), its default and its help, as
``--help`` prints them (each parameter's ``get_help_record``)."""

from __future__ import annotations

import html
import importlib
import inspect
import re
import tomllib
from pathlib import Path

#: The help record's trailing notes, as click and Typer append them to the help text.
_NOTES = re.compile(r"\s*\[(default: (?P<default>.*?)|(?P<required>required))\]\s*$")
#: A metavar listing a fixed set of values: ``[a|b|c]``.
_CHOICE_METAVAR = re.compile(r"^\[([^\[\]|]+(?:\|[^\[\]|]+)+|[^\[\]|]+)\]$")


def entry_point(pyproject):
    """The object the ``pbrkit`` script runs (``[project.scripts]``: ``"module:attr"``)."""
    scripts = tomllib.loads(Path(pyproject).read_text(encoding="utf-8"))["project"]["scripts"]
    module, _, attribute = scripts["pbrkit"].partition(":")
    target = importlib.import_module(module)
    for name in attribute.split("."):
        target = getattr(target, name)
    return target


def root_command(pyproject):
    """The click command of the ``pbrkit`` entry point (a Typer app converted with
    ``typer.main.get_command``; a click command as it is)."""
    app = entry_point(pyproject)
    if hasattr(app, "registered_commands"):  # a typer.Typer
        import typer.main

        return typer.main.get_command(app)
    return app


def walk(command, name="pbrkit", parent=None):
    """(context, command) of ``command`` and of every subcommand below it, depth
    first, in the order ``--help`` lists them (hidden commands left out)."""
    ctx = command.context_class(command, info_name=name, parent=parent)
    yield ctx, command
    if hasattr(command, "list_commands"):
        for sub_name in command.list_commands(ctx):
            sub = command.get_command(ctx, sub_name)
            if sub is not None and not getattr(sub, "hidden", False):
                yield from walk(sub, sub_name, ctx)


def anchor(ctx):
    """The section id of a command: ``pbrkit-render``, ``pbrkit-batch-bake``."""
    return re.sub(r"[^a-z0-9]+", "-", ctx.command_path.lower()).strip("-")


def _text(text):
    """Help text as Markdown that shows it as written: HTML and Markdown emphasis
    escaped (a help text is prose, not markup)."""
    text = html.escape(text, quote=False)
    return re.sub(r"([\\`*_\[\]#|])", r"\\\1", text)


def _paragraphs(help_text):
    """A command's help as Markdown paragraphs: click's ``\\b`` blocks keep their lines."""
    out = []
    for block in re.split(r"\n\s*\n", inspect.cleandoc(help_text or "")):
        lines = block.splitlines()
        if lines and lines[0].strip() == "\b":
            out.append("<br>\n".join(_text(line.strip()) for line in lines[1:]))
        elif block.strip():
            out.append(_text(" ".join(line.strip() for line in lines)))
    return out


def choices(param):
    """The fixed set of values a parameter takes, or None: a click ``Choice`` type's,
    Typer's choice descriptor's, or those its metavar lists (``[a|b|c]``)."""
    found = getattr(getattr(param, "type", None), "choices", None)
    descriptor = getattr(param, "type_descriptor", None)
    if found is None and descriptor is not None and getattr(descriptor, "is_choice", False):
        found = descriptor.choices
    if found is None and isinstance(param.metavar, str):
        match = _CHOICE_METAVAR.match(param.metavar)
        if match:
            found = match.group(1).split("|")
    return None if found is None else [getattr(c, "value", c) for c in found]


def describe(param, ctx):
    """A parameter as a row: (names, value, default, help), from its help record."""
    record = param.get_help_record(ctx)
    if record is None:
        return None
    left, help_text = record
    default, required = "", False
    match = _NOTES.search(help_text)
    while match:
        if match.group("required"):
            required = True
        else:
            default = match.group("default")
        help_text = help_text[:match.start()]
        match = _NOTES.search(help_text)
    if param.param_type_name == "argument":
        names = [left.split()[0]]
        value = ""
    else:
        names = list(param.opts) + list(param.secondary_opts)
        value = "" if getattr(param, "is_flag", False) else (param.metavar or "")
    values = choices(param)
    value_cell = " \u00b7 ".join(f"`{v}`" for v in values) if values else (f"`{value}`" if value else "")
    default_cell = "required" if required else (f"`{default}`" if default else "")
    return ", ".join(f"`{n}`" for n in names), value_cell, default_cell, _text(" ".join(help_text.split()))


def _section(ctx, command):
    level = "#" * min(2 + max(0, ctx.command_path.count(" ") - 1), 4)
    lines = [f"{level} `{ctx.command_path}` {{#{anchor(ctx)}}}", ""]
    if getattr(command, "deprecated", False):
        lines += ["!!! warning \"Deprecated\"", "", "    This command is deprecated.", ""]
    lines += ["```text", f"{ctx.command_path} {' '.join(command.collect_usage_pieces(ctx))}".rstrip(), "```", ""]
    for paragraph in _paragraphs(command.help or command.short_help or ""):
        lines += [paragraph, ""]
    rows = [row for row in (describe(p, ctx) for p in command.get_params(ctx)) if row is not None]
    if rows:
        lines += ["| parameter | value | default | meaning |", "|---|---|---|---|"]
        lines += [f"| {' | '.join(row)} |" for row in rows]
        lines.append("")
    example = example_lines(command)
    if example:
        lines += ["Example:", "", "```sh", *example, "```", ""]
    if hasattr(command, "list_commands"):
        subs = [(n, command.get_command(ctx, n)) for n in command.list_commands(ctx)]
        subs = [(n, c) for n, c in subs if c is not None and not getattr(c, "hidden", False)]
        panels = {}  # the help panels --help groups the commands in (Typer's rich_help_panel), in order
        for sub_name, sub in subs:
            panels.setdefault(getattr(sub, "rich_help_panel", None) or "Commands", []).append((sub_name, sub))
        for panel, members in panels.items():
            lines += [f"| {_text(panel)} | |", "|---|---|"]
            for sub_name, sub in members:
                sub_ctx = sub.context_class(sub, info_name=sub_name, parent=ctx)
                lines.append(f"| [`{sub_name}`](#{anchor(sub_ctx)}) | {_text(sub.get_short_help_str(200))} |")
            lines.append("")
    return lines


def example_lines(command):
    """The command lines of a command's example (its ``epilog``, one a line; an
    "Example:" heading dropped)."""
    lines = [line.strip() for line in (getattr(command, "epilog", None) or "").strip().splitlines()]
    return [line for line in lines if line and line.rstrip(":").lower() not in ("example", "examples")]


def page(pyproject):
    """The Markdown of ``reference/cli.md``."""
    command = root_command(pyproject)
    lines = ["# Command line", "",
             "Generated from the `pbrkit` command itself when the site is built "
             "(`docs/hooks/site_cli.py`): every command, its help and every option with "
             "its values and default, as `pbrkit COMMAND --help` prints them.", ""]
    for ctx, sub in walk(command):
        lines += _section(ctx, sub)
    return "\n".join(lines) + "\n"
