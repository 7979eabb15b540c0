"""The stages and the dense output of a DOP853 step, and the rows a compiled loop keeps
its steps in.

The dense output of order 7 of a DOP853 step needs three evaluations beyond the step's
own twelve.  A segment with event functions keeps every step of the compiled loop for
Python to check (:func:`mechdyn.simulate.compiled_loop.kept_steps`), but only the steps
in which an event function changes sign, a coordinate rate turns or an output time
falls need their dense output; the loop keeps the stages of the others
(:func:`keep_step`) and :func:`dense_output` finishes them on demand: the same three
evaluations at the same points, from the workspace of the step's end, so that the
coefficients are the loop's own to round-off.

A kept row holds t, h, t_new, then y, y_new, f_new (m each), the 7 m coefficients of
the dense output, the first N_STAGES + 1 stages (13 m, where the dense output was not
made), a flag (made), and last the kernel's workspace (:func:`kept_offsets`).
"""

from __future__ import annotations

import numpy as np

from ..integrate import dop853_dense as _plain
from ..integrate.dop853_tableau import N_STAGES, A, C
from .lagrange_numba import D_NI, evaluate_into
from .rows_numba import copy_into, copy_rows, njit

__all__ = ["stage", "dense_at", "dense_coefficients", "keep_step", "dense_output",
           "kept_offsets", "kept_parts"]

#: the dense output at a time of the step, and its coefficients: the plain functions of
#: :mod:`mechdyn.integrate.dop853_dense`, compiled
dense_at = njit(_plain.dense_at)
dense_coefficients = njit(_plain.dense_coefficients)


@njit
def stage(y, K, s, h, ys):
    """ys = y + h sum_j a_sj K_j."""
    m = y.size
    for i in range(m):
        acc = 0.0
        for j in range(s):
            a = A[s, j]
            if a != 0.0:
                acc += a * K[j, i]
        ys[i] = y[i] + h * acc


@njit
def kept_offsets(m):
    """Where the parts of a kept row begin (state size m): y, y_new, f_new, the dense
    output, the stages, the flag, and the workspace."""
    return 3, 3 + m, 3 + 2 * m, 3 + 3 * m, 3 + 10 * m, 3 + 23 * m, 4 + 23 * m


@njit
def keep_step(row, t, h, t_new, y, ynew, fnew, dns, K, made):
    """A step into a row of ``kept``: the dense output where ``made``, else the first
    N_STAGES + 1 stages K for :func:`dense_output` to finish when it is wanted (the
    workspace, at the row's end, is written by the loop)."""
    m = y.size
    o_y, o_yn, o_f, o_d, o_k, o_made, _ = kept_offsets(m)
    row[0], row[1], row[2] = t, h, t_new
    copy_into(row[o_y:o_y + m], y)
    copy_into(row[o_yn:o_yn + m], ynew)
    copy_into(row[o_f:o_f + m], fnew)
    for r in range(7):
        copy_into(row[o_d + r * m:o_d + (r + 1) * m], dns[r])
    if not made:
        for r in range(N_STAGES + 1):
            copy_into(row[o_k + r * m:o_k + (r + 1) * m], K[r])
    row[o_made] = 1.0 if made else 0.0


def kept_parts(row, m: int) -> tuple:
    """The parts of a kept row (views): ``(t, h, t_new, y, y_new, f_new, dns (7, m),
    stages (13, m), made, ws)``."""
    o_y, o_yn, o_f, o_d, o_k, o_made, o_ws = kept_offsets(m)
    return (float(row[0]), float(row[1]), float(row[2]), row[o_y:o_y + m],
            row[o_yn:o_yn + m], row[o_f:o_f + m], row[o_d:o_k].reshape(7, m),
            row[o_k:o_made].reshape(N_STAGES + 1, m), row[o_made] != 0.0, row[o_ws:])


@njit
def dense_output(y, ynew, stages, t, h, ip, fp, ri, rf, dims, ws, sc, piv, dns):
    """The 7 coefficients of the dense output (into ``dns``, shape (7, m)) of the step
    from (t, y) to (t + h, ynew) with its first N_STAGES + 1 stages ``stages`` (the last
    one the rates at its end); returns the kernel's status (0: made), the evaluations
    leaving their pose and analogs in ``ws``."""
    m = y.size
    ni = dims[D_NI]
    K = np.empty((N_STAGES + 4, m))
    copy_rows(K[:N_STAGES + 1], stages)
    ys = np.empty(m)
    ext = np.empty(0)
    for s in range(N_STAGES + 1, N_STAGES + 4):
        stage(y, K, s, h, ys)
        st = evaluate_into(t + C[s] * h, ys[:ni], ys[ni:2 * ni], ip, fp, ri, rf, dims, ws,
                           K[s], ext, ext.size < 0, sc, piv)  # a runtime False
        if st != 0:
            return st
    dense_coefficients(y, ynew, K[0], K[N_STAGES], K, h, dns)
    return 0
