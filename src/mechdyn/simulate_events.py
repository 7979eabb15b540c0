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

from .dynamics.contact import gaps, touching
from .dynamics.dead_position import diagnose, status_of, turning_point
from .dynamics.friction import friction_joints
from .dynamics.impact import frame_impulse_key
from .dynamics.joint_friction import SelfLockingError, stick_slip_joints
from .dynamics.lagrange import kinetic_energy
from .dynamics.mode_equations import ModeEquations
from .dynamics.modes import ModeSystem, switched_model
from .dynamics.reactions import element_forces, element_width, frame_forces, net_on_ground
from .dynamics.switching import apply_switch, event_functions
from .errors import (
    LockupError,
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
from .kernels import rows_numpy as RN
from .model import Model
from .model.workspace import Workspace
from .progress import Progress
from .results.events import format_events
from .results.trajectory import SwitchedSamples, Trajectory

__all__ = ["simulate_events", "SwitchEvent", "format_events", "needs_event_loop"]


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
                    min_step: float | None = None, point=(0.0, 0.0),
                    progress: bool | None = None, dt: float | None = None,
                    steps: int | None = None, iterations: int | None = None,
                    tol: float | None = None, theta: float | None = None,
                    first_step: float | None = None, events=None,
                    backend: str = "auto", formulation: str = "exact",
                    d=None, sink=None, chunk: int = 2000, keep: bool = True) -> Trajectory:
    """The segment loop that runs every simulation: the keywords of
    :func:`mechdyn.simulate` (``method`` is its ``integrator``) and its ``**switching``
    options, without the checks of the keywords that :func:`mechdyn.simulate` makes.
    ``sink``, ``chunk`` and ``keep``: see :class:`Samples`.

    Returns
    -------
    Trajectory
        See :func:`mechdyn.simulate`.
    """
    wall0 = time.perf_counter()
    model = mech_or_model if isinstance(mech_or_model, Model) else mech_or_model.compile()
    sm = switched_model(model)
    L = model.length_scale
    scale = np.where(model.coord_is_angle, 1.0, L)  # of the coordinates' tolerances
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
    if np.shape(point) != (2,) or not np.all(np.isfinite(np.asarray(point, float))):
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
    force_scale = max(float(np.sum(model.mass) * max(np.hypot(*model.gravity), 1.0)), 1.0)
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
    targets: dict = {}
    locks = sm.initial_locks() if mode is None else frozenset(mode)
    unknown = [n for n in locks if n not in sm.lock_names]
    if unknown:
        raise ModelError("mode: " + did_you_mean(unknown[0], sm.lock_names, "lock"))
    stats["mode"] = sorted(locks)  # the engaged locks at the start
    welds = sorted(locks & set(sm.welds))
    q_init, qd_init, x_guess = initial_state(model, q0, qdot0, mode=welds)
    t = t0
    # the integrated work: W_nc (every non-conservative force, friction included) and,
    # with friction in the joints, the work W_f lost to it (>= 0)
    w = np.zeros(2 if friction_joints(model) else 1)
    ws = Workspace()  # the run's caches, shared by the mode systems of the run
    try:
        x = x_guess
        if locks:
            try:  # the pose at which undeclared locks capture what they hold
                free = ModeSystem(sm, frozenset(), targets, x_guess, workspace=ws)
                x = free.solve_position(q_init[free.coords], x_guess, t=t)
            except LockupError:  # the coordinates need the locks: the welded pose
                pass
        for n in locks:
            sm.capture_target(n, x, targets)
        ms = ModeSystem(sm, locks, targets, x, workspace=ws)
        x = ms.solve_position(q_init[ms.coords], x, t=t)
        # rates: given for the independent coordinates of the mode with every
        # touching stop and contact closed (the rest are dependent there)
        touch0 = touching(sm, x, gap_tol=gap_tol)
        ms_t = ModeSystem(sm, locks | frozenset(touch0), targets, x, workspace=ws) \
            if touch0 else ms
        B, _ = ms_t.velocity_analogs(x)
        xd = B @ qd_init[ms_t.coords]
        for tok, (g, is_angle) in gaps(sm, x).items():
            n, side = tok.split("@")
            if g >= -(gap_tol / L if is_angle else gap_tol):
                continue
            if side == "contact":
                raise ModelError(f"contact {n!r}: the initial state penetrates by {-g:.3g} m")
            st, meas = sm.stops[n]
            raise ModelError(f"stop {n!r}: the initial state violates its limits ({meas.label} "
                             f"= {meas.value(x):.9g}, lower {st.lower}, upper {st.upper})")
        if sm.has_switching or stick_slip_joints(model):
            # the mode the state is in: touching stops and contacts, sticking pairs
            ms, x, xd, _ = apply_switch(sm, t, ms, x, xd, targets, events, fired=[],
                                        small_velocity=small_velocity, gap_tol=gap_tol,
                                        force_scale=force_scale, initial=True)
    except (MechdynError, np.linalg.LinAlgError) as exc:
        if isinstance(exc, ModelError):
            raise
        return _finish(model, rec, events, stats, wall0, *_status(exc, None), sm, point)

    qi, qdi = ms.independent(x, xd)
    just_fired: set = set()
    after_event = False
    good = None  # (t, ModeEval) of the last accepted step: where a failed run was well
    next_out = 0
    fired_once: set = set()
    n_events = 0
    last_event_t, repeat = None, 0
    bar = Progress(progress, t0, t_end)
    while t < t_end or not stats["segments"]:
        stats["segments"] += 1
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
                if not np.all(np.isfinite(y)):
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
    return _finish(model, rec, events, stats, wall0, status, message, sm, point)


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


# ============================================================================ output
def element_shapes(model, sm) -> dict:
    """Every element that can carry a force in some mode, with the trailing shape of its
    force: joints (2,) or (3,), coordinate locks, stops and contacts () (see
    :func:`~mechdyn.dynamics.reactions.element_forces`)."""
    out: dict = {j: (element_width(model, j),) for j in model.mechanism.joints}
    for names in (sm.coord_locks, sm.stops, sm.contacts):
        out.update({n: () for n in names if n not in out})
    return out


class Samples:
    """The samples of a run as they are recorded, and their hand-over in chunks.

    Each sample is ``(t, mode system, evaluation, (w_nc[, w_f]), impact losses so far)``.  Without
    a ``sink`` they are all kept and evaluated at the end (:func:`_finish`).  With a
    ``sink``, every ``chunk`` samples are evaluated (forces, frame loads and energies,
    batched over each mode's samples: the numbers of the end-of-run table) into a partial
    :class:`~mechdyn.results.trajectory.Trajectory` that is handed to ``sink(part, start)``
    (``start``: the index of its first row in the run) and, unless ``keep``, dropped; its
    force columns cover every element of the model from the first chunk on (zeros while
    an element is not engaged).

    Parameters
    ----------
    model, sm
        The compiled model and its switchable elements.
    point : (2,) m
        The point of the frame moment.
    sink : callable, optional
    chunk : int
        Samples per chunk (>= 1).
    keep : bool
        Keep every chunk for the Trajectory returned (else it holds the last chunk, and
        ``stats["streamed"]`` the run's row count, first time, energy drift and largest
        constraint residual).

    Raises
    ------
    ModelError
        ``chunk`` is not a positive integer.
    """

    def __init__(self, model, sm, point, *, sink=None, chunk: int = 2000, keep: bool = True):
        if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
            raise ModelError(f"chunk must be a positive number of samples, got {chunk!r}")
        self.model, self.sm, self.point = model, sm, np.asarray(point, float)
        self.sink, self.chunk, self.keep = sink, int(chunk), keep or sink is None
        self.state: tuple = (0, [])  # (samples handed over, samples waiting): set at once
        self.last = None  # the last sample recorded (also once handed over)
        self.modes: list = []  # the modes in the order they appeared, over the whole run
        self.blocks: list = []
        self.shapes = element_shapes(model, sm) if sink is not None else None
        self.streamed: dict = {}
        self.penetration = 0.0

    def append(self, sample, stats) -> None:
        """Record a sample; hand a full chunk to the sink."""
        self.state[1].append(sample)
        self.last = sample
        if self.sink is not None and len(self.state[1]) >= self.chunk:
            self.flush(stats)

    def flush(self, stats) -> None:
        """Evaluate the waiting samples and hand them to the sink."""
        start, rows = self.state
        if not rows:
            return
        block = _block(self.model, self.sm, rows, self.point, self.modes, self.shapes)
        self.sink(_trajectory(self.model, block, self.modes, [], {"mode": stats.get("mode")},
                              Status.SUCCESS, ""), start)
        self.state = (start + len(rows), [])
        bal, res = block["balance"], block["residual"]
        s = self.streamed
        if not s:
            s.update(rows=0, t_first=float(block["t"][0]), balance0=float(bal[0]),
                     energy_drift=0.0, residual=0.0)
        s["rows"] += len(rows)
        s["energy_drift"] = max(s["energy_drift"], float(np.max(np.abs(bal - s["balance0"]))))
        s["residual"] = max(s["residual"], float(np.max(res)))
        self.penetration = max(self.penetration, block["penetration"])
        self.blocks = [*self.blocks, block] if self.keep else [block]


def _block(model, sm, rec, point, modes: list, shapes=None) -> dict:
    """Forces, frame loads and energies of samples ``rec``, batched over each mode's
    samples; ``modes`` (the run's modes so far) is extended by the new ones; ``shapes``
    (element -> trailing shape) makes a force entry of every element listed."""
    n_q, n_x, n = model.n_q, model.n_x, len(rec)
    t = np.array([r[0] for r in rec], float)
    W = np.array([r[3][0] for r in rec], float)
    W_f = np.array([r[3][1] if len(r[3]) > 1 else 0.0 for r in rec], float)
    lost = np.array([r[4] for r in rec], float)
    x, xd, q, qd, qdd = (np.array([getattr(r[2], k) for r in rec], float).reshape(n, w)
                         for k, w in (("x", n_x), ("xdot", n_x), ("q", n_q), ("qdot", n_q),
                                      ("qddot", n_q)))
    frame, res, p_f = np.zeros((n, 3)), np.zeros(n), np.zeros(n)
    forces: dict = {el: np.zeros((n, *shape)) for el, shape in (shapes or {}).items()}
    starts = [k for k in range(n) if k == 0 or rec[k][1] is not rec[k - 1][1]] + [n]
    for a, b in zip(starts[:-1], starts[1:], strict=True):
        ms, sl = rec[a][1], slice(a, b)
        lam = np.array([r[2].lam for r in rec[a:b]], float).reshape(b - a, ms.n_rows)
        parts = RN.Parts(ms.rowset, x[sl])  # the rows' Jacobian and values share them
        R = RN.jacobian(ms.rowset, x[sl], parts)
        # the frame also carries the load elements anchored on it (spring ends, torque
        # reactions) and the stators of the drives between it and the bodies
        _, on_ground, Qd = sm.fm.loads(t[sl], x[sl], xd[sl], q[sl], qd[sl])
        on_ground[:, 2] -= point[0] * on_ground[:, 1] - point[1] * on_ground[:, 0]  # about P
        drives = np.einsum("nqx,nq->nx", RN.jacobian(model.coordinate_rows, x[sl]), Qd)
        frame[sl] = (frame_forces(ms, x[sl], lam, point=point, R=R)["total"] + on_ground
                     + net_on_ground(model, x[sl], drives, point))
        pairs = None
        if ms.friction is not None:
            # the friction of the pairs: a pair between two bodies adds no net force or
            # moment to them, so the net of the friction on the bodies is that of the
            # pairs with the frame, whose opposite the frame receives
            Ff = np.array([r[2].F_friction for r in rec[a:b]], float).reshape(b - a, n_x)
            frame[sl] += net_on_ground(model, x[sl], Ff, point)
            p_f[sl] = -np.einsum("nx,nx->n", Ff, xd[sl])  # the power friction dissipates
            pairs = ms.friction.by_pair(x[sl], xd[sl], lam)  # part of their reactions
        for el, v in element_forces(ms, x[sl], lam, pairs, R=R).items():
            forces.setdefault(el, np.zeros((n,) + np.shape(v)[1:]))[sl] = v
        if ms.n_rows:
            res[sl] = np.max(np.abs(RN.values(ms.rowset, x[sl], parts)), axis=-1)
    for r in rec:
        if r[1].mode not in modes:
            modes.append(r[1].mode)
    # the bodies, plus the rotors and gears of the drives reduced to their coordinates
    T = kinetic_energy(model, x, xd) + 0.5 * (qd**2) @ sm.drive_inertia
    U = sm.fm.potential_energy(x)
    # the largest penetration of a stop (lengths only) or contact, m
    pen = [float(np.max(-g)) for g, angle in gaps(sm, x).values() if not angle] if n else []
    return dict(t=t, q=q, qdot=qd, qddot=qdd, x=x, xdot=xd, frame=frame, forces=forces,
                mode=[r[1].mode for r in rec],
                mode_index=np.array([modes.index(r[1].mode) for r in rec], int),
                kinetic=T, potential=U, work_nc=W, work_friction=W_f, power_friction=p_f,
                balance=T + U - W + lost, residual=res,
                impact_losses=lost, penetration=max([0.0, *pen]))


def _joined(blocks: list) -> dict:
    """The blocks of a run as one block (rows in order)."""
    if len(blocks) == 1:
        return blocks[0]
    out = {k: np.concatenate([b[k] for b in blocks]) for k in blocks[0]
           if isinstance(blocks[0][k], np.ndarray)}
    out["mode"] = [m for b in blocks for m in b["mode"]]
    out["forces"] = {el: np.concatenate([b["forces"][el] for b in blocks])
                     for el in blocks[0]["forces"]}
    out["penetration"] = max(b["penetration"] for b in blocks)
    return out


def _trajectory(model, block, modes, events, stats, status, message) -> Trajectory:
    """The Trajectory of an evaluated block of samples."""
    b = block
    stats = dict(stats)
    stats["penetration"] = b["penetration"]
    stats["variable_structure"] = SwitchedSamples(
        mode=b["mode"], modes=list(modes), mode_index=b["mode_index"],
        frame_force=b["frame"][:, :2], frame_moment=b["frame"][:, 2], forces=b["forces"],
        impact_losses=b["impact_losses"], penetration=b["penetration"])
    energy = {k: b[k] for k in ("kinetic", "potential", "work_nc", "balance", "residual")}
    if friction_joints(model):
        energy.update(work_friction=b["work_friction"], power_friction=b["power_friction"])
    return Trajectory(b["t"], b["q"], b["qdot"], b["qddot"], b["x"], b["xdot"],
                      status=status, message=message, events=list(events), stats=stats,
                      energy=energy, coordinate_names=model.coordinate_names,
                      body_names=model.body_names,
                      coordinate_is_angle=tuple(bool(v) for v in model.coord_is_angle),
                      model=model)


def _finish(model, rec: Samples, events, stats, wall0, status, message, sm,
            point=(0.0, 0.0)) -> Trajectory:
    """The Trajectory of a run from its samples: forces, frame loads and energies are
    evaluated here (or chunk by chunk as they were handed to the sink), batched over the
    samples of each mode segment."""
    point = np.asarray(point, float)
    stats = dict(stats)
    if rec.sink is not None:
        rec.flush(stats)
        blocks = rec.blocks
        if rec.streamed and not rec.keep:
            stats["streamed"] = dict(rec.streamed)
    else:
        blocks = [_block(model, sm, rec.state[1], point, rec.modes)]
    if not blocks:  # nothing recorded
        blocks = [_block(model, sm, [], point, rec.modes)]
    key = frame_impulse_key(sm)
    for ev in events:  # the frame's impulse of an impact: its angular part about the point
        if key in ev.impulses:
            f = np.array(ev.impulses[key], float)
            f[2] -= point[0] * f[1] - point[1] * f[0]
            ev.impulses[key] = f
    block = _joined(blocks)
    if rec.sink is not None:
        block["penetration"] = max(rec.penetration, block["penetration"])
    stats["wall_time_s"] = time.perf_counter() - wall0
    return _trajectory(model, block, rec.modes, events, stats, status, message)
