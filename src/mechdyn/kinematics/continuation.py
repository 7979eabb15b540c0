"""Numerical continuation along one coordinate: the building blocks of the sweep.

The evaluation kernel (:class:`Kernel`: [Phi; g - q], [Phi_x; g_x] and gamma of the
model's rows, evaluated and factored by the compiled drivers of
:mod:`mechdyn.kernels.rows_sweep` one position or a whole batch per call, since NumPy's
per-call overhead and temporaries would dominate; sparse LU with partial pivoting
gives the branch sign too), its Newton solve, the solved positions (:class:`_Node`),
their quintic Hermite predictor and the step-halving march through bifurcation
positions (:mod:`mechdyn.kinematics.branch_chart`).  Used by
:mod:`mechdyn.kinematics.sweep`, :mod:`mechdyn.kinematics.records` and
:mod:`mechdyn.kinetostatics.prescribed`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kernels import rows_numpy
from ..model import ConstraintLayout, Model
from ..model.rows import concat
from .assembly import _dense_solve, column_scale, newton

#: Newton iterations allowed per step of the continuation
_MAX_NEWTON = 10
#: the sweep kernels have been compiled (or loaded) in this process: they are generic over
#: their arrays, so the first Kernel's warm-up serves every later one
_WARM = {"done": False}


def _c(a) -> np.ndarray:
    """A C-contiguous float array (one compiled specialization for every caller)."""
    return np.ascontiguousarray(a, dtype=float)


class Kernel:
    """Residual, Jacobian and gamma of the position problem of one model and layout.

    The equations are the rows of the layout (joints, then engaged locks) followed
    by the coordinate rows, F(x) = [Phi(x); g(x) - q], evaluated by the compiled
    drivers of :mod:`mechdyn.kernels.rows_sweep` (or, when numba is not installed
    or ``compiled`` is set to False, by :mod:`mechdyn.kernels.rows_numpy`).
    The methods take a batch (``x`` (N, n_x), ``q`` (N, n_q)) or one position
    (1-D arrays).

    Parameters
    ----------
    model : Model
    layout : ConstraintLayout
        The mode's row layout (``layout.rowset``).
    idx : sequence of int, optional
        The coordinates q stands for (default all; a branch chart's path prescribes some).
    """

    def __init__(self, model: Model, layout: ConstraintLayout, idx=None):
        self.model, self.lay = model, layout
        #: the coordinates q stands for
        self.idx = np.arange(model.n_q) if idx is None else np.asarray(idx, dtype=int)
        nb = self.nb = model.n_bodies
        self.n_x = 3 * nb
        self.n_rows = layout.n_rows
        #: the rows of F: the layout's constraint rows, then the coordinate rows
        self.rows = layout.position_rows if idx is None else concat(
            nb, layout.rowset, model.coordinate_rows.take(idx))
        self.n_eq = len(self.rows)
        self.n_q = self.n_eq - self.n_rows
        self.square = self.n_eq == self.n_x
        self.col_scale = column_scale(model)
        self._ints, self._flts = self.rows.packed()
        from ..kernels import rows_numba, rows_sweep  # numba is imported only here

        self._drivers = rows_sweep
        #: evaluate and factor with the compiled drivers (numba installed), else NumPy
        self.compiled = rows_numba.NUMBA
        if self.compiled and not _WARM["done"]:
            with rows_numba.compiling("numba kernels of the kinematic sweep"):
                x = np.random.default_rng(1).normal(size=(1, self.n_x))
                J = self.system(x, np.zeros((1, self.n_q)))[1]
                self.apply(J, self.factor(J), J[..., :1])
            _WARM["done"] = self.square  # a square kernel has compiled the LU path too

    def system(self, x, q):
        """F (N, n_eq) (m or rad) and J (N, n_eq, n_x) at poses x (N, n_x), q (N, n_q)."""
        if x.ndim == 1:
            F, J = self.system(x[None], q[None])
            return F[0], J[0]
        if not self.compiled:
            F, J, _ = rows_numpy.evaluate(self.rows, x)
            F[..., self.n_rows:] -= q
            return F, J
        F = np.empty((x.shape[0], self.n_eq))
        J = np.zeros((x.shape[0], self.n_eq, self.n_x))
        self._drivers.system_batch(_c(x), _c(q), self.nb, self._ints, self._flts,
                                   self.n_rows, F, J)
        return F, J

    def gamma(self, x, xdot):
        """[gamma; gamma_g] (N, n_eq): [Phi_x; g_x] xddot = this + [0; qddot]."""
        if x.ndim == 1:
            return self.gamma(x[None], xdot[None])[0]
        if not self.compiled:
            return -rows_numpy.quad(self.rows, x, xdot)
        out = np.empty((x.shape[0], self.n_eq))
        self._drivers.gamma_batch(_c(x), _c(xdot), self.nb, self._ints, self._flts, out)
        return out

    def factor(self, J):
        """Factors of Jacobians J (N, n_eq, n_x) or (n_eq, n_x) for :meth:`apply`, and the
        signs of det [Phi_x; g_x] (the branch sign, as ``assembly.branch_sign``):
        ``(lu, piv, sign)``, ``lu`` None where the solves are dense."""
        one = J.ndim == 2
        Jb = J[None] if one else J
        lu = piv = None
        if not self.square:
            sign = np.ones(Jb.shape[0])
        elif not self.compiled:
            sign = np.sign(np.linalg.det(Jb))
        else:
            lu, piv = np.array(Jb, dtype=float), np.empty(Jb.shape[:2], dtype=np.intp)
            sign = np.empty(Jb.shape[0])
            self._drivers.lu_batch(lu, piv, sign)
        return (lu, piv, float(sign[0]) if one else sign)

    def apply(self, J, fac, rhs):
        """y with J y = rhs, J (N, n_eq, n_x) and rhs (N, n_eq, k) -> (N, n_x, k), or one
        position (J 2-D, rhs 1-D or 2-D), with the factors of :meth:`factor`."""
        if fac is None or fac[0] is None or not np.size(rhs):
            return _dense_solve(J, rhs)
        y = np.array(rhs, dtype=float)
        shape = y.shape
        y = y.reshape((-1,) + shape[-2:] if J.ndim == 3 else (1, self.n_eq, -1))
        self._drivers.lu_solve_batch(fac[0], fac[1], y)
        y = y.reshape(shape)
        return y if np.all(np.isfinite(y)) else _dense_solve(J, rhs)

    def rhs_unit(self, N):
        """[0; I], the right-hand side of the velocity-analog equations, (N, n_eq, n_q)."""
        E = np.zeros((N, self.n_eq, self.n_q))
        E[:, self.n_rows:, :] = np.eye(self.n_q)
        return E


@dataclass
class _Node:
    """One solved position of the continuation: pose, analogs, second derivative, sign;
    ``s``, ``xs``, ``xss``: q_k, dx/dq_k and d2x/dq_k^2 of the swept coordinate k."""

    q: np.ndarray  # (n_q,)
    x: np.ndarray  # (n_x,)
    B: np.ndarray  # (n_x, n_q)
    H: np.ndarray  # (n_x,) d2x/dq_k^2 of the swept coordinate
    sign: float
    k: int = 0
    s = property(lambda self: float(self.q[self.k]))
    xs = property(lambda self: self.B[:, self.k])
    xss = property(lambda self: self.H)


def path_newton(kern: Kernel, x, q, tol, max_iter=_MAX_NEWTON):
    """The one position Newton (:func:`~mechdyn.kinematics.assembly.newton`) on the
    kernel's equations [Phi; g - q] = 0, from poses x (N, n_x) or one pose (1-D x, q);
    returns x, converged, and the residual F and the Jacobian J at x."""
    at = []

    def system(xx):
        at[:] = kern.system(xx, q)
        return at[0], at[1]

    def solve(J, F):
        return kern.apply(J, kern.factor(J), F[..., None])[..., 0]

    x, ok = newton(kern.rows, x, np.zeros(kern.n_eq), tol=tol, max_iter=max_iter,
                   system=system, solve=solve)
    return x, ok, at[0], at[1]


def path_node(kern: Kernel, x, q, k: int, J=None) -> _Node:
    """Analogs, second derivative along coordinate ``k`` and branch sign at a solved pose."""
    if J is None:
        J = kern.system(x, q)[1]
    fac = kern.factor(J)
    B = kern.apply(J, fac, kern.rhs_unit(1)[0])
    H = kern.apply(J, fac, kern.gamma(x, B[:, k]))
    return _Node(q.copy(), x.copy(), B, H, fac[2], k)


@dataclass
class _Stop:
    """Where the continuation could not go on."""

    node: _Node  # last solved position
    q_try: np.ndarray  # the coordinates it could not reach
    reason: str


def _predict(prev: _Node | None, node: _Node, k: int, h: float) -> np.ndarray:
    """Pose predicted at q_k + h: quintic Hermite through the last two nodes, extrapolated
    (error O(h^6)); a second-order Taylor step when there is no usable previous node."""
    if prev is not None:
        hp = node.q[k] - prev.q[k]
        if hp != 0 and abs(h) <= 2 * abs(hp):
            t = 1.0 + h / hp  # a float: the basis is then computed in plain Python
            return _hermite5(t, hp, prev.x, prev.B[:, k], prev.H, node.x, node.B[:, k], node.H)
    return node.x + node.B[:, k] * h + 0.5 * node.H * h * h


def _chart_node(kern: Kernel, chart, q, k: int) -> _Node:
    """The node at q from a branch chart (a bifurcation zone, see
    :mod:`mechdyn.kinematics.branch_chart`): pose, analogs along coordinate k and second
    derivative from the chart; the other columns of B by a direct solve at that pose."""
    x, xs, xss = chart.evaluate(q[k])
    with np.errstate(all="ignore"):
        J = kern.system(x, q)[1]
        B = kern.apply(J, kern.factor(J), kern.rhs_unit(1)[0])  # a new array
    B[:, k] = xs
    return _Node(np.array(q, dtype=float), x, B, xss, chart.side_sign(q[k]), k)


def march_path(kern: Kernel, start: _Node, k: int, targets, *, max_step, min_step, tol,
           counter: dict, prev: _Node | None = None, book=None):
    """Sequential continuation through ``targets`` (values of coordinate k).

    With ``book`` (a :class:`~mechdyn.kinematics.branch_chart.ChartBook` of this path)
    every accepted position is watched for a bifurcation ahead; in a chart's zone the
    positions come from the chart, in its window the chart predicts them and tells
    the branch sign to expect, so the march goes through the bifurcation on its
    branch.  Where the step would fall below ``min_step`` without a chart, one is
    tried from an earlier position at least a zone away before giving up.

    Returns the list of nodes reached (one per target) and a :class:`_Stop` or None.
    """
    node = start
    out: list[_Node] = []
    h_try = max_step
    L = kern.model.length_scale
    trail: list[_Node] = [node]
    for target in targets:
        while node.q[k] != target:
            remaining = target - node.q[k]
            qn = node.q.copy()
            qn[k] = target if abs(remaining) <= h_try * (1 + 1e-6) else \
                node.q[k] + np.sign(remaining) * h_try
            h = qn[k] - node.q[k]
            counter["coarse_steps"] = counter.get("coarse_steps", 0) + 1
            zone = book.zone_chart(qn[k]) if book is not None else None
            if zone is not None:
                prev, node = node, _chart_node(kern, zone, qn, k)
                h_try = min(2 * h_try, max_step)
                continue
            win = (book.window_chart(qn[k]) or book.window_chart(node.q[k])) if book else None
            xp = win.evaluate(qn[k])[0] if win is not None else _predict(prev, node, k, h)
            x, ok, _, J = path_newton(kern, xp, qn, tol)
            reason = "Newton's method does not converge"  # None: the step is accepted
            if ok:
                nn = path_node(kern, x, qn, k, J=J)
                step = np.max(np.abs((nn.x - node.x) * kern.col_scale))
                corr = np.max(np.abs((nn.x - xp) * kern.col_scale))
                expected = win.side_sign(qn[k]) if win is not None else node.sign
                if nn.sign != expected:
                    reason = "the sign of det [Phi_x; g_x] changes (the branch would be left)"
                elif corr > 0.25 * step + 1e-9 * L:
                    reason = "the corrector moves far from the predictor"
                else:
                    reason = None
            if reason is not None:
                counter["rejected_steps"] = counter.get("rejected_steps", 0) + 1
                h_try = abs(h) / 2
                prev = None  # fall back to the Taylor predictor near trouble
                if h_try < min_step:
                    if book is not None and _chart_across(book, trail, node, k):
                        h_try = max_step
                        continue
                    return out, _Stop(node, qn, reason)
                continue
            prev, node = node, nn
            trail = (trail + [nn])[-64:]
            if book is not None:
                book.watch(nn.q[k], nn.x)
            h_try = min(2 * h_try, max_step)
        out.append(node)
    return out, None


def _chart_across(book, trail, node: _Node, k: int) -> bool:
    """A chart across the singular position the march stopped at (near node), built
    from the latest earlier position at least a zone away; whether one was built."""
    s_star = float(node.q[k])
    far = [nd for nd in trail if abs(nd.q[k] - s_star) >= book.zone * book.path.unit]
    base = far[-1] if far else trail[0]
    return book.watch(float(base.q[k]), base.x, force_at=s_star) is not None


def _hermite5(t, h, x0, d0, a0, x1, d1, a1):
    """Quintic Hermite interpolation on t in [0, 1] over an interval of length h.

    x0, d0, a0 (value, first, second derivative at t=0) etc. are (N, n_x) arrays, t (N, 1).
    """
    t2 = t * t
    t3 = t2 * t
    t4 = t3 * t
    t5 = t4 * t
    h0 = 1 - 10 * t3 + 15 * t4 - 6 * t5
    h1 = t - 6 * t3 + 8 * t4 - 3 * t5
    h2 = 0.5 * (t2 - 3 * t3 + 3 * t4 - t5)
    h3 = 0.5 * (t3 - 2 * t4 + t5)
    h4 = -4 * t3 + 7 * t4 - 3 * t5
    h5 = 10 * t3 - 15 * t4 + 6 * t5
    return (h0 * x0 + h1 * h * d0 + h2 * h * h * a0 + h3 * h * h * a1 + h4 * h * d1
            + h5 * x1)


def _anchor_indices(values, max_step) -> np.ndarray:
    """Indices of the values solved sequentially: the first, the last, every turning
    point of the sequence, and enough in between that consecutive anchors are at most
    ``max_step`` apart (or neighbours, if the values themselves are further apart)."""
    n = len(values)
    if n <= 2:
        return np.arange(n)
    d = np.diff(values)
    path = np.concatenate([[0.0], np.cumsum(np.abs(d))])
    turning = np.flatnonzero(d[:-1] * d[1:] < 0) + 1
    ends = [0, *turning.tolist(), n - 1]
    anchors = [0]
    reach = max_step * (1 + 1e-9)
    for a, b in zip(ends[:-1], ends[1:], strict=True):
        i = a
        while i < b:
            j = int(np.searchsorted(path, path[i] + reach, side="right")) - 1
            i = min(max(j, i + 1), b)
            anchors.append(i)
    return np.array(anchors, dtype=int)


def sweep_kernel(model: Model, layout, idx=None) -> Kernel:
    """The evaluation kernel of a model in a mode (for the coordinates ``idx``, default
    all), made for the analysis that asks (packing the rows costs microseconds)."""
    if idx is not None and np.array_equal(idx, np.arange(model.n_q)):
        idx = None
    return Kernel(model, layout, idx)
