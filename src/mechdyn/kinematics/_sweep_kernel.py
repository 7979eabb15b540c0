"""Private: fast evaluation of the position problem for :mod:`mechdyn.kinematics.sweep`.

The equations are exactly those of :mod:`mechdyn.kinematics.constraints`
(residual [Phi; g - q], Jacobian [Phi_x; g_x] and the acceleration right-hand
side [gamma; gamma_g]); this module only evaluates them more cheaply:

* the Jacobian is scattered into a pre-zeroed array through index arrays built
  once per model and layout (vectorized path, any batch size);
* a pure-Python path for a single position (the sequential continuation), where
  NumPy's per-call overhead would dominate;
* batched linear solves exploit the sparsity of the Jacobian: rows and columns
  are permuted to block-triangular form (a maximum matching followed by the
  strongly connected components, as in the Dulmage-Mendelsohn decomposition),
  so a 15 x 15 system of a six-bar becomes a few scalar equations and two 4 x 4
  blocks, solved level by level over the whole batch.

``tests/unit/test_sweep.py`` checks every function here against
``constraints.py`` and against dense solves.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import lapack
from scipy.sparse import csr_array
from scipy.sparse.csgraph import connected_components, maximum_bipartite_matching

from ..model import COORD_ANGLE, COORD_RELATIVE, COORD_TRAVEL, ConstraintLayout, Model
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


class Kernel:
    """Residual, Jacobian and gamma of the position problem of one model and layout.

    Batched methods take 2-D arrays: ``x`` (N, n_x), ``q`` (N, n_q); the ``*1``
    methods take one position (1-D arrays).
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

        rv, pr, lk = model.rev, model.pri, model.lock
        act = layout.lock_active
        self.nr, self.np_ = len(rv.names), len(pr.names)
        self.lk_i, self.lk_j = lk.i[act], lk.j[act]
        self.lk_c, self.lk_a = lk.c[act], lk.angle[act]
        self.nl = int(act.sum())
        self.r_rev = 2 * np.arange(self.nr)
        self.r_pri = 2 * self.nr + 2 * np.arange(self.np_)
        self.r_lock = 2 * self.nr + 2 * self.np_ + 3 * np.arange(self.nl)
        self.r_coord = self.n_rows + np.arange(self.n_q)

        kind = model.coord_kind
        self.c_ang = np.flatnonzero(kind == COORD_ANGLE)
        self.c_ang_b = model.coord_body[self.c_ang]
        self.c_rel = np.flatnonzero(kind == COORD_RELATIVE)
        jr = model.coord_joint[self.c_rel]
        self.c_rel_i, self.c_rel_j = rv.i[jr], rv.j[jr]
        self.c_tra = np.flatnonzero(kind == COORD_TRAVEL)
        jt = model.coord_joint[self.c_tra]
        self.c_tra_i, self.c_tra_j = pr.i[jt], pr.j[jt]
        self.c_tra_si, self.c_tra_sj, self.c_tra_ui = pr.si[jt], pr.sj[jt], pr.ui[jt]
        self.c_off = model.coord_offset

        # ---- Jacobian entries: constant ones, and variable ones in two orders
        const: list[tuple[int, int, int, float]] = []
        var_g: list[tuple[np.ndarray, np.ndarray, int]] = []  # group-major (batched path)
        var_1: list[tuple[int, int, int]] = []  # joint-major (single-position path)

        def c_add(rows, bodies, dof, val):
            for r, b in zip(np.atleast_1d(rows), np.atleast_1d(bodies), strict=True):
                const.append((int(r), int(b), dof, float(val)))

        def v_group(rows, bodies, dof):
            var_g.append((np.asarray(rows, int), np.asarray(bodies, int), dof))

        rx, ry = self.r_rev, self.r_rev + 1
        c_add(rx, rv.i, 0, 1.0)
        c_add(ry, rv.i, 1, 1.0)
        c_add(rx, rv.j, 0, -1.0)
        c_add(ry, rv.j, 1, -1.0)
        rev_spec = ((rx, rv.i), (ry, rv.i), (rx, rv.j), (ry, rv.j))
        for rows, bodies in rev_spec:
            v_group(rows, bodies, 2)
        for k in range(self.nr):
            for rows, bodies in rev_spec:
                var_1.append((int(rows[k]), int(bodies[k]), 2))
        rn, ra = self.r_pri, self.r_pri + 1
        pri_spec = [(bodies, dof) for bodies in (pr.j, pr.i) for dof in (0, 1, 2)]
        for bodies, dof in pri_spec:
            v_group(rn, bodies, dof)
        for k in range(self.np_):
            for bodies, dof in pri_spec:
                var_1.append((int(rn[k]), int(bodies[k]), dof))
        c_add(ra, pr.j, 2, 1.0)
        c_add(ra, pr.i, 2, -1.0)
        lx, ly, lt = self.r_lock, self.r_lock + 1, self.r_lock + 2
        c_add(lx, self.lk_j, 0, 1.0)
        c_add(ly, self.lk_j, 1, 1.0)
        c_add(lx, self.lk_i, 0, -1.0)
        c_add(ly, self.lk_i, 1, -1.0)
        c_add(lt, self.lk_j, 2, 1.0)
        c_add(lt, self.lk_i, 2, -1.0)
        v_group(lx, self.lk_i, 2)
        v_group(ly, self.lk_i, 2)
        for k in range(self.nl):
            var_1.append((int(lx[k]), int(self.lk_i[k]), 2))
            var_1.append((int(ly[k]), int(self.lk_i[k]), 2))
        c_add(self.r_coord[self.c_ang], self.c_ang_b, 2, 1.0)
        c_add(self.r_coord[self.c_rel], self.c_rel_j, 2, 1.0)
        c_add(self.r_coord[self.c_rel], self.c_rel_i, 2, -1.0)
        rt = self.r_coord[self.c_tra]
        tra_spec = [(bodies, dof) for bodies in (self.c_tra_j, self.c_tra_i) for dof in (0, 1, 2)]
        for bodies, dof in tra_spec:
            v_group(rt, bodies, dof)
        for k in range(self.c_tra.size):
            for bodies, dof in tra_spec:
                var_1.append((int(rt[k]), int(bodies[k]), dof))

        n_x = self.n_x
        const = [c for c in const if c[1] < nb]
        self.c_flat = np.array([r * n_x + 3 * b + d for r, b, d, _ in const], dtype=np.intp)
        self.c_val = np.array([v for *_, v in const], dtype=float)
        rows = np.concatenate([v[0] for v in var_g])
        bods = np.concatenate([v[1] for v in var_g])
        dofs = np.concatenate([np.full(len(v[0]), v[2]) for v in var_g])
        self.v_keep = np.flatnonzero(bods < nb)
        self.v_flat = (rows * n_x + 3 * bods + dofs)[self.v_keep]
        self.v1_keep = np.array([k for k, (_, b, _) in enumerate(var_1) if b < nb], dtype=np.intp)
        self.v1_flat = np.array([r * n_x + 3 * b + d for r, b, d in var_1 if b < nb],
                                dtype=np.intp)

        # ---- plain-Python tables for the single-position path
        def fl(a):
            return [float(v) for v in a]

        self._rev1 = [(int(rx[k]), int(rv.i[k]), int(rv.j[k]), *fl(rv.si[k]), *fl(rv.sj[k]))
                      for k in range(self.nr)]
        self._pri1 = [(int(rn[k]), int(pr.i[k]), int(pr.j[k]), *fl(pr.si[k]), *fl(pr.sj[k]),
                       *fl(pr.ui[k]), float(pr.angle[k])) for k in range(self.np_)]
        self._lock1 = [(int(lx[k]), int(self.lk_i[k]), int(self.lk_j[k]), *fl(self.lk_c[k]),
                        float(self.lk_a[k])) for k in range(self.nl)]
        self._coord1 = []
        jr_all, jt_all = model.coord_joint, model.coord_joint
        for c in range(self.n_q):
            row, off = self.n_rows + c, float(self.c_off[c])
            if kind[c] == COORD_ANGLE:
                self._coord1.append((0, row, off, int(model.coord_body[c])))
            elif kind[c] == COORD_RELATIVE:
                jj = jr_all[c]
                self._coord1.append((1, row, off, int(rv.i[jj]), int(rv.j[jj])))
            else:
                jj = jt_all[c]
                self._coord1.append((2, row, off, int(pr.i[jj]), int(pr.j[jj]), *fl(pr.si[jj]),
                                     *fl(pr.sj[jj]), *fl(pr.ui[jj])))

        # ---- sparsity pattern and block-triangular solver
        rng = np.random.default_rng(12345)
        L = model.length_scale
        xs = rng.normal(size=(3, self.n_x)) * np.tile([L, L, 3.0], nb)
        J = self.system(xs, rng.normal(size=(3, self.n_q)))[1]
        self.pattern = np.any(J != 0, axis=0)
        self._arange = np.arange(self.n_eq)
        self.blocks = _BlockSolver(self.pattern) if self.square else None
        if self.blocks is not None and not self.blocks.ok:
            self.blocks = None

    # ------------------------------------------------------------------ batched
    def _poses(self, x):
        N = x.shape[0]
        X = np.zeros((N, self.nb + 1, 3))
        X[:, : self.nb] = x.reshape(N, self.nb, 3)
        return X, np.cos(X[:, :, 2]), np.sin(X[:, :, 2])

    @staticmethod
    def _rot(c, s, b, p):
        """A(theta_b) p for bodies b (m,) and points p (m, 2): two (N, m) arrays."""
        cb, sb = c[:, b], s[:, b]
        return cb * p[:, 0] - sb * p[:, 1], sb * p[:, 0] + cb * p[:, 1]

    def _prismatic(self, X, c, s, i, j, si, sj, ui):
        aix, aiy = self._rot(c, s, i, si)
        ajx, ajy = self._rot(c, s, j, sj)
        dx = X[:, j, 0] + ajx - X[:, i, 0] - aix
        dy = X[:, j, 1] + ajy - X[:, i, 1] - aiy
        ux, uy = self._rot(c, s, i, ui)
        return aix, aiy, ajx, ajy, dx, dy, ux, uy

    def system(self, x, q, want_jacobian: bool = True):
        """F (N, n_eq) and J (N, n_eq, n_x) (J is None if not wanted)."""
        N = x.shape[0]
        X, c, s = self._poses(x)
        F = np.empty((N, self.n_eq))
        vals = []
        rv, pr = self.model.rev, self.model.pri
        if self.nr:
            aix, aiy = self._rot(c, s, rv.i, rv.si)
            ajx, ajy = self._rot(c, s, rv.j, rv.sj)
            F[:, self.r_rev] = X[:, rv.i, 0] + aix - X[:, rv.j, 0] - ajx
            F[:, self.r_rev + 1] = X[:, rv.i, 1] + aiy - X[:, rv.j, 1] - ajy
            vals += [-aiy, aix, ajy, -ajx]
        if self.np_:
            aix, aiy, ajx, ajy, dx, dy, ux, uy = self._prismatic(
                X, c, s, pr.i, pr.j, pr.si, pr.sj, pr.ui)
            nx, ny = -uy, ux
            F[:, self.r_pri] = nx * dx + ny * dy
            F[:, self.r_pri + 1] = X[:, pr.j, 2] - X[:, pr.i, 2] - pr.angle
            # d/dtheta_j: n . perp(aj);  d/dtheta_i: -u . d - n . perp(ai)
            vals += [nx, ny, -nx * ajy + ny * ajx,
                     -nx, -ny, -(ux * dx + uy * dy) + nx * aiy - ny * aix]
        if self.nl:
            i, j = self.lk_i, self.lk_j
            acx, acy = self._rot(c, s, i, self.lk_c)
            F[:, self.r_lock] = X[:, j, 0] - X[:, i, 0] - acx
            F[:, self.r_lock + 1] = X[:, j, 1] - X[:, i, 1] - acy
            F[:, self.r_lock + 2] = X[:, j, 2] - X[:, i, 2] - self.lk_a
            vals += [acy, -acx]
        if self.n_q:
            g = np.empty((N, self.n_q))
            if self.c_ang.size:
                g[:, self.c_ang] = X[:, self.c_ang_b, 2]
            if self.c_rel.size:
                g[:, self.c_rel] = X[:, self.c_rel_j, 2] - X[:, self.c_rel_i, 2]
            if self.c_tra.size:
                aix, aiy, ajx, ajy, dx, dy, ux, uy = self._prismatic(
                    X, c, s, self.c_tra_i, self.c_tra_j, self.c_tra_si, self.c_tra_sj,
                    self.c_tra_ui)
                g[:, self.c_tra] = ux * dx + uy * dy
                nx, ny = -uy, ux
                vals += [ux, uy, -ux * ajy + uy * ajx,
                         -ux, -uy, (nx * dx + ny * dy) + ux * aiy - uy * aix]
            F[:, self.n_rows:] = g + self.c_off - q
        if not want_jacobian:
            return F, None
        J = np.zeros((N, self.n_eq * self.n_x))
        J[:, self.c_flat] = self.c_val
        if vals:
            J[:, self.v_flat] = np.concatenate(vals, axis=1)[:, self.v_keep]
        return F, J.reshape(N, self.n_eq, self.n_x)

    def gamma(self, x, xdot):
        """[gamma; gamma_g] (N, n_eq): [Phi_x; g_x] xddot = this + [0; qddot]."""
        N = x.shape[0]
        X, c, s = self._poses(x)
        V = np.zeros((N, self.nb + 1, 3))
        V[:, : self.nb] = xdot.reshape(N, self.nb, 3)
        w = V[:, :, 2]
        out = np.zeros((N, self.n_eq))
        rv, pr = self.model.rev, self.model.pri
        if self.nr:
            aix, aiy = self._rot(c, s, rv.i, rv.si)
            ajx, ajy = self._rot(c, s, rv.j, rv.sj)
            wi2, wj2 = w[:, rv.i] ** 2, w[:, rv.j] ** 2
            out[:, self.r_rev] = aix * wi2 - ajx * wj2
            out[:, self.r_rev + 1] = aiy * wi2 - ajy * wj2
        if self.np_:
            out[:, self.r_pri] = -self._quad(X, V, c, s, pr.i, pr.j, pr.si, pr.sj, pr.ui, True)
        if self.nl:
            acx, acy = self._rot(c, s, self.lk_i, self.lk_c)
            wi2 = w[:, self.lk_i] ** 2
            out[:, self.r_lock] = -acx * wi2
            out[:, self.r_lock + 1] = -acy * wi2
        if self.c_tra.size:
            out[:, self.n_rows + self.c_tra] = -self._quad(
                X, V, c, s, self.c_tra_i, self.c_tra_j, self.c_tra_si, self.c_tra_sj,
                self.c_tra_ui, False)
        return out

    def _quad(self, X, V, c, s, i, j, si, sj, ui, normal):
        """Second time derivative of n.d (normal) or u.d (travel) at zero xddot, (N, m)."""
        aix, aiy, ajx, ajy, dx, dy, ux, uy = self._prismatic(X, c, s, i, j, si, sj, ui)
        wi, wj = V[:, i, 2], V[:, j, 2]
        ddx = V[:, j, 0] - wj * ajy - V[:, i, 0] + wi * aiy
        ddy = V[:, j, 1] + wj * ajx - V[:, i, 1] - wi * aix
        nx, ny = -uy, ux
        ex = -wj**2 * ajx + wi**2 * aix
        ey = -wj**2 * ajy + wi**2 * aiy
        if normal:
            return (-wi**2 * (nx * dx + ny * dy) - 2 * wi * (ux * ddx + uy * ddy)
                    + nx * ex + ny * ey)
        return (-wi**2 * (ux * dx + uy * dy) + 2 * wi * (nx * ddx + ny * ddy)
                + ux * ex + uy * ey)

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
    def _trig1(self, x):
        xs = x.tolist()
        px, py, th = xs[0::3] + [0.0], xs[1::3] + [0.0], xs[2::3] + [0.0]
        return px, py, th, [math.cos(t) for t in th], [math.sin(t) for t in th]

    def system1(self, x, q):
        """F (n_eq,) and J (n_eq, n_x) at one position."""
        px, py, th, c, s = self._trig1(x)
        F = [0.0] * self.n_eq
        vals: list[float] = []
        for r, i, j, sxi, syi, sxj, syj in self._rev1:
            aix, aiy = c[i] * sxi - s[i] * syi, s[i] * sxi + c[i] * syi
            ajx, ajy = c[j] * sxj - s[j] * syj, s[j] * sxj + c[j] * syj
            F[r] = px[i] + aix - px[j] - ajx
            F[r + 1] = py[i] + aiy - py[j] - ajy
            vals += (-aiy, aix, ajy, -ajx)
        for r, i, j, sxi, syi, sxj, syj, uxi, uyi, ang in self._pri1:
            aix, aiy = c[i] * sxi - s[i] * syi, s[i] * sxi + c[i] * syi
            ajx, ajy = c[j] * sxj - s[j] * syj, s[j] * sxj + c[j] * syj
            ux, uy = c[i] * uxi - s[i] * uyi, s[i] * uxi + c[i] * uyi
            dx, dy = px[j] + ajx - px[i] - aix, py[j] + ajy - py[i] - aiy
            nx, ny = -uy, ux
            F[r] = nx * dx + ny * dy
            F[r + 1] = th[j] - th[i] - ang
            vals += (nx, ny, -nx * ajy + ny * ajx,
                     -nx, -ny, -(ux * dx + uy * dy) + nx * aiy - ny * aix)
        for r, i, j, cx, cy, ang in self._lock1:
            acx, acy = c[i] * cx - s[i] * cy, s[i] * cx + c[i] * cy
            F[r] = px[j] - px[i] - acx
            F[r + 1] = py[j] - py[i] - acy
            F[r + 2] = th[j] - th[i] - ang
            vals += (acy, -acx)
        qs = q.tolist()
        for k, spec in enumerate(self._coord1):
            kind, r, off = spec[:3]
            if kind == 0:
                F[r] = th[spec[3]] + off - qs[k]
            elif kind == 1:
                F[r] = th[spec[4]] - th[spec[3]] + off - qs[k]
            else:
                i, j, sxi, syi, sxj, syj, uxi, uyi = spec[3:]
                aix, aiy = c[i] * sxi - s[i] * syi, s[i] * sxi + c[i] * syi
                ajx, ajy = c[j] * sxj - s[j] * syj, s[j] * sxj + c[j] * syj
                ux, uy = c[i] * uxi - s[i] * uyi, s[i] * uxi + c[i] * uyi
                dx, dy = px[j] + ajx - px[i] - aix, py[j] + ajy - py[i] - aiy
                nx, ny = -uy, ux
                F[r] = ux * dx + uy * dy + off - qs[k]
                vals += (ux, uy, -ux * ajy + uy * ajx,
                         -ux, -uy, (nx * dx + ny * dy) + ux * aiy - uy * aix)
        J = np.zeros(self.n_eq * self.n_x)
        J[self.c_flat] = self.c_val
        if vals:
            J[self.v1_flat] = np.array(vals)[self.v1_keep]
        return np.array(F), J.reshape(self.n_eq, self.n_x)

    def gamma1(self, x, xdot):
        """[gamma; gamma_g] (n_eq,) at one position."""
        px, py, th, c, s = self._trig1(x)
        vs = xdot.tolist()
        vx, vy, w = vs[0::3] + [0.0], vs[1::3] + [0.0], vs[2::3] + [0.0]
        out = [0.0] * self.n_eq

        def quad(i, j, sxi, syi, sxj, syj, uxi, uyi, normal):
            aix, aiy = c[i] * sxi - s[i] * syi, s[i] * sxi + c[i] * syi
            ajx, ajy = c[j] * sxj - s[j] * syj, s[j] * sxj + c[j] * syj
            ux, uy = c[i] * uxi - s[i] * uyi, s[i] * uxi + c[i] * uyi
            dx, dy = px[j] + ajx - px[i] - aix, py[j] + ajy - py[i] - aiy
            wi, wj = w[i], w[j]
            ddx = vx[j] - wj * ajy - vx[i] + wi * aiy
            ddy = vy[j] + wj * ajx - vy[i] - wi * aix
            nx, ny = -uy, ux
            ex = -wj * wj * ajx + wi * wi * aix
            ey = -wj * wj * ajy + wi * wi * aiy
            if normal:
                return (-wi * wi * (nx * dx + ny * dy) - 2 * wi * (ux * ddx + uy * ddy)
                        + nx * ex + ny * ey)
            return (-wi * wi * (ux * dx + uy * dy) + 2 * wi * (nx * ddx + ny * ddy)
                    + ux * ex + uy * ey)

        for r, i, j, sxi, syi, sxj, syj in self._rev1:
            wi2, wj2 = w[i] * w[i], w[j] * w[j]
            out[r] = (c[i] * sxi - s[i] * syi) * wi2 - (c[j] * sxj - s[j] * syj) * wj2
            out[r + 1] = (s[i] * sxi + c[i] * syi) * wi2 - (s[j] * sxj + c[j] * syj) * wj2
        for r, i, j, sxi, syi, sxj, syj, uxi, uyi, _ in self._pri1:
            out[r] = -quad(i, j, sxi, syi, sxj, syj, uxi, uyi, True)
        for r, i, _j, cx, cy, _ in self._lock1:
            wi2 = w[i] * w[i]
            out[r] = -(c[i] * cx - s[i] * cy) * wi2
            out[r + 1] = -(s[i] * cx + c[i] * cy) * wi2
        for spec in self._coord1:
            if spec[0] == 2:
                out[spec[1]] = -quad(*spec[3:], False)
        return np.array(out)

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
