"""The small dense solves of :mod:`mechdyn.kernels.linalg` against NumPy's LAPACK solve."""

from __future__ import annotations

import numpy as np
import pytest

from mechdyn.kernels.linalg import lu_factor, lu_factor_solve, lu_solve, lu_solve_transposed


def _matrix(rng, n, sparse):
    a = rng.standard_normal((n, n))
    if sparse:  # zeros as in a constraint Jacobian, kept regular by the diagonal
        a[rng.random((n, n)) < 0.5] = 0.0
        a += np.diag(3.0 + rng.standard_normal(n))
    return a


@pytest.mark.parametrize("n", [1, 2, 3, 9, 12, 20])
@pytest.mark.parametrize("sparse", [False, True])
def test_solves_match_lapack_and_fused_equals_separate(n, sparse):
    rng = np.random.default_rng(n + 100 * sparse)
    for _ in range(20):
        a = _matrix(rng, n, sparse)
        b = rng.standard_normal(n)
        lu, piv = a.copy(), np.empty(n, np.int64)
        rc = lu_factor(lu, piv, n)
        x, z = b.copy(), b.copy()
        lu_solve(lu, piv, x, n)
        lu_solve_transposed(lu, piv, z, n)
        lu2, piv2, y = a.copy(), np.empty(n, np.int64), b.copy()
        assert lu_factor_solve(lu2, piv2, y, n) == rc > 0.0
        np.testing.assert_array_equal(lu2, lu)
        np.testing.assert_array_equal(piv2, piv)
        np.testing.assert_array_equal(y, x)
        tol = 1e-14 * np.linalg.cond(a)
        np.testing.assert_allclose(x, np.linalg.solve(a, b), rtol=0, atol=tol * np.abs(x).max())
        np.testing.assert_allclose(z, np.linalg.solve(a.T, b), rtol=0,
                                   atol=tol * np.abs(z).max())


def test_singular_matrix_gives_zero_pivot_ratio():
    a = np.array([[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 1.0, 1.0]])
    a[1] = 2.0 * a[0]  # exactly dependent rows
    piv = np.empty(3, np.int64)
    assert lu_factor(a.copy(), piv, 3) == 0.0
    assert lu_factor_solve(a.copy(), piv, np.ones(3), 3) == 0.0
    assert lu_factor(np.zeros((3, 3)), piv, 3) == 0.0
