"""Records of the kinematic analyses: :class:`KinematicSweep` and :class:`KinematicPoint`.

Read-only arrays of positions, velocities, accelerations and velocity analogs, and the
derived figures of :meth:`KinematicSweep.summary` (:class:`SweepSummary`): stroke and
dead centres (TDC/BDC, refined on the exact travel rate) of every slider, range of the
transmission angle of every four-bar loop and the largest speed and acceleration of
every named point.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from functools import partial

import numpy as np

from ..brief import brief, number, span, status_text
from ..fieldmap import FieldMapping
from ..kernels import rows_numpy
from ..kernels.planar import cross
from ..mechanism.joint import Revolute
from ..model import Model
from ..model.constraints import point_kinematics, point_position, point_velocity, travel_rows
from .assembly import position_tol
from .continuation import path_newton, path_node, sweep_kernel

__all__ = ["SweepStats", "KinematicSweep", "KinematicPoint", "SweepSummary", "DeadCentre",
           "TransmissionAngle", "PointExtremes", "FourBarLoop", "four_bar_loops"]


def _ro(a):
    a = np.asarray(a)
    a.flags.writeable = False
    return a


@dataclass(frozen=True, repr=False)
class KinematicPoint:
    """Kinematics of one position (see :func:`~mechdyn.kinematics.sweep.analyze`).

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

    def __repr__(self) -> str:
        names = self.model.coordinate_names if self.model is not None else ()
        at = ", ".join(f"{n} = {number(v)}" for n, v in zip(names[:4], self.q, strict=False))
        return brief(self, at, f"{self.q.size} coordinates, {self.x.size // 3} bodies")

    def point(self, body: str, name) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position (m), velocity (m/s) and acceleration (m/s^2) of a body point, each (2,)."""
        return point_kinematics(self.model, self.x, self.xdot, self.xddot, body, name)

    def angular(self, body: str) -> tuple[float, float, float]:
        """Angle (rad), angular velocity (rad/s) and acceleration (rad/s^2) of a body."""
        k = 3 * self.model.body_index(body) + 2
        return float(self.x[k]), float(self.xdot[k]), float(self.xddot[k])


@dataclass(frozen=True)
class SweepStats(FieldMapping):
    """The counts and timings of a kinematic sweep (``KinematicSweep.stats``).

    Typed like the stats of every record (:mod:`mechdyn.results.records`, which
    re-exports it: it lives here, below the results, with the sweep); every field also
    reads as a key (``stats["n_points"]``).

    Attributes
    ----------
    n_points : int
        Positions solved and kept.
    n_requested : int
        Positions requested.
    anchors : int
        Positions the path was anchored at (solved from the initial guess).
    coarse_steps : int
        Accepted steps of the continuation along the path.
    rejected_steps : int
        Rejected steps of the continuation.
    fallback_segments : int
        Segments the continuation had to redo with small steps.
    time_s : float
        Wall time of the sweep, s.
    time_coarse_s : float
        Wall time of the continuation, s.
    positions_per_s : float
        ``n_points / time_s``, 1/s.
    bifurcations : list of dict
        The bifurcation positions the sweep went through on its branch (``at``, the
        swept coordinate there, rad or m; ``kind``).
    mode : tuple of str
        The locks engaged during the sweep.

    Examples
    --------
    >>> s = SweepStats(n_points=3, n_requested=3, anchors=1, coarse_steps=2,
    ...                rejected_steps=0, fallback_segments=0, time_s=0.5,
    ...                time_coarse_s=0.25, positions_per_s=6.0)
    >>> s.n_points, s["positions_per_s"], s.bifurcations
    (3, 6.0, [])
    """

    n_points: int
    n_requested: int
    anchors: int
    coarse_steps: int
    rejected_steps: int
    fallback_segments: int
    time_s: float
    time_coarse_s: float
    positions_per_s: float
    bifurcations: list = field(default_factory=list)
    mode: tuple = ()


@dataclass(frozen=True, repr=False)
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
    status : Status
        ``"success"``, or ``"singular-position"``: the sweep stopped at a dead or toggle
        position; the positions before it are kept and ``message`` says where.
    message : str
    stats : SweepStats
        Counts and timings (:class:`SweepStats`: ``n_points``, ``n_requested``,
        ``coarse_steps``, ``fallback_segments``, ``time_s``, ``positions_per_s`` ...);
        also read as the mapping it used to be (``stats["n_points"]``).
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
    stats: SweepStats
    events: tuple = ()
    error: Exception | None = field(default=None, repr=False, compare=False)
    model: Model = field(default=None, repr=False, compare=False)

    def __repr__(self) -> str:
        n_req = getattr(self.stats, "n_requested", None)
        of = f" of {n_req}" if n_req is not None and n_req != len(self) else ""
        unit = "rad" if self.model is None or self.over_is_angle else "m"
        return brief(self, f"{len(self)}{of} positions over {self.over!r}",
                     span(self.values, unit) if len(self) else "",
                     f"{self.q.shape[-1]} coordinates, {self.x.shape[-1] // 3} bodies",
                     status_text(self))

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
        return point_kinematics(self.model, self.x, self.xdot, self.xddot, body, name)

    def point_analogs(self, body: str, name) -> np.ndarray:
        """Velocity analogs dr/dq of a body point, shape (n, 2, n_q) (m/rad or m/m)."""
        # the point's velocity per unit rate of each coordinate (linear in xdot)
        v = point_velocity(self.model, self.x, np.moveaxis(self.B, -1, 0), body, name)
        return np.moveaxis(v, 0, -1)

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
        units = ["rad" if a else "m" for a in m.coord_is_angle]
        per = ["" if a else "_m" for a in m.coord_is_angle]  # analogs: per m is written
        for c, (name, u) in enumerate(zip(names, units, strict=True)):
            cols[f"{name}_{u}"] = self.q[:, c]
            if name == self.over and u == "rad":
                cols[f"{name}_deg"] = np.rad2deg(self.q[:, c])
        for c, (name, u) in enumerate(zip(names, units, strict=True)):
            cols[f"{name}_dot_{u}_s"] = self.qdot[:, c]
            cols[f"{name}_ddot_{u}_s2"] = self.qddot[:, c]
        for b in m.body_names:
            cols.update(zip((f"theta_{b}_rad", f"omega_{b}_rad_s", f"alpha_{b}_rad_s2"),
                            self.angular(b), strict=True))
            k = 3 * m.body_index(b) + 2
            for c, name in enumerate(names):
                cols[f"dtheta_{b}_d{name}_rad{per[c]}"] = self.B[:, k, c]
        for b, p in m.named_points():
            r, v, a = self.point(b, p)
            dr = self.point_analogs(b, p)
            tag = f"{b}_{p}"
            for pre, arr, unit in (("", r, "m"), ("v", v, "m_s"), ("a", a, "m_s2")):
                cols[f"{pre}x_{tag}_{unit}"], cols[f"{pre}y_{tag}_{unit}"] = arr[:, 0], arr[:, 1]
            for c, name in enumerate(names):
                cols[f"dx_{tag}_d{name}_m{per[c]}"] = dr[:, 0, c]
                cols[f"dy_{tag}_d{name}_m{per[c]}"] = dr[:, 1, c]
        return pd.DataFrame(cols)

    # ------------------------------------------------------------------ summary
    def summary(self) -> SweepSummary:
        """Strokes and dead centres of the sliders, transmission angles of the four-bar
        loops, and the extreme speed and acceleration of every named point."""
        return _summarize(self)


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


@dataclass(frozen=True, repr=False)
class SweepSummary:
    """Derived figures of a :class:`~mechdyn.kinematics.records.KinematicSweep`.

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

    def __repr__(self) -> str:
        strokes = ", ".join(f"{j} {number(s, 'm')}" for j, s in list(self.strokes.items())[:3])
        return brief(self, f"over {self.over!r}", f"stroke {strokes}" if strokes else "",
                     f"{len(self.dead_centres)} dead centres",
                     f"{len(self.transmission)} transmission angles",
                     f"{len(self.extremes)} points", model="")

    def as_dict(self) -> dict:
        """Plain nested dict (for JSON)."""
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

        out = [f"stroke of slider {j!r}: {s * 1e3:.6g} mm" for j, s in self.strokes.items()]
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


def _travel(model: Model, joint: str, x, xdot, xddot):
    """Travel s of a prismatic joint's child point along the parent's axis, and its rates.

    s = u . (r_P - r_O) (the joint's travel row, :func:`~.constraints.travel_rows`),
    s' = s_x xdot and s'' = s_x xddot + quad, at poses x (..., n_x); each (...,), in m,
    m/s and m/s^2 (or per unit and per unit squared of a coordinate for analogs).
    """
    xdot, xddot = np.asarray(xdot, float), np.asarray(xddot, float)
    s, s_x, quad = rows_numpy.evaluate(travel_rows(model, joint), x, xdot)
    s_x = s_x[..., 0, :]
    return s[..., 0], np.sum(s_x * xdot, axis=-1), np.sum(s_x * xddot, axis=-1) + quad[..., 0]


def four_bar_loops(model: Model, over: str | None = None) -> list[FourBarLoop]:
    """Four-bar loops ground-crank-coupler-rocker-ground joined by revolutes only.

    The crank is the link driven by coordinate ``over`` when it drives one of the
    two grounded links of a loop; otherwise the grounded link added first.
    """
    mech = model.mechanism

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
                    forward = a in driven or (d not in driven and order[a] <= order[d])
                    loops.append(FourBarLoop(a, c, d, (j0, j1, j2, j3)) if forward
                                 else FourBarLoop(d, c, a, (j3, j2, j1, j0)))
    return loops


def _joint_point(model: Model, name: str, x) -> np.ndarray:
    """Ground-frame position of a revolute joint (its child point), (..., 2)."""
    jn = model.mechanism.joints[name]
    if jn.child != "ground":
        return point_position(model, x, jn.child, jn.child_point)
    return point_position(model, x, jn.parent, jn.parent_point)


def _summarize(sw: KinematicSweep) -> SweepSummary:
    m, k, n = sw.model, sw.over_index, len(sw)
    strokes, dcs, trans, ext = {}, [], [], []
    if n == 0:
        return SweepSummary(sw.over, sw.over_is_angle, strokes, dcs, trans, ext)
    for jname in m.pri.names:
        # travel and its analog (per unit of the swept coordinate)
        s, ds, _ = _travel(m, jname, sw.x, sw.B[..., k], np.zeros_like(sw.x))
        found = []
        for i in np.flatnonzero(np.sign(ds[:-1]) * np.sign(ds[1:]) < 0):
            # a maximum where the travel rate goes from + to - along the sweep direction
            is_max = (ds[i] > 0) == (sw.values[i + 1] > sw.values[i])
            found.append((*refine_root(sw, i, partial(_travel, m, jname)), is_max))
        for i in np.flatnonzero(ds == 0.0):  # exactly on a sample: keep it if an extremum
            j0, j1 = max(i - 1, 0), min(i + 1, n - 1)
            hi, lo = s[i] >= max(s[j0], s[j1]), s[i] <= min(s[j0], s[j1])
            if hi != lo:
                found.append((float(sw.values[i]), float(s[i]), bool(hi)))
        strokes[jname] = float(np.ptp(np.concatenate([s, [f[1] for f in found]])))
        dcs.extend(DeadCentre(jname, "TDC" if is_max else "BDC", q_at, s_at)
                   for q_at, s_at, is_max in sorted(found))
    for lp in four_bar_loops(m, sw.over):
        B_, C_, D_ = (_joint_point(m, j, sw.x) for j in lp.joints[1:])
        u, v = B_ - C_, D_ - C_
        mu = np.arctan2(np.abs(cross(u, v)),
                        u[:, 0] * v[:, 0] + u[:, 1] * v[:, 1])
        i0, i1 = int(np.argmin(mu)), int(np.argmax(mu))
        trans.append(TransmissionAngle(lp, float(mu[i0]), float(sw.values[i0]),
                                       float(mu[i1]), float(sw.values[i1])))
    for b, p in m.named_points():
        _, v, a = sw.point(b, p)
        vn, an = np.hypot(v[:, 0], v[:, 1]), np.hypot(a[:, 0], a[:, 1])
        iv, ia = int(np.argmax(vn)), int(np.argmax(an))
        ext.append(PointExtremes(b, p, float(vn[iv]), float(sw.values[iv]), float(an[ia]),
                                 float(sw.values[ia])))
    return SweepSummary(sw.over, sw.over_is_angle, strokes, dcs, trans, ext)


def refine_root(sw: KinematicSweep, i: int, quantity) -> tuple[float, float]:
    """Root of the exact rate of a quantity along the swept coordinate between positions
    i and i+1 (Brent's method, each position solved from the last): ``quantity(x, x', x'')``
    gives the value and its first derivative (a travel, a point coordinate); returns
    (q there, value there)."""
    m, k = sw.model, sw.over_index
    kern = sweep_kernel(m, m.layout(sw.stats.mode))
    tol = position_tol(m)
    last = {"x": sw.x[i], "s": np.nan}

    def rate(q_over):
        q = sw.q[0].copy()
        q[k] = q_over
        x, ok, _, J = path_newton(kern, np.array(last["x"], dtype=float), q, tol)
        if not ok:
            raise ArithmeticError(f"no position at {sw.over} = {q_over!r}")
        node = path_node(kern, x, q, k, J=J)
        last["x"] = x
        s, ds = quantity(x, node.B[:, k], node.H)[:2]
        last["s"] = float(s)
        return float(ds)

    from scipy.optimize import brentq
    a, b = float(sw.values[i]), float(sw.values[i + 1])
    try:
        q = brentq(rate, min(a, b), max(a, b), xtol=1e-15, rtol=4 * np.finfo(float).eps)
        rate(q)
    except (ArithmeticError, ValueError):  # no solved root: interpolate the sampled rates
        fa = quantity(sw.x[i], sw.B[i, :, k], np.zeros(m.n_x))[1]
        fb = quantity(sw.x[i + 1], sw.B[i + 1, :, k], np.zeros(m.n_x))[1]
        q = a - fa * (b - a) / (fb - fa)
    return float(q), last["s"]
