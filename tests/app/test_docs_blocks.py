"""Every fenced code block of the README, docs/index.md and docs/guide/*.md runs.

* ```python blocks are executed as a reader pastes them, in an empty folder
  (the guide's API tour by tests/app/test_docs.py, with its own checks);
* ```sh / ```console blocks run line by line in one empty folder per block:
  ``pbrkit ...`` through the command's Typer app (the console script of
  pyproject.toml), after its arguments are parsed by the command itself (options,
  choices, types); commands that serve, fit for minutes or start a cluster are
  parsed only (:data:`PARSE_ONLY`, each with the test that runs it).  ``python -c``
  runs in a subprocess, ``pip install`` names extras that pyproject.toml declares,
  ``python -m pytest -m`` markers that it declares; any other line fails;
* ```toml blocks load: a scene file with :func:`pbrkit.load_scene`, a ``[style]``
  table with :func:`pbrkit.npr.style.resolve_style`;
* ```html and ```js blocks pass ``node --check`` (skipped without node); the
  README's three.js page imports the module and loads the files that ``pbrkit bake
  --target three`` writes, under the names its manifest gives, from the three.js
  version the in-engine tests pin (tests/engines/package.json);
* ```text blocks are output samples and are not run.

Assets a block names that the reader has are made here: ``demo/model.glb`` is the
demo's model (``pbrkit demo`` writes it), ``model.glb`` stands for the reader's
glTF model (the same file), ``studio.hdr`` for an environment map (the bundled one).
"""

from __future__ import annotations

import importlib
import json
import re
import shlex
import shutil
import subprocess
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGES = (ROOT / "README.md", ROOT / "docs" / "index.md", *sorted((ROOT / "docs" / "guide").glob("*.md")))
KINDS = ("python", "sh", "console", "toml", "html", "js", "text")
NODE = shutil.which("node")

#: Commands whose lines are parsed, not run, and the tests that run them.
PARSE_ONLY = {
    "demo": "a minute on a cold cache (tests/app/test_demo.py)",
    "batch": "starts a Dask cluster (tests/app/test_batch.py)",
    "ltc": "a fit takes minutes (tests/ltc/test_ltc_fit.py)",
    "explore": "serves until Ctrl-C (tests/explore/test_explore_app.py, tests/explore/test_explore_static.py)",
    "furnace": "converged quadrature of every lobe, 25 s (tests/albedo/test_furnace.py)",
    "approximations": "converged quadrature, 15-30 s (tests/albedo/test_approximations.py)",
}


@dataclass(frozen=True)
class Block:
    page: Path
    line: int
    kind: str
    text: str

    @property
    def name(self):
        return f"{self.page.relative_to(ROOT)}:{self.line}"


def code_blocks(page):
    """The fenced blocks of ``page``: (line of the opening fence, info string, text)."""
    blocks, kind, start, lines = [], None, 0, []
    for number, line in enumerate(page.read_text().splitlines(), 1):
        fence = re.match(r"\s*```(.*)$", line)
        if kind is None and fence:
            kind, start, lines = fence.group(1).strip(), number, []
        elif kind is not None and fence and not fence.group(1).strip():
            blocks.append(Block(page, start, kind, "\n".join(lines) + "\n"))
            kind = None
        elif kind is not None:
            lines.append(line)
    assert kind is None, f"{page}: the block opened on line {start} is not closed"
    return blocks


ALL_BLOCKS = [block for page in PAGES for block in code_blocks(page)]


def blocks(kind):
    return [pytest.param(b, id=b.name) for b in ALL_BLOCKS if b.kind == kind]


def cli_app():
    """The Typer app behind the ``pbrkit`` console script (pyproject.toml)."""
    target = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]["pbrkit"]
    module, _, attribute = target.partition(":")
    return getattr(importlib.import_module(module), attribute)


def make_reader_assets(folder):
    """The files a reader has that the blocks name (module docstring)."""
    from pbrkit.app.demo_model import demo_model_primitives
    from pbrkit.data import environment_path
    from pbrkit.io.gltf_writer import write_glb

    (folder / "demo").mkdir(exist_ok=True)
    write_glb(folder / "demo" / "model.glb", demo_model_primitives())
    shutil.copyfile(folder / "demo" / "model.glb", folder / "model.glb")
    shutil.copyfile(environment_path(), folder / "studio.hdr")


def test_pages_and_blocks_are_there():
    names = {p.relative_to(ROOT).as_posix() for p in PAGES}
    assert {"README.md", "docs/index.md", "docs/guide/python.md", "docs/guide/render.md"} <= names
    assert {b.kind for b in ALL_BLOCKS} >= {"python", "sh", "toml", "html"}


@pytest.mark.parametrize("block", [pytest.param(b, id=b.name) for b in ALL_BLOCKS])
def test_every_block_says_what_it_is(block):
    """A bare ``` fence would go untested: every block names a kind this file runs."""
    assert block.kind in KINDS, f"{block.name}: code block of kind {block.kind!r}; use one of {KINDS}"


def test_readme_is_short_and_links_resolve():
    """The README stays a front page (the issue: at most ~10 KB), and every relative
    link of the README and the guide names a file that exists (docs/reference/ is
    generated when the site is built)."""
    assert len((ROOT / "README.md").read_bytes()) <= 10 * 1024
    for page in PAGES:
        for target in re.findall(r"\]\(([^)\s]+)\)", page.read_text()):
            if re.match(r"[a-z]+:", target) or target.startswith("#"):
                continue
            path = (page.parent / target.split("#", 1)[0]).resolve()
            if (ROOT / "docs" / "reference") in path.parents:
                continue
            assert path.exists(), f"{page.relative_to(ROOT)}: link to {target}, which does not exist"


# ------------------------------------------------------------------------- python


def api_tour_block(block):
    from doc_pages import api_tour

    return block.page.name == "python.md" and block.text.strip() == api_tour().strip()


@pytest.mark.slow  # renders and bakes (seconds each once Numba's cache is warm)
@pytest.mark.parametrize("block", blocks("python"))
def test_python_block_runs(block, tmp_path, monkeypatch):
    if api_tour_block(block):
        pytest.skip("the API tour runs in tests/app/test_docs.py, with its own checks")
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "__docs__"}
    exec(compile(block.text, block.name, "exec"), namespace)
    if block.page.name == "README.md":  # what its comments say
        r, c, b = namespace["r"], namespace["c"], namespace["b"]
        assert r.mode == "realtime" and r.image.shape == (256, 256, 3) and r.reference is None
        assert r.to_srgb().shape == (256, 256, 3) and r._repr_png_()[:4] == b"\x89PNG"
        assert c.mode == "compare" and c.image.shape == c.reference.shape == (64, 64, 3)
        assert c.error.shape == (64, 64) and c.to_srgb().shape == (64, 192, 3)
        assert 0.0 < c.stats["errors"]["flip"] < 1.0 and c._repr_png_()[:4] == b"\x89PNG"
        assert (tmp_path / "spheres.png").is_file() and (tmp_path / "spheres.stderr.exr").is_file()
        assert list(b.roughness) == pytest.approx([0, 1 / 3, 2 / 3, 1])
    if "write_tam" in block.text:
        assert (tmp_path / "tam" / "manifest.json").is_file()


# ---------------------------------------------------------------------- sh, console


def command_lines(block):
    lines = [line.strip() for line in block.text.splitlines()]
    if block.kind == "console":  # commands after "$ ", the rest is output
        lines = [line[2:] for line in lines if line.startswith("$ ")]
    return [line for line in lines if line and not line.startswith("#")]


def parse_command(args):
    """Parse ``pbrkit ARGS`` as the command would (options, choices, types, the
    callbacks that check them) without running it."""
    from typer.main import get_command

    command, name, ctx = get_command(cli_app()), "pbrkit", None
    args = list(args)
    try:
        while True:
            ctx = command.make_context(name, args, parent=ctx)
            if not hasattr(command, "resolve_command"):  # a command, not a group
                return command.name
            args = [*getattr(ctx, "_protected_args", []), *ctx.args]
            name, command, args = command.resolve_command(ctx, args)
    except Exception as exc:  # --help (and --version) end parsing with exit status 0
        if type(exc).__name__ == "Exit" and getattr(exc, "exit_code", getattr(exc, "code", 1)) == 0:
            return command.name
        raise


def package_env():
    """The environment of a ``python -c`` line: this pbrkit importable (PYTHONPATH=src
    in a checkout is relative to it)."""
    import os

    import pbrkit

    path = [str(Path(pbrkit.__file__).resolve().parents[1]), os.environ.get("PYTHONPATH", "")]
    return dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in path if p))


def check_pip_line(words):
    extras = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"])
    targets = [w for w in words[2:] if not w.startswith("-")]
    assert targets, words
    for target in targets:
        spec = re.fullmatch(r"\.(?:\[([\w,-]+)\])?", target)
        assert spec, f"pip installs {target!r}; the guide installs from the checkout (. or .[extra])"
        assert set((spec.group(1) or "").split(",")) - {""} <= extras, f"{target}: unknown extra"


def check_pytest_line(words):
    markers = {m.split(":")[0] for m in tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"]
               ["ini_options"]["markers"]}
    options = words[3:]
    if "-m" in options:
        expression = options[options.index("-m") + 1]
        assert set(re.findall(r"\w+", expression)) - {"not", "and", "or"} <= markers, expression


@pytest.mark.slow  # bakes and renders through the command (seconds each)
@pytest.mark.parametrize("block", blocks("sh") + blocks("console"))
def test_shell_block_runs(block, tmp_path, monkeypatch):
    from typer.testing import CliRunner

    monkeypatch.chdir(tmp_path)
    make_reader_assets(tmp_path)
    lines = command_lines(block)
    assert lines, f"{block.name}: no command"
    for line in lines:
        for part in line.split(" && "):
            words = shlex.split(part)
            if words[0] == "pbrkit":
                name = parse_command(words[1:])
                if words[1] in PARSE_ONLY:
                    continue
                result = CliRunner().invoke(cli_app(), words[1:])
                assert result.exit_code == 0, f"{block.name}: {part}\n{result.output}"
                if name == "render" and "compare" in words:
                    assert "HDR-FLIP" in result.output and "floor" in result.output, result.output
            elif words[:2] == ["python", "-c"]:
                subprocess.run([sys.executable, *words[1:]], check=True, cwd=tmp_path, env=package_env())
            elif words[:2] == ["pip", "install"]:
                check_pip_line(words)
            elif words[:3] == ["python", "-m", "pytest"]:
                check_pytest_line(words)
            else:
                pytest.fail(f"{block.name}: {part!r}: no test knows how to run this line")


def test_shell_lines_parse():
    """The quick run's share of the above: every ``pbrkit`` line of every block
    names a command and options it has, with valid values."""
    count = 0
    for block in ALL_BLOCKS:
        if block.kind in ("sh", "console"):
            for line in command_lines(block):
                for part in line.split(" && "):
                    words = shlex.split(part)
                    if words[0] == "pbrkit":
                        parse_command(words[1:])
                        count += 1
    assert count >= 10


# --------------------------------------------------------------------------- toml


@pytest.mark.parametrize("block", blocks("toml"))
def test_toml_block_loads(block, tmp_path):
    import pbrkit
    from pbrkit.npr.style import resolve_style

    table = tomllib.loads(block.text)
    if set(table) == {"style"}:
        (tmp_path / "style.toml").write_text(block.text)
        style = resolve_style(tmp_path / "style.toml")
        for key, value in table["style"].items():
            got = getattr(style, key)
            assert (list(got) if isinstance(got, tuple) else got) == value, key
        return
    make_reader_assets(tmp_path)
    (tmp_path / "scene.toml").write_text(block.text)
    scene = pbrkit.load_scene(tmp_path / "scene.toml")
    assert set(table.get("materials", {})) <= set(scene.materials)
    assert len(scene.objects) == len(table["objects"])
    assert len(scene.lights) + len(scene.area_lights) == len(table.get("lights", []))


# --------------------------------------------------------------------- html, js


def module_scripts(block):
    """The JavaScript of a block: a js block, or an html block's module scripts."""
    if block.kind == "js":
        return [block.text]
    return re.findall(r'<script type="module">(.*?)</script>', block.text, re.S)


@pytest.mark.skipif(NODE is None, reason="needs node (Debian: apt-get install nodejs)")
@pytest.mark.parametrize("block", blocks("html") + blocks("js"))
def test_javascript_block_is_valid(block, tmp_path):
    scripts = module_scripts(block)
    assert scripts, f"{block.name}: no module script"
    for i, script in enumerate(scripts):
        path = tmp_path / f"block{i}.mjs"
        path.write_text(script)
        proc = subprocess.run([NODE, "--check", str(path)], capture_output=True, text=True)
        assert proc.returncode == 0, f"{block.name}: {proc.stderr}"


def readme_three_page():
    pages = [b for b in ALL_BLOCKS if b.page.name == "README.md" and b.kind == "html"]
    assert len(pages) == 1
    return pages[0].text


def readme_bake_folder():
    """The -o folder of the README's ``pbrkit bake ... --target three`` line."""
    for block in ALL_BLOCKS:
        if block.page.name == "README.md" and block.kind == "sh":
            for line in command_lines(block):
                words = shlex.split(line)
                if words[:2] == ["pbrkit", "bake"] and "three" in words:
                    return words[words.index("-o") + 1]
    pytest.fail("README.md has no `pbrkit bake ... --target three` line")


def test_readme_three_page_loads_what_the_three_target_writes(tmp_path):
    """The README's page imports three and its addons from the version the in-engine
    tests pin, imports the module the three.js target ships and loads its cube under
    the names that target's manifest gives, and uses the demo's model."""
    import pbrkit
    from pbrkit.app.demo import DEMO_ENTRIES
    from pbrkit.data import environment_path
    from pbrkit import write_bake
    from pbrkit.engines import chains_for

    page = readme_three_page()
    imports = json.loads(re.search(r'<script type="importmap">(.*?)</script>', page, re.S).group(1))["imports"]
    pinned = json.loads((ROOT / "tests" / "engines" / "package.json").read_text())["dependencies"]["three"]
    assert imports["three"].endswith(f"/three@{pinned}/build/three.module.js")
    assert imports["three/addons/"].endswith(f"/three@{pinned}/examples/jsm/")
    script = module_scripts(Block(Path("README.md"), 0, "html", page))[0]

    folder = readme_bake_folder()
    targets = ("generic", "three")
    b = pbrkit.bake(environment_path(), size=16, min_size=4, chains=chains_for(targets))
    write_bake(b, tmp_path / folder, targets=targets)
    files = json.loads((tmp_path / folder / "manifest.json").read_text())["targets"]["three"]["files"]
    assert f'from "./{folder}/{files["module"]}"' in script
    assert f'loadPbrkitCubeKTX2("{folder}/{files["specular"]}")' in script
    assert (tmp_path / folder / files["module"]).is_file() and (tmp_path / folder / files["specular"]).is_file()
    exported = set(re.findall(r"export (?:async )?function (\w+)", (tmp_path / folder / files["module"]).read_text()))
    imported = re.search(r"import \{ (.*?) \} from \"\./", script).group(1).split(", ")
    assert set(imported) <= exported
    assert "scene.environment = await loadPbrkitCubeKTX2(" in script
    model = re.search(r'loadAsync\("([^"]+)"\)', script).group(1)
    assert model.split("/", 1) == ["demo", "model.glb"] and "model.glb" in DEMO_ENTRIES
    addon = ROOT / "tests" / "engines" / "node_modules" / "three" / "examples" / "jsm" / "loaders" / "GLTFLoader.js"
    if addon.is_file():  # the pinned engines are installed (npm ci --prefix tests/engines)
        assert "export { GLTFLoader }" in addon.read_text() or "class GLTFLoader" in addon.read_text()


@pytest.mark.slow  # a bake, a browser and three.js (about 10 s)
def test_readme_three_page_renders_in_three(tmp_path, monkeypatch):
    """The README's page, as a reader saves it beside ``bake/`` and ``demo/``, runs in
    three.js 0.187.0 (headless Chromium, tests/engines): the importmap pointed at the
    pinned copy instead of the CDN, and a few lines appended that report what three
    holds after one frame.  The bake is the README's own command."""
    from engine_pages import needs_engines, run_page
    from typer.testing import CliRunner

    if needs_engines().args[0]:
        pytest.skip(needs_engines().kwargs["reason"])
    monkeypatch.chdir(tmp_path)
    make_reader_assets(tmp_path)
    (tmp_path / "sky.hdr").write_bytes((tmp_path / "studio.hdr").read_bytes())
    folder = readme_bake_folder()
    bake_line = next(line for b in ALL_BLOCKS if b.page.name == "README.md" and b.kind == "sh"
                     for line in command_lines(b) if line.startswith("pbrkit bake"))
    result = CliRunner().invoke(cli_app(), [*shlex.split(bake_line)[1:-1], str(tmp_path / folder)])
    assert result.exit_code == 0, result.output

    page = readme_three_page()
    pinned = re.search(r'"three": "(https://[^"]*/three@[^/]+/)build/three.module.js"', page).group(1)
    page = page.replace(pinned, "/node_modules/three/")
    errors = ('<script>addEventListener("error", (e) => { window.__pbrkitError = String(e.message); });\n'
              'addEventListener("unhandledrejection", (e) => { window.__pbrkitError = String(e.reason); });</script>\n')
    report = """
renderer.render(scene, camera);
const gl = renderer.getContext();
const px = new Uint8Array(gl.drawingBufferWidth * gl.drawingBufferHeight * 4);
gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA, gl.UNSIGNED_BYTE, px);
let meshes = 0;
gltf.scene.traverse((o) => { if (o.isMesh) meshes += 1; });
window.__pbrkitResult = { pmrem: scene.environment.isPMREMTexture, cube: scene.environment.isCubeTexture,
  levels: scene.environment.image[0].mipmaps.length, meshes, lit: px.filter((v, i) => i % 4 !== 3 && v > 0).length,
  pixels: px.length / 4 };
"""
    page = page.replace("<!doctype html>\n", "<!doctype html>\n" + errors, 1).replace("</script>\n```", "")
    page = re.sub(r"</script>\s*$", report + "</script>\n", page)
    (tmp_path / "index.html").write_text(page)
    # harness.mjs serves DIR as /data and opens /pages/PAGE: ../data/index.html is the reader's page
    got = run_page("../data/index.html", data=tmp_path, timeout=120)["result"]
    from pbrkit.io.ktx2 import read_ktx2

    levels = len(read_ktx2(tmp_path / folder / "three" / "specular.ktx2")[1])
    assert got["pmrem"] and got["cube"] and got["meshes"] >= 1 and got["levels"] == levels, (got, levels)
    assert got["lit"] > 0.1 * got["pixels"], got  # the model and the sky are lit, not black
