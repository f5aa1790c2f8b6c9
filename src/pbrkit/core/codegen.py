"""Functions generated from declarations: the dispatch over method tables and
models, and the value, sampling and pdf of a composition of lobes.

Generated code is Python source built from a declaration and compiled like
any :func:`pbrkit.core.jit.dual_use` helper (NumPy from Python, scalars inside
Numba kernels).  Its text is kept on the function (``__source__``) so that it
can be read and documented; nothing generated is typed by hand.
"""

from __future__ import annotations

from .jit import jitable, njit

__all__ = ["generate", "if_chain"]


def generate(source, name, namespace, inline=True):
    """Compile the function ``name`` defined by ``source`` with the globals
    ``namespace``, as a dual-use helper: ``inline=True`` inlines it at Numba's IR level
    where a kernel calls it (like ``dual_use(inline=True)``, without a disk cache: it
    is compiled into its callers), ``"llvm"`` compiles it once and has LLVM inline
    it (:func:`pbrkit.core.jit.jitable` with ``forceinline``), False registers it as
    a plain jitable helper."""
    scope = dict(namespace)
    exec(compile(source, f"<pbrkit generated {name}>", "exec"), scope)
    fn = scope[name]
    fn.__source__ = source
    if inline == "llvm":
        compiled = jitable(fn, forceinline=True)
    elif inline:
        compiled = njit(fn, inline="always", error_model="numpy")
    else:
        compiled = jitable(fn)
    compiled.__source__ = source
    return compiled


def if_chain(selector, calls, indent="    ", fallback=None, values=None):
    """Source lines ``if selector == 0: return calls[0] ...`` (the selector's values
    ``values``, default 0, 1, ...); the last call is the ``else`` (or ``fallback``
    when given, for a selector that may match none)."""
    values = range(len(calls)) if values is None else values
    lines = []
    last = len(calls) - 1 if fallback is None else len(calls)
    for i, (value, call) in enumerate(zip(values, calls)):
        if i == last:
            lines.append(f"{indent}return {call}")
        else:
            lines.append(f"{indent}if {selector} == {value}:")
            lines.append(f"{indent}    return {call}")
    if fallback is not None:
        lines.append(f"{indent}return {fallback}")
    return lines
