"""DOP853 with a compiled loop: the default integrator of the package.

:class:`DOP853` is the embedded Dormand-Prince 8(5,3) pair with Hairer's step control and
dense output of order 7 (coefficients: :mod:`mechdyn.integrate.dop853_tableau`), one
method with one step control wherever it runs.  Where the caller's equations run on a
compiled kernel (a fixed-structure segment on the Numba backend, no event functions)
the segment loop hands the segment to the kernel's compiled
loop (:mod:`mechdyn.kernels.dop853_numba`, driven by
:mod:`mechdyn.simulate.compiled_loop`): every step, every stage, the position solves and
the checks of the step run in machine code, and Python only records the output samples,
looks at a flagged step (a coordinate rate changing sign, a nearly singular Jacobian)
and reports a stop.  A segment with event functions (every mode of a variable-structure
run, a caller's events) takes its steps from the same compiled loop, each with its dense
output of order 7: only the checks of each step, the event functions and their location
on that dense output stay in Python.  Everywhere else -- the NumPy path (friction in the
joints, redundant constraints, ...), :func:`mechdyn.integrate.solve`, a segment from where
the compiled loop stopped -- it steps from Python with the same tableau and the same step
control (:mod:`mechdyn.integrate.dop853`).  It never calls SciPy's solvers:
``"scipy-dop853"`` asks for SciPy's implementation of the method (its own step control)
everywhere.

Examples
--------
>>> from mechdyn.integrate import make_integrator
>>> integ = make_integrator("dop853", rtol=1e-9)
>>> integ.name, integ.order, integ.compiled
('dop853', 8, True)
>>> make_integrator("scipy-dop853").compiled
False
"""

from __future__ import annotations

from collections.abc import Iterator

from .base import DEFAULT_RTOL, AdaptiveIntegrator, Step, first_order_function, split_state
from .dop853 import dop853_steps

__all__ = ["DOP853"]


class DOP853(AdaptiveIntegrator):
    """The Dormand-Prince 8(5,3) integrator, in the compiled loop where it can run and
    stepped from Python (:func:`mechdyn.integrate.dop853.dop853_steps`) elsewhere.

    Parameters and errors: those of :class:`~mechdyn.integrate.base.AdaptiveIntegrator`
    (``rtol``, ``atol``, ``first_step``, ``max_step``).
    """

    name = "dop853"
    order = 8
    #: the method, spelt as SciPy's class of it (for reports)
    method = "DOP853"
    #: segments on a compiled kernel run in the compiled loop
    compiled = True

    def __init__(self, rtol: float = DEFAULT_RTOL, atol=None, *,
                 first_step: float | None = None, max_step: float | None = None):
        super().__init__(rtol, atol, first_step=first_step, max_step=max_step)

    def _steps(self, rhs, t0, q0, qdot0, w0, t_end, first_order=None) -> Iterator[Step]:
        n = q0.size
        if t_end == t0:
            return
        stats = self.stats
        y0 = self.start_vector(q0, qdot0, w0)
        if first_order is None:
            fun = first_order_function(rhs, n)

            def count(k):  # rhs counts its own evaluations
                return None
        else:
            fun = first_order

            def count(k):
                stats.evaluations += k

        for t_old, t, y, f, dense, rejected in dop853_steps(
                fun, t0, y0, t_end, rtol=self.rtol, atol=self.atol,
                first_step=self.first_step, max_step=self.max_step, counter=count):
            stats.steps += 1
            stats.rejected += rejected
            yield Step(t_old, float(t), y[:n].copy(), y[n:2 * n].copy(), f[n:2 * n].copy(),
                       y[2 * n:].copy(), _Split(dense, n))


class _Split:
    """A step's dense output as ``(q, qdot, w)``."""

    def __init__(self, dense, n: int):
        self.dense, self.n = dense, n

    def __call__(self, s):
        return split_state(self.dense(s), self.n)
