"""Complementarity problems of unilateral contacts: the LCP of contact forces and
impulses, the frictional impact, the inverse under equality rows.

Following the cyclic-automata document (seed 4), the forces lambda of the
touching unilateral constraints (stops and point-on-line contacts) solve

    a = (G + C) lambda + r >= 0,   lambda >= 0,   lambda^T a = 0

with a the gap accelerations, G = W A^-1 W^T the contact (Delassus) matrix of
the constraint Jacobian W in the current coordinates, A the generalized mass
matrix, C the diagonal compliance (regularization) matrix and r the gap
accelerations without contact forces.  For symmetric G + C (no sliding
friction) this is the bound-constrained quadratic programme

    minimize 1/2 lambda^T (G + C) lambda + r^T lambda,  lambda >= 0,

whose optimality conditions are exactly the complementarity conditions; it is
solved with :func:`scipy.optimize.nnls` on a square-root factor of G + C.  A
sliding contact's friction makes G non-symmetric (no QP exists and no SciPy
routine solves a general LCP); those small problems are solved by enumerating
active sets, which is exact and cheap for the few contacts of a mechanism.

The same solver handles impacts at the velocity level (impulses instead of
forces, Newton's restitution law instead of a >= 0; with Coulomb friction
:func:`solve_frictional_impact`).  What the mechanism's contacts are and which
stay closed at a switching instant is :mod:`mechdyn.simulate.gaps`.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ..errors import ContactError

__all__ = ["ContactError", "solve_lcp", "LCPResult", "constrained_inverse",
           "FrictionalImpulse", "solve_frictional_impact", "MAX_FRICTIONAL_ROWS"]


@dataclass
class LCPResult:
    """Solution of an LCP w = H z + r, z >= 0, w >= 0, z^T w = 0.

    Attributes
    ----------
    z, w : ndarray, shape (m,)
    method : str
        ``"nnls"`` or ``"enumeration"``.
    residual : float
        Largest violation of the conditions, scaled.
    """

    z: np.ndarray
    w: np.ndarray
    method: str
    residual: float


def _lcp_residual(H, r, z):
    w = H @ z + r
    scale = max(np.max(np.abs(r)) if r.size else 0.0, 1e-300)
    hs = max(np.max(np.abs(H)) if H.size else 0.0, 1e-300)
    zs = z * hs
    viol = max(float(np.max(-np.minimum(w, 0.0), initial=0.0)),
               float(np.max(-np.minimum(zs, 0.0), initial=0.0)),
               float(np.max(np.minimum(np.abs(w), np.abs(zs)), initial=0.0)))
    return w, viol / scale


def solve_lcp(H, r, *, tol: float = 1e-9) -> LCPResult:
    """Solve the linear complementarity problem w = H z + r >= 0, z >= 0, z^T w = 0.

    Parameters
    ----------
    H : array_like, shape (m, m)
        Positive semidefinite (symmetric) or a P-matrix (non-symmetric, small m).
    r : array_like, shape (m,)
    tol : float
        Accepted relative violation of the conditions.

    Returns
    -------
    LCPResult

    Raises
    ------
    ContactError
        No solution was found (e.g. the contact configuration is jammed).

    Examples
    --------
    Two coupled contacts pressed together (by hand: 2 z1 + z2 = 1, z1 + 2 z2 = 1):

    >>> res = solve_lcp([[2.0, 1.0], [1.0, 2.0]], [-1.0, -1.0])
    >>> res.z.round(12).tolist(), res.w.round(12).tolist()
    ([0.333333333333, 0.333333333333], [0.0, 0.0])
    """
    H = np.atleast_2d(np.asarray(H, float))
    r = np.asarray(r, float).reshape(-1)
    m = r.size
    if m == 0:
        return LCPResult(np.zeros(0), np.zeros(0), "empty", 0.0)
    if np.all(r >= 0):
        return LCPResult(np.zeros(m), r.copy(), "trivial", 0.0)
    sym = np.allclose(H, H.T, rtol=1e-10, atol=1e-12 * max(np.max(np.abs(H)), 1e-300))
    if sym:
        Hs = 0.5 * (H + H.T)
        s, V = np.linalg.eigh(Hs)
        smax = max(float(s[-1]), 1e-300)
        s = np.maximum(s, 1e-13 * smax)
        # 1/2 z^T H z + r^T z = 1/2 |S^1/2 V^T z + S^-1/2 V^T r|^2 + const
        Lt = np.sqrt(s)[:, None] * V.T
        y = (V.T @ r) / np.sqrt(s)
        from scipy.optimize import nnls
        z, _ = nnls(Lt, -y, maxiter=50 * m)
        w, res = _lcp_residual(H, r, z)
        if res <= tol:
            return LCPResult(z, w, "nnls", res)
    best = None
    if m <= 12:
        for k in range(m + 1):
            for act in itertools.combinations(range(m), k):
                z = np.zeros(m)
                if act:
                    a = list(act)
                    try:
                        z[a] = np.linalg.solve(H[np.ix_(a, a)], -r[a])
                    except np.linalg.LinAlgError:
                        z[a] = np.linalg.lstsq(H[np.ix_(a, a)], -r[a], rcond=None)[0]
                w, res = _lcp_residual(H, r, z)
                if best is None or res < best[2]:
                    best = (z, w, res)
                if res <= tol:
                    return LCPResult(z, w, "enumeration", res)
    if best is not None and best[2] <= 1e3 * tol:
        return LCPResult(best[0], best[1], "enumeration", best[2])
    raise ContactError("the contact problem has no solution (no set of compressive contact "
                       "forces keeps every gap from closing further)")


@dataclass
class FrictionalImpulse:
    """Normal and tangential impulses of an impact with Coulomb friction.

    Attributes
    ----------
    normal : ndarray, shape (m,)
        P_n >= 0 of each unilateral row, N s (N m s for an angle stop).
    tangent : ndarray, shape (m_f,)
        P_t of each frictional row along its tangent, N s.
    states : tuple of str
        ``"stick"``, ``"slip+"`` or ``"slip-"`` of each frictional row (the sign of
        the tangential velocity after the impact).
    qdot_plus : ndarray, shape (n,)
        The generalized velocities after the impact.
    """

    normal: np.ndarray
    tangent: np.ndarray
    states: tuple
    qdot_plus: np.ndarray


#: the largest number of frictional rows in one impact (3^m friction states are tried)
MAX_FRICTIONAL_ROWS = 6


def solve_frictional_impact(Z, p_minus, Cu, target, Ct, of_row, mu, vt_minus, *,
                            tol: float = 1e-9) -> FrictionalImpulse:
    """Impulses of an impact with Newton's restitution and Coulomb friction.

    The impact law (one impulse per contact, Newton-Coulomb): the normal impulses P_n
    and the normal rates after the impact v_n+ are complementary with the restitution
    target, P_n >= 0, v_n+ - target >= 0, P_n (v_n+ - target) = 0; each frictional row
    either sticks (its tangential rate after the impact is zero and |P_t| <= mu P_n) or
    slides (P_t = -mu P_n s with s the sign of its tangential rate after the impact).
    The friction states (stick, slip in the direction of the rate before, slip against
    it) are tried in that order and the first one consistent with Coulomb's law is
    returned.  The friction impulse thus opposes the sliding *after* the impact
    (Coulomb's law at the impulse level, as in velocity-level time stepping): where
    friction alone would reverse the sliding the contact sticks; where the normal
    impulse reverses it (the end of a rotating rod) the whole friction impulse opposes
    the final sliding.  Routh's incremental analysis would split the impulse at the
    reversal; both agree (and Newton's and Poisson's restitution agree) whenever the
    tangential rate keeps its sign through the impact.

    Parameters
    ----------
    Z : ndarray, shape (n, n)
        qdot = Z (p + impulses) (:func:`constrained_inverse` of the mass matrix).
    p_minus : ndarray, shape (n,)
        Generalized momentum before.
    Cu : ndarray, shape (m, n)
        Normal rows (gap rates).
    target : ndarray, shape (m,)
        e max(0, -v_n-) of each row.
    Ct : ndarray, shape (m_f, n)
        Tangential rows of the frictional contacts.
    of_row : sequence of int, length m_f
        The normal row of each tangential row.
    mu : sequence of float, length m_f
    vt_minus : sequence of float, length m_f
        Tangential rates before.
    tol : float

    Returns
    -------
    FrictionalImpulse

    Raises
    ------
    ContactError
        Too many frictional rows, or no friction state is consistent.

    Examples
    --------
    A unit point mass (q = x, y) hits the floor y = 0 at (1, -1) m/s, plastic (e = 0),
    mu = 0.5: the normal impulse 1 N s stops the fall; sticking would need 1 N s > mu P_n,
    so it slides on with 1 - mu P_n = 0.5 m/s.

    >>> imp = solve_frictional_impact(np.eye(2), np.array([1.0, -1.0]), np.array([[0.0, 1.0]]),
    ...                               np.zeros(1), np.array([[1.0, 0.0]]), [0], [0.5], [1.0])
    >>> imp.normal.tolist(), imp.tangent.tolist(), imp.states, imp.qdot_plus.tolist()
    ([1.0], [-0.5], ('slip+',), [0.5, 0.0])
    """
    m, mf = Cu.shape[0], Ct.shape[0]
    if mf > MAX_FRICTIONAL_ROWS:
        raise ContactError(f"{mf} frictional contacts in one impact: at most "
                           f"{MAX_FRICTIONAL_ROWS} are solved")
    n = Z.shape[0]
    mu = np.asarray(mu, float)
    s_pre = np.where(np.asarray(vt_minus, float) < 0, -1, 1)
    v_scale = max(float(np.max(np.abs(Cu @ Z @ p_minus), initial=0.0)),
                  float(np.max(np.abs(vt_minus), initial=0.0)), 1e-300)
    for choice in itertools.product((0, 1, -1), repeat=mf):
        sgn = np.array(choice, dtype=int) * s_pre  # 0 stick, +-1 slip direction
        st = np.flatnonzero(sgn == 0)
        sl = np.flatnonzero(sgn != 0)
        S = np.zeros((sl.size, m))
        S[np.arange(sl.size), np.asarray(of_row, int)[sl]] = -mu[sl] * sgn[sl]
        D = Cu.T + Ct[sl].T @ S
        Cst = Ct[st]
        Kp = np.linalg.pinv(Cst @ Z @ Cst.T) if st.size else np.zeros((0, 0))
        Q = np.eye(n) - Z @ Cst.T @ Kp @ Cst
        qd0, R = Q @ Z @ p_minus, Q @ Z @ D
        try:
            Pn = solve_lcp(Cu @ R, Cu @ qd0 - target, tol=tol).z
        except ContactError:
            continue
        qd = qd0 + R @ Pn
        Pt = np.zeros(mf)
        Pt[st] = -Kp @ Cst @ Z @ (p_minus + D @ Pn)
        Pt[sl] = S @ Pn
        cone = mu[st] * Pn[np.asarray(of_row, int)[st]]
        p_scale = max(float(np.max(np.abs(Pn), initial=0.0)), 1e-300)
        vt = Ct @ qd
        if np.all(np.abs(Pt[st]) <= cone * (1 + tol) + tol * p_scale) and \
                np.all(np.abs(vt[st]) <= tol * v_scale) and \
                np.all(sgn[sl] * vt[sl] >= -tol * v_scale):
            states = tuple("stick" if g == 0 else "slip+" if vt[k] > 0 or (
                vt[k] == 0 and g > 0) else "slip-" for k, g in enumerate(sgn))
            return FrictionalImpulse(Pn, Pt, states, qd)
    raise ContactError("no stick or slip state of the frictional contacts is consistent "
                       "with Coulomb's law in this impact")


def constrained_inverse(A, C_eq):
    """Z = N (N^T A N)^-1 N^T with N a basis of the null space of ``C_eq``.

    With the equality rows C_eq qddot = 0 enforced, qddot = Z f solves
    A qddot = f + C_eq^T mu.

    Parameters
    ----------
    A : ndarray, shape (n, n)
        Symmetric positive definite on the null space (a reduced mass matrix, kg and
        kg m^2).
    C_eq : ndarray, shape (m, n)
        The equality rows (m may be 0); rows that depend on the others are allowed.

    Returns
    -------
    Z : ndarray, shape (n, n)
        Zero where ``C_eq`` leaves no freedom.

    Raises
    ------
    numpy.linalg.LinAlgError
        N^T A N is singular (A not definite on the free motions).

    Examples
    --------
    Holding the first of two coordinates leaves the second, of inertia 1:

    >>> import numpy as np
    >>> A = np.diag([2.0, 1.0])
    >>> constrained_inverse(A, np.array([[1.0, 0.0]])) + 0.0
    array([[0., 0.],
           [0., 1.]])
    >>> constrained_inverse(A, np.zeros((0, 2)))  # no rows: A^-1
    array([[0.5, 0. ],
           [0. , 1. ]])
    """
    n = A.shape[0]
    if C_eq.shape[0] == 0:
        N = np.eye(n)
    else:
        _, s, vt = np.linalg.svd(C_eq)
        rank = int(np.sum(s > 1e-10 * max(s[0] if s.size else 0.0, 1e-300)))
        N = vt[rank:].T
    if N.shape[1] == 0:
        return np.zeros((n, n))
    K = N.T @ A @ N
    return N @ np.linalg.solve(K, N.T)
