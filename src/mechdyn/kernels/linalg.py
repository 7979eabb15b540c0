"""Small dense linear algebra for the compiled kernels (LU with partial pivoting, Cholesky).

Written as loops over small arrays: for the 3..30-unknown systems of a planar
mechanism these beat a LAPACK call through NumPy by the call overhead.
"""

from __future__ import annotations

import numpy as np

from .rows_numba import njit

__all__ = ["lu_factor", "lu_solve", "lu_solve_transposed", "lu_factor_packed",
           "lu_solve_packed", "lu_solve_transposed_packed", "cholesky_solve"]


@njit
def lu_factor_packed(fac, off, s, piv, a0):
    """LU with partial pivoting, in place, of the s x s matrix kept row by row at
    ``fac[off:]`` (its pivots in ``piv[a0:a0 + s]``); returns the smallest |u_kk| (0 if
    singular) and the largest.  By index into one array, not through views: the
    diagonal blocks of :mod:`mechdyn.kernels.block_lu` are small and many."""
    umin = np.inf
    umax = 0.0
    for k in range(s):
        p = k
        best = abs(fac[off + k * s + k])
        for r in range(k + 1, s):
            v = abs(fac[off + r * s + k])
            if v > best:
                best = v
                p = r
        piv[a0 + k] = p
        if p != k:
            for c in range(s):
                tmp = fac[off + k * s + c]
                fac[off + k * s + c] = fac[off + p * s + c]
                fac[off + p * s + c] = tmp
        d = fac[off + k * s + k]
        umin = min(umin, best)
        umax = max(umax, best)
        if d == 0.0:
            return 0.0, umax
        inv = 1.0 / d
        for r in range(k + 1, s):
            f = fac[off + r * s + k] * inv
            fac[off + r * s + k] = f
            if f != 0.0:
                for c in range(k + 1, s):
                    fac[off + r * s + c] -= f * fac[off + k * s + c]
    return umin, umax


@njit
def lu_solve_packed(fac, off, s, piv, a0, w):
    """Solve with the block's factors of :func:`lu_factor_packed` (w[:s] overwritten)."""
    for k in range(s):
        p = piv[a0 + k]
        if p != k:
            tmp = w[k]
            w[k] = w[p]
            w[p] = tmp
    for r in range(s):
        acc = w[r]
        for c in range(r):
            acc -= fac[off + r * s + c] * w[c]
        w[r] = acc
    for r in range(s - 1, -1, -1):
        acc = w[r]
        for c in range(r + 1, s):
            acc -= fac[off + r * s + c] * w[c]
        w[r] = acc / fac[off + r * s + r]


@njit
def lu_solve_transposed_packed(fac, off, s, piv, a0, w):
    """Solve the transposed block with the factors of :func:`lu_factor_packed` (w[:s] overwritten):
    P B = L U, so B^T = U^T L^T P."""
    for r in range(s):
        acc = w[r]
        for c in range(r):
            acc -= fac[off + c * s + r] * w[c]
        w[r] = acc / fac[off + r * s + r]
    for r in range(s - 1, -1, -1):
        acc = w[r]
        for c in range(r + 1, s):
            acc -= fac[off + c * s + r] * w[c]
        w[r] = acc
    for j in range(s):
        k = s - 1 - j
        p = piv[a0 + k]
        if p != k:
            tmp = w[k]
            w[k] = w[p]
            w[p] = tmp


@njit
def _flat(a, n):
    """The n x n matrix ``a`` (C order) as one array, for the packed routines."""
    if a.shape[0] != n or a.shape[1] != n:
        raise ValueError("linalg: an n x n matrix is expected")
    return a.reshape(n * n)


@njit
def lu_factor(a, piv, n):
    """In-place LU with partial pivoting of ``a`` (n, n), pivots in ``piv``; returns
    min|u_ii| / max|u_ii| (0 if singular)."""
    umin, umax = lu_factor_packed(_flat(a, n), 0, n, piv, 0)
    return umin / umax if umax > 0.0 else 0.0


@njit
def lu_solve(a, piv, b, n):
    """Solve with the factors of ``lu_factor`` (b overwritten)."""
    lu_solve_packed(_flat(a, n), 0, n, piv, 0, b)


@njit
def lu_solve_transposed(a, piv, b, n):
    """Solve A^T z = b with the factors of ``lu_factor`` of A (b overwritten by z)."""
    lu_solve_transposed_packed(_flat(a, n), 0, n, piv, 0, b)


@njit
def _forward(L, b, n):
    """Solve L y = b for lower-triangular L, b overwritten."""
    for r in range(n):
        s = b[r]
        for c in range(r):
            s -= L[r, c] * b[c]
        b[r] = s / L[r, r]


@njit
def _backward(U, b, n):
    """Solve U y = b for upper-triangular U, b overwritten."""
    for r in range(n - 1, -1, -1):
        s = b[r]
        for c in range(r + 1, n):
            s -= U[r, c] * b[c]
        b[r] = s / U[r, r]


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
    _forward(A, rhs, n)
    _backward(A.T, rhs, n)
    return True
