"""Compiled drivers of the row evaluators and LU solves for the kinematic sweep.

The position problem of :mod:`mechdyn.kinematics.sweep` stacks the constraint
rows and the coordinate rows of a model into one :class:`~mechdyn.model.rows.Rows`
(``n_rows`` constraint rows, then ``n_q`` coordinate rows) and solves
F(x) = [Phi(x); g(x) - q] = 0.  These helpers evaluate F, its Jacobian and the
acceleration right-hand side -quad with the compiled evaluators of
:mod:`mechdyn.kernels.rows_numba` over a batch of poses (one pose is a batch of
one), and factor and solve with the Jacobians, in one call each: NumPy's per-call
overhead and temporaries would dominate.  They contain no formulas of their own.
Use them only when ``rows_numba.NUMBA`` is True: without numba they run as
(slow) plain Python.
"""

from __future__ import annotations

import numpy as np

from .rows_numba import njit, rows_jacobian, rows_quad, rows_values

__all__ = ["system_batch", "gamma_batch", "lu_batch", "lu_solve_batch"]


@njit
def system_batch(x, q, nb, ints, flts, n_rows, F, J):
    """F = [Phi; g - q] and J = [Phi_x; g_x] at every pose of a batch.

    Parameters
    ----------
    x : ndarray, shape (N, n_x)
        Poses (m, rad).
    q : ndarray, shape (N, n_q)
        Coordinates (rad or m); ``n_eq = n_rows + n_q``.
    nb : int
        Number of moving bodies.
    ints, flts : ndarray
        The packed rows (:meth:`mechdyn.model.rows.Rows.packed`), constraints first.
    n_rows : int
        Number of constraint rows before the coordinate rows.
    F, J : ndarray, shapes (N, n_eq) and (N, n_eq, n_x)
        Outputs, written in place (J zeroed by the caller).
    """
    for i in range(x.shape[0]):
        rows_values(x[i], nb, ints, flts, F[i], 0)
        for k in range(q.shape[1]):
            F[i, n_rows + k] -= q[i, k]
        rows_jacobian(x[i], nb, ints, flts, J[i], 0)


@njit
def gamma_batch(x, xdot, nb, ints, flts, out):
    """[gamma; gamma_g] = -quad at every pose of a batch: x (N, n_x) in m and rad, xdot
    (N, n_x) in m/s and rad/s, into out (N, n_eq) in m/s^2 and rad/s^2."""
    for i in range(x.shape[0]):
        rows_quad(x[i], xdot[i], nb, ints, flts, out[i], 0)
        for k in range(out.shape[1]):
            out[i, k] = -out[i, k]


@njit
def lu_batch(A, piv, sign):
    """LU factors with partial pivoting of every matrix of a batch, in place (LAPACK's
    ``getrf`` layout: P A = L U, L unit lower).

    Parameters
    ----------
    A : ndarray, shape (N, n, n)
        The matrices, overwritten by their factors; an exactly zero pivot is stored as
        NaN (the solves then return NaN instead of raising).
    piv : ndarray of int, shape (N, n)
        Output: the row swapped with row c at step c.
    sign : ndarray, shape (N,)
        Output: the sign of each determinant (0 for an exactly singular matrix).
    """
    n = A.shape[1]
    for b in range(A.shape[0]):
        M = A[b]
        s = 1.0
        for c in range(n):
            p = c
            for r in range(c + 1, n):
                if abs(M[r, c]) > abs(M[p, c]):
                    p = r
            piv[b, c] = p
            if p != c:
                s = -s
                for j in range(n):
                    M[c, j], M[p, j] = M[p, j], M[c, j]
            d = M[c, c]
            if d == 0.0:
                s = 0.0
                d = M[c, c] = np.nan
            elif d < 0.0:
                s = -s
            for r in range(c + 1, n):
                if M[r, c] != 0.0:  # the Jacobians are sparse
                    f = M[r, c] = M[r, c] / d
                    for j in range(c + 1, n):
                        M[r, j] -= f * M[c, j]
        sign[b] = s


@njit
def lu_solve_batch(LU, piv, y):
    """Solve with the factors of :func:`lu_batch`, in place: y (N, n, k) holds the
    right-hand sides on entry and the solutions on return."""
    n, k = y.shape[1], y.shape[2]
    for b in range(y.shape[0]):
        M, Y = LU[b], y[b]
        for c in range(n):
            p = piv[b, c]
            if p != c:
                for j in range(k):
                    Y[c, j], Y[p, j] = Y[p, j], Y[c, j]
        for c in range(n):
            for r in range(c + 1, n):
                if M[r, c] != 0.0:
                    for j in range(k):
                        Y[r, j] -= M[r, c] * Y[c, j]
        for c in range(n - 1, -1, -1):
            d = M[c, c]
            for j in range(k):
                Y[c, j] /= d
            for r in range(c):
                if M[r, c] != 0.0:
                    for j in range(k):
                        Y[r, j] -= M[r, c] * Y[c, j]
