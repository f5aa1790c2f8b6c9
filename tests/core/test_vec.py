"""Orthonormal basis (Duff et al. 2017): frame properties, and the compiled scalar path
equal to the NumPy path."""

import numba
import numpy as np

from pbrkit.core.vec import orthonormal_basis, orthonormal_basis_xyz


def _normals():
    rng = np.random.default_rng(5)
    n = rng.normal(size=(500, 3))
    n = np.concatenate([n, [[0, 0, 1], [0, 0, -1], [1, 0, 0], [0, 1, 0], [1e-9, 0, -1], [0, 1e-9, 1]]])
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def test_basis_is_orthonormal_and_right_handed():
    n = _normals()
    t, b = orthonormal_basis(n)
    for u in (t, b):
        np.testing.assert_allclose(np.linalg.norm(u, axis=-1), 1.0, atol=1e-12)
        np.testing.assert_allclose(np.sum(u * n, axis=-1), 0.0, atol=1e-12)
    np.testing.assert_allclose(np.sum(t * b, axis=-1), 0.0, atol=1e-12)
    np.testing.assert_allclose(np.cross(t, b), n, atol=1e-12)
    t1, b1 = orthonormal_basis(n[0])
    assert t1.shape == (3,) and np.array_equal(t1, t[0]) and np.array_equal(b1, b[0])


def test_compiled_term_equals_numpy_wrapper():
    n = _normals()

    @numba.njit
    def frames(n, out):
        for i in range(n.shape[0]):
            (tx, ty, tz), (bx, by, bz) = orthonormal_basis_xyz(n[i, 0], n[i, 1], n[i, 2])
            out[i, 0, 0], out[i, 0, 1], out[i, 0, 2] = tx, ty, tz
            out[i, 1, 0], out[i, 1, 1], out[i, 1, 2] = bx, by, bz

    out = np.empty((n.shape[0], 2, 3))
    frames(n, out)
    t, b = orthonormal_basis(n)
    np.testing.assert_array_equal(out[:, 0], t)
    np.testing.assert_array_equal(out[:, 1], b)
