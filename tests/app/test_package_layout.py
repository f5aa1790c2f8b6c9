"""The package order core -> sampling -> microfacet -> brdf, read from the sources.

Every ``import`` and ``from ... import`` statement of a module (at module level
or inside a function, absolute or relative) is resolved to the absolute
module names it may load, with :mod:`ast`, without importing anything; a
``from package import name`` counts as importing ``package.name`` too, and a
call ``importlib.import_module("...")`` with a literal name counts as well.
Then: no module of ``pbrkit.sampling`` may import ``pbrkit.microfacet`` or
``pbrkit.brdf``, and no module of ``pbrkit.microfacet`` may import
``pbrkit.brdf``.  The facades ``pbrkit.brdf.distributions`` and the Smith names of
``pbrkit.brdf.masking`` only re-export, so no formula is written twice.  The engine
table (:mod:`pbrkit.engines`) sits above what it imports and below the bake files and
the real-time renderer that look engines up in it, with no import loop.
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

import pbrkit

PACKAGE = Path(pbrkit.__file__).resolve().parent

#: subpackage -> the packages its modules must not import
FORBIDDEN = {
    "sampling": ("pbrkit.microfacet", "pbrkit.brdf"),
    "microfacet": ("pbrkit.brdf",),
}


def _module_name(path):
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def imported_modules(source, module, is_package=False):
    """The absolute module names the source of ``module`` may import (module docstring)."""
    package = module.split(".") if is_package else module.split(".")[:-1]
    found = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - (node.level - 1)] if node.level > 1 else package
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module
            found.add(target)
            found.update(f"{target}.{alias.name}" for alias in node.names if alias.name != "*")
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
              and node.func.attr == "import_module" and node.args
              and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str)):
            found.add(node.args[0].value)
    return found


def _violations(source, module, forbidden, is_package=False):
    return sorted(name for name in imported_modules(source, module, is_package)
                  if any(name == f or name.startswith(f + ".") for f in forbidden))


@pytest.mark.parametrize("subpackage", sorted(FORBIDDEN))
def test_lower_layers_do_not_import_higher_ones(subpackage):
    files = sorted((PACKAGE / subpackage).rglob("*.py"))
    assert files, subpackage
    bad = {}
    for path in files:
        found = _violations(path.read_text(encoding="utf-8"), _module_name(path), FORBIDDEN[subpackage],
                            is_package=path.name == "__init__.py")
        if found:
            bad[str(path.relative_to(PACKAGE))] = found
    assert not bad, f"pbrkit.{subpackage} must not import {' or '.join(FORBIDDEN[subpackage])}: {bad}"


@pytest.mark.parametrize("source, expected", [
    ("from ..brdf.distributions import d_ggx\n", ["pbrkit.brdf.distributions", "pbrkit.brdf.distributions.d_ggx"]),
    ("from .. import brdf\n", ["pbrkit.brdf"]),
    ("from ..brdf import masking as m\n", ["pbrkit.brdf", "pbrkit.brdf.masking"]),
    ("import pbrkit.brdf.bxdf\n", ["pbrkit.brdf.bxdf"]),
    ("from pbrkit.microfacet.ggx import d_ggx\n", ["pbrkit.microfacet.ggx", "pbrkit.microfacet.ggx.d_ggx"]),
    ("def f():\n    from ...pbrkit import x\n    from ..microfacet import ggx\n    return ggx\n",
     ["pbrkit.microfacet", "pbrkit.microfacet.ggx"]),
    ("import importlib\nm = importlib.import_module('pbrkit.brdf.models')\n", ["pbrkit.brdf.models"]),
    ("from .warps import reflect\nfrom ..core.jit import dual_use\nimport numpy as np\n", []),
])
def test_the_check_sees_every_form_of_import(source, expected):
    """The checker itself: relative (one or two dots, with and without a module),
    absolute, aliased, function-level and importlib imports are all caught."""
    assert _violations(source, "pbrkit.sampling.warps", FORBIDDEN["sampling"]) == sorted(expected)


def test_relative_imports_of_a_package_init_resolve_from_the_package():
    assert _violations("from ..brdf import bxdf\n", "pbrkit.microfacet", ("pbrkit.brdf",), is_package=True) == \
        ["pbrkit.brdf", "pbrkit.brdf.bxdf"]
    assert _violations("from .ggx import d_ggx\n", "pbrkit.microfacet", ("pbrkit.brdf",), is_package=True) == []


def _defined_functions(path):
    return {node.name for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
            if isinstance(node, ast.FunctionDef)}


def test_each_formula_is_written_once():
    """A function of the microfacet units is defined nowhere else in pbrkit.brdf or
    pbrkit.sampling, and brdf/distributions.py defines nothing: facades only import."""
    unit_functions = set()
    for path in sorted((PACKAGE / "microfacet").glob("*.py")):
        unit_functions |= {name for name in _defined_functions(path) if not name.startswith("_")}
    assert {"d_ggx", "lambda_beckmann", "warp_ggx_vndf", "warp_beckmann_vndf", "lambda_blinn_phong"} <= unit_functions
    for sub in ("brdf", "sampling"):
        for path in sorted((PACKAGE / sub).rglob("*.py")):
            twice = _defined_functions(path) & unit_functions
            assert not twice, f"{path.relative_to(PACKAGE)} defines {sorted(twice)} again"
    assert _defined_functions(PACKAGE / "brdf" / "distributions.py") == set()


def test_facades_re_export_the_units():
    from pbrkit import microfacet
    from pbrkit.brdf import distributions, masking

    for name in distributions.__all__:
        value = getattr(distributions, name)
        homes = [unit for unit in (microfacet.roughness, microfacet.ggx, microfacet.beckmann, microfacet.gtr,
                                   microfacet.blinn_phong) if name in unit.__all__]
        assert len(homes) == 1 and getattr(homes[0], name) is value, name
    for name in ("COS_MIN", "erf", "g1_smith", "g2_separable", "g2_height_correlated", "visibility"):
        assert getattr(masking, name) is getattr(microfacet.smith, name), name
    for name in ("lambda_ggx", "lambda_ggx_anisotropic", "g1_ggx", "v_smith_ggx_height_correlated"):
        assert getattr(masking, name) is getattr(microfacet.ggx, name), name
    for name in ("lambda_beckmann", "lambda_beckmann_anisotropic", "g1_beckmann"):
        assert getattr(masking, name) is getattr(microfacet.beckmann, name), name
    assert masking.alpha_g_disney is microfacet.roughness.alpha_g_disney
    assert set(masking.__all__) >= {"k_schlick_from_alpha", "g1_schlick_ggx", "g2_kelemen", "v_kelemen", "v_neubelt"}
    # the top level's names are the facades (no dotted aliases: pbrkit has no import hook)
    import pbrkit

    assert pbrkit.distributions is distributions and pbrkit.masking is masking


def test_sampling_keeps_only_the_generic_warps():
    from pbrkit import sampling

    assert "reflect" in sampling.__all__ and "sample_cosine_hemisphere" in sampling.__all__
    leaked = [name for name in sampling.__all__ if any(d in name for d in ("ggx", "beckmann", "gtr", "phong"))]
    assert not leaked, leaked
    assert not hasattr(sampling, "sample_ggx_vndf")


def test_microfacet_method_table():
    from pbrkit import microfacet
    from pbrkit.brdf.terms import DISTRIBUTIONS

    assert set(DISTRIBUTIONS) <= set(microfacet.UNITS)
    assert microfacet.unit("ggx") is microfacet.ggx and microfacet.unit("gtr1") is microfacet.gtr
    assert microfacet.unit("blinn-phong") is microfacet.blinn_phong
    assert microfacet.unit("beckmann").warp_beckmann_vndf is microfacet.beckmann.warp_beckmann_vndf
    with pytest.raises(ValueError, match="choose one of ggx, beckmann, blinn-phong, gtr1"):
        microfacet.unit("phong")
    assert pbrkit.microfacet is microfacet  # the lazy name of the API tour


# ------------------------------------------------------------ the engines' layer


def _top_level_imports(path, module):
    """The pbrkit modules that importing ``module`` runs at once: its module-level
    imports (with those under a top-level ``if`` or ``try``), each with the
    packages above it (importing ``a.b.c`` runs ``a`` and ``a.b`` first), and the
    packages above ``module`` itself.  Imports inside functions run later and are left out."""
    is_package = path.name == "__init__.py"
    body, statements = list(ast.parse(path.read_text(encoding="utf-8")).body), []
    while body:
        node = body.pop(0)
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            statements.append(node)
        elif isinstance(node, (ast.If, ast.Try)):
            body[:0] = node.body + node.orelse + [s for h in getattr(node, "handlers", []) for s in h.body] \
                + getattr(node, "finalbody", [])
    names = imported_modules(ast.unparse(ast.Module(body=statements, type_ignores=[])), module, is_package)
    names |= {module.rsplit(".", 1)[0]} if not is_package and "." in module else set()
    found = set()
    for name in names:
        parts = name.split(".")
        found.update(".".join(parts[:k]) for k in range(1, len(parts) + 1))
    return found


@pytest.fixture(scope="module")
def import_graph():
    modules = {_module_name(p): p for p in PACKAGE.rglob("*.py")}
    return {m: _top_level_imports(p, m) & set(modules) - {m} for m, p in modules.items()}


def _reach(graph, start):
    seen, todo = set(), [start]
    while todo:
        for nxt in graph[todo.pop()]:
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
    return seen


def test_the_engine_table_sits_between_the_formats_and_the_bake_files(import_graph):
    """pbrkit.engines builds on ibl, io's file formats and the Sample Viewer's kernels;
    the bake files and the real-time renderer look engines up in it.  Nothing the
    engines import at module level imports them back (no loop: any of these modules
    can be imported first), and the engines load neither the bake files, the renderer
    nor the application."""
    engines = {m for m in import_graph if m == "pbrkit.engines" or m.startswith("pbrkit.engines.")}
    assert {"pbrkit.engines.filament", "pbrkit.engines.khronos", "pbrkit.engines.three",
            "pbrkit.engines.babylon"} <= engines
    below = _reach(import_graph, "pbrkit.engines") - engines
    assert {"pbrkit.ibl.prefilter", "pbrkit.io.ktx1", "pbrkit.rendering.khronos_ibl"} <= below
    loops = sorted(m for m in below if "pbrkit.engines" in _reach(import_graph, m))
    assert not loops, f"imported by pbrkit.engines and importing it back: {loops}"
    above = {"pbrkit.io.bake_files", "pbrkit.rendering.realtime", "pbrkit.rendering.run", "pbrkit.app"}
    assert not below & above, sorted(below & above)
    for user in ("pbrkit.io.bake_files", "pbrkit.rendering.realtime"):
        assert "pbrkit.engines" in import_graph[user], user


@pytest.mark.parametrize("first", ["pbrkit.engines", "pbrkit.engines.three", "pbrkit.ibl.sh", "pbrkit.ibl",
                                   "pbrkit.io.bake_files", "pbrkit.rendering.run"])
def test_each_side_of_the_engine_table_imports_first(first):
    """The check above, run: a fresh interpreter imports ``first`` before anything else."""
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", f"import {first}; import pbrkit.engines as e; "
                           "assert len(e.ENGINES) == 4"], capture_output=True, text=True, timeout=300,
                          env=_child_env())
    assert done.returncode == 0, done.stderr[-2000:]


def _child_env():
    import os

    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(PACKAGE.parent)] + [p for p in [env.get("PYTHONPATH")] if p])
    return env
# ---------------------------------------------------------------- the tests' own layout

#: tests/: one folder per subpackage of pbrkit, plus these (the command line, demo and
#: docs; the in-engine tests beside their npm files; the shared helpers).
TESTS = Path(__file__).resolve().parents[1]
TEST_FOLDERS_BESIDES = {"app", "engines", "support"}
#: Folders that are not tests (npm's, Python's caches) and are never searched.
NOT_TESTS = {"node_modules", "__pycache__"}


def _test_tree_files(pattern):
    return [p for p in TESTS.rglob(pattern) if not NOT_TESTS & set(p.relative_to(TESTS).parts)]


def _imported_roots(path):
    """The first component of every module that ``path`` imports (any level, any form;
    ``importlib.import_module`` with a literal name too)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "import_module"
              and node.args and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str)):
            names.add(node.args[0].value.split(".")[0])
    return names


def test_the_tests_mirror_the_package():
    """Every folder of tests/ names a subpackage of pbrkit (or app, engines, support);
    every test module lies in one of them (none at the top), its basename unique (pytest
    imports them by basename: no __init__.py in tests/), and none in support."""
    subpackages = {p.parent.name for p in PACKAGE.glob("*/__init__.py")}
    folders = {p.name for p in TESTS.iterdir() if p.is_dir() and p.name not in NOT_TESTS and not p.name.startswith(".")}
    assert folders - subpackages - TEST_FOLDERS_BESIDES == set()
    modules = _test_tree_files("test_*.py")
    assert modules, TESTS
    assert [p.name for p in modules if p.parent == TESTS] == []
    assert [p.name for p in modules if p.relative_to(TESTS).parts[0] == "support"] == []
    names = [p.name for p in modules]
    assert sorted({n for n in names if names.count(n) > 1}) == []
    assert [str(p.relative_to(TESTS)) for p in _test_tree_files("__init__.py")] == []


def test_no_test_module_imports_another():
    """Shared helpers live in tests/support: no file of tests/ imports a test module
    (``test_*``) or conftest.py (its hooks only; the skip reasons are support/skips.py)."""
    offenders = {}
    for path in _test_tree_files("*.py"):
        bad = sorted(n for n in _imported_roots(path) if n.startswith("test_") or n == "conftest")
        if bad:
            offenders[str(path.relative_to(TESTS))] = bad
    assert offenders == {}


def test_the_check_sees_every_form_of_test_import(tmp_path):
    path = tmp_path / "module.py"
    path.write_text("import test_a\nfrom test_b import x\nimport os.path\nfrom . import y\n"
                    "def f():\n    from test_c.sub import z\n    importlib.import_module('test_d')\n")
    assert _imported_roots(path) == {"test_a", "test_b", "os", "test_c", "test_d"}


def test_support_holds_no_tests():
    """tests/support's modules define helpers only: no test function or class (pytest
    would not collect them there, so a test put there would silently never run)."""
    found = []
    for path in (TESTS / "support").glob("*.py"):
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.name.startswith("test"):
                found.append(f"{path.name}: {node.name}")
            elif isinstance(node, ast.ClassDef) and node.name.startswith("Test"):
                found.append(f"{path.name}: {node.name}")
    assert found == []


# ===================================================== the import graph of the whole package
#
# Every module of pbrkit, read with ast (nothing imported): its imports of pbrkit's
# modules, each marked module-level or function-level (inside a def or lambda), relative
# ones resolved.  `from package import x` is an import of the submodule package.x when x
# is one, else of the package's __init__; `import a.b` of a.b.  Then:
# (a) the library (everything but pbrkit.cli, pbrkit.app and pbrkit.__main__) imports
#     neither the command line nor the application, and the application not the command line;
# (b) no cycle among pbrkit's modules through module-level imports;
# (c) no cycle at all, counting function-level imports too, but the known ones below.

#: Cycles that need function-level imports, in library parts outside the command line and
#: the application, to be fixed there (each a sorted tuple of the modules of one strongly
#: connected component; the test fails once one is gone, so the list stays true).
KNOWN_CYCLES = set()
#: The optional extras' top-level modules (pyproject's explore and batch extras).
EXTRA_MODULES = {"panel", "bokeh", "dask", "distributed"}


def _all_modules():
    return {_module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def import_edges(source, module, modules, is_package=False):
    """{(imported module, function_level)} of ``module``'s source: pbrkit's modules
    (names in ``modules``) and the top-level names of other packages."""
    package = module.split(".") if is_package else module.split(".")[:-1]
    found = set()

    def visit(node, function_level):
        for child in ast.iter_child_nodes(node):
            inner = function_level or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            if isinstance(child, ast.Import):
                found.update((alias.name, inner) for alias in child.names)
            elif isinstance(child, ast.ImportFrom):
                if child.level:
                    base = package[:len(package) - (child.level - 1)]
                    target = ".".join(base + ([child.module] if child.module else []))
                else:
                    target = child.module
                for alias in child.names:
                    sub = f"{target}.{alias.name}"
                    found.add((sub if sub in modules else target, inner))
            elif (isinstance(child, ast.Call) and isinstance(child.func, ast.Attribute)
                  and child.func.attr == "import_module" and child.args
                  and isinstance(child.args[0], ast.Constant) and isinstance(child.args[0].value, str)):
                found.add((child.args[0].value, True))
            visit(child, inner)

    visit(ast.parse(source), False)
    return {(name if name in modules or not name else name.split(".")[0], level)
            for name, level in found if name and name != module}


@functools.lru_cache(maxsize=1)
def _graph():
    """{module: {(imported, function_level)}} of every module of pbrkit (read once; not to be changed)."""
    modules = _all_modules()
    return {name: import_edges(path.read_text(encoding="utf-8"), name, modules, path.name == "__init__.py")
            for name, path in modules.items()}


def cycles(graph):
    """The strongly connected components of more than one module (Tarjan), each sorted."""
    index, low, stack, on, found = {}, {}, [], set(), []

    def strong(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in graph:
                continue
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(tuple(sorted(component)))

    for v in sorted(graph):
        if v not in index:
            strong(v)
    return found


def _inside(name, package):
    return name == package or name.startswith(package + ".")


def test_the_library_imports_neither_the_command_line_nor_the_application():
    bad = {}
    for module, edges in _graph().items():
        if module == "pbrkit.__main__":
            wrong = [n for n, _ in edges if _inside(n, "pbrkit.app")]
        elif _inside(module, "pbrkit.cli"):
            continue
        elif _inside(module, "pbrkit.app"):
            wrong = [n for n, _ in edges if _inside(n, "pbrkit.cli")]
        else:
            wrong = [n for n, _ in edges if _inside(n, "pbrkit.cli") or _inside(n, "pbrkit.app")]
        if wrong:
            bad[module] = sorted(set(wrong))
    assert not bad, f"imports against the layers (library < app < cli): {bad}"
    assert ("pbrkit.cli", False) in _graph()["pbrkit.__main__"]


def test_no_import_cycle_through_module_level_imports():
    graph = {m: {n for n, function_level in e if not function_level} for m, e in _graph().items()}
    assert cycles(graph) == []


def test_no_import_cycle_at_all_but_the_known_ones():
    """Function-level imports count too: one that only hides a cycle is still a cycle.
    The command line and the application have none; the known library ones are
    listed in KNOWN_CYCLES (and each must still exist, so the list stays true)."""
    found = set(cycles({m: {n for n, _ in e} for m, e in _graph().items()}))
    assert found - KNOWN_CYCLES == set(), sorted(found - KNOWN_CYCLES)
    assert KNOWN_CYCLES <= found, f"fixed, drop them from KNOWN_CYCLES: {sorted(KNOWN_CYCLES - found)}"
    assert not [c for c in found if any(_inside(m, "pbrkit.cli") or _inside(m, "pbrkit.app") for m in c)]


@pytest.mark.parametrize("source, module, expected", [
    ("from . import console\nfrom .options import _flag\n", "pbrkit.cli.render",
     {("pbrkit.cli.console", False), ("pbrkit.cli.options", False)}),
    ("from .. import choices, __version__\n", "pbrkit.cli.render", {("pbrkit.choices", False), ("pbrkit", False)}),
    ("def f():\n    from ..app.demo import run_demo\n", "pbrkit.cli.demo", {("pbrkit.app.demo", True)}),
    ("from . import render\n", "pbrkit.cli", {("pbrkit.cli.render", False)}),
    ("import numpy as np\nx = lambda: __import__('y')\n", "pbrkit.core.vec", {("numpy", False)}),
    ("import importlib\ndef f():\n    return importlib.import_module('pbrkit.app.demo')\n", "pbrkit.core.vec",
     {("importlib", False), ("pbrkit.app.demo", True)}),
])
def test_the_graph_resolves_every_form_of_import(source, module, expected):
    modules = set(_all_modules()) | {"pbrkit.app.demo"}
    assert import_edges(source, module, modules, is_package=module == "pbrkit.cli") == expected


def test_the_cycle_finder_finds_cycles():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [("a", "b", "c")]
    assert cycles({"a": {"b"}, "b": set()}) == []


def _reachable(graph, start):
    seen, todo = set(), [start]
    while todo:
        v = todo.pop()
        if v in seen:
            continue
        seen.add(v)
        todo.extend(n for n, _ in graph.get(v, ()))
    return seen


@pytest.mark.parametrize("command", ["render", "demo", "bake", "lut", "furnace", "approximations", "ltc",
                                     "hatching", "shaders"])
def test_the_base_commands_need_no_extra(command):
    """Nothing the command can import, at any level, is Panel, Bokeh or Dask: the
    base install runs it (only ``pbrkit explore`` serving and ``pbrkit batch`` need an
    extra).  The demo's warm-up runs as ``python -m pbrkit.app.warmup``: counted too."""
    graph = _graph()
    reached = _reachable(graph, f"pbrkit.cli.{command}")
    if command == "demo":
        reached |= _reachable(graph, "pbrkit.app.warmup")
    assert not reached & EXTRA_MODULES, sorted(reached & EXTRA_MODULES)


def test_the_extras_check_sees_the_commands_that_need_them():
    graph = _graph()
    assert {"dask", "distributed"} <= _reachable(graph, "pbrkit.cli.batch")
    assert {"panel", "bokeh"} & _reachable(graph, "pbrkit.cli.explore")
