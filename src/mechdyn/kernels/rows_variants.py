"""Compiled drivers over a batch of VARIANTS of one topology: the position continuation,
the rates and the kinetostatic solve, with a variant axis through the row data.

The kinetostatic equations ``[-Phi_x^T, g_d,x^T] z = I - F`` of
:func:`mechdyn.dynamics.reactions._inverse` have the transposed Jacobian of the
position problem as their matrix: one factorization per position serves the rates,
the accelerations and the multipliers.

Variants of one model differ only in numbers: their rows share the packed integers
``ints`` (n, 5) of :meth:`mechdyn.model.rows.Rows.packed` and each has its own floats,
``flts`` (V, n, 9) (local points, directions, factors and offsets).  The position
problem is F(x) = [Phi(x); g_d(x) - q_d] = 0 (``n_rows`` constraint rows, then the
driven coordinates' rows), square; its Jacobian J is factored by
:func:`mechdyn.kernels.linalg.lu_factor`.  The rows are evaluated by the compiled
evaluators of :mod:`mechdyn.kernels.rows_numba` (no formula of their own here).
"""

from __future__ import annotations

import numpy as np

from .linalg import lu_factor, lu_solve, lu_solve_transposed
from .rows_numba import njit, rows_jacobian, rows_quad, rows_values

__all__ = ["path_variants", "motion_variants", "inverse_variants"]


@njit
def _system(x, q, nb, ints, flts, n_rows, F, J):
    """F = [Phi; g_d - q] and J at one pose of one variant (in place)."""
    rows_values(x, nb, ints, flts, F, 0)
    for k in range(q.shape[0]):
        F[n_rows + k] -= q[k]
    J[:, :] = 0.0
    rows_jacobian(x, nb, ints, flts, J, 0)


@njit
def _det_sign(lu, piv, n):
    """Sign of the determinant from the factors of ``lu_factor``."""
    s = 1.0
    for k in range(n):
        if piv[k] != k:
            s = -s
        if lu[k, k] < 0.0:
            s = -s
        elif lu[k, k] == 0.0:
            return 0.0
    return s


@njit
def path_variants(X0, Q, nb, ints, flts, n_rows, tol, max_iter, min_rc, X, ok, fail):
    """Continuation of every variant along its own path of driven coordinates.

    Parameters
    ----------
    X0 : ndarray, shape (V, n_x)
        Assembled start poses (m, rad), at or near ``Q[:, 0]``.
    Q : ndarray, shape (V, M, n_d)
        The driven coordinates at the M steps of each variant's path.
    nb : int
    ints : ndarray of int, shape (n, 5)
        Packed row integers, shared (``n = n_rows + n_d = n_x``).
    flts : ndarray, shape (V, n, 9)
        Packed row floats of each variant.
    n_rows : int
    tol : ndarray, shape (V,)
        Residual tolerance of each variant's Newton solve (m or rad).
    max_iter : int
        Newton iterations per step.
    min_rc : float
        Smallest pivot ratio min|u_ii| / max|u_ii| of J accepted (below: a dead or
        bifurcation position, left to the single-model continuation).
    X : ndarray, shape (V, M, n_x)
        Output: the poses.
    ok : ndarray of bool, shape (V,)
        In: variants to solve; out: False where a step failed.
    fail : ndarray of int, shape (V,)
        Output: the step where a variant failed (-1: none).

    Each step starts from the previous pose plus the tangent times the change of the
    coordinates and the curvature along q_0 from the last two tangents; the branch is
    kept by the sign of det J, which must not change along the path.
    """
    V, M, nd = Q.shape
    n = X0.shape[1]
    F = np.empty(n)
    J = np.empty((n, n))
    lu = np.empty((n, n))
    piv = np.empty(n, np.int64)
    b = np.empty(n)
    T = np.empty((n, nd))
    Tp = np.empty(n)
    for v in range(V):
        fail[v] = -1
        if not ok[v]:
            continue
        x = X0[v].copy()
        sign0 = 0.0
        hp = 0.0
        for m in range(M):
            q = Q[v, m]
            if m > 0:
                h = q[0] - Q[v, m - 1, 0]
                curved = m > 1 and hp != 0.0
                for i in range(n):
                    for c in range(nd):
                        x[i] += T[i, c] * (q[c] - Q[v, m - 1, c])
                    if curved:  # the second derivative along q_0 from the last two tangents
                        x[i] += 0.5 * (T[i, 0] - Tp[i]) / hp * h * h
                hp = h
            # Newton; the factors of the last Jacobian (at the solution, or one step before
            # it: within the tolerance's square root) give the branch sign, the pivot ratio
            # and the tangent dx/dq_d for the next step's start
            done = False
            rc = 0.0
            for it in range(max_iter + 1):
                if it == 0:
                    _system(x, q, nb, ints, flts[v], n_rows, F, J)
                else:
                    rows_values(x, nb, ints, flts[v], F, 0)
                    for c in range(nd):
                        F[n_rows + c] -= q[c]
                err = 0.0
                for i in range(n):
                    err = max(err, abs(F[i]))
                if not np.isfinite(err):
                    break
                if err <= tol[v] and it > 0:
                    done = True
                    break
                if it == max_iter:
                    break
                if it > 0:
                    J[:, :] = 0.0
                    rows_jacobian(x, nb, ints, flts[v], J, 0)
                lu[:, :] = J
                rc = lu_factor(lu, piv, n)
                if rc == 0.0:
                    break
                b[:] = F
                lu_solve(lu, piv, b, n)
                for i in range(n):
                    x[i] -= b[i]
            if not done:
                ok[v] = False
                fail[v] = m
                break
            s = _det_sign(lu, piv, n)
            if m == 0:
                sign0 = s
            if rc < min_rc or s != sign0:
                ok[v] = False
                fail[v] = m
                break
            for i in range(n):
                Tp[i] = T[i, 0]
            for c in range(nd):
                b[:] = 0.0
                b[n_rows + c] = 1.0
                lu_solve(lu, piv, b, n)
                for i in range(n):
                    T[i, c] = b[i]
            for i in range(n):
                X[v, m, i] = x[i]


@njit
def motion_variants(X, qdot, qddot, nb, ints, flts, n_rows, Xdot, Xddot, J, LU, piv, rc):
    """Rates and accelerations at the poses of every variant,
    J xdot = [0; qdot_d] and J xddot = gamma + [0; qddot_d], keeping J = [Phi_x; g_d,x]
    and its factors for :func:`inverse_variants` and the reactions.

    Parameters
    ----------
    X : ndarray, shape (V, N, n_x)
    qdot, qddot : ndarray, shape (N, n_d)
        The driven coordinates' rates (the same for every variant).
    Xdot, Xddot : ndarray, shape (V, N, n_x)
        Outputs (NaN where J is singular).
    J, LU : ndarray, shape (V, N, n, n_x)
        Outputs: the Jacobians and their LU factors (:func:`~mechdyn.kernels.linalg.lu_factor`).
    piv : ndarray of int, shape (V, N, n)
        Output: the pivots.
    rc : ndarray, shape (V, N)
        Output: the pivot ratio min|u_ii| / max|u_ii| (0: singular).
    """
    V, N, n = X.shape
    nd = qdot.shape[1]
    F = np.empty(n)
    b = np.empty(n)
    qz = np.zeros(nd)
    for v in range(V):
        for k in range(N):
            _system(X[v, k], qz, nb, ints, flts[v], n_rows, F, J[v, k])
            A, p = LU[v, k], piv[v, k]
            A[:, :] = J[v, k]
            rc[v, k] = lu_factor(A, p, n)
            if rc[v, k] == 0.0:
                Xdot[v, k, :] = np.nan
                Xddot[v, k, :] = np.nan
                continue
            b[:] = 0.0
            for c in range(nd):
                b[n_rows + c] = qdot[k, c]
            lu_solve(A, p, b, n)
            Xdot[v, k, :] = b
            rows_quad(X[v, k], Xdot[v, k], nb, ints, flts[v], b, 0)
            for i in range(n):
                b[i] = -b[i]
            for c in range(nd):
                b[n_rows + c] += qddot[k, c]
            lu_solve(A, p, b, n)
            Xddot[v, k, :] = b


@njit
def inverse_variants(LU, piv, rhs, n_rows, Z):
    """The kinetostatic solve of every position of every variant,
    [-Phi_x^T, g_d,x^T] z = rhs (z: the multipliers, then the driving torques/forces),
    with the factors of J = [Phi_x; g_d,x] from :func:`motion_variants`: z is J^-T rhs
    with the multipliers' sign turned.

    Parameters
    ----------
    LU, piv : ndarray
        Factors of :func:`motion_variants`, (V, N, n, n) and (V, N, n).
    rhs : ndarray, shape (V, N, n)
        Inertia forces minus applied forces (N, N m).
    Z : ndarray, shape (V, N, n)
        Output.
    """
    V, N, n = rhs.shape
    b = np.empty(n)
    for v in range(V):
        for k in range(N):
            b[:] = rhs[v, k]
            lu_solve_transposed(LU[v, k], piv[v, k], b, n)
            for c in range(n):
                Z[v, k, c] = -b[c] if c < n_rows else b[c]
