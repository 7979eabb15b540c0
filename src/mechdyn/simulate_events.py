"""The segment loop of variable-structure mechanisms: locks, stops, contacts, switches.

The motion is integrated piecewise, one *mode* (the set of active switchable
constraints, :class:`~mechdyn.model.state.Mode`) at a time:

1. in a mode, the independent coordinates q_I (a subset of the declared
   coordinates) are integrated by one segment of
   :func:`mechdyn.integrate.segment.run_segment`, with any integrator of the
   package (DOP853 by default, rtol 1e-10 as every run), the right-hand side on
   the compiled kernel of the mode (:mod:`mechdyn.dynamics.mode_equations`);
   positions are re-solved from q_I at every evaluation, so every constraint of
   the mode holds to round-off, and a singular position of the mode stops the
   run with its time and coordinates;
2. after every accepted step the event functions of the mode
   (:func:`mechdyn.dynamics.switching.event_functions`: switch conditions and
   schedules, gaps of open stops and contacts, forces of closed ones, the friction
   cone of a sticking contact, the slip velocity of a slipping one) and the
   caller's events are evaluated; the first crossing is located by Brent's method
   on the step's dense output;
3. at an event the switch is applied (:func:`mechdyn.dynamics.switching.apply_switch`:
   releases, engagements, the impact, the new mode by complementarity, its
   coordinates) and the next segment starts from the consistent state.

All declared coordinates are recorded in every mode (dependent ones measured on
the pose), so one :class:`~mechdyn.results.trajectory.Trajectory` covers the whole
run; its ``events`` list holds an :class:`~mechdyn.integrate.events.EventRecord`
per switching instant and per caller's event.  Per-sample mode, constraint forces
and forces on the frame are in ``trajectory.stats["variable_structure"]``.
"""

from __future__ import annotations

import math
import time

import numpy as np

from .dynamics.dead_position import diagnose, status_of, turning_point
from .dynamics.friction import friction_joints
from .dynamics.joint_friction import SelfLockingError
from .dynamics.mode_equations import ModeEquations
from .dynamics.modes import switched_model
from .dynamics.run_samples import Samples, finish
from .dynamics.run_start import give_back, start_equations, start_state
from .dynamics.switching import apply_switch, event_functions
from .errors import (
    MechdynError,
    ModelError,
    Status,
    did_you_mean,
)
from .initial_state import initial_state
from .integrate.base import DEFAULT_RTOL, IntegratorOptionError
from .integrate.driver import segment_integrators
from .integrate.events import EventRecord, as_events
from .integrate.segment import (
    Stop,
    arm,
    run_segment,
    user_event_functions,
    user_event_records,
)
from .model import Model
from .model.workspace import Workspace
from .progress import Progress
from .results.events import format_events
from .results.trajectory import Trajectory

__all__ = ["simulate_events", "SwitchEvent", "format_events", "needs_event_loop"]


#: the default point of the frame moment: the ground origin, m
ORIGIN = (0.0, 0.0)

#: a switching instant is an :class:`~mechdyn.integrate.events.EventRecord`, the one record
#: of events in the package (kind ``"engage"``, ``"release"``, ``"impact"`` ...)
SwitchEvent = EventRecord


def needs_event_loop(model: Model) -> bool:
    """True if the model has switches, stops, contacts or coordinate locks (decided when
    it was compiled)."""
    return model.has_switching


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
    ``sink``, ``chunk`` and ``keep``: see :class:`~mechdyn.dynamics.run_samples.Samples`;
    ``workspace``: see :func:`mechdyn.simulate`.

    Returns
    -------
    Trajectory
        See :func:`mechdyn.simulate`.
    """
    wall0 = time.perf_counter()
    model = mech_or_model if isinstance(mech_or_model, Model) else mech_or_model.compile()
    sm = switched_model(model)
    L = model.length_scale
    scale, force_scale = model.tolerance_scale, model.force_scale
    t_end = float(t_end)
    t0 = float(t0)
    if not t_end >= t0:
        raise ModelError(f"t_end must not be before t0 = {t0} s, got {t_end}")
    if atol is None:
        atol = 1e-3 * rtol  # the same default as every integrator of the package
    if small_velocity is None:
        small_velocity = 1e-6 * L
    if gap_tol is None:
        gap_tol = 1e-9 * L
    span = t_end - t0
    if zeno_time is None:
        zeno_time = 1e-4 * span
    if point is not ORIGIN and (np.shape(point) != (2,)
                                or not np.all(np.isfinite(np.asarray(point, float)))):
        raise ModelError(f"point must be a finite (x, y) in m, got {point!r}")
    if min_step is None:
        min_step = 1e-13 * span
    fixed_step = str(getattr(method, "name", method)).lower() in ("wilson", "rk4")
    if max_steps is None:
        max_steps = max(200_000, 2 * int((span / dt if dt else steps or 0) if fixed_step else 0))
    last_impact: dict = {}
    every_step = t_eval is None and dt_out is None  # as a fixed-structure run
    if every_step:
        t_eval = np.zeros(0)
    elif t_eval is None:
        t_eval = t0 + dt_out * np.arange(int(math.floor(span / dt_out + 1e-9)) + 1)
        if t_eval[-1] < t_end - 1e-12 * max(1.0, abs(t_end)):
            t_eval = np.append(t_eval, t_end)
    t_eval = np.asarray(t_eval, float)
    segment_integrator, method_name = segment_integrators(
        method, t0, t_end, rtol=rtol, atol=atol, dt=dt, steps=steps, iterations=iterations,
        tol=tol, theta=theta, first_step=first_step, max_step=max_step)
    user_events = as_events(events)

    # ---------------------------------------------------------------- records
    # per sample: t, the mode system, the evaluation, the work (w_nc and, with friction in
    # the joints, the friction work w_f) and the impact losses so far;
    # forces and energies are computed at the end (with a sink: chunk by chunk), batched
    # over each mode's samples
    rec = Samples(model, sm, point, sink=sink, chunk=chunk, keep=keep)
    events: list[SwitchEvent] = []
    stats = dict(steps=0, rejected=0, evaluations=0, integrator=method_name,
                 formulation=formulation, backend="numpy", rtol=rtol, atol=atol, segments=0,
                 bifurcations=[])
    backends: set = set()
    lost_total = 0.0

    def store(t, ms, ev, w):
        rec.append((t, ms, ev, w, lost_total), stats)

    # ---------------------------------------------------------------- initial state
    status, message = Status.SUCCESS, ""
    locks = sm.initial_locks() if mode is None else frozenset(mode)
    unknown = [n for n in locks if n not in sm.lock_names]
    if unknown:
        raise ModelError("mode: " + did_you_mean(unknown[0], sm.lock_names, "lock"))
    stats["mode"] = sorted(locks)  # the engaged locks at the start
    welds = sorted(locks & set(sm.welds))
    # the run's caches, shared by the mode systems of the run (the caller's, if given)
    ws = (Workspace() if workspace is None else workspace).begin()
    q_init, qd_init, x_guess = initial_state(model, q0, qdot0, mode=welds, workspace=ws)
    t = t0
    # the integrated work: W_nc (every non-conservative force, friction included) and,
    # with friction in the joints, the work W_f lost to it (>= 0)
    w = np.zeros(2 if friction_joints(model) else 1)
    try:
        ms, x, xd, targets, qi, qdi, start = start_state(
            sm, t, locks, q_init, qd_init, x_guess, ws, events, gap_tol=gap_tol,
            small_velocity=small_velocity, force_scale=force_scale)
    except (MechdynError, np.linalg.LinAlgError) as exc:
        if isinstance(exc, ModelError):
            raise
        return finish(model, rec, events, stats, wall0, *_status(exc, None), sm, point)

    just_fired: set = set()
    after_event = False
    good = None  # (t, ModeEval) of the last accepted step: where a failed run was well
    next_out = 0
    fired_once: set = set()
    n_events = 0
    last_event_t, repeat = None, 0
    bar = Progress(progress, t0, t_end)
    first_eqs = kept_eqs = None
    while t < t_end or not stats["segments"]:
        stats["segments"] += 1
        if stats["segments"] == 1:  # kept with the run's start, if it was kept
            eqs, kept_eqs = start_equations(sm, ms, backend, formulation, d, start)
            first_eqs = eqs
        else:
            eqs = ModeEquations(sm, ms, backend, formulation, d)
        backends.add(eqs.backend)
        if eqs.note:
            stats["backend_note"] = eqs.note
        if eqs.kernel is not None:
            stats["compile_time_s"] = eqs.kernel.compile_time
        # the last few states evaluated: the step ends, the event functions and the output
        # samples often meet the same (t, y)
        state_cache: dict = {}

        def evaluate(tt, y, eqs=eqs, cache=state_cache):
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

        y0 = np.concatenate([qi, qdi, w])
        efns = event_functions(sm, ms, t, fired_once, force_scale, gap_tol, L)
        efns += user_event_functions(user_events)
        try:
            ev0 = evaluate(t, y0)
            # the start of the run is an output sample with every_step (else when it is
            # one of t_eval); each segment after an event starts with one
            if after_event or (every_step or stats["segments"] > 1 or t >= t_end) and (
                    rec.last is None or rec.last[0] != t or rec.last[1].mode != ms.mode):
                store(t, ms, ev0, w)
            after_event = False
            good = (t, ev0, ms)
            if t >= t_end:
                break
            arm(efns, t, ev0, just_fired)
            first = None if not just_fired else 1e-7 * (t_end - t0)

            def after_step(step, y, eqs=eqs, evaluate=evaluate, ms=ms):
                nonlocal good
                if not np.isfinite(y).all():
                    raise Stop(Status.NON_FINITE, f"non-finite state at t = {step.t:.9g} s "
                               f"after t = {good[0]:.9g} s")
                turn = turning_point(eqs, step, good[1].qdot[ms.coords], good[1].x)
                if turn is not None:
                    raise Stop(Status.SINGULAR_POSITION, turn)
                ev = evaluate(step.t, y)
                eqs.check_position(step.t, ev.x, ev.q)
                _budget(step, ev, ms, stats, span, min_step, max_steps, fixed_step)
                good = (step.t, ev, ms)
                return ev

            def sample(ts, y, step, ev, ms=ms, evaluate=evaluate):
                if rec.last is not None and rec.last[0] >= ts:
                    return
                store(ts, ms, ev if ev is not None else evaluate(ts, y), y[2 * ms.n_i:].copy())

            integ = segment_integrator(scale[ms.coords], first)
            if w.size > 1 and np.ndim(getattr(integ, "atol", None)):
                integ.atol = np.append(integ.atol, integ.atol[-1])  # W_f: as W_nc
            hit, next_out = run_segment(
                integ, eqs, t, y0, t_end, efns, evaluate=evaluate,
                after_step=after_step, sample=sample, t_eval=t_eval, next_out=next_out,
                every_step=every_step, stats=stats, bar=bar,
                deadline=None if max_wall_time is None else wall0 + max_wall_time, n=ms.n_i)
            if hit is None:
                t = t_end
                break
            # ------------------------------------------------------------ switch
            t_hit, fired, dense = hit
            y_hit = dense(t_hit)
            ev_hit = evaluate(t_hit, y_hit)
            w = y_hit[2 * ms.n_i:].copy()
            if rec.last is None or rec.last[0] != t_hit:
                store(t_hit, ms, ev_hit, w)
            user = [e for e in fired if e.kind == "user"]
            fired = [e for e in fired if e.kind != "user"]
            events.extend(user_event_records(user, t_hit, np.concatenate([ev_hit.q, ev_hit.qdot]),
                                             model.n_q))
            if any(e.data.terminal for e in user):
                raise Stop(Status.EVENT, f"terminal event {user[0].key!r} at t = {t_hit:.9g} s")
            just_fired = {(e.kind, e.key) for e in user}
            if not fired:  # only the caller's events: go on in the same mode
                t = t_hit
                qi, qdi = y_hit[:ms.n_i], y_hit[ms.n_i:2 * ms.n_i]
                continue
            n_before = len(events)
            plastic = {k for k, tl in last_impact.items() if t_hit - tl <= zeno_time}
            ms_new, x, xd, lost = apply_switch(sm, t_hit, ms, ev_hit.x, ev_hit.xdot, targets,
                                               events, fired=fired,
                                               small_velocity=small_velocity,
                                               gap_tol=gap_tol, force_scale=force_scale,
                                               plastic=plastic)
            for ev_ in events[n_before:]:
                if getattr(ev_, "kind", None) == "impact":
                    last_impact[ev_.element] = t_hit
            for e in fired:
                if e.kind == "switch" and e.data[0].once and len(events) > n_before \
                        and any(getattr(ev, "kind", None) in ("engage", "release")
                                and ev.element == e.key for ev in events[n_before:]):
                    fired_once.add(e.key)
                if e.kind == "time":
                    fired_once.add((e.key, e.data[1]))
            lost_total += lost
            n_events += 1
            if last_event_t is not None and t_hit - last_event_t <= 1e-12 * max(1, abs(t_hit)):
                repeat += 1
                if repeat > 50:
                    raise Stop(Status.TOO_MANY_EVENTS, f"switching does not settle at t = "
                                f"{t_hit:.9g} s (more than 50 events at the same instant)")
            else:
                repeat = 0
            last_event_t = t_hit
            if n_events >= max_events:
                raise Stop(Status.TOO_MANY_EVENTS, f"stopped after {max_events} switching events "
                            f"at t = {t_hit:.9g} s")
            just_fired |= {(e.kind, e.key) for e in fired}
            ms = ms_new
            t = t_hit
            qi, qdi = ms.independent(x, xd)
            after_event = True  # the state after it: the first sample of the next segment
        except Stop as exc:
            status, message = exc.status, exc.message
            break
        except KeyboardInterrupt:
            status = Status.INTERRUPTED
            t_last = t if rec.last is None else rec.last[0]
            message = (f"interrupted (Ctrl-C) after t = {t_last:.9g} s; "
                       f"the samples computed so far are kept")
            break
        except (MechdynError, np.linalg.LinAlgError, ValueError, ArithmeticError) as exc:
            if isinstance(exc, IntegratorOptionError):
                raise
            status, message = _status(exc, good)
            break
        finally:
            stats["bifurcations"] += eqs.report()
    if after_event:  # the run ended before the next segment stored the state after it
        store(t, ms, ms.evaluate_x(t, x, xd), w)
    stats["backend"] = "numba" if backends == {"numba"} else (
        "numpy" if backends <= {"numpy"} else "numba+numpy")
    bar.close()
    give_back(ws, first_eqs, kept_eqs)  # for the next run from the same start
    return finish(model, rec, events, stats, wall0, status, message, sm, point)


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
    if stats["steps"] > max_steps:  # the steps within the budget are all recorded
        raise Stop(Status.BUDGET, f"step budget exhausted after t = {step.t_old:.9g} s "
                                  f"({max_steps} steps; raise max_steps to go on)")
