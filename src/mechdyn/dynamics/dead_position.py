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
    IntegrationError,
    LockupError,
    SingularPositionError,
    Status,
)
from ..kinematics.assembly import DEAD_RCOND
from .contact import ContactError

__all__ = ["turning_point", "diagnose", "status_of", "TURN_RCOND"]


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


def turning_point(eqs, step, qd_old, x_good) -> str | None:
    """A coordinate whose rate changes sign during the step may turn back at a dead
    position (the rate of the driving coordinate vanishes there and the mechanism would
    have to change assembly branch to go on): locate the turn on the dense output and
    test the position there.

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
            try:
                xk = ms.solve_position(qk, x_good)
            except AssemblyError:
                xk = None
            rep = ms.singularity(x_good if xk is None else xk)
            if xk is None or (rep["rcond"] < TURN_RCOND
                              and ms.coord_names[k] in rep["coordinates"]):
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
