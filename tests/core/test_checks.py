"""pbrkit.core.checks (the shared input validators) and
pbrkit.core.atomic.atomic_directory (outputs committed together)."""

import os

import numpy as np
import pytest

from pbrkit.core import checks
from pbrkit.core.atomic import atomic_directory, check_output_directory, current_umask

# ------------------------------------------------------------------ integer


@pytest.mark.parametrize("value", [2, 7, 9, np.int64(2), np.uint8(9), np.int32(5)])
def test_integer_accepts_the_range_and_its_bounds(value):
    got = checks.integer(value, "count", 2, 9)
    assert got == int(value) and type(got) is int


@pytest.mark.parametrize("value", [True, False, np.bool_(True), 3.0, 2.5, "3", None, np.float64(3.0), np.nan,
                                   np.inf, 1, 10, -1, np.int64(10)])
def test_integer_rejects_bools_non_integers_and_out_of_range(value):
    with pytest.raises(ValueError, match=r"^count must be an integer in \[2, 9\]; got "):
        checks.integer(value, "count", 2, 9)


def test_integer_with_one_or_no_bound():
    assert checks.integer(0, "n", 0) == 0 and checks.integer(2**70, "n", 0) == 2**70
    with pytest.raises(ValueError, match=r"^n must be an integer >= 1; got 0$"):
        checks.integer(0, "n", 1)
    assert checks.integer(-5, "k", hi=3) == -5
    with pytest.raises(ValueError, match=r"^k must be an integer <= 3; got 4$"):
        checks.integer(4, "k", hi=3)
    assert checks.integer(-(2**80), "k") == -(2**80)
    with pytest.raises(ValueError, match=r"^k must be an integer; got True$"):
        checks.integer(True, "k")


# ------------------------------------------------------------- power of two


@pytest.mark.parametrize("value", [2, 4, 64, 4096, np.int64(1024)])
def test_power_of_two_accepts(value):
    assert checks.power_of_two(value, "size", 2, 4096) == int(value)


@pytest.mark.parametrize("value", [1, 3, 48, 8192, 0, -4, True, 64.0, np.nan, "64"])
def test_power_of_two_rejects(value):
    with pytest.raises(ValueError, match=r"^size must be a power of two in \[2, 4096\]; got "):
        checks.power_of_two(value, "size", 2, 4096)


def test_power_of_two_lower_bound_one():
    assert checks.power_of_two(1, "min size", 1, 8) == 1
    with pytest.raises(ValueError, match="min size"):
        checks.power_of_two(0, "min size", 0, 8)


# ------------------------------------------------------------------ vectors


def test_vector_accepts_finite_numbers():
    a = checks.vector((1, -2, 3.5), "light position")
    assert a.dtype == np.float64 and a.tolist() == [1.0, -2.0, 3.5]
    q = checks.vector([0, 0, 0, 1], "rotation", 4)
    assert q.shape == (4,)
    np.testing.assert_array_equal(checks.vector((0, -2, 0), "d", unit=True), [0.0, -1.0, 0.0])


@pytest.mark.parametrize("value", [(0, np.nan, 0), (np.inf, 0, 0), (1, 2), (1, 2, 3, 4), [[1, 2, 3]], "abc", None,
                                   (1, "x", 3), ({}, 1, 2)])
def test_vector_rejects(value):
    with pytest.raises(ValueError, match=r"^light color must be 3 finite numbers; got "):
        checks.vector(value, "light color")


def test_vector_rejects_the_zero_vector_only_when_unit():
    assert checks.vector((0, 0, 0), "p").tolist() == [0.0, 0.0, 0.0]
    with pytest.raises(ValueError, match=r"^light direction must not be the zero vector$"):
        checks.vector((0, 0, 0), "light direction", unit=True)
    with pytest.raises(ValueError, match="light direction must be 3 finite numbers"):
        checks.vector((np.nan, 0, 1), "light direction", unit=True)


# --------------------------------------------------------------- directions


def test_directions_accept_any_non_zero_finite_length():
    d = [[1, 0, 0], [0, -3, 0], [1e-200, 0, 0], [1e200, 1e200, 0]]
    got = checks.directions(d)
    assert got.dtype == np.float64 and got.shape == (4, 3)
    assert checks.directions([0, 0, 2]).shape == (3,)
    assert checks.directions(np.zeros((0, 3))).shape == (0, 3)


@pytest.mark.parametrize("fn", [checks.directions, checks.direction_lengths])
def test_directions_reject_zero_and_non_finite_vectors(fn):
    bad = [[1, 0, 0], [0, 0, 0], [np.nan, 1, 0], [0, np.inf, 0]]
    with pytest.raises(ValueError, match=r"^wi must be finite and non-zero; got 3 zero or non-finite vector"):
        fn(bad, "wi")
    for shape in [(3, 2), (4,), ()]:
        with pytest.raises(ValueError, match=r"^wi must have shape \(\.\.\., 3\); got "):
            fn(np.ones(shape), "wi")


def test_direction_lengths_returns_the_norm_and_rejects_unrepresentable_lengths():
    d, length = checks.direction_lengths([[3, 4, 0], [0, 0, -2]])
    assert d.tolist() == [[3, 4, 0], [0, 0, -2]]
    np.testing.assert_array_equal(length, np.linalg.norm(d, axis=-1))
    for extreme in (1e-200, 1e200):  # |d|^2 underflows to 0 / overflows to inf: cannot be normalised
        with pytest.raises(ValueError, match="1 zero or non-finite"):
            checks.direction_lengths([extreme, 0, 0])
    with pytest.raises(ValueError, match=r"^directions must"):
        checks.direction_lengths([0, 0, 0])


# --------------------------------------------------------- atomic directory


def test_atomic_directory_commits_on_success(tmp_path):
    out = tmp_path / "a" / "b" / "out"
    with atomic_directory(out) as tmp:
        assert tmp.parent == out.parent and tmp.name.endswith(".partial") and not out.exists()
        (tmp / "x.txt").write_text("x")
        (tmp / "sub").mkdir()
    assert (out / "x.txt").read_text() == "x" and (out / "sub").is_dir()
    assert sorted(p.name for p in out.parent.iterdir()) == ["out"]
    assert os.stat(out).st_mode & 0o777 == 0o777 & ~current_umask()


def test_atomic_directory_failure_leaves_nothing_not_even_created_parents(tmp_path):
    out = tmp_path / "deep" / "er" / "out"
    with pytest.raises(RuntimeError, match="boom"), atomic_directory(out) as tmp:
        (tmp / "half.txt").write_text("half")
        raise RuntimeError("boom")
    assert list(tmp_path.iterdir()) == []


def test_atomic_directory_failure_keeps_existing_parents_and_destination(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("old")
    with pytest.raises(KeyboardInterrupt), atomic_directory(out, force=True) as tmp:
        (tmp / "new.txt").write_text("new")
        raise KeyboardInterrupt
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert [p.name for p in out.iterdir()] == ["keep.txt"]


def test_atomic_directory_refuses_non_empty_unless_force(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("old")
    with pytest.raises(ValueError, match="not empty"), atomic_directory(out):
        pytest.fail("the body must not run")
    assert [p.name for p in out.iterdir()] == ["keep.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    with atomic_directory(out, force=True) as tmp:
        (tmp / "new.txt").write_text("new")
    assert [p.name for p in out.iterdir()] == ["new.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_atomic_directory_replaces_an_empty_directory_and_rejects_a_file(tmp_path):
    (tmp_path / "empty").mkdir()
    with atomic_directory(tmp_path / "empty") as tmp:
        (tmp / "a").write_text("a")
    assert [p.name for p in (tmp_path / "empty").iterdir()] == ["a"]
    (tmp_path / "file").write_text("f")
    with pytest.raises(ValueError, match="exists and is not a directory"):
        check_output_directory(tmp_path / "file", force=True)
    with pytest.raises(ValueError, match="exists and is not a directory"), atomic_directory(tmp_path / "file", True):
        pass
