"""Static indeterminacy by influence coefficients (the cyclic-automata method).

A body rests on k possible contact or support points.  Their forces lambda (k,) (N,
positive when the support pushes) and the gaps g (k,) (m, open when positive) are linked
by the full influence-coefficient (compliance) matrix C (k x k, m/N, symmetric positive
semidefinite) and the active-force term q = C_Plambda P + g0 (the gaps that the active
loads P and the initial clearances g0 produce, m):

    g = C lambda + q - A u,

where u (m,) is the unknown rigid-body motion of the supported body and A (k x m) maps it
to the gaps (A = 0 columns, m = 0, when the body cannot move as a whole).  A unilateral
support obeys Signorini's conditions lambda >= 0, g >= 0, lambda g = 0; a bilateral one
keeps g = 0 with a force of either sign; the body is in equilibrium, A^T lambda = f (the
resultant of the active loads in the coordinates of u).  These are exactly the optimality
conditions of the convex quadratic programme

    minimize 1/2 lambda^T C lambda + q^T lambda
    subject to A^T lambda = f,  lambda_i >= 0 for the unilateral supports,

in which u is the multiplier of the equilibrium equations.  The small systems of a
machine are solved exactly, by their active sets: for a guessed set of closed supports
the KKT equations are linear; the primal-dual active-set iteration updates the guess
(open a closed support whose force came out negative, close an open one whose gap came
out negative) and, should it cycle, every set is tried (at most 2^16 sets).  The answer
is accepted only when every condition holds to the tolerance, so it is the exact
solution up to rounding.

:func:`beam_on_supports` builds C, q, A and f for a beam (rigid, or flexible with the
bending stiffness EI) on elastic supports; :func:`share_by_compliance` shares the
reactions of redundant bilateral joints by their compliances rather than by the minimum
norm.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError

__all__ = ["SupportSolution", "SupportProblem", "check_compliance", "load_gaps",
           "solve_supports", "simple_beam_influence", "beam_on_supports",
           "share_by_compliance"]

#: the largest number of unilateral supports whose active sets are all tried
MAX_ENUMERATED = 16


def check_compliance(C, *, name: str = "C") -> np.ndarray:
    """A compliance (influence-coefficient) matrix, checked.

    Parameters
    ----------
    C : array_like, shape (k, k)
        m/N (or any consistent units); symmetric positive semidefinite.
    name : str
        Its name in the error messages.

    Returns
    -------
    ndarray, shape (k, k)
        The matrix as floats, symmetrised (its rounding-level asymmetry removed).

    Raises
    ------
    ModelError
        Not square, not finite, not symmetric (to 1e-9 relative) or with a negative
        eigenvalue (below -1e-10 of the largest).

    Examples
    --------
    >>> check_compliance([[2.0, 1.0], [1.0, 2.0]]).tolist()
    [[2.0, 1.0], [1.0, 2.0]]
    >>> try:
    ...     check_compliance([[1.0, 2.0], [2.0, 1.0]])
    ... except ModelError as exc:
    ...     print(str(exc)[:61])
    C is not positive semidefinite: its smallest eigenvalue is -1
    """
    a = np.asarray(C, dtype=float)
    if a.ndim != 2 or a.shape[0] != a.shape[1]:
        raise ModelError(f"{name} must be a square (k x k) matrix, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ModelError(f"{name} has non-finite entries (a rigid support has compliance 0, "
                         "not an infinite one)")
    scale = float(np.max(np.abs(a), initial=0.0))
    asym = float(np.max(np.abs(a - a.T), initial=0.0))
    if asym > 1e-9 * max(scale, 1e-300):
        i, j = np.unravel_index(int(np.argmax(np.abs(a - a.T))), a.shape)
        raise ModelError(f"{name} is not symmetric: {name}[{i}, {j}] = {a[i, j]:.6g} but "
                         f"{name}[{j}, {i}] = {a[j, i]:.6g} (influence coefficients are "
                         "reciprocal, Maxwell-Betti)")
    a = 0.5 * (a + a.T)
    if a.size:
        ev = np.linalg.eigvalsh(a)
        if ev[0] < -1e-10 * max(abs(ev[-1]), 1e-300):
            raise ModelError(f"{name} is not positive semidefinite: its smallest eigenvalue "
                             f"is {ev[0]:.6g} (the largest {ev[-1]:.6g}); a compliance matrix "
                             "stores energy, it cannot give it")
    return a


def load_gaps(C_P, P, initial_gaps=None) -> np.ndarray:
    """The active-force term q = C_Plambda P + g0 (m).

    Parameters
    ----------
    C_P : array_like, shape (k, n_P)
        Gap at each support per unit active load, m/N (a load that closes a gap gives a
        negative coefficient).
    P : array_like, shape (n_P,)
        The active loads, N.
    initial_gaps : array_like, shape (k,), optional
        Clearances without load, m (default 0).

    Returns
    -------
    ndarray, shape (k,)
        The gaps the loads alone would leave, m (negative: the support must push).

    Raises
    ------
    ModelError
        Shapes that do not match.

    Examples
    --------
    >>> load_gaps([[-1e-6], [-2e-6]], [1000.0], [0.0, 1e-3]).tolist()
    [-0.001, -0.001]
    """
    cp = np.atleast_2d(np.asarray(C_P, dtype=float))
    p = np.asarray(P, dtype=float).reshape(-1)
    if cp.shape[1] != p.size:
        raise ModelError(f"C_P has {cp.shape[1]} column(s) but P has {p.size} load(s)")
    q = cp @ p
    if initial_gaps is not None:
        g0 = np.asarray(initial_gaps, dtype=float).reshape(-1)
        if g0.size != q.size:
            raise ModelError(f"initial_gaps has {g0.size} value(s) for {q.size} support(s)")
        q = q + g0
    return q


@dataclass
class SupportSolution:
    """The forces of the supports and what goes with them.

    Attributes
    ----------
    forces : ndarray, shape (k,)
        lambda, N (positive: the support pushes).
    gaps : ndarray, shape (k,)
        g = C lambda + q - A u, m (exactly 0 where closed).
    motion : ndarray, shape (m,)
        u, the rigid-body motion of the supported body (the multipliers of the
        equilibrium equations).
    closed : ndarray of bool, shape (k,)
        The supports that carry load (bilateral ones always).
    method : str
        ``"active-set"`` (primal-dual iteration) or ``"enumeration"``.
    residual : float
        Largest violation of the conditions, relative to the load and gap scales.

    Examples
    --------
    A rigid beam on rigid supports at 0 and 2 m, 900 N at 1.5 m (statics: 225 N, 675 N):

    >>> s = beam_on_supports([0.0, 2.0], loads=[(1.5, 900.0)]).solve()
    >>> s.forces.tolist(), s.closed.tolist(), s.method
    ([225.0, 675.0], [True, True], 'active-set')
    """

    forces: np.ndarray
    gaps: np.ndarray
    motion: np.ndarray
    closed: np.ndarray
    method: str
    residual: float


def _kkt(C, q, A, f, closed):
    """Forces, motion and gaps with ``closed`` the closed supports; None if they do not
    determine them (a mechanism, or forces not unique)."""
    k, m = A.shape
    s = np.flatnonzero(closed)
    n = s.size + m
    K = np.zeros((n, n))
    K[:s.size, :s.size] = C[np.ix_(s, s)]
    K[:s.size, s.size:] = -A[s]
    K[s.size:, :s.size] = A[s].T
    rhs = np.concatenate([-q[s], f])
    if n == 0:
        z = np.zeros(0)
    else:
        sv = np.linalg.svd(K, compute_uv=False)
        if sv[-1] <= 1e-12 * max(sv[0], 1e-300) * n:
            return None
        z = np.linalg.solve(K, rhs)
    lam = np.zeros(k)
    lam[s] = z[:s.size]
    u = z[s.size:]
    g = C @ lam + q - A @ u
    g[s] = 0.0  # closed: zero by the solve (its rounding dropped)
    return lam, u, g


def _violation(lam, g, uni, lam_scale, gap_scale):
    """Largest relative violation of the sign conditions (the closed gaps are zero by the
    solve, to rounding)."""
    if not uni.any():
        return 0.0
    return max(float(np.max(-np.minimum(lam[uni], 0.0))) / lam_scale,
               float(np.max(-np.minimum(g[uni], 0.0))) / gap_scale)


def solve_supports(C, q, *, bilateral=None, equilibrium=None,
                   tol: float = 1e-9) -> SupportSolution:
    """The forces of unilateral (and bilateral) supports with the compliance matrix C.

    Solves min 1/2 lambda^T C lambda + q^T lambda subject to A^T lambda = f and
    lambda_i >= 0 on the unilateral supports (see the module notes).

    Parameters
    ----------
    C : array_like, shape (k, k)
        Influence coefficients, m/N: symmetric positive semidefinite.
    q : array_like, shape (k,)
        The active-force term C_Plambda P + g0, m (:func:`load_gaps`).
    bilateral : array_like of bool, shape (k,), optional
        True for supports that also pull (no sign condition; always closed).
    equilibrium : (A, f), optional
        A (k, m): the gap change per unit rigid-body motion u of the supported body is
        -A u; f (m,): the resultant of the active loads, so that A^T lambda = f.
        Omitted: the body has no rigid-body motion (m = 0).
    tol : float
        Accepted relative violation of the conditions.

    Returns
    -------
    SupportSolution

    Raises
    ------
    ModelError
        Bad shapes or C (:func:`check_compliance`); no set of supports holds the body (it
        is a mechanism under the load); the forces are not unique (rigid supports with no
        compliance to share the load).

    Examples
    --------
    Two equal springs of 1e-6 m/N under a rigid block loaded by 1000 N (one translation
    u): each carries half.

    >>> s = solve_supports(np.eye(2) * 1e-6, [0.0, 0.0],
    ...                    equilibrium=([[1.0], [1.0]], [1000.0]))
    >>> s.forces.round(9).tolist(), round(float(s.motion[0]), 12)
    ([500.0, 500.0], 0.0005)
    """
    C = check_compliance(C)
    k = C.shape[0]
    q = np.asarray(q, dtype=float).reshape(-1)
    if q.size != k:
        raise ModelError(f"q has {q.size} value(s) but C is {k} x {k}")
    bil = np.zeros(k, dtype=bool) if bilateral is None else np.asarray(bilateral, dtype=bool)
    if bil.shape != (k,):
        raise ModelError(f"bilateral must give one flag per support ({k}), got shape "
                         f"{bil.shape}")
    if equilibrium is None:
        A, f = np.zeros((k, 0)), np.zeros(0)
    else:
        A = np.asarray(equilibrium[0], dtype=float).reshape(k, -1) if k else np.zeros((0, 0))
        f = np.asarray(equilibrium[1], dtype=float).reshape(-1)
        if A.shape != (k, f.size):
            raise ModelError(f"equilibrium: A must be (k, m) = ({k}, {f.size}) for the {f.size} "
                             f"equilibrium equation(s) in f, got shape {np.shape(equilibrium[0])}")
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(A)) and np.all(np.isfinite(f))):
        raise ModelError("q and the equilibrium equations must be finite")
    uni = ~bil
    f_scale = float(np.max(np.abs(f), initial=0.0))
    q_scale = float(np.max(np.abs(q), initial=0.0))
    C_scale = float(np.max(np.abs(C), initial=0.0))
    A_scale = float(np.max(np.abs(A), initial=0.0))

    def scales(lam, u):
        """Force and gap scales of a candidate: its own forces, not q / C (which is
        unbounded for rigid supports and would accept pulling ones)."""
        ls = max(f_scale, float(np.max(np.abs(lam), initial=0.0)), 1e-300)
        return ls, max(q_scale, C_scale * ls, A_scale * float(np.max(np.abs(u), initial=0.0)),
                       1e-300)
    singular_ok = []  # solutions of sets whose KKT matrix is singular

    def attempt(closed):
        sol = _kkt(C, q, A, f, closed)
        if sol is None:
            # a singular set may still satisfy the conditions: forces not unique
            ns = int(closed.sum())
            K = np.block([[C[np.ix_(closed, closed)], -A[closed]],
                          [A[closed].T, np.zeros((A.shape[1],) * 2)]])
            rhs = np.concatenate([-q[closed], f])
            z = np.linalg.lstsq(K, rhs, rcond=None)[0]
            lam = np.zeros(k)
            lam[closed] = z[:ns]
            g = C @ lam + q - A @ z[ns:]
            solved = np.max(np.abs(K @ z - rhs), initial=0.0) <= 1e-9 * max(
                float(np.max(np.abs(K), initial=0.0)) * float(np.max(np.abs(z), initial=0.0)),
                float(np.max(np.abs(rhs), initial=0.0)), 1e-300)
            # closed gaps are held by the solve (its residual), open ones checked here
            if solved and _violation(lam, g, uni, *scales(lam, z[ns:])) <= tol:
                singular_ok.append(lam)
            return None
        lam, u, g = sol
        return lam, u, g, _violation(lam, g, uni, *scales(lam, u))

    def unique(sol):
        for other in singular_ok:
            if np.max(np.abs(other - sol.forces)) > 1e-8 * scales(sol.forces, sol.motion)[0]:
                raise ModelError(not_unique)
        return sol

    not_unique = ("the support forces are not unique: the closed supports are statically "
                  "indeterminate and C gives them no compliance to share the load (give the "
                  "supports' or the body's flexibility)")
    closed = np.ones(k, dtype=bool)
    seen = set()
    method = "active-set"
    while closed.tobytes() not in seen:
        seen.add(closed.tobytes())
        res = attempt(closed)
        if res is None:
            break
        lam, u, g, viol = res
        if viol <= tol:
            return unique(SupportSolution(lam, g, u, closed.copy(), method, viol))
        closed = bil | (closed & (lam > 0)) | (~closed & (g < 0))
    n_uni = int(uni.sum())
    if n_uni > MAX_ENUMERATED:
        raise ModelError(f"the support forces were not found by the active-set iteration and "
                         f"there are too many unilateral supports ({n_uni} > "
                         f"{MAX_ENUMERATED}) to try every set")
    idx = np.flatnonzero(uni)
    method = "enumeration"
    for n_open in range(n_uni + 1):
        for opened in itertools.combinations(idx, n_open):
            closed = np.ones(k, dtype=bool)
            closed[list(opened)] = False
            res = attempt(closed)
            if res is not None and res[3] <= tol:
                lam, u, g, viol = res
                return unique(SupportSolution(lam, g, u, closed, method, viol))
    if singular_ok:
        raise ModelError(not_unique)
    raise ModelError("no set of supports holds the body under these loads (with the "
                     "unilateral supports able only to push, the body is a mechanism)")


@dataclass
class SupportProblem:
    """The data of :func:`solve_supports` for one body on its supports.

    Attributes
    ----------
    C : ndarray, shape (k, k)
        m/N.
    q : ndarray, shape (k,)
        m.
    A : ndarray, shape (k, m)
    f : ndarray, shape (m,)
        N (and N m for a rotation).
    bilateral : ndarray of bool, shape (k,)

    Examples
    --------
    Two springs of 1e-6 m/N under a block that can only translate (u: its sinking, m),
    loaded by 1000 N: A = [[1], [1]], f = [1000].

    >>> prob = SupportProblem(np.eye(2) * 1e-6, np.zeros(2), np.ones((2, 1)),
    ...                       np.array([1000.0]), np.zeros(2, bool))
    >>> prob.solve().forces.round(9).tolist()
    [500.0, 500.0]
    """

    C: np.ndarray
    q: np.ndarray
    A: np.ndarray
    f: np.ndarray
    bilateral: np.ndarray

    def solve(self, *, tol: float = 1e-9) -> SupportSolution:
        """:func:`solve_supports` of this problem."""
        return solve_supports(self.C, self.q, bilateral=self.bilateral,
                              equilibrium=(self.A, self.f), tol=tol)


def simple_beam_influence(x, xi, a: float, b: float, EI: float) -> np.ndarray:
    """Deflection at x per unit load at xi of a beam simply supported at a and b.

    Beam theory (Euler-Bernoulli): with l = b - a, s = x - a, t = xi - a, for s <= t
    w = s (l - t) (2 l t - t^2 - s^2) / (6 l EI), and the reciprocal (Maxwell) value for
    s > t.

    Parameters
    ----------
    x, xi : array_like
        Positions, m, within [a, b]; broadcast together.
    a, b : float
        The supports, m (a < b).
    EI : float
        Bending stiffness, N m^2 (> 0).

    Returns
    -------
    ndarray
        m/N, positive along the load.

    Raises
    ------
    ModelError
        a >= b, EI <= 0, or a point outside [a, b].

    Examples
    --------
    Midspan load of a 2 m beam: w = l^3 / (48 EI).

    >>> float(simple_beam_influence(1.0, 1.0, 0.0, 2.0, 1.0)) == 8 / 48
    True
    """
    if not b > a:
        raise ModelError(f"the supports a = {a!r} and b = {b!r} must have a < b")
    if not EI > 0:
        raise ModelError(f"EI must be > 0 (N m^2), got {EI!r}")
    x, xi = np.broadcast_arrays(np.asarray(x, float), np.asarray(xi, float))
    span = 1e-12 * (b - a)
    if np.any((x < a - span) | (x > b + span) | (xi < a - span) | (xi > b + span)):
        raise ModelError(f"simple_beam_influence: positions must lie between the supports "
                         f"[{a:g}, {b:g}] m")
    ln = b - a
    s = np.minimum(x, xi) - a
    t = np.maximum(x, xi) - a
    return s * (ln - t) * (2 * ln * t - t * t - s * s) / (6 * ln * EI)


def _load(i: int, load) -> tuple[float, float]:
    """Load ``i`` of :func:`beam_on_supports` as finite floats (x m, P N)."""
    try:
        xl, p = (float(v) for v in load)
    except (TypeError, ValueError):
        raise ModelError(f"load {i}: expected a pair (x, P) of numbers (m, N), got "
                         f"{load!r}") from None
    if not (np.isfinite(xl) and np.isfinite(p)):
        raise ModelError(f"load {i}: x and P must be finite, got ({xl!r}, {p!r})")
    return xl, p


def beam_on_supports(positions, stiffness=None, *, EI: float = np.inf, loads=(),
                     gaps=None, bilateral=None) -> SupportProblem:
    """C, q and the equilibrium equations of a beam on k supports.

    The beam lies along x; w (m) is its deflection, positive downwards; the loads P are
    positive downwards, the support forces positive upwards.  The rigid-body motion is
    u = (w0, phi): w = w0 + phi x.  The gap of support i is

        g_i = g0_i + lambda_i / k_i + sum_j D_ij lambda_j - sum_loads D(x_i, xi) P - w0 - phi x_i

    with D the influence coefficients of the flexible beam simply supported on its outer
    supports (:func:`simple_beam_influence`; 0 for a rigid beam): C = diag(1/k) + D.

    Parameters
    ----------
    positions : array_like, shape (k,)
        Support positions, m (k >= 2 for a flexible beam: the outer two are its base).
    stiffness : array_like, shape (k,), optional
        Support stiffnesses, N/m (np.inf: rigid; default all rigid).
    EI : float
        Bending stiffness of the beam, N m^2 (np.inf: rigid beam).
    loads : iterable of (x, P)
        Downward point loads P (N) at x (m); on a flexible beam between its outer supports.
    gaps : array_like, shape (k,), optional
        Clearances between the unloaded beam and the supports, m (default 0).
    bilateral : array_like of bool, shape (k,), optional
        Supports that hold the beam down as well.

    Returns
    -------
    SupportProblem

    Raises
    ------
    ModelError
        Shapes, non-positive stiffness or EI, a load that is not a finite pair (x, P),
        loads off a flexible beam.

    Examples
    --------
    A rigid beam on two rigid supports 2 m apart, 900 N at 0.5 m: 675 N and 225 N.

    >>> beam_on_supports([0.0, 2.0], loads=[(0.5, 900.0)]).solve().forces.tolist()
    [675.0, 225.0]
    """
    x = np.asarray(positions, dtype=float).reshape(-1)
    k = x.size
    if k == 0 or not np.all(np.isfinite(x)):
        raise ModelError("positions must be finite support positions (m)")
    kk = np.full(k, np.inf) if stiffness is None else np.asarray(stiffness, float).reshape(-1)
    if kk.size != k:
        raise ModelError(f"stiffness has {kk.size} value(s) for {k} support(s)")
    bad = [i for i, v in enumerate(kk) if not v > 0]
    if bad:
        raise ModelError(f"stiffness of support(s) {bad} must be > 0 N/m (np.inf for rigid), "
                         f"got {[float(kk[i]) for i in bad]}")
    if not EI > 0:
        raise ModelError(f"EI must be > 0 N m^2 (np.inf for a rigid beam), got {EI!r}")
    loads = [_load(i, load) for i, load in enumerate(loads)]
    C = np.diag(1.0 / kk)
    q = np.zeros(k) if gaps is None else np.asarray(gaps, float).reshape(-1).copy()
    if q.size != k:
        raise ModelError(f"gaps has {q.size} value(s) for {k} support(s)")
    if np.isfinite(EI):
        a, b = float(x.min()), float(x.max())
        if k < 2 or a == b:
            raise ModelError("a flexible beam needs supports at two different positions")
        C = C + simple_beam_influence(x[:, None], x[None, :], a, b, EI)
        for xl, p in loads:
            if not a <= xl <= b:
                raise ModelError(f"load at x = {xl:g} m is off the flexible beam's base "
                                 f"[{a:g}, {b:g}] m (overhangs are not modelled)")
            q -= p * simple_beam_influence(x, xl, a, b, EI)
    A = np.column_stack([np.ones(k), x])
    f = np.array([sum(p for _, p in loads), sum(p * xl for xl, p in loads)])
    bil = np.zeros(k, dtype=bool) if bilateral is None else np.asarray(bilateral, bool)
    return SupportProblem(C, q, A, f, bil)


def share_by_compliance(E, b, C) -> np.ndarray:
    """Reactions of redundant bilateral joints shared by their compliances.

    The equilibrium equations E lambda = b of a statically indeterminate structure leave
    lambda free along the null space of E; the minimum-norm choice ignores how stiff each
    joint is.  With the joints' compliance C the reactions are the ones of least
    complementary energy, min 1/2 lambda^T C lambda subject to E lambda = b
    (:func:`solve_supports` with every support bilateral and q = 0).

    Parameters
    ----------
    E : array_like, shape (m, k)
        Equilibrium equations (the transposed constraint Jacobian of the joints).
    b : array_like, shape (m,)
        Their right-hand side (active and inertia loads).
    C : array_like, shape (k, k)
        Compliance of the reaction components (positive definite on the null space of E).

    Returns
    -------
    ndarray, shape (k,)
        The reactions, in the units of b.

    Raises
    ------
    ModelError
        Shapes, C, or E lambda = b has no solution / C leaves it non-unique.

    Examples
    --------
    Two parallel springs carry 30 N in inverse proportion to their compliances 1 and 2.

    >>> share_by_compliance([[1.0, 1.0]], [30.0], np.diag([1.0, 2.0])).round(12).tolist()
    [20.0, 10.0]
    """
    E = np.atleast_2d(np.asarray(E, dtype=float))
    C = check_compliance(C)
    if E.shape[1] != C.shape[0]:
        raise ModelError(f"E has {E.shape[1]} column(s) but C is {C.shape[0]} x {C.shape[0]}")
    k = C.shape[0]
    return solve_supports(C, np.zeros(k), bilateral=np.ones(k, dtype=bool),
                          equilibrium=(E.T, b)).forces
