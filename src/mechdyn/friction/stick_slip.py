"""The stick-slip state of every Coulomb pair at a switching instant.

A pair with true Coulomb friction (``smoothing = 0``) carries a state token in the mode,
``"B:stick"``, ``"B:slip+"`` or ``"B:slip-"`` (:mod:`mechdyn.friction.forward`
holds the states, the stick rows and the coupled solve of a mode); at every switching
instant the segment loop decides the states again here (:func:`resolve_joints`).
"""

from __future__ import annotations

from ..kernels import rows_numpy as RN
from ..model.state import friction_token, stick_key
from .forward import _measure, capture_stick, stick_slip_joints

__all__ = ["state_tokens", "resolve_joints"]


def state_tokens(states: dict) -> frozenset:
    """The mode tokens of joint friction states.

    Parameters
    ----------
    states : dict
        {joint: 'stick' | 'slip+' | 'slip-'}.

    Returns
    -------
    frozenset of str
        ``"joint:state"`` per pair.

    Examples
    --------
    >>> sorted(state_tokens({"B": "stick", "C": "slip+"}))
    ['B:stick', 'C:slip+']
    """
    return frozenset(friction_token(j, s) for j, s in states.items())


def resolve_joints(system, sm, t, x, xdot, mode, targets: dict, *, before: dict,
                   forced_slip: dict, forced_stick, velocity_tol: float, force_tol: float,
                   workspace=None) -> dict:
    """The friction state of every stick-slip pair at a switching instant.

    A pair slips in the direction of its sliding velocity when that exceeds
    ``velocity_tol``, in the direction given by ``forced_slip`` ({joint: +1/-1}: it just
    broke away), and is tried sticking otherwise (or when listed in ``forced_stick``:
    its sliding velocity just vanished).  A pair whose velocity passes zero by the
    kinematics alone (its stick row depends on the rows of the joints there: a slider at
    a dead centre) slips on, in the direction its sliding acceleration takes.  The trial
    pairs stick if each one's needed friction is within its capacity mu S; else the most
    overloaded one slips against its holding force and the others are tried again.
    Pairs whose stick rows hold ONE freedom together (:meth:`JointFriction.group`: the
    pins of a mechanism at rest) stick or slip as one: they hold while the holding
    force along the freedom, |H| = |sum lambda_j c_j| (whatever share of the redundant
    multipliers), is within C = sum mu S_j |c_j|; they break away together, each in the
    direction of the motion against H.

    Parameters
    ----------
    system : type
        :class:`~mechdyn.dynamics.mode_system.ModeSystem` (passed in: it imports this
        module).
    sm : SwitchedModel
    t : float
    x, xdot : ndarray, shape (n_x,)
        A consistent state of ``mode``.
    mode : frozenset of str
        The mode without joint friction tokens (locks, stops, contacts).
    targets : dict
        Held values; the stick values of the pairs that stick are stored here.
    before : dict
        The states of the mode left (:func:`joint_states`).
    forced_slip, forced_stick
        See above.
    velocity_tol, force_tol : float
        m/s or rad/s; N (N m for a pin: times the model's length scale).

    Returns
    -------
    dict
        {joint: 'stick' | 'slip+' | 'slip-'}.

    Raises
    ------
    AssemblyError
        A trial mode's rows cannot be assembled at ``x``.

    Examples
    --------
    The block at rest in its horizontal guide needs no friction to stay (no force
    along the guide), so it sticks where it is; moving at 1 m/s it slips forward:

    >>> from mechdyn.friction.forward import _block
    >>> model = _block()
    >>> import numpy as np
    >>> from mechdyn.model.switchable import switched_model
    >>> from mechdyn.dynamics.mode_system import ModeSystem
    >>> sm, x, targets = switched_model(model), np.zeros(3), {}
    >>> tols = {"velocity_tol": 1e-9, "force_tol": 1e-9}
    >>> resolve_joints(ModeSystem, sm, 0.0, x, np.zeros(3), frozenset(), targets,
    ...                before={}, forced_slip={}, forced_stick=(), **tols)
    {'guide': 'stick'}
    >>> targets
    {'guide:stick': 0.0}
    >>> resolve_joints(ModeSystem, sm, 0.0, x, np.array([1.0, 0.0, 0.0]), frozenset(), {},
    ...                before={}, forced_slip={}, forced_stick=(), **tols)
    {'guide': 'slip+'}
    """
    model = sm.model
    states: dict = {}
    pending = set()  # pairs that broke away from sticking: with their group, if they had one
    for j in stick_slip_joints(model):
        if j in forced_slip:
            states[j] = "slip+" if forced_slip[j] > 0 else "slip-"
            if before.get(j) == "stick" and stick_key(j) in targets:
                states[j] = "stick"
                pending.add(j)
            continue
        v = _measure(model, j).rate(x, xdot)
        if j not in forced_stick and abs(v) > velocity_tol:
            states[j] = "slip+" if v > 0 else "slip-"
            continue
        if before.get(j) != "stick" or stick_key(j) not in targets:
            capture_stick(model, j, x, targets)
        states[j] = "stick"
    L = model.length_scale
    sliding = {j: s for j, s in states.items() if s != "stick"}
    for j in [j for j, s in states.items() if s == "stick"]:
        # a pair whose velocity passes zero by the kinematics alone (a slider at a dead
        # centre: its stick row depends on the joints' rows there) slips on
        ms = system(sm, frozenset(mode) | state_tokens({**sliding, j: "stick"}), targets, x,
                    workspace=workspace)
        if ms.friction.stick_index[j] not in ms.independent_rows:
            states[j] = _passing_direction(system, sm, t, x, xdot, mode, targets, sliding, j,
                                           before.get(j), workspace)
    while any(s == "stick" for s in states.values()):
        ms = system(sm, frozenset(mode) | state_tokens(states), targets, x,
                    workspace=workspace)
        jf = ms.friction
        lam = ms.evaluate_x(t, x, xdot).lam
        c = jf.group(x) or {}
        if c:  # pairs holding one freedom together: they stick or slip as one
            H, C = jf.group_terms(c, x, lam)
            if pending & set(c) or C - abs(H) < -1e-9 * (C + abs(H)):
                # the motion e goes against the holding force H
                states.update({j: "slip+" if -cj * H > 0 else "slip-" for j, cj in c.items()})
                pending -= set(c)
                continue
        if pending:  # the others broke away alone, as the event said
            states.update({j: "slip+" if forced_slip[j] > 0 else "slip-" for j in pending})
            pending = set()
            continue
        worst, worst_ratio = None, 0.0
        for j, k in jf.stick_index.items():
            if j in c:
                continue
            tol = force_tol * (L if _measure(model, j).is_angle else 1.0)
            cap = jf.capacity(j, x, lam)
            over = abs(float(lam[k])) - cap - tol
            if over > 0 and (worst is None or over / max(cap, tol) > worst_ratio):
                worst, worst_ratio = j, over / max(cap, tol)
        if worst is None:
            break
        states[worst] = "slip-" if lam[jf.stick_index[worst]] > 0 else "slip+"
    for j, s in states.items():
        if s != "stick":
            targets.pop(stick_key(j), None)
    return states


def _passing_direction(system, sm, t, x, xdot, mode, targets, states, joint, prev,
                       workspace) -> str:
    """The slip state of a pair whose sliding velocity passes zero where holding it is
    not independent of the other rows: the direction s whose sliding acceleration has
    the sign of s (the reverse of ``prev`` tried first)."""
    meas = _measure(sm.model, joint)
    order = ("slip-", "slip+") if prev == "slip+" else ("slip+", "slip-")
    for st in order:
        trial = dict(states, **{joint: st})
        ms = system(sm, frozenset(mode) | state_tokens(trial), targets, x,
                    workspace=workspace)
        ev = ms.evaluate_x(t, x, xdot)
        acc = float(RN.jacobian(meas.rows, ev.x)[0] @ ev.xddot
                    + RN.quad(meas.rows, ev.x, ev.xdot)[0])
        if acc * (1.0 if st == "slip+" else -1.0) > 0:
            return st
    return order[0]
