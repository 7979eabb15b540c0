"""A segment of a run in the compiled loop: the Python side of :mod:`mechdyn.kernels.dop853_numba`.

:func:`integrate_segment` is the segment of the segment loop
(:mod:`mechdyn.simulate.segments`): it decides which path runs it -- the compiled loop
of the mode's kernel, or :func:`mechdyn.integrate.segment.run_segment` stepping from
Python -- and hands the compiled loop's steps (:func:`kept_steps`) or what is left of
the segment (after :func:`fast_forward`) to ``run_segment``, which knows no kernel.  The
loop's arrays and its warm-up runs are the kernel's
(:mod:`mechdyn.dynamics.loop_buffers`).

:func:`fast_forward` runs a segment on a mode's compiled kernel (fixed structure, no
event functions) in the compiled DOP853 loop, batch after batch, and does in Python
only what the caller's callbacks of :func:`mechdyn.integrate.segment.run_segment` need:

* the output samples, recorded by the loop with the full evaluation at each (pose,
  rates, every declared coordinate, the multipliers), handed to ``sample`` as
  :class:`~mechdyn.dynamics.mode_system.ModeEval` records (``step`` is None);
* ``after_step`` on the last step of every batch, and on every step the loop flags with
  the step before it (so that the caller's record of the last good state is fresh): a
  coordinate rate changing sign (a dead position may be near), a small pivot of the
  position Jacobian (below :data:`PIVOT_FLAG`, the threshold of the caller's singularity
  check), a step below :data:`STALL_FLAG` of the segment;
* the watch of the branch charts (:meth:`ChartBook.watch
  <mechdyn.kinematics.branch_chart.ChartBook.watch>`) where it is due, at the first
  evaluation past its window;
* the progress bar and the wall-time limit, once per batch.

It stops early -- the caller goes on with the same DOP853 stepped from Python
(:mod:`mechdyn.integrate.dop853`: the tableau and step control of the loop, never SciPy's
solvers) from the last state it checked, its checks after every step from there --
where the compiled loop cannot: a kernel
failure (the NumPy path then names the cause), a step too small, a branch chart built by
the watch (bifurcation zones are evaluated in Python), or a check at the end of a batch
that stops the run (the step budget: the generic loop then stops at the very step).
"""

from __future__ import annotations

import time

import numpy as np

from ..dynamics.loop_buffers import KEEP_STEPS, buffers
from ..dynamics.mode_system import ModeEval
from ..errors import Status
from ..integrate.base import FixedStep, Step, hermite_dense
from ..integrate.runge_kutta import RungeKutta4
from ..integrate.segment import Stop, run_segment
from ..integrate.wilson import Wilson
from ..kernels import dop853_numba as L
from ..kernels import fixed_step_numba as F
from ..kernels.dop853_dense import dense_at, dense_output, kept_offsets, kept_parts
from ..results.records import RunCounters

__all__ = ["integrate_segment", "fast_forward", "kept_steps", "PIVOT_FLAG", "STALL_FLAG",
           "BATCH_STEPS", "BETA"]

#: pivot ratio of the kernel's LU below which a step is looked at (the value of
#: :data:`mechdyn.dynamics.mode_equations.PIVOT_CHECK`; a test keeps them equal)
PIVOT_FLAG = 1e-5
#: steps below this fraction of the segment are looked at (the stall check of the run)
STALL_FLAG = 1e-7
#: steps per call of the compiled loop (its output samples per call:
#: :data:`mechdyn.dynamics.loop_buffers.BATCH_SAMPLES`)
BATCH_STEPS = 2048
#: exponent of the PI step control (0: Hairer's DOP853 and SciPy's, a step from the last
#: error alone; 0.04 gave 4-10 % fewer evaluations on some runs, more on others)
BETA = 0.0


def _evals(b, ms, n) -> list:
    """The ModeEval records of the first n output samples (views into one copy of each
    block)."""
    nx, _, nq, nc, _ = b.dims
    X, XD, E = b.o_x[:n].copy(), b.o_xd[:n].copy(), b.o_ext[:n].copy()
    rows = ms.independent_rows
    if rows.tolist() == list(range(ms.n_rows)):
        LAM = E[:, nx + 3 * nq:nx + 3 * nq + nc]
    else:
        LAM = np.zeros((n, ms.n_rows))
        LAM[:, rows] = E[:, nx + 3 * nq:nx + 3 * nq + nc]
    XDD, Q, QD, QDD, F = (E[:, a:b] for a, b in ((0, nx), (nx, nx + nq), (nx + nq, nx + 2 * nq),
                                                 (nx + 2 * nq, nx + 3 * nq),
                                                 (nx + 3 * nq + nc, 2 * nx + 3 * nq + nc)))
    return [ModeEval(X[k], XD[k], XDD[k], Q[k], QD[k], QDD[k], LAM[k], F[k]) for k in range(n)]


def _step(b, i0, i1, dense=None) -> Step:
    """The step between history rows i0 and i1 (t | y | f), with the loop's dense output
    or the quintic Hermite interpolant of its ends."""
    _, ni, _, _, m = b.dims
    h0, h1 = b.hist[i0].copy(), b.hist[i1].copy()
    y0, f0, y1, f1 = h0[1:m + 1], h0[m + 1:], h1[1:m + 1], h1[m + 1:]
    if dense is None:  # made on first use (a check that needs no dense output is common)
        made = []

        def d(s):
            if not made:
                made.append(_hermite(h0[0], y0, f0, h1[0], y1, f1, ni))
            return made[0](s)
    else:
        dns, t_old, h = dense

        def d(s):
            out = np.empty(m)
            dense_at(dns, y0, t_old, h, s, out)
            return out[:ni], out[ni:2 * ni], out[2 * ni:]
    return Step(float(h0[0]), float(h1[0]), y1[:ni], y1[ni:2 * ni], f1[ni:2 * ni], y1[2 * ni:],
                d)


def _hermite(t0, y0, f0, t1, y1, f1, ni: int):
    """The quintic Hermite interpolant (:func:`~mechdyn.integrate.base.hermite_dense`) of
    a step's ends, states y = (q_I, q_I', w) and rates f = (q_I', q_I'', P)."""
    return hermite_dense(t0, y0[:ni], y0[ni:2 * ni], f0[ni:2 * ni], y0[2 * ni:], f0[2 * ni:],
                         t1, y1[:ni], y1[ni:2 * ni], f1[ni:2 * ni], y1[2 * ni:], f1[2 * ni:])


def _start(b, integ, t: float, t_end: float) -> np.ndarray:
    """The loop's scalars cleared and set for a segment from ``t`` to ``t_end`` with the
    settings of ``integ``; returns atol, shape (m,)."""
    par, ipar = b.par, b.ipar
    par[:] = 0.0
    ipar[:] = 0
    par[L.P_T], par[L.P_TEND] = t, t_end
    par[L.P_LAST] = -np.inf
    if isinstance(integ, FixedStep):
        wilson = _fixed_method(integ) == F.WILSON
        ipar[F.I_METHOD] = F.WILSON if wilson else F.RK4
        ipar[F.I_ITER] = integ.iterations if wilson else 0
        tol = integ.tol if wilson else None
        par[F.P_TOL] = -1.0 if tol is None else tol
        par[F.P_THETA] = integ.theta if wilson else 1.0
        return np.zeros(b.dims[4])
    par[L.P_H] = integ.first_step or 0.0
    par[L.P_RTOL] = integ.rtol
    par[L.P_HMAX] = integ.max_step or np.inf
    par[L.P_BETA], par[L.P_ERROLD] = BETA, 1e-4
    par[L.P_BRACKET] = np.inf  # no table point aimed at
    atol = np.empty(b.dims[4])
    atol[:] = integ.atol  # a scalar or one value per state
    return atol


def _fixed_method(integ) -> int | None:
    """The fixed-step loop's method of ``integ`` (RK4 or Wilson's), or None (a subclass
    that steps otherwise: its Python stepper)."""
    step = type(integ)._advance
    return F.RK4 if step is RungeKutta4._advance else (
        F.WILSON if step is Wilson._advance else None)


def _loop(kernel, b, integ, y, atol, te, t: float, t_end: float):
    """``(call, fixed)``: ``call()`` runs the compiled loop of ``integ`` once on the
    buffers (DOP853's, or the fixed-step loop over ``integ``'s grid from ``t``); ``fixed``:
    whether it is the fixed-step loop (its flagged steps interpolated as the Python
    stepper's, :func:`~mechdyn.integrate.base.hermite_dense`)."""
    if isinstance(integ, FixedStep):
        grid = integ.grid(t, t_end)
        b.ipar[F.I_GRID] = 0
        return (lambda: F.run(y, b.f, grid, b.par, b.ipar, b.K, b.ynew, b.ys, b.hist, te,
                              b.o_t, b.o_y, b.o_x, b.o_xd, b.o_ext, b.ext, b.ext_end, b.x_end,
                              *kernel.arrays, kernel.ws, b.sc, b.piv, b.kept)), True
    return (lambda: L.run(y, b.f, atol, b.par, b.ipar, b.K, b.ynew, b.ys, b.hist, b.dns, te,
                          b.o_t, b.o_y, b.o_x, b.o_xd, b.o_ext, b.ext, b.ext_end, b.x_end,
                          *kernel.arrays, kernel.ws, b.sc, b.piv, b.kept, b.kv)), False


def integrate_segment(integ, eqs, t: float, y0, t_end: float, efns: list, *,
                      evaluate, after_step, sample, t_eval, next_out: int, every_step: bool,
                      stats: RunCounters, bar=None, deadline: float | None = None,
                      n: int | None = None):
    """Integrate one segment of a mode (:func:`mechdyn.integrate.segment.run_segment`), in
    the compiled loop of its kernel where it can run there.

    A segment without event functions runs in the loop as far as it can go
    (:func:`fast_forward`); where the loop hands it over, the method goes on from there
    with the step it had (``integ.going_on(h)``).  A segment with event functions takes
    its steps from the loop (:func:`kept_steps`), each checked by ``run_segment``.  A
    mode whose multipliers are not all the kernel's (redundant rows), an integrator
    without a compiled loop or equations without a kernel step from Python.  The loop's
    group of compiled functions is compiled on first use (:meth:`CompiledKernel.ensure
    <mechdyn.dynamics.compiled.CompiledKernel.ensure>`).

    Parameters
    ----------
    integ, eqs, t, y0, t_end, efns
        As in :func:`mechdyn.integrate.segment.run_segment`; ``eqs`` a
        :class:`~mechdyn.dynamics.mode_equations.ModeEquations` (its ``kernel``).
    evaluate, after_step, sample, t_eval, next_out, every_step, stats, bar, deadline, n
        As in :func:`mechdyn.integrate.segment.run_segment`.

    Returns
    -------
    hit : tuple or None
        ``(t_hit, fired event functions, dense)``; None at ``t_end``.
    next_out : int
    """
    y0 = np.asarray(y0, float)
    kernel, steps = eqs.kernel, None
    if getattr(integ, "compiled", False) and _ready(kernel, integ, eqs, y0):
        if not efns:
            t, y0, next_out, done, h = fast_forward(
                kernel, integ, eqs, t, y0, t_end, after_step=after_step, sample=sample,
                t_eval=t_eval, next_out=next_out, every_step=every_step, stats=stats,
                bar=bar, deadline=deadline)
            if done:
                return None, next_out
            integ = integ.going_on(h) if integ.adaptive else integ
        else:
            steps = kept_steps(kernel, integ, eqs, t, y0, t_end, stats)
    return run_segment(integ, eqs, t, y0, t_end, efns, evaluate=evaluate,
                       after_step=after_step, sample=sample, t_eval=t_eval,
                       next_out=next_out, every_step=every_step, stats=stats, bar=bar,
                       deadline=deadline, n=n, steps=steps)


def _ready(kernel, integ, eqs, y0) -> bool:
    """Whether the compiled loop of ``integ`` can run a segment of ``eqs`` from ``y0`` on
    ``kernel`` (a kernel, every multiplier of the mode its own, one quadrature state);
    where it can, the loop's group is compiled (on first use, its time added to the
    kernel's ``compile_time``)."""
    ms = eqs.ms
    if kernel is None or len(ms.independent_rows) != ms.n_rows or y0.size != 2 * kernel.n_i + 1:
        return False
    kernel.ensure("fixed-step loop" if isinstance(integ, FixedStep) else "integration loop")
    return True


def fast_forward(kernel, integ, eqs, t: float, y0, t_end: float, *, after_step, sample, t_eval,
                 next_out: int, every_step: bool, stats: RunCounters, bar=None,
                 deadline: float | None = None):
    """Integrate a segment on ``kernel`` in the compiled loop of its integrator (DOP853,
    or RK4 and Wilson's method on their grid), as far as it can.

    Parameters
    ----------
    kernel : CompiledKernel
        The mode's kernel (``eqs.kernel``).
    integ : AdaptiveIntegrator or FixedStep
        Tolerances and step bounds (``rtol``, ``atol``, ``first_step``, ``max_step``), or
        the fixed-step integrator (its grid from ``t``, Wilson's settings).
    eqs : ModeEquations
        The mode's equations (its mode system and branch charts).
    t, y0, t_end
        Start, state (q_I, q_I', w) and end of the segment.
    after_step, sample, t_eval, next_out, every_step, stats, bar, deadline
        As in :func:`mechdyn.integrate.segment.run_segment`.

    Returns
    -------
    t : float
        Where the loop stopped (``t_end`` when it got there).
    y : ndarray
        The state there.
    next_out : int
        The first output time not yet sampled.
    done : bool
        Whether ``t_end`` was reached.
    h : float or None
        The step to go on with from ``t`` (the one the loop had there), where the segment
        is handed over; None where the loop took no step.

    Raises
    ------
    Stop
        From ``after_step`` (a dead position, the step budget) or the wall-time limit.
    """
    if isinstance(integ, FixedStep) and _fixed_method(integ) is None:
        return t, np.asarray(y0, float), next_out, False, None
    ms = eqs.ms
    b = buffers(kernel)
    y = np.array(y0, float)
    book = eqs.book
    par, ipar = b.par, b.ipar
    atol = _start(b, integ, t, t_end)
    if not isinstance(integ, FixedStep):  # the stall check is that of the adaptive runs
        par[L.P_STALL] = STALL_FLAG * (t_end - t)
    par[L.P_PIVOT] = PIVOT_FLAG
    ipar[L.I_NEXT] = next_out
    ipar[L.I_EVERY] = int(every_step)
    ipar[L.I_MAXSTEPS] = BATCH_STEPS
    te = np.ascontiguousarray(t_eval, dtype=float)
    counted = [0, 0, 0]
    call, fixed = _loop(kernel, b, integ, y, atol, te, t, t_end)
    if book is not None and book.charts:
        return t, y, next_out, False, None
    _watch_window(book, par, ipar)
    # the last checked state, and the step the loop had there
    mark = (t, y.copy(), next_out, list(counted), kernel.snapshot(), None)
    checked_to = -np.inf  # the end of the last step checked
    while True:
        code = call()
        _account(ipar, stats, counted)
        t_now = float(par[L.P_T])
        # a kernel failure, or a branch chart built by the watch (bifurcation zones are
        # evaluated in Python): the Python stepper goes on from the last checked state
        if code == L.FAILED or not _watched(eqs, b):
            return _rewind(mark, counted, stats, kernel, ipar)
        if code == L.WATCH:
            continue
        if not _check(code, kernel, b, ms, fixed, checked_to, y, t_now, after_step=after_step,
                      sample=sample, te=te, every_step=every_step):
            return _rewind(mark, counted, stats, kernel, ipar)
        checked_to = float(b.hist[2, 0]) if ipar[L.I_STEPS] else checked_to
        mark = (t_now, y.copy(), int(ipar[L.I_NEXT]), list(counted), kernel.snapshot(),
                float(par[L.P_H]))
        if bar is not None:
            bar.update(t_now)
        if code == L.DONE:
            return t_now, y.copy(), int(ipar[L.I_NEXT]), True, None
        if deadline is not None and time.perf_counter() > deadline:
            raise Stop(Status.TIMEOUT, f"stopped on the wall-time limit at t = {t_now:.9g} s")


def _watch_window(book, par, ipar) -> None:
    """The loop's watch of the branch charts set to the window of ``book`` (off where it
    has none)."""
    w = None if book is None else book.watch_window()
    ipar[L.I_WATCH] = w is not None
    if w is not None:
        par[L.P_WC0], par[L.P_WC1] = w


def _watched(eqs, b) -> bool:
    """The watch of the branch charts where the loop found it due (at ``par[P_WS]``, the
    pose in ``x_end``), its window set again; False where it built a chart (the loop
    cannot go on)."""
    par, ipar, book = b.par, b.ipar, eqs.book
    if not ipar[L.I_WPEND]:
        return True
    ipar[L.I_WPEND] = 0
    if eqs.watching and book.watch(float(par[L.P_WS]), b.x_end[2 * b.dims[0]:].copy()) \
            is not None or book.charts:
        return False
    _watch_window(book, par, ipar)
    return True


def _account(ipar, stats, counted: list) -> None:
    """The loop's steps, evaluations and rejected steps since they were last ``counted``
    added to the run's ``stats``."""
    steps, evals, rej = (int(ipar[i]) for i in (L.I_STEPS, L.I_EVALS, L.I_REJ))
    stats.steps += steps - counted[0]
    stats.evaluations += evals - counted[1]
    stats.rejected += rej - counted[2]
    counted[:] = steps, evals, rej


def _rewind(mark, counted: list, stats, kernel, ipar):
    """Back to the last checked state ``mark``: the generic loop takes the steps since then
    one by one, with the caller's checks after each (the exact step budget ...); returns
    what :func:`fast_forward` does."""
    t0_, y0_, next0, (st, _, rej), ws0, h = mark
    stats.steps -= counted[0] - st
    stats.rejected -= counted[2] - rej
    kernel.restore(ws0)
    ipar[L.I_NOUT] = 0
    return t0_, y0_, next0, False, h


def _hand(b, ms, sample) -> None:
    """The output samples in the buffers handed to ``sample`` (and the buffers emptied)."""
    n = int(b.ipar[L.I_NOUT])
    if n:
        T, Y = b.o_t[:n].tolist(), b.o_y[:n].copy()
        for j, ev in enumerate(_evals(b, ms, n)):
            sample(T[j], Y[j], None, ev)
    b.ipar[L.I_NOUT] = 0


def _checked(after_step, step, y_) -> tuple:
    """``(after_step(step, y_), True)``, or ``(None, False)`` where it stops the run."""
    try:
        return after_step(step, y_), True
    except Stop:
        return None, False


def _check(code, kernel, b, ms, fixed: bool, checked_to: float, y, t_now: float, *,
           after_step, sample, te, every_step) -> bool:
    """The caller's checks after a call of the loop that returned ``code``, and the
    samples: a flagged step (:func:`_flagged`), else the batch's last step (unless checked
    already, ``checked_to``); False where a check of a step before the last checked state
    stops the run (the generic loop then goes on from it)."""
    if code == L.FLAGGED:
        return _flagged(kernel, b, ms, fixed, checked_to, y, t_now, after_step=after_step,
                        sample=sample, te=te, every_step=every_step)
    if b.ipar[L.I_STEPS] and b.hist[2, 0] > checked_to:  # the batch's last step
        _, ok = _checked(after_step, _step(b, 1, 2), y.copy())
        if not ok:
            return False
        _hand(b, ms, sample)
    return True


def _flagged(kernel, b, ms, fixed: bool, checked_to: float, y, t_now: float, *, after_step,
             sample, te, every_step) -> bool:
    """A step the loop flagged: the step before it checked (unless checked already; False
    where that stops the run), the samples of the batch handed on, the flagged step
    checked (a stop there is the run's) and its samples made as the generic loop makes
    them."""
    par, ipar, m = b.par, b.ipar, b.dims[4]
    if ipar[L.I_PREV] >= 2 and b.hist[1, 0] > checked_to:
        # the step before (unless checked already): the caller's last good state
        ws_end = kernel.snapshot() if fixed else None
        _, ok = _checked(after_step, _step(b, 0, 1), b.hist[1, 1:m + 1].copy())
        if not ok:
            return False
        if fixed:
            # the flagged step's end evaluated from the pose the loop left there, as in
            # the Python stepper (whose check of the step before came first): the same
            # numbers to round-off (DOP853's compiled runs stay as they were)
            kernel.restore(ws_end)
    _hand(b, ms, sample)
    step = _step(b, 1, 2, None if fixed else (b.dns.copy(), float(par[L.P_TOLD]),
                                              float(par[L.P_HOLD])))
    y_new = y.copy()
    ev = after_step(step, y_new)  # a stop here is the run's
    _samples_of(step, y_new, ev, sample, te, ipar, every_step, t_now)
    return True


def _samples_of(step, y_new, ev, sample, te, ipar, every_step, t_now):
    """The samples of a flagged step (after its check), as the generic loop makes them;
    returns the state for the generic loop to go on from."""
    while ipar[L.I_NEXT] < te.size and te[ipar[L.I_NEXT]] <= t_now:
        to = float(te[ipar[L.I_NEXT]])
        at_end = to >= step.t
        sample(to, y_new if at_end else np.concatenate(step.dense(to)), step,
               ev if at_end else None)
        ipar[L.I_NEXT] += 1
    if every_step:
        sample(t_now, y_new, step, ev)
    return t_now, y_new, int(ipar[L.I_NEXT]), False, None


def kept_steps(kernel, integ, eqs, t: float, y0, t_end: float, stats: RunCounters):
    """The steps of a segment with event functions from the compiled loop of the
    integrator (:func:`_kept_steps`), or None for a fixed-step method the loop does not
    have (its Python stepper takes them)."""
    if isinstance(integ, FixedStep) and _fixed_method(integ) is None:
        return None
    return _kept_steps(kernel, integ, eqs, t, y0, t_end, stats)


def _kept_steps(kernel, integ, eqs, t: float, y0, t_end: float, stats: RunCounters):
    """The steps of a segment with event functions, taken in the compiled loop.

    The loop takes :data:`KEEP_STEPS` steps per call (those after an event are taken in
    vain) and keeps each one with the stages of its dense output of order 7
    (:func:`mechdyn.kernels.dop853_dense.keep_step`), made on first use (the steps in
    which an event function changes sign or a rate turns: 3 evaluations each, where
    every step's would add 15 % to the press cycle's); they are
    yielded one by one as :class:`~mechdyn.integrate.base.Step` records for
    :func:`mechdyn.integrate.segment.run_segment` to check (the caller's checks, the
    event functions and their location on that dense output, the output samples), as
    it checks the steps of the Python stepper.  Before a step is yielded the kernel's
    workspace is put back as it was after the evaluation at the step's end, so that the
    evaluations of the checks start where they would after a Python step; a generator
    closed at an event drops the later steps of its batch.  Where the loop cannot go on
    (a kernel failure, a step too small, a branch chart built by the watch) the steps
    go on with the same DOP853 stepped from Python (``integ.integrate``,
    :mod:`mechdyn.integrate.dop853`) from the last step yielded.  A
    fixed-step integrator's steps come from the fixed-step loop, each with the quintic
    Hermite interpolant of its ends (as its Python stepper's), and its Python stepper
    goes on where the loop cannot.

    Parameters
    ----------
    kernel, integ, eqs, t, y0, t_end
        As in :func:`fast_forward`; ``y0`` (q_I, q_I', w), shape (2 n_i + 1,).
    stats : RunCounters
        The run's ``evaluations`` and ``rejected`` are counted in it (``steps`` by the
        caller); ``integ.stats`` is reset.

    Yields
    ------
    Step
    """
    book = eqs.book
    integ.stats = type(integ.stats)()
    b = buffers(kernel)
    _, ni, _, _, m = b.dims
    y = np.array(y0, float)

    def python_from(t_, y_, h=None):
        # the same method from (t_, y_), with the step the loop had there (as a segment
        # handed over by fast_forward); its counters are integ's, which the caller reads
        cont = integ.going_on(h) if integ.adaptive else integ
        steps = cont.integrate(eqs.rhs, t_, y_[:ni], y_[ni:2 * ni], t_end, w0=y_[2 * ni:],
                               first_order=eqs.first_order_function())
        integ.stats = cont.stats
        return steps

    if book is not None and book.charts:
        yield from python_from(t, y)
        return
    par, ipar = b.par, b.ipar
    atol = _start(b, integ, t, t_end)
    par[L.P_PIVOT] = -np.inf  # every step is checked by the caller
    ipar[L.I_KEEP] = 1
    te = np.zeros(0)
    counted = [0, 0]
    o_ws = kept_offsets(m)[-1]  # the workspace at the row's end
    _watch_window(book, par, ipar)
    ipar[L.I_MAXSTEPS] = min(KEEP_STEPS, b.kept.shape[0])
    call, fixed = _loop(kernel, b, integ, y, atol, te, t, t_end)
    while True:
        ipar[L.I_NKEPT] = 0
        code = call()
        evals, rej = int(ipar[L.I_EVALS]), int(ipar[L.I_REJ])
        stats.evaluations += evals - counted[0]
        stats.rejected += rej - counted[1]
        counted[:] = evals, rej
        nk = int(ipar[L.I_NKEPT])
        rows = b.kept[:nk].copy()
        ws_end = kernel.snapshot()
        for row in rows:
            kernel.restore(row[o_ws:])
            yield _kept_step(row, m, ni, fixed, kernel, stats)
        kernel.restore(ws_end)
        # a kernel failure, or a branch chart built by the watch: the Python stepper
        # of the same method goes on from the last step
        if code == L.FAILED or not _watched(eqs, b):
            yield from python_from(float(par[L.P_T]), y.copy(), float(par[L.P_H]))
            return
        if code == L.DONE:
            return


def _kept_step(row, m: int, ni: int, fixed: bool = False, kernel=None,
               stats: RunCounters | None = None) -> Step:
    """The :class:`Step` of a row of the loop's kept steps, with its dense output (a
    fixed-step loop's: the Python stepper's quintic Hermite interpolant of its ends).  A
    DOP853 step whose dense output the loop did not make gets it on first use
    (:func:`mechdyn.kernels.dop853_dense.dense_output`: three evaluations of ``kernel``
    from the workspace of the step's end, counted in ``stats``; the workspace is put
    back after them)."""
    t0, h, t1, y0, y1, f1, dns, stages, made, ws = kept_parts(row, m)
    if fixed:  # the rates at the step's start in the place of dns[0]
        return Step(t0, t1, y1[:ni], y1[ni:2 * ni], f1[ni:2 * ni], y1[2 * ni:],
                    _hermite(t0, y0, dns[0], t1, y1, f1, ni))
    coeffs = [dns] if made else []
    fallback = []

    def dense(s):
        if not coeffs and not fallback:  # the dense output, or where an evaluation fails,
            saved = kernel.snapshot()   # the quintic Hermite interpolant of the ends
            kernel.restore(ws)
            b = buffers(kernel)
            d = np.empty((7, m))
            st = dense_output(y0, y1, stages, t0, h, *kernel.arrays, kernel.ws, b.sc,
                              b.piv, d)
            kernel.restore(saved)
            if stats is not None:
                stats.evaluations += 3
            if st == 0:
                coeffs.append(d)
            else:
                fallback.append(_hermite(t0, y0, stages[0], t1, y1, f1, ni))
        if fallback:
            return fallback[0](s)
        out = np.empty(m)
        dense_at(coeffs[0], y0, t0, h, s, out)
        return out[:ni], out[ni:2 * ni], out[2 * ni:]

    return Step(t0, t1, y1[:ni], y1[ni:2 * ni], f1[ni:2 * ni], y1[2 * ni:], dense)
