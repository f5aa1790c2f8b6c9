"""The documentation site: ``mkdocs build --strict`` (mkdocs.yml) succeeds, and its
generated pages are complete.  The command-line page is checked against the
``pbrkit`` command's own click tree (every command, every option spelling, every
value of a fixed set, every default ``--help`` shows), the scene-file page
against what the scene parser accepts: the keys each section allows, read from
the parser's own refusals of an unknown key ("allowed: ..."), and the names
its refusals of an unknown model, term, falloff, unit or style list.  Neither
side is a list written here."""

import html
import importlib
import importlib.util
import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
#: The site's tools: module -> the distribution that installs it (the `docs` extra).
_TOOLS = {"mkdocs": "mkdocs", "material": "mkdocs-material", "mkdocstrings": "mkdocstrings",
          "mkdocstrings_handlers.python": "mkdocstrings-python"}


def _installed(module):
    try:
        return importlib.util.find_spec(module) is not None
    except ModuleNotFoundError:  # its parent package is missing
        return False


_MISSING = [dist for module, dist in _TOOLS.items() if not _installed(module)]
if _MISSING:
    pytest.skip(f"the documentation tools are not installed ({', '.join(_MISSING)}): pip install -e \".[docs]\"",
                allow_module_level=True)

pytestmark = pytest.mark.slow  # the strict build renders the gallery: about 20 s on two cores, Numba's cache warm


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The site built with ``mkdocs build --strict`` into a temporary folder."""
    out = tmp_path_factory.mktemp("site")
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1", PYTHONPATH=os.pathsep.join(
        [str(ROOT / "src")] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
    run = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file",
                          str(ROOT / "mkdocs.yml"), "--site-dir", str(out)],
                         cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, f"mkdocs build --strict failed:\n{run.stderr[-4000:]}"
    return out


def _page(site, name):
    return (site / name / "index.html").read_text(encoding="utf-8")


def _sections(text):
    """[(heading text, the HTML up to the next h1-h3)] of a page in order, the
    headings' tags and permalinks stripped."""
    marks = list(re.finditer(r"<h([123])[^>]*>(.*?)</h\1>", text, re.S))
    out = []
    for mark, following in zip(marks, marks[1:] + [None]):
        title = html.unescape(re.sub(r"<[^>]+>", "", mark.group(2))).replace("\u00b6", "").strip()
        out.append((title, text[mark.end():following.start() if following else len(text)]))
    return out


def _codes(fragment):
    """The texts of the ``<code>`` elements of an HTML fragment."""
    return {html.unescape(re.sub(r"<[^>]+>", "", c)) for c in re.findall(r"<code>(.*?)</code>", fragment, re.S)}


# ------------------------------------------------------------------ the CLI page


def _root_command():
    """The click command of pyproject.toml's ``pbrkit`` script (a Typer app)."""
    import typer.main

    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["scripts"]
    module, _, attribute = scripts["pbrkit"].partition(":")
    app = importlib.import_module(module)
    for name in attribute.split("."):
        app = getattr(app, name)
    return typer.main.get_command(app) if hasattr(app, "registered_commands") else app


def _commands(command, name="pbrkit", parent=None):
    ctx = command.context_class(command, info_name=name, parent=parent)
    yield ctx, command
    if hasattr(command, "list_commands"):
        for sub in command.list_commands(ctx):
            sub_command = command.get_command(ctx, sub)
            if not getattr(sub_command, "hidden", False):
                yield from _commands(sub_command, sub, ctx)


def test_the_cli_page_lists_every_command_option_choice_and_default(site):
    sections = dict(_sections(_page(site, "reference/cli")))
    commands = list(_commands(_root_command()))
    assert len(commands) > 10  # the tree was walked (groups and their subcommands)
    for ctx, command in commands:
        section = sections.get(ctx.command_path)
        assert section is not None, f"no section for {ctx.command_path!r}"
        codes = _codes(section)
        words = " ".join(html.unescape(re.sub(r"<[^>]+>", "", section)).split())
        first_line = (command.help or command.short_help or "").strip().splitlines()[0]
        assert " ".join(first_line.split()) in words, ctx.command_path
        for line in (command.epilog or "").strip().splitlines():  # the example, as --help shows it
            if line.strip() and line.strip().rstrip(":").lower() not in ("example", "examples"):
                assert " ".join(line.split()) in words, f"{ctx.command_path}: example {line.strip()!r} missing"
        for sub in (command.list_commands(ctx) if hasattr(command, "list_commands") else []):
            assert sub in codes, f"{ctx.command_path}: subcommand {sub!r} not listed"
        for param in command.get_params(ctx):
            record = param.get_help_record(ctx)
            if record is None:  # hidden
                continue
            left, help_text = record
            where = f"{ctx.command_path}: {left}"
            if param.param_type_name == "argument":
                assert left.split()[0] in codes, where
                continue
            for spelling in list(param.opts) + list(param.secondary_opts):
                assert spelling in codes, f"{where}: {spelling} missing"
            listed = re.search(r"\[([^\[\]]+\|[^\[\]]+)\]$", left)
            for choice in (listed.group(1).split("|") if listed else []):
                assert choice in codes, f"{where}: value {choice!r} missing"
            default = re.search(r"\[default: (.*?)\]\s*$", help_text)
            if default:
                assert default.group(1) in codes, f"{where}: default {default.group(1)!r} missing"


# ---------------------------------------------------------------- the scene page


def _refusal(data):
    from pbrkit.rendering.scene import scene_from_dict

    with pytest.raises(ValueError) as caught:
        scene_from_dict(data)
    return str(caught.value)


def _allowed(data):
    """The keys the parser allows where ``data`` puts the unknown key ``zz_unknown``:
    the list its one-line refusal names."""
    message = _refusal(data)
    assert "zz_unknown" in message and "allowed: " in message, message
    return set(message.split("allowed: ", 1)[1].split(", "))


def _choices(data):
    """The names the parser's refusal of an unknown name lists ("choose one of ...")."""
    message = _refusal(data)
    assert "choose one of " in message or "must be one of " in message, message
    return set(re.split(r"(?:choose|must be) one of ", message, maxsplit=1)[1].split("; got")[0].split(", "))


_UNKNOWN = {"zz_unknown": 1}
#: (section heading, sub-heading or None, a scene whose unknown key is in that section).
_SECTIONS = [
    ("[camera]", None, {"camera": _UNKNOWN}),
    ("[environment]", None, {"environment": _UNKNOWN}),
    ("[materials.<name>]", None, {"materials": {"m": _UNKNOWN}}),
    ("[style]", None, {"style": _UNKNOWN}),
]


def _typed(section, kinds_from):
    return [(section, f'type = "{kind}"', data) for kind, data in kinds_from]


def test_the_scene_page_lists_every_key_the_parser_accepts(site):
    from pbrkit.rendering.area_lights import AREA_LIGHT_TYPES
    from pbrkit.rendering.lights import LIGHT_TYPES

    sections = _sections(_page(site, "reference/scene"))
    top = _allowed(_UNKNOWN)
    assert {"camera", "environment", "materials", "objects", "lights"} <= top
    for key in top:
        assert any(key in title for title, _ in sections), f"section {key!r} missing"
    object_types = _choices({"objects": [{"type": "zz_unknown"}]})
    cases = list(_SECTIONS)
    cases += _typed("[[objects]]", [(t, {"objects": [{"type": t, **_UNKNOWN}]}) for t in object_types])
    cases += _typed("[[lights]]", [(t, {"lights": [{"type": t, **_UNKNOWN}]})
                                   for t in LIGHT_TYPES + AREA_LIGHT_TYPES])
    assert _choices({"lights": [{"type": "zz_unknown"}]}) == set(LIGHT_TYPES + AREA_LIGHT_TYPES)
    checked = 0
    for heading, sub, data in cases:
        start = next((i for i, (t, _) in enumerate(sections) if heading in t), None)
        assert start is not None, f"no section {heading!r}"
        if sub is not None:  # the sub-heading under its own section (sphere is an object and a light)
            start = next((i for i, (t, _) in enumerate(sections) if i > start and sub in t), None)
            assert start is not None, f"no section {sub!r} under {heading!r}"
        title, content = sections[start]
        codes = _codes(content)
        for key in _allowed(data) - {"type"}:
            assert key in codes, f"{title}: key {key!r} missing"
            checked += 1
    assert checked > 100


def test_the_scene_page_lists_the_names_the_parser_accepts(site):
    codes = _codes(_page(site, "reference/scene"))
    refusals = [{"materials": {"m": {"model": "zz_unknown"}}},
                {"materials": {"m": {"model": "cook_torrance", "distribution": "zz_unknown"}}},
                {"materials": {"m": {"model": "cook_torrance", "masking": "zz_unknown"}}},
                {"materials": {"m": {"model": "cook_torrance", "fresnel": "zz_unknown"}}},
                {"materials": {"m": {"model": "cook_torrance", "diffuse": "zz_unknown"}}},
                {"lights": [{"type": "point", "falloff": "zz_unknown"}]},
                {"lights": [{"type": "rect", "unit": "zz_unknown"}]},
                {"style": {"shading": "zz_unknown"}},
                {"style": {"outline": "zz_unknown"}}]
    for data in refusals:
        names = _choices(data)
        assert names and names <= codes, f"{data}: {sorted(names - codes)} missing"


def test_the_gallery_shows_its_images(site):
    page = _page(site, "gallery")
    images = re.findall(r'<img[^>]+src="([^"]+\.png)"', page)
    assert len(images) >= 4
    for src in images:
        data = (site / "gallery" / src).resolve().read_bytes()
        assert data.startswith(b"\x89PNG\r\n\x1a\n"), src
