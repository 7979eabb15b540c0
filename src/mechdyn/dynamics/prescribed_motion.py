"""Poses, velocities and accelerations of a mechanism whose driven coordinates follow
a prescribed motion (batched over positions), the choice of the driven coordinates,
and the dead centres of a crank's turn.

The driving constraints ``g_d(x) - q_d = 0`` are appended to the joint constraints
``Phi(x) = 0``; the poses are found by continuation (branch kept by the sign of the
scaled Jacobian's determinant) with the package's position Newton
(:func:`mechdyn.kinematics.assembly.newton`), the rates from
``[Phi_x; g_d,x] xdot = [0; qdot_d]`` and the accelerations from the same matrix with
the exact right-hand side gamma.  Through a bifurcation position (two branches
crossing, one driven coordinate varying) poses, rates and accelerations near it come
from a branch chart (:mod:`mechdyn.kinematics.branch_chart`), the limit of the branch
from both sides.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from ..errors import AssemblyError, ModelError, SingularPositionError
from ..kernels import rows_numpy
from ..kinematics.assembly import _rank, _scale, joint_residuals, newton
from ..kinematics.branch_chart import ChartBook, PathProblem
from ..kinematics.constraints import _point_kinematics, coordinates, coordinates_jacobian
from ..kinematics.records import _refine_root
from ..kinematics.sweep import sweep
from ..model import ConstraintLayout, Model, as_model
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
    ``n_rows``, ``rows`` of the joints and weld locks, ``row_joint``,
    ``lock_active``, ``mode``); ``extra`` are the switchable rows, ``elements``
    the row indices of every switchable element but the weld locks (which report
    as joints), ``row_is_angle`` whether each switchable row is in rad.
    """

    def __init__(self, model: Model, extra, mode):
        base = model.layout(frozenset())
        self.extra = list(extra)
        self.mode = frozenset(mode)
        self.n_base = base.n_rows
        self.rowset = concat(model.n_bodies, model.joint_rows, *[r.rows for r in self.extra])
        self.n_rows = len(self.rowset)
        self.lock_active = np.array([n in self.mode for n in model.lock.names], dtype=bool)
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


def _lin_solve(J, F):
    """Solve J dx = F (batched), least squares / minimum norm when not square or singular."""
    if J.shape[-1] == J.shape[-2]:
        try:
            dx = np.linalg.solve(J, F)
            if np.all(np.isfinite(dx)):
                return dx
        except np.linalg.LinAlgError:
            pass
    return np.linalg.pinv(J, rcond=1e-12) @ F


class _Positions:
    """Position, velocity and acceleration analysis with a subset of driven coordinates:
    the rows of the layout, then the driven coordinates' rows (:attr:`rows`)."""

    def __init__(self, model: Model, lay: ConstraintLayout, didx: np.ndarray):
        self.model, self.lay, self.didx = model, lay, didx
        self.rows = concat(model.n_bodies, lay.rowset, model.coordinate_rows.take(didx))
        self.tol = 1e-12 * max(model.length_scale, 1e-3)
        self.scale = _scale(model)
        self.solves = 0
        self.branch_changes: list = []
        #: branch charts of the bifurcation positions passed (one varying coordinate)
        self.book: ChartBook | None = None
        self._j = 0
        #: samples in a chart's zone: mask (n,), x' and x'' along the varying coordinate
        self.charted = None

    def residual(self, x, qd):
        """[Phi; g_d - q_d] at x, shape (..., n_rows + n_d)."""
        F = rows_numpy.values(self.rows, x)
        F[..., self.lay.n_rows:] -= qd
        return F

    def jac(self, x):
        """[Phi_x; g_d,x] at x, shape (..., n_rows + n_d, n_x)."""
        return rows_numpy.jacobian(self.rows, x)

    def newton(self, qd, x, max_iter=30):
        """:func:`~mechdyn.kinematics.assembly.newton` (batched); returns x, converged
        flags, and J at x."""
        self.solves += 1
        qd = np.asarray(qd, dtype=float)
        target = np.concatenate([np.zeros(qd.shape[:-1] + (self.lay.n_rows,)), qd], axis=-1)
        x, ok = newton(self.rows, x, target, tol=self.tol, max_iter=max_iter)
        return x, ok, self.jac(x)

    def analogs(self, J):
        """dx/dq_d from the Jacobian J, shape (..., n_x, n_d)."""
        rhs = np.zeros(J.shape[:-2] + (J.shape[-2], len(self.didx)))
        rhs[..., self.lay.n_rows:, :] = np.eye(len(self.didx))
        return _lin_solve(J, rhs)

    def det_sign(self, J):
        """Sign of det of the scaled J (ones when J is not square)."""
        if J.shape[-1] != J.shape[-2]:
            return np.ones(J.shape[:-2])
        return np.sign(np.linalg.det(J * self.scale))

    def first(self, qd, x_start):
        """The first pose: continuation from the assembled start pose keeps its branch
        (by :meth:`advance` in small steps when one coordinate varies, so that a
        bifurcation on the way is charted)."""
        q_s = coordinates(self.model, x_start)[self.didx]
        if np.max(np.abs(self.residual(x_start, q_s)), initial=0.0) <= 1e3 * self.tol:
            j, x, q = self._j, np.array(x_start, dtype=float), q_s
            n_sub = 1
            if self.book is not None and not np.delete(q_s - qd, j).any():
                n_sub = max(1, int(np.ceil(abs(qd[j] - q_s[j]) / (0.1 * self.book.path.unit))))
            try:
                for i in range(1, n_sub + 1):
                    qn = q_s + (qd - q_s) * (i / n_sub)
                    x = self.advance(q, x, qn)[0]
                    q = qn
                return x
            except (AssemblyError, SingularPositionError):
                pass
        x, ok, _ = self.newton(qd, x_start, max_iter=60)
        if ok:
            return x
        sol = least_squares(self.residual, x_start, jac=lambda xx, qd: self.jac(xx),
                            args=(qd,), method="trf", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                            x_scale=self.scale / self.model.length_scale, max_nfev=2000)
        x, ok, _ = self.newton(qd, sol.x)
        if not ok:
            raise self._error(qd, x)
        return x

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

    def step(self, qd_from, x_from, qd_to, J_from=None, depth=0):
        """Solve at qd_to continuing from a solved pose, halving the step on failure.

        Returns the pose and the Jacobian there."""
        L = self.model.length_scale
        if J_from is None:
            J_from = self.jac(x_from)
        dx = self.analogs(J_from) @ (qd_to - qd_from)
        # near a singular position the analogs blow up: then start from x_from itself
        pred = x_from + dx if np.max(np.abs(dx * self.scale)) <= 0.5 * L else x_from
        x, ok, J = self.newton(qd_to, pred)
        if ok:
            # a link turning by more than ~1 rad in one step means the solve jumped
            jump = np.max(np.abs((x - x_from) * self.scale)) > L
            same = self.det_sign(J) == self.det_sign(J_from)
            if (same and not jump) or depth > 10:
                if not same or jump:
                    self.branch_changes.append(np.array(qd_to, dtype=float))
                return x, J
        if depth > 14:
            raise self._error(qd_to, x)
        mid = 0.5 * (qd_from + qd_to)
        xm, Jm = self.step(qd_from, x_from, mid, J_from, depth + 1)
        return self.step(mid, xm, qd_to, Jm, depth + 1)

    def solve(self, qd, x_start, x_guess=None):
        """Poses for all rows of qd (n, n_d), by continuation from x_start.

        Sequential continuation on about 100 anchor positions, then one batched
        Newton solve for all the others from the anchors' first-order predictions
        (with a branch check, falling back to continuation where it fails)."""
        n = qd.shape[0]
        self._open_book(qd)
        if x_guess is not None:
            x, ok, _ = self.newton(qd, x_guess)
            if np.all(ok):
                return self._charts_after(qd, x)
        x = np.empty((n, self.model.n_x))
        x[0] = self.first(qd[0], x_start if x_guess is None else x_guess[0])
        if n == 1:
            return self._charts_after(qd, x)
        stride = max(1, n // 100)
        anchors = sorted({*range(0, n, stride), n - 1})
        J0 = self.jac(x[0])
        Ja = np.empty((len(anchors),) + J0.shape)
        Ja[0] = J0
        for i, (a0, a1) in enumerate(zip(anchors[:-1], anchors[1:], strict=True)):
            x[a1], Ja[i + 1] = self.advance(qd[a0], x[a0], qd[a1], Ja[i])
        rest = np.setdiff1d(np.arange(n), anchors)
        if rest.size:
            base = np.searchsorted(anchors, rest, side="right") - 1
            a = np.asarray(anchors)[base]
            with np.errstate(all="ignore"):
                B = self.analogs(Ja[base])
            pred = x[a] + (B @ (qd[rest] - qd[a])[..., None])[..., 0]
            sign = self.det_sign(Ja[base])
            near = np.zeros(rest.size, dtype=bool)
            if self.book is not None:  # near a bifurcation: the chart predicts
                for i, k in enumerate(rest):
                    ch = self.book.window_chart(qd[k, self._j])
                    if ch is not None:
                        near[i] = True
                        pred[i] = ch.evaluate(qd[k, self._j])[0]
                        sign[i] = ch.side_sign(qd[k, self._j])
            with np.errstate(all="ignore"):
                xr, ok, Jr = self.newton(qd[rest], np.where(np.isfinite(pred), pred, x[a]))
                ok &= (self.det_sign(Jr) == sign) | near
            x[rest] = xr
            for k in rest[~ok]:
                x[k] = self.advance(qd[k - 1], x[k - 1], qd[k])[0]
        return self._charts_after(qd, x)

    # ------------------------------------------------------------------ bifurcations
    def _open_book(self, qd):
        """A chart book when one driven coordinate varies and the others are held, for
        a square system of joint rows (not the rows of a variable-structure mode)."""
        self.book, self.charted = None, None
        var = np.flatnonzero(np.ptp(qd, axis=0) > 0) if qd.shape[0] > 1 else []
        if isinstance(self.lay, ModeRows) or len(var) != 1 or \
                self.lay.n_rows + len(self.didx) != self.model.n_x:
            return
        self._j = int(var[0])
        self.book = ChartBook(PathProblem(self.model, self.lay, self.didx, qd[0], self._j))

    def advance(self, qd_from, x_from, qd_to, J_from=None):
        """:meth:`step` that goes through bifurcation positions on the branch: poses in
        a chart's zone come from the chart, steps near or across a chart start from it."""
        book, j = self.book, self._j
        if book is None:
            return self.step(qd_from, x_from, qd_to, J_from)
        s0, s1 = float(qd_from[j]), float(qd_to[j])
        if book.zone_chart(s0) is None:
            book.watch(s0, x_from)
        ch = book.zone_chart(s1)
        if ch is not None:
            x = ch.evaluate(s1)[0]
            return x, self.jac(x)
        ch = book.window_chart(s1) or book.crossed(s0, s1) or book.window_chart(s0)
        if ch is None:
            return self.step(qd_from, x_from, qd_to, J_from)
        se = float(np.clip(s1, ch.centre - ch.window, ch.centre + ch.window))
        qe = np.array(qd_to, dtype=float)
        qe[j] = se
        xe = ch.evaluate(se)[0]
        if se == s1:
            x, ok, J = self.newton(qd_to, xe)
            if ok:
                return x, J
        return self.step(qe, xe, qd_to)

    def _charts_after(self, qd, x):
        """Watch the solved poses for bifurcations (when they came from guesses), and
        take the poses in the charts' zones from the charts."""
        if self.book is None:
            return x
        j = self._j
        if not self.book.charts:
            for k in range(qd.shape[0]):
                if self.book.zone_chart(qd[k, j]) is None:
                    self.book.watch(float(qd[k, j]), x[k])
        mask, xc, xs, xss = self.book.apply(qd[:, j])
        if mask.any():
            x = x.copy()
            x[mask] = xc
            self.charted = (mask, xs, xss)
        return x

    def motion(self, x, qd_dot, qd_ddot):
        """Velocities and accelerations of the poses for driven rates (batched)."""
        J, n_r = self.jac(x), self.lay.n_rows
        rhs = np.zeros(J.shape[:-1])
        rhs[..., n_r:] = qd_dot
        with np.errstate(all="ignore"):  # singular at a bifurcation: charted below
            xdot = _lin_solve(J, rhs[..., None])[..., 0]
            gam = -rows_numpy.quad(self.rows, x, xdot)
            gam[..., n_r:] += qd_ddot
            xddot = _lin_solve(J, gam[..., None])[..., 0]
        if self.charted is not None and x.ndim == 2:
            mask, xs, xss = self.charted
            held = np.delete(qd_dot[mask], self._j, axis=1)
            if not np.any(held) and not np.any(np.delete(qd_ddot[mask], self._j, axis=1)):
                w, a = qd_dot[mask, self._j, None], qd_ddot[mask, self._j, None]
                xdot, xddot = xdot.copy(), xddot.copy()
                xdot[mask] = xs * w
                xddot[mask] = xs * a + xss * w * w
        return xdot, xddot


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
