"""The compiled integration loop: DOP853 fused with a mode's kernel.

:func:`run` integrates y = (q_I, q_I', w), y' = (q_I', q_I'', P_nc) with the embedded
Dormand-Prince 8(5,3) pair (:mod:`mechdyn.integrate.dop853_tableau`), its step control
(the error norm of orders 5 and 3 of Hairer's DOP853, step factors within [1/6, 3] with
safety 0.9, no increase right after a rejection) and its dense output of order 7, every
stage evaluated by :func:`mechdyn.kernels.lagrange_numba.evaluate_into` -- the position
solve from the last pose, the analogs, the mass matrix and its factorization -- without
allocating and without going back to Python.  It returns only

* ``BATCH``: the output buffers are full (or ``max_steps`` steps were taken): the
  caller records the samples and calls again;
* ``DONE``: ``t_end`` reached;
* ``FLAGGED``: the step just accepted needs a check in Python (``flags``: a coordinate
  rate changed sign -- a dead position may be near --, a small pivot of the position
  Jacobian, a stalling step); its samples are not recorded and its dense output is in
  ``dns``;
* ``WATCH``: the watch of the branch charts is due (at the coordinate ``par[P_WS]`` and
  the pose ``x_end[2 n_x:]`` of the first evaluation where it was); the step is done;
* ``FAILED``: the kernel failed at a stage, or the step fell below the smallest step;
  the state is the last accepted one.

The arrays of a call (all preallocated by the caller, see
:class:`mechdyn.dynamics.loop_buffers.LoopBuffers`): ``par`` (float) and ``ipar`` (int)
hold the scalars named by the ``P_*`` and ``I_*`` indices (of
:mod:`mechdyn.kernels.dop853_steps`, which has the parts of a step; the step control is in
:mod:`mechdyn.kernels.dop853_control`).
"""

from __future__ import annotations

import numpy as np

from ..integrate.dop853_tableau import N_STAGES
from .dop853_control import error_factor, error_norm, next_step, shrunk, too_large
from .dop853_dense import dense_at
from .dop853_steps import (
    BATCH,
    DONE,
    F_PIVOT,
    F_STALL,
    F_TURN,
    FAILED,
    FLAGGED,
    I_EVALS,
    I_EVERY,
    I_FLAGS,
    I_FSAL,
    I_KEEP,
    I_MAXSTEPS,
    I_NEXT,
    I_NKEPT,
    I_NOUT,
    I_PREV,
    I_REJ,
    I_STATUS,
    I_STEPS,
    I_WATCH,
    I_WPEND,
    N_IPAR,
    N_PAR,
    P_BETA,
    P_BRACKET,
    P_ERROLD,
    P_H,
    P_HMAX,
    P_HOLD,
    P_LAST,
    P_PIVOT,
    P_RTOL,
    P_STALL,
    P_T,
    P_TEND,
    P_TOLD,
    P_WC0,
    P_WC1,
    P_WS,
    WATCH,
    _after_points,
    _again,
    _counted,
    _dense_kept,
    _end_sampled,
    _next_piece,
    _pieces_at_start,
    _put_back,
    _stages,
    _step_at_start,
    _step_to_try,
    _watch,
)
from .held_tables import KEEP, NEXT_PIECE, again, crossed, hold, shortened, switch_at, table_vars
from .hermite_numba import hermite_at
from .lagrange_numba import D_NI, N_FLAGS, W_PIVOT, evaluate_into, held_pieces
from .loads_numba import H_NB, H_NTAB
from .rows_numba import copy_into, njit, njit_inline
from .table_regions import ETA

__all__ = ["run", "evaluate_states", "DONE", "BATCH", "FLAGGED", "FAILED", "WATCH",
           "F_TURN", "F_PIVOT", "F_STALL", "P_T", "P_TEND", "P_H", "P_RTOL",
           "P_HMAX", "P_STALL", "P_PIVOT", "P_WC0", "P_WC1", "P_LAST", "P_TOLD", "P_HOLD",
           "I_EVALS", "I_STEPS", "I_REJ", "I_NOUT", "I_NEXT", "I_FLAGS", "I_FSAL",
           "I_EVERY", "I_WATCH", "I_MAXSTEPS", "I_STATUS", "I_PREV", "I_WPEND", "P_WS",
           "I_KEEP", "I_NKEPT", "P_BRACKET", "step_end", "accept", "samples",
           "N_PAR", "N_IPAR"]

@njit
def _switch(switch, ahead, t_new, ynew, fnew, s_old, s_new, ni, ip, fp, ri, rf, dims, ws,
            ext_end, full, sc, piv, ipar, locks):
    """At the end of an accepted step (after its dense output and samples, made on the
    pieces it was taken on): with ``switch``, hold the next pieces of the tables whose
    variable in ``s_new`` has left its piece and evaluate the rates there again on them; the
    table variables there (as evaluated) become the step's start values."""
    nt = ip[H_NTAB]
    if nt == 0:
        return True
    if switch:
        # the variables a little further on, the way they went (the part ``ahead`` of the
        # step's travel): every table whose point lies within it gets its next piece
        # (tables that share a point switch together; extrapolated by a whole step, a
        # variable near a point of its own would be moved onto the next piece too early)
        hold(ip, fp, s_new, s_new + ahead * (s_new - s_old), locks, True)
        if not _counted(t_new, ynew, fnew, ni, ip, fp, ri, rf, dims, ws, ext_end, full, sc,
                        piv, ipar):
            return False
        table_vars(t_new, ip, fp, dims, sc, s_new)
    copy_into(s_old, s_new)
    return True


@njit
def _record(k, ts, y, ws, ext, nx, ni, o_t, o_y, o_x, o_xd, o_ext):
    o_t[k] = ts
    copy_into(o_y[k, :], y)
    copy_into(o_x[k, :], ws[:nx])
    o = nx + ni + nx * ni
    copy_into(o_xd[k, :], ws[o:o + nx])
    copy_into(o_ext[k, :], ext)


@njit
def step_end(t, h, t_new, y, f, ynew, fnew, ws, x_end, hist, par, ni, turns):
    """After the evaluation at an accepted step's end: the pose and its rates there into
    ``x_end``, the step into the history rows (start of the previous step, start and end of
    this one), its start and size into ``par``; returns its flags: F_TURN where a
    coordinate rate changed sign (when ``turns``), F_PIVOT where the pivot ratio of the
    position Jacobian fell below ``par[P_PIVOT]``."""
    m = y.size
    nx = x_end.size // 3
    flags = 0
    for c in range(ni if turns else 0):
        if (y[ni + c] > 0.0 and ynew[ni + c] < 0.0) or (y[ni + c] < 0.0
                                                       and ynew[ni + c] > 0.0):
            flags |= F_TURN
    if ws[ws.size - N_FLAGS + W_PIVOT] < par[P_PIVOT]:
        flags |= F_PIVOT
    o = nx + ni + nx * ni
    for i in range(nx):
        x_end[i] = ws[i]
        x_end[nx + i] = ws[o + i]
    copy_into(hist[0, :], hist[1, :])
    hist[1, 0] = t
    copy_into(hist[1, 1:m + 1], y)
    copy_into(hist[1, m + 1:], f)
    hist[2, 0] = t_new
    copy_into(hist[2, 1:m + 1], ynew)
    copy_into(hist[2, m + 1:], fnew)
    par[P_TOLD], par[P_HOLD] = t, h
    return flags


@njit
def accept(y, f, ynew, fnew, ipar):
    """The step's end becomes the state (y, f) the next step starts from."""
    for i in range(y.size):
        y[i] = ynew[i]
        f[i] = fnew[i]
    ipar[I_PREV] += 1


@njit
def samples(hermite, t, h, t_new, y, f, ynew, fnew, dns, ys, fs, end_sample, t_eval, par,
            ipar, ip, fp, ri, rf, dims, ws, ext, ext_end, x_end, on, sc, piv, o_t, o_y, o_x,
            o_xd, o_ext):
    """The output samples of an accepted step into the buffers: the times of ``t_eval``
    inside it, on the step's dense output (``dns``,
    :func:`~mechdyn.kernels.dop853_dense.dense_at`) or, with
    ``hermite``, on the quintic Hermite interpolant of its ends
    (:func:`mechdyn.kernels.hermite_numba.hermite_at`), each evaluated in full (``on``: a
    runtime True) and not counted as a step's evaluation; then its end where
    ``end_sample`` (its evaluation in ``ext_end``, ``x_end``).  False where the kernel
    failed at a sample."""
    ni = dims[D_NI]
    nx = x_end.size // 3
    n_te = t_eval.size
    while ipar[I_NEXT] < n_te and t_eval[ipar[I_NEXT]] <= t_new:
        ts = t_eval[ipar[I_NEXT]]
        ipar[I_NEXT] += 1
        if ts <= par[P_LAST] or ts >= t_new:
            continue
        if hermite:
            hermite_at(t, y, f, t_new, ynew, fnew, ni, ts, ys)
        else:
            dense_at(dns, y, t, h, ts, ys)
        ok = _counted(ts, ys, fs, ni, ip, fp, ri, rf, dims, ws, ext, on, sc, piv, ipar)
        ipar[I_EVALS] -= 1  # an output sample, not a step's evaluation
        if not ok:
            return False
        _record(ipar[I_NOUT], ts, ys, ws, ext, nx, ni, o_t, o_y, o_x, o_xd, o_ext)
        ipar[I_NOUT] += 1
        par[P_LAST] = ts
    if end_sample and t_new > par[P_LAST]:
        k = ipar[I_NOUT]
        o_t[k] = t_new
        copy_into(o_y[k, :], ynew)
        copy_into(o_x[k, :], x_end[:nx])
        copy_into(o_xd[k, :], x_end[nx:2 * nx])
        copy_into(o_ext[k, :], ext_end)
        ipar[I_NOUT] += 1
        par[P_LAST] = t_new
    return True


@njit
def run(y, f, atol, par, ipar, K, ynew, ys, hist, dns, t_eval, o_t, o_y, o_x, o_xd, o_ext,
        ext, ext_end, x_end, ip, fp, ri, rf, dims, ws, sc, piv, kept, kv):
    """:func:`_run`, with the held table pieces (:mod:`mechdyn.kernels.table_regions`)
    kept in ``kv`` between calls (``kv``: 4 values per held table) and released in the
    work array when it returns (every evaluation outside the loop sees the tables)."""
    code = _run(y, f, atol, par, ipar, K, ynew, ys, hist, dns, t_eval, o_t, o_y, o_x, o_xd,
                o_ext, ext, ext_end, x_end, ip, fp, ri, rf, dims, ws, sc, piv, kept, kv)
    nt = ip[H_NTAB]
    if nt > 0:
        locks = held_pieces(ws, 3 * ip[H_NB], dims[D_NI])
        copy_into(kv[2 * nt:4 * nt], locks)
        locks[:] = 0.0
    return code


@njit_inline
def _run(y, f, atol, par, ipar, K, ynew, ys, hist, dns, t_eval, o_t, o_y, o_x, o_xd, o_ext,
         ext, ext_end, x_end, ip, fp, ri, rf, dims, ws, sc, piv, kept, kv):
    """Integrate from ``par[P_T]`` (state ``y``, rates ``f`` when ``ipar[I_FSAL]``) towards
    ``par[P_TEND]``; returns DONE, BATCH, FLAGGED or FAILED (see the module).

    With ``ipar[I_KEEP]`` every accepted step is kept in row ``ipar[I_NKEPT]`` of ``kept``
    (see :func:`~mechdyn.kernels.dop853_dense.keep_step`; at most ``ipar[I_MAXSTEPS]`` rows
    per call), with its dense output (or the stages to make it), and no step is flagged
    for a rate changing sign (the caller checks each).

    Each table with sharp points has its piece held through a step; a step at whose end
    a table variable has left its piece is taken again up to the piece's end (within
    ``ETA`` of the step), and the next piece is held from there (``kv``: the variables at
    the last accepted point | at the step's end | the pieces held between calls).  The
    cuts are regula falsi with Illinois' rule on both sides of the point: where an attempt
    lands past it again, the start's distance is halved; where the step lands short, the
    next ones aim at it over the bracket of its time (``par[P_BRACKET:]``).  A variable
    that leaves its piece at a stage and is back on it at the end has the step cut back to
    that stage (:func:`mechdyn.kernels.held_tables.again`)."""
    ni = dims[D_NI]
    nx = x_end.size // 3
    t = par[P_T]
    rtol = par[P_RTOL]
    off = ipar[I_FSAL] < 0  # False and True at run time (see _counted)
    on = not off
    nt = ip[H_NTAB]
    locks = held_pieces(ws, nx, ni)
    s_old, s_new = kv[:nt], kv[nt:2 * nt]
    s_st = np.empty(nt)  # the table variables at a stage
    if not _pieces_at_start(t, y, f, ip, fp, ri, rf, dims, ws, ext, off, sc, piv, ipar, locks,
                            kv):
        return FAILED
    h = _step_at_start(t, y, f, K, atol, par, ip, fp, ri, rf, dims, ws, ext, off, sc, piv,
                       ipar)
    rejected = False
    # (the counters int64 from the start: a literal 0 would compile the helpers they go to
    # once more, for the literal)
    retried = np.int64(0)  # attempts of this step taken again up to a table's point
    over = np.int64(0)  # of them, those past the same point in a row
    h_full = 0.0  # the step before the first of them
    # a table point a step was taken again up to, kept between calls: the bracket of its
    # time (the end of the last attempt past it: time, variable), how often a step has
    # since landed short of it (Illinois' rule), the variable's travel in the first step
    # past it, the point and its table (see P_BRACKET)
    br = par[P_BRACKET:P_BRACKET + 6]
    switch = False  # the next pieces are held from the end of the step
    ahead = 2.0 * ETA  # (the part of its travel past its end at which a table switches)
    steps = 0
    ws0, wp0 = np.empty(ws.size), 0  # the workspace and watch at a step's start (put back)
    ipar[I_FLAGS] = 0
    while True:
        code, h, hmin, t_new = _step_to_try(t, h, par, ipar, steps, t_eval, o_t.size)
        if code >= 0:
            return _stop(par, t, h, code)
        if not rejected and retried == 0:
            copy_into(ws0, ws)
            wp0 = ipar[I_WPEND]  # a watch armed by an attempt that is not kept is dropped
        ok, first = _stages(t, h, y, f, K, ys, ynew, ip, fp, ri, rf, dims, ws, ext, off, sc,
                            piv, par, ipar, x_end, s_old, s_st, locks)
        if not ok:
            _put_back(ws, ws0)
            return _stop(par, t, h, FAILED)
        err = error_norm(y, ynew, K, atol, rtol, h)
        fac11 = error_factor(err, par[P_BETA])
        if too_large(err):  # rejected
            rejected = True
            retried = 0
            over = 0
            h_full = 0.0
            # a retry starts its solves where the step started, not from the poses of the
            # rejected stages (a long trial step may have jumped to another assembly branch)
            _again(ws, ws0, ipar, wp0)
            h = shrunk(h, err, fac11)
            if h < hmin:
                ipar[I_STATUS] = -1
                return _stop(par, t, h, FAILED)
            continue
        # accepted: the rates at the new point (with every output there when sampled)
        end_sample = _end_sampled(t_new, t_eval, ipar)
        fnew = K[N_STAGES]
        if not _counted(t_new, ynew, fnew, ni, ip, fp, ri, rf, dims, ws, ext_end, end_sample,
                        sc, piv, ipar):
            return _stop(par, t, h, FAILED)
        if nt > 0:  # has a table variable left its piece?
            th, jt, ct, aiming = crossed(t_new, ip, fp, dims, sc, s_old, s_new, locks, br)
            kind = again(th, first, retried, aiming, h, hmin, s_old, jt, ct, br)
            if kind != KEEP:  # the step again
                _again(ws, ws0, ipar, wp0)
                if kind == NEXT_PIECE:
                    if not _next_piece(t, y, f, jt, ip, fp, ri, rf, dims, ws, ws0, ext, off,
                                       sc, piv, ipar, locks, s_old, s_new, br):
                        return _stop(par, t, h, FAILED)
                else:
                    h_full = h if retried == 0 else h_full
                    h, over = shortened(kind, h, hmin, first, t_new, over, aiming, s_old,
                                        s_new, jt, ct, br)
                retried += 1
                continue
            switch, ahead = switch_at(th, aiming, br, s_old, s_new)
        _watch(ynew[0], ws, nx, par, ipar, x_end)
        steps += 1
        ipar[I_STEPS] += 1
        h_next, par[P_ERROLD] = next_step(h, err, fac11, par[P_BETA], par[P_ERROLD])
        h_next = _after_points(h_next, h, h_full, rejected, hmin, t_new, s_new, br)
        aimed = retried > 0  # (a step shortened to a table's point: no stall)
        rejected = False
        retried = 0
        over = 0
        h_full = 0.0
        # what Python must look at, the dense output where it is wanted, the kept row
        flags = _flags(t, h, t_new, y, f, ynew, fnew, ws, x_end, hist, par, ipar, ni, aimed)
        if not _dense_kept(flags, t, h, t_new, y, f, ynew, fnew, K, ys, dns, t_eval, ip, fp,
                           ri, rf, dims, ws, ext, off, sc, piv, ipar, kept):
            return _stop(par, t, h, FAILED)
        # the samples of a step not flagged: t_eval inside it (dense output), then its end
        if flags == 0 and not samples(off, t, h, t_new, y, f, ynew, fnew, dns, ys,
                                      K[N_STAGES + 1], end_sample, t_eval, par, ipar, ip, fp,
                                      ri, rf, dims, ws, ext, ext_end, x_end, on, sc, piv, o_t,
                                      o_y, o_x, o_xd, o_ext):
            return FAILED
        ipar[I_FLAGS] = flags
        if not _switch(switch, ahead, t_new, ynew, fnew, s_old, s_new, ni, ip, fp, ri, rf,
                       dims, ws, ext_end, end_sample, sc, piv, ipar, locks):
            return _stop(par, t, h, FAILED)
        accept(y, f, ynew, fnew, ipar)
        t = t_new
        h = h_next
        if flags != 0:
            return _stop(par, t, h, FLAGGED)
        if ipar[I_WPEND] != 0:
            return _stop(par, t, h, WATCH)


@njit_inline
def _stop(par, t, h, code):
    """The end of a call at ``t``, the step ``h`` to go on with: returns ``code``."""
    par[P_T], par[P_H] = t, h
    return code


@njit
def _flags(t, h, t_new, y, f, ynew, fnew, ws, x_end, hist, par, ipar, ni, aimed):
    """:func:`step_end` (no F_TURN where every step is kept), and F_STALL for a step
    below ``par[P_STALL]`` not shortened to a table's point (``aimed``)."""
    flags = step_end(t, h, t_new, y, f, ynew, fnew, ws, x_end, hist, par, ni,
                     ipar[I_KEEP] == 0)
    if h < par[P_STALL] and not aimed:
        flags |= F_STALL
    return flags


@njit
def evaluate_states(t, Y, reps, ip, fp, ri, rf, dims, ws, sc, piv):
    """Evaluate the kernel ``reps`` times over the states ``Y`` (rows (q_I, q_I')) in order,
    without allocating (the timing loop of the benchmarks); returns the number of
    failures."""
    ni = dims[D_NI]
    out = np.empty(2 * ni + 1)
    ext = np.empty(0)
    bad = 0
    for _ in range(reps):
        for k in range(Y.shape[0]):
            if evaluate_into(t[k], Y[k, :ni], Y[k, ni:], ip, fp, ri, rf, dims, ws, out, ext,
                             reps < 0, sc, piv):  # a runtime False (see _counted)
                bad += 1
    return bad
