"""The linear-acceleration method (Wilson, 1962), as the source paper uses it.

Step i -> i+1 with step h (reference [1], docs/references.md):

1. q''_i = f(t_i, q_i, q'_i);
2. predict with constant acceleration:
   q'_(i+1) = q'_i + q''_i h,  q_(i+1) = q_i + q'_i h + q''_i h^2 / 2;
3. q''_(i+1) = f(t_(i+1), predicted state);
4. correct with a linearly varying acceleration:
   q'_(i+1) = q'_i + (q''_i + q''_(i+1)) h / 2,
   q_(i+1) = q_i + q'_i h + (2 q''_i + q''_(i+1)) h^2 / 6;

3-4 are repeated ``iterations`` times or until the correction is below ``tol``.
The method is second order.  With ``theta > 1`` (Wilson-theta, unconditionally
stable for linear systems when theta >= 1.37) steps 2-4 are taken over the
extended interval theta h and the acceleration at t_(i+1) is interpolated
linearly, q''_(i+1) = q''_i + (q''_(i+theta) - q''_i) / theta.

Quadrature states w' = p are advanced with the trapezoidal rule, consistent
with the linear variation of the acceleration.
"""

from __future__ import annotations

import numpy as np

from .base import FixedStep, IntegratorOptionError, check_positive

__all__ = ["Wilson"]

#: smallest theta for which Wilson-theta is unconditionally stable (linear systems)
THETA_MIN = 1.37


class Wilson(FixedStep):
    """Linear-acceleration predictor-corrector (optionally Wilson-theta), fixed step.

    Parameters
    ----------
    steps : int, optional
        Number of equal steps over [t0, t_end] (default 100 when ``dt`` is not given).
    dt : float, optional
        Step size, s.
    iterations : int
        Largest number of corrector passes per step (default 4).
    tol : float or None
        Stop correcting when the change of (q, q') is below ``tol`` relative to
        (1 + |(q, q')|) in the max norm; None always makes ``iterations`` passes.
    theta : float
        1 (the plain linear-acceleration method, default) or >= 1.37 (Wilson-theta).
    compiled : bool, optional
        Run segments on a compiled kernel in the compiled loop
        (:mod:`mechdyn.kernels.fixed_step_numba`, default), or (False) always step in
        Python.
    """

    name = "wilson"
    order = 2
    compiled = True

    def __init__(self, steps: int | None = None, dt: float | None = None, *,
                 iterations: int = 4, tol: float | None = 1e-12, theta: float = 1.0,
                 compiled: bool | None = None):
        super().__init__(steps, dt, compiled=compiled)
        self.iterations = check_positive("iterations", iterations, integer=True)
        self.tol = check_positive("tol", tol, allow_none=True)
        theta = float(theta)
        if not (theta == 1.0 or (np.isfinite(theta) and theta >= THETA_MIN)):
            raise IntegratorOptionError(
                f"`theta` must be 1 (plain linear-acceleration method) or >= {THETA_MIN} "
                f"(Wilson-theta, unconditionally stable), got {theta!r}")
        self.theta = theta

    def settings(self) -> dict:
        return {**super().settings(), "iterations": self.iterations, "tol": self.tol,
                "theta": self.theta}

    def _advance(self, rhs, t, t1, q, v, w, a, p):
        th = self.theta
        h = t1 - t
        tau = th * h
        # predictor: constant acceleration over tau
        qt = q + v * tau + a * (tau * tau / 2)
        vt = v + a * tau
        for _ in range(self.iterations):
            at, _pt = rhs(t + tau, qt, vt)
            qn = q + v * tau + (2 * a + at) * (tau * tau / 6)
            vn = v + (a + at) * (tau / 2)
            change = max(np.max(np.abs(qn - qt), initial=0.0),
                         np.max(np.abs(vn - vt), initial=0.0))
            size = 1.0 + max(np.max(np.abs(qn), initial=0.0), np.max(np.abs(vn), initial=0.0))
            qt, vt = qn, vn
            if self.tol is not None and change <= self.tol * size:
                break
        if th == 1.0:
            q1, v1 = qt, vt
        else:
            a_end = a + (at - a) / th
            q1 = q + v * h + (2 * a + a_end) * (h * h / 6)
            v1 = v + (a + a_end) * (h / 2)
        a1, p1 = rhs(t1, q1, v1)
        return q1, v1, w + (p + p1) * (h / 2), a1, p1
