"""The record of a dynamic simulation: :class:`Trajectory`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..brief import brief, number, span, status_text
from ..errors import ModelError, did_you_mean
from ..kinematics.analogs import accelerations
from ..model.constraints import point_acceleration, point_position, point_velocity
from .records import RunStats, SwitchedSamples
from .table import coordinate_columns, force_columns, mode_columns

__all__ = ["Trajectory", "SwitchedSamples"]

#: statuses of a run that reached its end (or a terminal event)
SUCCESS_STATUSES = ("success", "event")


@dataclass(frozen=True, repr=False)
class Trajectory:
    """Samples of a simulated motion, time-major.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Times, s.
    q, qdot, qddot : ndarray, shape (n, n_q)
        Generalized coordinates (rad or m), rates and accelerations.
    x : ndarray, shape (n, n_x)
        Body poses (x, y in m, theta in rad per body, in ``body_names`` order).
    xdot : ndarray, shape (n, n_x)
        Body frame velocities (m/s, rad/s).
    status : str
        ``"success"``, ``"event"`` (a terminal event ended the run), or why the run
        stopped early: ``"singular-position"``, ``"assembly-failed"``,
        ``"singular-mass-matrix"``, ``"non-finite"``, ``"failed"``.
    message : str
        What happened, with the time and the coordinates when the run stopped early.
    events : list of EventRecord
        Occurrences of the requested events, in time order.
    stats : RunStats
        The run's counters and settings (:class:`~mechdyn.results.records.RunStats`:
        ``steps``, ``rejected``, ``evaluations``, ``wall_time_s``, ``integrator``,
        ``formulation``, ``backend``, the tolerances; ``segments``, ``bifurcations``;
        ``variable_structure``, a :class:`SwitchedSamples`, see :attr:`switching`; for a
        run handed to a sink without keeping its samples (``simulate(sink=...,
        keep=False)``, which holds the last chunk) ``streamed``, a
        :class:`~mechdyn.results.records.StreamedStats`).  It also reads as the mapping
        it used to be: ``stats["steps"]``.
    energy : dict or None
        Arrays of shape (n,): ``kinetic`` T, ``potential`` U, ``work_nc`` (work of
        the non-conservative forces since t0: drives, applied forces and torques,
        dampers), all in J; ``balance`` = T + U - W_nc (constant for exact
        dynamics); ``residual``, the largest constraint residual (m or rad); with
        friction in the pairs ``work_friction`` (the energy they dissipated since t0,
        J, included in ``work_nc``) and ``power_friction`` (the power they dissipate,
        W, >= 0).
    coordinate_names, body_names : tuple of str
    coordinate_is_angle : tuple of bool
    model : Model or None
        The compiled model (for point positions in :meth:`to_dataframe`).
    """

    t: np.ndarray
    q: np.ndarray
    qdot: np.ndarray
    qddot: np.ndarray
    x: np.ndarray
    xdot: np.ndarray
    status: str = "success"
    message: str = ""
    events: list = field(default_factory=list)
    stats: RunStats = field(default_factory=RunStats)
    energy: dict | None = None
    coordinate_names: tuple = ()
    body_names: tuple = ()
    coordinate_is_angle: tuple = ()
    model: object = field(default=None, repr=False, compare=False)

    def __repr__(self) -> str:
        s = self.stats
        rows = s.streamed.rows if s.streamed is not None else self.n_samples
        first = s.streamed.t_first if s.streamed is not None else self.t[:1]
        times = span([*np.ravel(first), self.t[-1]], "s") if self.t.size else ""
        drift = self.energy_drift()
        return brief(self, f"{rows} samples" + (f", t = {times}" if times else ""),
                     f"{len(self.coordinate_names)} coordinates, {len(self.body_names)} bodies",
                     status_text(self), f"integrator {s.integrator!r}" if s.integrator else "",
                     f"energy drift {number(drift, 'J')}" if drift == drift else "",
                     f"{len(self.events)} events" if self.events else "")

    @property
    def success(self) -> bool:
        """True when the run reached ``t_end`` (or a terminal event)."""
        return self.status in SUCCESS_STATUSES

    @property
    def n_samples(self) -> int:
        return int(self.t.shape[0])

    def coordinate(self, name: str) -> np.ndarray:
        """Samples (n,) of one coordinate (rad or m)."""
        return self.q[:, self._ci(name)]

    def rate(self, name: str) -> np.ndarray:
        """Samples (n,) of one coordinate's rate."""
        return self.qdot[:, self._ci(name)]

    def acceleration(self, name: str) -> np.ndarray:
        """Samples (n,) of one coordinate's acceleration."""
        return self.qddot[:, self._ci(name)]

    def _ci(self, name):
        try:
            return self.coordinate_names.index(name)
        except ValueError:
            raise ModelError(did_you_mean(name, self.coordinate_names, "coordinate")) from None

    def energy_drift(self) -> float:
        """Largest |balance - balance[0]| over the run, J (NaN without energy)."""
        if self.stats.streamed is not None:  # a run handed to a sink, of which this is the end
            return float(self.stats.streamed.energy_drift)
        if not self.energy or self.t.size == 0:
            return float("nan")
        b = self.energy["balance"]
        return float(np.max(np.abs(b - b[0])))

    def summary(self) -> str:
        """Multi-line text: status, counters and the energy balance."""
        lines = [f"status: {self.status}" + (f" - {self.message}" if self.message else "")]
        s = self.stats
        if s.integrator:
            wall = float("nan") if s.wall_time_s is None else s.wall_time_s
            lines.append(
                f"integrator {s.integrator} ({s.formulation}, backend {s.backend}): "
                f"{s.steps} steps, {s.evaluations} evaluations, wall time {wall:.4g} s")
        streamed = s.streamed
        if streamed is not None:
            lines.append(f"samples: {streamed.rows} (streamed), t = "
                         f"{streamed.t_first:.6g} .. {self.t[-1]:.6g} s")
        elif self.t.size:
            lines.append(f"samples: {self.t.size}, t = {self.t[0]:.6g} .. {self.t[-1]:.6g} s")
        bif = s.bifurcations
        if bif:
            unit = " rad" if self.coordinate_is_angle[0] else " m"
            lines.append(f"went through {len(bif)} bifurcation position(s) on its branch, at "
                         f"{self.coordinate_names[0]} = "
                         + ", ".join(f"{b['at']:.6g}" for b in bif[:6])
                         + (" ..." if len(bif) > 6 else "") + unit)
        if self.energy and self.t.size:
            e = self.energy
            lines.append(
                f"energy at the end: T = {e['kinetic'][-1]:.9g} J, U = {e['potential'][-1]:.9g}"
                f" J, W_nc = {e['work_nc'][-1]:.9g} J; balance T + U - W_nc drifts by "
                f"{self.energy_drift():.3e} J; largest constraint residual "
                f"{streamed.residual if streamed is not None else np.max(e['residual']):.3e}")
        return "\n".join(lines)

    # ------------------------------------------------------------------ tables
    def to_dataframe(self, points: bool = False, energy: bool = True, bodies: bool = True,
                     degrees: bool = True):
        """A pandas DataFrame, one row per sample, columns with unit suffixes.

        Parameters
        ----------
        points : bool
            Add position, velocity and acceleration of every named body point
            (``x_rod_B_m``, ``vx_rod_B_m_s``, ``ax_rod_B_m_s2`` ...).
        energy : bool
            Add ``T_J``, ``U_J``, ``W_nc_J``, ``E_balance_J`` and ``residual``; with
            friction in the pairs also ``W_friction_J`` (the work friction has
            dissipated, J, ``energy["work_friction"]``) and ``P_friction_W`` (the power
            it dissipates, W, ``energy["power_friction"]``).
        bodies : bool
            Add the body frame poses and velocities (``x_rod_m``, ``theta_rod_rad``,
            ``omega_rod_rad_s`` ...).
        degrees : bool
            Add ``<angle>_deg`` columns next to the radians.
        """
        import pandas as pd

        is_angle = self.coordinate_is_angle or (True,) * len(self.coordinate_names)
        cols = {"t_s": self.t, **coordinate_columns(self.coordinate_names, is_angle, self.q,
                                                    self.qdot, self.qddot, degrees=degrees)}
        body_columns = (("x", "m"), ("y", "m"), ("theta", "rad"),
                        ("vx", "m_s"), ("vy", "m_s"), ("omega", "rad_s"))
        for b, name in enumerate(self.body_names if bodies else ()):
            for i, (what, unit) in enumerate(body_columns):
                cols[f"{what}_{name}_{unit}"] = (self.x if i < 3 else self.xdot)[:, 3 * b + i % 3]
        if points and self.model is not None and self.t.size:
            m, xdd = self.model, self.xddot()
            for body, pt in m.named_points():
                r = point_position(m, self.x, body, pt)
                v = point_velocity(m, self.x, self.xdot, body, pt)
                a = point_acceleration(m, self.x, self.xdot, xdd, body, pt)
                for what, unit, val in (("", "m", r), ("v", "m_s", v), ("a", "m_s2", a)):
                    cols[f"{what}x_{body}_{pt}_{unit}"] = val[:, 0]
                    cols[f"{what}y_{body}_{pt}_{unit}"] = val[:, 1]
        if energy and self.energy:
            cols.update({col: self.energy[key] for col, key in (
                ("T_J", "kinetic"), ("U_J", "potential"), ("W_nc_J", "work_nc"),
                ("E_balance_J", "balance"), ("residual", "residual"))})
            cols.update({col: self.energy[key] for col, key in (
                ("W_friction_J", "work_friction"), ("P_friction_W", "power_friction"))
                if key in self.energy})
        vs = self.switching
        if vs and self.t.size:  # the forces of a run (see docs/variable-structure.md)
            if getattr(self.model, "has_switching", True):  # else one mode: no mode column
                cols.update(mode_columns(vs["mode"], vs["mode_index"]))
            cols.update(force_columns("frame", vs["frame_force"], magnitude=True))
            if vs.get("frame_moment") is not None:
                cols["M_frame_Nm"] = np.asarray(vs["frame_moment"], float)
            for name, f in vs.get("forces", {}).items():
                cols.update(force_columns(str(name).replace("@", "_"), f))
        return pd.DataFrame(cols)

    @property
    def switching(self) -> SwitchedSamples | None:
        """The per-sample modes and element forces of a variable-structure run, else None."""
        return self.stats.variable_structure

    def xddot(self) -> np.ndarray:
        """Body frame accelerations xddot = B q'' + b, shape (n, n_x) (needs ``model``)."""
        return accelerations(self.model, self.x, self.xdot, self.qddot,
                             layout=self.model.layout(self.stats.mode))
