"""Unilateral contacts of a mechanism: their gaps, which touch, their terms in a mode,
and the mode at a switching instant.

:func:`gap_measures` and :func:`gaps` give the gap of every stop side and contact,
:func:`touching` those closed to within a tolerance, :func:`row_terms` a mode's view of
their rows (rates, force directions, acceleration offsets).  :func:`resolve_mode`
decides, at a switching instant, which touching constraints stay closed and whether
frictional contacts stick or slip: the complementarity problem of their forces
(:mod:`mechdyn.contact.complementarity`, where the LCP and the frictional impact are
solved; their names are also importable from here).
"""

from __future__ import annotations

import numpy as np

from ..contact.complementarity import (
    MAX_FRICTIONAL_ROWS,
    ContactError,
    FrictionalImpulse,
    LCPResult,
    constrained_inverse,
    solve_frictional_impact,
    solve_lcp,
)
from ..dynamics.mode_system import ModeSystem, mode_system
from ..kernels import rows_numpy
from ..model.rows import concat
from ..model.state import contact_of, contact_token, friction_token, side_token, stick_key
from ..model.switchable import Row, SwitchedModel

__all__ = ["ContactError", "solve_lcp", "LCPResult", "resolve_mode", "constrained_inverse",
           "row_terms", "FrictionalImpulse", "solve_frictional_impact", "MAX_FRICTIONAL_ROWS",
           "gap_measures", "gaps", "touching"]


def _drop(restitution: float = 0.5):
    """The model of the Examples: a 1 kg ball (0.1 kg m^2) in a vertical prismatic guide
    ``"guide"`` from the ground origin, its height the travel ``"s"`` (poses x = (x, y,
    angle), so s = y), and a stop ``"floor"`` at s >= 0 with that restitution."""
    from ..mechanism.contact import Stop
    from ..mechanism.mechanism import Mechanism
    m = Mechanism("drop")
    m.add_body("ball", mass=1.0, inertia=0.1)
    m.add_prismatic("guide", "ground", "ball", axis=(0.0, 1.0))
    m.add_coordinate("s", kind="travel", joint="guide")
    m.add(Stop("floor", "s", lower=0.0, restitution=restitution))
    return m.compile()




def row_terms(ms: ModeSystem, rows: list[Row], x, xdot, B, b):
    """A mode's view of some rows: their rates, force directions and acceleration
    offsets in the mode's independent coordinates.

    Parameters
    ----------
    ms : ModeSystem
        The mode (:class:`~mechdyn.dynamics.mode_system.ModeSystem`).
    rows : list of Row
        Rows of the switched model (:meth:`SwitchedModel.rows`).
    x, xdot : ndarray, shape (n_x,)
        Body poses (m, rad) and rates (m/s, rad/s).
    B : ndarray, shape (n_x, n_i)
        xdot = B qdot_I (the mode's velocity analogs).
    b : ndarray, shape (n_x,)
        xddot = B qddot_I + b, m/s^2 and rad/s^2.

    Returns
    -------
    C : ndarray, shape (m, n_i)
        Rates: rate = C qdot_I.
    W : ndarray, shape (m, n_i)
        The force directions, C with the sliding friction of rows that slip.
    d : ndarray, shape (m,)
        Acceleration offsets: accel = C qddot_I + d.

    Examples
    --------
    The floor stop's row is the ball's height s, the mode's one coordinate:

    >>> import numpy as np
    >>> from mechdyn.model.switchable import switched_model
    >>> sm = switched_model(_drop())
    >>> from mechdyn.dynamics.mode_system import ModeSystem
    >>> x = np.zeros(3)
    >>> ms = ModeSystem(sm, frozenset(), {}, x)
    >>> B, _ = ms.velocity_analogs(x)
    >>> rows = sm.rows(frozenset({"floor@lower"}), {})
    >>> row_terms(ms, rows, x, np.array([0.0, -2.0, 0.0]), B, np.zeros(3))
    (array([[1.]]), array([[1.]]), array([0.]))
    """
    n = B.shape[1]
    if not rows:
        return np.zeros((0, n)), np.zeros((0, n)), np.zeros(0)
    nb = ms.model.n_bodies
    _, g, quad = rows_numpy.evaluate(concat(nb, *[r.rows for r in rows]), x, xdot)
    gw = g.copy()
    for k, r in enumerate(rows):
        if r.slip:
            gw[k] += rows_numpy.jacobian(r.friction_rows, x)[0]
    return g @ B, gw @ B, g @ b + quad


def gap_measures(sm: SwitchedModel):
    """``(token, measure, sign, limit)`` of every stop side and contact, its gap being
    sign (measure - limit).

    Parameters
    ----------
    sm : SwitchedModel
        The switchable elements of a model.

    Yields
    ------
    tuple
        (``"stop@lower"`` | ``"stop@upper"`` | ``"contact@contact"``, Measure, +1.0 or
        -1.0, limit in m or rad).

    Examples
    --------
    >>> import numpy as np
    >>> from mechdyn.model.switchable import switched_model
    >>> sm = switched_model(_drop())
    >>> [(tok, sign, limit) for tok, _, sign, limit in gap_measures(sm)]
    [('floor@lower', 1.0, 0.0)]
    """
    for n, (st, meas) in sm.stops.items():
        for side in st.sides():
            yield side_token(n, side), meas, (1.0 if side == "lower" else -1.0), getattr(st, side)
    for n, (_ct, gap, _) in sm.contacts.items():
        yield contact_token(n), gap, 1.0, 0.0


def gaps(sm: SwitchedModel, x) -> dict:
    """The gap of every stop side and contact.

    Parameters
    ----------
    sm : SwitchedModel
        The switchable elements of a model.
    x : ndarray, shape (..., n_x)
        Body poses, m and rad.

    Returns
    -------
    dict
        {token: (gap (...), is_angle)}: m, or rad for angle stops, negative where it
        penetrates.

    Examples
    --------
    The ball 0.3 m above the floor:

    >>> import numpy as np
    >>> from mechdyn.model.switchable import switched_model
    >>> sm = switched_model(_drop())
    >>> g, is_angle = gaps(sm, np.array([0.0, 0.3, 0.0]))["floor@lower"]
    >>> float(g), is_angle
    (0.3, False)
    """
    return {tok: (sign * (rows_numpy.values(m.rows, x)[..., 0] - lim), m.is_angle)
            for tok, m, sign, lim in gap_measures(sm)}


def touching(sm: SwitchedModel, x, *, gap_tol: float) -> list[str]:
    """Unilateral tokens whose gap is within ``gap_tol``.

    Parameters
    ----------
    sm : SwitchedModel
        The switchable elements of a model.
    x : ndarray, shape (n_x,)
        Body poses, m and rad.
    gap_tol : float
        m, or rad for angle stops.

    Returns
    -------
    list of str
        The tokens (:func:`gaps`), in the model's order.

    Examples
    --------
    >>> import numpy as np
    >>> from mechdyn.model.switchable import switched_model
    >>> sm = switched_model(_drop())
    >>> touching(sm, np.array([0.0, 1e-12, 0.0]), gap_tol=1e-9)
    ['floor@lower']
    >>> touching(sm, np.array([0.0, 0.3, 0.0]), gap_tol=1e-9)
    []
    """
    return [tok for tok, (g, _) in gaps(sm, x).items() if g <= gap_tol]


def resolve_mode(sm: SwitchedModel, t, x, xdot, locks, targets: dict, candidates,
                 *, slip_velocity_tol: float, force_tol: float, forced_open=(),
                 forced_slip: dict | None = None, forced_stick=(), workspace=None):
    """Decide which touching constraints are closed, and stick or slip, at a state.

    Parameters
    ----------
    sm : SwitchedModel
    t : float
    x, xdot : ndarray, shape (n_x,)
        A pose and velocity consistent with the locks; the candidates' gaps
        and gap rates are (nearly) zero.
    locks : frozenset of str
        The engaged locks (bilateral).
    targets : dict
        Held values of the locks; updated with the stick positions chosen.
    candidates : iterable of str
        Unilateral tokens (``"stop@lower"``, contact names) that may close.
    slip_velocity_tol : float
        Below this tangential speed (m/s) a frictional contact may stick.
    force_tol : float
        Forces below it (N) count as zero.
    forced_open : iterable of str
        Tokens whose force just fell to zero: kept open unless their gap would
        then accelerate into penetration.
    forced_slip : dict, optional
        {contact: +1/-1}: contacts that must slip in that direction (they
        just broke away from sticking).
    forced_stick : iterable of str
        Contacts whose slip velocity just vanished: they are tried sticking first.
    workspace : Workspace, optional
        The run's workspace (:func:`~mechdyn.dynamics.mode_system.mode_system`).

    Returns
    -------
    mode : frozenset of str
    lam : dict
        Normal force of each closed token (N, or N m for angle stops).

    Raises
    ------
    ContactError
    """
    locks = frozenset(locks)
    cand = sorted(set(candidates))
    if not cand:
        return locks, {}
    forced_open = set(forced_open)
    forced_slip = dict(forced_slip or {})
    base = mode_system(sm, locks, targets, x, workspace=workspace)
    terms = base.terms(t, x, xdot)
    B, b, A, f = terms["B"], terms["b"], terms["A"], terms["f"]
    # friction state of each candidate contact
    fric = {}
    for tok in cand:
        c = contact_of(tok)
        if c is not None and sm.contacts[c][0].friction > 0:
            if c in forced_slip:
                fric[c] = "slip+" if forced_slip[c] > 0 else "slip-"
                continue
            vt = sm.contacts[c][2].rate(x, xdot)
            if abs(vt) <= slip_velocity_tol or c in forced_stick:
                fric[c] = "stick"
            else:
                fric[c] = "slip+" if vt > 0 else "slip-"
    active = [c for c in cand if c not in forced_open]
    for _ in range(4 * len(cand) + 4):
        toks = frozenset(active) | frozenset(friction_token(c, s) for c, s in fric.items()
                                             if contact_token(c) in active)
        stick_targets = dict(targets)
        for c in [a for a in map(contact_of, active) if a is not None]:
            if fric.get(c) == "stick":
                stick_targets[stick_key(c)] = sm.contacts[c][2].value(x)
        rows = sm.rows(toks, stick_targets)
        eq = [r for r in rows if r.kind == "stick"]
        uni = [r for r in rows if r.unilateral]
        Ce, _, de = row_terms(base, eq, x, xdot, B, b)
        Cu, Wu, du = row_terms(base, uni, x, xdot, B, b)
        # equality rows: A qdd = f + Ce^T mu + Wu^T lam ; Ce qdd + de = 0
        n = A.shape[0]
        ne = Ce.shape[0]
        K = np.block([[A, -Ce.T], [Ce, np.zeros((ne, ne))]])
        Kinv = np.linalg.pinv(K) if K.size else np.zeros((0, 0))
        base_sol = Kinv @ np.concatenate([f, -de]) if K.size else np.zeros(0)
        resp = Kinv[:, :n] @ Wu.T if K.size else np.zeros((0, len(uni)))
        H = Cu @ resp[:n] + np.diag(np.array([r_.compliance for r_ in uni], float))
        sol = solve_lcp(H, Cu @ base_sol[:n] + du)
        lam, acc = sol.z, sol.w
        mu_e = base_sol[n:] + resp[n:] @ lam if ne else np.zeros(0)
        changed = False
        # drop rows without force (they separate or just touch)
        keep = [u.label for u, l_ in zip(uni, lam, strict=True) if l_ > force_tol]
        if set(keep) != set(active):
            active = keep
            changed = True
        # friction: sticking force within the cone?
        lam_n = {u.element: l_ for u, l_ in zip(uni, lam, strict=True) if u.kind == "contact"}
        for r_, m_ in zip(eq, mu_e, strict=True):
            c = r_.element
            mu = sm.contacts[c][0].friction
            if contact_token(c) in active and \
                    abs(m_) > mu * lam_n.get(c, 0.0) * (1 + 1e-12) + force_tol:
                fric[c] = "slip-" if m_ > 0 else "slip+"
                changed = True
        if not changed:
            # released tokens must not accelerate into penetration
            reopen = []
            if forced_open:
                trial = sm.rows(frozenset(forced_open & set(cand)), targets)
                Ct, _, dt_ = row_terms(base, [r_ for r_ in trial if r_.unilateral], x, xdot, B,
                                       b)
                qdd = base_sol[:n] + resp[:n] @ lam
                at = Ct @ qdd + dt_
                for r_, a_ in zip([r_ for r_ in trial if r_.unilateral], at, strict=True):
                    if a_ < -1e-6 * max(1.0, float(np.max(np.abs(acc)) if acc.size else 1.0)):
                        reopen.append(r_.label)
            if reopen:
                forced_open -= set(reopen)
                active = sorted(set(active) | set(reopen))
                continue
            targets.update(stick_targets)  # the stick positions chosen
            return locks | toks, {u.label: float(l_) for u, l_ in zip(uni, lam, strict=True)
                                  if u.label in active}
    raise ContactError("the contact and friction states do not settle (stick/slip cycling)",
                       t=t)
