"""The segment loop of variable-structure mechanisms: locks, stops, contacts, switches.

The motion is integrated piecewise, one *mode* (the set of active switchable
constraints, :class:`~mechdyn.model.state.Mode`) at a time:

1. in a mode, the independent coordinates q_I (a subset of the declared
   coordinates) are integrated by one segment of
   :func:`mechdyn.integrate.segment.run_segment`, with any integrator of the
   package (DOP853 by default, rtol 1e-10 as every run), the right-hand side on
   the compiled kernel of the mode (:mod:`mechdyn.dynamics.mode_equations`), in
   the kernel's compiled loop where it can run
   (:func:`mechdyn.simulate.compiled_loop.integrate_segment`);
   positions are re-solved from q_I at every evaluation, so every constraint of
   the mode holds to round-off, and a singular position of the mode stops the
   run with its time and coordinates;
2. after every accepted step the event functions of the mode
   (:func:`mechdyn.simulate.switching.event_functions`: switch conditions and
   schedules, gaps of open stops and contacts, forces of closed ones, the friction
   cone of a sticking contact, the slip velocity of a slipping one) and the
   caller's events are evaluated; the first crossing is located by Brent's method
   on the step's dense output;
3. at an event the switch is applied (:func:`mechdyn.simulate.switching.apply_switch`:
   releases, engagements, the impact, the new mode by complementarity, its
   coordinates) and the next segment starts from the consistent state.

All declared coordinates are recorded in every mode (dependent ones measured on
the pose), so one :class:`~mechdyn.results.trajectory.Trajectory` covers the whole
run; its ``events`` list holds an :class:`~mechdyn.integrate.events.EventRecord`
per switching instant and per caller's event.  Per-sample mode, constraint forces
and forces on the frame are in ``trajectory.switching``
(``trajectory.stats.variable_structure``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..dynamics.dead_position import diagnose, status_of, turning_point
from ..dynamics.mode_equations import ModeEquations
from ..errors import (
    MechdynError,
    ModelError,
    Status,
    did_you_mean,
)
from ..friction.forward import SelfLockingError
from ..friction.law import friction_joints
from ..initial_state import initial_state
from ..integrate.base import DEFAULT_RTOL, IntegratorOptionError
from ..integrate.driver import segment_integrators
from ..integrate.events import EventRecord, as_events
from ..integrate.segment import (
    Stop,
    arm,
    user_event_functions,
    user_event_records,
)
from ..model import Model
from ..model.switchable import switched_model
from ..model.workspace import Workspace
from ..progress import Progress
from ..results.events import format_events
from ..results.records import RunCounters
from ..results.trajectory import Trajectory
from .compiled_loop import integrate_segment
from .run_start import give_back, start_equations, start_state
from .samples import Samples, finish
from .switching import apply_switch, event_functions

__all__ = ["simulate_events", "SwitchEvent", "format_events", "needs_event_loop",
           "LoopOptions", "loop_options", "output_times"]


#: the default point of the frame moment: the ground origin, m
ORIGIN = (0.0, 0.0)

#: a switching instant is an :class:`~mechdyn.integrate.events.EventRecord`, the one record
#: of events in the package (kind ``"engage"``, ``"release"``, ``"impact"`` ...)
SwitchEvent = EventRecord


def needs_event_loop(model: Model) -> bool:
    """True if the model has switches, stops, contacts or coordinate locks (decided when
    it was compiled)."""
    return model.has_switching


@dataclass(frozen=True)
class LoopOptions:
    """The tolerances and budgets of the segment loop (SI units), made by
    :func:`loop_options` from the keywords of :func:`mechdyn.simulate`.

    Attributes
    ----------
    t0, t_end : float
        Start and end of the run, s.
    small_velocity : float
        Rates below it count as rest at a switch, m/s (angles: rad/s over the length
        scale).
    gap_tol : float
        Gaps below it count as touching, m.
    zeno_time : float
        Impacts of one element closer than this are made plastic, s.
    min_step : float
        The smallest step of an adaptive integrator, s.
    max_steps, max_events : int
        The budgets of steps and of switching events.
    max_wall_time : float or None
        The budget of wall time, s.
    fixed_step : bool
        Whether the integrator is a fixed-step one (no step-size checks).
    point : tuple of float
        The point of the frame moment, m.
    """

    t0: float
    t_end: float
    small_velocity: float
    gap_tol: float
    zeno_time: float
    min_step: float
    max_steps: int
    max_events: int
    max_wall_time: float | None
    fixed_step: bool
    point: tuple

    @property
    def span(self) -> float:
        """t_end - t0, s."""
        return self.t_end - self.t0


def loop_options(model: Model, t0, t_end, *, method, small_velocity=None, gap_tol=None,
                 zeno_time=None, min_step=None, max_steps=None, max_events=100000,
                 max_wall_time=None, point=ORIGIN, dt=None, steps=None) -> LoopOptions:
    """The loop's options with their defaults (scaled by the model's length scale and the
    run's span).

    Raises
    ------
    ModelError
        ``t_end`` before ``t0``, or a ``point`` that is not a finite (x, y).

    Examples
    --------
    >>> import mechdyn
    >>> model = mechdyn.examples.load("slider_crank").compile()
    >>> o = loop_options(model, 0.0, 2.0, method="dop853")
    >>> o.min_step, o.zeno_time, o.max_steps
    (2e-13, 0.0002, 200000)
    """
    L = model.length_scale
    t0, t_end = float(t0), float(t_end)
    if not t_end >= t0:
        raise ModelError(f"t_end must not be before t0 = {t0} s, got {t_end}")
    if point is not ORIGIN and (np.shape(point) != (2,)
                                or not np.all(np.isfinite(np.asarray(point, float)))):
        raise ModelError(f"point must be a finite (x, y) in m, got {point!r}")
    span = t_end - t0
    fixed_step = str(getattr(method, "name", method)).lower() in ("wilson", "rk4")
    if max_steps is None:
        max_steps = max(200_000, 2 * int((span / dt if dt else steps or 0) if fixed_step else 0))
    return LoopOptions(
        t0, t_end, 1e-6 * L if small_velocity is None else small_velocity,
        1e-9 * L if gap_tol is None else gap_tol,
        1e-4 * span if zeno_time is None else zeno_time,
        1e-13 * span if min_step is None else min_step, max_steps, max_events,
        max_wall_time, fixed_step, point)


def output_times(t0: float, t_end: float, dt_out, t_eval) -> tuple[np.ndarray, bool]:
    """``(t_eval, every_step)``: the output times of a run (none when every step is an
    output sample, ``every_step`` True), from ``t_eval`` or a spacing ``dt_out``, s.

    Examples
    --------
    >>> output_times(0.0, 0.25, 0.1, None)
    (array([0.  , 0.1 , 0.2 , 0.25]), False)
    """
    if t_eval is None and dt_out is None:  # as a fixed-structure run
        return np.zeros(0), True
    if t_eval is None:
        t_eval = t0 + dt_out * np.arange(int(math.floor((t_end - t0) / dt_out + 1e-9)) + 1)
        if t_eval[-1] < t_end - 1e-12 * max(1.0, abs(t_end)):
            t_eval = np.append(t_eval, t_end)
    return np.asarray(t_eval, float), False


# ============================================================================ main
def simulate_events(mech_or_model, t_end: float, *, q0=None, qdot0=None, t0: float = 0.0,
                    mode=None, rtol: float = DEFAULT_RTOL, atol=None,
                    max_step: float | None = None, dt_out: float | None = None,
                    t_eval=None, method="dop853", max_events: int = 100000,
                    small_velocity: float | None = None, gap_tol: float | None = None,
                    zeno_time: float | None = None,
                    max_wall_time: float | None = None, max_steps: int | None = None,
                    min_step: float | None = None, point=ORIGIN,
                    progress: bool | None = None, dt: float | None = None,
                    steps: int | None = None, iterations: int | None = None,
                    tol: float | None = None, theta: float | None = None,
                    first_step: float | None = None, events=None,
                    backend: str = "auto", formulation: str = "exact",
                    d=None, sink=None, chunk: int = 2000, keep: bool = True,
                    workspace: Workspace | None = None) -> Trajectory:
    """The segment loop that runs every simulation: the keywords of
    :func:`mechdyn.simulate` (``method`` is its ``integrator``) and its ``**switching``
    options, without the checks of the keywords that :func:`mechdyn.simulate` makes.
    ``sink``, ``chunk`` and ``keep``: see :class:`~mechdyn.simulate.samples.Samples`;
    ``workspace``: see :func:`mechdyn.simulate`.

    Returns
    -------
    Trajectory
        See :func:`mechdyn.simulate`.
    """
    wall0 = time.perf_counter()
    model = mech_or_model if isinstance(mech_or_model, Model) else mech_or_model.compile()
    opts = loop_options(model, t0, t_end, method=method, small_velocity=small_velocity,
                        gap_tol=gap_tol, zeno_time=zeno_time, min_step=min_step,
                        max_steps=max_steps, max_events=max_events,
                        max_wall_time=max_wall_time, point=point, dt=dt, steps=steps)
    if atol is None:
        atol = 1e-3 * rtol  # the same default as every integrator of the package
    t_eval, every_step = output_times(opts.t0, opts.t_end, dt_out, t_eval)
    segment_integrator, method_name = segment_integrators(
        method, opts.t0, opts.t_end, rtol=rtol, atol=atol, dt=dt, steps=steps,
        iterations=iterations, tol=tol, theta=theta, first_step=first_step,
        max_step=max_step)
    stats = RunCounters(integrator=method_name, formulation=formulation, backend="numpy",
                        rtol=rtol, atol=atol)
    # per sample: t, the mode system, the evaluation, the work (w_nc and, with friction in
    # the joints, the friction work w_f) and the impact losses so far;
    # forces and energies are computed at the end (with a sink: chunk by chunk), batched
    # over each mode's samples
    sm = switched_model(model)
    rec = Samples(model, sm, opts.point, sink=sink, chunk=chunk, keep=keep)
    loop = _SegmentLoop(model, opts, rec, stats, segment_integrator, as_events(events),
                        t_eval, every_step, (backend, formulation, d), wall0)
    locks = sm.initial_locks() if mode is None else frozenset(mode)
    unknown = [n for n in locks if n not in sm.lock_names]
    if unknown:
        raise ModelError("mode: " + did_you_mean(unknown[0], sm.lock_names, "lock"))
    stats.mode = sorted(locks)  # the engaged locks at the start
    # the run's caches, shared by the mode systems of the run (the caller's, if given)
    ws = (Workspace() if workspace is None else workspace).begin()
    guess = loop.initial(locks, q0, qdot0, ws)
    try:
        start = loop.start(locks, *guess, ws)
    except (MechdynError, np.linalg.LinAlgError) as exc:
        if isinstance(exc, ModelError):
            raise
        return finish(model, rec, loop.events, stats, wall0, *_status(exc, None), sm,
                      opts.point)
    status, message = loop.run(start, Progress(progress, opts.t0, opts.t_end), ws)
    return finish(model, rec, loop.events, stats, wall0, status, message, sm, opts.point)


class _SegmentLoop:
    """One run of the segment loop: the state it advances from segment to segment and
    what it records (see the module's text)."""

    def __init__(self, model, opts: LoopOptions, rec, stats: RunCounters, segment_integrator,
                 user_events, t_eval, every_step, equations, wall0):
        self.model, self.sm, self.opts = model, switched_model(model), opts
        self.rec, self.stats, self.events = rec, stats, []
        self.segment_integrator, self.user_events = segment_integrator, user_events
        self.t_eval, self.every_step, self.equations = t_eval, every_step, equations
        self.deadline = None if opts.max_wall_time is None else wall0 + opts.max_wall_time
        self.lost_total = 0.0
        self.just_fired: set = set()
        self.fired_once: set = set()
        self.last_impact: dict = {}
        self.after_event = False
        self.good = None  # (t, ModeEval, ms) of the last accepted step: where a run was well
        self.next_out = 0
        self.n_events, self.last_event_t, self.repeat = 0, None, 0
        self.backends: set = set()

    def store(self, t, ms, ev, w) -> None:
        """Record an output sample."""
        self.rec.append((t, ms, ev, w, self.lost_total), self.stats)

    # ---------------------------------------------------------------- the start
    def initial(self, locks, q0, qdot0, ws) -> tuple:
        """``(q, qdot, x)``: the initial coordinates, rates and assembled pose
        (:func:`~mechdyn.initial_state.initial_state`)."""
        welds = sorted(locks & set(self.sm.welds))
        self.t = self.opts.t0
        # the integrated work: W_nc (every non-conservative force, friction included) and,
        # with friction in the joints, the work W_f lost to it (>= 0)
        self.w = np.zeros(2 if friction_joints(self.model) else 1)
        return initial_state(self.model, q0, qdot0, mode=welds, workspace=ws)

    def start(self, locks, q_init, qd_init, x_guess, ws):
        """The consistent initial state (:func:`start_state`); returns its key in the
        workspace (None: not kept)."""
        model, sm, o = self.model, self.sm, self.opts
        (self.ms, self.x, self.xd, self.targets, self.qi, self.qdi, key) = start_state(
            sm, self.t, locks, q_init, qd_init, x_guess, ws, self.events, gap_tol=o.gap_tol,
            small_velocity=o.small_velocity, force_scale=model.force_scale)
        return key

    # ---------------------------------------------------------------- the loop
    def run(self, start, bar, ws) -> tuple[str, str]:
        """Integrate segment after segment to the end, a stop or an interruption;
        returns ``(status, message)``."""
        stats, o = self.stats, self.opts
        status, message = Status.SUCCESS, ""
        first_eqs = kept_eqs = None
        while self.t < o.t_end or not stats.segments:
            stats.segments += 1
            if stats.segments == 1:  # kept with the run's start, if it was kept
                eqs, kept_eqs = start_equations(self.sm, self.ms, *self.equations, start)
                first_eqs = eqs
            else:
                eqs = ModeEquations(self.sm, self.ms, *self.equations)
            self._note_backend(eqs)
            evaluate = _evaluator(eqs)
            efns = event_functions(self.sm, self.ms, self.t, self.fired_once,
                                   self.model.force_scale, o.gap_tol, self.model.length_scale)
            efns += user_event_functions(self.user_events)
            try:
                if not self._segment(eqs, evaluate, efns, bar):
                    break
            except Stop as exc:
                status, message = exc.status, exc.message
                break
            except KeyboardInterrupt:
                status = Status.INTERRUPTED
                t_last = self.t if self.rec.last is None else self.rec.last[0]
                message = (f"interrupted (Ctrl-C) after t = {t_last:.9g} s; "
                           f"the samples computed so far are kept")
                break
            except (MechdynError, np.linalg.LinAlgError, ValueError, ArithmeticError) as exc:
                if isinstance(exc, IntegratorOptionError):
                    raise
                status, message = _status(exc, self.good)
                break
            finally:
                stats.bifurcations += eqs.report()
                self._note_compile(eqs)
        if self.after_event:  # the run ended before the next segment stored the state after
            self.store(self.t, self.ms, self.ms.evaluate_x(self.t, self.x, self.xd), self.w)
        b = self.backends
        stats.backend = "numba" if b == {"numba"} else (
            "numpy" if b <= {"numpy"} else "numba+numpy")
        bar.close()
        give_back(ws, first_eqs, kept_eqs)  # for the next run from the same start
        return status, message

    def _note_backend(self, eqs) -> None:
        self.backends.add(eqs.backend)
        if eqs.note:
            self.stats.backend_note = eqs.note
        self._note_compile(eqs)

    def _note_compile(self, eqs) -> None:
        """The compile time of the run so far: the kernel's groups compiled on first use
        (the dynamics when the kernel was made, its loop when the segment ran it)."""
        if eqs.kernel is not None:
            self.stats.compile_time_s = max(self.stats.compile_time_s or 0.0,
                                            eqs.kernel.compile_time)

    def _segment(self, eqs, evaluate, efns, bar) -> bool:
        """Integrate one segment of the mode (its event functions ``efns``) and apply its
        event; False when the run has reached its end."""
        ms, t, o, stats = self.ms, self.t, self.opts, self.stats
        y0 = np.concatenate([self.qi, self.qdi, self.w])
        ev0 = evaluate(t, y0)
        # the start of the run is an output sample with every_step (else when it is
        # one of t_eval); each segment after an event starts with one
        last = self.rec.last
        if self.after_event or (self.every_step or stats.segments > 1 or t >= o.t_end) and (
                last is None or last[0] != t or last[1].mode != ms.mode):
            self.store(t, ms, ev0, self.w)
        self.after_event = False
        self.good = (t, ev0, ms)
        if t >= o.t_end:
            return False
        arm(efns, t, ev0, self.just_fired)
        first = None if not self.just_fired else 1e-7 * o.span
        integ = self.segment_integrator(self.model.tolerance_scale[ms.coords], first)
        if self.w.size > 1 and np.ndim(getattr(integ, "atol", None)):
            integ.atol = np.append(integ.atol, integ.atol[-1])  # W_f: as W_nc
        hit, self.next_out = integrate_segment(
            integ, eqs, t, y0, o.t_end, efns, evaluate=evaluate,
            after_step=self._after_step(eqs, evaluate), sample=self._sampler(evaluate),
            t_eval=self.t_eval, next_out=self.next_out, every_step=self.every_step,
            stats=stats, bar=bar, deadline=self.deadline, n=ms.n_i)
        if hit is None:
            self.t = o.t_end
            return False
        self._switch(hit, evaluate)
        return True

    def _after_step(self, eqs, evaluate):
        """The check of every accepted step: finite, no turning point, position kept,
        within the budgets; the step becomes the last good one."""
        ms, o, stats = self.ms, self.opts, self.stats

        def after_step(step, y):
            good = self.good
            if not np.isfinite(y).all():
                raise Stop(Status.NON_FINITE, f"non-finite state at t = {step.t:.9g} s "
                           f"after t = {good[0]:.9g} s")
            turn = turning_point(eqs, step, good[1].qdot[ms.coords], good[1].x)
            if turn is not None:
                raise Stop(Status.SINGULAR_POSITION, turn)
            ev = evaluate(step.t, y)
            eqs.check_position(step.t, ev.x, ev.q)
            _budget(step, ev, ms, stats, o.span, o.min_step, o.max_steps, o.fixed_step)
            self.good = (step.t, ev, ms)
            return ev
        return after_step

    def _sampler(self, evaluate):
        """The output sample at ``ts`` of a segment (once per time)."""
        ms = self.ms

        def sample(ts, y, step, ev):
            if self.rec.last is not None and self.rec.last[0] >= ts:
                return
            self.store(ts, ms, ev if ev is not None else evaluate(ts, y),
                       y[2 * ms.n_i:].copy())
        return sample

    # ---------------------------------------------------------------- a switch
    def _switch(self, hit, evaluate) -> None:
        """Apply the event that ended a segment: the caller's events are recorded (a
        terminal one stops the run), the switchable elements' change the mode."""
        ms, model = self.ms, self.model
        t_hit, fired, dense = hit
        y_hit = dense(t_hit)
        ev_hit = evaluate(t_hit, y_hit)
        self.w = y_hit[2 * ms.n_i:].copy()
        if self.rec.last is None or self.rec.last[0] != t_hit:
            self.store(t_hit, ms, ev_hit, self.w)
        user = [e for e in fired if e.kind == "user"]
        fired = [e for e in fired if e.kind != "user"]
        self.events.extend(user_event_records(
            user, t_hit, np.concatenate([ev_hit.q, ev_hit.qdot]), model.n_q))
        if any(e.data.terminal for e in user):
            raise Stop(Status.EVENT, f"terminal event {user[0].key!r} at t = {t_hit:.9g} s")
        self.just_fired = {(e.kind, e.key) for e in user}
        if not fired:  # only the caller's events: go on in the same mode
            self.t = t_hit
            self.qi, self.qdi = y_hit[:ms.n_i], y_hit[ms.n_i:2 * ms.n_i]
            return
        self._apply(t_hit, fired, ev_hit)

    def _apply(self, t_hit, fired, ev_hit) -> None:
        """Apply the switchable elements' events at ``t_hit`` and start the next mode."""
        o, events = self.opts, self.events
        n_before = len(events)
        plastic = {k for k, tl in self.last_impact.items() if t_hit - tl <= o.zeno_time}
        ms_new, self.x, self.xd, lost = apply_switch(
            self.sm, t_hit, self.ms, ev_hit.x, ev_hit.xdot, self.targets, events,
            fired=fired, small_velocity=o.small_velocity, gap_tol=o.gap_tol,
            force_scale=self.model.force_scale, plastic=plastic)
        new = events[n_before:]
        for ev_ in new:
            if getattr(ev_, "kind", None) == "impact":
                self.last_impact[ev_.element] = t_hit
        for e in fired:
            if e.kind == "switch" and e.data[0].once and new and any(
                    getattr(ev, "kind", None) in ("engage", "release") and ev.element == e.key
                    for ev in new):
                self.fired_once.add(e.key)
            if e.kind == "time":
                self.fired_once.add((e.key, e.data[1]))
        self.lost_total += lost
        self._count_event(t_hit)
        self.just_fired |= {(e.kind, e.key) for e in fired}
        self.ms, self.t = ms_new, t_hit
        self.qi, self.qdi = ms_new.independent(self.x, self.xd)
        self.after_event = True  # the state after it: the first sample of the next segment

    def _count_event(self, t_hit) -> None:
        """Stop a run whose switching does not settle or exceeds its budget."""
        self.n_events += 1
        last = self.last_event_t
        if last is not None and t_hit - last <= 1e-12 * max(1, abs(t_hit)):
            self.repeat += 1
            if self.repeat > 50:
                raise Stop(Status.TOO_MANY_EVENTS, f"switching does not settle at t = "
                           f"{t_hit:.9g} s (more than 50 events at the same instant)")
        else:
            self.repeat = 0
        self.last_event_t = t_hit
        if self.n_events >= self.opts.max_events:
            raise Stop(Status.TOO_MANY_EVENTS, f"stopped after {self.opts.max_events} "
                       f"switching events at t = {t_hit:.9g} s")


def _evaluator(eqs):
    """``evaluate(t, y)`` of a segment's equations, keeping the last few states
    evaluated: the step ends, the event functions and the output samples often meet the
    same (t, y)."""
    cache: dict = {}

    def evaluate(tt, y):
        n_i = eqs.ms.n_i
        key = (tt, y.tobytes())
        ev = cache.get(key)
        if ev is not None:
            return ev
        ev = eqs.evaluate(tt, y[:n_i], y[n_i:2 * n_i])
        if len(cache) >= 8:
            del cache[next(iter(cache))]
        cache[key] = ev
        return ev
    return evaluate


def _status(exc, good):
    """(status, message) of the error that ended a run (:func:`diagnose`), with friction
    locking the pairs as ``"self-locking"``."""
    if isinstance(exc, SelfLockingError):
        return Status.SELF_LOCKING, str(exc)
    return status_of(exc) if good is None else diagnose(exc, good)


#: steps below this fraction of the run, where sigma_min/sigma_max of the position
#: Jacobian is below APPROACH_RCOND, are a dead position being approached
STALL, APPROACH_RCOND = 1e-7, 1e-5


def _budget(step, ev, ms, stats, span, min_step, max_steps, fixed_step) -> None:
    """Stop a run whose steps became too small or too many (with the data kept).

    Raises
    ------
    Stop
        ``"step-too-small"``, ``"budget-exhausted"`` or, where the steps shrink at a
        nearly singular position, ``"singular-position"``.
    """
    h = step.t - step.t_old
    if not fixed_step and 0 < h < STALL * span:
        where = f"at t = {step.t:.9g} s"
        rep = ms.singularity(ev.x)
        if rep["rcond"] < APPROACH_RCOND:
            raise Stop(Status.SINGULAR_POSITION, (
                f"dead position approached {where}: the step size fell to {h:.3g} s where "
                f"sigma_min/sigma_max of the position Jacobian is {rep['rcond']:.2e}; "
                f"coordinate(s) {', '.join(rep['coordinates']) or '-'} lose control"))
        if h < min_step:
            raise Stop(Status.STEP_TOO_SMALL, (
                f"step size fell below {min_step:.3g} s {where} (h = {h:.3g} s): the "
                f"motion is too fast for the requested tolerance"))
    if stats.steps > max_steps:  # the steps within the budget are all recorded
        raise Stop(Status.BUDGET, f"step budget exhausted after t = {step.t_old:.9g} s "
                                  f"({max_steps} steps; raise max_steps to go on)")
