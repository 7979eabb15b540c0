"""The state a run starts from: its mode system, consistent pose and rates.

:func:`start_state` builds the mode system of the engaged locks at the initial pose,
projects the initial coordinates onto its constraints, takes the rates of its
independent coordinates (with every touching stop and contact closed) and, in a
variable-structure model, decides the mode the state is in
(:func:`~mechdyn.simulate.switching.apply_switch`: touching stops and contacts,
sticking pairs).  That is a function of the compiled model and the initial state
alone, and costs about as much as a short run itself: where it records nothing but
the state (no event, no warning, no friction in the pairs, nothing touching), it is
kept in the run's :class:`~mechdyn.model.workspace.Workspace`, and the next run given
the same workspace from the same state starts from a copy of the mode system, as the
last solve left it.  The Model itself keeps nothing of a run.

The equations of the first segment of such a run (:class:`ModeEquations` on the mode's
compiled kernel: the kernel's packed rows and loads, the compiled loop's buffers) are
kept too, in a small pool of the workspace: a finished run gives them back
(:func:`give_back`) cleared of the run -- no mode system of it, the kernel's workspace
as it was when they were made, the loop's buffers cleared -- and
:func:`start_equations` gives them to the next run from the same start with its mode
system, else it makes new ones.  Equations with more state than is cleared here (a
branch-chart book, attributes this module does not know) are not kept.
"""

from __future__ import annotations

import copy

import numpy as np

from ..dynamics.mode_equations import ModeEquations
from ..dynamics.mode_rows import held_key
from ..dynamics.mode_system import ModeSystem
from ..errors import LockupError, ModelError
from ..friction.forward import stick_slip_joints
from ..friction.law import friction_joints
from ..model.state import side_of
from ..model.workspace import KEPT, Workspace
from .gaps import gaps, touching
from .switching import apply_switch

__all__ = ["start_state", "start_equations", "give_back"]


def start_state(sm, t: float, locks: frozenset, q_init, qd_init, x_guess, ws: Workspace,
                events: list, *, gap_tol: float, small_velocity: float, force_scale: float):
    """The mode system, pose and rates a run starts from.

    Parameters
    ----------
    sm : SwitchedModel
    t : float
        Start time, s.
    locks : frozenset of str
        The engaged locks.
    q_init, qd_init : ndarray, shape (n_q,)
        The initial coordinates and rates (those of the mode's independent coordinates
        are kept).
    x_guess : ndarray, shape (n_x,)
        The assembled pose at ``q_init`` (:func:`mechdyn.initial_state.initial_state`).
    ws : Workspace
        The run's workspace (new).
    events : list
        The run's events: the switching events of the start are appended.
    gap_tol, small_velocity, force_scale
        As in :func:`mechdyn.simulate.segments.simulate_events`.

    Returns
    -------
    ms : ModeSystem
    x, xd : ndarray, shape (n_x,)
    targets : dict
        The held values of the engaged locks (and sticking contacts).
    qi, qdi : ndarray, shape (n_i,)
        The mode's independent coordinates and their rates.
    key : tuple or None
        The key of the start kept in the workspace (None: not kept).

    Raises
    ------
    ModelError
        A stop or contact violated by the initial state.
    MechdynError, LinAlgError
        The state cannot be assembled or has no consistent mode.
    """
    model = sm.model
    key = (float(t), tuple(sorted(locks)), np.asarray(q_init, float).tobytes(),
           np.asarray(qd_init, float).tobytes(), np.asarray(x_guess, float).tobytes(),
           float(gap_tol), float(small_velocity), float(force_scale))
    kept = ws.starts.get(key)
    if kept is not None:
        return (*_restart(kept, ws), key)
    n_events = len(events)
    ms, x, xd, targets, touch0 = _start(sm, t, locks, q_init, qd_init, x_guess, ws, events,
                                        gap_tol=gap_tol, small_velocity=small_velocity,
                                        force_scale=force_scale)
    qi, qdi = ms.independent(x, xd)
    if (not touch0 and len(events) == n_events and not ws.warned and ms.friction is None
            and not friction_joints(model) and not stick_slip_joints(model)
            and held_key(targets) is not None and len(ws.starts) < KEPT):
        ws.starts[key] = _kept(ms, x, xd, targets, ws, qi, qdi)
    else:
        key = None
    return ms, x, xd, targets, qi, qdi, key


def _start(sm, t, locks, q_init, qd_init, x_guess, ws, events, *, gap_tol, small_velocity,
           force_scale):
    """:func:`start_state` computed: ``(ms, x, xd, targets, touching at the start)``."""
    model = sm.model
    L = model.length_scale
    targets: dict = {}
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
        n, side = side_of(tok)
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
    return ms, x, xd, targets, touch0


def _kept(ms, x, xd, targets, ws, qi, qdi) -> tuple:
    """What :func:`_restart` needs: the mode system (a copy, so that the run that made it
    changes nothing of it), the state, the held values and the workspace's solve state
    (its arrays marked where they are ``x`` itself)."""
    def own(a):
        return None if a is None else ("x" if a is x else np.array(a, float))

    parts = None if ws.parts is None else (own(ws.parts[0]), *ws.parts[1:])
    ms0 = copy.copy(ms)
    ms0.x_ref = np.array(ms.x_ref, float)
    ms0.ws = None
    return (ms0, np.array(x, float), np.array(xd, float), dict(targets),
            (own(ws.x), own(ws.B), own(ws.qi), parts), np.array(qi, float),
            np.array(qdi, float))


def _restart(kept, ws):
    """The start of a kept run for a new run: a copy of the mode system in the run's
    workspace, set as the start's last solve left it."""
    ms0, x0, xd0, targets, (wx, wB, wqi, parts), qi, qdi = kept
    x = x0.copy()

    def own(a):
        return None if a is None else (x if isinstance(a, str) else a.copy())

    ms = copy.copy(ms0)
    ms.x_ref = ms0.x_ref.copy()
    ms.ws = ws
    ws.x, ws.B, ws.qi = own(wx), own(wB), own(wqi)
    ws.parts = None if parts is None else (own(parts[0]), *parts[1:])
    return ms, x, xd0.copy(), dict(targets), qi.copy(), qdi.copy()


#: the attributes of :class:`ModeEquations` and of its compiled kernel that :func:`_clear`
#: knows (equations with others are not kept)
_EQUATIONS_STATE = frozenset({
    "sm", "ms", "formulation", "kernel", "note", "book", "watching", "_s_last", "_anchor",
    "_failures", "_rejects", "d", "backend", "_full", "_in_order", "_first_order"})
_KERNEL_STATE = frozenset({
    "ip", "fp", "ri", "rf", "dims", "_arrays", "n_x", "n_i", "ws", "compile_time", "status",
    "_st", "_ext_size", "_ext_parts", "_out", "_loop_buffers"})
#: equations kept per start, backend and formulation
EQUATIONS_KEPT = 2


def start_equations(sm, ms, backend: str, formulation: str, d, key):
    """The equations of the first segment of a run from the start ``key``
    (:func:`start_state`): kept ones restarted, else new ones.

    Returns
    -------
    eqs : ModeEquations
    kept : tuple or None
        What :func:`give_back` needs to keep them for the next run (None: not kept).
    """
    pool_key = None if key is None or d is not None else (key, backend, formulation)
    pool = None if pool_key is None else ms.ws.equations.get(pool_key)
    while pool:
        eqs, fresh = pool.pop()
        if eqs.sm is sm and _restartable(eqs):
            eqs.ms = ms
            return eqs, (pool_key, fresh)
    eqs = ModeEquations(sm, ms, backend, formulation, d)
    if pool_key is None or eqs.kernel is None or not _restartable(eqs):
        return eqs, None
    return eqs, (pool_key, eqs.kernel.ws.copy())


def give_back(ws, eqs, kept) -> None:
    """Keep the equations of a finished run in its workspace ``ws`` for the next run from
    its start, cleared of the run (no mode system or anchor of it; the kernel as it was
    made)."""
    if kept is None or not _restartable(eqs):
        return
    pool_key, fresh = kept
    if pool_key not in ws.equations and len(ws.equations) >= KEPT:
        return
    pool = ws.equations.setdefault(pool_key, [])
    if len(pool) < EQUATIONS_KEPT and all(e is not eqs for e, _ in pool):
        _clear(eqs, fresh)
        pool.append((eqs, fresh))


def _restartable(eqs) -> bool:
    k = eqs.kernel
    return (k is not None and eqs.book is None and set(vars(eqs)) <= _EQUATIONS_STATE
            and set(vars(k)) <= _KERNEL_STATE)


def _clear(eqs, fresh) -> None:
    """Equations of a run as :class:`ModeEquations` made them, without a mode system: no
    anchor, the kernel's workspace as it was made (``fresh``), the compiled loop's
    scalars and history cleared."""
    eqs.ms = None
    eqs.watching, eqs._s_last = True, None
    eqs._anchor, eqs._failures, eqs._rejects = None, 0, 0
    k = eqs.kernel
    k.ws[:] = fresh
    k.status, k._st[0], k.compile_time = 0, 0, 0.0
    b = getattr(k, "_loop_buffers", None)
    if b is not None:
        b.restart()
