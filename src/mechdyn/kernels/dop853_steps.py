"""One step of the compiled DOP853 loop (:func:`mechdyn.kernels.dop853_numba.run`), in parts.

The scalars of a call of the loop (``par``, ``ipar``: the ``P_*`` and ``I_*`` indices,
re-exported by :mod:`mechdyn.kernels.dop853_numba`), its return codes and flags, and the
parts of a step that its loop (``_run``) calls in turn: the start of a call (the held
pieces, the starting step), the step to try, its stages, the rates at its end, what
becomes of it at a table's point (:mod:`mechdyn.kernels.held_tables`), the step after it,
its dense output and kept row.  Every kernel evaluation is counted (:func:`_counted`).

The parts of the loop are compiled into it (``njit_inline``), as they were when
they were written out in it: each would otherwise be a compiled library of its own with
the whole kernel linked in (seconds of first use each).
"""

from __future__ import annotations

import numpy as np

from ..integrate.dop853_tableau import N_STAGES, C
from .dop853_control import initial_guess, initial_step
from .dop853_dense import dense_coefficients, keep_step, kept_offsets, stage
from .held_tables import aim, hold, left, table_vars
from .lagrange_numba import D_NI, N_FLAGS, W_COUNT, evaluate_into, held_pieces
from .loads_numba import H_NB, H_NTAB
from .rows_numba import copy_into, njit, njit_inline
from .table_regions import ETA

__all__ = ["DONE", "BATCH", "FLAGGED", "FAILED", "WATCH", "F_TURN", "F_PIVOT", "F_STALL",
           "P_T", "P_TEND", "P_H", "P_RTOL", "P_HMAX", "P_STALL", "P_PIVOT", "P_WC0",
           "P_WC1", "P_LAST", "P_TOLD", "P_HOLD", "P_WS", "P_BETA", "P_ERROLD", "P_BRACKET",
           "I_EVALS", "I_STEPS", "I_REJ", "I_NOUT", "I_NEXT", "I_FLAGS", "I_FSAL", "I_EVERY",
           "I_WATCH", "I_MAXSTEPS", "I_STATUS", "I_PREV", "I_WPEND", "I_KEEP", "I_NKEPT",
           "N_PAR", "N_IPAR"]

# return codes of run
DONE, BATCH, FLAGGED, FAILED, WATCH = 0, 1, 2, 3, 4
# flags of a FLAGGED step
F_TURN, F_PIVOT, F_STALL = 1, 2, 8
# par: time, end, step, rtol, largest step, stall step, pivot ratio to check, watch window
# (centre, half width), last sample time, start and size of the last step, coordinate of a
# watch due, step control (beta, last error), and from P_BRACKET six values: the bracket of
# the time of a table point a step was taken again up to (inf: none; see
# dop853_numba._run)
P_T, P_TEND, P_H, P_RTOL, P_HMAX, P_STALL, P_PIVOT, P_WC0, P_WC1, P_LAST, P_TOLD, P_HOLD, \
    P_WS, P_BETA, P_ERROLD, P_BRACKET = range(16)
N_PAR = P_BRACKET + 6
# ipar: evaluations, accepted and rejected steps, samples in the buffers, next t_eval,
# flags, f valid, every step sampled, watch on, steps per call, kernel status, history,
# a watch due, every step kept (with its dense output) in ``kept``, steps kept
I_EVALS, I_STEPS, I_REJ, I_NOUT, I_NEXT, I_FLAGS, I_FSAL, I_EVERY, I_WATCH, I_MAXSTEPS, \
    I_STATUS, I_PREV, I_WPEND, I_KEEP, I_NKEPT = range(15)
N_IPAR = 15


@njit_inline
def _counted(ts, ys, fout, ni, ip, fp, ri, rf, dims, ws, ext, full, sc, piv, ipar):
    """One evaluation y' = (q_I', q_I'', P_nc) at (ts, ys), counted; False where the kernel
    failed (its status in ipar).  ``full`` must be a runtime boolean: a literal True or
    False would compile the kernel once more for each (minutes of first use)."""
    ipar[I_EVALS] += 1
    st = evaluate_into(ts, ys[:ni], ys[ni:2 * ni], ip, fp, ri, rf, dims, ws, fout, ext, full,
                       sc, piv)
    ipar[I_STATUS] = st
    return st == 0


@njit
def _again(ws, ws0, ipar, wp0):
    """An attempt that is not kept: counted as rejected, its workspace and watch put back
    to those of the step's start."""
    ipar[I_REJ] += 1
    ipar[I_WPEND] = wp0
    _put_back(ws, ws0)


@njit
def _put_back(ws, ws0):
    """The workspace saved at the start of a step put back (the evaluation count goes on)."""
    cnt = ws[ws.size - N_FLAGS + W_COUNT]
    copy_into(ws, ws0)
    ws[ws.size - N_FLAGS + W_COUNT] = cnt


@njit
def _watch(s, ws, nx, par, ipar, x_end):
    """Keep the first evaluation (coordinate s, pose) where the watch of the branch charts
    is due (its pose in x_end[2 n_x:])."""
    if ipar[I_WATCH] != 0 and ipar[I_WPEND] == 0 and abs(s - par[P_WC0]) >= par[P_WC1]:
        ipar[I_WPEND] = 1
        par[P_WS] = s
        for i in range(nx):
            x_end[2 * nx + i] = ws[i]


@njit_inline
def _pieces_at_start(t, y, f, ip, fp, ri, rf, dims, ws, ext, off, sc, piv, ipar, locks, kv):
    """The held pieces at the start of a call: at a segment's start (``ipar[I_FSAL]`` 0)
    the rates ``f`` at (t, y) and the pieces there (at a point exactly: the piece above
    it), else the pieces held at the end of the last call (``kv``).  False where the
    kernel failed."""
    nt = ip[H_NTAB]
    if ipar[I_FSAL] != 0:
        copy_into(locks, kv[2 * nt:4 * nt])
        return True
    s_old, s_new = kv[:nt], kv[nt:2 * nt]
    locks[:] = 0.0
    if not _counted(t, y, f, dims[D_NI], ip, fp, ri, rf, dims, ws, ext, off, sc, piv, ipar):
        return False
    table_vars(t, ip, fp, dims, sc, s_old)
    for j in range(nt):
        s_new[j] = s_old[j] + 1.0
    hold(ip, fp, s_old, s_new, locks, False)
    ipar[I_FSAL] = 1
    return True


@njit_inline
def _step_at_start(t, y, f, K, atol, par, ip, fp, ri, rf, dims, ws, ext, off, sc, piv, ipar):
    """The first step of a call: ``par[P_H]``, or where it is not set Hairer's starting
    step from one trial evaluation (in ``K[1]``, ``K[2]``)."""
    h = par[P_H]
    if h > 0.0:
        return h
    rtol, hmax = par[P_RTOL], par[P_HMAX]
    h, dnf = initial_guess(y, f, atol, rtol, hmax)
    for i in range(y.size):
        K[1, i] = y[i] + h * f[i]
    if _counted(t + h, K[1], K[2], dims[D_NI], ip, fp, ri, rf, dims, ws, ext, off, sc, piv,
                ipar):
        h = initial_step(y, f, K[2], h, dnf, atol, rtol, hmax)
    return h


@njit_inline
def _step_to_try(t, h, par, ipar, steps, t_eval, cap):
    """``(code, h, hmin, t_new)``: DONE or BATCH where the call ends at ``t`` (``t_end``
    reached, ``steps`` the steps per call, or the buffers too full for the samples of the
    next step), else -1 and the step to try: ``h`` within the smallest step ``hmin`` and
    the largest, stretched to the end where it nearly gets there, cut to give at most
    ``cap`` - 1 samples (the buffers' size ``cap``)."""
    t_end = par[P_TEND]
    if t >= t_end:
        return DONE, h, 0.0, t
    if steps >= ipar[I_MAXSTEPS]:
        return BATCH, h, 0.0, t
    hmin = 10.0 * abs(np.nextafter(t, np.inf) - t)
    h = min(max(h, hmin), par[P_HMAX])
    last = t + 1.01 * h >= t_end
    if last:
        h = t_end - t
    # room in the buffers for the samples this step can give
    k = ipar[I_NEXT]
    while k < t_eval.size and t_eval[k] <= t + h:
        k += 1
    need = k - ipar[I_NEXT] + (1 if ipar[I_EVERY] != 0 else 0)
    if ipar[I_NOUT] + need > cap:
        if ipar[I_NOUT] > 0:
            return BATCH, h, hmin, t
        h = t_eval[ipar[I_NEXT] + cap - 2] - t  # at most cap - 1 samples in a step
        last = False
    return -1, h, hmin, (t_end if last else t + h)


@njit_inline
def _stages(t, h, y, f, K, ys, ynew, ip, fp, ri, rf, dims, ws, ext, off, sc, piv, par, ipar,
            x_end, s_old, s_st, locks):
    """The stages of a step from (t, y) (``f`` the first, the end in ``ynew``), the
    watch kept at the first stage where it is due; ``(ok, first)``: False where the kernel
    failed at a stage, and the earliest part of the step at which a stage has left a held
    piece (2.0: none; ``s_st``: the table variables at a stage)."""
    ni = dims[D_NI]
    nx = x_end.size // 3
    for i in range(y.size):
        K[0, i] = f[i]
    first = 2.0
    for s in range(1, N_STAGES):
        stage(y, K, s, h, ys)
        if not _counted(t + C[s] * h, ys, K[s], ni, ip, fp, ri, rf, dims, ws, ext, off,
                        sc, piv, ipar):
            return False, first
        _watch(ys[0], ws, nx, par, ipar, x_end)
        if ip[H_NTAB] > 0:
            table_vars(t + C[s] * h, ip, fp, dims, sc, s_st)
            th_s = left(ip, fp, s_old, s_st, locks)[0]
            if th_s <= 1.0:
                first = min(first, th_s * C[s])
    stage(y, K, N_STAGES, h, ynew)
    return True, first


@njit_inline
def _end_sampled(t_new, t_eval, ipar):
    """Whether the end ``t_new`` of an accepted step is sampled (every step, or an output
    time there)."""
    end_sample = ipar[I_EVERY] != 0
    k = ipar[I_NEXT]
    while k < t_eval.size and t_eval[k] <= t_new:
        if t_eval[k] >= t_new:
            end_sample = True
        k += 1
    return end_sample


@njit_inline
def _next_piece(t, y, f, jt, ip, fp, ri, rf, dims, ws, ws0, ext, off, sc, piv, ipar, locks,
                s_old, s_new, br):
    """A step that ends at the point of table ``jt`` already (see
    :func:`~mechdyn.kernels.held_tables.again`), to be taken again on the next piece: that
    piece held from the step's start, the rates there evaluated again on it and the
    workspace saved again; False where the kernel failed."""
    br[0] = np.inf
    hold(ip, fp, s_old, s_new, locks, True, jt)
    if not _counted(t, y, f, dims[D_NI], ip, fp, ri, rf, dims, ws, ext, off, sc, piv, ipar):
        return False
    copy_into(ws0, ws)
    return True


@njit_inline
def _after_points(h_next, h, h_full, rejected, hmin, t_new, s_new, br):
    """The step after an accepted step ``h`` to ``t_new``, from the control's ``h_next``:
    after one taken again up to a point, on with the step chosen before (``h_full``);
    right after a rejection, no longer than ``h``; where it landed short of a bracket's
    point, aimed at it (:func:`~mechdyn.kernels.held_tables.aim`)."""
    if h_full > 0.0:  # taken again up to a point: on with the step chosen before
        # (after a rejection that step alone: the short step's error says nothing of
        # it, and a short step kept as the next one can land short of the point again
        # and again, each time shorter, down to the smallest step)
        h_next = h_full if rejected else max(h_next, h_full)
    elif rejected:
        h_next = min(h_next, h)
    if t_new >= br[0]:
        br[0] = np.inf
    elif br[0] < np.inf:  # landed short of the point: the next step aims at it
        h_next = min(h_next, max(aim(br, t_new, s_new[int(br[5])], ETA), hmin))
    return h_next


@njit_inline
def _dense_kept(flags, t, h, t_new, y, f, ynew, fnew, K, ys, dns, t_eval, ip, fp, ri, rf,
                dims, ws, ext, off, sc, piv, ipar, kept):
    """The dense output of an accepted step where it is wanted (a flagged step, an output
    time inside it; its three stages, into ``dns``), and with ``ipar[I_KEEP]`` the step
    into the next row of ``kept``; False where the kernel failed at a stage."""
    ni = dims[D_NI]
    nx = ip[H_NB] * 3
    m = y.size
    keep = ipar[I_KEEP] != 0
    interior = ipar[I_NEXT] < t_eval.size and t_eval[ipar[I_NEXT]] < t_new
    if keep:
        row_ws = kept[ipar[I_NKEPT], kept_offsets(m)[-1]:]
        copy_into(row_ws, ws)
        held_pieces(row_ws, nx, ni)[:] = 0.0  # (a kept workspace holds no pieces)
    made = flags != 0 or interior  # a kept step's is made when it is wanted
    if made:
        for s in range(N_STAGES + 1, N_STAGES + 4):  # the stages of the dense output
            stage(y, K, s, h, ys)
            if not _counted(t + C[s] * h, ys, K[s], ni, ip, fp, ri, rf, dims, ws, ext, off,
                            sc, piv, ipar):
                return False
        dense_coefficients(y, ynew, f, fnew, K, h, dns)
    if keep:
        keep_step(kept[ipar[I_NKEPT]], t, h, t_new, y, ynew, fnew, dns, K, made)
        ipar[I_NKEPT] += 1
    return True
