"""The engines pbrkit bakes for and renders as: Filament, the Khronos glTF Sample
Viewer, three.js and Babylon.js, one module each (:mod:`~pbrkit.engines.filament`,
:mod:`~pbrkit.engines.khronos`, :mod:`~pbrkit.engines.three`,
:mod:`~pbrkit.engines.babylon`), each declaring its :class:`Engine`: its level curve
(roughness <-> mip level), its IBL shading, its target writer and the npm version it
is pinned to.

:data:`ENGINES` maps the names (:data:`pbrkit.choices.RENDER_ENGINES` less pbrkit's
own) to them and :func:`engine` looks one up; ``pbrkit bake --target``
(:func:`pbrkit.io.bake_files.write_bake`: :func:`parse_targets`, :func:`chains_for`,
:func:`write_target`) and ``pbrkit render --engine``
(:func:`pbrkit.rendering.realtime.render_realtime`) both go through it.

Layers: the engines build on :mod:`pbrkit.ibl` (level curves, cube and SH forms; the
bake prefilters the engines' chains at their curves, so the curves' formulas stay in
:mod:`pbrkit.ibl.prefilter`), the file formats of :mod:`pbrkit.io` and the Sample
Viewer's kernels (:mod:`pbrkit.rendering.khronos_ibl`); the bake files and the
real-time renderer build on the engines (tests/app/test_package_layout.py checks).

A target's files go to ``OUT/<name>/`` beside the generic files (or alone,
``only_targets``); its manifest entry says how to load them, every path relative
to the bake folder (:data:`LOAD_BASE`, docs/engine-targets.md).
"""

from __future__ import annotations

from pathlib import Path

from ..choices import BAKE_TARGETS, RENDER_ENGINES
from . import babylon, filament, khronos, three
from .engine import LOAD_BASE, Engine

__all__ = ["Engine", "ENGINES", "engine", "TARGETS", "LOAD_BASE", "parse_targets", "chains_for", "write_target",
           "filament", "khronos", "three", "babylon"]

#: Engine name -> its :class:`Engine`, in :data:`pbrkit.choices.RENDER_ENGINES` order.
ENGINES = {e.name: e for e in sorted((filament.ENGINE, khronos.ENGINE, three.ENGINE, babylon.ENGINE),
                                     key=lambda e: e.code)}

#: What a bake can be written for (:data:`pbrkit.choices.BAKE_TARGETS`): ``generic``, pbrkit's own
#: files (the bake folder's top level), or an engine's (a subfolder named after it).
TARGETS = BAKE_TARGETS


def engine(name):
    """The :class:`Engine` called ``name`` (:data:`ENGINES`); a one-line ValueError naming the choices."""
    try:
        return ENGINES[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown engine {name!r}; choose one of {', '.join(ENGINES)}") from None


def parse_targets(values, only_targets=False):
    """The targets of ``--target`` values (each a name, ``all``, or a comma-separated
    list of them), in :data:`TARGETS` order without repeats.  ``generic`` is always
    among them (the engines' files sit beside the generic ones) unless
    ``only_targets``, which writes the engines' files alone: then ``generic`` is
    left out (``all`` meaning every engine), and naming it, or no engine, is refused.
    ValueError names an unknown target."""
    chosen = set() if only_targets else {"generic"}
    named_generic = False
    for value in values or (() if only_targets else ("generic",)):
        for name in str(value).split(","):
            name = name.strip().lower()
            if name == "all":
                chosen.update(TARGETS)
            elif name in TARGETS:
                chosen.add(name)
                named_generic |= name == "generic"
            else:
                raise ValueError(f"--target: unknown target {name!r}; choose from {', '.join(TARGETS)}, all")
    if only_targets:
        if named_generic:
            raise ValueError("--target generic writes pbrkit's own files, which --only-target leaves out; "
                             "name engines only")
        chosen.discard("generic")
        if not chosen:
            raise ValueError(f"--only-target needs an engine: --target {'|'.join(ENGINES)}|all")
    return tuple(t for t in TARGETS if t in chosen)


def chains_for(targets):
    """The extra chains (level curves other than the generic one) that ``targets``
    need, for :func:`pbrkit.ibl.bake.bake`'s ``chains``."""
    curves = (ENGINES[t].extra_chain for t in parse_targets(targets) if t != "generic")
    return tuple(dict.fromkeys(c for c in curves if c is not None))


def write_target(name, root, b):
    """Write engine ``name``'s files into ``root/name`` (its writer,
    :attr:`Engine.writer`) for the bake ``b`` and return its manifest entry, with
    the base its load line's paths are relative to (``load_base``)."""
    folder = Path(root) / name
    folder.mkdir()
    entry = engine(name).writer(folder, b)
    return dict(entry, load_base=LOAD_BASE)
