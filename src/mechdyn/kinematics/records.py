"""Records of the kinematic analyses: :class:`KinematicSweep` and :class:`KinematicPoint`.

Read-only arrays of positions, velocities, accelerations and velocity analogs,
with point and body accessors and :meth:`KinematicSweep.to_dataframe`; the derived
figures of :meth:`KinematicSweep.summary` are in :mod:`mechdyn.kinematics.figures`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model import Model
from .constraints import _point_kinematics
from .figures import SweepSummary, _summarize, _travel

__all__ = ["KinematicSweep", "KinematicPoint"]


def _ro(a):
    a = np.asarray(a)
    a.flags.writeable = False
    return a


def _unit_of(model: Model, c: int) -> str:
    return "rad" if model.coord_is_angle[c] else "m"


@dataclass(frozen=True)
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

    def point(self, body: str, name) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position (m), velocity (m/s) and acceleration (m/s^2) of a body point, each (2,)."""
        return _point_kinematics(self.model, self.x, self.xdot, self.xddot, body, name)

    def angular(self, body: str) -> tuple[float, float, float]:
        """Angle (rad), angular velocity (rad/s) and acceleration (rad/s^2) of a body."""
        k = 3 * self.model.body_index(body) + 2
        return float(self.x[k]), float(self.xdot[k]), float(self.xddot[k])


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
    status : Status
        ``"success"`` or ``"singular-position"``
        ``"singular-position"``: the sweep stopped at a dead or toggle position; the
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
        return _point_kinematics(self.model, self.x, self.xdot, self.xddot, body, name)

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
