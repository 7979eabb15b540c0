"""Kinematic sweep: positions, velocities and accelerations over a range of one coordinate.

The sweep drives one generalized coordinate (``over``) through a sequence of
values while the other coordinates stay at their initial values, and records
the poses ``x``, the exact velocity analogs ``B = dx/dq`` and the velocities
and accelerations of every body at a constant rate of the coordinates.

How it is computed (vectorized over the positions):

1. *Coarse continuation.*  Starting from the assembled sketch, the mechanism is
   driven sequentially through a coarse subset of the values (steps of at most
   ``max_step``, 5 deg by default), predicting each step by quintic Hermite
   extrapolation through the last two solutions (their poses, velocity analogs
   ``x' = B`` and second derivatives ``x''``; a Taylor step ``x + x' h + x'' h^2/2``
   when there is only one), then Newton's method.  A step is accepted only if
   Newton converges, the sign of det [Phi_x; g_x] (the assembly branch) is
   unchanged and the corrector stays small compared with the step; otherwise
   the step is halved.  When the step falls below ``min_step`` the mechanism
   has reached a dead (or toggle) position: the sweep stops there and reports
   it, keeping everything computed before.
2. *Batched solve.*  Every value is predicted by quintic Hermite interpolation
   between the two coarse solutions around it (positions, first and second
   derivatives with respect to the swept coordinate), then polished by Newton's
   method on the whole batch at once.  Each point is checked for convergence,
   for the branch sign of its segment and for staying close to its predictor; a
   segment with a failing point is re-solved sequentially.
3. *Velocities and accelerations* of all positions in one batched solve:
   ``xdot = B qdot`` and ``xddot = B qddot + b(x, xdot)`` (here ``qddot = 0``).

The residual, Jacobian and acceleration right-hand side are the exact
equations of :mod:`mechdyn.kinematics.constraints`, evaluated by a private
kernel that precomputes the sparsity pattern of the Jacobian (the result is
identical; it is only cheaper per call).
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError, SingularPositionError, did_you_mean
from ..model import Model, as_model
from ._sweep_kernel import Kernel
from .assembly import assemble, singularity
from .constraints import coordinates, point_acceleration, point_position, point_velocity

__all__ = ["sweep", "analyze", "initial_coordinates", "KinematicSweep", "KinematicPoint",
           "SweepSummary", "DeadCentre", "TransmissionAngle", "PointExtremes", "FourBarLoop",
           "four_bar_loops", "DEFAULT_MAX_STEP"]

#: largest step of the sequential coarse continuation for angle coordinates, rad (5 deg)
DEFAULT_MAX_STEP = np.deg2rad(5.0)
#: smallest step before a dead position is declared, rad (times the length scale for travels)
DEFAULT_MIN_STEP = 1e-11
#: Newton iterations allowed per step of the continuation / per batched polish
_MAX_NEWTON = 10


# ====================================================================== nodes
@dataclass
class _Node:
    """One solved position of the continuation: pose, analogs, second derivative, sign."""

    q: np.ndarray  # (n_q,)
    x: np.ndarray  # (n_x,)
    B: np.ndarray  # (n_x, n_q)
    H: np.ndarray  # (n_x,) d2x/dq_k^2 of the swept coordinate
    sign: float


def _newton(kern: Kernel, x, q, tol, max_iter=_MAX_NEWTON):
    """Newton on a batch from ``x``; returns x, converged (N,), last F and J (at x)."""
    x = x.copy()
    F, J = kern.system(x, q)
    err = np.max(np.abs(F), axis=1)
    prev = np.full(x.shape[0], np.inf)
    ok = err <= tol
    active = ~ok
    it = 0
    while active.any() and it < max_iter:
        it += 1
        idx = np.flatnonzero(active)
        dx = kern.solve(J[idx], F[idx, :, None])[..., 0]
        xi = x[idx] - dx
        bad = ~np.all(np.isfinite(xi), axis=1)
        xi[bad] = x[idx][bad]
        x[idx] = xi
        Fi, Ji = kern.system(xi, q[idx])
        F[idx], J[idx] = Fi, Ji
        e = np.max(np.abs(Fi), axis=1)
        # converged, or stagnating at round-off level
        ok[idx] = ~bad & ((e <= tol) | ((e >= 0.5 * prev[idx]) & (e <= 1e3 * tol)))
        diverged = bad | ~np.isfinite(e) | (e > 1e3 * np.maximum(err[idx], tol))
        prev[idx] = e
        active[idx] = ~ok[idx] & ~diverged
    return x, ok, F, J


def _newton1(kern: Kernel, x, q, tol, max_iter=_MAX_NEWTON):
    """Newton for one position; returns x, converged, J at x and its LU factors."""
    F, J = kern.system1(x, q)
    err = float(np.max(np.abs(F))) if F.size else 0.0
    first, prev = err, np.inf
    for _ in range(max_iter):
        if err <= tol:
            break
        fac = kern.factor1(J, want_sign=False)
        dx = kern.solve1(J, fac, F)
        xn = x - dx
        if not np.all(np.isfinite(xn)):
            return x, False, J, None
        x = xn
        F, J = kern.system1(x, q)
        prev, err = err, float(np.max(np.abs(F)))
        if not np.isfinite(err) or err > 1e3 * max(first, tol):
            return x, False, J, None
        if err >= 0.5 * prev and err <= 1e3 * tol:  # stagnating at round-off level
            break
    ok = err <= 1e3 * tol
    return x, ok, J, kern.factor1(J) if ok else None


def _polish(kern: Kernel, xp, Q, tol):
    """Newton from accurate predictions ``xp`` (N, n_x): one batched step, then more
    iterations only where needed.  Returns x, F and J at x, and the converged mask."""
    F, J = kern.system(xp, Q)
    X = xp - kern.apply(J, kern.factor(J, want_sign=False), F[..., None])[..., 0]
    F, J = kern.system(X, Q)
    ok = np.max(np.abs(F), axis=1) <= tol
    if not ok.all():
        idx = np.flatnonzero(~ok)
        x2, ok2, F2, J2 = _newton(kern, X[idx], Q[idx], tol, max_iter=4)
        X[idx], F[idx], J[idx], ok[idx] = x2, F2, J2, ok2
    return X, F, J, ok


def _node(kern: Kernel, x, q, k: int, J=None, fac=None) -> _Node:
    """Analogs, second derivative along coordinate ``k`` and branch sign at a solved pose."""
    if J is None:
        _, J = kern.system1(x, q)
        fac = kern.factor1(J)
    B = kern.solve1(J, fac, kern.rhs_unit(1)[0])
    H = kern.solve1(J, fac, kern.gamma1(x, B[:, k]))
    sign = fac[2] if fac is not None else 1.0
    return _Node(q.copy(), x.copy(), B, H, sign)


@dataclass
class _Stop:
    """Where the continuation could not go on."""

    node: _Node  # last solved position
    q_try: np.ndarray  # the coordinates it could not reach
    reason: str


def _scaled_norm(kern, dx):
    return float(np.max(np.abs(dx * kern.col_scale)))


def _predict(prev: _Node | None, node: _Node, k: int, h: float) -> np.ndarray:
    """Pose predicted at q_k + h: quintic Hermite through the last two nodes, extrapolated
    (error O(h^6)); a second-order Taylor step when there is no usable previous node."""
    if prev is not None:
        hp = node.q[k] - prev.q[k]
        if hp != 0 and abs(h) <= 2 * abs(hp):
            t = 1.0 + h / hp  # a float: the basis is then computed in plain Python
            return _hermite5(t, hp, prev.x, prev.B[:, k], prev.H, node.x, node.B[:, k], node.H)
    return node.x + node.B[:, k] * h + 0.5 * node.H * h * h


def _march(kern: Kernel, start: _Node, k: int, targets, *, max_step, min_step, tol,
           counter: dict, prev: _Node | None = None):
    """Sequential continuation through ``targets`` (values of coordinate k).

    Returns the list of nodes reached (one per target) and a :class:`_Stop` or None.
    """
    node = start
    out: list[_Node] = []
    h_try = max_step
    L = kern.model.length_scale
    for target in targets:
        while node.q[k] != target:
            remaining = target - node.q[k]
            qn = node.q.copy()
            if abs(remaining) <= h_try * (1 + 1e-6):
                qn[k] = target
            else:
                qn[k] = node.q[k] + np.sign(remaining) * h_try
            h = qn[k] - node.q[k]
            xp = _predict(prev, node, k, h)
            counter["coarse_steps"] = counter.get("coarse_steps", 0) + 1
            x, ok, J, fac = _newton1(kern, xp, qn, tol)
            accepted = False
            reason = "Newton's method does not converge"
            if ok:
                nn = _node(kern, x, qn, k, J=J, fac=fac)
                step = _scaled_norm(kern, nn.x - node.x)
                corr = _scaled_norm(kern, nn.x - xp)
                if nn.sign != node.sign:
                    reason = "the sign of det [Phi_x; g_x] changes (the branch would be left)"
                elif corr > 0.25 * step + 1e-9 * L:
                    reason = "the corrector moves far from the predictor"
                else:
                    accepted = True
            if not accepted:
                counter["rejected_steps"] = counter.get("rejected_steps", 0) + 1
                h_try = abs(h) / 2
                prev = None  # fall back to the Taylor predictor near trouble
                if h_try < min_step:
                    return out, _Stop(node, qn, reason)
                continue
            prev, node = node, nn
            h_try = min(2 * h_try, max_step)
        out.append(node)
    return out, None


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


# ====================================================================== records
def _ro(a):
    a = np.asarray(a)
    a.flags.writeable = False
    return a


def _unit_of(model: Model, c: int) -> str:
    return "rad" if model.coord_is_angle[c] else "m"


@dataclass(frozen=True)
class KinematicPoint:
    """Kinematics of one position (see :func:`analyze`).

    Attributes
    ----------
    q, qdot, qddot : ndarray, shape (n_q,)
        Coordinates (rad or m) and their rates.
    x, xdot, xddot : ndarray, shape (n_x,)
        Body poses (m, m, rad per body) and their rates.
    B : ndarray, shape (n_x, n_q)
        Velocity analogs dx/dq.
    """

    q: np.ndarray
    qdot: np.ndarray
    qddot: np.ndarray
    x: np.ndarray
    xdot: np.ndarray
    xddot: np.ndarray
    B: np.ndarray
    model: Model = field(repr=False, compare=False)

    def point(self, body: str, name) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position (m), velocity (m/s) and acceleration (m/s^2) of a body point, each (2,)."""
        m = self.model
        return (point_position(m, self.x, body, name),
                point_velocity(m, self.x, self.xdot, body, name),
                point_acceleration(m, self.x, self.xdot, self.xddot, body, name))

    def angular(self, body: str) -> tuple[float, float, float]:
        """Angle (rad), angular velocity (rad/s) and acceleration (rad/s^2) of a body."""
        k = 3 * self.model.body_index(body) + 2
        return float(self.x[k]), float(self.xdot[k]), float(self.xddot[k])


@dataclass(frozen=True)
class DeadCentre:
    """A dead centre of a slider: its travel along the guide has an extremum there.

    Attributes
    ----------
    joint : str
        The prismatic joint.
    label : {"TDC", "BDC"}
        ``"TDC"`` at the maximum travel along the joint's axis direction, ``"BDC"``
        at the minimum (point the axis away from the crank for the engine convention).
    at : float
        Value of the swept coordinate there (rad or m).
    travel : float
        Travel of the slider point along the axis there, m.
    """

    joint: str
    label: str
    at: float
    travel: float


@dataclass(frozen=True)
class FourBarLoop:
    """A loop ground - crank - coupler - rocker - ground joined by four revolutes.

    ``joints`` = (ground-crank, crank-coupler, coupler-rocker, rocker-ground).
    """

    crank: str
    coupler: str
    rocker: str
    joints: tuple[str, str, str, str]


@dataclass(frozen=True)
class TransmissionAngle:
    """Range of the transmission angle of a four-bar loop over the sweep.

    The transmission angle mu is the angle between the coupler and the rocker at
    their common joint, in [0, pi] (rad); 90 deg transmits best.
    """

    loop: FourBarLoop
    min: float
    min_at: float
    max: float
    max_at: float


@dataclass(frozen=True)
class PointExtremes:
    """Largest speed (m/s) and acceleration magnitude (m/s^2) of a point, and where."""

    body: str
    point: str
    v_max: float
    v_max_at: float
    a_max: float
    a_max_at: float


@dataclass(frozen=True)
class SweepSummary:
    """Derived figures of a :class:`KinematicSweep`.

    Attributes
    ----------
    over : str
        The swept coordinate; ``*_at`` values are in its unit (rad or m).
    strokes : dict of str to float
        Stroke (max - min travel over the sweep) of each slider, by prismatic joint, m.
    dead_centres : list of DeadCentre
    transmission : list of TransmissionAngle
    extremes : list of PointExtremes
    """

    over: str
    over_is_angle: bool
    strokes: dict
    dead_centres: list
    transmission: list
    extremes: list

    def as_dict(self) -> dict:
        """Plain nested dict (for JSON)."""
        from dataclasses import asdict

        return asdict(self)

    def lines(self) -> list[str]:
        """Human-readable lines (angles in degrees)."""
        def at(v):
            if not self.over_is_angle:
                return f"{self.over} = {v * 1e3:.4f} mm"
            deg = np.rad2deg(v)
            wrapped = deg % 360.0
            extra = f" = {wrapped:.4f} deg mod 360" if abs(wrapped - deg) > 1e-9 else ""
            return f"{self.over} = {deg:.4f} deg{extra}"

        out = []
        for j, s in self.strokes.items():
            out.append(f"stroke of slider {j!r}: {s * 1e3:.6g} mm")
        for d in self.dead_centres:
            out.append(f"dead centre {d.label} of {d.joint!r} at {at(d.at)} "
                       f"(travel {d.travel * 1e3:.6g} mm)")
        for t in self.transmission:
            lp = t.loop
            out.append(f"transmission angle {lp.coupler}/{lp.rocker} at {lp.joints[2]!r}: "
                       f"{np.rad2deg(t.min):.3f} deg ({at(t.min_at)}) .. "
                       f"{np.rad2deg(t.max):.3f} deg ({at(t.max_at)})")
        return out

    def __str__(self) -> str:
        return "\n".join(self.lines())


@dataclass(frozen=True)
class KinematicSweep:
    """Positions, velocities and accelerations of a mechanism over one coordinate.

    Attributes
    ----------
    over : str
        Name of the swept coordinate.
    values : ndarray, shape (n,)
        Its values at the recorded positions (rad or m).
    q, qdot, qddot : ndarray, shape (n, n_q)
        Generalized coordinates, their (constant) rates and accelerations (zero).
    x, xdot, xddot : ndarray, shape (n, n_x)
        Body poses (x, y in m, theta in rad per body; theta continuous, not wrapped)
        and their first and second time derivatives.
    B : ndarray, shape (n, n_x, n_q)
        Velocity analogs dx/dq (m/rad, rad/rad, m/m or rad/m).
    status : {"success", "dead-position"}
        ``"dead-position"``: the sweep stopped at a dead or toggle position; the
        positions before it are kept and ``message`` says where.
    message : str
    stats : dict
        Counts and timings (``n_points``, ``n_requested``, ``coarse_steps``,
        ``fallback_segments``, ``time_s``, ``positions_per_s``).
    events : tuple of dict
        ``{"kind": "dead-position", "at": value, "index": i, ...}`` when it stopped.
    error : SingularPositionError or None
        The error describing the stop (raise it with :meth:`raise_for_status`).
    """

    over: str
    values: np.ndarray
    q: np.ndarray
    qdot: np.ndarray
    qddot: np.ndarray
    x: np.ndarray
    xdot: np.ndarray
    xddot: np.ndarray
    B: np.ndarray
    status: str
    message: str
    stats: dict
    events: tuple = ()
    error: Exception | None = field(default=None, repr=False, compare=False)
    model: Model = field(default=None, repr=False, compare=False)

    # ------------------------------------------------------------------ access
    def __len__(self) -> int:
        return int(self.values.shape[0])

    @property
    def ok(self) -> bool:
        """True if every requested position was computed."""
        return self.status == "success"

    @property
    def over_index(self) -> int:
        return self.model.coordinate_index(self.over)

    @property
    def over_is_angle(self) -> bool:
        return bool(self.model.coord_is_angle[self.over_index])

    def raise_for_status(self) -> KinematicSweep:
        """Raise the stored error if the sweep stopped early; else return self."""
        if self.error is not None:
            raise self.error
        return self

    def point(self, body: str, name) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position (m), velocity (m/s) and acceleration (m/s^2) of a body point.

        Parameters
        ----------
        body : str
        name : str or (float, float)
            A named point (``"com"`` for the centre of mass) or body-frame coordinates, m.

        Returns
        -------
        r, v, a : ndarray, shape (n, 2) each
        """
        m = self.model
        return (point_position(m, self.x, body, name),
                point_velocity(m, self.x, self.xdot, body, name),
                point_acceleration(m, self.x, self.xdot, self.xddot, body, name))

    def point_analogs(self, body: str, name) -> np.ndarray:
        """Velocity analogs dr/dq of a body point, shape (n, 2, n_q) (m/rad or m/m)."""
        m = self.model
        k = m.body_index(body)
        s = m.point_local(body, name)
        th = self.x[:, 3 * k + 2]
        ax = np.cos(th) * s[0] - np.sin(th) * s[1]
        ay = np.sin(th) * s[0] + np.cos(th) * s[1]
        Bk = self.B[:, 3 * k:3 * k + 3, :]
        return np.stack([Bk[:, 0] - ay[:, None] * Bk[:, 2],
                         Bk[:, 1] + ax[:, None] * Bk[:, 2]], axis=1)

    def angular(self, body: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Angle (rad), angular velocity (rad/s), angular acceleration (rad/s^2), (n,) each."""
        k = 3 * self.model.body_index(body) + 2
        return self.x[:, k], self.xdot[:, k], self.xddot[:, k]

    def slider_travel(self, joint: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Travel (m) of a prismatic joint's child point along its axis, its rate (m/s)
        and its second derivative (m/s^2), (n,) each."""
        return _travel(self.model, joint, self.x, self.xdot, self.xddot)

    # ------------------------------------------------------------------ tables
    def to_dataframe(self):
        """One row per position; columns named as in ``docs/notation.md`` (unit suffixes).

        Columns: every coordinate ``<c>_rad`` (``<c>_m`` for travels), the swept one also
        ``<c>_deg``, rates ``<c>_dot_rad_s``, ``<c>_ddot_rad_s2``; per body ``theta_<b>_rad``,
        ``omega_<b>_rad_s``, ``alpha_<b>_rad_s2`` and analogs ``dtheta_<b>_d<c>_rad``;
        per named point ``x_<b>_<p>_m``, ``y_..``, ``vx_<b>_<p>_m_s``, ``vy_..``,
        ``ax_<b>_<p>_m_s2``, ``ay_..`` and analogs ``dx_<b>_<p>_d<c>_m``, ``dy_..``.
        """
        import pandas as pd

        m = self.model
        cols: dict[str, np.ndarray] = {}
        names = m.coordinate_names
        for c, name in enumerate(names):
            u = _unit_of(m, c)
            cols[f"{name}_{u}"] = self.q[:, c]
            if name == self.over and u == "rad":
                cols[f"{name}_deg"] = np.rad2deg(self.q[:, c])
        for c, name in enumerate(names):
            u = _unit_of(m, c)
            cols[f"{name}_dot_{u}_s"] = self.qdot[:, c]
            cols[f"{name}_ddot_{u}_s2"] = self.qddot[:, c]

        def per(c):  # analog unit suffix: per rad is implied, per m is written
            return "" if m.coord_is_angle[c] else "_m"

        for b in m.body_names:
            th, om, al = self.angular(b)
            cols[f"theta_{b}_rad"] = th
            cols[f"omega_{b}_rad_s"] = om
            cols[f"alpha_{b}_rad_s2"] = al
            k = 3 * m.body_index(b) + 2
            for c, name in enumerate(names):
                cols[f"dtheta_{b}_d{name}_rad{per(c)}"] = self.B[:, k, c]
        for b, p in m.named_points():
            r, v, a = self.point(b, p)
            dr = self.point_analogs(b, p)
            tag = f"{b}_{p}"
            cols[f"x_{tag}_m"], cols[f"y_{tag}_m"] = r[:, 0], r[:, 1]
            cols[f"vx_{tag}_m_s"], cols[f"vy_{tag}_m_s"] = v[:, 0], v[:, 1]
            cols[f"ax_{tag}_m_s2"], cols[f"ay_{tag}_m_s2"] = a[:, 0], a[:, 1]
            for c, name in enumerate(names):
                cols[f"dx_{tag}_d{name}_m{per(c)}"] = dr[:, 0, c]
                cols[f"dy_{tag}_d{name}_m{per(c)}"] = dr[:, 1, c]
        return pd.DataFrame(cols)

    # ------------------------------------------------------------------ summary
    def summary(self) -> SweepSummary:
        """Strokes and dead centres of the sliders, transmission angles of the four-bar
        loops, and the extreme speed and acceleration of every named point."""
        return _summarize(self)


# ====================================================================== helpers
def _travel(model: Model, joint: str, x, xdot, xddot):
    """Travel s of a prismatic joint's child point along the parent's axis, and its rates.

    s = u . (r_P - r_O): r_P the child point, r_O the parent point of the line, u the axis.
    """
    if model.joint_kind(joint) != "prismatic":
        valid = list(model.pri.names)
        raise ModelError(f"joint {joint!r} is not a prismatic joint; prismatic joints: "
                         + (", ".join(repr(v) for v in valid) or "(none)"))
    p = model.pri.names.index(joint)
    jn = model.mechanism.joints[joint]
    x, xdot, xddot = (np.asarray(v, float) for v in (x, xdot, xddot))
    rP, vP, aP = (point_position(model, x, jn.child, jn.child_point),
                  point_velocity(model, x, xdot, jn.child, jn.child_point),
                  point_acceleration(model, x, xdot, xddot, jn.child, jn.child_point))
    if jn.parent == "ground" or model.body_index(jn.parent) == model.n_bodies:
        rO = np.broadcast_to(model.pri.si[p], rP.shape)
        vO = aO = np.zeros_like(rP)
        th = w = al = np.zeros(rP.shape[:-1])
    else:
        rO = point_position(model, x, jn.parent, jn.parent_point)
        vO = point_velocity(model, x, xdot, jn.parent, jn.parent_point)
        aO = point_acceleration(model, x, xdot, xddot, jn.parent, jn.parent_point)
        k = 3 * model.body_index(jn.parent) + 2
        th, w, al = x[..., k], xdot[..., k], xddot[..., k]
    ui = model.pri.ui[p]
    u = np.stack([np.cos(th) * ui[0] - np.sin(th) * ui[1],
                  np.sin(th) * ui[0] + np.cos(th) * ui[1]], axis=-1)
    n = np.stack([-u[..., 1], u[..., 0]], axis=-1)
    d, dd, ddd = rP - rO, vP - vO, aP - aO

    def dot(a, b):
        return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]

    s = dot(u, d)
    sd = w * dot(n, d) + dot(u, dd)
    sdd = al * dot(n, d) - w**2 * dot(u, d) + 2 * w * dot(n, dd) + dot(u, ddd)
    return s, sd, sdd


def four_bar_loops(model: Model, over: str | None = None) -> list[FourBarLoop]:
    """Four-bar loops ground-crank-coupler-rocker-ground joined by revolutes only.

    The crank is the link driven by coordinate ``over`` when it drives one of the
    two grounded links of a loop; otherwise the grounded link added first.
    """
    mech = model.mechanism
    from ..mechanism.joint import Revolute

    revs = [j for j in mech.joints.values() if isinstance(j, Revolute)]
    adj: dict[str, list[tuple[str, str]]] = {}
    for j in revs:
        adj.setdefault(j.parent, []).append((j.child, j.name))
        adj.setdefault(j.child, []).append((j.parent, j.name))
    driven: set[str] = set()
    if over is not None and over in mech.coordinates:
        c = mech.coordinates[over]
        if c.kind == "angle" and c.body:
            driven.add(c.body)
        elif c.kind == "relative_angle" and c.joint in mech.joints:
            jj = mech.joints[c.joint]
            driven.update({jj.parent, jj.child} - {"ground"})
    order = {b: k for k, b in enumerate(model.body_names)}
    seen: set[frozenset] = set()
    loops = []
    for a, j0 in adj.get("ground", []):
        for c, j1 in adj.get(a, []):
            if c in ("ground", a) or j1 == j0:
                continue
            for d, j2 in adj.get(c, []):
                if d in ("ground", a, c) or j2 == j1:
                    continue
                for g, j3 in adj.get(d, []):
                    if g != "ground" or j3 == j0:
                        continue
                    key = frozenset((j0, j1, j2, j3))
                    if key in seen:
                        continue
                    seen.add(key)
                    forward = FourBarLoop(a, c, d, (j0, j1, j2, j3))
                    backward = FourBarLoop(d, c, a, (j3, j2, j1, j0))
                    if d in driven and a not in driven:
                        loops.append(backward)
                    elif a in driven or order[a] <= order[d]:
                        loops.append(forward)
                    else:
                        loops.append(backward)
    return loops


def _joint_point(model: Model, name: str, x) -> np.ndarray:
    """Ground-frame position of a revolute joint (its child point), (..., 2)."""
    jn = model.mechanism.joints[name]
    if jn.child != "ground":
        return point_position(model, x, jn.child, jn.child_point)
    return point_position(model, x, jn.parent, jn.parent_point)


def _summarize(sw: KinematicSweep) -> SweepSummary:
    m = sw.model
    k = sw.over_index
    strokes, dcs = {}, []
    n = len(sw)
    for jname in m.pri.names:
        # travel and its analog (per unit of the swept coordinate)
        s, ds, _ = _travel(m, jname, sw.x, sw.B[..., k], np.zeros_like(sw.x))
        if n == 0:
            continue
        found = []
        for i in np.flatnonzero(np.sign(ds[:-1]) * np.sign(ds[1:]) < 0):
            q_at, s_at = _refine_dead_centre(sw, jname, i)
            # a maximum where the travel rate goes from + to - along the sweep direction
            is_max = (ds[i] > 0) == (sw.values[i + 1] > sw.values[i])
            found.append((q_at, s_at, is_max))
        for i in np.flatnonzero(ds == 0.0):  # exactly on a sample: keep it if an extremum
            j0, j1 = max(i - 1, 0), min(i + 1, n - 1)
            hi, lo = s[i] >= max(s[j0], s[j1]), s[i] <= min(s[j0], s[j1])
            if hi != lo:
                found.append((float(sw.values[i]), float(s[i]), bool(hi)))
        allvals = np.concatenate([s, [f[1] for f in found]])
        strokes[jname] = float(np.max(allvals) - np.min(allvals))
        for q_at, s_at, is_max in sorted(found):
            dcs.append(DeadCentre(jname, "TDC" if is_max else "BDC", q_at, s_at))
    trans = []
    for lp in four_bar_loops(m, sw.over):
        if n == 0:
            continue
        B_ = _joint_point(m, lp.joints[1], sw.x)
        C_ = _joint_point(m, lp.joints[2], sw.x)
        D_ = _joint_point(m, lp.joints[3], sw.x)
        u, v = B_ - C_, D_ - C_
        mu = np.arctan2(np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]),
                        u[:, 0] * v[:, 0] + u[:, 1] * v[:, 1])
        i0, i1 = int(np.argmin(mu)), int(np.argmax(mu))
        trans.append(TransmissionAngle(lp, float(mu[i0]), float(sw.values[i0]),
                                       float(mu[i1]), float(sw.values[i1])))
    ext = []
    for b, p in m.named_points():
        if n == 0:
            continue
        _, v, a = sw.point(b, p)
        vn, an = np.hypot(v[:, 0], v[:, 1]), np.hypot(a[:, 0], a[:, 1])
        iv, ia = int(np.argmax(vn)), int(np.argmax(an))
        ext.append(PointExtremes(b, p, float(vn[iv]), float(sw.values[iv]), float(an[ia]),
                                 float(sw.values[ia])))
    return SweepSummary(sw.over, sw.over_is_angle, strokes, dcs, trans, ext)


def _point_state(sw: KinematicSweep, q_over: float, x_guess):
    """Solve one position on the sweep's path; returns the node (B, H along ``over``)."""
    m = sw.model
    kern = _kernel(m, m.layout(sw.stats.get("mode")))
    k = sw.over_index
    q = sw.q[0].copy()
    q[k] = q_over
    tol = 1e-13 * max(m.length_scale, 1e-3)
    x, ok, J, fac = _newton1(kern, np.asarray(x_guess, float), q, tol)
    if not ok:
        return None
    return _node(kern, x, q, k, J=J, fac=fac)


def _travel_derivs(sw, jname, node):
    s, ds, dds = _travel(sw.model, jname, node.x, node.B[:, sw.over_index], node.H)
    return float(s), float(ds), float(dds)


def _refine_dead_centre(sw: KinematicSweep, jname: str, i: int) -> tuple[float, float]:
    """Root of ds/dq between positions i and i+1 by safeguarded Newton (exact s'')."""
    k = sw.over_index
    a, b = float(sw.values[i]), float(sw.values[i + 1])
    _, fa, _ = _travel(sw.model, jname, sw.x[i], sw.B[i, :, k], np.zeros(sw.model.n_x))
    _, fb, _ = _travel(sw.model, jname, sw.x[i + 1], sw.B[i + 1, :, k],
                       np.zeros(sw.model.n_x))
    fa, fb = float(fa), float(fb)
    q = a - fa * (b - a) / (fb - fa)
    lo, hi, flo = a, b, fa
    s_at = np.nan
    xg = sw.x[i] if abs(q - a) <= abs(q - b) else sw.x[i + 1]
    for _ in range(60):
        node = _point_state(sw, q, xg)
        if node is None:
            break
        xg = node.x
        s_at, f, fp = _travel_derivs(sw, jname, node)
        if f == 0.0:
            break
        if np.sign(f) == np.sign(flo):
            lo, flo = q, f
        else:
            hi = q
        qn = q - f / fp if fp != 0 else np.nan
        if not (min(lo, hi) < qn < max(lo, hi)):
            qn = 0.5 * (lo + hi)
        if abs(qn - q) <= 1e-14 * max(1.0, abs(q)):
            q = qn
            break
        q = qn
    node = _point_state(sw, q, xg)
    if node is not None:
        s_at = _travel_derivs(sw, jname, node)[0]
    return float(q), float(s_at)


# ====================================================================== analyses


def initial_coordinates(model: Model, x0=None) -> np.ndarray:
    """Initial coordinates of a model, shape (n_q,) (rad or m).

    Those given in ``mechanism.extras["initial"]["q"]`` (a mapping name -> value, as
    the model-file loader stores them, or a sequence of n_q values); the others
    measured on the pose ``x0`` (default the assembled sketch ``model.x0``).
    """
    if x0 is None:
        x0 = getattr(model, "x0", None)
        if x0 is None:
            x0 = assemble(model)
    q0 = coordinates(model, np.asarray(x0, float))
    init = (model.mechanism.extras or {}).get("initial", {})
    given = init.get("q") if isinstance(init, Mapping) else None
    if given is None:
        return q0
    q = q0.copy()
    if isinstance(given, Mapping):
        for name, v in given.items():
            q[model.coordinate_index(name)] = float(v)
    else:
        arr = np.asarray(given, float).reshape(-1)
        if arr.shape != (model.n_q,):
            raise ModelError(f"initial q must list {model.n_q} value(s) "
                             f"({', '.join(model.coordinate_names)}), got {given!r}")
        q = arr
    return q


def _rates(model: Model, k: int, speed) -> np.ndarray:
    qdot = np.zeros(model.n_q)
    if speed is None:
        qdot[k] = 1.0
    elif isinstance(speed, Mapping):
        qdot[k] = 1.0
        for name, v in speed.items():
            if name not in model.coordinate_names:
                raise ModelError("speed: " + did_you_mean(name, model.coordinate_names,
                                                          "coordinate"))
            qdot[model.coordinate_index(name)] = float(v)
    else:
        qdot[k] = float(speed)
    if not np.all(np.isfinite(qdot)):
        raise ModelError(f"speed must be finite, got {speed!r}")
    return qdot


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


def _kernel(model: Model, layout) -> Kernel:
    """The evaluation kernel of a model in a mode, cached on the model itself (so that
    it goes away with the model)."""
    per = model.__dict__.setdefault("_sweep_kernels", {})
    kern = per.get(layout.mode)
    if kern is None:
        kern = per[layout.mode] = Kernel(model, layout)
    return kern


def sweep(mech_or_model, over: str | None = None, values=None, *, speed=None, x_start=None,
          mode=None, max_step: float | None = None, min_step: float | None = None,
          tol: float | None = None) -> KinematicSweep:
    """Positions, velocities and accelerations of a mechanism over one coordinate.

    Parameters
    ----------
    mech_or_model : Mechanism or Model
    over : str, optional
        Name of the coordinate to sweep; default the only coordinate.  The other
        coordinates stay at their initial values (``mechanism.extras["initial"]["q"]``
        if given, else measured on the assembled sketch).
    values : array_like, shape (n,), optional
        Values of the swept coordinate, rad (angles) or m (travels), visited in this
        order.  Default for an angle: a full turn from its assembled value in 1 deg
        steps (361 values).  Required for a travel coordinate.
    speed : float or mapping of str to float, optional
        Constant rate of the swept coordinate (rad/s or m/s); default 1, so that the
        velocities are the velocity analogs and the accelerations are the second-order
        analogs (per unit rate squared).  A mapping gives rates for any coordinates
        (missing ones: 0; the swept one: 1 unless given).
    x_start : array_like, shape (n_x,), optional
        Pose to start the continuation from (chooses the assembly branch; the other
        coordinates are then measured on it); default the assembled sketch ``model.x0``.
    mode : iterable of str, optional
        Engaged locks (default: the model's initial mode).
    max_step : float, optional
        Largest step of the sequential coarse continuation, rad (default 5 deg) or m
        (default 5 % of the model's length scale).
    min_step : float, optional
        Step below which the continuation gives up and reports a dead position
        (default 1e-11 rad, or 1e-11 times the length scale in m).
    tol : float, optional
        Residual tolerance of the position solve, m (default 1e-13 x length scale).

    Returns
    -------
    KinematicSweep
        ``status`` is ``"success"``, or ``"dead-position"`` when a dead or toggle
        position stopped the sweep (the positions computed before it are kept).

    Raises
    ------
    ModelError
        Unknown coordinate name, bad values.
    AssemblyError
        The mechanism cannot be assembled at the start of the sweep.
    """
    t_start = time.perf_counter()
    model = as_model(mech_or_model)
    if model.n_q == 0:
        raise ModelError("the mechanism has no coordinates to sweep")
    if over is None:
        if model.n_q != 1:
            raise ModelError("the mechanism has several coordinates; choose one with over=: "
                             + ", ".join(repr(c) for c in model.coordinate_names))
        over = model.coordinate_names[0]
    k = model.coordinate_index(over)
    is_angle = bool(model.coord_is_angle[k])
    lay = model.layout(mode)
    kern = _kernel(model, lay)
    L = model.length_scale
    if tol is None:
        tol = 1e-13 * max(L, 1e-3)
    if max_step is None:
        max_step = DEFAULT_MAX_STEP if is_angle else 0.05 * L
    if min_step is None:
        min_step = DEFAULT_MIN_STEP if is_angle else DEFAULT_MIN_STEP * L

    # ---- start pose and coordinates
    if x_start is None:
        x0 = getattr(model, "x0", None)
        if x0 is None or (mode is not None and lay.mode != model.initial_mode):
            x0 = assemble(model, layout=lay)
        q_init = initial_coordinates(model, x0)
    else:
        x0 = np.asarray(x_start, float).reshape(model.n_x)
        q_init = coordinates(model, x0)
    x_init, ok, J0, fac0 = _newton1(kern, x0, q_init, tol)
    if not ok:
        x_init = assemble(model, q_init, x_guess=x0, layout=lay)
        J0 = fac0 = None
    start = _node(kern, x_init, q_init, k, J=J0, fac=fac0)

    if values is None:
        if not is_angle:
            raise ModelError(f"coordinate {over!r} is a travel (m): give the values to sweep")
        values = q_init[k] + np.linspace(0.0, 2 * np.pi, 361)
    values = np.asarray(values, dtype=float).reshape(-1)
    if values.size == 0 or not np.all(np.isfinite(values)):
        raise ModelError(f"values of {over!r} must be a non-empty sequence of finite numbers")
    n_req = values.size
    qdot_c = _rates(model, k, speed)

    counter: dict = {}
    t_coarse = time.perf_counter()
    # ---- 1. coarse continuation through the anchors
    anchors = _anchor_indices(values, max_step)
    anodes, stop = _march(kern, start, k, values[anchors], max_step=max_step,
                          min_step=min_step, tol=tol, counter=counter)
    n_anch = len(anodes)

    t_coarse = time.perf_counter() - t_coarse
    # ---- 2. batched solve of every value between solved anchors
    n_ok = int(anchors[n_anch - 1]) + 1 if n_anch else 0
    Q = np.broadcast_to(q_init, (n_ok, model.n_q)).copy()
    Q[:, k] = values[:n_ok]
    X = np.empty((n_ok, model.n_x))
    F = J = fac = None
    fallback = 0
    if n_anch == 1:
        X[:] = anodes[0].x
        F, J = kern.system(X, Q)
        fac = kern.factor(J)
    elif n_anch > 1:
        a_idx = anchors[:n_anch]
        seg = np.clip(np.searchsorted(a_idx, np.arange(n_ok), side="right") - 1, 0, n_anch - 2)
        xa = np.array([nd.x for nd in anodes])
        da = np.array([nd.B[:, k] for nd in anodes])
        aa = np.array([nd.H for nd in anodes])
        sg = np.array([nd.sign for nd in anodes])
        qa = values[a_idx]
        h = (qa[seg + 1] - qa[seg])[:, None]
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.where(h != 0, (values[:n_ok, None] - qa[seg, None]) / h, 0.0)
        xp = _hermite5(t, h, xa[seg], da[seg], aa[seg], xa[seg + 1], da[seg + 1], aa[seg + 1])
        X, F, J, ok_f = _polish(kern, xp, Q, tol)
        fac = kern.factor(J)
        sgn = fac.sign if fac is not None else kern.sign(J)
        near = np.max(np.abs((X - xp) * kern.col_scale), axis=1) <= 1e-3 * L
        ok_f &= (sgn == sg[seg]) & near
        bad_segments = np.unique(seg[~ok_f])
        for m_ in bad_segments:  # re-solve those segments point by point
            fallback += 1
            i0, i1 = a_idx[m_], a_idx[m_ + 1]
            nodes, st = _march(kern, anodes[m_], k, values[i0 + 1:i1 + 1],
                               max_step=max_step, min_step=min_step, tol=tol, counter=counter)
            for r, nd in enumerate(nodes):
                X[i0 + 1 + r] = nd.x
            if st is not None:  # only if a singular position lies between two anchors
                stop = st
                n_ok = i0 + 1 + len(nodes)
                X, Q = X[:n_ok], Q[:n_ok]
                anodes, n_anch = anodes[:m_ + 1], -1
                break
        if bad_segments.size:
            F, J = kern.system(X, Q)
            fac = kern.factor(J)

    # ---- 3. past the last anchor: go on point by point up to the dead position
    if stop is not None and n_anch >= 0 and n_ok < n_req:
        last = anodes[-1] if n_anch else start
        nxt = anchors[n_anch] if n_anch < len(anchors) else n_req - 1
        nodes, stop = _march(kern, last, k, values[n_ok:nxt + 1], max_step=max_step,
                             min_step=min_step, tol=tol, counter=counter, prev=None)
        if stop is None:  # cannot happen: the anchor itself was unreachable
            stop = _Stop(nodes[-1], nodes[-1].q, "the continuation could not reach "
                         f"{over} = {values[nxt]:.9g}")
        if nodes:
            Xn = np.array([nd.x for nd in nodes])
            Qn = np.broadcast_to(q_init, (len(nodes), model.n_q)).copy()
            Qn[:, k] = values[n_ok:n_ok + len(nodes)]
            X, Q = np.concatenate([X, Xn]), np.concatenate([Q, Qn])
            n_ok += len(nodes)
            F, J = kern.system(X, Q)
            fac = kern.factor(J)

    # ---- 4. velocities and accelerations in one batch
    N = n_ok
    qdot = np.broadcast_to(qdot_c, (N, model.n_q)).copy()
    qddot = np.zeros((N, model.n_q))
    if N:
        rhs = np.concatenate([F[..., None], kern.rhs_unit(N)], axis=-1)
        sol = kern.apply(J, fac, rhs)
        X = X - sol[:, :, 0]  # a last Newton correction, at round-off level
        B = sol[:, :, 1:]
        xdot = np.einsum("nij,nj->ni", B, qdot)
        xddot = kern.apply(J, fac, kern.gamma(X, xdot)[..., None])[..., 0]
    else:
        B = np.empty((0, model.n_x, model.n_q))
        xdot = xddot = np.empty((0, model.n_x))

    status, message, events, error = "success", "", (), None
    if stop is not None:
        status = "dead-position"
        error, event = _dead_report(model, lay, k, stop, N, n_req)
        message = str(error)
        events = (event,)
    elapsed = time.perf_counter() - t_start
    stats = {"n_points": int(N), "n_requested": int(n_req), "anchors": int(len(anchors)),
             "coarse_steps": int(counter.get("coarse_steps", 0)),
             "rejected_steps": int(counter.get("rejected_steps", 0)),
             "fallback_segments": int(fallback), "time_s": elapsed,
             "time_coarse_s": t_coarse,
             "positions_per_s": N / elapsed if elapsed > 0 else np.inf,
             "mode": tuple(sorted(lay.mode))}
    return KinematicSweep(
        over=over, values=_ro(values[:N].copy()), q=_ro(Q), qdot=_ro(qdot), qddot=_ro(qddot),
        x=_ro(X), xdot=_ro(xdot), xddot=_ro(xddot), B=_ro(B), status=status, message=message,
        stats=stats, events=events, error=error, model=model)


def _dead_report(model, lay, k, stop: _Stop, n_done, n_req):
    """SingularPositionError and event describing where the continuation stopped."""
    name = model.coordinate_names[k]
    q_last = float(stop.node.q[k])
    is_angle = bool(model.coord_is_angle[k])
    where = (f"{name} = {np.rad2deg(q_last):.6f} deg ({q_last:.9g} rad)" if is_angle
             else f"{name} = {q_last * 1e3:.6f} mm")
    direction = "beyond" if stop.q_try[k] > q_last else "below"
    try:
        rep = singularity(model, stop.node.x, lay)
    except (np.linalg.LinAlgError, ValueError):
        rep = {"rcond": np.nan, "sigma_min": np.nan, "coordinates": [], "joints": []}
    joints = ", ".join(repr(j) for j in rep["joints"]) or "-"
    msg = (f"dead position at {where}: the mechanism cannot be driven {direction} it by "
           f"{name!r} ({stop.reason}; sigma_min/sigma_max = {rep['rcond']:.2e}, joints "
           f"{joints} become dependent); {n_done} of {n_req} positions computed")
    err = SingularPositionError(msg, q=stop.node.q, sigma_min=rep["sigma_min"],
                                coordinates=[name], joints=rep["joints"])
    event = {"kind": "dead-position", "coordinate": name, "at": q_last, "index": n_done - 1,
             "q": stop.node.q.copy(), "rcond": rep["rcond"], "joints": list(rep["joints"]),
             "reason": stop.reason}
    return err, event


def analyze(mech_or_model, q, qdot, qddot=None, x_guess=None, *, mode=None) -> KinematicPoint:
    """Positions, velocities and accelerations at one set of coordinates.

    Parameters
    ----------
    mech_or_model : Mechanism or Model
    q, qdot : array_like, shape (n_q,)
        Coordinates (rad or m) and their rates (rad/s or m/s).
    qddot : array_like, shape (n_q,), optional
        Accelerations of the coordinates (default zero).
    x_guess : array_like, shape (n_x,), optional
        Starting pose for Newton (chooses the branch); default the assembled sketch.

    Returns
    -------
    KinematicPoint
    """
    model = as_model(mech_or_model)
    lay = model.layout(mode)
    kern = _kernel(model, lay)
    q = np.asarray(q, float).reshape(model.n_q)
    qdot = np.asarray(qdot, float).reshape(model.n_q)
    qddot = np.zeros(model.n_q) if qddot is None else np.asarray(qddot, float).reshape(
        model.n_q)
    if x_guess is None:
        x_guess = getattr(model, "x0", None)
        if x_guess is None:
            x_guess = assemble(model, layout=lay)
    tol = 1e-13 * max(model.length_scale, 1e-3)
    x, ok, _, J = _newton(kern, np.asarray(x_guess, float)[None], q[None], tol)
    if not ok[0]:
        x = assemble(model, q, x_guess=x_guess, layout=lay)[None]
        _, J = kern.system(x, q[None])
    B = kern.solve(J, kern.rhs_unit(1))[0]
    xdot = B @ qdot
    xddot = B @ qddot + kern.solve(J, kern.gamma(x, xdot[None])[..., None])[0, :, 0]
    return KinematicPoint(q=_ro(q.copy()), qdot=_ro(qdot.copy()), qddot=_ro(qddot.copy()),
                          x=_ro(x[0]), xdot=_ro(xdot), xddot=_ro(xddot), B=_ro(B), model=model)


