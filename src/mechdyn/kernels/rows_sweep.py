"""Compiled drivers of the row evaluators for the position problem of the kinematic sweep.

The position problem of :mod:`mechdyn.kinematics.sweep` stacks the constraint
rows and the coordinate rows of a model into one :class:`~mechdyn.model.rows.Rows`
(``n_rows`` constraint rows, then ``n_q`` coordinate rows) and solves
F(x) = [Phi(x); g(x) - q] = 0.  These helpers evaluate F, its Jacobian and the
acceleration right-hand side -quad at one pose with the compiled evaluators of
:mod:`mechdyn.kernels.rows_numba`, in one call, where NumPy's per-call overhead
would dominate (the sequential continuation).  They contain no formulas of
their own.  Use them only when ``rows_numba.NUMBA`` is True: without numba they
run as (slow) plain Python.
"""

from __future__ import annotations

from .rows_numba import njit, rows_jacobian, rows_quad, rows_values

__all__ = ["system1", "gamma1"]


@njit
def system1(x, q, nb, ints, flts, n_rows, F, J):
    """F = [Phi; g - q] (n_eq,) and J = [Phi_x; g_x] (n_eq, n_x, zeroed by the caller).

    Parameters
    ----------
    x : ndarray, shape (n_x,)
        Pose (m, rad).
    q : ndarray, shape (n_q,)
        Coordinates (rad or m); ``n_eq = n_rows + n_q``.
    nb : int
        Number of moving bodies.
    ints, flts : ndarray
        The packed rows (:meth:`mechdyn.model.rows.Rows.packed`), constraints first.
    n_rows : int
        Number of constraint rows before the coordinate rows.
    F, J : ndarray
        Outputs, written in place.
    """
    rows_values(x, nb, ints, flts, F, 0)
    for k in range(q.shape[0]):
        F[n_rows + k] -= q[k]
    rows_jacobian(x, nb, ints, flts, J, 0)


@njit
def gamma1(x, xdot, nb, ints, flts, out):
    """[gamma; gamma_g] = -quad (n_eq,) at one pose, into ``out``.

    ``x`` (n_x,) in m and rad, ``xdot`` (n_x,) in m/s and rad/s; ``out`` in m/s^2
    and rad/s^2.
    """
    rows_quad(x, xdot, nb, ints, flts, out, 0)
    for k in range(out.shape[0]):
        out[k] = -out[k]

