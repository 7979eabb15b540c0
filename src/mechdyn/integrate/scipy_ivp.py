"""SciPy's initial-value solvers (the methods of ``scipy.integrate.solve_ivp``).

``solve_ivp`` drives an ``OdeSolver`` class (DOP853, RK45, Radau, LSODA, ...) in
a loop; here the same classes are stepped one by one, so that ``simulate`` can
re-solve positions, check the state and keep everything computed so far when a
run stops.  Dense output comes from the solver's own interpolant; events are
located on it (see :mod:`mechdyn.integrate.events`).

The second-order system is integrated as y = (q, q', w), y' = (q', q'', p).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from ..errors import IntegrationError
from .base import DEFAULT_RTOL, Integrator, IntegratorOptionError, Step, check_positive

__all__ = ["ScipyIntegrator", "SCIPY_METHODS", "first_order_function", "split_state"]

#: our name -> scipy OdeSolver class name
SCIPY_METHODS = {"dop853": "DOP853", "rk45": "RK45", "rk23": "RK23", "radau": "Radau",
                 "bdf": "BDF", "lsoda": "LSODA"}
_FSAL = {"DOP853", "RK45", "RK23"}  # solver.f holds f(t_new, y_new) after a step


class ScipyIntegrator(Integrator):
    """An adaptive SciPy solver.

    Parameters
    ----------
    method : {"dop853", "rk45", "rk23", "radau", "bdf", "lsoda"}
        The solver (case-insensitive; SciPy's spelling ``"DOP853"`` works too).
    rtol : float
        Relative tolerance (> 0), default ``DEFAULT_RTOL`` (1e-10).
    atol : float or array_like
        Absolute tolerance, SI units of each state component (> 0); a scalar, or an
        array of length 2 n + n_w over (q, q', w).  Default ``1e-3 rtol``.
    first_step, max_step : float, optional
        Initial and largest step sizes, s.
    """

    adaptive = True
    #: whether a segment on a compiled kernel may run in a compiled loop (see
    #: :class:`mechdyn.integrate.compiled_dop853.DOP853`)
    compiled = False

    def __init__(self, method: str = "dop853", rtol: float = DEFAULT_RTOL, atol=None, *,
                 first_step: float | None = None, max_step: float | None = None):
        super().__init__()
        key = str(method).lower()
        if key not in SCIPY_METHODS:
            raise IntegratorOptionError(
                f"unknown scipy method {method!r}; valid: {', '.join(SCIPY_METHODS)}")
        self.method = SCIPY_METHODS[key]
        self.name = key
        self.order = {"DOP853": 8, "RK45": 5, "RK23": 3, "Radau": 5, "BDF": 5,
                      "LSODA": 12}[self.method]
        self.rtol = check_positive("rtol", rtol)
        if atol is None:
            atol = 1e-3 * self.rtol
        at = np.asarray(atol, dtype=float)
        if not np.all(np.isfinite(at)) or np.any(at <= 0):
            raise IntegratorOptionError(f"`atol` must be positive, got {atol!r}")
        self.atol = float(at) if at.ndim == 0 else at
        self.first_step = check_positive("first_step", first_step, allow_none=True)
        self.max_step = check_positive("max_step", max_step, allow_none=True)

    def start_vector(self, q0, qdot0, w0) -> np.ndarray:
        """The first-order start (q, q', w), its size checked against ``atol``."""
        y0 = np.concatenate([q0, qdot0, w0])
        if np.ndim(self.atol) and np.size(self.atol) != y0.size:
            raise IntegratorOptionError(
                f"`atol` has {np.size(self.atol)} components but the state (q, q', w) has "
                f"{y0.size}")
        return y0

    def settings(self) -> dict:
        return {"method": self.method, "rtol": self.rtol, "atol": self.atol,
                "first_step": self.first_step, "max_step": self.max_step}

    def _steps(self, rhs, t0, q0, qdot0, w0, t_end, first_order=None) -> Iterator[Step]:
        n = q0.size
        if t_end == t0:
            return
        stats = self.stats
        fun = first_order_function(rhs, n) if first_order is None else first_order
        y0 = self.start_vector(q0, qdot0, w0)
        atol = self.atol
        kw = {k: v for k, v in (("first_step", self.first_step), ("max_step", self.max_step))
              if v is not None}
        import scipy.integrate as si
        solver = getattr(si, self.method)(fun, t0, y0, t_end, vectorized=False,
                                          rtol=self.rtol, atol=atol, **kw)
        fsal = self.method in _FSAL
        base_count = stats.evaluations
        while solver.status == "running":
            t_old = solver.t
            message = solver.step()
            if solver.status == "failed":
                raise IntegrationError(f"{self.method} failed: {message}", t=solver.t,
                                       q=solver.y[:n])
            stats.steps += 1
            y = solver.y
            if fsal:
                a = solver.f[n:2 * n].copy()
            else:
                a, _ = rhs(solver.t, y[:n], y[n:2 * n])
                base_count += 1
            if first_order is not None:
                stats.evaluations = base_count + solver.nfev
            yield Step(t_old, float(solver.t), y[:n].copy(), y[n:2 * n].copy(), a,
                       y[2 * n:].copy(), _LazyDense(solver, n))
            if first_order is not None:
                stats.evaluations = base_count + solver.nfev


class _LazyDense:
    """The solver's interpolant of the last step, built on first use (DOP853 spends
    three extra evaluations on it).  Valid until the solver takes its next step."""

    def __init__(self, solver, n):
        self.solver, self.n, self.sol = solver, n, None

    def __call__(self, s):
        if self.sol is None:
            self.sol = self.solver.dense_output()
        return split_state(self.sol(s), self.n)


def first_order_function(rhs, n: int):
    """y' = f(t, y) of the first-order state y = (q, q', w) (n coordinates) from the
    second-order ``rhs(t, q, qdot) -> (qddot, P_nc)``.

    Examples
    --------
    >>> f = first_order_function(lambda t, q, qd: (-q, np.zeros(1)), 1)
    >>> f(0.0, np.array([2.0, 3.0, 0.0])).tolist()
    [3.0, -2.0, 0.0]
    """
    def fun(t, y):
        return np.concatenate([y[n:2 * n], *rhs(t, y[:n], y[n:2 * n])])

    return fun


def split_state(y, n: int) -> tuple:
    """``(q, q', w)`` of a first-order state y of n coordinates (views of y).

    Examples
    --------
    >>> [a.tolist() for a in split_state(np.arange(5.0), 2)]
    [[0.0, 1.0], [2.0, 3.0], [4.0]]
    """
    return y[:n], y[n:2 * n], y[2 * n:]
