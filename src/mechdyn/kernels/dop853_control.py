"""The step control of the compiled DOP853 loop (:mod:`mechdyn.kernels.dop853_numba`).

Hairer's DOP853 (the error norm of orders 5 and 3, step factors within [1/6, 3] with
safety 0.9, the starting step of order 8), over the states y and rates f of the loop; no
kernel evaluations here (the loop makes them).  It is the one step control of the loop,
with and without event functions (SciPy's variant runs only as ``scipy-dop853``).

The functions are those of :mod:`mechdyn.integrate.dop853_control`, written there once as
plain Python that Numba can compile and called as they are by the Python stepper
(:func:`mechdyn.integrate.dop853.dop853_steps`); here they are compiled with the kernels'
:func:`~mechdyn.kernels.rows_numba.njit` (none calls another plain function, so each
compiles whole; their constants are frozen into the compiled code, and the source file is
part of the cache digest, :func:`mechdyn.kernels.sources_digest`).  Without Numba they are
the plain functions themselves.
"""

from __future__ import annotations

from ..integrate import dop853_control as _plain
from .rows_numba import njit

__all__ = ["initial_guess", "initial_step", "error_norm", "error_factor", "too_large",
           "shrunk", "next_step"]

initial_guess = njit(_plain.initial_guess)
initial_step = njit(_plain.initial_step)
error_norm = njit(_plain.error_norm)
error_factor = njit(_plain.error_factor)
too_large = njit(_plain.too_large)
shrunk = njit(_plain.shrunk)
next_step = njit(_plain.next_step)
