"""One segment of a run: integrate one set of equations until an event or the end.

Every run is a sequence of segments (a fixed-structure run usually has one; a
variable-structure run one per mode, joined at its switches and impacts).  A
segment integrates y = (q_I, q_I', w) with one integrator of
:mod:`mechdyn.integrate` through its one contract (``Integrator.integrate``,
yielding steps with a dense output), calls back after every accepted step (the
caller's checks: singular positions, non-finite values), watches the event
functions, locates the first crossing by Brent's method on the step's dense
output, and hands the output samples to the caller.  Nothing here knows bodies.

Event functions fire when they fall to zero or below (:class:`EventFunction`): a
switch condition, a gap, a force, a caller's event ``g(t, q, qdot)`` (rising ones
watched as -g); after a firing they re-arm only once positive again.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import Status
from .events import EventRecord

__all__ = ["EventFunction", "Stop", "run_segment", "locate",
           "user_event_functions", "arm", "user_event_records"]


class Stop(Exception):
    """A run that cannot go on: ``status`` (:class:`~mechdyn.errors.Status`) and a
    ``message`` naming when and where."""

    def __init__(self, status, message):
        self.status, self.message = status, message
        super().__init__(message)


@dataclass
class EventFunction:
    """An event function of a segment: ``fn(t, ev)`` fires at a fall to zero or below.

    Attributes
    ----------
    kind : str
        ``"switch"``, ``"time"``, ``"gap"``, ``"force"``, ``"cone"``, ``"slip"`` or
        ``"user"`` (a caller's event).
    key : str
        The element (or event name) concerned.
    fn : callable
        ``fn(t, ev) -> float`` with ``ev`` the evaluation of the state (see
        :func:`run_segment`).
    hard : float
        Fire at once where ``fn`` is below ``-hard`` (a missed crossing).
    data : object
        What the caller needs to act on it.
    armed, fresh : bool
        Whether a fall fires; whether it fired at the start of this segment.
    arm : float
        After a firing, re-arm only above this value.
    """

    kind: str
    key: str
    fn: Callable
    hard: float
    data: object = None
    armed: bool = False
    arm: float = 0.0
    fresh: bool = False


def user_event_functions(user_events) -> list[EventFunction]:
    """The caller's events g(t, q, qdot) over the declared coordinates as event functions
    (``ev.q``, ``ev.qdot``); a rising event is watched as -g, a two-way one both ways."""
    out = []
    for ev in user_events:
        for d in ((1, -1) if ev.direction == 0 else (ev.direction,)):
            sign = -1.0 if d > 0 else 1.0
            out.append(EventFunction(
                "user", ev.name, lambda tt, me, ev=ev, sign=sign: sign * ev(tt, me.q, me.qdot),
                np.inf, ev))
    return out


def arm(efns, t: float, ev, fresh) -> None:
    """Arm the event functions at the start of a segment: those positive at (t, ev)
    and not among ``fresh`` (``(kind, key)`` of the events that fired at t)."""
    for e in efns:
        e.fresh = (e.kind, e.key) in fresh
        e.armed = e.fn(t, ev) > 0 and not e.fresh


def user_event_records(fired, t: float, y, n: int) -> list:
    """An :class:`~mechdyn.integrate.events.EventRecord` per caller's event that fired at
    ``t``; ``y`` = (q, q', ...) there with ``n`` coordinates."""
    q, qdot = np.array(y[:n]), np.array(y[n:2 * n])
    return [EventRecord(float(t), "event", e.key, q_before=q, qdot_before=qdot, q_after=q,
                        qdot_after=qdot) for e in fired if e.kind == "user"]


def locate(cands, t_old: float, t_new: float, dense: Callable, evaluate: Callable):
    """The first of the candidate events crossed in (t_old, t_new], by Brent's method
    on the step's dense output: ``(t_hit, events at t_hit, dense)``."""

    def gfun(s, e):
        return e.fn(s, evaluate(s, dense(s)))

    from scipy.optimize import brentq
    roots = []
    for e in cands:
        a_val = gfun(t_old, e)
        t_a = t_old
        if a_val <= 0:
            # started at (or just below) zero: look for the positive excursion inside
            # the step before the crossing
            h_ = t_new - t_old
            probes = np.concatenate([t_old + h_ * 2.0 ** -np.arange(30, 0, -1),
                                     np.linspace(t_old, t_new, 33)[1:-1]])
            for s_ in np.unique(probes):
                if gfun(s_, e) > 0:
                    t_a, a_val = s_, 1.0
                    break
        if a_val > 0 and gfun(t_new, e) > 0:
            # the step's end has crossed by its own evaluation, not by the dense output's
            # (the two differ by round-off where the end lies on the crossing, as a step
            # ended at a table point that is also a stop): the event at the end
            ts = t_new
        elif a_val > 0:
            ts = brentq(gfun, t_a, t_new, args=(e,), xtol=1e-15,
                        rtol=4 * np.finfo(float).eps, maxiter=200)
            if gfun(ts, e) > 0:  # take the side where the event has happened
                ts = min(np.nextafter(ts, np.inf), t_new)
        else:
            ts = t_old
        roots.append((ts, e))
    roots.sort(key=lambda r: r[0])
    t_hit = roots[0][0]
    tol_sim = 1e-12 * max(1.0, abs(t_hit))
    return t_hit, [e for ts, e in roots if ts <= t_hit + tol_sim], dense


def run_segment(integ, eqs, t: float, y0, t_end: float, efns: list[EventFunction], *,
                evaluate: Callable, after_step: Callable, sample: Callable, t_eval,
                next_out: int, every_step: bool, stats, bar=None,
                deadline: float | None = None, n: int | None = None, steps=None):
    """Integrate one segment from ``t`` until the first event or ``t_end``.

    Parameters
    ----------
    integ : Integrator
        The segment's integrator (settings only).
    eqs
        ``rhs(t, q_I, q_I') -> (q_I'', p)`` and ``first_order_function()``.
    y0 : ndarray, shape (2 n + n_w,)
        (q, q', w) at ``t``.
    efns : list of EventFunction
        Armed by the caller.
    evaluate : callable
        ``evaluate(t, y) -> ev``, what the event functions read.
    after_step : callable
        ``after_step(step, y) -> ev or None`` after every accepted step (the caller's
        checks; raises :class:`Stop` or an error to end the run); a returned ``ev``
        is the evaluation at the step end.
    sample : callable
        ``sample(t, y, step, ev)``: an output sample (``step`` is the step it falls in,
        ``ev`` the evaluation at the step end when the sample is the step end, else
        None).
    t_eval : ndarray
        Output times (``next_out`` is the first not yet sampled); with ``every_step``
        the end of every step is sampled too.
    stats
        Counters with the attributes ``steps``, ``rejected``, ``evaluations``, counted
        in it (:class:`~mechdyn.integrate.base.IntegratorStats`, or the run's
        :class:`~mechdyn.results.records.RunCounters`).
    deadline : float, optional
        ``time.perf_counter()`` value after which the run stops (status timeout).
    n : int, optional
        Number of coordinates q (default: one quadrature state w, n = (len(y0) - 1) / 2).
    steps : iterator of Step, optional
        The segment's steps taken elsewhere (a generator with ``close``: the compiled
        loop of a mode's kernel, :func:`mechdyn.simulate.compiled_loop.integrate_segment`),
        checked here as the integrator's; by default ``integ.integrate`` takes them.

    Returns
    -------
    hit : tuple or None
        ``(t_hit, fired event functions, dense)``; None at ``t_end``.
    next_out : int
    """
    n = (np.size(y0) - 1) // 2 if n is None else n
    y0 = np.asarray(y0, float)
    if steps is None:
        steps = integ.integrate(eqs.rhs, t, y0[:n], y0[n:2 * n], t_end, w0=y0[2 * n:],
                                first_order=eqs.first_order_function())
    # the solves of every attempt of a step start from the state accepted last, and a failed
    # solve rejects the attempt (see ModeEquations.anchor): adaptive integrators only, and
    # not LSODA (its Fortran takes NaN rates into the state instead of rejecting the step)
    reject = getattr(integ, "method", None) != "LSODA"
    anchor = getattr(eqs, "anchor", None) if integ.adaptive else None
    anchor = (lambda: None) if anchor is None else (lambda a=anchor: a(reject))
    anchor()
    hit = None
    try:
        for step in steps:
            anchor()
            stats.steps += 1
            t_old, t_new = step.t_old, step.t
            if bar is not None:
                bar.update(t_new)

            def dense(s_, step=step):
                return np.concatenate(step.dense(s_))

            y_new = np.concatenate([step.q, step.qdot, step.w])
            ev_new = after_step(step, y_new)
            gs = []
            if efns:
                if ev_new is None:
                    ev_new = evaluate(t_new, y_new)
                gs = [e.fn(t_new, ev_new) for e in efns]
                cands = [e for e, g in zip(efns, gs, strict=True)
                         if (e.armed and g <= 0) or g < -e.hard]
                if cands:
                    hit = locate(cands, t_old, t_new, dense, evaluate)
                    t_new = hit[0]
            while next_out < t_eval.size and t_eval[next_out] <= t_new:
                to = t_eval[next_out]
                at_end = to >= step.t
                sample(to, y_new if at_end else dense(to), step, ev_new if at_end else None)
                next_out += 1
            if hit is not None:
                break
            if every_step:
                sample(t_new, y_new, step, ev_new)
            for e, g in zip(efns, gs, strict=True):
                if g > 0 and (not e.fresh or g > e.arm):
                    e.armed = True
            if deadline is not None and time.perf_counter() > deadline:
                raise Stop(Status.TIMEOUT, f"stopped on the wall-time limit at "
                           f"t = {t_new:.9g} s")
    finally:
        steps.close()
        stats.rejected += integ.stats.rejected
        stats.evaluations += integ.stats.evaluations
    return hit, next_out

