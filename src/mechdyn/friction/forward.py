"""Friction of the joints in forward dynamics: the coupled solve and the stick-slip states
(which state each pair takes at a switching instant: :mod:`mechdyn.friction.stick_slip`).

The friction of a revolute or prismatic pair (the law: :mod:`mechdyn.friction.law`)
depends on the pair's reaction, so on the multipliers lambda, which depend on the
accelerations.  In a mode the equations of motion with friction

    [M B, -Phi_x^T] [qddot_I; lambda] = F - h - M b + F_f(x, xdot, lambda)

are solved per evaluation of the right-hand side by Newton's method on the
multipliers, started from the frictionless solution, with the exact derivative
dF_f/dlambda of the law: r(lambda) = lambda - P K^-1 (rhs + F_f(lambda)) (P picks the
multipliers out of the solution), r' = I - P K^-1 dF_f/dlambda, one factorization of
K for every iterate.  A few iterations reach machine precision (the law is linear in
lambda except through |R|); a Newton matrix that is singular or iterates that do not
converge mean that friction locks the mechanism (self-locking): the run stops with
the time and the position.

True Coulomb friction (``smoothing = 0``) of a pair is a matter of modes.  Each such
pair carries a state token in the mode, ``"B:stick"``, ``"B:slip+"`` or
``"B:slip-"`` (the tokens of a contact's friction, :class:`~mechdyn.model.state.Mode`):

* sticking, the pair's travel (prismatic) or relative angle (revolute) is held at the
  value it had when it stuck, by one more row (a ``"stick"`` row, as a coordinate
  lock); its multiplier is the friction force (N) or moment (N m) needed to hold;
* slipping in direction s = +1 / -1, the law applies with sgn(v) = s for the whole
  segment (so that the right-hand side stays smooth up to the event).

Events (:func:`mechdyn.simulate.switching.event_functions`): slip -> stick when
s v falls to zero, and the pair sticks there if the friction needed to hold is at
most mu S (else it slips the other way); stick -> slip when the needed friction
|lambda_stick| exceeds the capacity mu S (mu r |R| for a pin), in the direction the
holding force resisted.  With ``smoothing > 0`` the pair has no state: the law's
tanh regularisation applies everywhere.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..errors import LockupError
from ..kernels import rows_numpy as RN
from ..model.state import Mode, friction_of, stick_key
from ..model.variable import parse_variable
from .law import friction_joints

__all__ = ["SelfLockingError", "stick_slip_joints", "joint_states", "split_mode",
           "stick_row", "capture_stick", "JointFriction"]

class SelfLockingError(LockupError):
    """Friction in the pairs admits no motion consistent with the law (self-locking, or a
    Painleve-type inconsistency of sliding friction): the friction solve has a singular
    Newton matrix or does not converge.  A run stops with status ``"self-locking"``.

    Parameters
    ----------
    message : str
        What locks, naming the joints and the mode.
    t : float, optional
        The time, s.
    q : array_like, shape (n_q,), optional
        The coordinates there, rad or m.

    Examples
    --------
    >>> err = SelfLockingError("the friction of 'guide' locks the mechanism", t=0.5)
    >>> str(err)
    "the friction of 'guide' locks the mechanism (at t = 0.5 s)"
    >>> from mechdyn.errors import LockupError
    >>> isinstance(err, LockupError)
    True
    """


#: Newton iterations on the multipliers before the solve is declared failed
_MAX_ITER = 30


def _block(mu: float = 0.3):
    """The model of the Examples: a 1 kg block (0.1 kg m^2) in a horizontal prismatic
    guide ``"guide"`` along x from the ground origin, Coulomb friction ``mu``, gravity
    9.81 m/s^2 down, the travel ``"s"`` its coordinate; poses x = (x, y, angle)."""
    from ..mechanism.mechanism import Mechanism
    m = Mechanism("block")
    m.add_body("block", mass=1.0, inertia=0.1)
    m.add_prismatic("guide", "ground", "block", friction=mu)
    m.add_coordinate("s", kind="travel", joint="guide")
    return m.compile()


def stick_slip_joints(model) -> tuple:
    """The joints with true Coulomb friction (``friction > 0``, ``smoothing = 0``): the
    pairs that stick and slip as modes.

    Parameters
    ----------
    model : Model
        Compiled; its friction joints are
        :func:`~mechdyn.friction.law.friction_joints`.

    Returns
    -------
    names : tuple of str
        Those joints, in the model's joint order (empty without such pairs: joints
        with viscous or smoothed friction only have no stick-slip states).

    Examples
    --------
    >>> model = _block()
    >>> stick_slip_joints(model)
    ('guide',)
    """
    joints = model.mechanism.joints
    return tuple(n for n in friction_joints(model)
                 if joints[n].friction > 0 and joints[n].smoothing == 0)


def joint_states(model, mode) -> dict:
    """{joint: 'stick' | 'slip+' | 'slip-'} of the stick-slip pairs in a mode.

    Parameters
    ----------
    model : Model
        A compiled model.
    mode : iterable of str
        The mode's tokens (locks, stops, contacts and friction states).

    Returns
    -------
    dict
        {joint: state} of the tokens ``"joint:state"`` whose joint is a stick-slip pair
        (:func:`stick_slip_joints`); a contact's friction tokens are left out.

    Examples
    --------
    >>> model = _block()
    >>> joint_states(model, {"guide:stick", "clutch"})
    {'guide': 'stick'}
    """
    ss = stick_slip_joints(model)
    return {k: v for k, v in Mode(mode).friction.items() if k in ss}


def split_mode(model, mode) -> tuple[Mode, dict]:
    """Split a mode into its joints' friction states and the rest.

    Parameters
    ----------
    model : Model
        A compiled model.
    mode : iterable of str
        The mode's tokens.

    Returns
    -------
    rest : Mode
        The mode without the stick-slip pairs' tokens.
    states : dict
        {joint: state} (:func:`joint_states`).

    Examples
    --------
    >>> model = _block()
    >>> rest, states = split_mode(model, {"guide:slip+", "clutch"})
    >>> sorted(rest), states
    (['clutch'], {'guide': 'slip+'})
    """
    st = joint_states(model, mode)
    return Mode(t for t in mode if (friction_of(t) or (None,))[0] not in st), st


def _measure(model, joint: str):
    """The pair's travel (m) or relative angle (rad), a Measure (resolved by the
    compiler for the joints with friction)."""
    sm = model.switchable
    meas = None if sm is None else sm.joint_measures.get(joint)
    return parse_variable(model, f"joint:{joint}") if meas is None else meas


def capture_stick(model, joint: str, x, targets: dict) -> None:
    """Store in ``targets`` the travel or relative angle a pair sticks at.

    Parameters
    ----------
    model : Model
        A compiled model.
    joint : str
        A revolute or prismatic joint.
    x : ndarray, shape (n_x,)
        The body poses (x, y, angle per body; m and rad).
    targets : dict
        Updated in place: ``targets["joint:stick"]`` = the pair's travel (m) or
        relative angle (rad) at ``x``.

    Raises
    ------
    ModelError
        ``joint`` is not a joint of the model (the message lists the valid ones).

    Examples
    --------
    The block's travel in the guide along x is its x position:

    >>> model = _block()
    >>> import numpy as np
    >>> targets = {}
    >>> capture_stick(model, "guide", np.array([0.25, 0.0, 0.0]), targets)
    >>> targets
    {'guide:stick': 0.25}
    """
    targets[stick_key(joint)] = _measure(model, joint).value(x)


@dataclass(frozen=True)
class StickRow:
    """The row holding a sticking pair: its travel or relative angle at ``target``; the
    interface of :class:`mechdyn.model.switchable.Row` (kind ``"stick"``, element the
    joint), which this module cannot import (modes -> mode_system -> here)."""

    element: str
    label: str
    measure: object
    target: float
    kind: str = "stick"
    sign: float = 1.0
    mu: float = 0.0
    slip: int = 0
    tangent: object = None
    compliance: float = 0.0
    unilateral: bool = False
    friction_rows: object = None

    @cached_property
    def rows(self):
        """The row as data, with its label and element."""
        return self.measure.rows.scaled(1.0, -self.target).renamed(self.label, self.element)


def stick_row(model, joint: str, targets: dict) -> StickRow:
    """The row holding a sticking pair at its captured value.

    Parameters
    ----------
    model : Model
        A compiled model.
    joint : str
        The sticking pair.
    targets : dict
        Held values, with ``"joint:stick"`` (:func:`capture_stick`), m or rad.

    Returns
    -------
    StickRow
        Kind ``"stick"``, label ``"joint:stick"``: the pair's travel or relative angle
        minus the target.

    Raises
    ------
    KeyError
        No value captured for the pair in ``targets``.

    Examples
    --------
    >>> model = _block()
    >>> row = stick_row(model, "guide", {"guide:stick": 0.25})
    >>> row.kind, row.label, row.target
    ('stick', 'guide:stick', 0.25)
    """
    return StickRow(joint, stick_key(joint), _measure(model, joint),
                    float(targets[stick_key(joint)]))


def friction_set(model, joints):
    """The friction law (:class:`~mechdyn.friction.law.FrictionSet`) of some joints of
    a model (a mode's :class:`JointFriction` keeps those of its sliding pairs)."""
    from .law import FrictionSet
    return FrictionSet(model, joints)


class JointFriction:
    """The friction of the joints in one mode.

    Parameters
    ----------
    ms : ModeSystem
        The mode's equations (:class:`~mechdyn.dynamics.mode_system.ModeSystem`, whose
        attribute ``friction`` this is when the model has friction joints).

    Attributes
    ----------
    states : dict
        {joint: state} of the stick-slip pairs (:func:`joint_states`).
    sliding : list of str
        The pairs whose friction the law gives (all friction joints but the sticking
        ones).
    signs : dict
        {joint: +1 / -1}: sgn(v) of the slipping stick-slip pairs.
    stick_index : dict
        {joint: index into ``ms.rowset`` of its stick row}.

    Examples
    --------
    The 1 kg block sliding at 1 m/s in its horizontal guide (mu = 0.3): the guide
    carries the weight, 9.81 N, so its friction capacity is 0.3 * 9.81 = 2.943 N, and
    friction decelerates the block at mu g:

    >>> model = _block()
    >>> import numpy as np
    >>> from mechdyn.model.switchable import switched_model
    >>> from mechdyn.dynamics.mode_system import ModeSystem
    >>> ms = ModeSystem(switched_model(model), frozenset(), {}, np.zeros(3))
    >>> jf = ms.friction
    >>> jf.sliding
    ['guide']
    >>> x, xdot = np.zeros(3), np.array([1.0, 0.0, 0.0])
    >>> ev = ms.evaluate_x(0.0, x, xdot)
    >>> round(jf.capacity("guide", x, ev.lam), 6), round(float(ev.xddot[0]), 6)
    (2.943, -2.943)
    """

    def __init__(self, ms):
        self.ms = ms
        model = ms.model
        self.model = model
        self.states = joint_states(model, ms.mode)
        self.sliding = [j for j in friction_joints(model) if self.states.get(j) != "stick"]
        self.signs = {j: (1.0 if s == "slip+" else -1.0) for j, s in self.states.items()
                      if s != "stick"}
        self.stick_index = {r.element: ms.n_base + k for k, r in enumerate(ms.rows)
                            if r.kind == "stick" and r.element in self.states}
        #: the law of the sliding pairs
        self.law = friction_set(model, tuple(self.sliding))
        self._single: dict = {}  # the law of each pair alone, as asked for

    # ------------------------------------------------------------------ the law
    def forces(self, x, xdot, lam):
        """(F_f (n_x,), dF_f/dlambda (n_x, n_rows)): the generalized friction force of
        the sliding pairs (:attr:`sliding`) on the body poses, N and N m, and its
        derivative with respect to the multipliers of the mode's rows.

        A slipping stick-slip pair whose velocity is zero or against its direction s
        (the start of its segment, trial states beyond the event) gets the Coulomb
        friction of sgn(v) = s (its viscous part that of the actual velocity), so that
        the right-hand side of the segment stays smooth up to the event.
        """
        return self.prepared(x, xdot).generalized(lam)

    def prepared(self, x, xdot):
        """The law of the sliding pairs at a pose and its rates, for any multipliers
        (:class:`~mechdyn.friction.law.PreparedFriction`), with the mode's slip
        directions."""
        return self.law.prepare(x, xdot, signs=self.signs)

    def by_pair(self, x, xdot, lam) -> dict:
        """{joint: generalized force (..., n_x) of its friction on the poses, N and N m} of
        the sliding pairs, batched over samples x, xdot (..., n_x), lam (..., n_rows): the
        forces of :meth:`forces`, pair by pair (the friction part of their reactions)."""
        fs = self.law
        return {j: F for j, (F, _) in fs.by_pair(x, xdot, lam, signs=self.signs).items()}

    def velocity(self, joint: str, x, xdot) -> float:
        """The pair's sliding velocity (m/s) or relative angular velocity (rad/s).

        Parameters
        ----------
        joint : str
            A friction joint of the model.
        x, xdot : ndarray, shape (n_x,)
            Body poses (m, rad) and their rates (m/s, rad/s).

        Returns
        -------
        float
        """
        return _measure(self.model, joint).rate(x, xdot)

    def capacity(self, joint: str, x, lam) -> float:
        """mu S of a pair (N; mu r |R|, N m, for a pin): the largest friction the pair
        can give at the multipliers ``lam``.

        Parameters
        ----------
        joint : str
            A friction joint of the model.
        x : ndarray, shape (n_x,)
            Body poses (m, rad).
        lam : ndarray, shape (n_rows,)
            Multipliers of the mode's rows (N, N m).

        Returns
        -------
        float
            N for a guide, N m for a pin.
        """
        fs = self._single.get(joint)
        if fs is None:
            fs = self._single[joint] = friction_set(self.model, (joint,))
        p = fs.pairs[0]
        load = fs.loads(x, np.asarray(lam, float))[joint][0]
        return float(p.mu * (p.length if p.kind == "revolute" else 1.0) * load)

    def margin(self, joint: str, x, lam) -> float:
        """Capacity minus the friction needed to hold a sticking pair (< 0: it slips).

        Parameters
        ----------
        joint : str
            A sticking pair of this mode (a key of :attr:`stick_index`).
        x : ndarray, shape (n_x,)
            Body poses (m, rad).
        lam : ndarray, shape (n_rows,)
            Multipliers of the mode's rows (N, N m), its stick row's the holding force.

        Returns
        -------
        float
            N (N m for a pin).

        Raises
        ------
        KeyError
            ``joint`` does not stick in this mode.
        """
        return self.capacity(joint, x, lam) - abs(float(lam[self.stick_index[joint]]))

    def group(self, x) -> dict | None:
        """The sticking pairs that hold ONE freedom together (their stick rows redundant:
        the pins of a one-degree-of-freedom mechanism at rest), as {joint: c_j}, c_j the
        pair's velocity along the unit motion e that the other rows leave free; None when
        the sticking rows are independent (or free more than one motion together)."""
        ms, stick = self.ms, self.stick_index
        if len(stick) < 2 or all(k in ms.independent_rows for k in stick.values()):
            return None
        rest = [i for i in range(ms.n_rows) if i not in stick.values()]
        R = ms.row_jacobian(x)[rest]
        R = R / np.maximum(np.linalg.norm(R, axis=1), 1e-300)[:, None]
        sv, vt = np.linalg.svd(R)[1:]
        rank = int(np.sum(sv > 1e-9 * (sv[0] if sv.size else 1.0)))
        if vt.shape[0] - rank != 1:
            return None
        e = vt[rank]
        c = {j: float(RN.jacobian(_measure(self.model, j).rows, x)[0] @ e) for j in stick}
        big = max(abs(v) for v in c.values())
        c = {j: v for j, v in c.items() if abs(v) > 1e-9 * big}
        return c if len(c) > 1 else None

    def group_terms(self, c: dict, x, lam) -> tuple[float, float]:
        """(H, C) of a group (:meth:`group`): the holding force of its stick rows along
        the free motion e, H = sum lam_j c_j (the same for every share of the redundant
        multipliers), and its capacity C = sum mu S_j |c_j|."""
        H = sum(float(lam[self.stick_index[j]]) * cj for j, cj in c.items())
        return H, sum(self.capacity(j, x, lam) * abs(cj) for j, cj in c.items())

    def group_margin(self, c: dict, x, lam) -> float:
        """C - |H| of a group: < 0 where its friction cannot hold the freedom."""
        H, C = self.group_terms(c, x, lam)
        return C - abs(H)

    # ------------------------------------------------------------------ the solve
    def solve(self, lin, n_i: int, rhs, x, xdot, t=None, q=None):
        """The accelerations and multipliers with friction, by Newton on the multipliers.

        Parameters
        ----------
        lin : callable
            ``lin(r) -> K^-1 r``, r (n_x,) or (n_x, k): the mode's linear solve for
            [qddot_I; lambda] (one factorization).
        n_i : int
            Number of independent accelerations (the first entries of a solution).
        rhs : ndarray, shape (n_x,)
            F - h - M b without friction.
        x, xdot : ndarray, shape (n_x,)
        t, q : optional
            Where, for the messages.

        Returns
        -------
        sol : ndarray, shape (n_i + n_rows,)
        F_f : ndarray, shape (n_x,)

        Raises
        ------
        SelfLockingError
            The Newton matrix is singular (friction locks the mechanism) or the
            iteration does not converge (no motion is consistent with the law).
        """
        sol = lin(rhs)
        if not self.sliding:
            return sol, np.zeros_like(rhs)
        lam = sol[n_i:]
        prev = np.inf
        law = self.prepared(x, xdot)  # the per-pose part, once for the iteration
        for it in range(_MAX_ITER):
            F, D = law.generalized(lam)
            sol = lin(rhs + F)
            r = lam - sol[n_i:]
            rn = float(np.linalg.norm(r))
            scale = max(float(np.linalg.norm(sol[n_i:])), 1e-300)
            if rn <= 1e-14 * scale or (it >= 2 and rn <= 1e-9 * scale and rn > 0.5 * prev):
                return sol, F
            Jn = np.eye(lam.size) - lin(D)[n_i:]
            try:
                step = np.linalg.solve(Jn, r)
            except np.linalg.LinAlgError:
                raise SelfLockingError(self._where("the friction of " + ", ".join(
                    repr(j) for j in self.sliding) + " locks the mechanism (self-locking: "
                    "the Newton matrix of the friction solve is singular)"), t=t, q=q) from None
            lam, prev = lam - step, rn
        raise SelfLockingError(self._where(
            f"the friction solve did not converge in {_MAX_ITER} Newton iterations "
            f"(residual {rn:.3g} of {scale:.3g}); the friction of "
            + ", ".join(repr(j) for j in self.sliding) + " may lock the mechanism"), t=t, q=q)

    def _where(self, msg: str) -> str:
        return f"{msg} in mode {{{', '.join(sorted(self.ms.mode))}}}"
