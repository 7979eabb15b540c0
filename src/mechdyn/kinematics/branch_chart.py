"""Branch charts: a mechanism's branch through a bifurcation position, by continuity.

At a *bifurcation* (change point) two assembly branches cross: the joint
Jacobian Phi_x loses rank, [Phi_x; g_x] is singular, yet the branch the
mechanism is on goes on smoothly and its coordinate keeps control (the flat
positions of a parallelogram four-bar).  The pose x(s) along the path
coordinate s is an analytic function there, but evaluated from the equations
at a distance d from the crossing it is ill-conditioned: the pose is fixed
only to eps/d in the direction of the other branch, and the analogs x' and
x'' are computed with errors growing like eps/d^2 and eps/d^3 (a parallelogram
four-bar's crank acceleration errs by about 2e-16/d^3 rad/s^2, d in rad).

A :class:`BranchChart` replaces the equations in a zone |s - s*| < ``zone``
around the singular position s* by the limit from the sides: one polynomial
x(s) (a Chebyshev series) that interpolates x, x' and x'' at nodes
``zone <= |s - s*| <= window`` on both sides, where the equations are well
conditioned.  The nodes beyond s* are reached by continuation across it: a
quintic Hermite extrapolation of the approach side predicts the pose, Newton
corrects it, and the landing is accepted only if the corrector is small and
the tangent continues the predicted one -- so the branch kept is the one the
motion is on (continuity), never the other one through the same point.  The
same test rejects a *dead* position (a fold, where the coordinate cannot go
on): there is no solution beyond it, and no chart is built.


:class:`ChartBook` watches poses along a path, estimates the distance to the
nearest singular position by a Newton step on the determinant D of the scaled
Jacobian along the branch (s* ~ s - D / D'), builds charts
when one comes within reach and remembers where none could be built.

The path is a line in coordinate space: coordinates ``idx`` of the model are
prescribed, all held at ``q_fixed`` but the one at position ``k`` in ``idx``,
which is the path coordinate s (rad or m).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.polynomial import chebyshev as cheb

from ..model import ConstraintLayout, Model
from .assembly import column_scale
from .continuation import _hermite5, _Node, march_path, path_newton, path_node, sweep_kernel

__all__ = ["PathProblem", "BranchChart", "ChartBook", "bridge", "ZONE", "WINDOW", "REACH"]

#: half-width of the zone where a chart replaces the equations, in units of the path
#: coordinate (rad; the model's length scale for travels)
ZONE = 0.15
#: half-width of the chart's node window (same units)
WINDOW = 0.6
#: a singular position estimated closer than this starts a chart (same units)
REACH = 0.9
#: a chart without a sign change of det [Phi_x; g_x] is kept only if the smallest
#: sigma_min / sigma_max along it falls below this (a near miss of a crossing)
NEAR_MISS_RCOND = 1e-3
#: largest continuation step while placing the nodes (same units)
_STEP = 0.1
#: the chart is rejected if it misses a direct solve at a check point by more (scaled)
_CHART_TOL = 1e-7


class PathProblem:
    """The position problem along a line in coordinate space.

    Parameters
    ----------
    model : Model
    layout : ConstraintLayout
        Joint rows of the mode.
    idx : sequence of int
        Prescribed coordinates (the others follow from the constraints); with the
        joint rows they must form a square system.
    q_fixed : array_like, shape (len(idx),)
        Values of the prescribed coordinates (rad or m); entry ``k`` is replaced by s.
    k : int
        Position in ``idx`` of the path coordinate s.

    Raises
    ------
    ValueError
        The system [Phi_x; g_idx,x] is not square.

    Examples
    --------
    >>> import numpy as np, mechdyn as md
    >>> m = md.Mechanism("crank")
    >>> _ = m.add_body("crank", points={"A": (0.1, 0.0)})
    >>> _ = m.add_revolute("O", "ground", "crank")
    >>> _ = m.add_coordinate("phi", kind="angle", body="crank")
    >>> path = PathProblem(m.compile(), m.compile().layout(), [0], [0.0], 0)
    >>> node = path.solve(0.3, np.zeros(3))
    >>> round(float(node.x[2]), 9), round(float(node.xs[2]), 9)   # crank angle, its analog
    (0.3, 1.0)
    """

    def __init__(self, model: Model, layout: ConstraintLayout, idx, q_fixed, k: int):
        self.model, self.layout = model, layout
        self.idx = np.asarray(idx, dtype=int).reshape(-1)
        self.q_fixed = np.asarray(q_fixed, dtype=float).reshape(self.idx.size).copy()
        self.k = int(k)
        if layout.n_rows + self.idx.size != model.n_x:
            raise ValueError("a branch chart needs a square position system "
                             f"({layout.n_rows} joint rows + {self.idx.size} coordinates "
                             f"for {model.n_x} pose components)")
        self.scale = column_scale(model)
        #: unit of the path coordinate for the zone sizes: 1 rad, or the length scale
        self.unit = 1.0 if model.coord_is_angle[self.idx[self.k]] else float(model.length_scale)
        self.tol = 1e-14 * max(model.length_scale, 1e-3)
        #: the equations [Phi; g_idx - q] (the compiled kernel of the sweep)
        self.kernel = sweep_kernel(model, layout, self.idx)

    # ------------------------------------------------------------------ equations
    def _q(self, s) -> np.ndarray:
        q = self.q_fixed.copy()
        q[self.k] = s
        return q

    def jacobian(self, x) -> np.ndarray:
        """[Phi_x; g_idx,x] at x, shape (n_x, n_x)."""
        return self.kernel.system(np.asarray(x, dtype=float), self.q_fixed)[1]

    def node(self, s, x, J=None) -> _Node:
        """The solved pose x at s with x' = dx/ds (``xs``), x'' (``xss``) and the branch sign."""
        return path_node(self.kernel, np.asarray(x, dtype=float), self._q(s), self.k, J)

    def solve(self, s, x_guess) -> _Node | None:
        """The node at s by Newton from ``x_guess`` (None if it does not converge)."""
        x, ok, _, J = path_newton(self.kernel, np.asarray(x_guess, dtype=float), self._q(s),
                              self.tol, max_iter=12)
        return self.node(s, x, J) if ok else None

    # ------------------------------------------------------------------ singular values
    def singular_offset(self, x, xs=None) -> float:
        """Estimated offset s* - s of the nearest singular position from the pose x at s
        (``xs``: its analog dx/ds, computed if not given).

        The determinant D(s) of the scaled Jacobian along the branch is smooth with a
        simple zero at a crossing (and a square-root zero at a fold); one Newton step
        on it, s* ~ s - D / D' with D' by a difference along the tangent, places
        the singular position (exact to first order).  The smallest singular value is
        no guide: away from the crossing the vanishing one need not be the smallest."""
        J = self.jacobian(x)
        if xs is None:
            xs = np.linalg.solve(J, np.eye(len(J))[self.layout.n_rows + self.k])
        h = 1e-5 * self.unit
        d0 = np.linalg.det(J * self.scale)
        d1 = (np.linalg.det(self.jacobian(x + h * xs) * self.scale) - d0) / h
        if d1 == 0.0 or not np.isfinite(d1):
            return np.inf
        return float(-d0 / d1)

    def rcond(self, x) -> float:
        """sigma_min / sigma_max of the scaled Jacobian at x."""
        sv = np.linalg.svd(self.jacobian(x) * self.scale, compute_uv=False)
        return float(sv[-1] / sv[0]) if sv[0] > 0 else 0.0

    # ------------------------------------------------------------------ continuation
    def march(self, node: _Node, s_to: float):
        """Continuation from ``node`` to s_to (the sweep's march, without charts); returns
        (node reached, ok).  A change of the branch sign is refused, so the march stops
        in front of a singular position."""
        out, stop = march_path(self.kernel, node, self.k, [s_to], max_step=_STEP * self.unit,
                           min_step=1e-9 * self.unit, tol=self.tol, counter={})
        return (stop.node if stop is not None else out[-1]), stop is None


@dataclass
class BranchChart:
    """One branch around a singular position: x(s), x'(s), x''(s) as a Chebyshev series
    (built by :func:`bridge`; see its example and that of :class:`ChartBook`).

    Attributes
    ----------
    centre : float
        Estimated singular position s* (rad or m).
    zone : float
        Half-width of the zone where the chart replaces the equations.
    window : float
        Half-width of the node window (the chart is valid there).
    coef : ndarray, shape (N, 3 n_x)
        Chebyshev coefficients of (x, x', x'') on u = (s - centre) / window.
    kind : str
        ``"bifurcation"`` (the branch sign changes across it) or ``"near-singular"``.
    signs : tuple of float
        Branch sign (det of the scaled Jacobian) below and above the centre.
    error : float
        Largest scaled difference from direct solves at two check points (m).
    rcond : float
        sigma_min / sigma_max at the nodes next to the centre.
    """

    centre: float
    zone: float
    window: float
    coef: np.ndarray = field(repr=False)
    kind: str
    signs: tuple
    error: float
    rcond: float

    def in_zone(self, s) -> bool:
        """Whether s lies in the zone where the chart replaces the equations."""
        return abs(s - self.centre) < self.zone

    def in_window(self, s) -> bool:
        """Whether s lies in the node window (where the chart is valid)."""
        return abs(s - self.centre) <= self.window

    def side_sign(self, s) -> float:
        """The branch sign expected at s (on its side of the centre)."""
        return self.signs[0] if s < self.centre else self.signs[1]

    def evaluate(self, s):
        """Pose x, x' = dx/ds and x'' at s (scalar, or an array of shape (m,)).

        Returns
        -------
        x, xs, xss : ndarray, shape (n_x,) or (m, n_x)
        """
        s = np.asarray(s, dtype=float)
        u = (s - self.centre) / self.window
        out = cheb.chebvander(u, self.coef.shape[0] - 1) @ self.coef
        return tuple(np.split(out.reshape(-1) if s.ndim == 0 else out, 3, axis=-1))

    def summary(self) -> dict:
        """The chart as a plain dict (for run statistics)."""
        return {"at": self.centre, "kind": self.kind, "zone": self.zone,
                "window": self.window, "error": self.error, "rcond": self.rcond}


def _fit(nodes, centre: float, window: float) -> np.ndarray:
    """Chebyshev coefficients (N, 3 n_x) of the confluent Hermite interpolant of the
    nodes (value, first and second derivative at each)."""
    N = 3 * len(nodes)
    u = np.array([(nd.s - centre) / window for nd in nodes])
    V0 = cheb.chebvander(u, N - 1)
    # the derivatives of T_0 .. T_(N-1) as Chebyshev series (one row each)
    D1, D2 = (np.pad(cheb.chebder(np.eye(N), m, axis=1), ((0, 0), (0, m))) for m in (1, 2))
    V = np.concatenate([V0, V0 @ D1.T / window, V0 @ D2.T / window**2])
    Y = np.concatenate([[getattr(nd, f) for nd in nodes] for f in ("x", "xs", "xss")])
    c = np.linalg.solve(V, Y)
    return np.concatenate([c, D1.T @ c / window, D2.T @ c / window**2], axis=1)


def bridge(path: PathProblem, start: _Node, s_star: float, *, zone: float = ZONE,
           window: float = WINDOW) -> BranchChart | None:
    """Build the chart of the branch of ``start`` across the singular position near s*.

    Parameters
    ----------
    path : PathProblem
    start : _Node
        A solved pose on the branch (its side of s* is the approach side).
    s_star : float
        Estimate of the singular position (rad or m); refined on the way.
    zone, window : float
        Half-widths of the zone and the node window, in units of the path coordinate.

    Returns
    -------
    BranchChart or None
        None where the branch does not go on past s* (a dead position: no solution
        beyond, or only the other half of a fold), or where there is no singular
        position after all.

    Raises
    ------
    numpy.linalg.LinAlgError
        A Jacobian on the way is exactly singular (:meth:`ChartBook.watch` catches it).

    Examples
    --------
    A parallelogram four-bar of unit bars, its crank at 0.5 rad, towards its flat
    position phi = 0: the coupler stays level on the other side too.

    >>> import numpy as np, mechdyn as md
    >>> m = md.Mechanism("parallelogram")
    >>> _ = m.add_ground({"O": (0.0, 0.0), "C": (1.0, 0.0)})
    >>> c, s = np.cos(0.5), np.sin(0.5)
    >>> _ = m.add_body("crank", points={"E": (1.0, 0.0)}, pose=(0.0, 0.0, 0.5))
    >>> _ = m.add_body("coupler", points={"E": (1.0, 0.0)}, pose=(c, s, 0.0))
    >>> _ = m.add_body("rocker", points={"E": (1.0, 0.0)}, pose=(1.0, 0.0, 0.5))
    >>> o = (0.0, 0.0)
    >>> pins = [("O", "ground", "crank", "O", o), ("B", "coupler", "rocker", "E", "E"),
    ...         ("A", "crank", "coupler", "E", o), ("C", "ground", "rocker", "C", o)]
    >>> _ = [m.add_revolute(*pin) for pin in pins]
    >>> _ = m.add_coordinate("phi", kind="angle", body="crank")
    >>> model = m.compile()
    >>> path = PathProblem(model, model.layout(), [0], [0.5], 0)
    >>> chart = bridge(path, path.node(0.5, model.x0), 0.0)
    >>> x, _, _ = chart.evaluate(-0.1)
    >>> round(float(x[2]), 9), abs(float(x[5])) < 1e-9   # crank angle; coupler level?
    (-0.1, True)
    """
    r1, R = zone * path.unit, window * path.unit
    ts = r1 + (R - r1) * (1.0 - np.cos(np.array([0.0, 0.25, 0.5]) * np.pi))  # r1 .. R
    dsgn = 1.0 if s_star >= start.s else -1.0
    for _ in range(4):  # place the approach side, re-centring on the way
        near, n = [], start
        for t in ts[::-1]:
            n, ok = path.march(n, s_star - dsgn * t)
            if not ok:  # the singular position is closer than estimated
                break
            near.append(n)
        if len(near) < ts.size:
            s_star = n.s + dsgn * 1e-3 * path.unit
            continue
        new = near[-1].s + path.singular_offset(near[-1].x, near[-1].xs)
        if not np.isfinite(new) or abs(new - s_star) <= 0.2 * r1:
            break
        s_star = new
    else:
        return None
    # ---- across: extrapolate the approach side, correct, check the continuation
    a, b = near[-2], near[-1]
    sb = s_star + dsgn * r1
    hp = b.s - a.s
    xp = _hermite5(1.0 + (sb - b.s) / hp, hp, a.x, a.xs, a.xss, b.x, b.xs, b.xss)
    nb = path.solve(sb, xp)
    if nb is None:
        return None
    sc = path.scale
    if np.max(np.abs((nb.x - xp) * sc)) > 0.1 * np.max(np.abs((nb.x - b.x) * sc)):
        return None
    xs_p = b.xs + b.xss * (sb - b.s)
    if np.max(np.abs((nb.xs - xs_p) * sc)) > 0.25 * max(np.max(np.abs(nb.xs * sc)),
                                                         np.max(np.abs(b.xs * sc))):
        return None
    far = [nb]
    for t in ts[1:]:
        n, ok = path.march(far[-1], s_star + dsgn * t)
        if not ok:
            return None
        far.append(n)
    flip = nb.sign != b.sign
    rc = min(path.rcond(b.x), path.rcond(nb.x))
    if not flip:
        # no crossing: keep the chart only if the branches nearly touch in between
        mid = path.solve(0.5 * (b.s + nb.s), _hermite5(0.5, nb.s - b.s, b.x, b.xs, b.xss,
                                                       nb.x, nb.xs, nb.xss))
        if mid is None:
            return None
        rc = min(rc, path.rcond(mid.x))
        if rc >= NEAR_MISS_RCOND:
            return None
    nodes = sorted(near + far, key=lambda nd: nd.s)
    coef = _fit(nodes, s_star, R)
    signs = (b.sign, nb.sign) if dsgn > 0 else (nb.sign, b.sign)
    chart = BranchChart(float(s_star), r1, R, coef, "bifurcation" if flip else "near-singular",
                        signs, 0.0, rc)
    err = 0.0
    for t in (0.5 * (ts[0] + ts[1]), -0.5 * (ts[0] + ts[1])):
        x, xs, _ = chart.evaluate(s_star + t)
        chk = path.solve(s_star + t, x)
        if chk is None:
            return None
        err = max(err, float(np.max(np.abs((chk.x - x) * sc))),
                  float(np.max(np.abs((chk.xs - xs) * sc))) * path.unit)
    if err > _CHART_TOL * path.model.length_scale:
        return None
    chart.error = err
    return chart


class ChartBook:
    """The charts met along one path, and the places where none could be built.

    Parameters
    ----------
    path : PathProblem
    zone, window, reach : float
        Zone and window half-widths of the charts, and the estimated distance of a
        singular position that starts a chart (units of the path coordinate).

    Examples
    --------
    A parallelogram four-bar goes through its flat position on the parallelogram
    branch: the rocker turns with the crank, also at the flat position itself.

    >>> import numpy as np, mechdyn as md
    >>> m = md.Mechanism("parallelogram")
    >>> _ = m.add_ground({"O": (0.0, 0.0), "C": (1.0, 0.0)})
    >>> for name, pose in (("crank", (0, 0, 0.5)), ("coupler", (np.cos(0.5), np.sin(0.5), 0)),
    ...                    ("rocker", (1, 0, 0.5))):
    ...     _ = m.add_body(name, points={"E": (1.0, 0.0)}, pose=pose)
    >>> _ = m.add_revolute("O", "ground", "crank", "O", (0.0, 0.0))
    >>> _ = m.add_revolute("A", "crank", "coupler", "E", (0.0, 0.0))
    >>> _ = m.add_revolute("B", "coupler", "rocker", "E", "E")
    >>> _ = m.add_revolute("C", "ground", "rocker", "C", (0.0, 0.0))
    >>> _ = m.add_coordinate("phi", kind="angle", body="crank")
    >>> model = m.compile()
    >>> book = ChartBook(PathProblem(model, model.layout(), [0], [0.5], 0))
    >>> chart = book.watch(0.5, model.x0)
    >>> chart.kind, abs(chart.centre) < 1e-3     # centre: an estimate of the crossing
    ('bifurcation', True)
    >>> x, xs, _ = chart.evaluate(0.0)
    >>> abs(float(x[8])) < 1e-9, round(float(xs[8]), 9)  # rocker angle zero?; its analog
    (True, 1.0)
    """

    def __init__(self, path: PathProblem, *, zone: float = ZONE, window: float = WINDOW,
                 reach: float = REACH):
        self.path = path
        self.zone, self.window, self.reach = zone, window, reach
        self.charts: list[BranchChart] = []
        #: windows (lo, hi, reason) where no chart is needed or none can be built
        self.skipped: list[tuple] = []
        self._checked: tuple | None = None

    def zone_chart(self, s) -> BranchChart | None:
        """The chart whose zone holds s, else None."""
        return next((ch for ch in self.charts if ch.in_zone(s)), None)

    def window_chart(self, s) -> BranchChart | None:
        """The chart whose window holds s, else None."""
        return next((ch for ch in self.charts if ch.in_window(s)), None)

    def crossed(self, s_from, s_to) -> BranchChart | None:
        """A chart whose centre lies between s_from and s_to, else None."""
        return next((ch for ch in self.charts
                     if (s_from - ch.centre) * (s_to - ch.centre) < 0), None)

    def due(self, s: float) -> bool:
        """Whether a pose at s would be checked by :meth:`watch` (cheap)."""
        return self._checked is None or abs(s - self._checked[0]) >= self._checked[1]

    def watch_window(self) -> tuple[float, float]:
        """``(centre, half width)``: :meth:`due` is true where |s - centre| >= half width
        (a compiled loop checks it without calling back)."""
        return (0.0, 0.0) if self._checked is None else self._checked

    def watch(self, s: float, x, *, force_at: float | None = None) -> BranchChart | None:
        """Check the solved pose x at s for a singular position within reach and build
        its chart.  Returns the chart built by this call, else None.

        ``force_at`` skips the estimate: a singular position is known to lie there."""
        unit = self.path.unit
        if force_at is None and (not self.due(s) or self._blocked(s)):
            return None
        try:
            off = force_at - s if force_at is not None else self.path.singular_offset(x)
        except np.linalg.LinAlgError:
            return None
        dist = abs(off)
        if force_at is None:
            # far estimates are rough: look again sooner than halfway there
            r = self.reach * unit
            again = min(0.25 * min(dist, r) + 0.3 * max(dist - r, 0.0), r)
            self._checked = (s, max(again, 0.02 * unit))
            if not dist <= r:
                return None
        s_star = s + off
        if self._blocked(s_star):
            return None
        try:
            with np.errstate(all="ignore"):
                chart = bridge(self.path, self.path.node(s, x), s_star, zone=self.zone,
                               window=self.window)
        except np.linalg.LinAlgError:
            chart = None
        if chart is None:
            w = self.window * unit
            self.skipped.append((s_star - w, s_star + w, "no chart"))
            return None
        self.charts.append(chart)
        return chart

    def _blocked(self, s) -> bool:
        """Whether s lies in the window of a chart or of a place where none was built."""
        return self.window_chart(s) is not None or any(lo <= s <= hi for lo, hi, _ in self.skipped)

    def apply(self, s):
        """Chart values for the samples s (m,) that lie in a zone.

        Returns
        -------
        mask : ndarray of bool, shape (m,)
        x, xs, xss : ndarray, shape (mask.sum(), n_x)
        """
        s = np.asarray(s, dtype=float).reshape(-1)
        mask = np.zeros(s.size, dtype=bool)
        x, xs, xss = (np.empty((s.size, self.path.model.n_x)) for _ in range(3))
        for ch in self.charts:
            m = (np.abs(s - ch.centre) < ch.zone) & ~mask
            if m.any():
                x[m], xs[m], xss[m] = ch.evaluate(s[m])
                mask |= m
        return mask, x[mask], xs[mask], xss[mask]

    def report(self) -> list[dict]:
        """The charts built, as plain dicts (``at``, ``kind``, ``zone``, ``error`` ...)."""
        return [ch.summary() for ch in self.charts]
