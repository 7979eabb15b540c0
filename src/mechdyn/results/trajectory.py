"""The record of a dynamic simulation: :class:`Trajectory`."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..errors import ModelError, did_you_mean
from ..kinematics.analogs import accelerations
from ..model.constraints import point_acceleration, point_position, point_velocity
from .table import coordinate_columns, force_columns, mode_columns

__all__ = ["Trajectory", "SwitchedSamples"]

#: statuses of a run that reached its end (or a terminal event)
SUCCESS_STATUSES = ("success", "event")
#: the keys of a :class:`SwitchedSamples` read as a mapping, in order
SWITCHED_KEYS = ("mode", "modes", "mode_index", "frame_force", "forces", "impact_losses",
                 "penetration", "frame_moment")


@dataclass(frozen=True)
class SwitchedSamples(Mapping):
    """What a variable-structure run records per sample beyond the motion (typed; it also
    reads as the mapping ``trajectory.stats["variable_structure"]`` it used to be).

    The loads on the frame and in every element (``frame_force``, ``frame_moment``,
    ``forces``) are computed from the run's samples when first read: ``loads`` is the
    mapping of them or the function that computes it (an error of the function is raised
    again by the next read).

    Attributes
    ----------
    mode : list of Mode
        The mode of every sample, shape (n,).
    modes : list of Mode
        The distinct modes in the order they appeared.
    mode_index : ndarray of int, shape (n,)
        Index of each sample's mode in ``modes``.
    impact_losses : ndarray, shape (n,)
        Kinetic energy lost in impacts up to each sample, J.
    penetration : float
        Largest penetration of a stop or contact seen, m.
    frame_force : ndarray, shape (n, 2)
        Force the frame receives (reactions and the ground ends of springs), N.
    frame_moment : ndarray, shape (n,)
        Moment the frame receives about the ground origin, N m.
    forces : dict
        Per joint, lock, stop and contact: its reaction per sample ((n, 2) or (n, 3):
        force on the child from the parent at the joint point, N, and moment, N m;
        (n,) normal force of a stop or contact, N).

    Examples
    --------
    >>> s = SwitchedSamples([frozenset()], [frozenset()], np.zeros(1, int), np.zeros(1),
    ...                     loads=lambda: {"frame_force": np.ones((1, 2)), "forces": {}})
    >>> s["frame_force"].tolist(), s.frame_moment is None, len(s)
    ([[1.0, 1.0]], True, 8)
    """

    mode: list
    modes: list
    mode_index: np.ndarray
    impact_losses: np.ndarray
    penetration: float = 0.0
    loads: Callable[[], Mapping] | Mapping = field(default_factory=dict, repr=False,
                                                   compare=False)

    @classmethod
    def lazy(cls, fill, **fields) -> SwitchedSamples:
        """The record with its loads computed by ``fill()`` on first read."""
        return cls(**fields, loads=fill)

    @cached_property
    def _loads(self) -> dict:
        """The loads, computed once (see the class's text)."""
        return dict(self.loads() if callable(self.loads) else self.loads)

    @property
    def frame_force(self) -> np.ndarray:
        """Force the frame receives, N, shape (n, 2)."""
        return self._loads.get("frame_force")

    @property
    def frame_moment(self) -> np.ndarray | None:
        """Moment the frame receives about the ground origin, N m, shape (n,)."""
        return self._loads.get("frame_moment")

    @property
    def forces(self) -> dict:
        """The reaction of every joint, lock, stop and contact per sample, N (N m)."""
        return self._loads.get("forces", {})

    def __getstate__(self) -> dict:  # pickled and copied with the loads computed
        state = {k: v for k, v in self.__dict__.items() if k != "_loads"}
        state["loads"] = self._loads
        return state

    def __getitem__(self, key):
        if key not in SWITCHED_KEYS:
            raise KeyError(key)
        return getattr(self, key)

    def __iter__(self):
        return iter(SWITCHED_KEYS)

    def __len__(self) -> int:
        return len(SWITCHED_KEYS)


@dataclass(frozen=True)
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
    stats : dict
        ``steps``, ``rejected``, ``evaluations`` (right-hand sides), ``wall_time_s``,
        ``integrator``, ``formulation``, ``backend`` and the integrator's settings; for a
        variable-structure run also ``segments`` and ``variable_structure``, a
        :class:`SwitchedSamples` (see :attr:`switching`); for a run handed to a sink
        without keeping its samples (``simulate(sink=..., keep=False)``, which holds the
        last chunk) ``streamed``: the run's ``rows``, ``t_first``, ``energy_drift`` and
        largest constraint ``residual``.
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
    stats: dict = field(default_factory=dict)
    energy: dict | None = None
    coordinate_names: tuple = ()
    body_names: tuple = ()
    coordinate_is_angle: tuple = ()
    model: object = field(default=None, repr=False, compare=False)

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
        if "streamed" in self.stats:  # a run handed to a sink, of which this is the end
            return float(self.stats["streamed"]["energy_drift"])
        if not self.energy or self.t.size == 0:
            return float("nan")
        b = self.energy["balance"]
        return float(np.max(np.abs(b - b[0])))

    def summary(self) -> str:
        """Multi-line text: status, counters and the energy balance."""
        lines = [f"status: {self.status}" + (f" - {self.message}" if self.message else "")]
        s = self.stats
        if s:
            lines.append(
                f"integrator {s.get('integrator')} ({s.get('formulation')}, backend "
                f"{s.get('backend')}): {s.get('steps')} steps, {s.get('evaluations')} "
                f"evaluations, wall time {s.get('wall_time_s', float('nan')):.4g} s")
        streamed = s.get("streamed") if s else None
        if streamed:
            lines.append(f"samples: {streamed['rows']} (streamed), t = "
                         f"{streamed['t_first']:.6g} .. {self.t[-1]:.6g} s")
        elif self.t.size:
            lines.append(f"samples: {self.t.size}, t = {self.t[0]:.6g} .. {self.t[-1]:.6g} s")
        bif = s.get("bifurcations") if s else None
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
                f"{streamed['residual'] if streamed else np.max(e['residual']):.3e}")
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
        vs = self.stats.get("variable_structure")
        return vs if isinstance(vs, SwitchedSamples) else None

    def xddot(self) -> np.ndarray:
        """Body frame accelerations xddot = B q'' + b, shape (n, n_x) (needs ``model``)."""
        return accelerations(self.model, self.x, self.xdot, self.qddot,
                             layout=self.model.layout(self.stats.get("mode")))
