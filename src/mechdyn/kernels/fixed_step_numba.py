"""The compiled fixed-step loops: RK4 and Wilson's linear-acceleration method fused with
a mode's kernel.

:func:`run` steps y = (q_I, q_I', w), y' = (q_I', q_I'', P_nc) over a grid of step ends
(that of :meth:`mechdyn.integrate.base.FixedStep.grid`) with the method of
``ipar[I_METHOD]``, every evaluation made by
:func:`mechdyn.kernels.lagrange_numba.evaluate_into` as in the DOP853 loop
(:mod:`mechdyn.kernels.dop853_numba`, whose return codes, flags, scalars and buffers it
shares, so that one Python side drives both: :mod:`mechdyn.simulate.compiled_loop`):

* ``RK4`` (:class:`mechdyn.integrate.runge_kutta.RungeKutta4`): the classical
  fourth-order Runge-Kutta method, four evaluations per step, the one at the end of a step
  the first stage of the next;
* ``WILSON`` (:class:`mechdyn.integrate.wilson.Wilson`): the linear-acceleration
  predictor-corrector, ``ipar[I_ITER]`` corrector passes at most, stopped early when the
  change of (q, q') is below ``par[P_TOL]`` (1 + |(q, q')|) (a negative tolerance never
  stops early), over theta h with the acceleration interpolated back to the step's end
  when ``par[P_THETA]`` > 1; w by the trapezoidal rule.

The arithmetic is that of the Python steppers, operation for operation, so that both
give the same numbers to round-off.  The output samples inside a step are taken on the
quintic Hermite interpolant of its ends (:func:`mechdyn.integrate.base.hermite_dense`).
A step cannot be shortened for the output buffers: a single step with more output
samples than the buffers hold ends the call with ``FAILED`` and ``ipar[I_STATUS] = -2``
(the Python stepper takes the segment from there).
"""

from __future__ import annotations

import numpy as np

from .dop853_dense import keep_step
from .dop853_numba import (
    BATCH,
    DONE,
    FAILED,
    FLAGGED,
    I_EVERY,
    I_FLAGS,
    I_FSAL,
    I_KEEP,
    I_MAXSTEPS,
    I_NEXT,
    I_NKEPT,
    I_NOUT,
    I_STATUS,
    I_STEPS,
    I_WPEND,
    N_IPAR,
    N_PAR,
    P_T,
    WATCH,
    accept,
    samples,
    step_end,
)
from .dop853_steps import _counted, _put_back, _watch
from .lagrange_numba import D_NI
from .rows_numba import copy_into, njit

__all__ = ["run", "RK4", "WILSON", "I_GRID", "I_METHOD", "I_ITER", "P_TOL",
           "P_THETA", "N_PAR_FIXED", "N_IPAR_FIXED"]

#: the methods (``ipar[I_METHOD]``)
RK4, WILSON = 0, 1
#: beyond the DOP853 loop's scalars: the index of the step's start in the grid, the
#: method, Wilson's corrector passes; its corrector tolerance and theta
I_GRID, I_METHOD, I_ITER = N_IPAR, N_IPAR + 1, N_IPAR + 2
N_IPAR_FIXED = N_IPAR + 3
P_TOL, P_THETA = N_PAR, N_PAR + 1
N_PAR_FIXED = N_PAR + 2


@njit
def _rk4(t, t_new, h, y, f, K, ynew, ys, ni, ip, fp, ri, rf, dims, ws, ext, off, sc, piv, par, ipar,
         nx, x_end):
    """The stages of one RK4 step (K[0] = f) and its end state into ``ynew``; False where
    the kernel failed."""
    m = y.size
    hh = h / 2
    for i in range(m):
        K[0, i] = f[i]
    for s in range(1, 4):
        c = h if s == 3 else hh
        for i in range(m):
            ys[i] = y[i] + c * K[s - 1, i]
        if not _counted(t_new if s == 3 else t + hh, ys, K[s], ni, ip, fp, ri, rf, dims, ws,
                        ext, off, sc, piv, ipar):
            return False
        _watch(ys[0], ws, nx, par, ipar, x_end)
    h6 = h / 6
    for i in range(m):
        ynew[i] = y[i] + h6 * (K[0, i] + 2 * K[1, i] + 2 * K[2, i] + K[3, i])
    return True


@njit
def _wilson(t, h, y, f, K, ynew, ys, ni, ip, fp, ri, rf, dims, ws, ext, off, sc, piv, par,
            ipar, nx, x_end):
    """The predictor and corrector passes of one step of Wilson's method, its end (q, q')
    into ``ynew`` (w by the caller); False where the kernel failed."""
    th = par[P_THETA]
    tol = par[P_TOL]
    tau = th * h
    t2 = tau * tau / 2
    t6 = tau * tau / 6
    for i in range(ni):  # predictor: constant acceleration over tau
        ys[i] = y[i] + y[ni + i] * tau + f[ni + i] * t2
        ys[ni + i] = y[ni + i] + f[ni + i] * tau
    for i in range(2 * ni, y.size):
        ys[i] = y[i]
    at = K[1]
    for _ in range(ipar[I_ITER]):
        if not _counted(t + tau, ys, at, ni, ip, fp, ri, rf, dims, ws, ext, off, sc, piv,
                        ipar):
            return False
        _watch(ys[0], ws, nx, par, ipar, x_end)
        change = 0.0
        size = 0.0
        for i in range(ni):
            qn = y[i] + y[ni + i] * tau + (2 * f[ni + i] + at[ni + i]) * t6
            vn = y[ni + i] + (f[ni + i] + at[ni + i]) * (tau / 2)
            change = max(change, abs(qn - ys[i]), abs(vn - ys[ni + i]))
            size = max(size, abs(qn), abs(vn))
            ys[i] = qn
            ys[ni + i] = vn
        if tol >= 0.0 and change <= tol * (1.0 + size):
            break
    if th == 1.0:
        for i in range(2 * ni):
            ynew[i] = ys[i]
    else:
        hh6 = h * h / 6
        for i in range(ni):
            a_end = f[ni + i] + (at[ni + i] - f[ni + i]) / th
            ynew[i] = y[i] + y[ni + i] * h + (2 * f[ni + i] + a_end) * hh6
            ynew[ni + i] = y[ni + i] + (f[ni + i] + a_end) * (h / 2)
    return True


@njit
def run(y, f, grid, par, ipar, K, ynew, ys, hist, t_eval, o_t, o_y, o_x, o_xd, o_ext, ext,
        ext_end, x_end, ip, fp, ri, rf, dims, ws, sc, piv, kept):
    """Step from ``grid[ipar[I_GRID]]`` (state ``y``, rates ``f`` when ``ipar[I_FSAL]``)
    to the end of ``grid``; returns DONE, BATCH, FLAGGED, WATCH or FAILED, as
    :func:`mechdyn.kernels.dop853_numba.run` (the history rows, ``x_end``, the output
    buffers and the flags F_TURN and F_PIVOT as there).  With ``ipar[I_KEEP]`` every step
    is kept in row ``ipar[I_NKEPT]`` of ``kept`` as there
    (:func:`mechdyn.kernels.dop853_dense.keep_step`), the rates at its start in the place
    of the first coefficient of the dense output."""
    ni = dims[D_NI]
    nx = x_end.size // 3
    m = y.size
    cap = o_t.size
    n_te = t_eval.size
    every = ipar[I_EVERY] != 0
    off = ipar[I_FSAL] < 0  # False and True at run time (see dop853_steps._counted)
    on = not off
    k = ipar[I_GRID]
    t = grid[k]
    if ipar[I_FSAL] == 0:
        if not _counted(t, y, f, ni, ip, fp, ri, rf, dims, ws, ext, off, sc, piv, ipar):
            return FAILED
        ipar[I_FSAL] = 1
    wilson = ipar[I_METHOD] == WILSON
    steps = 0
    ws0 = np.empty(ws.size)  # the Newton start of a step, put back where a stage fails
    ipar[I_FLAGS] = 0
    while True:
        par[P_T] = t
        ipar[I_GRID] = k
        if k + 1 >= grid.size:
            return DONE
        if steps >= ipar[I_MAXSTEPS]:
            return BATCH
        t_new = grid[k + 1]
        h = t_new - t
        # room in the buffers for the samples of this step
        j = ipar[I_NEXT]
        end_sample = every
        while j < n_te and t_eval[j] <= t_new:
            if t_eval[j] >= t_new:
                end_sample = True
            j += 1
        if ipar[I_NOUT] + j - ipar[I_NEXT] + (1 if every else 0) > cap:
            if ipar[I_NOUT] > 0:
                return BATCH
            ipar[I_STATUS] = -2
            return FAILED
        copy_into(ws0, ws)
        if wilson:
            ok = _wilson(t, h, y, f, K, ynew, ys, ni, ip, fp, ri, rf, dims, ws, ext, off, sc,
                         piv, par, ipar, nx, x_end)
        else:
            ok = _rk4(t, t_new, h, y, f, K, ynew, ys, ni, ip, fp, ri, rf, dims, ws, ext, off,
                      sc, piv, par, ipar, nx, x_end)
        fnew = K[4]
        if not (ok and _counted(t_new, ynew, fnew, ni, ip, fp, ri, rf, dims, ws, ext_end,
                                end_sample, sc, piv, ipar)):
            _put_back(ws, ws0)  # (the caller goes on from the step's start)
            return FAILED
        _watch(ynew[0], ws, nx, par, ipar, x_end)
        if wilson:  # w by the trapezoidal rule
            for i in range(2 * ni, m):
                ynew[i] = y[i] + (f[i] + fnew[i]) * (h / 2)
        steps += 1
        ipar[I_STEPS] += 1
        flags = step_end(t, h, t_new, y, f, ynew, fnew, ws, x_end, hist, par, ni,
                         ipar[I_KEEP] == 0)
        if ipar[I_KEEP] != 0:
            row = kept[ipar[I_NKEPT]]
            copy_into(row[row.size - ws.size:], ws)
            copy_into(K[6, :], f)
            keep_step(row, t, h, t_new, y, ynew, fnew, K[6:13], K, True)
            ipar[I_NKEPT] += 1
        if flags != 0:
            ipar[I_FLAGS] = flags
            accept(y, f, ynew, fnew, ipar)
            par[P_T] = t_new
            ipar[I_GRID] = k + 1
            return FLAGGED
        # the samples of the step: t_eval inside it (Hermite interpolant), then its end
        if not samples(on, t, h, t_new, y, f, ynew, fnew, K, ys, K[5], end_sample, t_eval,
                       par, ipar, ip, fp, ri, rf, dims, ws, ext, ext_end, x_end, on, sc, piv,
                       o_t, o_y, o_x, o_xd, o_ext):
            return FAILED
        accept(y, f, ynew, fnew, ipar)
        t = t_new
        k += 1
        if ipar[I_WPEND] != 0:
            par[P_T] = t
            ipar[I_GRID] = k
            return WATCH
