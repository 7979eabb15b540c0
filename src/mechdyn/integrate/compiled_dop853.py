"""DOP853 with a compiled loop: the default integrator of the package.

:class:`DOP853` is the embedded Dormand-Prince 8(5,3) pair with step control and dense
output of order 7 (coefficients: :mod:`mechdyn.integrate.dop853_tableau`).  Where the
caller's equations run on a compiled kernel (a fixed-structure segment on the Numba
backend, no event functions) :func:`mechdyn.integrate.segment.run_segment` hands the
segment to the kernel's compiled loop (:mod:`mechdyn.kernels.dop853_numba`, driven by
:mod:`mechdyn.dynamics.compiled_loop`): every step, every stage, the position solves and
the checks of the step run in machine code, and Python only records the output samples,
looks at a flagged step (a coordinate rate changing sign, a nearly singular Jacobian)
and reports a stop.  A segment with event functions (every mode of a variable-structure
run, a caller's events) takes its steps from the same compiled loop, each
with its dense output of order 7 and under SciPy's step control (so that its events fall
where ``"scipy-dop853"`` finds them): only the checks of each step, the event functions
and their location on that dense output stay in Python.  Everywhere else -- the NumPy
path, :func:`mechdyn.integrate.solve` -- it steps with SciPy's implementation of the
same method (``"scipy-dop853"`` asks for that everywhere).

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

from .base import DEFAULT_RTOL
from .scipy_ivp import ScipyIntegrator

__all__ = ["DOP853"]


class DOP853(ScipyIntegrator):
    """The Dormand-Prince 8(5,3) integrator, in the compiled loop where it can run.

    Parameters and errors: those of :class:`~mechdyn.integrate.scipy_ivp.ScipyIntegrator`
    (``rtol``, ``atol``, ``first_step``, ``max_step``), without its ``method``.
    """

    #: segments on a compiled kernel run in the compiled loop
    compiled = True

    def __init__(self, rtol: float = DEFAULT_RTOL, atol=None, *,
                 first_step: float | None = None, max_step: float | None = None):
        super().__init__("dop853", rtol, atol, first_step=first_step, max_step=max_step)
