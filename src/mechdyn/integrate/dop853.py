"""DOP853 stepped from Python: the method and step control of the compiled loop.

The embedded Dormand-Prince 8(5,3) pair (:mod:`mechdyn.integrate.dop853_tableau`) with
Hairer's step control as in his code DOP853 and as the compiled loop
(:mod:`mechdyn.kernels.dop853_numba`) has it: the starting step of order 8 from one trial
evaluation, the error norm of the embedded orders 5 and 3 in the weights ``atol_i + rtol
max(|y_i|, |y_new_i|)``, step factors within [1/6, 3] with safety 0.9, no increase right
after a rejection, a last step stretched by up to 1 % to land on ``t_end``, and the dense
output of order 7 (three more evaluations, made on first use).  The formulas of the step
control (:mod:`mechdyn.integrate.dop853_control`) and of the dense output
(:mod:`mechdyn.integrate.dop853_dense`) are the very functions the compiled loop compiles;
here they run as Python over the step's arrays.  It steps a segment wherever the compiled
loop does not (the NumPy path, :func:`mechdyn.integrate.solve`, a segment from where the
compiled loop stopped), so that the default integrator is one method with one step control
everywhere; SciPy's solvers run only where the caller names one.

A step whose evaluations give non-finite rates is rejected (its error is infinite) and
tried again three times shorter, as in the compiled loop; a step that would fall below
ten units in the last place of ``t`` ends the integration with an
:class:`~mechdyn.errors.IntegrationError`.

Examples
--------
>>> import numpy as np
>>> y0 = np.array([1.0, 0.0])
>>> steps = list(dop853_steps(lambda t, y: np.array([y[1], -y[0]]), 0.0, y0, np.pi,
...                           rtol=1e-10, atol=np.full(2, 1e-13)))
>>> t, y = steps[-1][1], steps[-1][2]
>>> float(t), bool(np.allclose(y, [-1.0, 0.0], atol=1e-9))
(3.141592653589793, True)
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np

from ..errors import IntegrationError
from . import dop853_control as ctl
from .dop853_dense import dense_at, dense_coefficients
from .dop853_tableau import N_STAGES, A, B, C

__all__ = ["dop853_steps", "initial_step", "DenseDOP853", "BETA"]

#: exponent of the PI step control: 0, Hairer's DOP853 (a step from the last error alone),
#: as in the compiled loop by default (:data:`mechdyn.simulate.compiled_loop.BETA`)
BETA = 0.0


def initial_step(fun: Callable, t: float, y, f, atol, rtol: float, hmax: float) -> tuple:
    """Hairer's starting step of order 8 from one trial evaluation
    (:func:`~mechdyn.integrate.dop853_control.initial_guess`, then
    :func:`~mechdyn.integrate.dop853_control.initial_step` where the trial rates are
    finite; else the guess, as in the compiled loop).

    Parameters
    ----------
    fun : callable
        ``fun(t, y) -> y'``.
    t : float
        Start time, s.
    y, f : ndarray, shape (m,)
        State and rates at ``t`` (units of y, and of y per second).
    atol, rtol, hmax
        The tolerances (absolute: shape (m,), units of y) and the largest step, s, as
        for :func:`~mechdyn.integrate.dop853_control.initial_guess`.

    Returns
    -------
    h : float
        The starting step, s.
    evaluations : int
        Evaluations spent (1).

    Examples
    --------
    >>> import numpy as np
    >>> h, k = initial_step(lambda t, y: -y, 0.0, np.ones(1), -np.ones(1), np.full(1, 1e-8),
    ...                     1e-6, np.inf)
    >>> round(float(h), 4), k  # y' = -y from 1, tolerance 1e-6
    (0.1001, 1)
    """
    h, dnf = ctl.initial_guess(y, f, atol, rtol, hmax)
    f1 = np.asarray(fun(t + h, y + h * f), float)
    if not np.all(np.isfinite(f1)):  # the compiled loop keeps the guess where it fails
        return h, 1
    return ctl.initial_step(y, f, f1, h, dnf, atol, rtol, hmax), 1


class DenseDOP853:
    """The dense output of order 7 of one step, its three evaluations made on first use.

    Parameters
    ----------
    fun : callable
        ``fun(t, y) -> y'``.
    t, h : float
        Start and size of the step, s.
    y, ynew : ndarray, shape (m,)
        Its start and end.
    K : ndarray, shape (16, m)
        The rates at its first 13 stages (the 13th at its end); the last three rows are
        filled here.
    counter : callable
        Called with the number of evaluations spent.
    """

    def __init__(self, fun, t, h, y, ynew, K, counter):
        self.fun, self.t, self.h, self.y, self.ynew, self.K = fun, t, h, y, ynew, K
        self.counter, self.coeffs = counter, None

    def _make(self) -> np.ndarray:
        K, y, h, t = self.K, self.y, self.h, self.t
        for s in range(N_STAGES + 1, N_STAGES + 4):
            K[s] = self.fun(t + C[s] * h, y + h * (A[s, :s] @ K[:s]))
        self.counter(3)
        dns = np.empty((7, y.size))
        dense_coefficients(y, self.ynew, K[0], K[N_STAGES], K, h, dns)
        return dns

    def __call__(self, ts: float) -> np.ndarray:
        """The state at ``ts`` within the step, shape (m,)."""
        if self.coeffs is None:
            self.coeffs = self._make()
        out = np.empty(self.y.size)
        dense_at(self.coeffs, self.y, self.t, self.h, ts, out)
        return out


def _stages(fun, t: float, h: float, y, K) -> np.ndarray:
    """The stages 2 to 12 of a step into ``K`` (``K[0]`` the rates at its start);
    returns its end."""
    for s in range(1, N_STAGES):
        K[s] = fun(t + C[s] * h, y + h * (A[s, :s] @ K[:s]))
    return y + h * (B @ K[:N_STAGES])


def dop853_steps(fun: Callable, t0: float, y0, t_end: float, *, rtol: float, atol,
                 first_step: float | None = None, max_step: float | None = None,
                 counter: Callable | None = None) -> Iterator[tuple]:
    """Integrate y' = fun(t, y) from ``t0`` to ``t_end``, yielding every accepted step.

    Parameters
    ----------
    fun : callable
        ``fun(t, y) -> y'`` (non-finite rates reject the step).
    t0, t_end : float
        Start and end, s (``t_end > t0``).
    y0 : array_like, shape (m,)
    rtol : float
    atol : float or array_like, shape (m,)
    first_step, max_step : float, optional
        The first step (default Hairer's starting step) and the largest, s.
    counter : callable, optional
        ``counter(k)`` after every ``k`` evaluations made.

    Yields
    ------
    tuple
        ``(t_old, t, y, f, dense, rejected)``: the step's start and end, the state and
        rates at its end, its dense output (:class:`DenseDOP853`) and the attempts
        rejected before it.

    Raises
    ------
    IntegrationError
        Where the step falls below ten units in the last place of ``t``.
    """
    count = counter if counter is not None else (lambda k: None)
    y = np.array(y0, float)
    at = np.broadcast_to(np.asarray(atol, float), y.shape).copy()
    hmax = np.inf if max_step is None else float(max_step)
    t = float(t0)
    f = np.asarray(fun(t, y), float)
    count(1)
    if not np.all(np.isfinite(f)):
        raise IntegrationError("DOP853 failed: non-finite rates at the start", t=t)
    if first_step:
        h = float(first_step)
    else:
        h, k = initial_step(fun, t, y, f, at, rtol, hmax)
        count(k)
    while t < t_end:
        h, t, y, f, dense, rejected = _one_step(fun, t, y, f, h, t_end, at, rtol, hmax, count)
        yield dense.t, t, y, f, dense, rejected


def _one_step(fun, t, y, f, h, t_end, atol, rtol, hmax, count) -> tuple:
    """One accepted step from (t, y) with rates ``f``, tried first with ``h``:
    ``(h_next, t_new, y_new, f_new, dense, rejected)``."""
    rejected = 0
    while True:
        hmin = 10.0 * abs(np.nextafter(t, np.inf) - t)
        h = min(max(h, hmin), hmax)
        last = t + 1.01 * h >= t_end
        if last:
            h = t_end - t
        t_new = t_end if last else t + h
        K = np.empty((N_STAGES + 4, y.size))
        K[0] = f
        with np.errstate(all="ignore"):
            ynew = _stages(fun, t, h, y, K)
            count(N_STAGES - 1)
            err = ctl.error_norm(y, ynew, K, atol, rtol, h)
            if not ctl.too_large(err):
                K[N_STAGES] = fun(t_new, ynew)
                count(1)
                if not np.all(np.isfinite(K[N_STAGES])):
                    err = np.inf
        fac11 = ctl.error_factor(err, BETA)
        if not ctl.too_large(err):
            h_next = ctl.next_step(h, err, fac11, BETA, ctl.ERR_MIN)[0]
            if rejected:  # no increase right after a rejection
                h_next = min(h_next, h)
            dense = DenseDOP853(fun, t, h, y, ynew, K, count)
            return h_next, t_new, ynew, K[N_STAGES].copy(), dense, rejected
        rejected += 1
        h = ctl.shrunk(h, err, fac11)
        if h < hmin:
            raise IntegrationError(
                f"DOP853 failed: the step fell below {hmin:.3g} s (error {err:.3g} of "
                f"the tolerance)", t=t)
