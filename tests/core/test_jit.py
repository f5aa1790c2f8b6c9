"""The compiled-helper decorator and the kernel cache keyed on the package's sources."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

import pbrkit
from pbrkit.core import jit

PACKAGE = Path(pbrkit.__file__).resolve().parent


def test_source_hash_follows_every_source_file(tmp_path):
    copy = tmp_path / "pbrkit"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__", "*.hdr"))
    before = jit.source_hash.__wrapped__(copy)
    assert before == jit.source_hash.__wrapped__(PACKAGE)
    masking = copy / "brdf" / "masking.py"  # a term that kernels in other files call
    masking.write_text(masking.read_text() + "\n# edited\n")
    assert jit.source_hash.__wrapped__(copy) != before
    assert jit.source_hash()[:16] in jit.cache_directory()


def test_pbrkit_kernels_use_the_hash_keyed_cache(tmp_path):
    """In a fresh process with PBRKIT_CACHE_DIR set, a kernel's cache index lands in
    <dir>/numba-<version>-<hash>/<subpackage>/, and a second process loads it."""
    code = ("import numpy as np; from pbrkit.albedo.tables import sample_table; "
            "print(float(sample_table(np.ones((2, 2, 1)), 0.3, 0.6)[0]))")
    env = dict(os.environ, PBRKIT_CACHE_DIR=str(tmp_path))
    for _ in range(2):
        out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
        assert out.stdout.strip() == "1.0"
    folders = list(tmp_path.glob("numba-*"))
    assert len(folders) == 1 and folders[0].name.endswith(jit.source_hash()[:16])
    index = list((folders[0] / "albedo").glob("tables._sample_table_kernel-*.nbi"))
    assert index, sorted(p.name for p in folders[0].rglob("*"))


def test_dual_use_runs_on_arrays_and_inside_kernels():
    @jit.dual_use
    def twice_plus(x, y):
        return 2.0 * x + jit.select(y > 0.0, y, 0.0)

    @jit.kernel
    def use(a, out):
        for i in range(a.shape[0]):
            out[i] = twice_plus(a[i], a[i] - 1.0)

    a = np.array([0.5, 2.0, 3.0])
    out = np.empty(3)
    use(a, out)
    np.testing.assert_array_equal(out, twice_plus(a, a - 1.0))
    np.testing.assert_array_equal(out, [1.0, 5.0, 8.0])


def test_a_helper_compiles_once_for_callers_that_differ_only_in_flags_it_does_not_inherit():
    """jit.jitable: one compilation of a helper serves a plain kernel, a ``nogil`` kernel,
    another helper, a force-inlined helper and a force-inlined kernel (Numba's
    register_jitable compiles it once for each: its cache key holds every flag of the
    caller, and ``forceinline`` passes from caller to callee); a caller with another
    error model, a flag the helper inherits, gets its own compilation, which divides by
    zero as that model says.  A helper made with ``forceinline=True`` is marked for
    LLVM to inline, its callees not."""
    import numba
    from numba.core import event

    def scale(x):
        return x / (x - 1.0)

    jit.jitable(scale)

    def twice(x):
        return scale(x) + scale(x)

    jit.jitable(twice)

    def twice_inlined(x):
        return scale(x) * scale(x)

    jit.jitable(twice_inlined, forceinline=True)

    compiled = []
    helpers = {}

    class Listener(event.Listener):
        def on_start(self, ev):
            if ev.data["dispatcher"].py_func is scale:
                compiled.append(str(ev.data["args"]))

        def on_end(self, ev):
            helpers[ev.data["dispatcher"].py_func.__name__] = ev.data["dispatcher"]

    def call(x):
        return scale(x)

    def call_twice(x):
        return twice(x)

    def call_twice_inlined(x):
        return twice_inlined(x)

    listener = Listener()
    event.register("numba:compile", listener)
    try:
        plain = numba.njit(error_model="numpy")(call)
        nogil = numba.njit(error_model="numpy", nogil=True)(call)
        nested = numba.njit(error_model="numpy")(call_twice)
        python_model = numba.njit(error_model="python")(call)
        inlined = numba.njit(error_model="numpy")(call_twice_inlined)
        forced = numba.njit(error_model="numpy", forceinline=True)(call)
        assert plain(3.0) == nogil(3.0) == forced(3.0) == 1.5 and nested(3.0) == 3.0 and inlined(3.0) == 2.25
        assert len(compiled) == 1
        code = {name: [r.library.get_llvm_str() for r in d.overloads.values()] for name, d in helpers.items()}
        assert all("alwaysinline" in c for c in code["twice_inlined"])  # LLVM must inline it ...
        assert not any("alwaysinline" in c for c in code["scale"])  # ... and not its callee
        assert np.isinf(plain(1.0))  # NumPy's error model: x / 0 is inf
        try:
            python_model(1.0)
            raise AssertionError("Python's error model raises on a division by zero")
        except ZeroDivisionError:
            pass
        assert len(compiled) == 2
    finally:
        event.unregister("numba:compile", listener)


# ---------------------------------------------------------------- rebind


def _one(x):
    return x + 1.0


def _two(x):
    return x + 2.0


def _untouched(x):
    return 10.0 * x


def _middle(x):
    return _one(x) * 3.0 + _untouched(x)


def _kernel(x):
    return _middle(x) - 1.0


def _rows(start, stop, values, out):
    for i in range(start, stop):
        out[i] = _middle(values[i])


jit.jitable(_one)
jit.jitable(_two)
jit.jitable(_untouched)
jit.dual_use(_middle, inline="llvm")
_KERNEL = jit.njit(_kernel)
_ROWS = jit.row_kernel(0)(_rows)


def test_rebind_replaces_a_helper_two_calls_down_and_keeps_the_rest():
    """The kernel calls _middle, which calls _one: rebinding _one to _two changes the
    kernel's result as the formula says ((x + 2) 3 + 10 x - 1), leaves the original
    kernel as it was, copies only the functions on the way (_untouched is kept), and
    names the copies after the suffix."""
    memo = {}
    rebound = jit.rebind(_KERNEL, {id(_one): _two}, "t", memo)
    assert _KERNEL(1.0) == (1.0 + 1.0) * 3.0 + 10.0 - 1.0
    assert rebound(1.0) == (1.0 + 2.0) * 3.0 + 10.0 - 1.0
    assert rebound.py_func.__qualname__ == "_kernel__t"
    copied = rebound.py_func.__globals__["_middle"]
    assert copied is not _middle and copied.__globals__["_two"] is _two and copied.__globals__["_one"] is _two
    assert copied.__globals__["_untouched"] is _untouched
    assert jit.rebind(_KERNEL, {id(_one): _two}, "t", memo) is rebound  # the memo shares copies
    assert jit.rebind(_KERNEL, {id(_untouched) + 1: _two}, "u") is _KERNEL  # nothing reached: the original


def test_rebind_runs_a_row_kernel_with_its_rebound_kernel():
    values = np.arange(5.0)
    rebound = jit.rebind(_ROWS, {id(_one): _two}, "t")
    out, expected = np.empty(5), (values + 2.0) * 3.0 + 10.0 * values
    rebound(values, out)
    np.testing.assert_array_equal(out, expected)
    _ROWS(values, out)
    np.testing.assert_array_equal(out, (values + 1.0) * 3.0 + 10.0 * values)
