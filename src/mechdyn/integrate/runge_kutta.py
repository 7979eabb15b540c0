"""Classical fourth-order Runge-Kutta method with a fixed step.

The second-order system q'' = f(t, q, q') is integrated as the first-order
system y = (q, q', w), y' = (q', f, p).  Four evaluations per step; the
evaluation at the end of a step is the first stage of the next one.
"""

from __future__ import annotations

from .base import FixedStep

__all__ = ["RungeKutta4"]


class RungeKutta4(FixedStep):
    """Classical Runge-Kutta method of order 4, fixed step.

    Parameters
    ----------
    steps : int, optional
        Number of equal steps over [t0, t_end] (default 100 when ``dt`` is not given).
    dt : float, optional
        Step size, s (the last step is shortened to land on ``t_end``).
    compiled : bool, optional
        Run segments on a compiled kernel in the compiled loop
        (:mod:`mechdyn.kernels.fixed_step_numba`, default), or (False) always step in
        Python.
    """

    name = "rk4"
    order = 4
    compiled = True

    def _advance(self, rhs, t, t1, q, v, w, a, p):
        h = t1 - t
        k1q, k1v, k1w = v, a, p
        a2, p2 = rhs(t + h / 2, q + h / 2 * k1q, v + h / 2 * k1v)
        k2q, k2v, k2w = v + h / 2 * k1v, a2, p2
        a3, p3 = rhs(t + h / 2, q + h / 2 * k2q, v + h / 2 * k2v)
        k3q, k3v, k3w = v + h / 2 * k2v, a3, p3
        a4, p4 = rhs(t1, q + h * k3q, v + h * k3v)
        k4q, k4v, k4w = v + h * k3v, a4, p4
        q1 = q + h / 6 * (k1q + 2 * k2q + 2 * k3q + k4q)
        v1 = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        w1 = w + h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w)
        return q1, v1, w1, *rhs(t1, q1, v1)
