"""Poses, velocities and accelerations of a mechanism whose driven coordinates follow
a prescribed motion (batched over positions), the choice of the driven coordinates,
and the dead centres of a crank's turn.

The driving constraints ``g_d(x) - q_d = 0`` are appended to the joint constraints
``Phi(x) = 0`` (the kernel of :mod:`mechdyn.kinematics.continuation` with the driven
coordinates prescribed); the poses are found by the kinematic sweep's continuation
(branch kept by the sign of det [Phi_x; g_d,x], through bifurcation positions with the
branch charts of :mod:`mechdyn.kinematics.branch_chart`), the rates from
``[Phi_x; g_d,x] xdot = [0; qdot_d]`` and the accelerations from the same matrix with
the exact right-hand side gamma.  The dead centres are refined on a sweep of the crank.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from ..errors import AssemblyError, ModelError, SingularPositionError
from ..kernels import rows_numpy
from ..kinematics.assembly import _rank, _scale, joint_residuals
from ..kinematics.branch_chart import ChartBook, PathProblem
from ..kinematics.constraints import _point_kinematics, coordinates, coordinates_jacobian
from ..kinematics.continuation import Kernel, _kernel, _march, _newton, _node
from ..kinematics.records import _refine_root
from ..kinematics.sweep import DEFAULT_MAX_STEP, DEFAULT_MIN_STEP, _motion, _path, sweep
from ..model import Model, as_model
from ..model.rows import concat

__all__ = ["dead_centres", "ModeRows"]

#: relative singular value below which constraint equations count as dependent
REDUNDANT_RCOND = 1e-9


class ModeRows:
    """The constraint rows of a variable-structure mode for kinetostatics: the joint
    rows of the model, then the switchable rows of the mode (weld and coordinate
    locks, closed stops, closed contacts and sticking contacts), the
    :class:`~mechdyn.dynamics.modes.Row` objects of
    :meth:`~mechdyn.dynamics.modes.SwitchedModel.rows` -- the rows of the
    forward dynamics, :attr:`mechdyn.dynamics.modes.ModeSystem.rowset`.

    It stands in for a layout everywhere kinetostatics uses one (``rowset``,
    ``n_rows``, ``rows`` of the joints and weld locks, ``row_joint``, ``mode``);
    ``extra`` are the switchable rows, ``elements`` the row indices of every
    switchable element but the weld locks (which report as joints), ``row_is_angle``
    whether each switchable row is in rad.
    """

    def __init__(self, model: Model, extra, mode):
        base = model.layout(frozenset())
        self.extra = list(extra)
        self.mode = frozenset(mode)
        self.n_base = base.n_rows
        self.rowset = concat(model.n_bodies, model.joint_rows, *[r.rows for r in self.extra])
        self.n_rows = len(self.rowset)
        self.rows = dict(base.rows)
        self.elements: dict[str, list[int]] = {}
        welds = set(model.lock.names)
        keys = [r.label if r.kind == "stick" else r.element for r in self.extra]
        for k, (r, key) in enumerate(zip(self.extra, keys, strict=True)):
            if r.element in welds:
                self.rows[key] = np.append(self.rows.get(key, np.zeros(0, int)),
                                           self.n_base + k)
            else:
                self.elements.setdefault(key, []).append(self.n_base + k)
        self.row_joint = np.array([*base.row_joint, *keys], dtype=object)
        self.row_is_angle = self.rowset.is_angle[self.n_base:]
        slip = [(self.n_base + k, r.friction_rows) for k, r in enumerate(self.extra) if r.slip]
        self.slip_rows = np.array([k for k, _ in slip], int)
        self.friction = concat(model.n_bodies, *[f for _, f in slip])


def mode_jacobian(model: Model, x, lay, *, friction: bool = False) -> np.ndarray:
    """Jacobian of every row of ``lay`` (a layout or :class:`ModeRows`), (..., n_rows, n_x).
    With ``friction``, the rows of slipping contacts carry their Coulomb friction
    (R - mu s T_x, the force direction of the row, as in
    :meth:`mechdyn.dynamics.modes.ModeSystem.evaluate_x`)."""
    J = rows_numpy.jacobian(lay.rowset, x)
    if friction and isinstance(lay, ModeRows) and lay.slip_rows.size:
        J[..., lay.slip_rows, :] += rows_numpy.jacobian(lay.friction, x)
    return J


class _Positions:
    """Poses, velocities and accelerations with the driven coordinates ``didx`` prescribed,
    on the kinematics continuation: the kernel of the rows of the layout then the driven
    coordinates' rows (:class:`~mechdyn.kinematics.continuation.Kernel`) and the sweep's
    continuation (:func:`~mechdyn.kinematics.sweep._path`) along the one varying driven
    coordinate, through bifurcation positions with a chart book; coordinate by coordinate
    (:func:`~mechdyn.kinematics.continuation._march`) when several vary."""

    def __init__(self, model: Model, lay, didx):
        self.model, self.lay, self.didx = model, lay, np.asarray(didx, dtype=int)
        self.kern = (Kernel(model, lay, self.didx) if isinstance(lay, ModeRows)
                     else _kernel(model, lay, self.didx))
        self.tol = 1e-12 * max(model.length_scale, 1e-3)
        #: step counts of the continuation (``coarse_steps`` ...) and batched solves
        self.counter: dict = {"solves": 0}
        #: branch charts of the bifurcation positions passed (one varying coordinate)
        self.book: ChartBook | None = None
        #: samples in a chart's zone (mask (n,), x', x'' along the varying coordinate)
        self.charted = None
        self._j, self._system = 0, None

    def _newton(self, qd, x, max_iter=30):
        self.counter["solves"] += 1
        return _newton(self.kern, np.asarray(x, dtype=float), qd, self.tol, max_iter)

    def _steps(self, c: int) -> dict:
        """The march's step limits for driven coordinate c (those of the sweep)."""
        L = 1.0 if self.model.coord_is_angle[self.didx[c]] else self.model.length_scale
        return {"max_step": (DEFAULT_MAX_STEP if L == 1.0 else 0.05 * L),
                "min_step": DEFAULT_MIN_STEP * L, "tol": self.tol, "counter": self.counter}

    def _move(self, node, c: int, target: float):
        """March node's coordinate c to target (no chart book); raises where it stalls."""
        if node.q[c] == target:
            return node
        nodes, stop = _march(self.kern, _node(self.kern, node.x, node.q, c), c, [target],
                             **self._steps(c))
        if stop is not None:
            raise self._error(stop.q_try, stop.node.x)
        return nodes[-1]

    def _start(self, q0, x_start):
        """The node at the held coordinates of q0 (the varying one as at x_start), by
        continuation from the pose x_start when it is assembled, else by Newton's method
        (least squares first when that fails) at q0."""
        q_s = coordinates(self.model, x_start)[self.didx]
        x, ok, _, J = self._newton(q_s, x_start, max_iter=60)
        if ok:
            try:
                node = _node(self.kern, x, q_s, self._j, J)
                for c in range(len(q0)):
                    if c != self._j:
                        node = self._move(node, c, q0[c])
                return node
            except (AssemblyError, SingularPositionError):
                pass
        x, ok, _, J = self._newton(q0, x_start, max_iter=60)
        if not ok:
            def system(xx):
                return self.kern.system(xx, q0)

            sol = least_squares(lambda xx: system(xx)[0], x_start, jac=lambda xx: system(xx)[1],
                                method="trf", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                                x_scale=self.kern.col_scale / self.model.length_scale,
                                max_nfev=2000)
            x, ok, _, J = self._newton(q0, sol.x)
            if not ok:
                raise self._error(q0, x)
        return _node(self.kern, x, q0, self._j, J)

    def _error(self, qd, x, t=None):
        res = joint_residuals(self.model, x, self.lay)
        r = rows_numpy.values(self.lay.rowset, x)
        res.update({el: float(np.linalg.norm(r[idx]))
                    for el, idx in getattr(self.lay, "elements", {}).items()})
        names = [self.model.coordinate_names[k] for k in self.didx]
        if max(res.values(), default=0.0) < 1e-6 * self.model.length_scale:
            return SingularPositionError(
                "the position solve stalls near a dead, toggle or change point: the driven "
                "coordinate(s) " + ", ".join(names) + " lose control of the mechanism there "
                "(largest joint residual " + f"{max(res.values()):.3g}); analyse up to that "
                "position or choose another driven coordinate", t=t, q=qd,
                coordinates=names, joints=list(res))
        open_ = {n: v for n, v in res.items() if v > 1e-9 * max(self.model.length_scale, 1e-3)}
        qs = ", ".join(f"{n} = {v:.6g}" for n, v in zip(names, np.atleast_1d(qd), strict=True))
        parts = ", ".join(f"{n!r}: {v:.3g}" for n, v in open_.items()) or "none"
        return AssemblyError(f"the mechanism cannot be assembled at {qs}; joints that stay "
                             f"open (residual, m or rad): {parts}", t=t, q=qd,
                             residuals=open_)

    def solve(self, qd, x_start, x_guess=None):
        """Poses (n, n_x) at the driven coordinates qd (n, n_d): one batched Newton solve
        from the guesses x_guess when it converges everywhere, else by continuation from
        x_start (or the first guess)."""
        n, kern = qd.shape[0], self.kern
        var = np.flatnonzero(np.ptp(qd, axis=0) > 0) if n > 1 else []
        self._j = int(var[0]) if len(var) == 1 else 0
        self.book, self.charted, self._system = None, None, None
        if len(var) == 1 and kern.square and not isinstance(self.lay, ModeRows):
            self.book = ChartBook(PathProblem(self.model, self.lay, self.didx, qd[0], self._j))
        if x_guess is not None:
            x, ok, F, J = self._newton(qd, x_guess)
            if np.all(ok):
                self._system = (F, J, kern.factor(J))
                if self.book is not None:  # watch the poses for bifurcations
                    for k in range(n):
                        if self.book.zone_chart(qd[k, self._j]) is None:
                            self.book.watch(float(qd[k, self._j]), x[k])
                return x
            x_start = x_guess[0]
        node = self._start(qd[0], np.asarray(x_start, dtype=float))
        if len(var) <= 1:
            x, stop, self._system = _path(kern, node, self._j, qd[:, self._j], book=self.book,
                                          **self._steps(self._j))
            if stop is not None:
                raise self._error(stop.q_try, stop.node.x)
            return x
        x = np.empty((n, self.model.n_x))
        for k in range(n):
            for c in var:
                node = self._move(node, c, qd[k, c])
            x[k] = node.x
        return x

    def motion(self, x, qd, qd_dot, qd_ddot):
        """Poses, velocities and accelerations for the driven coordinates and their rates
        at the poses x of :meth:`solve` (batched), from the charts in bifurcation zones
        (:attr:`charted`)."""
        x, _, xdot, xddot, self.charted = _motion(self.kern, x, qd, qd_dot, qd_ddot,
                                                  self.book, self._j, self._system,
                                                  correct=False)
        return x, xdot, xddot


def _independent_subset(model, lay, x0, first: list[int], candidates=None) -> list[int]:
    """Extend ``first`` with coordinates that add rank, up to the DOF of the layout
    (``candidates``: the order in which the others are tried; default declared order)."""
    sc = _scale(model)
    P = mode_jacobian(model, x0, lay) * sc
    G = coordinates_jacobian(model, x0) * sc
    r_phi = _rank(P, REDUNDANT_RCOND)
    dof = model.n_x - r_phi
    chosen: list[int] = []

    def adds_rank(k):
        A = np.concatenate([P, G[chosen + [k]]])
        return _rank(A, REDUNDANT_RCOND) == r_phi + len(chosen) + 1

    for k in first:
        if not adds_rank(k):
            raise ModelError(
                f"coordinate {model.coordinate_names[k]!r} cannot be driven in mode "
                f"{sorted(lay.mode)}: it is fixed by the other driven coordinates and the "
                f"constraints ({dof} degree(s) of freedom)")
        chosen.append(k)
    for k in (range(model.n_q) if candidates is None else candidates):
        if len(chosen) < dof and k not in chosen and adds_rank(k):
            chosen.append(k)
    if len(chosen) < dof:
        raise ModelError(f"the mechanism has {dof} degrees of freedom in mode "
                         f"{sorted(lay.mode)}, but only {len(chosen)} coordinates can be driven")
    return chosen


def dead_centres(mech_or_model, body: str, point, *, coordinate: str = "y",
                 over: str | None = None, mode=None, n: int = 720) -> dict:
    """Extreme positions of a point over one turn of a crank coordinate.

    Parameters
    ----------
    body, point :
        The watched point (e.g. the slider's ``"F"``).
    coordinate : {"x", "y"}
        Which ground coordinate of the point.
    over : str, optional
        The crank coordinate (default the first independent coordinate).
    n : int
        Samples of the turn before refinement.

    Returns
    -------
    dict
        ``{"min": (angle_rad, value_m), "max": (angle_rad, value_m)}`` with the
        angle in [0, 2 pi) and the extreme refined to about 1e-10 rad.
    """
    model = as_model(mech_or_model)
    x_start = getattr(model, "x0", model.x_sketch)
    over_idx = [model.coordinate_index(over)] if over else []
    k = _independent_subset(model, model.layout(mode), x_start, over_idx)[0]
    sw = sweep(model, model.coordinate_names[k], np.linspace(0.0, 2 * np.pi, n + 1),
               x_start=x_start, mode=mode).raise_for_status()
    c = 0 if coordinate == "x" else 1

    def quantity(x, xs, xss):  # the point's coordinate and its derivatives along the crank
        return [v[..., c] for v in _point_kinematics(model, x, xs, xss, body, point)]

    y, dy, _ = quantity(sw.x, sw.B[..., k], sw.x * 0.0)
    out = {}
    for key, i in (("min", int(np.argmin(y[:-1]))), ("max", int(np.argmax(y[:-1])))):
        # the sample interval where the rate changes sign (the turn is closed)
        j = i if i == 0 or np.sign(dy[i - 1]) == np.sign(dy[i]) else i - 1
        if i == 0 and np.sign(dy[0]) == np.sign(dy[1]):
            j = n - 1
        a, v = _refine_root(sw, j, quantity)
        out[key] = (float(np.mod(a, 2 * np.pi)), v)
    return out
