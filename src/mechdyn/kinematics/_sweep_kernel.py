"""Private: fast evaluation of the position problem for :mod:`mechdyn.kinematics.sweep`.

The equations are the model's constraint rows (:mod:`mechdyn.model.rows`): the
residual [Phi; g - q], the Jacobian [Phi_x; g_x] and the acceleration
right-hand side [gamma; gamma_g] = -quad, the same rows that
:mod:`mechdyn.kinematics.constraints` evaluates.  This module knows no joint's
formulas; it only evaluates the rows where each evaluator is cheapest and
solves with their Jacobian:

* with numba, one position (the sequential continuation, where NumPy's per-call
  overhead would dominate) and batches (where NumPy's temporaries cost more
  than the compiled loop) go to the compiled drivers of
  :mod:`mechdyn.kernels.rows_sweep`; without numba, to the NumPy evaluator
  :mod:`mechdyn.kernels.rows_numpy`;
* batched linear solves exploit the sparsity of the Jacobian: rows and columns
  are permuted to block-triangular form (a maximum matching followed by the
  strongly connected components, as in the Dulmage-Mendelsohn decomposition),
  so a 15 x 15 system of a six-bar becomes a few scalar equations and two 4 x 4
  blocks, solved level by level over the whole batch.

``tests/unit/test_sweep.py`` checks the kernel against central differences of
its residual, its two evaluation paths against each other and the block solves
against dense ones.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import lapack
from scipy.sparse import csr_array
from scipy.sparse.csgraph import connected_components, maximum_bipartite_matching

from ..kernels import rows_numpy
from ..model import ConstraintLayout, Model
from ..model.rows import concat
from .assembly import _scale

__all__ = ["Kernel"]


def _parity(perm) -> int:
    """+1 for an even permutation, -1 for an odd one."""
    perm = list(perm)
    seen = [False] * len(perm)
    sign = 1
    for i in range(len(perm)):
        if seen[i]:
            continue
        j, length = i, 0
        while not seen[j]:
            seen[j] = True
            j = perm[j]
            length += 1
        if length % 2 == 0:
            sign = -sign
    return sign


class _BlockSolver:
    """Batched solves with a square Jacobian of fixed sparsity, by block-triangular form."""

    def __init__(self, pattern: np.ndarray):
        n = pattern.shape[0]
        self.ok = False
        if pattern.shape[0] != pattern.shape[1] or n == 0:
            return
        match = maximum_bipartite_matching(csr_array(pattern.astype(np.int8)),
                                           perm_type="column")
        if np.any(match < 0):  # structurally singular: leave it to the dense solver
            return
        G = pattern[:, match]  # G[r, r2]: row r involves the variable matched to row r2
        ncomp, label = connected_components(csr_array(G.astype(np.int8)), directed=True,
                                            connection="strong")
        deps = [set() for _ in range(ncomp)]
        rr, cc = np.nonzero(G)
        for r, r2 in zip(rr, cc, strict=True):
            if label[r] != label[r2]:
                deps[label[r]].add(int(label[r2]))
        level = [-1] * ncomp

        def depth(b, stack=()):
            if level[b] < 0:
                if b in stack:  # cannot happen for a condensation, but stay safe
                    raise RuntimeError("cyclic block dependency")
                level[b] = 1 + max((depth(d, (*stack, b)) for d in deps[b]), default=-1)
            return level[b]

        for b in range(ncomp):
            depth(b)
        groups: dict[tuple[int, int], list[np.ndarray]] = {}
        for b in range(ncomp):
            rows = np.flatnonzero(label == b)
            groups.setdefault((level[b], rows.size), []).append(rows)
        self.levels = []  # per level: list of (R (g, s), C (g, s), P (m,) coupling columns)
        solved: set[int] = set()
        order_r: list[int] = []
        for lev in range(max(level) + 1):
            items = []
            new_cols: list[int] = []
            for (lv, _s), blocks in sorted(groups.items()):
                if lv != lev:
                    continue
                R = np.array(blocks, dtype=np.intp)
                C = match[R]
                used = set(np.flatnonzero(pattern[R.reshape(-1)].any(axis=0)).tolist())
                P = np.array(sorted(used & solved), dtype=np.intp)
                items.append((R, C, P))
                order_r.extend(R.reshape(-1).tolist())
                new_cols.extend(C.reshape(-1).tolist())
            solved.update(new_cols)
            self.levels.append(items)
        order_c = match[np.array(order_r, dtype=np.intp)]
        self.perm_sign = _parity(order_r) * _parity(order_c.tolist())
        self.n = n
        self.ok = True

    def factor(self, J, want_sign: bool = True) -> _Factors:
        """Inverses of the diagonal blocks of a batch of Jacobians (N, n, n), and det signs."""
        N = J.shape[0]
        sign = np.full(N, float(self.perm_sign)) if want_sign else None
        levels = []
        for items in self.levels:
            out = []
            for R, C, P in items:
                g, s = R.shape
                Rf = R.reshape(-1)
                coup = J[:, Rf[:, None], P] if P.size else None  # (N, g s, m)
                A = J[:, R[:, :, None], C[:, None, :]]  # (N, g, s, s)
                inv, det_sign = _small_inverse(A, want_sign)
                if want_sign:
                    sign *= np.prod(det_sign, axis=1)
                out.append((C.reshape(-1), Rf, P, coup, inv, g, s))
            levels.append(out)
        return _Factors(levels, sign)

    def apply(self, fac: _Factors, rhs):
        """y with J y = rhs for the factored J; rhs (N, n, k) -> (N, n, k)."""
        N, _, k = rhs.shape
        y = np.empty((N, self.n, k))
        for items in fac.levels:
            for Cf, Rf, P, coup, inv, g, s in items:
                r = rhs[:, Rf]  # (N, g s, k)
                if coup is not None:
                    r = r - coup @ y[:, P]
                if s == 1:
                    y[:, Cf] = r * inv[..., None]
                else:
                    y[:, Cf] = (inv @ r.reshape(N, g, s, k)).reshape(N, g * s, k)
        return y

    def solve(self, J, rhs):
        """y with J y = rhs; J (N, n, n), rhs (N, n, k) -> (N, n, k)."""
        return self.apply(self.factor(J, want_sign=False), rhs)

    def sign(self, J):
        """Sign of det J, (N,)."""
        return self.factor(J, want_sign=True).sign


class _Factors:
    """Block inverses of a batch of Jacobians (see :meth:`_BlockSolver.factor`)."""

    def __init__(self, levels, sign):
        self.levels = levels
        self.sign = sign


def _small_inverse(A, want_sign: bool):
    """Inverses of a stack of s x s matrices (..., s, s) and the signs of their dets.

    Closed forms for s <= 4 (adjugate over determinant: many times faster than LAPACK
    on stacks of tiny matrices, and as accurate for the well-conditioned blocks of a
    mechanism away from dead positions); LAPACK beyond.  For s = 1
    the "inverse" is returned as (...,) reciprocals.
    """
    s = A.shape[-1]
    with np.errstate(divide="ignore", invalid="ignore"):
        if s == 1:
            a = A[..., 0, 0]
            return 1.0 / a, np.sign(a)
        if s == 2:
            a, b, c, d = A[..., 0, 0], A[..., 0, 1], A[..., 1, 0], A[..., 1, 1]
            det = a * d - b * c
            inv = np.stack([np.stack([d, -b], -1), np.stack([-c, a], -1)], -2) / det[..., None,
                                                                                     None]
            return inv, np.sign(det)
        if s == 3:
            c0, c1, c2 = A[..., :, 0], A[..., :, 1], A[..., :, 2]
            r0, r1, r2 = np.cross(c1, c2), np.cross(c2, c0), np.cross(c0, c1)
            det = np.sum(c0 * r0, axis=-1)
            inv = np.stack([r0, r1, r2], -2) / det[..., None, None]
            return inv, np.sign(det)
        if s == 4:
            return _inverse4(A)
    try:
        inv = np.linalg.inv(A)
    except np.linalg.LinAlgError:
        inv = np.linalg.pinv(A)
    return inv, (np.sign(np.linalg.det(A)) if want_sign else None)


def _inverse4(A):
    """Adjugate / determinant of a stack of 4 x 4 matrices, by 2 x 2 minors (Laplace)."""
    a = [[A[..., i, j] for j in range(4)] for i in range(4)]
    # minors of rows 0-1 (s) and rows 2-3 (c), columns (0,1) (0,2) (0,3) (1,2) (1,3) (2,3)
    s0 = a[0][0] * a[1][1] - a[1][0] * a[0][1]
    s1 = a[0][0] * a[1][2] - a[1][0] * a[0][2]
    s2 = a[0][0] * a[1][3] - a[1][0] * a[0][3]
    s3 = a[0][1] * a[1][2] - a[1][1] * a[0][2]
    s4 = a[0][1] * a[1][3] - a[1][1] * a[0][3]
    s5 = a[0][2] * a[1][3] - a[1][2] * a[0][3]
    c0 = a[2][0] * a[3][1] - a[3][0] * a[2][1]
    c1 = a[2][0] * a[3][2] - a[3][0] * a[2][2]
    c2 = a[2][0] * a[3][3] - a[3][0] * a[2][3]
    c3 = a[2][1] * a[3][2] - a[3][1] * a[2][2]
    c4 = a[2][1] * a[3][3] - a[3][1] * a[2][3]
    c5 = a[2][2] * a[3][3] - a[3][2] * a[2][3]
    det = s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0
    b = [a[1][1] * c5 - a[1][2] * c4 + a[1][3] * c3,
         -a[0][1] * c5 + a[0][2] * c4 - a[0][3] * c3,
         a[3][1] * s5 - a[3][2] * s4 + a[3][3] * s3,
         -a[2][1] * s5 + a[2][2] * s4 - a[2][3] * s3,
         -a[1][0] * c5 + a[1][2] * c2 - a[1][3] * c1,
         a[0][0] * c5 - a[0][2] * c2 + a[0][3] * c1,
         -a[3][0] * s5 + a[3][2] * s2 - a[3][3] * s1,
         a[2][0] * s5 - a[2][2] * s2 + a[2][3] * s1,
         a[1][0] * c4 - a[1][1] * c2 + a[1][3] * c0,
         -a[0][0] * c4 + a[0][1] * c2 - a[0][3] * c0,
         a[3][0] * s4 - a[3][1] * s2 + a[3][3] * s0,
         -a[2][0] * s4 + a[2][1] * s2 - a[2][3] * s0,
         -a[1][0] * c3 + a[1][1] * c1 - a[1][2] * c0,
         a[0][0] * c3 - a[0][1] * c1 + a[0][2] * c0,
         -a[3][0] * s3 + a[3][1] * s1 - a[3][2] * s0,
         a[2][0] * s3 - a[2][1] * s1 + a[2][2] * s0]
    inv = np.stack(b, axis=-1).reshape(A.shape) / det[..., None, None]
    return inv, np.sign(det)


def _c(a) -> np.ndarray:
    """A C-contiguous float array (one compiled specialization for every caller)."""
    return np.ascontiguousarray(a, dtype=float)


class Kernel:
    """Residual, Jacobian and gamma of the position problem of one model and layout.

    The equations are the rows of the layout (joints, then engaged locks) followed
    by the coordinate rows, F(x) = [Phi(x); g(x) - q], evaluated by the compiled
    drivers of :mod:`mechdyn.kernels.rows_sweep` (or, when numba is not installed
    or ``compiled`` is set to False, by :mod:`mechdyn.kernels.rows_numpy`).
    Batched methods take 2-D arrays: ``x`` (N, n_x), ``q`` (N, n_q); the ``*1``
    methods take one position (1-D arrays).

    Parameters
    ----------
    model : Model
    layout : ConstraintLayout
        The mode's row layout (``layout.rowset``).
    """

    def __init__(self, model: Model, layout: ConstraintLayout):
        self.model = model
        self.lay = layout
        nb = self.nb = model.n_bodies
        self.n_x = 3 * nb
        self.n_rows = layout.n_rows
        self.n_q = model.n_q
        self.n_eq = layout.n_rows + model.n_q
        self.square = self.n_eq == self.n_x
        self.col_scale = _scale(model)
        #: the rows of F: the layout's constraint rows, then the coordinate rows
        self.rows = concat(nb, layout.rowset, model.coordinate_rows)
        self._ints, self._flts = self.rows.packed()
        from ..kernels import rows_numba, rows_sweep  # numba is imported only here

        self._drivers = rows_sweep
        #: evaluate with the compiled drivers (numba installed), else with NumPy
        self.compiled = rows_numba.NUMBA

        # ---- sparsity pattern and block-triangular solver
        rng = np.random.default_rng(12345)
        L = model.length_scale
        xs = rng.normal(size=(3, self.n_x)) * np.tile([L, L, 3.0], nb)
        with rows_numba.compiling("numba kernels of the kinematic sweep"):
            J = self.system(xs, rng.normal(size=(3, self.n_q)))[1]
            if self.compiled:  # the one-position drivers too
                self.system1(xs[0], np.zeros(self.n_q))
        self.pattern = np.any(J != 0, axis=0)
        self._arange = np.arange(self.n_eq)
        self.blocks = _BlockSolver(self.pattern) if self.square else None
        if self.blocks is not None and not self.blocks.ok:
            self.blocks = None

    # ------------------------------------------------------------------ batched
    def _system_numpy(self, x, q):
        """F and J by the NumPy evaluator, for one pose or a batch."""
        p = rows_numpy.parts(self.rows, x)
        F = rows_numpy.values(self.rows, x, p)
        F[..., self.n_rows:] -= q
        return F, rows_numpy.jacobian(self.rows, x, p)

    def system(self, x, q):
        """F (N, n_eq) (m or rad) and J (N, n_eq, n_x) at poses x (N, n_x), q (N, n_q)."""
        if not self.compiled:
            return self._system_numpy(x, q)
        N = x.shape[0]
        F = np.empty((N, self.n_eq))
        J = np.zeros((N, self.n_eq, self.n_x))
        self._drivers.system_batch(_c(x), _c(q), self.nb, self._ints, self._flts,
                                   self.n_rows, F, J)
        return F, J

    def gamma(self, x, xdot):
        """[gamma; gamma_g] (N, n_eq): [Phi_x; g_x] xddot = this + [0; qddot]."""
        if not self.compiled:
            return -rows_numpy.quad(self.rows, x, xdot)
        out = np.empty((x.shape[0], self.n_eq))
        self._drivers.gamma_batch(_c(x), _c(xdot), self.nb, self._ints, self._flts, out)
        return out

    def solve(self, J, rhs):
        """y with J y = rhs for J (N, n_eq, n_x), rhs (N, n_eq, k) -> (N, n_x, k)."""
        if self.blocks is not None:
            with np.errstate(divide="ignore", invalid="ignore"):
                try:
                    y = self.blocks.solve(J, rhs)
                except np.linalg.LinAlgError:
                    y = None
            if y is not None and np.all(np.isfinite(y)):
                return y
        if self.square:
            try:
                return np.linalg.solve(J, rhs)
            except np.linalg.LinAlgError:
                pass
        return np.linalg.pinv(J) @ rhs

    def factor(self, J, want_sign: bool = True):
        """Factors of a batch of Jacobians for :meth:`apply` (None: use dense solves)."""
        if self.blocks is None:
            return None
        return self.blocks.factor(J, want_sign)

    def apply(self, J, fac, rhs):
        """y with J y = rhs, using the factors of :meth:`factor` when they are usable."""
        if fac is not None:
            with np.errstate(divide="ignore", invalid="ignore"):
                y = self.blocks.apply(fac, rhs)
            if np.all(np.isfinite(y)):
                return y
        return self.solve(J, rhs)

    def sign(self, J):
        """Sign of det [Phi_x; g_x], (N,); the same as ``assembly.branch_sign``."""
        if not self.square:
            return np.ones(J.shape[0])
        if self.blocks is not None:
            return self.blocks.sign(J)
        return np.sign(np.linalg.det(J))

    def rhs_unit(self, N):
        """[0; I], the right-hand side of the velocity-analog equations, (N, n_eq, n_q)."""
        E = np.zeros((N, self.n_eq, self.n_q))
        E[:, self.n_rows:, :] = np.eye(self.n_q)
        return E

    # ------------------------------------------------------------------ one position
    def system1(self, x, q):
        """F (n_eq,) and J (n_eq, n_x) at one position, x (n_x,), q (n_q,)."""
        if not self.compiled:
            return self._system_numpy(x, q)
        F = np.empty(self.n_eq)
        J = np.zeros((self.n_eq, self.n_x))
        self._drivers.system1(_c(x), _c(q), self.nb, self._ints, self._flts, self.n_rows, F, J)
        return F, J

    def gamma1(self, x, xdot):
        """[gamma; gamma_g] (n_eq,) at one position, x and xdot (n_x,)."""
        if not self.compiled:
            return -rows_numpy.quad(self.rows, x, xdot)
        out = np.empty(self.n_eq)
        self._drivers.gamma1(_c(x), _c(xdot), self.nb, self._ints, self._flts, out)
        return out

    def factor1(self, J, want_sign: bool = True):
        """LU factors of one Jacobian: (lu, piv, sign of det), or None if singular/non-square."""
        if not self.square:
            return None
        lu, piv, info = lapack.dgetrf(J)
        if info != 0:
            return None
        sign = 1.0
        if want_sign:
            neg = np.count_nonzero(lu.diagonal() < 0) + np.count_nonzero(piv != self._arange)
            sign = -1.0 if neg % 2 else 1.0
        return lu, piv, sign

    def solve1(self, J, fac, rhs):
        """Solve J y = rhs for one position with the factors of :meth:`factor1`."""
        if fac is not None:
            y, info = lapack.dgetrs(fac[0], fac[1], rhs)
            if info == 0:
                return y
        return np.linalg.pinv(J) @ rhs
