"""Forward dynamics: integrate the equations of motion and record a :class:`Trajectory`.

``simulate`` is the entry of every run: it checks the keywords (one set of defaults
for every model) and hands the run to the one segment loop of
:mod:`mechdyn.simulate.segments`.  A fixed-structure model is a run in one mode, one
segment of that loop; a model with switches, stops, contacts or coordinate locks
goes mode by mode.  In every mode the equations are those of
:mod:`mechdyn.dynamics.mode_equations` (Lagrange II in the mode's independent
coordinates, positions re-solved at every evaluation, on the compiled kernel when
it can, through bifurcation positions on the branch the motion is on).  A run that
cannot go on (dead or toggle position, a mechanism that cannot be assembled, a
singular mass matrix, a failing integrator, Ctrl-C) ends with its ``status`` and a
``message`` naming the time, the coordinates and the joints concerned, and returns
everything computed so far.

The work of the non-conservative forces is integrated with the motion, as an
extra state w' = P_nc, so that the energy balance T + U - W_nc = const holds
to the integrator's tolerance.

Friction in the pairs (docs/friction.md) enters the equations of every mode with its
dependence on the reactions (Newton on the multipliers at every evaluation,
:mod:`mechdyn.friction.forward`); true Coulomb pairs stick and slip as modes of
the run, and the friction work is a second quadrature state (``energy["work_friction"]``).
"""

from __future__ import annotations

import math
import warnings

from ..dynamics.mode_equations import FORMULATIONS
from ..initial_state import initial_state
from ..integrate.base import DEFAULT_RTOL, IntegratorOptionError, IntegratorWarning
from ..integrate.driver import sample_times
from ..model import as_model
from ..results.trajectory import Trajectory
from .segments import needs_event_loop, simulate_events

__all__ = ["simulate", "initial_state"]  # initial_state: re-exported from .initial_state

#: the options of the segment loop that :func:`simulate` passes on (``**switching``)
SWITCHING_OPTIONS = ("dt_out", "max_events", "small_velocity", "gap_tol", "zeno_time",
                     "max_wall_time", "max_steps", "min_step", "point")


def simulate(mech_or_model, t_end: float, *, integrator="dop853", steps: int | None = None,
             dt: float | None = None, rtol: float | None = None, atol=None, q0=None, qdot0=None,
             t_eval=None, formulation: str = "exact", d=None, progress: bool | None = None,
             events=None, t0: float = 0.0, mode=None, backend: str = "auto",
             iterations: int | None = None, tol: float | None = None,
             theta: float | None = None, first_step: float | None = None,
             max_step: float | None = None, sink=None, chunk: int = 2000, keep: bool = True,
             workspace=None, **switching) -> Trajectory:
    """Simulate the motion of a mechanism under its loads and drives, through every
    switch, impact and contact of a variable-structure mechanism.

    Parameters
    ----------
    mech_or_model : Mechanism or Model
        Switchable elements (``switches``, ``stops``, ``contacts``,
        ``coordinate_locks`` in ``extras``, weld :class:`~mechdyn.mechanism.joint.Lock`
        joints) make it a variable-structure run, integrated mode by mode.
    t_end : float
        End time, s (>= ``t0``).
    integrator : str or Integrator
        One of :data:`mechdyn.integrate.INTEGRATORS`: ``"dop853"`` (default: the
        Dormand-Prince 8(5,3) pair, in the compiled loop of
        :mod:`mechdyn.kernels.dop853_numba` where it can run -- a segment on the compiled
        (Numba) kernel without event functions: a fixed-structure model, no ``events``,
        no redundant constraints, no friction in the joints --, its steps checked from
        Python in variable-structure modes and runs with ``events``, and elsewhere (the
        NumPy backend) the same method and step control stepped from Python,
        :mod:`mechdyn.integrate.dop853`; it never calls SciPy's solvers);
        ``"scipy-dop853"`` (SciPy's DOP853 everywhere, stepped from Python: the same
        method, for cross-checks); ``"rk45"``, ``"rk23"``, ``"radau"``, ``"bdf"``,
        ``"lsoda"`` (adaptive, SciPy); ``"rk4"`` or ``"wilson"`` (fixed step; the
        source paper's linear-acceleration method; they step on a grid of ``dt`` from
        the start of every mode segment, its last step shortened to the event; in the
        compiled fixed-step loop of :mod:`mechdyn.kernels.fixed_step_numba` on the
        compiled kernel, with the numbers of their Python steppers, which run elsewhere
        or with ``compiled=False`` on an instance).
    steps, dt
        Number of steps over [t0, t_end] (default 100) or step size (s) of the
        fixed-step integrators.
    rtol, atol
        Tolerances of the adaptive integrators (rtol default 1e-10, atol default
        ``1e-3 rtol``, the same on every path; SI units of q, scaled by the length
        scale for travels, ten times that for q' and 1e3 atol for the work W_nc in J).
    q0, qdot0 : array_like (n_q,) or mapping {name: value}, optional
        Initial state; default from the model file's ``initial`` table, then the
        sketch with zero rates.  Coordinates dependent in the initial mode are
        re-measured.
    t_eval : array_like, optional
        Output times (from the dense output); default every accepted step.  Samples
        are also stored just before and just after every switching event.
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
        Engaged locks at the start (default: as declared by the elements); stops and
        contacts found touching are closed automatically.
    backend : {"auto", "numpy", "numba"}
        Evaluation of the right-hand side (see
        :class:`~mechdyn.dynamics.mode_equations.ModeEquations`).
    iterations, tol, theta
        Corrector passes, corrector tolerance and Wilson's theta (``wilson`` only).
    first_step, max_step
        Step-size bounds of the adaptive integrators, s (after an event the first
        step is 1e-7 of the run).
    **switching
        Options of the segment loop: ``dt_out`` (output interval, s, instead of
        ``t_eval``); ``max_events`` (stop, status ``"too-many-events"``, after this
        many switching instants; default 100000); ``small_velocity`` (approach speeds
        below it are absorbed plastically, m/s; default 1e-6 length scale / s);
        ``gap_tol`` (distance at which a stop or contact touches, also the
        penetration tolerance, m; default 1e-9 length scale); ``zeno_time`` (a stop
        or contact that impacts again within it is absorbed plastically, ending a
        bouncing sequence, s; default 1e-4 (t_end - t0)); ``max_wall_time`` (stop,
        status ``"timeout"``, after this many seconds of computing); ``max_steps`` (stop,
        status ``"budget-exhausted"``, after this many accepted steps; default 200 000,
        or twice the grid of a fixed-step integrator); ``min_step`` (stop, status
        ``"step-too-small"``, when an adaptive step falls below it, s; default
        1e-13 (t_end - t0)).  A run whose steps shrink below 1e-7 (t_end - t0) where the
        position Jacobian is nearly singular (sigma_min/sigma_max < 1e-5) stops at once
        as a dead position approached; ``point`` ((2,) m, default the ground origin):
        the point the frame moment ``M_frame_Nm`` is taken about, as in
        :func:`mechdyn.kinetostatics`.
    sink : callable, optional
        Receives the table as it is computed: every ``chunk`` output samples (and at the
        end) ``sink(part, start)`` is called with a :class:`Trajectory` of those samples
        (forces, frame loads and energies evaluated as for the whole run; the work
        W_nc and the impact losses run on from the start) and the index of its first row
        in the run; its force columns cover every joint, lock, stop and contact from the
        first chunk on.  :class:`mechdyn.results.table.CsvStream` appends them to a CSV.
    chunk : int
        Output samples per chunk handed to ``sink`` (default 2000).
    keep : bool
        With a ``sink``: also keep every sample for the Trajectory returned (default);
        ``False`` keeps only the last chunk, so memory does not grow with the run, and
        ``stats.streamed`` (:class:`~mechdyn.results.records.StreamedStats`) gives the
        run's ``rows``, ``t_first``, ``energy_drift`` and largest constraint
        ``residual``.
    workspace : Workspace, optional
        The caches of the run (:class:`~mechdyn.model.workspace.Workspace`): pass the
        same one to many runs of one model from one initial state (a study, an
        optimiser) and they pay the start of the run -- the assembly, the first mode
        system, the equations of the first segment -- once.  By default each run makes
        its own; the Model keeps nothing of a run.

    Returns
    -------
    Trajectory
        ``t``, ``q``, ``qdot``, ``qddot`` (all declared coordinates), ``x``,
        ``xdot``; ``events`` (an :class:`~mechdyn.integrate.events.EventRecord` per
        switching instant and per caller's event); ``energy`` (kinetic, potential,
        work_nc, balance = T + U - W_nc + impact losses, residual; with friction in the
        pairs also work_friction, the energy they dissipated, J, included in work_nc,
        and power_friction, W);
        ``stats`` (:class:`~mechdyn.results.records.RunStats`: the counters, and
        ``variable_structure``, see ``switching``); ``switching``
        (:class:`~mechdyn.results.records.SwitchedSamples`: the mode of each
        sample, the force on the frame, the force of every joint, lock, stop and
        contact, see :func:`mechdyn.dynamics.reactions.element_forces`).  Also when
        the run stopped early: then ``status`` and ``message`` say why and where,
        and the samples computed so far are kept.

    Raises
    ------
    IntegratorOptionError, ModelError
        Bad options (unknown integrator or formulation, steps <= 0, theta < 1.37 but
        != 1, rtol <= 0, t_end < t0 ...), or an initial state that cannot be
        assembled.
    """
    model = as_model(mech_or_model)
    try:
        t0 = float(t0)
        t_end_f = float(t_end)
    except (TypeError, ValueError):
        raise IntegratorOptionError(f"`t_end` must be a time in s, got {t_end!r}") from None
    if not math.isfinite(t_end_f) or t_end_f < t0 or t_end_f < 0:
        raise IntegratorOptionError(f"`t_end` must be finite and >= t0 = {t0:g} s, "
                                    f"got {t_end!r}")
    unknown = sorted(set(switching) - set(SWITCHING_OPTIONS))
    if unknown:
        raise IntegratorOptionError(f"simulate() got an unknown keyword {unknown[0]!r}; the "
                                    "options of the segment loop are "
                                    + ", ".join(SWITCHING_OPTIONS))
    # keywords that would have no effect are named in a warning
    name = integrator.lower() if isinstance(integrator, str) else getattr(integrator, "name", "")
    given = [k for k, v in (("rtol", rtol), ("atol", atol)) if v is not None]
    if name in ("wilson", "rk4") and given:
        warnings.warn(f"option(s) {', '.join(given)} have no effect with the fixed-step "
                      f"integrator {name!r} (it takes steps or dt)", IntegratorWarning,
                      stacklevel=2)
    if d is not None and formulation == "exact":
        warnings.warn("option d (the virtual displacement) has no effect with "
                      "formulation='exact'; it belongs to formulation='analogs'",
                      IntegratorWarning, stacklevel=2)
    rtol = DEFAULT_RTOL if rtol is None else rtol
    if formulation not in FORMULATIONS:
        raise IntegratorOptionError(f"unknown formulation {formulation!r}; valid formulations: "
                                    + ", ".join(FORMULATIONS))
    if needs_event_loop(model) and (formulation != "exact" or d is not None):
        warnings.warn(f"formulation={formulation!r}" + (" and d" if d is not None else "")
                      + " have no effect on a variable-structure run (switches, stops or "
                      "contacts): its modes use the exact formulation", IntegratorWarning,
                      stacklevel=2)
        formulation, d = "exact", None
    return simulate_events(model, t_end_f, q0=q0, qdot0=qdot0, t0=t0, mode=mode,
                           rtol=rtol, atol=atol, max_step=max_step, first_step=first_step,
                           t_eval=sample_times(t0, t_end_f, t_eval), method=integrator,
                           progress=progress, dt=dt, steps=steps, iterations=iterations,
                           tol=tol, theta=theta, events=events, backend=backend,
                           formulation=formulation, d=d, sink=sink, chunk=chunk, keep=keep,
                           workspace=workspace, **switching)
