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
