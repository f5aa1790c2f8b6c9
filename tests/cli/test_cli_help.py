"""``pbrkit --help`` and ``pbrkit CMD --help`` at 80 columns, the examples they show,
and the commands that need an optional extra (pbrkit.cli).

At COLUMNS=80 every help page has no line over 80 columns, names every option
whole (the long form and its negative, as the parser knows them) with its metavar
unbroken or broken only between two choices, shows no ``{ENV}`` metavar, and one
example line ``pbrkit CMD ...``, which the real parser accepts: the example's
arguments are parsed with click's ``make_context`` (callbacks and ``-o`` parsers
run; the command's body does not), so a typo in an example fails here.
"""

from __future__ import annotations

import re
import shlex

import pytest
import typer.main
from typer.testing import CliRunner

from pbrkit.cli import COMMANDS, app
from pbrkit.cli import batch as batch_cli
from pbrkit.cli.help import EXAMPLE_HEADING, fit_names

GROUP = typer.main.get_command(app)
#: Every command as its words after ``pbrkit``, e.g. ("batch", "bake").
COMMAND_PATHS = [(name,) for _, name, _ in COMMANDS] + [("batch", "bake"), ("batch", "render")]


def _command(words):
    command = GROUP
    for word in words:
        command = command.commands[word]
    return command


def _help(words, columns=80):
    result = CliRunner().invoke(app, [*words, "--help"], env={"COLUMNS": str(columns)})
    assert result.exit_code == 0, result.output
    return result.stdout


def _example(text, words):
    prefix = "pbrkit " + " ".join(words) + " "
    lines = [line.strip() for line in text.splitlines() if line.strip().startswith(prefix)]
    assert len(lines) == 1, (words, lines)
    return lines[0]


def test_every_command_is_registered_in_a_help_panel():
    assert [name for name in GROUP.list_commands(None)] == [name for _, name, _ in COMMANDS] + ["batch"]
    text = _help(())
    panels = re.findall(r"─ ([A-Z][A-Za-z ]+?) ─", text)
    assert panels == ["Options", "Render and compare", "Bake and tables", "Reports", "Batch and apps"], panels
    assert max(len(line) for line in text.splitlines()) <= 80


@pytest.mark.parametrize("words", COMMAND_PATHS, ids=" ".join)
def test_help_fits_80_columns_and_names_every_option_whole(words):
    text = _help(words)
    lines = text.splitlines()
    assert max(len(line) for line in lines) <= 80, [line for line in lines if len(line) > 80]
    assert "…" not in text  # Rich's mark of a cut cell
    usage = next(line for line in lines if "Usage:" in line)
    assert "{" not in usage, usage
    command = _command(words)
    assert command.epilog, f"pbrkit {' '.join(words)} has no example"
    for param in command.params:
        if param.param_type_name != "option":
            continue
        for opt in param.opts + param.secondary_opts:
            if opt.startswith("--"):
                assert re.search(rf"(?<![\w-]){re.escape(opt)}(?![\w-])", text), (words, opt)
        metavar = param.metavar or ""
        if metavar:
            assert _metavar_as_shown(lines, param) == metavar, (words, metavar)


def _inside_panel(line):
    """A line of a help panel without its borders (``│ text   │`` -> ``text``)."""
    return re.sub(r"\s*│\s*$", "", re.sub(r"^\s*│ ?", "", line))


def _metavar_as_shown(lines, param):
    """The metavar of ``param`` as the page shows it, read from its names' line and the
    indented lines that continue it: a line that ends elsewhere than between two
    choices (after a ``|``) ends it, so a choice split mid-word is read short."""
    names = ", ".join(param.opts) if not param.secondary_opts else " / ".join(param.opts + param.secondary_opts)
    content = [_inside_panel(line) for line in lines]
    start = next(k for k, text in enumerate(content) if text == names or text.startswith(names + " "))
    pieces = [content[start][len(names):].strip()]
    k = start + 1
    if not pieces[0]:  # the metavar starts on the next line
        pieces.append(content[k].strip())
        k += 1
    while pieces[-1].endswith("|"):  # a line may end only between two choices
        pieces.append(content[k].strip())
        k += 1
    return "".join(pieces)


@pytest.mark.parametrize("words", COMMAND_PATHS, ids=" ".join)
def test_the_example_is_shown_and_parses(words, tmp_path, monkeypatch):
    text = _help(words)
    example = _example(text, words)
    assert example == _command(words).epilog.strip()
    args = shlex.split(example)[1:]
    monkeypatch.chdir(tmp_path)  # the example's -o paths are checked against an empty folder
    ctx = GROUP.make_context("pbrkit", list(args))
    with ctx:
        command, sub = _parse(GROUP, ctx, args)
        assert command is _command(words)
        assert not sub.args, sub.args  # every word was taken by an option or an argument


def _parse(group, ctx, args):
    """(command, its context) of ``args`` (a command line after ``pbrkit``), parsed as
    the command line does: options, arguments, their callbacks and parsers, no body."""
    name, command, rest = group.resolve_command(ctx, list(args))
    sub = command.make_context(name, list(rest), parent=ctx)
    if hasattr(command, "resolve_command"):  # a group (batch): its command next
        return _parse(command, sub, rest)
    return command, sub


def test_an_example_with_a_typo_is_refused_by_the_same_parse():
    args = ["bake", "sky.hdr", "-o", "sky", "--sise", "256"]
    with pytest.raises(Exception, match="sise"):
        _parse(GROUP, GROUP.make_context("pbrkit", list(args)), args)


def test_the_group_help_shows_an_example_too():
    assert _example(_help(()), ("render",)).startswith("pbrkit render ")
    assert _example(_help(("batch",)), ("batch", "bake")) == batch_cli.EXAMPLE_BAKE


def test_wide_help_keeps_each_metavar_on_the_names_line():
    text = _help(("bake",), columns=200)
    assert "--target [generic|filament|khronos|babylon|three|all]" in text
    assert "--layout [equirect|hcross|vcross]" in text


@pytest.mark.parametrize("names, metavar, width, expected", [
    ("--mode", "[a|b|c]", 40, ["--mode [a|b|c]"]),
    ("--fresnel", "[schlick|schlick-pow4|exact-dielectric|none]", 30,
     ["--fresnel", "    [schlick|schlick-pow4|", "    exact-dielectric|none]"]),
    ("--quiet", "", 10, ["--quiet"]),
    ("-o, --out", "DIR", 12, ["-o, --out", "    DIR"]),
])
def test_fit_names_breaks_only_between_choices(names, metavar, width, expected):
    lines = fit_names(names, metavar, width)
    assert lines == expected
    assert "".join(line.strip() for line in lines[1:]) in (metavar, "") or lines[0].endswith(metavar)


def test_the_example_heading_is_on_every_command_page():
    assert EXAMPLE_HEADING in _help(("render",)) and EXAMPLE_HEADING in _help(("batch", "render"))


# ================================================================ extras


def _without(monkeypatch, *modules):
    """Simulate an install without ``modules`` (importing them fails, find_spec is None)."""
    for name in modules:
        monkeypatch.setitem(__import__("sys").modules, name, None)


@pytest.mark.parametrize("module", ["panel", "bokeh"])
def test_explore_without_its_extra_says_what_to_install(monkeypatch, module):
    _without(monkeypatch, module)
    result = CliRunner().invoke(app, ["explore", "--no-browser"])
    assert result.exit_code == 1
    assert result.stderr == 'pbrkit: error: pbrkit explore needs the explore extra: pip install "pbrkit[explore]"\n'
    assert result.stdout == ""


@pytest.mark.parametrize("command", ["bake", "render"])
@pytest.mark.parametrize("module", ["dask", "distributed"])
def test_batch_without_its_extra_says_what_to_install(monkeypatch, tmp_path, command, module):
    _without(monkeypatch, module)
    result = CliRunner().invoke(app, ["batch", command, str(tmp_path / "in"), "-o", str(tmp_path / "out")])
    assert result.exit_code == 1
    assert result.stderr == 'pbrkit: error: pbrkit batch needs the batch extra: pip install "pbrkit[batch]"\n'
    assert not (tmp_path / "out").exists()


def test_help_needs_no_extra(monkeypatch):
    _without(monkeypatch, "panel", "bokeh", "dask", "distributed")
    for words in (("explore",), ("batch",), ("batch", "bake")):
        assert "Usage: " in _help(words)


def test_pyproject_extras_hold_what_the_commands_check():
    """pyproject's explore and batch extras install the modules need_extra looks for,
    the base install none of them, the test extra both; the script is pbrkit.cli:app."""
    import tomllib
    from pathlib import Path

    from pbrkit.cli.console import EXTRAS

    project = tomllib.loads((Path(__file__).resolve().parents[2] / "pyproject.toml").read_text())["project"]

    def names(requirements):
        return {re.split(r"[\[<>=!~ ;]", r, maxsplit=1)[0].lower() for r in requirements}

    extras = project["optional-dependencies"]
    assert names(extras["explore"]) == set(EXTRAS["explore"])
    assert names(extras["batch"]) == {"dask"} and "distributed" in extras["batch"][0]  # dask[distributed]
    assert not names(project["dependencies"]) & {"panel", "bokeh", "dask", "distributed"}
    assert "pbrkit[explore,batch]" in extras["test"]
    assert project["scripts"]["pbrkit"] == "pbrkit.cli:app"


def test_render_imports_nothing_of_the_extras(tmp_path):
    """``pbrkit render`` with Panel, Bokeh and Dask unimportable (as without the extras)
    gets as far as reading its input: everything the command imports is there (the
    image itself, a Numba compile, is left to the render tests)."""
    import subprocess
    import sys

    missing = tmp_path / "missing.hdr"
    code = ("import sys\n"
            "for name in ('panel', 'bokeh', 'dask', 'distributed'):\n    sys.modules[name] = None\n"
            "from pbrkit.cli import app\n"
            f"app(['render', 'sphere', '-o', {str(tmp_path / 'r.png')!r}, '--env', {str(missing)!r}, "
            "'--width', '8', '--height', '8', '--bake-size', '8', '-q'], prog_name='pbrkit')\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 1, done.stderr
    assert done.stderr.startswith(f"pbrkit: error: {missing}") and len(done.stderr.splitlines()) == 1, done.stderr
    for name in ("panel", "bokeh", "dask", "distributed", "extra"):
        assert name not in done.stderr
