"""The typed ``stats`` of the records of mechdyn.

Every record's ``stats`` is a typed dataclass (no free dict): :class:`RunStats` of a
simulation (:class:`~mechdyn.results.trajectory.Trajectory`), with
:class:`StreamedStats` of a run handed to a sink and :class:`RunCounters`, the
builder the segment loop counts into and freezes at the end;
:class:`KinetostaticsStats` (with a :class:`SegmentStats` per segment of a switched
trajectory) of a kinetostatic analysis
(:class:`~mechdyn.results.kinetostatics_record.Kinetostatics`);
:class:`ReductionStats`, :class:`SteadyCycleStats` and :class:`FlywheelStats` of the
records of :mod:`mechdyn.reduction` (whose runs, ``ReducedRun`` and ``StartupResult``,
carry the :class:`~mechdyn.integrate.driver.SolveStats` of their integration).  Each
also reads as the read-only mapping it used to be (``stats["evaluations"]``,
:class:`~mechdyn.fieldmap.FieldMapping`): the keys are its fields that are not None.

The record classes themselves stay in their modules
(:mod:`mechdyn.results.trajectory` ...); only their stats are here.  The stats of a
kinematic sweep, :class:`~mechdyn.kinematics.records.SweepStats`, are defined with the
sweep in :mod:`mechdyn.kinematics.records` (the kinematics are a layer below the
results and may not import them) and re-exported here.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields
from functools import cached_property

import numpy as np

from ..fieldmap import FieldMapping
from ..kinematics.records import SweepStats

__all__ = ["RunStats", "RunCounters", "StreamedStats", "SwitchedSamples", "SweepStats",
           "KinetostaticsStats", "SegmentStats", "ReductionStats", "SteadyCycleStats",
           "FlywheelStats"]

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
class StreamedStats(FieldMapping):
    """What a run handed to a sink without keeping its samples
    (``simulate(sink=..., keep=False)``) tells of all its rows, beyond the last chunk
    its Trajectory holds.

    Attributes
    ----------
    rows : int
        Samples of the whole run.
    t_first : float
        Time of its first sample, s.
    balance0 : float
        The energy balance T + U - W_nc at the first sample, J.
    energy_drift : float
        Largest |balance - balance0| over the run, J.
    residual : float
        Largest constraint residual over the run (m or rad).

    Examples
    --------
    >>> s = StreamedStats(rows=501, t_first=0.0, balance0=1.5, energy_drift=1e-9,
    ...                   residual=1e-12)
    >>> s.rows, s["rows"]
    (501, 501)
    """

    rows: int
    t_first: float
    balance0: float
    energy_drift: float
    residual: float

    def joined(self, rows: int, drift: float, residual: float) -> StreamedStats:
        """These counters with ``rows`` more rows, whose largest drift from
        :attr:`balance0` is ``drift`` (J) and largest residual ``residual``."""
        return StreamedStats(self.rows + rows, self.t_first, self.balance0,
                             max(self.energy_drift, drift), max(self.residual, residual))


@dataclass(frozen=True)
class RunStats(FieldMapping):
    """The counters and settings of a simulation (``Trajectory.stats``).

    Every field is also read as a key (``stats["steps"]``); the fields that are None
    (not known for this run) are not among its keys.

    Attributes
    ----------
    integrator : str
        The integrator and its settings, e.g. ``"dop853"`` or ``"wilson(dt=0.002 s)"``.
    formulation : str
        ``"exact"`` or the formulation the run was made with.
    backend : str
        Where the right-hand sides were evaluated: ``"numba"``, ``"numpy"`` or
        ``"numba+numpy"``.
    rtol : float or None
        Relative tolerance of the integrator (1).
    atol : float, ndarray or None
        Absolute tolerance of the integrator (in the units of each state).
    steps : int
        Accepted steps.
    rejected : int
        Rejected steps (adaptive integrators).
    evaluations : int
        Right-hand-side evaluations.
    segments : int
        Segments of the run (one per mode between two switching events).
    bifurcations : list of dict
        The bifurcation positions the run went through on its branch (``at``, the
        first coordinate there, rad or m; ``kind``).
    mode : list of str or None
        The locks engaged at the start.
    backend_note : str or None
        Why (part of) the run took the NumPy path, if it did.
    compile_time_s : float or None
        Time spent compiling the run's kernels, s (0 when they were cached).
    wall_time_s : float or None
        Wall time of the run, s.
    penetration : float or None
        Largest penetration of a stop or contact seen, m.
    variable_structure : SwitchedSamples or None
        The modes and element forces per sample (see ``Trajectory.switching``).
    streamed : StreamedStats or None
        Of a run handed to a sink without keeping its samples: its counts over every
        row.

    Examples
    --------
    >>> s = RunStats(integrator="dop853", steps=120, evaluations=1441, wall_time_s=0.05)
    >>> s.steps, s["evaluations"], "streamed" in s
    (120, 1441, False)
    >>> sorted(dict(s))[:4]
    ['backend', 'bifurcations', 'evaluations', 'formulation']
    """

    integrator: str = ""
    formulation: str = ""
    backend: str = ""
    rtol: float | None = None
    atol: float | np.ndarray | None = None
    steps: int = 0
    rejected: int = 0
    evaluations: int = 0
    segments: int = 0
    bifurcations: list = field(default_factory=list)
    mode: list | None = None
    backend_note: str | None = None
    compile_time_s: float | None = None
    wall_time_s: float | None = None
    penetration: float | None = None
    variable_structure: SwitchedSamples | None = field(default=None, repr=False)
    streamed: StreamedStats | None = None


@dataclass
class RunCounters:
    """The counters of a simulation while it runs, frozen into its :class:`RunStats` at
    the end by :meth:`freeze` (the fields mean what those of :class:`RunStats` mean).

    Examples
    --------
    >>> c = RunCounters(integrator="rk4", formulation="exact")
    >>> c.steps += 10
    >>> c.evaluations += 41
    >>> s = c.freeze(wall_time_s=0.01)
    >>> s.steps, s.evaluations, s.wall_time_s
    (10, 41, 0.01)
    """

    integrator: str = ""
    formulation: str = ""
    backend: str = "numpy"
    rtol: float | None = None
    atol: float | np.ndarray | None = None
    steps: int = 0
    rejected: int = 0
    evaluations: int = 0
    segments: int = 0
    bifurcations: list = field(default_factory=list)
    mode: list | None = None
    backend_note: str | None = None
    compile_time_s: float | None = None

    def freeze(self, **more) -> RunStats:
        """The run's :class:`RunStats`: these counters (copied) and ``more`` of its
        fields (``wall_time_s``, ``penetration``, ...)."""
        now = {f.name: getattr(self, f.name) for f in fields(self)}
        now["bifurcations"] = list(self.bifurcations)
        return RunStats(**now, **more)


@dataclass(frozen=True)
class SegmentStats(FieldMapping):
    """One segment of the kinetostatics of a switched trajectory (the samples of one
    mode in a row), an entry of ``KinetostaticsStats.segments``.

    Attributes
    ----------
    mode : frozenset of str
        The engaged locks of the segment.
    start, stop : int
        Its sample range ``start .. stop - 1``.
    t_start, t_end : float
        The times of its first and last samples, s.
    driven : tuple of str
        The coordinates driven in it (none when it was not analysed).
    status : str
        The status of its analysis, or ``"not analysed: <why>"``.
    power_balance_rel : float or None
        Largest power-balance residual, relative to the largest power (1).
    rcond_min : float or None
        Smallest reciprocal condition number of its equations (1).

    Examples
    --------
    >>> s = SegmentStats(frozenset({"clutch"}), 0, 50, 0.0, 0.49, ("th1",), "success")
    >>> s.stop - s.start, s["driven"], "rcond_min" in s
    (50, ('th1',), False)
    """

    mode: frozenset
    start: int
    stop: int
    t_start: float
    t_end: float
    driven: tuple = ()
    status: str = ""
    power_balance_rel: float | None = None
    rcond_min: float | None = None


@dataclass(frozen=True)
class KinetostaticsStats(FieldMapping):
    """The figures of a kinetostatic analysis (``Kinetostatics.stats``).

    A field that is None does not apply to the analysis (and is not among its keys:
    ``friction_iterations`` only with friction in the pairs, ``segments`` only for a
    switched trajectory ...).

    Attributes
    ----------
    positions : int or None
        Positions analysed.
    seconds : float or None
        Wall time of the analysis, s.
    position_solves : int or None
        Newton solves of the positions (continuation steps and batched solves).
    power_balance_rel : float or None
        Largest |driving power - rate of kinetic energy - losses|, relative to the
        largest power of the run (1): a self-check, round-off small.
    rcond_min : float or None
        Smallest reciprocal condition number of the equations over the positions (1).
    redundant_equations : int or None
        Linearly dependent joint equations.
    redundant_shared_by : str or None
        With redundant equations: ``"compliance"`` (shared by the joints'
        compliances) or ``"minimum norm"``.
    singular_positions : int or None
        Positions where the driven coordinates lose control of the mechanism.
    bifurcation_positions : int or None
        Positions at a bifurcation the analysis went through on its branch.
    bifurcations : list of dict or None
        The bifurcations charted on the way (``at``, ``kind``).
    self_locked_positions : int or None
        With friction: the self-locked positions.
    friction_iterations : int or None
        With friction: iterations of the friction solve.
    segments : tuple of SegmentStats or None
        For a switched trajectory: one entry per segment.

    Examples
    --------
    >>> s = KinetostaticsStats(positions=361, seconds=0.02, power_balance_rel=3e-15)
    >>> s.positions, s["power_balance_rel"] < 1e-9, "segments" in s
    (361, True, False)
    """

    positions: int | None = None
    seconds: float | None = None
    position_solves: int | None = None
    power_balance_rel: float | None = None
    rcond_min: float | None = None
    redundant_equations: int | None = None
    redundant_shared_by: str | None = None
    singular_positions: int | None = None
    bifurcation_positions: int | None = None
    bifurcations: list | None = None
    self_locked_positions: int | None = None
    friction_iterations: int | None = None
    segments: tuple | None = None


@dataclass(frozen=True)
class ReductionStats(FieldMapping):
    """The figures of a reduction to one coordinate (``Reduction.stats``).

    Attributes
    ----------
    positions : int
        Positions the reduced quantities were evaluated at.
    extra_inertia_coordinate : float
        The inertia of the rotors and gears of the drives reduced to the coordinate,
        kg m^2 (kg for a travel).
    friction_ignored : tuple of str
        The joints with friction, which the reduction leaves out.

    Examples
    --------
    >>> s = ReductionStats(positions=361, extra_inertia_coordinate=0.0, friction_ignored=())
    >>> s.positions, s["friction_ignored"]
    (361, ())
    """

    positions: int
    extra_inertia_coordinate: float
    friction_ignored: tuple = ()


@dataclass(frozen=True)
class SteadyCycleStats(FieldMapping):
    """How the steady cycle of a reduced machine was found (``SteadyCycle.stats``).

    Attributes
    ----------
    cycles_integrated : int
        Cycles integrated until the speed repeated.
    evaluations : int
        Right-hand-side evaluations.
    omega0 : float
        The speed the steady cycle starts with, rad/s (m/s for a travel).
    steps : int
        Steps of the cycle kept.

    Examples
    --------
    >>> s = SteadyCycleStats(cycles_integrated=3, evaluations=5000, omega0=10.0, steps=720)
    >>> s.omega0, s["steps"]
    (10.0, 720)
    """

    cycles_integrated: int
    evaluations: int
    omega0: float
    steps: int


@dataclass(frozen=True)
class FlywheelStats(FieldMapping):
    """A figure of the sizing of a flywheel (``FlywheelSizing.stats``).

    Attributes
    ----------
    mean_torque_removed_Nm : float
        The mean of the reduced torque over the cycle, removed before sizing (a
        machine out of balance), N m (N for a travel).

    Examples
    --------
    >>> FlywheelStats(mean_torque_removed_Nm=0.25)["mean_torque_removed_Nm"]
    0.25
    """

    mean_torque_removed_Nm: float
