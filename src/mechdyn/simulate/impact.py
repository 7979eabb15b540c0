"""What happens at a switch: impacts when constraints engage, none when they release.

When a lock engages, or a stop or contact closes, with a velocity that the new
constraint does not allow, the velocities jump.  The impact is computed in the
generalized coordinates q of the structure *before* the switch (its bilateral
part, after any releases), where the generalized mass matrix is A = B^T M B and
the new constraint rows are C = Phi_new,x B:

* plastic (locks, and stops/contacts with e = 0): generalized momentum is
  conserved up to the impulses of the new rows,

      [A  -C^T] [qdot+]   [A qdot-]
      [C    0 ] [ P   ] = [   0   ]

  (P the impulses of the new rows; the brief's form with -P);
* unilateral rows with Newton's restitution e: the impulses P >= 0 and the
  rows' velocities after the impact v+ >= e max(0, -v-) are complementary
  (v+ = -e v- on every row that receives an impulse), a velocity-level LCP
  solved by :func:`mechdyn.contact.complementarity.solve_lcp`;
* Coulomb friction in the impact, on contacts and on point stops with ``friction``
  mu > 0: a tangential impulse P_t along the contact line (the other ground axis for
  a stop on ``body.point.y|x``) with |P_t| <= mu P_n.  The contact sticks (its
  tangential velocity after the impact is zero) when the impulse that stops the
  sliding lies in the cone, and otherwise slides with P_t = -mu P_n sgn(v_t+)
  (:func:`mechdyn.contact.complementarity.solve_frictional_impact`: Newton's restitution on
  the normal velocity with Coulomb's law at the impulse level, the friction impulse
  opposing the sliding after the impact; when the sliding keeps its direction through
  the impact this is Routh's result, sgn(v_t+) = sgn(v_t-)).

The pairs' own friction (revolute and prismatic joints with ``friction``,
:mod:`mechdyn.friction.law`) is not part of the impulse problem: their impulsive
reactions would make impulsive friction, mu times the impulse, which is not modelled.
The pairs are taken as frictionless during the impact, and a warning
(:class:`~mechdyn.friction.ignored.FrictionIgnoredWarning`) names, once per
event, the pairs with friction that carry an impulse (``docs/friction.md``).

The kinetic energy lost is T- - T+; for a plastic impact it equals
1/2 (qdot- - qdot+)^T A (qdot- - qdot+).  The impulse of every joint, lock,
stop and contact (including the pins that carry the impact through) comes from
M (xdot+ - xdot-) = Phi_x^T Lambda + T_x^T P_t over all rows of the new mode (T the
tangents of the frictional rows).  The impulse that
the frame receives (the opposite of the impulses of the rows that act between it and the
moving bodies) is reported as well: minus the jump of the mechanism's momentum.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from ..contact.complementarity import constrained_inverse, solve_frictional_impact, solve_lcp
from ..dynamics.mode_rows import ModeRows
from ..dynamics.mode_system import mode_system
from ..dynamics.reactions import element_forces, frame_forces
from ..friction.ignored import FrictionIgnoredWarning
from ..friction.law import friction_joints
from ..kernels import rows_numpy
from ..kernels.inertia import reduced_mass
from ..kernels.planar import cross
from ..model.inertia import mass_matrix_x
from ..model.switchable import Row, SwitchedModel
from ..model.variable import parse_variable
from .gaps import row_terms

__all__ = ["ImpactResult", "impact", "element_forces", "frame_forces", "frame_impulse_key"]


def frame_impulse_key(sm: SwitchedModel) -> str:
    """The key of the frame's impulse in :attr:`ImpactResult.element_impulses` (and in
    the ``impulses`` of an event): ``"frame"``, or ``"frame (total)"`` if a joint, lock,
    stop or contact of the model is named ``"frame"``.

    Parameters
    ----------
    sm : SwitchedModel

    Returns
    -------
    str

    Examples
    --------
    >>> import mechdyn as md
    >>> from mechdyn.model.switchable import switched_model
    >>> frame_impulse_key(switched_model(md.examples.load("four_bar").compile()))
    'frame'
    """
    names = set(sm.model.mechanism.joints) | set(sm.lock_names) | set(sm.stops) | set(
        sm.contacts)
    return "frame (total)" if "frame" in names else "frame"


@dataclass
class ImpactResult:
    """The outcome of an impact.

    Attributes
    ----------
    xdot_plus : ndarray, shape (n_x,)
        Body velocities after the impact.
    energy_before, energy_after, energy_lost : float
        Kinetic energies (J) and their difference (J, >= 0).
    impulses : dict
        Impulse of each row (N s, or N m s for angular rows) by row label;
        joint rows are labelled ``"O.x"``, ``"O.y"``, ....
    element_impulses : dict
        For each joint or weld lock, the impulse on its child body from its
        parent at the joint point, ground frame (:func:`~mechdyn.dynamics.reactions.
        element_forces`): (Px, Py) N s for a revolute joint, (Px, Py, L) N s, N s,
        N m s for a prismatic joint or a weld (L about the child frame origin, the
        weld's point); for each coordinate lock, stop or contact, the impulse of
        its row (N s or N m s); for each stop or contact with friction, under
        ``"NAME.tangent"``, its tangential impulse P_t (N s, along the contact line's
        direction, or the +x / +y ground axis for a stop on ``body.point.y`` / ``.x``).
        Under the key ``"frame"`` (``"frame (total)"`` if an element is named
        ``"frame"``): :attr:`frame_impulse`.
    velocity_before, velocity_after : dict
        Rate of each new row (m/s or rad/s) before and after the impact (and the
        tangential rate ``"NAME.tangent"`` of each frictional stop or contact, m/s).
    friction_states : dict
        ``"stick"``, ``"slip+"`` or ``"slip-"`` of each frictional stop or contact in the
        impact (the sign of its tangential velocity after it).
    frame_impulse : ndarray, shape (3,)
        The impulse that the frame receives (:func:`~mechdyn.dynamics.reactions.
        frame_forces` of the impulses): (Px, Py) N s and the angular impulse about the
        ground origin, N m s.  By Newton's third law it is minus the jump of the
        mechanism's linear and angular momentum.
    """

    xdot_plus: np.ndarray
    energy_before: float
    energy_after: float
    energy_lost: float
    impulses: dict = field(default_factory=dict)
    element_impulses: dict = field(default_factory=dict)
    velocity_before: dict = field(default_factory=dict)
    velocity_after: dict = field(default_factory=dict)
    frame_impulse: np.ndarray = field(default_factory=lambda: np.zeros(3))
    friction_states: dict = field(default_factory=dict)


def _tangent(sm: SwitchedModel, r: Row):
    """(mu, tangent Measure) of a unilateral row, or None without friction."""
    if r.kind == "contact":
        ct, _, slip = sm.contacts[r.element]
        return (ct.friction, slip) if ct.friction > 0 else None
    st = sm.stops[r.element][0]
    if not st.friction > 0:
        return None
    tangent = sm.stop_tangents.get(r.element)
    if tangent is None:  # not resolved by the compiler: its error, here
        tangent = parse_variable(sm.model, st.tangent_variable())
    return st.friction, tangent


def _momentum(x, Q):
    """Linear and angular (about the ground origin) impulse of the generalized impulse
    Q (n_x,) (forces and moments about each body's origin at poses x)."""
    F, pos = Q.reshape(-1, 3), np.asarray(x, float).reshape(-1, 3)
    return np.array([F[:, 0].sum(), F[:, 1].sum(),
                     float(np.sum(F[:, 2] + cross(pos[:, :2], F[:, :2])))])


def impact(sm: SwitchedModel, x, xdot_minus, locks_before, locks_after, targets: dict,
           unilateral=(), *, restitution: dict | None = None, small_velocity: float = 0.0,
           t=None, warned: set | None = None, workspace=None) -> ImpactResult:
    """Velocities after locks engage and/or unilateral constraints close at pose ``x``.

    Parameters
    ----------
    sm : SwitchedModel
        The switchable elements of the model (:func:`~mechdyn.model.switchable.
        switched_model`).
    x : ndarray, shape (n_x,)
        The pose at the switch (satisfies every row involved), m and rad.
    xdot_minus : ndarray, shape (n_x,)
        Velocities before (m/s, rad/s), consistent with ``locks_before``.
    locks_before : frozenset of str
        Locks engaged before (after the releases of the same instant).
    locks_after : frozenset of str
        Locks engaged after (``locks_before`` plus the ones engaging).
    targets : dict
        Held values of the locks (the engaging ones captured at ``x``).
    unilateral : iterable of str
        Touching stop sides and contacts (closed before, or closing now).
    restitution : dict, optional
        Coefficient e per unilateral token (default: the element's own).
    small_velocity : float
        Approach speeds below it (m/s, or rad/s for angle stops) are treated as
        plastic (e = 0), which ends bouncing sequences in finite time.
    t : float, optional
        The time, s, for the warnings.
    warned : set, optional
        The warnings already given in this run (the run's
        :attr:`~mechdyn.model.workspace.Workspace.warned`), so that each is given once per
        run; None: every call warns.
    workspace : Workspace, optional
        The run's workspace: the mode systems built here are those the run builds at the
        same pose (:func:`~mechdyn.dynamics.mode_system.mode_system`).

    Returns
    -------
    ImpactResult
        The velocities after, the energies, and the impulses of every row and element.

    Raises
    ------
    ContactError
        No stick or slip state of the frictional stops and contacts is consistent with
        Coulomb's law.
    ModelError
        An unknown lock, stop or contact token.

    Warns
    -----
    FrictionIgnoredWarning
        Joints with friction carry impulses (taken as frictionless in the impact).
    UserWarning
        A stop with friction stays closed after the impact (its friction acts in
        impacts only).

    Examples
    --------
    A 1 kg ball falling at 2 m/s onto a floor stop of restitution e = 0.5 leaves at
    e * 2 = 1 m/s; the floor's impulse is m (1 + 2) = 3 N s and the energy lost
    1/2 m (2^2 - 1^2) = 1.5 J:

    >>> import numpy as np
    >>> from mechdyn.simulate.gaps import _drop
    >>> from mechdyn.model.switchable import switched_model
    >>> r = impact(switched_model(_drop(0.5)), np.zeros(3), np.array([0.0, -2.0, 0.0]),
    ...            frozenset(), frozenset(), {}, ["floor@lower"])
    >>> r.xdot_plus + 0.0, r.impulses["floor@lower"], r.energy_lost
    (array([0., 1., 0.]), 3.0, 1.5)
    """
    model = sm.model
    xdot_minus = np.asarray(xdot_minus, float)
    base = mode_system(sm, frozenset(locks_before), targets, x, workspace=workspace)
    B, _ = base.velocity_analogs(x)
    G_all = base._coord_jac(x)
    # bodies, plus the rotors and gears of the drives reduced to their coordinates
    M, _ = sm.with_drive_inertia(*mass_matrix_x(model, x), G_all, np.zeros(model.n_q))
    A = reduced_mass(M, B)
    G = G_all[base.coords]
    qd_minus = G @ xdot_minus
    new_locks = frozenset(locks_after) - frozenset(locks_before)
    rows_b = sm.rows(new_locks, targets) if new_locks else []
    uni_tokens = sorted(set(unilateral))
    rows_u = [r for r in sm.rows(frozenset(uni_tokens), targets) if r.unilateral]
    Cb, _, _ = row_terms(base, rows_b, x, xdot_minus, B, np.zeros(model.n_x))
    Cu, _, _ = row_terms(base, rows_u, x, xdot_minus, B, np.zeros(model.n_x))
    Z = constrained_inverse(A, Cb)
    p_minus = A @ qd_minus
    v_minus = Cu @ qd_minus
    v0 = Cu @ Z @ p_minus
    Hm = Cu @ Z @ Cu.T
    e = np.zeros(len(rows_u))
    for k, r in enumerate(rows_u):
        tok = r.label
        if restitution and tok in restitution:
            e[k] = restitution[tok]
        elif r.kind == "stop":
            e[k] = sm.stops[r.element][0].restitution
        else:
            e[k] = sm.contacts[r.element][0].restitution
        if -v_minus[k] <= small_velocity:
            e[k] = 0.0
    target = e * np.maximum(-v_minus, 0.0)
    fric = [(k, *ft) for k, r in enumerate(rows_u) if (ft := _tangent(sm, r)) is not None]
    if fric:
        Tx = np.array([rows_numpy.jacobian(meas.rows, x)[0] for _, _, meas in fric])
        Ct = Tx @ B
        imp = solve_frictional_impact(Z, p_minus, Cu, target, Ct, [k for k, _, _ in fric],
                                      [mu for _, mu, _ in fric], Ct @ qd_minus)
        P_u, P_t, qd_plus = imp.normal, imp.tangent, imp.qdot_plus
        t_labels = [f"{rows_u[k].element}.tangent" for k, _, _ in fric]
        states = dict(zip([rows_u[k].element for k, _, _ in fric], imp.states, strict=True))
        _warn_closed_stops(sm, rows_u, fric, v_minus, Cu @ qd_plus, P_u, warned)
    else:
        P_u = solve_lcp(Hm, v0 - target).z
        qd_plus = Z @ (p_minus + Cu.T @ P_u)
        Tx, Ct, P_t, t_labels, states = (np.zeros((0, model.n_x)), np.zeros((0, B.shape[1])),
                                         np.zeros(0), [], {})
    xdot_plus = B @ qd_plus
    T0 = 0.5 * float(xdot_minus @ M @ xdot_minus)
    T1 = 0.5 * float(xdot_plus @ M @ xdot_plus)
    # impulses of every row of the mode after the impact (its rows alone: no coordinates)
    after = ModeRows(sm, frozenset(locks_after) | frozenset(uni_tokens), targets)
    R = after.row_jacobian(x)
    Q_t = Tx.T @ P_t  # the friction impulses on the bodies
    dp = M @ (xdot_plus - xdot_minus) - Q_t
    Lam = np.linalg.lstsq(R.T, dp, rcond=None)[0] if R.size else np.zeros(0)
    labels = [r.label for r in rows_b + rows_u] + t_labels
    C = np.concatenate([Cb, Cu, Ct])  # the rates of the new rows and the tangents
    # the frame takes the opposite of the friction impulses between it and the bodies
    # (those between two moving bodies cancel in the sum)
    on_frame = frame_forces(after, x, Lam, point=np.zeros(2))["total"] - _momentum(x, Q_t)
    per_element = element_forces(after, x, Lam)
    _warn_pair_friction(sm, per_element, [*(f"lock {n!r} engaging" for n in sorted(new_locks)),
                                          *(f"{r.label!r} closing" for k, r in enumerate(rows_u)
                                            if v_minus[k] < 0)], t, warned)
    per_element.update(zip(t_labels, map(float, P_t), strict=True))
    per_element[frame_impulse_key(sm)] = on_frame
    impulses = dict(zip(after.row_labels(), map(float, Lam), strict=True))
    impulses.update(zip(t_labels, map(float, P_t), strict=True))
    return ImpactResult(xdot_plus, T0, T1, T0 - T1, impulses, per_element,
                        dict(zip(labels, map(float, C @ qd_minus), strict=True)),
                        dict(zip(labels, map(float, C @ qd_plus), strict=True)), on_frame,
                        states)


def _warn_pair_friction(sm: SwitchedModel, per_element: dict, event: list, t,
                        warned: set | None) -> None:
    """Warn (once per event) that the pairs with friction carrying an impulse were taken
    as frictionless in the impact (``per_element``: the impulses of the mode's elements,
    :func:`element_forces`)."""
    fj = friction_joints(sm.model)
    if not fj or not event:
        return
    size = {j: float(np.hypot(*np.asarray(per_element[j])[:2])) for j in fj
            if j in per_element}
    big = max(size.values(), default=0.0)
    pairs = [j for j, v in size.items() if v > 1e-9 * big]
    told = set() if warned is None else warned
    key = ("impact pair friction", *event)
    if not pairs or key in told:
        return
    told.add(key)
    when = "" if t is None else f" at t = {float(t):.6g} s"
    warnings.warn(
        f"impact{when} ({', '.join(event)}): joint(s) " + ", ".join(repr(j) for j in pairs)
        + " with friction carry impulsive reactions; the impulse problem takes the pairs as "
        "frictionless (their impulsive friction, mu times the impulse, is not modelled: "
        "docs/friction.md); the friction acts again from the instant after the impact",
        FrictionIgnoredWarning, stacklevel=4)


def _warn_closed_stops(sm: SwitchedModel, rows_u, fric, v_minus, v_plus, P_n,
                       warned: set | None) -> None:
    """Warn (once per stop) when a stop with friction stays closed after an impact: its
    friction acts in impacts only, not while it stays closed."""
    scale = max(float(np.max(np.abs(v_minus), initial=0.0)), 1e-300)
    told = set() if warned is None else warned
    for k, _, _ in fric:
        r = rows_u[k]
        key = ("closed stop friction", r.element)
        if r.kind == "stop" and P_n[k] > 0 and abs(v_plus[k]) <= 1e-9 * scale \
                and key not in told:
            told.add(key)
            warnings.warn(f"stop {r.element!r} has friction = "
                          f"{sm.stops[r.element][0].friction:g}: it acts in its impacts only; "
                          "while the stop stays closed the point slides along it without "
                          "friction (use a contact for lasting friction)", stacklevel=3)
