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

from ..errors import IntegrationError
from .base import (
    DEFAULT_RTOL,
    AdaptiveIntegrator,
    IntegratorOptionError,
    Step,
    first_order_function,
    split_state,
)

__all__ = ["ScipyIntegrator", "SCIPY_METHODS", "first_order_function", "split_state"]

#: our name -> scipy OdeSolver class name
SCIPY_METHODS = {"dop853": "DOP853", "rk45": "RK45", "rk23": "RK23", "radau": "Radau",
                 "bdf": "BDF", "lsoda": "LSODA"}
_FSAL = {"DOP853", "RK45", "RK23"}  # solver.f holds f(t_new, y_new) after a step


class ScipyIntegrator(AdaptiveIntegrator):
    """An adaptive SciPy solver, run only where a caller names it.

    Parameters
    ----------
    method : {"dop853", "rk45", "rk23", "radau", "bdf", "lsoda"}
        The solver (case-insensitive; SciPy's spelling ``"DOP853"`` works too).
    rtol, atol, first_step, max_step
        Tolerances and step bounds, checked by
        :class:`~mechdyn.integrate.base.AdaptiveIntegrator`: ``rtol`` > 0 (default
        ``DEFAULT_RTOL``, 1e-10); ``atol`` > 0, SI units of each state component, a
        scalar or one value per component of (q, q', w) (default ``1e-3 rtol``);
        initial and largest step sizes, s.

    Raises
    ------
    IntegratorOptionError
        An unknown method, or a bad tolerance or step bound (the message names it).

    Examples
    --------
    >>> integ = ScipyIntegrator("Radau", rtol=1e-6)
    >>> integ.name, integ.method, integ.order, integ.atol
    ('radau', 'Radau', 5, 1e-09)
    """

    def __init__(self, method: str = "dop853", rtol: float = DEFAULT_RTOL, atol=None, *,
                 first_step: float | None = None, max_step: float | None = None):
        key = str(method).lower()
        if key not in SCIPY_METHODS:
            raise IntegratorOptionError(
                f"unknown scipy method {method!r}; valid: {', '.join(SCIPY_METHODS)}")
        super().__init__(rtol, atol, first_step=first_step, max_step=max_step)
        self.method = SCIPY_METHODS[key]
        self.name = key
        self.order = {"DOP853": 8, "RK45": 5, "RK23": 3, "Radau": 5, "BDF": 5,
                      "LSODA": 12}[self.method]

    def settings(self) -> dict:
        return {"method": self.method, **super().settings()}

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
