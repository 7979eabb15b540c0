"""The dense output of a kept DOP853 step, made when it is wanted.

The dense output of order 7 of a DOP853 step needs three evaluations beyond the step's
own twelve.  A segment with event functions keeps every step of the compiled loop for
Python to check (:func:`mechdyn.dynamics.compiled_loop.kept_steps`), but only the steps
in which an event function changes sign, a coordinate rate turns or an output time
falls need their dense output; the loop keeps the stages of the others
(:func:`mechdyn.kernels.dop853_numba.keep_step`) and :func:`dense_output` finishes them
on demand: the same three evaluations at the same points, from the workspace of the
step's end, so that the coefficients are the loop's own to round-off.
"""

from __future__ import annotations

import numpy as np

from ..integrate.dop853_tableau import N_STAGES, C
from .dop853_numba import I_STATUS, N_IPAR, _counted, _dense, _stage
from .lagrange_numba import D_NI
from .rows_numba import njit

__all__ = ["dense_output"]


@njit
def dense_output(y, ynew, stages, t, h, ip, fp, ri, rf, dims, ws, sc, piv, dns):
    """The 7 coefficients of the dense output (into ``dns``, shape (7, m)) of the step
    from (t, y) to (t + h, ynew) with its first N_STAGES + 1 stages ``stages`` (the last
    one the rates at its end); returns the kernel's status (0: made), the evaluations
    leaving their pose and analogs in ``ws``."""
    m = y.size
    ni = dims[D_NI]
    K = np.empty((N_STAGES + 4, m))
    K[:N_STAGES + 1] = stages
    ys = np.empty(m)
    ext = np.empty(0)
    ipar = np.zeros(N_IPAR, dtype=np.int64)
    for s in range(N_STAGES + 1, N_STAGES + 4):
        _stage(y, K, s, h, ys)
        if not _counted(t + C[s] * h, ys, K[s], ni, ip, fp, ri, rf, dims, ws, ext,
                        ipar.size < 0, sc, piv, ipar):  # a runtime False (see _counted)
            return ipar[I_STATUS]
    _dense(y, ynew, K[0], K[N_STAGES], K, h, dns)
    return 0
