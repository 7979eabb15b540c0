"""DOP853 stepped from Python: the method and step control of the compiled loop, in NumPy.

The embedded Dormand-Prince 8(5,3) pair (:mod:`mechdyn.integrate.dop853_tableau`) with
Hairer's step control as in his code DOP853 and as the compiled loop
(:mod:`mechdyn.kernels.dop853_numba`, its control :mod:`mechdyn.kernels.dop853_control`)
has it: the starting step of order 8 from one trial evaluation, the error norm of the
embedded orders 5 and 3 in the weights ``atol_i + rtol max(|y_i|, |y_new_i|)``, step
factors within [1/6, 3] with safety 0.9, no increase right after a rejection, a last
step stretched by up to 1 % to land on ``t_end``, and the dense output of order 7 (three
more evaluations, made on first use).  It steps a segment wherever the compiled loop does
not (the NumPy path, :func:`mechdyn.integrate.solve`, a segment from where the compiled
loop stopped), so that the default integrator is one method with one step control
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
from .dop853_tableau import E3, E5, N_STAGES, A, B, C, D

__all__ = ["dop853_steps", "initial_step", "error_norm", "next_step", "DenseDOP853"]

#: Hairer's safety factor and the bounds of the step factor
SAFETY, FAC_MIN, FAC_MAX = 0.9, 1.0 / 6.0, 3.0


def initial_step(fun: Callable, t: float, y, f, atol, rtol: float, hmax: float) -> tuple:
    """Hairer's starting step of order 8 from one trial evaluation.

    Parameters
    ----------
    fun : callable
        ``fun(t, y) -> y'``.
    t : float
        Start time, s.
    y, f : ndarray, shape (m,)
        State and rates at ``t``.
    atol : ndarray, shape (m,)
        Absolute tolerances.
    rtol, hmax : float
        Relative tolerance; largest step, s.

    Returns
    -------
    h : float
        The starting step, s.
    evaluations : int
        Evaluations spent (1).
    """
    sk = atol + rtol * np.abs(y)
    dnf = float(np.sum((f / sk) ** 2))
    dny = float(np.sum((y / sk) ** 2))
    h = 1e-6 if (dnf <= 1e-10 or dny <= 1e-10) else 0.01 * np.sqrt(dny / dnf)
    h = min(h, hmax)
    f1 = np.asarray(fun(t + h, y + h * f), float)
    if not np.all(np.isfinite(f1)):  # the compiled loop keeps the guess where it fails
        return h, 1
    der2 = np.sqrt(float(np.sum(((f1 - f) / sk) ** 2))) / h
    der12 = max(der2, np.sqrt(dnf))
    h1 = max(1e-6, h * 1e-3) if der12 <= 1e-15 else (0.01 / der12) ** (1.0 / 8.0)
    return min(100.0 * h, h1, hmax), 1


def error_norm(y, ynew, K, atol, rtol: float, h: float) -> float:
    """The error of a step ``h`` from ``y`` to ``ynew`` with the stages ``K`` (12, m):
    the embedded orders 5 and 3 combined as in DOP853; inf where it is not finite.

    Parameters
    ----------
    y, ynew : ndarray, shape (m,)
        The step's start and end.
    K : ndarray, shape (>= 12, m)
        The rates at the stages.
    atol : ndarray, shape (m,)
    rtol, h : float

    Returns
    -------
    float
        The error in units of the tolerance (the step is rejected above 1).
    """
    sk = atol + rtol * np.maximum(np.abs(y), np.abs(ynew))
    k = K[:N_STAGES]
    e5n = float(np.sum((E5[:N_STAGES] @ k / sk) ** 2))
    e3n = float(np.sum((E3[:N_STAGES] @ k / sk) ** 2))
    deno = e5n + 0.01 * e3n
    err = abs(h) * e5n / np.sqrt(y.size * (deno if deno > 0.0 else 1.0))
    return err if np.isfinite(err) else np.inf


def next_step(h: float, err: float, rejected: bool) -> float:
    """The step after an accepted step ``h`` of error ``err`` (no longer than ``h`` right
    after a rejection).

    Parameters
    ----------
    h, err : float
    rejected : bool
        Whether an attempt of this step was rejected.

    Returns
    -------
    float
    """
    fac = max(FAC_MIN, min(FAC_MAX, err ** 0.125 / SAFETY))
    h_next = h / fac
    return min(h_next, h) if rejected else h_next


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
        dy = self.ynew - y
        f, fnew = K[0], K[N_STAGES]
        return np.vstack([dy, h * f - dy, 2.0 * dy - h * (f + fnew), h * (D @ K)])

    def __call__(self, ts: float) -> np.ndarray:
        """The state at ``ts`` within the step, shape (m,)."""
        if self.coeffs is None:
            self.coeffs = self._make()
        d = self.coeffs
        s = (ts - self.t) / self.h if self.h != 0.0 else 1.0
        s1 = 1.0 - s
        return self.y + s * (d[0] + s1 * (d[1] + s * (d[2] + s1 * (d[3] + s * (
            d[4] + s1 * (d[5] + s * d[6]))))))


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
            err = error_norm(y, ynew, K, atol, rtol, h)
            if err <= 1.0:
                K[N_STAGES] = fun(t_new, ynew)
                count(1)
                if not np.all(np.isfinite(K[N_STAGES])):
                    err = np.inf
        if err <= 1.0:
            h_next = next_step(h, err, rejected > 0)
            dense = DenseDOP853(fun, t, h, y, ynew, K, count)
            return h_next, t_new, ynew, K[N_STAGES].copy(), dense, rejected
        rejected += 1
        h = h / min(FAC_MAX, err ** 0.125 / SAFETY)
        if h < hmin:
            raise IntegrationError(
                f"DOP853 failed: the step fell below {hmin:.3g} s (error {err:.3g} of "
                f"the tolerance)", t=t)
