"""The result cache (pbrkit.core.cache.memoised_array) and the memoised lookup tables:
same bytes from the cache as from the integration, a corrupt or foreign cache entry
is recomputed, a cache that cannot be written costs nothing but time, and a
second ``pbrkit lut`` with the same options never imports Numba."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from pbrkit.albedo.lut import DEFAULT_NODES, TableSpec, lookup_table
from pbrkit.core import cache


@pytest.fixture
def private_cache(tmp_path, monkeypatch):
    """A fresh cache root (the lru-cached directory is reset around the test)."""
    monkeypatch.setenv("PBRKIT_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("PBRKIT_NO_RESULT_CACHE", raising=False)
    cache.cache_directory.cache_clear()
    yield tmp_path / "cache"
    cache.cache_directory.cache_clear()


def _entries(root):
    return sorted(root.rglob("results/*.npy"))


def test_memoised_array_computes_once_and_returns_the_same_bytes(private_cache):
    calls = []

    def compute():
        calls.append(1)
        return np.arange(12, dtype=np.float32).reshape(3, 4) / 7

    a = cache.memoised_array("demo", {"n": 3}, compute)
    b = cache.memoised_array("demo", {"n": 3}, compute)
    assert len(calls) == 1 and a.tobytes() == b.tobytes() and b.dtype == np.float32
    cache.memoised_array("demo", {"n": 4}, compute)  # other options: another entry
    assert len(calls) == 2 and len(_entries(private_cache)) == 2
    cache.memoised_array("demo", {"n": 3}, compute, enabled=False)
    assert len(calls) == 3
    # the entry lives under the directory keyed on pbrkit's sources
    assert all(cache.source_hash()[:16] in str(p) for p in _entries(private_cache))
    assert not list(private_cache.rglob("*.tmp"))


@pytest.mark.parametrize("damage", ["truncated", "garbage", "wrong shape", "nan"])
def test_a_damaged_entry_is_computed_again_and_replaced(private_cache, damage):
    expected = np.linspace(0.0, 1.0, 8, dtype=np.float32).reshape(2, 4)

    def check(x):
        return x.shape == (2, 4) and bool(np.isfinite(x).all())

    cache.memoised_array("t", {}, lambda: expected, check)
    (entry,) = _entries(private_cache)
    if damage == "truncated":
        entry.write_bytes(entry.read_bytes()[:40])
    elif damage == "garbage":
        entry.write_bytes(b"\x00not an npy file" * 10)
    elif damage == "wrong shape":
        np.save(entry, np.zeros((3, 3), dtype=np.float32))
    else:
        np.save(entry, np.full((2, 4), np.nan, dtype=np.float32))
    again = cache.memoised_array("t", {}, lambda: expected, check)
    assert again.tobytes() == expected.tobytes()
    assert np.load(entry).tobytes() == expected.tobytes()


def test_an_unwritable_cache_only_costs_the_computation(private_cache):
    private_cache.mkdir(parents=True)
    blocker = private_cache / cache.Path(cache.cache_directory()).name
    blocker.write_text("a file where the cache folder should be")
    out = cache.memoised_array("t", {}, lambda: np.ones(3))
    assert out.tolist() == [1.0, 1.0, 1.0] and blocker.is_file()


def test_memoised_table_is_the_integrated_table(private_cache):
    from pbrkit.albedo.tables import integrate_lookup_table

    for kind, cloth in (("dfg", False), ("splitsum", False), ("dfg", True)):
        first, spec = lookup_table(kind, 16, cloth=cloth)
        cached, spec2 = lookup_table(kind, 16, cloth=cloth)
        fresh, spec3 = integrate_lookup_table(kind, 16, cloth=cloth)
        assert first.tobytes() == cached.tobytes() == fresh.tobytes()
        assert spec == spec2 == spec3 == TableSpec(kind, 16, spec.visibility, cloth, DEFAULT_NODES)
    assert len(_entries(private_cache)) == 3
    with pytest.raises(ValueError, match="unknown table kind"):
        lookup_table("nope", 16)
    with pytest.raises(ValueError):
        lookup_table("dfg", 16, visibility="nope")
    assert len(_entries(private_cache)) == 3  # nothing cached for bad options


def test_second_lut_command_reads_the_cache_without_numba(private_cache, tmp_path):
    """The first ``pbrkit lut`` integrates (Numba); the second, same options, reads the
    memoised table: same bytes, and Numba is never imported (the start-up goal)."""
    env = dict(os.environ, PBRKIT_CACHE_DIR=str(private_cache))
    probe = ("import sys, runpy; sys.argv = ['pbrkit'] + sys.argv[1:]; "
             "from pbrkit.cli import app\n"
             "try:\n    app()\nexcept SystemExit as e:\n    code = e.code\n"
             "print('NUMBA' if 'numba' in sys.modules else 'NO-NUMBA'); sys.exit(code)")
    outs = []
    for name in ("a.npy", "b.npy"):
        out = tmp_path / name
        run = subprocess.run([sys.executable, "-c", probe, "lut", "--kind", "dfg", "--size", "32", "-o", str(out),
                              "-q"], env=env, capture_output=True, text=True, timeout=600)
        assert run.returncode == 0, run.stderr
        outs.append((run.stdout.strip().splitlines()[-1], out.read_bytes()))
    assert outs[0][0] == "NUMBA" and outs[1][0] == "NO-NUMBA"
    assert outs[0][1] == outs[1][1]
    # --no-cache integrates again, same bytes
    out = tmp_path / "c.npy"
    run = subprocess.run([sys.executable, "-c", probe, "lut", "--kind", "dfg", "--size", "32", "-o", str(out), "-q",
                          "--no-cache"], env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0 and run.stdout.strip().endswith("NUMBA") and not run.stdout.strip().endswith("NO-NUMBA")
    assert out.read_bytes() == outs[0][1]
