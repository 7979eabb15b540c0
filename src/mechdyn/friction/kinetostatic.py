"""Kinetostatics with friction in the pairs: the nonlinear system of one position,
solved by Newton with the exact Jacobian, batched over positions, and the detection of
self-locking positions.

With the friction of the pairs (:mod:`mechdyn.friction.law`) the kinetostatic
equations of :mod:`mechdyn.kinetostatics.inverse` become, per position,

    r(z) = A z - (I - F) + F_f(-lambda) = 0,        z = [lambda; tau],

(``A = [-Phi_x^T, g_d,x^T]``, the kinetostatic multipliers ``lambda`` being minus
those of the forward convention that the friction law takes), nonlinear because the
friction loads |R| and S are absolute values of the reactions.  Newton starts from
the frictionless solution with the Jacobian ``A - dF_f/dlambda`` and a backtracking
line search on |r| (so a position without a solution stalls instead of cycling).

Self-locking: a position where no finite driving torque moves the mechanism in the
prescribed direction.  It shows as (a) no solution: Newton does not converge,
(b) the Jacobian singular (the required torque unbounded), or (c) a solution on the
far side of the singularity: the determinant of the Jacobian has the opposite sign
of the frictionless matrix's (the friction-cone "jammed" solution, where the driving
torque would have to push the mechanism into its own friction).
"""

from __future__ import annotations

import numpy as np

from ..kinematics.assembly import SINGULAR_RCOND
from .law import FrictionSet

__all__ = ["friction_solve", "locking_note"]

#: Newton iterations per position before a position counts as self-locked
_MAX_ITER = 60
#: relative residual at which Newton stops
RTOL = 1e-13


def _residual(fs: FrictionSet, rows, As, bs, rs, cs_l, x, xdot, zs, signs=None):
    """Residual (n, m), Jacobian (n, m, m) of the scaled system and the friction force
    F_f (n, n_x) at scaled unknowns zs (n, m)."""
    n_l = cs_l.size
    Ff, dF = fs.generalized(x, xdot, -zs[:, :n_l] * cs_l, rows, signs)
    r = np.einsum("nij,nj->ni", As, zs) - bs + rs * Ff
    J = As.copy()
    J[:, :, :n_l] -= rs[None, :, None] * dF * cs_l
    return r, J, Ff


def _step(J, r):
    """Newton steps -J^-1 r, by least squares where J is not square or singular."""
    if J.shape[1] == J.shape[2]:
        try:
            return -np.linalg.solve(J, r[..., None])[..., 0]
        except np.linalg.LinAlgError:
            pass
    return -(np.linalg.pinv(J, rcond=1e-12) @ r[..., None])[..., 0]


def friction_solve(fs: FrictionSet, rows, n_rows: int, As, bs, rs, cs, x, xdot, zs0, *,
                   signs=None):
    """Solve the scaled kinetostatic system with friction at every position.

    Parameters
    ----------
    fs : FrictionSet
        The friction law of the pairs (:class:`~mechdyn.friction.law.FrictionSet`).
    rows : mapping
        {joint: indices of its rows among the multipliers}.
    n_rows : int
        Number of multipliers (the first columns; the driving torques follow).
    As : ndarray, shape (n, n_x, m)
        The scaled frictionless matrix (rows times ``rs``, columns times ``cs``).
    bs : ndarray, shape (n, n_x)
        The scaled right-hand side ``rs (I - F)``.
    rs : ndarray, shape (n_x,)
    cs : ndarray, shape (m,)
        The row and column scales; the first ``m - n_d`` columns are multipliers.
    x, xdot : ndarray, shape (n, n_x)
        The body poses (m, rad) and their rates (m/s, rad/s) at the n positions.
    zs0 : ndarray, shape (n, m)
        The frictionless (scaled) solution: the start.
    signs : mapping, optional
        {joint: +1 / -1}: the slip directions of a switched mode's stick-slip pairs
        (:meth:`FrictionSet.magnitudes`).

    Returns
    -------
    zs : ndarray, shape (n, m)
        The scaled solution (the last iterate where it failed).
    Ff : ndarray, shape (n, n_x)
        The generalized friction force at ``zs``, N and N m.
    locked : ndarray of bool, shape (n,)
        Self-locked positions (see the module docstring).
    info : dict
        ``iterations`` (largest count), ``no_solution``, ``unbounded`` and ``jammed``
        (bool masks of the three symptoms).

    Raises
    ------
    ValueError
        Shapes that do not fit together (from NumPy).

    Examples
    --------
    Without friction pairs the system is linear: a start that solves it, here z = b for
    A = I, is the solution, after no iteration and not locked:

    >>> import numpy as np
    >>> from mechdyn.friction.law import FrictionSet
    >>> from mechdyn.friction.forward import _block
    >>> fs = FrictionSet(_block(), ())
    >>> b = np.array([[2.0, -1.0, 0.5]])
    >>> zs, Ff, locked, info = friction_solve(fs, {}, 2, np.eye(3)[None], b, np.ones(3),
    ...                                       np.ones(3), np.zeros((1, 3)),
    ...                                       np.zeros((1, 3)), b.copy())
    >>> zs, Ff, locked, info["iterations"]
    (array([[ 2. , -1. ,  0.5]]), array([[0., 0., 0.]]), array([False]), 0)
    """
    cs_l = cs[:n_rows]
    zs = zs0.copy()
    n = zs.shape[0]
    r, J, Ff = _residual(fs, rows, As, bs, rs, cs_l, x, xdot, zs, signs)

    def scale(z, F):
        return np.maximum.reduce([np.abs(bs).max(axis=-1),
                                  np.abs(As).max(axis=(1, 2)) * np.abs(z).max(axis=-1),
                                  np.abs(rs * F).max(axis=-1), np.full(n, 1e-300)])

    done = np.abs(r).max(axis=-1) <= RTOL * scale(zs, Ff)
    it = 0
    while not done.all() and it < _MAX_ITER:
        it += 1
        a = ~done
        dz = _step(J[a], r[a])
        nrm0 = np.linalg.norm(r[a], axis=-1)
        alpha = np.ones(a.sum())
        za, ra, Ja, Fa = zs[a], r[a], J[a], Ff[a]
        todo = np.ones(a.sum(), dtype=bool)
        for _ in range(40):  # backtracking: accept the first step that lowers |r|
            zt = za[todo] + alpha[todo, None] * dz[todo]
            rt, Jt, Ft = _residual(fs, rows, As[a][todo], bs[a][todo], rs, cs_l, x[a][todo],
                                   xdot[a][todo], zt, signs)
            ok = np.linalg.norm(rt, axis=-1) <= (1 - 1e-4 * alpha[todo]) * nrm0[todo]
            ok |= ~np.isfinite(nrm0[todo])
            idx = np.flatnonzero(todo)[ok]
            za[idx], ra[idx], Ja[idx], Fa[idx] = zt[ok], rt[ok], Jt[ok], Ft[ok]
            todo[idx] = False
            if not todo.any():
                break
            alpha[todo] *= 0.5
        stalled = np.flatnonzero(a)[todo]  # no descent: a local minimum of |r| without root
        zs[a], r[a], J[a], Ff[a] = za, ra, Ja, Fa
        done |= np.abs(r).max(axis=-1) <= RTOL * scale(zs, Ff)
        if stalled.size:
            done[stalled] = True  # stop iterating them; they are reported as not converged
    conv = np.abs(r).max(axis=-1) <= 1e3 * RTOL * scale(zs, Ff)
    unbounded = np.zeros(n, dtype=bool)
    jammed = np.zeros(n, dtype=bool)
    if As.shape[1] == As.shape[2]:
        sv = np.linalg.svd(J, compute_uv=False)
        unbounded = sv[:, -1] < SINGULAR_RCOND * sv[:, 0]
        s0 = np.linalg.svd(As, compute_uv=False)
        regular = s0[:, -1] >= SINGULAR_RCOND * s0[:, 0]
        jammed = regular & (np.sign(np.linalg.det(J)) != np.sign(np.linalg.det(As)))
    locked = ~conv | unbounded | jammed
    return zs, Ff, locked, {"iterations": it, "no_solution": ~conv, "unbounded": unbounded,
                            "jammed": jammed & conv & ~unbounded}


def locking_note(model, didx, t, q, locked, info) -> str:
    """The warning naming the self-locked positions: the runs of consecutive locked
    samples with the first driven coordinate's values (deg or m) and times, and the
    symptoms.

    Parameters
    ----------
    model : Model
        Its ``coordinate_names`` and ``coord_is_angle`` are used.
    didx : sequence of int
        The driven coordinates' indices (the first is named first; none: coordinate 0).
    t : ndarray, shape (n,)
        The samples' times, s.
    q : ndarray, shape (n, n_q)
        The coordinates at the samples, rad or m.
    locked : ndarray of bool, shape (n,)
        The self-locked samples (at least one).
    info : dict
        The masks ``no_solution``, ``unbounded`` and ``jammed``, shape (n,)
        (:func:`friction_solve`).

    Returns
    -------
    str
        One sentence: the count, each run of locked samples (values, times, sample
        indices) and the count of each symptom.

    Examples
    --------
    Samples 1 and 2 of four, at 10 and 20 deg, have no solution:

    >>> import numpy as np
    >>> from types import SimpleNamespace
    >>> model = SimpleNamespace(coordinate_names=("phi",), coord_is_angle=(True,))
    >>> locked = np.array([False, True, True, False])
    >>> none = np.zeros(4, dtype=bool)
    >>> info = {"no_solution": locked, "unbounded": none, "jammed": none}
    >>> q = np.deg2rad([[0.0], [10.0], [20.0], [30.0]])
    >>> locking_note(model, [0], np.array([0.0, 0.1, 0.2, 0.3]), q, locked, info)
    '2 self-locking position(s): ... at phi = 10 .. 20 deg (t = 0.1 s, samples 1..2) (2 ...'
    """
    k0 = int(didx[0]) if len(didx) else 0
    names = model.coordinate_names
    # the driven coordinate first, then the others (a crank angle when a slider is driven)
    order = [k0, *[k for k in range(len(names)) if k != k0]][:3]

    def span(k, a, b):
        f, unit = (np.rad2deg(1.0), "deg") if model.coord_is_angle[k] else (1.0, "m")
        v0, v1 = q[a, k] * f, q[b - 1, k] * f
        return f"{names[k]} = " + (f"{v0:.6g}" if b == a + 1 else f"{v0:.6g} .. {v1:.6g}") \
            + f" {unit}"

    edges = np.flatnonzero(np.diff(np.concatenate([[0], locked.astype(int), [0]])))
    runs = []
    for a, b in zip(edges[0::2], edges[1::2], strict=True):
        also = ", ".join(span(k, a, b) for k in order[1:])
        runs.append(span(k0, a, b) + (f" ({also})" if also else "")
                    + f" (t = {t[a]:.6g} s, samples {a}..{b - 1})")
    why = [f"{int(info[key].sum())} {text}" for key, text in (
        ("no_solution", "without a solution"), ("unbounded", "with an unbounded torque"),
        ("jammed", "on the jammed side of the friction cone")) if info[key].any()]
    return (f"{int(locked.sum())} self-locking position(s): friction in the pairs locks the "
            f"mechanism (no finite driving torque moves it in the prescribed direction) at "
            + "; ".join(runs) + " (" + ", ".join(why) + "); driving torques, reactions and "
            "losses there are NaN")
