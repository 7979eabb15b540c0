"""A fixed-step integrator behind the step-by-step interface of SciPy's solvers.

The event loop of variable-structure mechanisms
(:func:`mechdyn.simulate_events.simulate_events`) steps a SciPy ``OdeSolver``
(``DOP853``, ``RK45``) on the first-order state ``y = (q, q', w)`` of one mode
segment: it constructs ``solver(fun, t0, y0, t_bound, ...)``, calls
``step()`` while ``status == "running"``, reads ``t``, ``y``, ``t_old`` and
locates events on ``dense_output()``.  :class:`FixedStepSolver` offers the same
interface on top of one of the project's fixed-step integrators
(:class:`~mechdyn.integrate.Wilson`, :class:`~mechdyn.integrate.RungeKutta4`):
steps of ``dt`` on a grid from the segment start ``t0``, the last one
shortened to land on ``t_bound``, and the dense output of each step is the
integrator's own interpolant (:attr:`Step.dense`).

The quadrature states ``w`` (the last ``n_w`` entries of ``y``) must not feed
back into the right-hand side: ``fun`` is called with ``w`` frozen at its value at
the segment start, and only its derivative ``p`` (the last ``n_w`` entries of
``fun(t, y)``) is used.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .base import Integrator, IntegratorOptionError, Step

__all__ = ["FixedStepSolver", "FixedStepDense"]


class FixedStepDense:
    """Dense output of one step, callable like SciPy's ``DenseOutput``: ``dense(t) -> y``.

    A scalar ``t`` gives ``y`` of shape (n,), an array of m times gives (n, m).
    """

    def __init__(self, step: Step):
        self.t_old, self.t = step.t_old, step.t
        self._dense = step.dense

    def __call__(self, t):
        if np.ndim(t) == 0:
            q, v, w = self._dense(float(t))
            return np.concatenate([q, v, w])
        return np.column_stack([self(s) for s in np.asarray(t, float)])


class FixedStepSolver:
    """SciPy-``OdeSolver``-like stepping of y' = fun(t, y), y = (q, q', w), with a
    fixed-step integrator.

    Parameters
    ----------
    fun : callable
        ``fun(t, y) -> y'`` with ``y = (q, q', w)`` and ``y' = (q', q'', p)``.
    t0 : float
        Start of the segment, s.
    y0 : array_like, shape (2 n + n_w,)
    t_bound : float
        End of the segment, s (``>= t0``).
    integrator : Integrator
        A fixed-step integrator (``Wilson``, ``RungeKutta4``) with ``dt`` set; its
        steps lie on the grid ``t0 + k dt``.
    n_w : int
        Number of quadrature states at the end of ``y`` (default 1).
    **_ignored
        The options of the adaptive SciPy solvers (``rtol``, ``atol``,
        ``first_step``, ``max_step``...) are accepted and ignored.

    Attributes
    ----------
    status : str
        ``"running"`` until ``t_bound`` is reached, then ``"finished"``
        (``"failed"`` after an error in a step).
    t, y, t_old
        Time and state after the last step, start of the last step.
    nfev : int
        Right-hand-side evaluations so far.
    """

    def __init__(self, fun: Callable, t0: float, y0, t_bound: float, *,
                 integrator: Integrator, n_w: int = 1, **_ignored):
        if integrator.adaptive or getattr(integrator, "dt", None) is None:
            raise IntegratorOptionError(
                f"FixedStepSolver needs a fixed-step integrator with `dt` set, got "
                f"{integrator!r}")
        y0 = np.array(y0, dtype=float).reshape(-1)
        n_w = int(n_w)
        n2 = y0.size - n_w
        if n_w < 0 or n2 < 0 or n2 % 2:
            raise IntegratorOptionError(
                f"y0 of size {y0.size} is not (q, q', w) with {n_w} quadrature state(s)")
        self.n = n = n2 // 2
        self.n_w = n_w
        self.fun = fun
        self.integrator = integrator
        self.t = self.t_old = float(t0)
        self.t_bound = float(t_bound)
        self.y = y0
        self.nfev = 0
        self._last: Step | None = None
        self.direction = 1.0
        w_frozen = y0[2 * n:].copy()

        def f(t, q, qdot):
            self.nfev += 1
            yd = np.asarray(fun(t, np.concatenate([q, qdot, w_frozen])), float)
            return yd[n:2 * n], yd[2 * n:]

        if self.t_bound <= self.t:
            self.status = "finished"
            self._steps = None
        else:
            self.status = "running"
            self._steps = integrator.integrate(f, self.t, y0[:n], y0[n:2 * n], self.t_bound,
                                               w0=w_frozen)

    @property
    def step_size(self):
        return None if self._last is None else self._last.t - self._last.t_old

    def step(self):
        """Take one step; returns None, or a message if the solver failed."""
        if self.status != "running":
            raise RuntimeError("attempt to step on a finished or failed solver")
        try:
            st = next(self._steps)
        except StopIteration:  # pragma: no cover - the last step sets "finished"
            self.status = "finished"
            return None
        except (FloatingPointError, OverflowError) as exc:
            self.status = "failed"
            return str(exc)
        if not (np.all(np.isfinite(st.q)) and np.all(np.isfinite(st.qdot))):
            self.status = "failed"
            return f"the state became non-finite at t = {st.t:.9g} s"
        self._last = st
        self.t_old, self.t = st.t_old, st.t
        self.y = np.concatenate([st.q, st.qdot, st.w])
        if self.t >= self.t_bound:
            self.t = self.t_bound
            self.status = "finished"
            self._steps.close()
        return None

    def dense_output(self) -> FixedStepDense:
        """Interpolant over the last step (``dense(t) -> y``)."""
        if self._last is None:
            raise RuntimeError("dense output is available after the first step")
        return FixedStepDense(self._last)
