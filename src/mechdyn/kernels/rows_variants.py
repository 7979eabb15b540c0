"""Compiled drivers over a batch of VARIANTS of one topology: the position continuation,
the rates and the kinetostatic solve, with a variant axis through the row data.

The kinetostatic equations ``[-Phi_x^T, g_d,x^T] z = I - F`` of
:func:`mechdyn.dynamics.reactions.batched_inverse` have the transposed Jacobian of the
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
from .rows_numba import (
    body_rotations,
    copy_into,
    copy_rows,
    njit,
    njit_inline,
    rows_jacobian_cs,
    rows_quad_cs,
    rows_values_cs,
)

__all__ = ["path_variants", "inverse_variants", "loads_variants", "body_loads_variants",
           "cycle_variants"]


@njit
def _system(x, q, nb, ints, flts, n_rows, cs, F, J):
    """F = [Phi; g_d - q] and J at one pose of one variant (in place; ``cs``: the
    rotations of x, :func:`~mechdyn.kernels.rows_numba.body_rotations`)."""
    rows_values_cs(x, nb, ints, flts, cs, F, 0)
    for k in range(q.shape[0]):
        F[n_rows + k] -= q[k]
    J[:, :] = 0.0
    rows_jacobian_cs(x, nb, ints, flts, cs, J, 0)


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
def _at_solution(x, qdot, qddot, nb, ints, flts, n_rows, cs, J, fresh, lu, piv, T, xd, xdd,
                 b):
    """J at a solved pose x (``cs``: its rotations; J evaluated into J unless ``fresh``:
    J holds it) and its factors; the tangents T = J^-1 [0; I] (n_x, n_d), the rates
    xd = T qdot and the accelerations xdd = J^-1 (gamma + [0; qddot]) (qdot, qddot of
    the driven rows).  Returns the pivot ratio (0: singular, T and the rates not set)."""
    n = x.shape[0]
    if not fresh:
        J[:, :] = 0.0
        rows_jacobian_cs(x, nb, ints, flts, cs, J, 0)
    copy_rows(lu, J)
    rc = lu_factor(lu, piv, n)
    if rc == 0.0:
        return rc
    xd[:] = 0.0
    for c in range(qdot.shape[0]):
        b[:] = 0.0
        b[n_rows + c] = 1.0
        lu_solve(lu, piv, b, n)
        for i in range(n):
            T[i, c] = b[i]
            xd[i] += b[i] * qdot[c]
    rows_quad_cs(x, xd, nb, ints, flts, cs, b, 0)
    for i in range(n):
        b[i] = -b[i]
    for c in range(qdot.shape[0]):
        b[n_rows + c] += qddot[c]
    lu_solve(lu, piv, b, n)
    copy_into(xdd, b)
    return rc


@njit
def path_variants(X0, Q, dQ, ddQ, keep, nb, ints, flts, n_rows, tol, max_iter, short,
                  min_rc, X, Xd, Xdd, J, LU, piv, rc, ok, fail):
    """Continuation of every variant along its own path of driven coordinates, with the
    rates and accelerations at the kept steps.

    Parameters
    ----------
    X0 : ndarray, shape (V, n_x)
        Start poses (m, rad): assembled, or sketches that the first step assembles.
    Q : ndarray, shape (V, M, n_d)
        The driven coordinates at the M steps of each variant's path.
    dQ, ddQ : ndarray, shape (M, n_d)
        Their rates and accelerations (the same for every variant; used at kept steps).
    keep : ndarray of int, shape (M,)
        Where each step is stored (-1: not stored).
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
    short : float
        A first Newton step no longer than ``short * tol`` is checked without evaluating
        the residual (see the code); with tol = 1e-12 L, 1e7 is 1e-5 L, whose cubed
        remainder is far below the tolerance.
    min_rc : float
        Smallest pivot ratio min|u_ii| / max|u_ii| of J accepted (below: a dead or
        bifurcation position, left to the single-model continuation).
    X, Xd, Xdd : ndarray, shape (V, K, n_x)
        Output: poses, rates and accelerations at the K kept steps.
    J, LU : ndarray, shape (V, K, n, n_x)
        Output: J = [Phi_x; g_d,x] at the kept poses and its LU factors
        (:func:`~mechdyn.kernels.linalg.lu_factor`), for :func:`inverse_variants`.
    piv : ndarray of int, shape (V, K, n)
        Output: the pivots.
    rc : ndarray, shape (V, K)
        Output: the pivot ratios.
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
    Jw = np.empty((n, n))
    J1 = np.empty((n, n))
    lu = np.empty((n, n))
    pv = np.empty(n, np.int64)
    b = np.empty(n)
    xd = np.empty(n)
    xdd = np.empty(n)
    T = np.empty((n, nd))
    Tp = np.empty(n)
    cs = np.empty((nb + 1, 2))  # the rotations of x, once per pose
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
                hp = _predict(x, q, Q[v, m - 1], T, Tp, hp, m > 1 and hp != 0.0)
            done, fresh = _newton(x, q, nb, ints, flts[v], n_rows, tol[v], max_iter, short,
                                  cs, F, Jw, J1, lu, pv, b)
            if not done:
                ok[v] = False
                fail[v] = m
                break
            # at the solution: J, its factors, the branch sign, the rates; the tangent
            k = keep[m]
            for i in range(n):
                Tp[i] = T[i, 0]
            r = _at_solution(x, dQ[m], ddQ[m], nb, ints, flts[v], n_rows, cs, Jw, fresh, lu,
                             pv, T, xd, xdd, b)
            s = _det_sign(lu, pv, n)
            if m == 0:
                sign0 = s
            if r < min_rc or s != sign0:
                ok[v] = False
                fail[v] = m
                break
            if k >= 0:
                copy_into(X[v, k, :], x)
                copy_into(Xd[v, k, :], xd)
                copy_into(Xdd[v, k, :], xdd)
                J[v, k] = Jw
                LU[v, k] = lu
                piv[v, k] = pv
                rc[v, k] = r


@njit_inline
def _predict(x, q, q_prev, T, Tp, hp, curved):
    """Move x (in place) from the pose at ``q_prev`` to the predictor at ``q``: the
    tangent T times the change of the driven coordinates, plus, where ``curved``, the
    second derivative along q_0 from T and the previous tangent Tp (``hp``: the previous
    step of q_0).  Returns this step of q_0."""
    n, nd = T.shape
    h = q[0] - q_prev[0]
    for i in range(n):
        for c in range(nd):
            x[i] += T[i, c] * (q[c] - q_prev[c])
        if curved:  # the second derivative along q_0 from the last two tangents
            x[i] += 0.5 * (T[i, 0] - Tp[i]) / hp * h * h
    return h


@njit_inline
def _short_step_error(x, b, nb, ints, flts, cs, Jw, J1):
    """The residual after a short first Newton step b (x already moved), estimated as
    |(J(x1) - J(x0)) b / 2| without evaluating F: J(x1) is evaluated (into J1, then Jw,
    with the rotations ``cs`` of x1) and Jw = J(x0) on entry."""
    n = x.shape[0]
    body_rotations(x, nb, cs)
    J1[:, :] = 0.0
    rows_jacobian_cs(x, nb, ints, flts, cs, J1, 0)
    err = 0.0
    for i in range(n):
        r = 0.0
        for j in range(n):
            r += (J1[i, j] - Jw[i, j]) * b[j]
        err = max(err, abs(0.5 * r))
    copy_rows(Jw, J1)
    return err


@njit_inline
def _newton(x, q, nb, ints, flts, n_rows, tol, max_iter, short, cs, F, Jw, J1, lu, pv, b):
    """Newton's method (at least one step) on F(x) = [Phi(x); g_d(x) - q] = 0 of one
    variant, in place from the predictor x; arguments as for :func:`path_variants`, the
    others work arrays.  Returns (done, fresh): converged, and whether Jw holds J at x
    (with ``cs`` its rotations).

    After a first step dx from x0 to x1 the residual is F(x1) = -(J(x1) - J(x0)) dx / 2
    + O(|dx|^3) (trapezoid rule along the step): a short step is checked with J(x1),
    which the solution needs anyway."""
    n, nd = x.shape[0], q.shape[0]
    fresh = False  # Jw is J at x
    for it in range(max_iter + 1):
        body_rotations(x, nb, cs)
        if it == 0:
            _system(x, q, nb, ints, flts, n_rows, cs, F, Jw)
            fresh = True
        else:
            rows_values_cs(x, nb, ints, flts, cs, F, 0)
            for c in range(nd):
                F[n_rows + c] -= q[c]
        err = 0.0
        for i in range(n):
            err = max(err, abs(F[i]))
        if not np.isfinite(err):
            return False, fresh
        if err <= tol and it > 0:
            return True, fresh
        if it == max_iter:
            return False, fresh
        if not fresh:
            Jw[:, :] = 0.0
            rows_jacobian_cs(x, nb, ints, flts, cs, Jw, 0)
        copy_rows(lu, Jw)
        if lu_factor(lu, pv, n) == 0.0:
            return False, fresh
        copy_into(b, F)
        lu_solve(lu, pv, b, n)
        step = 0.0
        for i in range(n):
            x[i] -= b[i]
            step = max(step, abs(b[i]))
        fresh = False
        if it == 0 and step <= short * tol:
            fresh = True
            if _short_step_error(x, b, nb, ints, flts, cs, Jw, J1) <= tol:
                return True, fresh
    return False, fresh


@njit
def inverse_variants(LU, piv, rhs, n_rows, Z):
    """The kinetostatic solve of every position of every variant,
    [-Phi_x^T, g_d,x^T] z = rhs (z: the multipliers, then the driving torques/forces),
    with the factors of J = [Phi_x; g_d,x] from :func:`path_variants`: z is J^-T rhs
    with the multipliers' sign turned.

    Parameters
    ----------
    LU, piv : ndarray
        Factors of :func:`path_variants`, (V, N, n, n) and (V, N, n).
    rhs : ndarray, shape (V, N, n)
        Inertia forces minus applied forces (N, N m).
    Z : ndarray, shape (V, N, n)
        Output.
    """
    V, N, n = rhs.shape
    b = np.empty(n)
    for v in range(V):
        for k in range(N):
            copy_into(b, rhs[v, k])
            lu_solve_transposed(LU[v, k], piv[v, k], b, n)
            for c in range(n):
                Z[v, k, c] = -b[c] if c < n_rows else b[c]


@njit
def loads_variants(X, J, Z, weight, group, cols, sign, frame, Fj):
    """Sums of the row forces ``Phi_x^T lambda`` (and ``g_d,x^T tau``) of every position
    of every variant, from J = [Phi_x; g_d,x] and the solution z of
    :func:`inverse_variants` (the multipliers with their sign turned, then the driving
    torques/forces):

    * ``frame[v, k]``: minus the net force and moment about the ground origin of the
      rows' forces ``D = sum_r weight[r] z_r J_r`` on the bodies (for instance the
      drives' stators and the joints to the frame), as
      :func:`mechdyn.dynamics.reactions.net_on_ground`: (Fx, Fy) N and the moment, N m;
    * ``Fj[g, v, k, c] = -sign[g] sum_{r: group[r] = g} z_r J[r, cols[g, c]]``: two
      columns (c = 0, 1) of the constraint force of the rows of each group g (a joint's
      force on one body, oriented by ``sign``).

    Parameters
    ----------
    X : ndarray, shape (V, N, n_x)
        Poses (m, rad).
    J : ndarray, shape (V, N, n, n_x)
    Z : ndarray, shape (V, N, n)
    weight : ndarray, shape (n,)
    group : ndarray of int, shape (n,)
        The group of each row (-1: none).
    cols : ndarray of int, shape (G, 2)
    sign : ndarray, shape (G,)
    frame : ndarray, shape (V, N, 3)
        Output.
    Fj : ndarray, shape (G, V, N, 2)
        Output.
    """
    V, N, n, nx = J.shape
    G = cols.shape[0]
    D = np.empty(nx)
    for v in range(V):
        for k in range(N):
            D[:] = 0.0
            for g in range(G):
                Fj[g, v, k, 0] = 0.0
                Fj[g, v, k, 1] = 0.0
            for r in range(n):
                z = Z[v, k, r]
                w = weight[r] * z
                if w != 0.0:
                    for i in range(nx):
                        D[i] += w * J[v, k, r, i]
                g = group[r]
                if g >= 0:
                    Fj[g, v, k, 0] -= z * J[v, k, r, cols[g, 0]]
                    Fj[g, v, k, 1] -= z * J[v, k, r, cols[g, 1]]
            for g in range(G):
                Fj[g, v, k, 0] *= sign[g]
                Fj[g, v, k, 1] *= sign[g]
            fx = fy = mz = 0.0
            for b in range(nx // 3):
                fx += D[3 * b]
                fy += D[3 * b + 1]
                mz += D[3 * b + 2] + (X[v, k, 3 * b] * D[3 * b + 1]
                                      - X[v, k, 3 * b + 1] * D[3 * b])
            frame[v, k, 0] = -fx
            frame[v, k, 1] = -fy
            frame[v, k, 2] = -mz


@njit
def body_loads_variants(X, Xd, Xdd, mass, inertia, com, gravity, rhs):
    """Inertia forces minus weights on the body poses, of every position of every
    variant: the right-hand side of :func:`inverse_variants` when the bodies' weights
    are the only applied loads.

    Per body (as :func:`mechdyn.model.inertia.inertia_forces` and the weights of
    :class:`mechdyn.model.forces.ForceModel`): ``m a_c - m g`` (N) and
    ``J_c alpha + a x (m a_c - m g)`` (N m, about the frame origin), with the
    centre-of-mass arm ``a = A(theta) c`` and ``a_c = rddot + alpha perp(a) - omega^2 a``.

    Parameters
    ----------
    X, Xd, Xdd : ndarray, shape (V, N, n_x)
        Poses (m, rad), rates and accelerations.
    mass, inertia : ndarray, shape (V, n_b)
        kg and kg m^2 (about the centre of mass).
    com : ndarray, shape (V, n_b, 2)
        Centres of mass in the body frames, m.
    gravity : ndarray, shape (2,)
        m/s^2.
    rhs : ndarray, shape (V, N, n_x)
        Output.
    """
    V, N, nx = X.shape
    nb = mass.shape[1]
    for v in range(V):
        for b in range(nb):
            m, Jc = mass[v, b], inertia[v, b]
            cx, cy = com[v, b, 0], com[v, b, 1]
            gx, gy = m * gravity[0], m * gravity[1]
            for k in range(N):
                th = X[v, k, 3 * b + 2]
                c, s = np.cos(th), np.sin(th)
                ax = c * cx - s * cy
                ay = s * cx + c * cy
                w2 = Xd[v, k, 3 * b + 2] ** 2
                al = Xdd[v, k, 3 * b + 2]
                fx = m * (Xdd[v, k, 3 * b] + al * -ay - w2 * ax)
                fy = m * (Xdd[v, k, 3 * b + 1] + al * ax - w2 * ay)
                rhs[v, k, 3 * b] = fx - gx
                rhs[v, k, 3 * b + 1] = fy - gy
                rhs[v, k, 3 * b + 2] = (Jc * al + (ax * fy - ay * fx)) - (ax * gy - ay * gx)


@njit
def cycle_variants(X0, Q, dQ, ddQ, keep, nb, ints, flts, n_rows, tol, max_iter, short, min_rc,
                   mass, inertia, com, gravity, weight, group, cols, sign, X, Xd, Xdd, Z, frame,
                   Fj, rc, ok, fail):
    """The whole kinetostatic cycle of every variant whose weights are its only loads,
    variant by variant: :func:`path_variants`, :func:`body_loads_variants`,
    :func:`inverse_variants` and :func:`loads_variants` of one variant in turn, its
    Jacobians and factors kept in one variant's memory (in the processor's cache)
    instead of the batch's.

    The arguments are those of these functions (X0 ... min_rc and X, Xd, Xdd, rc, ok,
    fail: :func:`path_variants`; mass, inertia, com, gravity:
    :func:`body_loads_variants`; weight ... sign, frame, Fj: :func:`loads_variants`);
    Z, shape (V, K, n): the solutions of :func:`inverse_variants`.  A variant that
    leaves the continuation (``ok`` False) has no loads.
    """
    V, K, n = Z.shape
    J = np.empty((1, K, n, n))
    LU = np.empty((1, K, n, n))
    piv = np.empty((1, K, n), np.int64)
    rhs = np.empty((1, K, n))
    for v in range(V):
        w = slice(v, v + 1)
        path_variants(X0[w], Q[w], dQ, ddQ, keep, nb, ints, flts[w], n_rows, tol[w], max_iter,
                      short, min_rc, X[w], Xd[w], Xdd[w], J, LU, piv, rc[w], ok[w], fail[w])
        if not ok[v]:
            continue
        body_loads_variants(X[w], Xd[w], Xdd[w], mass[w], inertia[w], com[w], gravity, rhs)
        inverse_variants(LU, piv, rhs, n_rows, Z[w])
        loads_variants(X[w], J, Z[w], weight, group, cols, sign, frame[w], Fj[:, w])
