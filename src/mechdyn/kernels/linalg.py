"""Small dense linear algebra for the compiled kernels (LU with partial pivoting, Cholesky).

Written as loops over small arrays: for the 3..30-unknown systems of a planar
mechanism these beat a LAPACK call through NumPy by the call overhead.
"""

from __future__ import annotations

import numpy as np

from .rows_numba import njit

__all__ = ["lu_factor", "lu_solve", "lu_solve_transposed", "cholesky_solve"]


@njit
def lu_factor(a, piv, n):
    """In-place LU with partial pivoting; returns min|u_ii| / max|u_ii| (0 if singular)."""
    umin = np.inf
    umax = 0.0
    for k in range(n):
        p = k
        best = abs(a[k, k])
        for r in range(k + 1, n):
            v = abs(a[r, k])
            if v > best:
                best = v
                p = r
        piv[k] = p
        if p != k:
            for c in range(n):
                tmp = a[k, c]
                a[k, c] = a[p, c]
                a[p, c] = tmp
        d = a[k, k]
        if best < umin:
            umin = best
        if best > umax:
            umax = best
        if d == 0.0:
            return 0.0
        inv = 1.0 / d
        for r in range(k + 1, n):
            f = a[r, k] * inv
            a[r, k] = f
            if f != 0.0:
                for c in range(k + 1, n):
                    a[r, c] -= f * a[k, c]
    if umax == 0.0:
        return 0.0
    return umin / umax


@njit
def _forward(L, b, n, unit):
    """Solve L y = b for lower-triangular L (unit diagonal if ``unit``), b overwritten."""
    for r in range(n):
        s = b[r]
        for c in range(r):
            s -= L[r, c] * b[c]
        b[r] = s if unit else s / L[r, r]


@njit
def _backward(U, b, n, unit):
    """Solve U y = b for upper-triangular U (unit diagonal if ``unit``), b overwritten."""
    for r in range(n - 1, -1, -1):
        s = b[r]
        for c in range(r + 1, n):
            s -= U[r, c] * b[c]
        b[r] = s if unit else s / U[r, r]


@njit
def _swap(b, piv, n, reverse):
    """Apply the row swaps of ``lu_factor`` to b (undo them with ``reverse``)."""
    for j in range(n):
        k = n - 1 - j if reverse else j
        p = piv[k]
        if p != k:
            tmp = b[k]
            b[k] = b[p]
            b[p] = tmp


@njit
def lu_solve(a, piv, b, n):
    """Solve with the factors of ``lu_factor`` (b overwritten)."""
    _swap(b, piv, n, False)
    _forward(a, b, n, True)
    _backward(a, b, n, False)


@njit
def cholesky_solve(A, rhs, n):
    """Solve A y = rhs for symmetric positive definite A (upper triangle read, A and rhs
    overwritten: the factor in the lower triangle, y in rhs).  Returns False if A is not
    positive definite."""
    for i in range(n):
        for j in range(i):
            A[i, j] = A[j, i]
    for j in range(n):
        s = A[j, j]
        for k in range(j):
            s -= A[j, k] * A[j, k]
        if not s > 0.0:
            return False
        d = np.sqrt(s)
        A[j, j] = d
        for i in range(j + 1, n):
            s2 = A[i, j]
            for k in range(j):
                s2 -= A[i, k] * A[j, k]
            A[i, j] = s2 / d
    _forward(A, rhs, n, False)
    _backward(A.T, rhs, n, False)
    return True


@njit
def lu_solve_transposed(a, piv, b, n):
    """Solve A^T z = b with the factors of ``lu_factor`` of A (b overwritten by z)."""
    # P A = L U, so A^T = U^T L^T P: solve U^T y = b, L^T u = y, then z = P^T u
    _forward(a.T, b, n, False)
    _backward(a.T, b, n, True)
    _swap(b, piv, n, True)
