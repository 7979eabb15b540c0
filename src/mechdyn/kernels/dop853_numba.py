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
:class:`mechdyn.dynamics.compiled_loop.LoopBuffers`): ``par`` (float) and ``ipar`` (int)
hold the scalars named by the ``P_*`` and ``I_*`` indices below.
"""

from __future__ import annotations

import numpy as np

from ..integrate.dop853_tableau import E3, E5, N_STAGES, C
from .dop853_dense import dense_at, dense_coefficients, keep_step, kept_offsets, stage
from .held_tables import aim, cut_back, hold, left, table_vars
from .hermite_numba import hermite_at
from .lagrange_numba import D_NI, N_FLAGS, W_COUNT, W_PIVOT, evaluate_into, held_pieces
from .loads_numba import H_NB, H_NTAB
from .rows_numba import njit
from .table_regions import ETA

__all__ = ["run", "evaluate_states", "DONE", "BATCH", "FLAGGED", "FAILED", "WATCH",
           "F_TURN", "F_PIVOT", "F_STALL", "P_T", "P_TEND", "P_H", "P_RTOL",
           "P_HMAX", "P_STALL", "P_PIVOT", "P_WC0", "P_WC1", "P_LAST", "P_TOLD", "P_HOLD",
           "I_EVALS", "I_STEPS", "I_REJ", "I_NOUT", "I_NEXT", "I_FLAGS", "I_FSAL",
           "I_EVERY", "I_WATCH", "I_MAXSTEPS", "I_STATUS", "I_PREV", "I_WPEND", "P_WS",
           "I_KEEP", "I_NKEPT", "I_CTRL", "P_BRACKET", "step_end", "accept", "samples",
           "N_PAR", "N_IPAR"]

# return codes of run
DONE, BATCH, FLAGGED, FAILED, WATCH = 0, 1, 2, 3, 4
# flags of a FLAGGED step
F_TURN, F_PIVOT, F_STALL = 1, 2, 8
# par: time, end, step, rtol, largest step, stall step, pivot ratio to check, watch window
# (centre, half width), last sample time, start and size of the last step, coordinate of a
# watch due, step control (beta, last error), and from P_BRACKET six values: the bracket of
# the time of a table point a step was taken again up to (inf: none; see _run)
P_T, P_TEND, P_H, P_RTOL, P_HMAX, P_STALL, P_PIVOT, P_WC0, P_WC1, P_LAST, P_TOLD, P_HOLD, \
    P_WS, P_BETA, P_ERROLD, P_BRACKET = range(16)
N_PAR = P_BRACKET + 6
# ipar: evaluations, accepted and rejected steps, samples in the buffers, next t_eval,
# flags, f valid, every step sampled, watch on, steps per call, kernel status, history,
# a watch due, every step kept (with its dense output) in ``kept``, steps kept, SciPy's
# step control (its starting step, step factors within [0.2, 10], a step accepted below an
# error of 1, no stretch of the last step) instead of Hairer's
I_EVALS, I_STEPS, I_REJ, I_NOUT, I_NEXT, I_FLAGS, I_FSAL, I_EVERY, I_WATCH, I_MAXSTEPS, \
    I_STATUS, I_PREV, I_WPEND, I_KEEP, I_NKEPT, I_CTRL = range(16)
N_IPAR = 16


@njit
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
    s_old[:] = s_new
    return True


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
    ws[:] = ws0
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


@njit
def _record(k, ts, y, ws, ext, nx, ni, o_t, o_y, o_x, o_xd, o_ext):
    o_t[k] = ts
    o_y[k, :] = y
    o_x[k, :] = ws[:nx]
    o = nx + ni + nx * ni
    o_xd[k, :] = ws[o:o + nx]
    o_ext[k, :] = ext


@njit
def _sizes2(y, f, atol, rtol):
    """(|y|^2, |f|^2) in the error weights 1 / (atol_i + rtol |y_i|), for the starting
    step."""
    dny = 0.0
    dnf = 0.0
    for i in range(y.size):
        sk = atol[i] + rtol * abs(y[i])
        dnf += (f[i] / sk) ** 2
        dny += (y[i] / sk) ** 2
    return dny, dnf


@njit
def _initial_guess(y, f, atol, rtol, hmax):
    """Hairer's starting step for order 8, first part: ``(h, |f|^2)``."""
    dny, dnf = _sizes2(y, f, atol, rtol)
    h = 1e-6 if (dnf <= 1e-10 or dny <= 1e-10) else 0.01 * np.sqrt(dny / dnf)
    return min(h, hmax), dnf


@njit
def _change2(y, f, f1, atol, rtol):
    """sum_i ((f1_i - f_i) / (atol_i + rtol |y_i|))^2, for the starting step."""
    acc = 0.0
    for i in range(y.size):
        sk = atol[i] + rtol * abs(y[i])
        acc += ((f1[i] - f[i]) / sk) ** 2
    return acc


@njit
def _initial_step(y, f, f1, h, dnf, atol, rtol, hmax):
    """Hairer's starting step, second part, from f1 = f(t + h, y + h f)."""
    der2 = np.sqrt(_change2(y, f, f1, atol, rtol)) / h
    der12 = max(der2, np.sqrt(dnf))
    h1 = max(1e-6, h * 1e-3) if der12 <= 1e-15 else (0.01 / der12) ** (1.0 / 8.0)
    return min(100.0 * h, h1, hmax)


@njit
def _scipy_guess(y, f, atol, rtol, span):
    """SciPy's starting step (``select_initial_step``), first part: ``(h0, d1)``, RMS
    norms."""
    d0, d1 = _sizes2(y, f, atol, rtol)
    d0, d1 = np.sqrt(d0 / y.size), np.sqrt(d1 / y.size)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    return min(h0, span), d1


@njit
def _scipy_step(y, f, f1, h0, d1, atol, rtol, hmax, span):
    """SciPy's starting step, second part, from f1 = f(t + h0, y + h0 f)."""
    d2 = np.sqrt(_change2(y, f, f1, atol, rtol) / y.size) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1, span, hmax)


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
    hist[0, :] = hist[1, :]
    hist[1, 0] = t
    hist[1, 1:m + 1] = y
    hist[1, m + 1:] = f
    hist[2, 0] = t_new
    hist[2, 1:m + 1] = ynew
    hist[2, m + 1:] = fnew
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
        o_y[k, :] = ynew
        o_x[k, :] = x_end[:nx]
        o_xd[k, :] = x_end[nx:2 * nx]
        o_ext[k, :] = ext_end
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
        kv[2 * nt:4 * nt] = locks
        locks[:] = 0.0
    return code


@njit
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
    that stage."""
    ni = dims[D_NI]
    nx = x_end.size // 3
    m = y.size
    cap = o_t.size
    n_te = t_eval.size
    t = par[P_T]
    t_end = par[P_TEND]
    rtol = par[P_RTOL]
    hmax = par[P_HMAX]
    every = ipar[I_EVERY] != 0
    off = ipar[I_FSAL] < 0  # False and True at run time (see _counted)
    on = not off
    nt = ip[H_NTAB]
    locks = held_pieces(ws, nx, ni)
    s_old, s_new = kv[:nt], kv[nt:2 * nt]
    s_st = np.empty(nt)  # the table variables at a stage
    if ipar[I_FSAL] == 0:
        locks[:] = 0.0
        if not _counted(t, y, f, ni, ip, fp, ri, rf, dims, ws, ext, off, sc, piv, ipar):
            return FAILED
        table_vars(t, ip, fp, dims, sc, s_old)
        for j in range(nt):
            s_new[j] = s_old[j] + 1.0  # (at a point exactly: the piece above it)
        hold(ip, fp, s_old, s_new, locks, False)
        ipar[I_FSAL] = 1
    else:
        locks[:] = kv[2 * nt:4 * nt]
    h = par[P_H]
    scipy_ctrl = ipar[I_CTRL] != 0
    if not h > 0.0:
        if scipy_ctrl:
            h, dnf = _scipy_guess(y, f, atol, rtol, t_end - t)
        else:
            h, dnf = _initial_guess(y, f, atol, rtol, hmax)
        for i in range(m):
            K[1, i] = y[i] + h * f[i]
        if _counted(t + h, K[1], K[2], ni, ip, fp, ri, rf, dims, ws, ext, off, sc, piv, ipar):
            if scipy_ctrl:
                h = _scipy_step(y, f, K[2], h, dnf, atol, rtol, hmax, t_end - t)
            else:
                h = _initial_step(y, f, K[2], h, dnf, atol, rtol, hmax)
    rejected = False
    retried = 0  # attempts of this step taken again up to a table's point
    over = 0  # of them, those past the same point in a row
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
        if t >= t_end:
            par[P_T], par[P_H] = t, h
            return DONE
        if steps >= ipar[I_MAXSTEPS]:
            par[P_T], par[P_H] = t, h
            return BATCH
        hmin = 10.0 * abs(np.nextafter(t, np.inf) - t)
        h = min(max(h, hmin), hmax)
        last = t + (1.0 if scipy_ctrl else 1.01) * h >= t_end
        if last:
            h = t_end - t
        # room in the buffers for the samples this step can give
        k = ipar[I_NEXT]
        while k < n_te and t_eval[k] <= t + h:
            k += 1
        need = k - ipar[I_NEXT] + (1 if every else 0)
        if ipar[I_NOUT] + need > cap:
            if ipar[I_NOUT] > 0:
                par[P_T], par[P_H] = t, h
                return BATCH
            h = t_eval[ipar[I_NEXT] + cap - 2] - t  # at most cap - 1 samples in a step
            last = False
        t_new = t_end if last else t + h
        # the stages
        if not rejected and retried == 0:
            ws0[:] = ws
            wp0 = ipar[I_WPEND]  # a watch armed by an attempt that is not kept is dropped
        for i in range(m):
            K[0, i] = f[i]
        first = 2.0  # the earliest part of the step at which a stage has left a piece
        for s in range(1, N_STAGES):
            stage(y, K, s, h, ys)
            if not _counted(t + C[s] * h, ys, K[s], ni, ip, fp, ri, rf, dims, ws, ext, off,
                            sc, piv, ipar):
                _put_back(ws, ws0)
                par[P_T], par[P_H] = t, h
                return FAILED
            _watch(ys[0], ws, nx, par, ipar, x_end)
            if nt > 0:
                table_vars(t + C[s] * h, ip, fp, dims, sc, s_st)
                th_s = left(ip, fp, s_old, s_st, locks)[0]
                if th_s <= 1.0:
                    first = min(first, th_s * C[s])
        stage(y, K, N_STAGES, h, ynew)
        # the error estimate (orders 5 and 3)
        e5n = 0.0
        e3n = 0.0
        for i in range(m):
            sk = atol[i] + rtol * max(abs(y[i]), abs(ynew[i]))
            a5 = 0.0
            a3 = 0.0
            for j in range(N_STAGES):
                a5 += E5[j] * K[j, i]
                a3 += E3[j] * K[j, i]
            e5n += (a5 / sk) ** 2
            e3n += (a3 / sk) ** 2
        deno = e5n + 0.01 * e3n
        err = abs(h) * e5n / np.sqrt(m * (deno if deno > 0.0 else 1.0))
        if not err == err:
            err = np.inf
        fac11 = err ** (0.125 - 0.2 * par[P_BETA])
        if err > 1.0 or (scipy_ctrl and err == 1.0):  # rejected
            rejected = True
            retried = 0
            over = 0
            h_full = 0.0
            # a retry starts its solves where the step started, not from the poses of the
            # rejected stages (a long trial step may have jumped to another assembly branch)
            _again(ws, ws0, ipar, wp0)
            if scipy_ctrl:
                h = h * max(0.2, 0.9 * err ** -0.125)
            else:
                h = h / min(3.0, fac11 / 0.9)
            if h < hmin:
                par[P_T], par[P_H] = t, h
                ipar[I_STATUS] = -1
                return FAILED
            continue
        # accepted: the rates at the new point (with every output there when sampled)
        end_sample = every
        k = ipar[I_NEXT]
        while k < n_te and t_eval[k] <= t_new:
            if t_eval[k] >= t_new:
                end_sample = True
            k += 1
        fnew = K[N_STAGES]
        if not _counted(t_new, ynew, fnew, ni, ip, fp, ri, rf, dims, ws, ext_end, end_sample,
                        sc, piv, ipar):
            par[P_T], par[P_H] = t, h
            return FAILED
        if nt > 0:  # has a table variable left its piece?
            table_vars(t_new, ip, fp, dims, sc, s_new)
            th, jt, ct = left(ip, fp, s_old, s_new, locks)
            # (a bracket of this point's time: the criteria relative to the first step
            # past it, not to the short steps that aim at it)
            aiming = br[0] < np.inf and jt == int(br[5]) and ct == br[4]
            if th > 1.0 and ETA < first < 1.0 - ETA and retried < 8:
                # a variable that left its piece and came back within the step (a ram
                # that, on the piece past its stop, would turn round there): the step
                # again, up to where the first stage past the point puts it
                _again(ws, ws0, ipar, wp0)
                if retried == 0:
                    h_full = h
                retried += 1
                h = max(first * h * (1.0 + 0.5 * ETA), hmin)
                continue
            if th <= 1.0 and retried < 8:
                if th <= ETA or th * h <= hmin or (
                        aiming and abs(s_old[jt] - ct) <= ETA * br[3]):  # at the point already
                    br[0] = np.inf  # (the next piece)
                    _again(ws, ws0, ipar, wp0)
                    hold(ip, fp, s_old, s_new, locks, True, jt)
                    if not _counted(t, y, f, ni, ip, fp, ri, rf, dims, ws, ext, off, sc, piv,
                                    ipar):
                        par[P_T], par[P_H] = t, h
                        return FAILED
                    ws0[:] = ws
                    retried += 1
                    continue
                if th < 1.0 - ETA:  # again, up to the point (just past it)
                    _again(ws, ws0, ipar, wp0)
                    if retried == 0:
                        h_full = h
                    if not aiming:
                        br[3] = abs(s_new[jt] - s_old[jt])
                    if not aiming or t_new < br[0]:
                        br[0], br[1], br[2] = t_new, s_new[jt], 0.0
                    over = over + 1 if aiming else 1
                    br[4], br[5] = ct, jt
                    retried += 1
                    h = cut_back(s_old[jt], s_new[jt], ct, over) * h * (1.0 + 0.5 * ETA)
                    continue
            switch = th <= 1.0  # past the point by at most ETA of the step: next piece
            ahead = 2.0 * ETA
            if switch and aiming:
                br[0] = np.inf
            jl = int(br[5])
            if not switch and br[0] < np.inf and abs(s_new[jl] - br[4]) <= ETA * br[3]:
                switch = True  # just short of it (by ETA of the first step past it): as well
                ahead = min(1.0, max(ahead, 2.0 * ETA * br[3] / max(abs(s_new[jl] - s_old[jl]),
                                                                   1e-300)))
                s_new[jl] = br[4] + (br[1] - br[4]) * ETA  # (for hold: past it)
                br[0] = np.inf
        _watch(ynew[0], ws, nx, par, ipar, x_end)
        steps += 1
        ipar[I_STEPS] += 1
        fac = fac11 / par[P_ERROLD] ** par[P_BETA] if par[P_BETA] != 0.0 else fac11
        par[P_ERROLD] = max(err, 1e-4)
        fac = max(1.0 / 6.0, min(3.0, fac / 0.9))
        h_next = h / fac
        if scipy_ctrl:
            h_next = h * (10.0 if err == 0.0 else min(10.0, 0.9 * err ** -0.125))
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
        rejected = False
        aimed = retried > 0  # (a step shortened to a table's point: no stall)
        retried = 0
        over = 0
        h_full = 0.0
        # what Python must look at
        flags = step_end(t, h, t_new, y, f, ynew, fnew, ws, x_end, hist, par, ni,
                         ipar[I_KEEP] == 0)
        if h < par[P_STALL] and not aimed:
            flags |= F_STALL
        interior = ipar[I_NEXT] < n_te and t_eval[ipar[I_NEXT]] < t_new
        if ipar[I_KEEP] != 0:
            row_ws = kept[ipar[I_NKEPT], kept_offsets(m)[-1]:]
            row_ws[:] = ws
            held_pieces(row_ws, nx, ni)[:] = 0.0  # (a kept workspace holds no pieces)
        made = flags != 0 or interior  # a kept step's is made when it is wanted
        if made:
            for s in range(N_STAGES + 1, N_STAGES + 4):  # the stages of the dense output
                stage(y, K, s, h, ys)
                if not _counted(t + C[s] * h, ys, K[s], ni, ip, fp, ri, rf, dims, ws, ext, off,
                                sc, piv, ipar):
                    par[P_T], par[P_H] = t, h
                    return FAILED
            dense_coefficients(y, ynew, f, fnew, K, h, dns)
        if ipar[I_KEEP] != 0:
            keep_step(kept[ipar[I_NKEPT]], t, h, t_new, y, ynew, fnew, dns, K, made)
            ipar[I_NKEPT] += 1
        if flags != 0:
            ipar[I_FLAGS] = flags
            if not _switch(switch, ahead, t_new, ynew, fnew, s_old, s_new, ni, ip, fp, ri, rf, dims,
                           ws, ext_end, end_sample, sc, piv, ipar, locks):
                par[P_T], par[P_H] = t, h
                return FAILED
            accept(y, f, ynew, fnew, ipar)
            par[P_T], par[P_H] = t_new, h_next
            return FLAGGED
        # the samples of the step: t_eval inside it (dense output), then its end
        if not samples(off, t, h, t_new, y, f, ynew, fnew, dns, ys, K[N_STAGES + 1],
                       end_sample, t_eval, par, ipar, ip, fp, ri, rf, dims, ws, ext, ext_end,
                       x_end, on, sc, piv, o_t, o_y, o_x, o_xd, o_ext):
            return FAILED
        if not _switch(switch, ahead, t_new, ynew, fnew, s_old, s_new, ni, ip, fp, ri, rf, dims, ws,
                       ext_end, end_sample, sc, piv, ipar, locks):
            par[P_T], par[P_H] = t, h
            return FAILED
        accept(y, f, ynew, fnew, ipar)
        t = t_new
        h = h_next
        if ipar[I_WPEND] != 0:
            par[P_T], par[P_H] = t, h
            return WATCH


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
