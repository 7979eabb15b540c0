"""Forward dynamics through bifurcation positions: Lagrange's equations on the branch.

At a bifurcation (change point) position -- a parallelogram four-bar lying flat --
two assembly branches cross and [Phi_x; g_x] is singular, but the motion is still
determined: the mechanism stays on its branch, a smooth curve x(q) along which
Lagrange's equations in the declared coordinate,

    A(q) q'' + c(q, q') = Q,   A = B_c^T M B_c,   c = B_c^T M b_c,   Q = B^T F + Q_drive,

hold with the analogs B = x'(q) and b = x''(q) q'^2 of that curve.  Only their
evaluation from the equations fails there: at a distance d from the crossing the
pose is fixed to eps/d across the branch, and B and b come out with errors
growing like eps/d^2 and eps/d^3 (for the parallelogram, 2e-16/d^3 rad/s^2 in
the crank acceleration: 2e-7 at d = 1e-3 rad, 2e5 at 1e-7).

:class:`BranchEquations` evaluates the same equations, but inside a zone
|q - q*| < 0.15 rad (0.15 length scale for a travel) of a bifurcation q* it
takes x, B and x'' from a :class:`~mechdyn.kinematics.branch_chart.BranchChart`:
the limit from both sides, a polynomial through the well-conditioned poses
beyond the zone, reached across q* by continuation (the branch kept is the one
the motion is on).  Outside the zones nothing changes (the compiled kernel
keeps its speed); inside, the chart's error (about 1e-13 in the acceleration
for the parallelogram) replaces the blow-up.  A chart is built when a run
comes within reach of a singular position (a Newton step on the determinant of
the scaled Jacobian along the branch predicts it); at a *dead* position (a fold:
the coordinate cannot go on) none can be built, and the run stops there with
status ``"singular-position"`` as before.

Why not the x-space formulations (augmented Lagrangian, or the KKT system
[M Phi_x^T; Phi_x 0] with minimum-norm multipliers at a rank-deficient Phi_x)?
At the crossing the constraint force is the limit of Phi_x^T lambda with
lambda ~ 1/d: it need not lie in the range of Phi_x^T at the singular pose, so the
minimum-norm solve there gives a wrong acceleration (the parallelogram under
gravity alone happens to be an exception; a torque on the crank is not), and
near it the multiplier solve and the projections of x and x' onto the
constraints suffer from the same eps/d^k loss of accuracy.

Charts are built for one-coordinate models with a square position system, in
the ``"exact"`` formulation; other models keep the plain equations.
"""

from __future__ import annotations

import numpy as np

from ..kinematics.analogs import velocity_analogs
from ..kinematics.branch_chart import BranchChart, ChartBook, PathProblem
from ..model import Model
from .lagrange import EquationsOfMotion, Terms

__all__ = ["BranchEquations"]


class BranchEquations(EquationsOfMotion):
    """:class:`~mechdyn.dynamics.lagrange.EquationsOfMotion` that go through
    bifurcation positions on the branch the motion is on.

    Parameters are those of :class:`~mechdyn.dynamics.lagrange.EquationsOfMotion`.

    Attributes
    ----------
    book : ChartBook or None
        The charts built so far (None where charts do not apply: several
        coordinates, redundant joints, or the ``"analogs"`` formulation).

    Examples
    --------
    A parallelogram four-bar of 1 m bars (1 kg, uniform) under gravity, its crank at
    1e-7 rad from the flat position: (5/3) phi'' = -2 g cos(phi).

    >>> import numpy as np, mechdyn as md
    >>> m = md.Mechanism("parallelogram", gravity=(0.0, -9.81))
    >>> _ = m.add_ground({"O": (0.0, 0.0), "C": (1.0, 0.0)})
    >>> for name, pose in (("crank", (0, 0, 0.5)), ("coupler", (np.cos(0.5), np.sin(0.5), 0)),
    ...                    ("rocker", (1, 0, 0.5))):
    ...     _ = m.add_body(name, mass=1.0, inertia=1 / 12, com=(0.5, 0.0),
    ...                    points={"E": (1.0, 0.0)}, pose=pose)
    >>> _ = m.add_revolute("O", "ground", "crank", "O", (0.0, 0.0))
    >>> _ = m.add_revolute("A", "crank", "coupler", "E", (0.0, 0.0))
    >>> _ = m.add_revolute("B", "coupler", "rocker", "E", "E")
    >>> _ = m.add_revolute("C", "ground", "rocker", "C", (0.0, 0.0))
    >>> _ = m.add_coordinate("phi", kind="angle", body="crank")
    >>> eom = BranchEquations(m.compile(), backend="numpy")
    >>> _ = eom.qddot(0.0, [0.5], [-1.0])          # approaching: the chart is built
    >>> a = eom.qddot(0.0, [1e-7], [-1.0])[0]
    >>> bool(abs(a - (-2 * 9.81 * np.cos(1e-7) / (5 / 3))) < 1e-11)
    True
    """

    def __init__(self, model: Model, formulation: str = "exact", **kwargs):
        super().__init__(model, formulation, **kwargs)
        self.book: ChartBook | None = None
        if (formulation == "exact" and model.n_q == 1
                and self.layout.n_rows + 1 == model.n_x):
            self.book = ChartBook(PathProblem(model, self.layout, [0], [0.0], 0))
        self._s_last: float | None = None
        #: whether evaluations look out for singular positions (off while a caller
        #: samples dense output, so that output times do not change the run)
        self.watching = True

    # ------------------------------------------------------------------ charts
    def chart_at(self, q) -> BranchChart | None:
        """The chart whose zone holds the coordinates q (n_q,), else None."""
        if self.book is None:
            return None
        return self.book.zone_chart(float(np.asarray(q, dtype=float).reshape(-1)[0]))

    def _prepare(self, s: float) -> None:
        """Start the direct Newton solve at s from the chart's pose when s lies in a chart
        window, or from the window's edge when the step jumps over a chart."""
        book = self.book
        ch = book.window_chart(s)
        if ch is None and self._s_last is not None:
            ch = book.crossed(self._s_last, s)
            if ch is not None:
                s = ch.centre + np.sign(s - ch.centre) * ch.window
        if ch is not None:
            self.reset(ch.evaluate(s)[0])

    def _watch(self, s: float) -> BranchChart | None:
        """After a direct solve at s: build a chart if a singular position is within
        reach; returns it if its zone holds s."""
        self._s_last = s
        if not self.watching or not self.book.due(s):
            return None
        x = self.kernel.x.copy() if self.kernel is not None and not self.kernel.status \
            else self.x
        ch = self.book.watch(s, x)
        return ch if ch is not None and ch.in_zone(s) else None

    def _chart_terms(self, ch: BranchChart, t, q, qdot) -> Terms:
        self.evaluations += 1
        q = np.asarray(q, dtype=float)
        qdot = np.asarray(qdot, dtype=float)
        x, xs, xss = ch.evaluate(float(q[0]))
        self.x = x
        return self._lagrange(t, q, qdot, x, xs[:, None], xss * qdot[0] ** 2)

    # ------------------------------------------------------------------ overrides
    def positions(self, q, t: float | None = None, *, check_singular: bool = False):
        """Body poses (n_x,) at q: from the chart in a bifurcation zone, else by Newton
        (see :meth:`EquationsOfMotion.positions`)."""
        if self.book is None:
            return super().positions(q, t, check_singular=check_singular)
        s = float(np.asarray(q, dtype=float).reshape(-1)[0])
        ch = self.book.zone_chart(s)
        if ch is None:
            self._prepare(s)
            x = super().positions(q, t, check_singular=check_singular)
            ch = self._watch(s)
            if ch is None:
                return x
        x = ch.evaluate(s)[0]
        self.reset(x)
        return x.copy()

    def rhs(self, t: float, q, qdot):
        """q'' and the non-conservative power at (t, q, q'), see
        :meth:`EquationsOfMotion.rhs`."""
        if self.book is None:
            return super().rhs(t, q, qdot)
        s = float(np.asarray(q, dtype=float).reshape(-1)[0])
        ch = self.book.zone_chart(s)
        if ch is None:
            self._prepare(s)
            out = super().rhs(t, q, qdot)
            ch = self._watch(s)
            if ch is None:
                return out
        tm = self._chart_terms(ch, t, q, qdot)
        return tm.qddot, np.array([tm.power_nc])

    def first_order_function(self):
        """``fun(t, y) -> y'`` calling the compiled kernel outside the bifurcation zones
        and the charts inside them; None without the compiled backend."""
        base = super().first_order_function()
        if base is None or self.book is None:
            return base
        book = self.book

        def fun(t, y):
            s = float(y[0])
            ch = book.zone_chart(s) if book.charts else None
            if ch is None:
                if book.charts:
                    self._prepare(s)
                out = base(t, y)
                self._s_last = s
                if not book.due(s):
                    return out
                ch = self._watch(s)
                if ch is None:
                    return out
            tm = self._chart_terms(ch, t, y[:1], y[1:2])
            return np.concatenate([y[1:2], tm.qddot, [tm.power_nc]])

        return fun

    def _exact(self, t, q, qdot) -> Terms:
        ch = self.chart_at(q)
        if ch is not None:
            return self._chart_terms(ch, t, q, qdot)
        return super()._exact(t, q, qdot)

    # ------------------------------------------------------------------ records
    def velocity_analogs(self, q, x) -> np.ndarray:
        """Velocity analogs B (n, n_x, n_q) of recorded samples q (n, n_q), x (n, n_x):
        the chart's tangent in bifurcation zones, else the exact analogs."""
        q = np.asarray(q, dtype=float).reshape(-1, self.model.n_q)
        x = np.asarray(x, dtype=float).reshape(q.shape[0], self.model.n_x)
        if self.book is None or not self.book.charts:
            return velocity_analogs(self.model, x, self.layout)
        mask, _, xs, _ = self.book.apply(q[:, 0])
        B = np.empty((q.shape[0], self.model.n_x, self.model.n_q))
        if (~mask).any():
            B[~mask] = velocity_analogs(self.model, x[~mask], self.layout)
        B[mask] = xs[:, :, None]
        return B

    def report(self) -> list[dict]:
        """The bifurcation positions met (one dict per chart, see
        :meth:`~mechdyn.kinematics.branch_chart.ChartBook.report`)."""
        return [] if self.book is None else self.book.report()
