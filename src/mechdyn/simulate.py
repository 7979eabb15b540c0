"""Forward dynamics: integrate the equations of motion and record a :class:`Trajectory`.

``simulate`` is the entry of every run.  A model with switches, stops, contacts or
coordinate locks goes mode by mode (:mod:`mechdyn.simulate_events`); a
fixed-structure model is one segment of the same segment integrator
(:func:`mechdyn.integrate.segment.run_segment`), with the equations of
:mod:`mechdyn.dynamics.lagrange` (q'' = A^-1 (Q - c), positions re-solved from q at
every evaluation, on the compiled kernel when it can).  After every accepted step
the positions are re-solved from q and checked for a dead position; q, q' and q''
are checked finite.  A run that cannot go on (dead or toggle position, a mechanism
that cannot be assembled, a singular mass matrix, a failing integrator) ends
with its ``status`` and a ``message`` naming the time, the coordinates and the
joints concerned, and returns everything computed so far.

Near a bifurcation (change-point) position -- two assembly branches crossing,
the coordinate keeping control, a parallelogram lying flat -- the equations are
evaluated on the branch from a chart (:mod:`mechdyn.dynamics.branch_dynamics`),
so the run goes through it; ``stats["bifurcations"]`` lists where.

The work of the non-conservative forces is integrated with the motion, as an
extra state w' = P_nc, so that the energy balance T + U - W_nc = const holds
to the integrator's tolerance.
"""

from __future__ import annotations

import math
import time
import warnings

import numpy as np

from .dynamics.branch_dynamics import BranchEquations
from .dynamics.lagrange import FORMULATIONS, EquationsOfMotion, kinetic_energy, potential_energy
from .errors import (
    AssemblyError,
    IntegrationError,
    MechdynError,
    ModelError,
    SingularPositionError,
    Status,
)
from .initial_state import initial_state
from .integrate.base import DEFAULT_RTOL, IntegratorOptionError, IntegratorWarning
from .integrate.driver import make_integrator, sample_times
from .integrate.events import as_events
from .integrate.segment import Coordinates, Stop, run_to_end, user_event_functions
from .kinematics.assembly import DEAD_RCOND, singularity, solve_position
from .kinematics.constraints import residual
from .model import as_model
from .progress import Progress
from .results.trajectory import Trajectory
from .simulate_events import needs_event_loop, simulate_events

__all__ = ["simulate", "initial_state"]  # initial_state: re-exported from .initial_state





def _fmt_q(model, q):
    return ", ".join(f"{n} = {v:.9g}" + (" rad" if a else " m")
                     for n, v, a in zip(model.coordinate_names, np.atleast_1d(q),
                                        model.coord_is_angle, strict=True))


def _diagnose(eom: EquationsOfMotion, exc: Exception, t_good: float, q_good, x_good):
    """Status and message of a run that stopped with ``exc`` after the state at ``t_good``."""
    model, lay = eom.model, eom.layout
    if isinstance(exc, SingularPositionError):
        return Status.SINGULAR_POSITION, str(exc)
    if isinstance(exc, AssemblyError) and exc.q is not None and q_good is not None:
        # The solve failed between an assemblable q_good and q_bad: the segment leaves the
        # assembly region, whose boundary is a singular position. Bisect for it.
        q_bad = np.asarray(exc.q, float)
        t_bad = exc.t if exc.t is not None else t_good
        lo, hi, x_lo = 0.0, 1.0, np.array(x_good, float)
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            try:
                x_lo = solve_position(model, q_good + mid * (q_bad - q_good), x_lo, layout=lay,
                                      check_singular=False)
                lo = mid
            except AssemblyError:
                hi = mid
            if hi - lo < 1e-13:
                break
        q_edge = q_good + lo * (q_bad - q_good)
        rep = singularity(model, x_lo, lay)
        t_edge = t_good + lo * (t_bad - t_good)
        if rep["rcond"] < DEAD_RCOND:
            return Status.SINGULAR_POSITION, (
                f"dead position reached near t = {t_edge:.9g} s at {_fmt_q(model, q_edge)}: "
                f"the mechanism cannot move past it (sigma_min/sigma_max of the constraint "
                f"Jacobian {rep['rcond']:.2e}); coordinate(s) "
                f"{', '.join(rep['coordinates']) or '-'} lose control, joints "
                f"{', '.join(rep['joints']) or '-'} become dependent")
        return Status.ASSEMBLY_FAILED, f"position solve failed at t = {t_bad:.9g} s: {exc}"
    if x_good is not None:
        rep = singularity(model, x_good, lay)
        if rep["rcond"] < DEAD_RCOND:
            return Status.SINGULAR_POSITION, (
                f"dead position near t = {t_good:.9g} s at {_fmt_q(model, q_good)}: "
                f"sigma_min/sigma_max = {rep['rcond']:.2e}; coordinate(s) "
                f"{', '.join(rep['coordinates']) or '-'} lose control, joints "
                f"{', '.join(rep['joints']) or '-'} become dependent ({exc})")
    if isinstance(exc, AssemblyError):
        return Status.ASSEMBLY_FAILED, str(exc)
    if isinstance(exc, IntegrationError) and "mass matrix" in str(exc):
        return Status.SINGULAR_MASS_MATRIX, str(exc)
    if isinstance(exc, FloatingPointError | ArithmeticError):
        return Status.NON_FINITE, f"non-finite values after t = {t_good:.9g} s: {exc}"
    return Status.FAILED, str(exc)


def _turning_point_check(eom: EquationsOfMotion, step, qd_old, x_good):
    """A coordinate whose rate changes sign during the step may turn back at a dead
    position (there the rate of the driving coordinate vanishes and the mechanism would
    have to change assembly branch to go on): locate the turn on the dense output and
    test the position there.  Returns (status, message) or None."""
    from scipy.optimize import brentq

    model, lay = eom.model, eom.layout
    for k in np.flatnonzero(np.sign(qd_old) * np.sign(step.qdot) < 0):
        try:
            tk = brentq(lambda s, k=k: step.dense(s)[1][k], step.t_old, step.t, xtol=1e-14,
                        rtol=4 * np.finfo(float).eps)
        except ValueError:
            continue
        qk = step.dense(tk)[0]
        if isinstance(eom, BranchEquations) and eom.chart_at(qk) is not None:
            continue  # a bifurcation: the branch goes on through it
        try:
            xk = solve_position(model, qk, x_good, layout=lay, check_singular=False)
        except AssemblyError:
            xk = None
        rep = singularity(model, xk, lay) if xk is not None else None
        if rep is None or rep["rcond"] < DEAD_RCOND:
            name = model.coordinate_names[k]
            if rep is None:
                rep = singularity(model, x_good, lay)
            return Status.SINGULAR_POSITION, (
                f"dead position reached near t = {tk:.9g} s at {_fmt_q(model, qk)}: "
                f"{name} turns back where the constraint Jacobian is singular "
                f"(sigma_min/sigma_max {rep['rcond']:.2e}); coordinate(s) "
                f"{', '.join(rep['coordinates']) or '-'} lose control, joints "
                f"{', '.join(rep['joints']) or '-'} become dependent; going on would need "
                f"the other assembly branch")
    return None


def __init__(self, q, qdot):
        self.q, self.qdot = q, qdot


def _keywords_without_effect(integrator, rtol, atol, formulation, d) -> float:
    """Warn (IntegratorWarning, naming them) about keywords that would have no effect;
    returns rtol with its default filled in."""
    name = integrator.lower() if isinstance(integrator, str) else getattr(integrator, "name", "")
    if name in ("wilson", "rk4"):
        given = [k for k, v in (("rtol", rtol), ("atol", atol)) if v is not None]
        if given:
            warnings.warn(f"option(s) {', '.join(given)} have no effect with the fixed-step "
                          f"integrator {name!r} (it takes steps or dt)", IntegratorWarning,
                          stacklevel=3)
    if d is not None and formulation == "exact":
        warnings.warn("option d (the virtual displacement) has no effect with "
                      "formulation='exact'; it belongs to formulation='analogs'",
                      IntegratorWarning, stacklevel=3)
    return DEFAULT_RTOL if rtol is None else rtol


def simulate(mech_or_model, t_end: float, *, integrator="dop853", steps: int | None = None,
             dt: float | None = None, rtol: float | None = None, atol=None, q0=None, qdot0=None,
             t_eval=None, formulation: str = "exact", d=None, progress: bool | None = None,
             events=None, t0: float = 0.0, mode=None, backend: str = "auto",
             iterations: int | None = None, tol: float | None = None,
             theta: float | None = None, first_step: float | None = None,
             max_step: float | None = None) -> Trajectory:
    """Simulate the motion of a mechanism under its loads and drives.

    Parameters
    ----------
    mech_or_model : Mechanism or Model
    t_end : float
        End time, s (>= ``t0``).
    integrator : str or Integrator
        ``"dop853"`` (default), ``"rk45"``, ``"rk23"``, ``"radau"``, ``"bdf"``,
        ``"lsoda"`` (adaptive, SciPy), ``"rk4"`` or ``"wilson"`` (fixed step; the
        source paper's linear-acceleration method).
    steps, dt
        Number of steps or step size (s) of the fixed-step integrators.
    rtol, atol
        Tolerances of the adaptive integrators (rtol default 1e-10, atol default
        ``1e-3 rtol``, the same on every path; SI units
        of q, q' and of the work W_nc in J).
    q0, qdot0 : array_like (n_q,) or mapping {name: value}, optional
        Initial state; default from the model file's ``initial`` table, then the
        sketch with zero rates.
    t_eval : array_like, optional
        Output times (from the dense output); default every accepted step.
    formulation : {"exact", "analogs"}
        Exact analogs (default) or the source paper's finite-difference analogs.
    d : float or array_like, optional
        Virtual displacement of ``formulation="analogs"`` (rad / m), default 0.1 deg.
    progress : bool or None
        Progress bar on stderr: always, never, or (None) once a run takes > 2 s.
    events : callable or list, optional
        Event functions ``g(t, q, qdot)`` (see :class:`mechdyn.integrate.Event`);
        occurrences are recorded in ``Trajectory.events``.
    t0 : float
        Start time, s.
    mode : iterable of str, optional
        Engaged locks (default: the model's initial mode).
    backend : {"auto", "numpy", "numba"}
        Evaluation of the right-hand side (see :class:`EquationsOfMotion`).
    iterations, tol, theta
        Corrector passes, corrector tolerance and Wilson's theta (``wilson`` only).
    first_step, max_step
        Step-size bounds of the adaptive integrators, s.

    Returns
    -------
    Trajectory
        Also when the run stopped early: then ``status`` and ``message`` say why and
        where, and the samples computed so far are kept.

    Raises
    ------
    IntegratorOptionError, ModelError
        Bad options (unknown integrator or formulation, steps <= 0, theta < 1.37 but
        != 1, rtol <= 0, t_end < t0 ...), or an initial state that cannot be
        assembled.
    """
    wall0 = time.perf_counter()
    model = as_model(mech_or_model)
    try:
        t0 = float(t0)
        t_end_f = float(t_end)
    except (TypeError, ValueError):
        raise IntegratorOptionError(f"`t_end` must be a time in s, got {t_end!r}") from None
    if not math.isfinite(t_end_f) or t_end_f < t0 or t_end_f < 0:
        raise IntegratorOptionError(f"`t_end` must be finite and >= t0 = {t0:g} s, "
                                    f"got {t_end!r}")
    rtol = _keywords_without_effect(integrator, rtol, atol, formulation, d)
    if formulation not in FORMULATIONS:
        raise IntegratorOptionError(f"unknown formulation {formulation!r}; valid formulations: "
                                    + ", ".join(FORMULATIONS))
    if needs_event_loop(model):
        # switches, stops, contacts: the same equations, integrated mode by mode
        if formulation != "exact" or d is not None:
            warnings.warn(f"formulation={formulation!r}"
                          + (" and d" if d is not None else "")
                          + " have no effect on a variable-structure run (switches, stops or "
                          "contacts): its modes use the exact formulation", IntegratorWarning,
                          stacklevel=2)
        return simulate_events(model, t_end_f, q0=q0, qdot0=qdot0, t0=t0, mode=mode,
                               rtol=rtol, atol=atol, max_step=max_step, first_step=first_step,
                               t_eval=sample_times(t0, t_end_f, t_eval), method=integrator,
                               progress=progress, dt=dt, steps=steps, iterations=iterations,
                               tol=tol, theta=theta, events=events, backend=backend)
    integ = make_integrator(integrator, steps=steps, dt=dt, rtol=rtol, atol=atol,
                            iterations=iterations, tol=tol, theta=theta,
                            first_step=first_step, max_step=max_step)
    te = sample_times(t0, t_end_f, t_eval)
    ev = as_events(events)

    q_init, qd_init, x_init = initial_state(model, q0, qdot0, mode=mode)
    t_compile = time.perf_counter()
    eom = BranchEquations(model, formulation, d=d, mode=mode, x0=x_init, backend=backend)
    t_compile = time.perf_counter() - t_compile
    # the initial position must be regular and the equations solvable there
    x_init = eom.positions(q_init, t0, check_singular=True)
    a_init = eom.qddot(t0, q_init, qd_init)
    eval0 = eom.total_evaluations

    T, Q, QD, QDD, X, W = [], [], [], [], [], []

    def record(t, q, qd, qdd, x, w):
        T.append(t)
        Q.append(np.array(q, float))
        QD.append(np.array(qd, float))
        QDD.append(np.array(qdd, float))
        X.append(np.array(x, float))
        W.append(float(w[0]) if len(w) else 0.0)

    k_eval = 0
    if te is None:
        record(t0, q_init, qd_init, a_init, x_init, [0.0])
    else:
        while k_eval < te.size and te[k_eval] <= t0:
            record(t0, q_init, qd_init, a_init, x_init, [0.0])
            k_eval += 1

    status, message = Status.SUCCESS, ""
    records: list = []
    bar = Progress(progress, t0, t_end_f)
    n = model.n_q
    good = [t0, q_init, x_init, qd_init]  # the last accepted state: t, q, x, qdot
    counts = {"steps": 0, "rejected": 0, "evaluations": 0}

    def evaluate(t, y):  # what the caller's event functions read
        return Coordinates(y, n)

    def after_step(step, y):
        if not (np.all(np.isfinite(step.q)) and np.all(np.isfinite(step.qdot))
                and np.all(np.isfinite(step.qddot))):
            raise Stop(Status.NON_FINITE, f"non-finite state at t = {step.t:.9g} s after "
                       f"{_fmt_q(model, good[1])} at t = {good[0]:.9g} s")
        turn = _turning_point_check(eom, step, good[3], good[2])
        if turn is not None:
            raise Stop(*turn)
        # positions at the step end, re-solved from q and checked for a dead position
        x_end = eom.positions(step.q, step.t, check_singular=True)
        good[:] = [step.t, step.q, x_end, step.qdot]
        return None

    def sample(ts, y, step, ev):
        if ts == step.t:
            record(ts, step.q, step.qdot, step.qddot, good[2], step.w)
            return
        eom.watching = False  # samples of the dense output leave the run as it is
        q, v, w = y[:n], y[n:2 * n], y[2 * n:]
        record(ts, q, v, eom.qddot(ts, q, v), eom.positions(q, ts), w)
        eom.positions(step.q, step.t)  # continue from the step end
        eom.watching = True

    efns = user_event_functions(ev)
    y0 = np.concatenate([q_init, qd_init, [0.0]])
    try:
        with np.errstate(over="raise", invalid="raise", divide="raise"):
            t, y, _, terminal = run_to_end(
                integ, eom, t0, y0, t_end_f, efns, evaluate=evaluate, after_step=after_step,
                sample=sample, t_eval=None if te is None else te[k_eval:],
                every_step=te is None, stats=counts, n=n, bar=bar,
                restart=lambda t_, y_: eom.positions(y_[:n], t_), records=records)
            if y is not None and te is None and T[-1] < t:
                q, v, w = y[:n], y[n:2 * n], y[2 * n:]
                record(t, q, v, eom.qddot(t, q, v), eom.positions(q, t), w)
            if terminal is not None:
                status = Status.EVENT
                message = f"terminal event {terminal.key!r} at t = {t:.9g} s"
    except Stop as exc:
        status, message = exc.status, exc.message
    except KeyboardInterrupt:
        status = Status.INTERRUPTED
        message = (f"interrupted (Ctrl-C) after t = {T[-1]:.9g} s; the samples computed so far "
                   f"are kept")
    except (MechdynError, FloatingPointError, ArithmeticError, np.linalg.LinAlgError) as exc:
        if isinstance(exc, ModelError) and not isinstance(exc, IntegratorOptionError):
            bar.close()
            raise
        status, message = _diagnose(eom, exc, *good[:3])
    finally:
        bar.close()

    n_q, n_x = model.n_q, model.n_x
    t_arr = np.array(T, float)
    q_arr = np.array(Q, float).reshape(-1, n_q)
    qd_arr = np.array(QD, float).reshape(-1, n_q)
    qdd_arr = np.array(QDD, float).reshape(-1, n_q)
    x_arr = np.array(X, float).reshape(-1, n_x)
    lay = eom.layout
    if t_arr.size:
        B = eom.velocity_analogs(q_arr, x_arr)
        xd_arr = (B @ qd_arr[..., None])[..., 0]
        # bodies, plus rotors and gears of the drives reduced to their coordinates
        Tk = kinetic_energy(model, x_arr, xd_arr) + 0.5 * (qd_arr**2) @ eom.extra_inertia
        U = potential_energy(model, x_arr)
        Wn = np.array(W, float)
        r = residual(model, x_arr, lay)
        res = np.max(np.abs(r), axis=-1) if r.shape[-1] else np.zeros(t_arr.size)
        energy = {"kinetic": Tk, "potential": U, "work_nc": Wn, "balance": Tk + U - Wn,
                  "residual": res}
    else:
        xd_arr = np.zeros((0, n_x))
        energy = None
    wall = time.perf_counter() - wall0
    stats = {"integrator": integ.name, "formulation": formulation, "backend": eom.backend,
             **counts, "evaluations": eom.total_evaluations - eval0,
             "integrator_evaluations": counts["evaluations"], "wall_time_s": wall,
             "setup_time_s": t_compile, "settings": integ.settings(),
             "mode": sorted(lay.mode), "rtol": getattr(integ, "rtol", None),
             "atol": getattr(integ, "atol", None), "bifurcations": eom.report()}
    if eom.kernel is not None:
        stats["compile_time_s"] = eom.kernel.compile_time
    elif eom.backend_note:
        stats["backend_note"] = eom.backend_note
    return Trajectory(t_arr, q_arr, qd_arr, qdd_arr, x_arr, xd_arr, status, message, records,
                      stats, energy, tuple(model.coordinate_names), tuple(model.body_names),
                      tuple(bool(v) for v in model.coord_is_angle), model)
