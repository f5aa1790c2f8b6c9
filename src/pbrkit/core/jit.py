"""Numba helpers shared by every module: one decorator for compiled helpers,
two for kernels, and a disk cache that follows pbrkit's sources.

Each formula in pbrkit is written once, as a plain NumPy function decorated
with :func:`dual_use`.  Called from Python it runs on arrays of any leading
shape (NumPy broadcasting); called from a Numba kernel it is compiled for
scalars into that kernel (:func:`jitable`, as Numba's ``register_jitable``).  So the NumPy
reference path and the compiled hot path share one formula.

Kernels (:func:`kernel`, :func:`threaded_kernel`, :func:`row_kernel`) use
NumPy's error model: a float division by zero gives inf or NaN as in NumPy
(the kernels guard the divisions whose result matters), not a branch that
raises, which would also keep loops from being vectorised.  They are cached on disk.  Numba's
own cache checks only the kernel's source file, so a kernel whose helpers
changed in another file would be loaded stale.  pbrkit's kernels therefore
use their own cache directory, keyed on the package version and a hash of
every source file of the package (:func:`source_hash`): editing any pbrkit
module starts a fresh cache, and installs of the same sources share one.  The
directory is ``$PBRKIT_CACHE_DIR`` if set, else ``$NUMBA_CACHE_DIR/pbrkit``,
else ``$XDG_CACHE_HOME/pbrkit`` (``~/.cache/pbrkit``), with a subdirectory
``numba-<version>-<hash>`` (:func:`cache_directory`, from :mod:`pbrkit.core.cache`,
which needs no Numba).
"""

from __future__ import annotations

import functools
import os
import threading
import types as pytypes
from pathlib import Path

import numba
import numpy as np
from numba import types
from numba.core import cgutils
from numba.core.caching import CacheImpl, _CacheLocator
from numba.core.errors import RequireLiteralValue
from numba.core.targetconfig import ConfigStack
from numba.core.typing.templates import infer, infer_global, make_overload_template
from numba.extending import intrinsic, overload

from .cache import cache_directory, source_hash

__all__ = ["dual_use", "jitable", "kernel", "threaded_kernel", "run_in_threads", "row_kernel", "lane_stage",
           "stack_array", "select", "njit", "rebind",
           "source_hash", "cache_directory"]

_PACKAGE_ROOT = Path(__file__).resolve().parent.parent


def dual_use(fn=None, *, inline=False, cache=True):
    """Mark ``fn`` as a dual-use helper: NumPy on arrays from Python, compiled for
    scalars into every Numba kernel that calls it.

    ``inline=True`` inlines it at Numba's IR level (``njit(inline="always")``)
    instead of leaving the choice to LLVM: for the few tiny helpers in the
    innermost loops (cube-map texel fetches) where a call costs as much as the
    work; called from Python such a helper is compiled for its argument types.
    ``inline="llvm"`` compiles it as a :func:`jitable` that LLVM always inlines
    (``forceinline``), its own callees not: for the few larger helpers between a
    kernel and its formulas whose call costs a kernel's speed (a model's value and
    setup), where inlining in Numba's IR would repeat their typing in every kernel;
    called from Python it is ``fn`` itself.  Use as ``@dual_use``,
    ``@dual_use(inline=True)`` or ``@dual_use(inline="llvm")``.  ``cache=False``
    keeps an inlined helper out of the disk cache, for helpers made by other
    functions (closures over compiled functions and arrays) that Python calls too:
    their compiled code is inlined into the kernels, which are cached."""
    if fn is None:
        return functools.partial(dual_use, inline=inline, cache=cache)
    if inline == "llvm":
        return jitable(fn, forceinline=True)
    if inline:
        return njit(fn, inline="always", cache=cache, error_model="numpy")
    return jitable(fn)


# The compiler flags a called helper's compilation takes from its caller's (Numba's
# CPUTargetOptions.finalize: ``inherit_if_not_set``); the caller's other flags (its
# Python wrapper, ``nogil``, ...) do not change the helper's code.
# ``forceinline`` is inherited too, but a helper here sets its own (False unless asked),
# so a helper called from a force-inlined one is not compiled a second time.
_INHERITED_FLAGS = ("nrt", "fastmath", "error_model")


def _hashable(value):
    """A flag's value as a dictionary key (``fastmath`` is a set of LLVM flags)."""
    return frozenset(value.flags) if hasattr(value, "flags") else value


def jitable(fn, *, forceinline=False):
    """Register the Python function ``fn`` as a helper that Numba kernels compile for
    scalars when they call it, as Numba's ``register_jitable`` does (an ``overload``
    whose implementation is ``fn`` itself, never inlined at the IR level), and return
    ``fn`` unchanged for Python callers.

    Numba keeps one compilation of such a helper per argument types *and* per set
    of the calling compilation's flags, so a helper called from a kernel, from a
    ``nogil`` kernel and from another helper is compiled three times over, to the
    same code.  Here the compilations are shared between callers whose flags agree
    on those a helper inherits (:data:`_INHERITED_FLAGS`): the same machine code,
    compiled once per process.  ``forceinline=True`` has LLVM inline it into every
    caller; either way the choice is the helper's own, not inherited from a caller."""
    def implementation(*args, **kwargs):
        return fn

    options = {"no_cpython_wrapper": True, "nopython": True, "forceinline": forceinline}
    template = make_overload_template(fn, implementation, options, False, "never")

    class SharedTemplate(template):
        def _get_impl(self, args, kws):
            flags = ConfigStack.top_or_none()
            inherited = None if flags is None else tuple(_hashable(getattr(flags, name)) for name in _INHERITED_FLAGS)
            key = self.context, tuple(args), tuple(kws.items()), inherited
            cached = self._impl_cache.get(key)
            return cached if cached is not None else self._build_impl(key, args, kws)

    infer(SharedTemplate)
    infer_global(fn, types.Function(SharedTemplate))
    _MADE[fn] = functools.partial(jitable, forceinline=forceinline)
    return fn


def njit(fn, **options):
    """``numba.njit(**options)(fn)``, remembered so that :func:`rebind` can compile a
    copy of ``fn`` the same way.  Every compiled function of pbrkit is made by this
    or :func:`jitable`."""
    compiled = numba.njit(**options)(fn)
    _MADE[fn] = lambda clone: numba.njit(**options)(clone)
    return compiled


def kernel(fn):
    """Compile *fn* with Numba, cached on disk (:func:`cache_directory`), serial,
    with NumPy's error model (module docstring)."""
    return numba.njit(cache=True, fastmath=False, error_model="numpy")(fn)


def threaded_kernel(fn):
    """Compile *fn* with Numba, cached on disk, serial and releasing the GIL
    (``nogil``), for kernels that :func:`run_in_threads` runs on ranges of work
    items from a pool of Python threads, and whose loops LLVM should turn into SIMD
    code: NumPy's error model, so a float division by zero gives inf or NaN instead
    of a branch that raises (a loop with an exit cannot be vectorised).  Against a
    ``prange`` kernel: Numba compiles the body once instead of once more for the
    parallel region's outlined function, which halves the first compilation of a
    large kernel, and work items are handed out dynamically all the same."""
    return njit(fn, cache=True, nogil=True, fastmath=False, error_model="numpy")


_POOL = {"key": None, "pool": None}


def _thread_pool(threads):
    """The process's pool of ``threads`` Python threads, created on first use and again
    when the thread count changes or after a fork (threads do not survive one)."""
    key = (os.getpid(), threads)
    if _POOL["key"] != key:
        from concurrent.futures import ThreadPoolExecutor

        _POOL["pool"] = ThreadPoolExecutor(threads, thread_name_prefix="pbrkit-kernel")
        _POOL["key"] = key
    return _POOL["pool"]


def run_in_threads(fn, count, *args, chunks_per_thread=16):
    """``fn(start, stop, *args)`` over ``range(count)`` cut into about ``chunks_per_thread``
    ranges per thread, on Numba's thread count (``numba.get_num_threads()``,
    ``NUMBA_NUM_THREADS``) of Python threads kept for the process, each taking the
    next range until none is left (a call costs one hand-over per thread, not the
    threads' start); ``fn`` is a :func:`threaded_kernel`.
    Results must not depend on which thread runs which range (each item writes
    its own outputs), so they are the same bytes for any thread count."""
    threads = max(1, numba.get_num_threads())
    step = max(1, -(-count // (chunks_per_thread * threads)))
    ranges = [(start, min(start + step, count)) for start in range(0, count, step)]
    if threads == 1 or len(ranges) == 1:
        for start, stop in ranges:
            fn(start, stop, *args)
        return
    pending = iter(ranges)
    lock = threading.Lock()

    def work():  # each thread takes the next range until none is left (dynamic balance)
        while True:
            with lock:
                r = next(pending, None)
            if r is None:
                return
            fn(r[0], r[1], *args)

    pool = _thread_pool(threads)
    for future in [pool.submit(work) for _ in range(min(threads, len(ranges)))]:
        future.result()


def row_kernel(rows):
    """Compile a kernel over independent rows, written as ``fn(start, stop, *args)``
    with a loop ``for i in range(start, stop)``, as a :func:`threaded_kernel`, and
    return a function of ``*args`` that runs it on every row from a pool of
    threads (:func:`run_in_threads`).  ``rows``: the index of the argument whose
    first dimension is the row count, or a function of ``*args`` giving it.  This
    is the form of pbrkit's per-pixel and per-texel kernels: the compiled code is
    the same as a ``prange`` loop's, but Numba compiles the body once (a
    ``prange`` body is compiled again as the parallel region's outlined function),
    so the first run compiles in a half to two thirds of the time.  The compiled
    kernel is the wrapper's ``kernel`` attribute."""
    count = rows if callable(rows) else (lambda *args: args[rows].shape[0])

    def wrap(fn):
        compiled = threaded_kernel(fn)

        @functools.wraps(fn)
        def run(*args):
            run_in_threads(compiled, int(count(*args)), *args)

        run.kernel = compiled
        run.rows = count
        return run

    return wrap


def lane_stage(fn):
    """Mark *fn* as a stage of a :func:`threaded_kernel`: compiled once for its argument
    types, without caching (LLVM needs its IR), and always inlined by LLVM where it
    is called, so that its loops over lanes are optimised again with the caller's
    constant arguments (a BxDF whose model is fixed loses its other models'
    branches) and vectorised.  Call stages from the kernel itself: a stage inlined
    into another stage has its loops optimised, and left as they are, in that
    stage's own compilation.  A stage's loops must not call functions that take
    arrays (the reference counting of those arrays adds calls that keep a loop from
    being vectorised); loops that gather from tables belong in the kernel, where
    LLVM knows its arrays apart."""
    return njit(fn, forceinline=True, fastmath=False, error_model="numpy")


@intrinsic
def stack_array(typingctx, rows, cols):
    """A (rows, cols) float64 array (C order, not initialised) in the stack frame of the
    compiled function that calls it, for the lane buffers of :func:`threaded_kernel`
    stages; ``rows`` and ``cols`` must be compile-time constants.  LLVM knows stack
    memory apart from every array argument, so loops that gather from tables and
    store into such a buffer are vectorised without the run-time overlap checks
    that gathers cannot have; and the array has no reference count.  It must not
    outlive the call (never return it or store it)."""
    if not isinstance(rows, types.IntegerLiteral) or not isinstance(cols, types.IntegerLiteral):
        raise RequireLiteralValue("stack_array needs constant sizes")
    n_rows = rows.literal_value
    n_cols = cols.literal_value
    array_type = types.Array(types.float64, 2, "C")

    def codegen(context, builder, signature, args):
        data = cgutils.alloca_once(builder, context.get_value_type(types.float64), size=n_rows * n_cols)
        array = context.make_array(array_type)(context, builder)
        intp = context.get_value_type(types.intp)
        context.populate_array(array, data=data, shape=(intp(n_rows), intp(n_cols)),
                               strides=(intp(8 * n_cols), intp(8)), itemsize=intp(8), meminfo=None)
        return array._getvalue()

    return array_type(rows, cols), codegen


def select(condition, if_true, if_false):
    """Elementwise ``if_true if condition else if_false``.

    ``np.where`` on arrays from Python; inside Numba kernels, on scalars, a plain
    conditional expression (Numba's ``np.where`` would allocate a 0-d array).
    """
    return np.where(condition, if_true, if_false)


@overload(select)
def _select_numba(condition, if_true, if_false):
    if isinstance(condition, types.Boolean):
        def scalar_select(condition, if_true, if_false):
            return if_true if condition else if_false

        return scalar_select

    def array_select(condition, if_true, if_false):
        return np.where(condition, if_true, if_false)

    return array_select


# ----------------------------------------------------------------- rebinding

#: How each compiled function of pbrkit was made, by its Python function: a function
#: of a copy that compiles the copy the same way (:func:`njit`, :func:`jitable`).
_MADE = {}


def _names(code):
    """The global names that ``code`` and the code objects nested in it read."""
    names = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, pytypes.CodeType):
            names |= _names(const)
    return names


def rebind(obj, replacements, suffix, memo=None):
    """``obj`` (a compiled function of pbrkit, a :func:`row_kernel` or any object) with
    every object of ``replacements`` (a dict from ``id(old)`` to the new object) put in
    its place, in ``obj`` and in every compiled function that it calls, directly or
    not: the functions that reach a replaced one are copied with new globals (and
    closure cells) and compiled again the way they were made (:func:`njit`,
    :func:`jitable`), the others are kept.  The copies are named ``<name>__<suffix>``,
    so that a copy's disk cache is its own.  This compiles one kernel for another set
    of helpers, such as the dispatch over fewer models
    (:func:`pbrkit.brdf.dispatch.restricted`), without writing it twice.
    ``memo`` (a dict) shares the copies between calls for the same replacements."""
    memo = {} if memo is None else memo
    return _rebind(obj, replacements, suffix, memo)


def _rebind(obj, replacements, suffix, memo):
    key = id(obj)
    if key in replacements:
        return replacements[key]
    if key in memo:
        return memo[key][0]
    if isinstance(obj, pytypes.FunctionType) and hasattr(obj, "kernel") and hasattr(obj, "rows"):
        memo[key] = (obj, obj)  # a row kernel: its compiled kernel rebound, run the same way
        compiled = _rebind(obj.kernel, replacements, suffix, memo)
        if compiled is obj.kernel:
            return obj
        count = obj.rows

        @functools.wraps(obj)
        def run(*args):
            run_in_threads(compiled, int(count(*args)), *args)

        run.kernel = compiled
        run.rows = count
        memo[key] = (run, obj)
        return run
    py = getattr(obj, "py_func", obj)
    if not isinstance(py, pytypes.FunctionType) or py not in _MADE:
        return obj
    memo[key] = (obj, obj)  # a recursive call keeps the original (none of pbrkit's do)
    scope = py.__globals__
    changed = {}
    for name in _names(py.__code__):
        if name in scope:
            new = _rebind(scope[name], replacements, suffix, memo)
            if new is not scope[name]:
                changed[name] = new
    closure = py.__closure__
    if closure:
        contents = [_rebind(c.cell_contents, replacements, suffix, memo) for c in closure]
        if any(new is not c.cell_contents for new, c in zip(contents, closure)):
            closure = tuple(pytypes.CellType(new) for new in contents)
            changed["<closure>"] = True
    if not changed:
        return obj
    clone = pytypes.FunctionType(py.__code__, {**scope, **{k: v for k, v in changed.items() if k != "<closure>"}},
                                 py.__name__, py.__defaults__, closure)
    clone.__kwdefaults__ = py.__kwdefaults__
    clone.__qualname__ = f"{py.__qualname__}__{suffix}"
    clone.__doc__ = py.__doc__
    clone.__module__ = py.__module__
    if hasattr(py, "__source__"):
        clone.__source__ = py.__source__
    compiled = _MADE[py](clone)
    memo[key] = (compiled, obj)  # the original is kept alive: ids stay unique
    return compiled


# ----------------------------------------------------------------- the cache


class _SourceHashLocator(_CacheLocator):
    """Numba cache locator for pbrkit's own kernels: entries live in
    :func:`cache_directory` (one subfolder per source folder) and are stamped
    with the hash of all the package's sources, not the kernel file's
    modification time."""

    def __init__(self, py_func, py_file):
        self._py_file = py_file  # what Numba's warnings about an uncachable function name
        self._lineno = py_func.__code__.co_firstlineno
        relative = Path(py_file).resolve().relative_to(_PACKAGE_ROOT)
        self._cache_path = os.path.join(cache_directory(), *relative.parent.parts)

    def get_cache_path(self):
        return self._cache_path

    def get_source_stamp(self):
        return source_hash()

    def get_disambiguator(self):
        return str(self._lineno)

    @classmethod
    def from_function(cls, py_func, py_file):
        try:
            Path(py_file).resolve().relative_to(_PACKAGE_ROOT)
        except (ValueError, OSError, TypeError):
            return None  # not one of pbrkit's files: Numba's own locators decide
        self = cls(py_func, py_file)
        try:
            self.ensure_cache_path()
        except OSError:
            return None  # unwritable: Numba's own locators are tried next
        return self


def _install_locator():
    # CacheImpl tries its locator classes in order; ours claims pbrkit's files only.
    if _SourceHashLocator not in CacheImpl._locator_classes:
        CacheImpl._locator_classes.insert(0, _SourceHashLocator)


_install_locator()
