"""Why a run stopped: dead positions, failed solves and the status of an error.

A run in a mode stops at a *dead* position of the mode's coordinates (the
position Jacobian [rows_I; g_I] of :class:`~mechdyn.dynamics.mode_system.ModeSystem`
singular, the motion not determined by the coordinates).  Two ways of meeting one
are recognised here, both reported with the time, the coordinates and the joints
concerned: a coordinate that turns back where the Jacobian is nearly singular
(:func:`turning_point`; a fixed-step integrator may step across the fold), and a
position solve that fails just beyond the last accepted state (:func:`diagnose`,
which bisects for the edge of the assembly region).
"""

from __future__ import annotations

import numpy as np

from ..errors import (
    AssemblyError,
    ContactError,
    IntegrationError,
    LockupError,
    SingularPositionError,
    Status,
)
from ..kernels import rows_numpy as RN
from ..kernels.rows_numba import NUMBA, rows_jacobian
from ..kinematics.assembly import DEAD_RCOND
from ..mechanism.coordinate import BODY_KINDS
from .compiled import ensure_compiled
from .mode_rows import held_key

__all__ = ["turning_point", "rigid_coordinates", "diagnose", "status_of", "TURN_RCOND"]


def _where(ms, q) -> str:
    return ", ".join(f"{n} = {v:.9g}" for n, v in zip(ms.model.coordinate_names, q,
                                                      strict=True))


def _dependent(rep) -> str:
    return (f"coordinate(s) {', '.join(rep['coordinates']) or '-'} lose control, joints "
            f"{', '.join(rep['joints']) or '-'} become dependent")


#: a coordinate that turns back where sigma_min / sigma_max of the mode's scaled position
#: Jacobian is below this, and which carries its null vector, has met a dead position (a
#: fold: near it sigma_min grows like the square root of the distance, so a fixed step
#: lands within about 1e-2 of it)
TURN_RCOND = 1e-2




def _assembly(rows, b: int) -> set[int]:
    """Body ``b`` and every body that the rows join to it, not passing through the ground
    (a row joins the bodies of its points, when it has a direction, and of its angles;
    the body of its direction alone does not count)."""
    nb = rows.nb
    uses = [set() for _ in range(len(rows))]
    for r in range(len(rows)):
        if np.any(rows.u[r] != 0.0):
            uses[r].update((int(rows.b1[r]), int(rows.b2[r])))
        if rows.ka[r] != 0.0:
            uses[r].add(int(rows.a[r]))
        if rows.kb[r] != 0.0:
            uses[r].add(int(rows.bb[r]))
    found, grew = {b}, True
    while grew:
        grew = False
        for u in uses:
            if u & found and not u <= found:
                found |= u
                grew = True
    return found if nb not in found else set()


def rigid_coordinates(ms, x) -> frozenset:
    """The mode's coordinates that cannot carry a dead position: their positions in
    ``ms.coord_names``.

    The rule: a coordinate that measures a body B (kind ``"x"``, ``"y"`` or ``"angle"``)
    qualifies when moving B rigidly (along x, along y, or turning about B's origin)
    together with every body the mode's constraint rows join to it, none of the rows
    reaching the ground, changes no row and no other coordinate.  That motion w then
    gives J w = e_k for the position Jacobian J = [rows_I; g_I] of the mode and the
    coordinate's row k, so every left null vector u of J has u_k = u^T J w = 0: the
    coordinate never carries a singular position, and the reversals of its rate (a
    base vibrating on its isolators) need no check.  The simplest case is a body whose
    only constraint rows are its coordinate rows (a free body); the base of a
    :func:`~mechdyn.foundation.mounted` machine, with the machine's joints on it and its
    own ``x``, ``y`` and angle coordinates, is the case this is for.  The assembly is
    found from the rows' bodies; J w = e_k is then verified at the pose ``x``.

    Parameters
    ----------
    ms : ModeSystem
    x : ndarray, shape (n_x,)
        A pose of the mode (the check of J w = e_k).

    Returns
    -------
    frozenset of int
        Kept in the run's workspace for the mode, its coordinates and rows (a property
        of the assembly, the same at every pose of the mode).
    """
    model = ms.model
    key = (ms.mode, tuple(int(c) for c in ms.coords),
           np.asarray(ms.independent_rows).tobytes())
    found = ms.ws.rigid.get(key)
    if found is not None:
        return found
    coords = list(model.mechanism.coordinates.values())
    rows = ms.layout.position_rows
    n_ind = len(ms.independent_rows)
    sel = np.concatenate([ms.independent_rows, ms.n_rows + np.asarray(ms.coords, int)])
    J = None
    out = set()
    for k, ci in enumerate(ms.coords):
        c = coords[ci]
        if c.kind not in BODY_KINDS:
            continue
        b = model.body_names.index(c.body)
        bodies = _assembly(ms.rowset, b)
        if not bodies:
            continue  # joined to the ground
        w = np.zeros(model.n_x)
        for i in bodies:
            if c.kind == "angle":  # turning about B's origin
                w[3 * i:3 * i + 3] = (-(x[3 * i + 1] - x[3 * b + 1]), x[3 * i] - x[3 * b], 1.0)
            else:
                w[3 * i + "xy".index(c.kind)] = 1.0
        J = RN.jacobian(rows, x)[sel] if J is None else J
        e = np.zeros(len(sel))
        e[n_ind + k] = 1.0
        Jw = J @ w
        if np.abs(Jw - e).max() <= 1e-9 * max(1.0, np.abs(J).max() * np.abs(w).max()):
            out.add(k)
    return ms.ws.keep(ms.ws.rigid, key, frozenset(out))


def turning_point(eqs, step, qd_old, x_good) -> str | None:
    """A coordinate whose rate changes sign during the step may turn back at a dead
    position (the rate of the driving coordinate vanishes there and the mechanism would
    have to change assembly branch to go on): locate the turn on the dense output and
    test the position there.  The coordinates of :func:`rigid_coordinates` (the pose of
    a free body or of a mounted base, which no singular position can involve) are not
    tested.

    Parameters
    ----------
    eqs : ModeEquations
    step
        The accepted step (``t_old``, ``t``, ``qdot``, ``dense``).
    qd_old : ndarray, shape (n_i,)
        The rates of the mode's coordinates at the start of the step.
    x_good : ndarray, shape (n_x,)
        The pose at the start of the step.

    Returns
    -------
    str or None
        The message of a dead position, or None.
    """
    turns = np.flatnonzero(np.sign(qd_old) * np.sign(step.qdot) < 0)
    if turns.size:
        rigid = rigid_coordinates(eqs.ms, x_good)
        turns = np.array([k for k in turns if k not in rigid], dtype=int)
    if not turns.size:
        return None
    # the dense output and the solves below must leave the run as it is
    kern, ws = eqs.kernel, eqs.ms.ws
    saved = kern.snapshot() if kern is not None else None
    kept = (ws.x, ws.B, ws.qi)
    from scipy.optimize import brentq
    ms = eqs.ms
    try:
        for k in turns:
            try:
                tk = brentq(lambda s, k=k: step.dense(s)[1][k], step.t_old, step.t,
                            xtol=1e-14, rtol=4 * np.finfo(float).eps)
            except ValueError:
                continue
            qk = step.dense(tk)[0]
            if eqs.chart_at(qk) is not None:
                continue  # a bifurcation: the branch goes on through it
            xk = _compiled_pose(eqs, tk, qk, x_good)
            if xk is not None and not _dead_at(ms, xk, k):
                continue  # (the pose of the kernel's Newton: the same decision)
            try:
                xk = ms.solve_position(qk, x_good)
            except AssemblyError:
                xk = None
            rep = ms.singularity(x_good if xk is None else xk)
            if xk is None or _dead_at(ms, xk, k, rep):
                q = ms.coordinates(x_good if xk is None else xk)
                return (f"dead position reached near t = {tk:.9g} s at {_where(ms, q)}: "
                        f"{ms.coord_names[k]} turns back where the position Jacobian is "
                        f"singular (sigma_min/sigma_max {rep['rcond']:.2e}); "
                        f"{_dependent(rep)}; going on would need the other assembly branch")
        return None
    finally:
        ws.x, ws.B, ws.qi = kept
        if saved is not None:
            kern.restore(saved)


def _dead_at(ms, x, k: int, rep=None) -> bool:
    """Whether coordinate ``k`` of the mode turning back at pose ``x`` is a dead position:
    sigma_min / sigma_max below :data:`TURN_RCOND` with the coordinate carrying the null
    vector (``rep``: the singularity report at x, else made here on the position rows'
    Jacobian from the compiled rows, bit for bit the NumPy rows' one and ~20x cheaper)."""
    if rep is None:
        packed = _packed_rows(ms)
        J = None
        if packed is not None:
            nb, ints, flts = packed
            J = np.zeros((len(ints), len(x)))
            ensure_compiled("turning check")
            rows_jacobian(np.asarray(x, float), nb, ints, flts, J, 0)
        rep = ms.singularity(x, jacobian=J)
    return bool(rep["rcond"] < TURN_RCOND and ms.coord_names[k] in rep["coordinates"])


def _packed_rows(ms):
    """``(nb, ints, flts)``: the mode's position rows packed for the compiled Jacobian (None
    without Numba), kept in the run's workspace for the mode's rows and held values (made
    anew for held values that are not numbers)."""
    if not NUMBA:
        return None
    held = held_key(ms.targets)
    key = None if held is None else (ms.mode, held)
    found = None if key is None else ms.ws.turn_rows.get(key)
    if found is None:
        rows = ms.layout.position_rows
        found = ms.ws.keep(ms.ws.turn_rows, key, (rows.nb, *rows.packed()))
    return found


def _compiled_pose(eqs, t: float, qk, x_good):
    """The pose at the mode's coordinates ``qk`` by the compiled kernel's Newton from
    ``x_good`` (the start of :meth:`ModeSystem.solve_position`, a solve about a hundred
    times cheaper), or None (no kernel, or its solve failed: the NumPy solve decides).
    The caller puts the kernel's workspace back."""
    kern = eqs.kernel
    if kern is None or len(eqs.ms.independent_rows) != eqs.ms.n_rows:
        return None
    kern.reset(x_good)
    if kern.rhs(t, qk, np.zeros_like(qk)) is None:
        return None
    return kern.x.copy()


def diagnose(exc, good):
    """(status, message) of a run that stopped with ``exc`` after the accepted state
    ``good`` = (t, ModeEval, ModeSystem) (or None).

    Returns
    -------
    status : Status
    message : str
        With the time and position of a dead position.
    """
    if isinstance(exc, SingularPositionError) or good is None:
        return status_of(exc)
    t_good, ev, ms = good
    if isinstance(exc, AssemblyError) and exc.q is not None \
            and np.size(exc.q) == ms.n_i:
        # the solve failed between an assemblable q_good and q_bad: the segment leaves
        # the assembly region, whose boundary is a singular position; bisect for it
        q_good, q_bad = ev.q[ms.coords], np.asarray(exc.q, float)
        t_bad = exc.t if exc.t is not None else t_good
        lo, hi, x_lo = 0.0, 1.0, ev.x
        while hi - lo > 1e-13:
            mid = 0.5 * (lo + hi)
            try:
                x_lo, lo = ms.solve_position(q_good + mid * (q_bad - q_good), x_lo), mid
            except AssemblyError:
                hi = mid
        rep = ms.singularity(x_lo)
        if rep["rcond"] < DEAD_RCOND:
            return Status.SINGULAR_POSITION, (
                f"dead position reached near t = {t_good + lo * (t_bad - t_good):.9g} s at "
                f"{_where(ms, ms.coordinates(x_lo))}: the mechanism cannot move past it in "
                f"mode {sorted(ms.mode) or '(none)'} (sigma_min/sigma_max of the position "
                f"Jacobian {rep['rcond']:.2e}); {_dependent(rep)}")
        return Status.ASSEMBLY_FAILED, f"position solve failed at t = {t_bad:.9g} s: {exc}"
    rep = ms.singularity(ev.x)
    if rep["rcond"] < DEAD_RCOND:
        return Status.SINGULAR_POSITION, (
            f"dead position near t = {t_good:.9g} s at {_where(ms, ev.q)}: "
            f"sigma_min/sigma_max = {rep['rcond']:.2e}; {_dependent(rep)} ({exc})")
    return status_of(exc)


def status_of(exc):
    """(status, message) of an error that ended a run (:class:`~mechdyn.errors.Status`)."""
    for cls, status in ((SingularPositionError, Status.SINGULAR_POSITION),
                        (AssemblyError, Status.ASSEMBLY_FAILED),
                        (ContactError, Status.NO_CONTACT_SOLUTION), (LockupError, Status.LOCKUP)):
        if isinstance(exc, cls):
            return status, str(exc)
    if isinstance(exc, IntegrationError) and "mass matrix" in str(exc):
        return Status.SINGULAR_MASS_MATRIX, str(exc)
    if isinstance(exc, ArithmeticError):
        return Status.NON_FINITE, f"non-finite values: {exc}"
    if isinstance(exc, np.linalg.LinAlgError):
        return Status.FAILED, f"singular system: {exc}"
    return Status.FAILED, str(exc)
