"""What a study computes for each variant: kinetostatic extremes, a kinematic summary,
a flywheel, or metrics of a simulation.

Each analysis is a small picklable object (it travels to worker processes) called as
``analysis(model, warm)`` with a compiled variant; it returns an :class:`Outcome`: the
figures (table columns named with their units), the status and message of the record,
and what the next variant may start from (``warm``, e.g. this variant's poses).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import ModelError, Status
from ..units import parse_quantity

__all__ = ["Outcome", "KinetostaticExtremes", "extremes", "KinematicSummary", "FlywheelSize",
           "SimulationMetrics", "Combined", "ANALYSES", "check_figures"]

_DEG = 180.0 / np.pi


@dataclass
class Outcome:
    """The figures of one variant and how its analysis ended.

    Attributes
    ----------
    figures : dict of str to float
        Column name with its unit (``"M_drive_phi_peak_Nm"``) -> value.
    status : str
        A :class:`mechdyn.errors.Status` value.
    message : str
    warm : object
        What the next variant starts from (None: start from its own sketch).
    """

    figures: dict
    status: str = Status.SUCCESS.value
    message: str = ""
    warm: object = None


def _si(value, kind: str, where: str) -> float:
    return float(parse_quantity(value, kind, where=where))


def _cycle(model, over: str | None, start: float, steps: int):
    """The driven coordinate (default the first) and ``steps`` values over one turn."""
    over = model.coordinate_names[0] if over is None else over
    k = model.coordinate_index(over)
    if not model.coord_is_angle[k]:
        raise ModelError(f"coordinate {over!r} is a travel: a study cycle turns an angle")
    if steps < 2:
        raise ModelError(f"steps must be at least 2, got {steps}")
    return over, start + np.linspace(0.0, 2 * np.pi, steps, endpoint=False)


@dataclass(frozen=True)
class KinetostaticExtremes:
    """Peak and RMS driving torque, peak joint forces and the shaking force over one
    turn at constant speed (:func:`mechdyn.kinetostatics`).

    Parameters
    ----------
    speed : float or str
        Constant speed of ``over``, rad/s or with a unit (``"1000 rpm"``).
    steps : int
        Positions over one turn, ``start + linspace(0, 2 pi, steps, endpoint=False)``.
    over : str, optional
        Driven coordinate (default the first).
    start : float or str
        First position, rad or with a unit.
    warm_start : bool
        Start each variant's position solve from the previous variant's poses (one
        batched Newton solve instead of the continuation; the result is the same to
        the solver's tolerance while the variants stay on one assembly branch).

    Examples
    --------
    >>> a = KinetostaticExtremes("1000 rpm", steps=36)
    >>> round(a.speed, 4)
    104.7198
    """

    speed: float | str
    steps: int = 360
    over: str | None = None
    start: float | str = 0.0
    warm_start: bool = True
    name: str = field(default="kinetostatics", init=False)

    def __post_init__(self):
        object.__setattr__(self, "speed", _si(self.speed, "angular_velocity", "speed"))
        object.__setattr__(self, "start", _si(self.start, "angle", "start"))

    def values(self, model) -> tuple[str, np.ndarray]:
        """The driven coordinate and its positions, rad, shape (steps,)."""
        return _cycle(model, self.over, self.start, self.steps)

    def record(self, model, warm=None):
        """The :class:`~mechdyn.Kinetostatics` record of a variant (from ``warm`` poses)."""
        from ..kinetostatics.inverse import kinetostatics

        over, values = self.values(model)
        guess = warm if self.warm_start and warm is not None and \
            np.shape(warm) == (values.size, model.n_x) else None
        return kinetostatics(model, over=over, speed=self.speed, values=values, x_guess=guess)

    def __call__(self, model, warm=None) -> Outcome:
        return self.figures(self.record(model, warm))

    def columns(self, model) -> tuple[str, ...]:
        """The names of the figures of ``model``'s variants (the analysis over four
        positions: the drives and joints name them)."""
        return tuple(replace(self, steps=4, warm_start=False)(model).figures)

    @staticmethod
    def figures(rec) -> Outcome:
        """The figures of a kinetostatics record (also for a plain loop's records)."""
        out = extremes(rec, rec.driving, rec.power, rec.reactions, rec.frame_force,
                       rec.frame_moment, rec.rms)
        ok = rec.status in (Status.SUCCESS, Status.REDUNDANT)
        return Outcome({k: float(v) for k, v in out.items()}, str(rec.status),
                       "" if ok else rec.message, rec.x if ok else None)


def extremes(rec, driving: dict, power: dict, reactions: dict, frame_force, frame_moment,
             rms) -> dict:
    """The figures of :class:`KinetostaticExtremes` from the series of a kinetostatics
    record, over the last axis (the positions); leading axes (variants) are kept.

    Parameters
    ----------
    rec : Kinetostatics
        Names the driven coordinates and their units (``driven``, ``_drive_unit``).
    driving, power : dict of str to ndarray, shape (..., n)
    reactions : dict of str to ndarray, shape (..., n, 2)
    frame_force : ndarray, shape (..., n, 2)
    frame_moment : ndarray, shape (..., n)
    rms : callable
        RMS over the positions of a series (..., n) -> (...) (the record's rule,
        :meth:`~mechdyn.Kinetostatics.rms`).

    Returns
    -------
    dict of str to ndarray, shape (...)
        Column name (with its unit) -> value.
    """
    out: dict = {}
    for c in rec.driven:
        sym, unit = rec._drive_unit(c)  # the record's own column names
        tau = np.asarray(driving[c], float)
        out[f"{sym}_drive_{c}_peak_{unit}"] = np.nanmax(np.abs(tau), axis=-1)
        out[f"{sym}_drive_{c}_max_{unit}"] = np.nanmax(tau, axis=-1)
        out[f"{sym}_drive_{c}_min_{unit}"] = np.nanmin(tau, axis=-1)
        out[f"{sym}_drive_{c}_rms_{unit}"] = rms(tau)
        out[f"P_drive_{c}_peak_W"] = np.nanmax(np.abs(power[c]), axis=-1)
    for j, r in reactions.items():
        out[f"F_{j}_peak_N"] = np.nanmax(np.hypot(r[..., 0], r[..., 1]), axis=-1)
    f = np.hypot(frame_force[..., 0], frame_force[..., 1])
    out["F_frame_peak_N"] = np.nanmax(f, axis=-1)
    out["F_frame_rms_N"] = rms(f)
    out["M_frame_peak_Nm"] = np.nanmax(np.abs(frame_moment), axis=-1)
    return out


@dataclass(frozen=True)
class KinematicSummary:
    """Strokes and dead centres of the sliders and the transmission-angle range of the
    four-bar loops over one turn (:meth:`mechdyn.KinematicSweep.summary`).

    Parameters
    ----------
    steps : int
        Positions over one turn.
    over : str, optional
        Swept coordinate (default the first).
    start : float or str
        First position, rad or with a unit.

    Examples
    --------
    >>> KinematicSummary(steps=90).name
    'kinematics'
    """

    steps: int = 361
    over: str | None = None
    start: float | str = 0.0
    name: str = field(default="kinematics", init=False)

    def __post_init__(self):
        object.__setattr__(self, "start", _si(self.start, "angle", "start"))

    def columns(self, model) -> tuple[str, ...]:
        """The names of the figures of ``model``'s variants: per slider its stroke and
        dead centres, per four-bar loop its transmission-angle range."""
        from ..kinematics.records import four_bar_loops

        over = _cycle(model, self.over, self.start, 2)[0]
        out = [f"stroke_{j}_m" for j in model.pri.names]
        out += [f"{label}_{j}_{what}" for j in model.pri.names for label in ("TDC", "BDC")
                for what in ("at_deg", "travel_m")]
        for lp in four_bar_loops(model, over):
            tag = f"{lp.coupler}_{lp.rocker}"
            out += [f"mu_min_{tag}_deg", f"mu_max_{tag}_deg", f"mu_min_{tag}_at_deg"]
        return tuple(out)

    def __call__(self, model, warm=None) -> Outcome:
        from ..kinematics.sweep import sweep

        over, values = _cycle(model, self.over, self.start, self.steps)
        sw = sweep(model, over, values)
        s = sw.summary()
        out: dict[str, float] = {}
        for j, v in s.strokes.items():
            out[f"stroke_{j}_m"] = float(v)
        for d in s.dead_centres:
            out[f"{d.label}_{d.joint}_at_deg"] = float(np.rad2deg(d.at) % 360.0)
            out[f"{d.label}_{d.joint}_travel_m"] = float(d.travel)
        for t in s.transmission:
            tag = f"{t.loop.coupler}_{t.loop.rocker}"
            out[f"mu_min_{tag}_deg"] = float(t.min * _DEG)
            out[f"mu_max_{tag}_deg"] = float(t.max * _DEG)
            out[f"mu_min_{tag}_at_deg"] = float(np.rad2deg(t.min_at) % 360.0)
        return Outcome(out, str(sw.status), "" if sw.status == Status.SUCCESS else sw.message)


@dataclass(frozen=True)
class FlywheelSize:
    """A flywheel for a coefficient of speed fluctuation (:func:`mechdyn.size_flywheel`
    on the reduced machine of :func:`mechdyn.reduce_model`).

    Parameters
    ----------
    delta : float
        Target coefficient of speed fluctuation, in (0, 2).
    speed : float or str, optional
        Mean speed (needed when the drive torque does not depend on the speed).
    method : {"energy", "refined", "simulation"}, optional
        See :func:`mechdyn.size_flywheel` (default ``"refined"``: fast, no simulation).
    steps : int
        Positions of the reduction table.

    Examples
    --------
    >>> FlywheelSize(0.05, speed="1000 rpm").method
    'refined'
    """

    delta: float
    speed: float | str | None = None
    method: str = "refined"
    steps: int = 361
    name: str = field(default="flywheel", init=False)

    def __post_init__(self):
        if self.speed is not None:
            object.__setattr__(self, "speed", _si(self.speed, "angular_velocity", "speed"))

    def columns(self, model) -> tuple[str, ...]:
        """The names of the figures (the same for every model)."""
        out = ("J_fly_kg_m2", "delta_E_max_J", "omega_mean_rpm", "J_red_mean_kg_m2",
               "J_fly_motor_kg_m2")
        return out + (("delta_simulated",) if self.method == "simulation" else ())

    def __call__(self, model, warm=None) -> Outcome:
        from ..reduction.flywheel import size_flywheel
        from ..reduction.reduce import reduce_model

        machine = reduce_model(model, steps=self.steps, omega=self.speed or 1.0).machine(model)
        key = "omega_guess" if machine.speed_dependent() else "omega_mean"
        fs = size_flywheel(machine, float(self.delta), method=self.method,
                           confirm=self.method == "simulation", **{key: self.speed})
        out = {"J_fly_kg_m2": fs.J_fly, "delta_E_max_J": fs.delta_E_max,
               "omega_mean_rpm": fs.omega_mean * 30.0 / np.pi, "J_red_mean_kg_m2": fs.J_red_mean}
        if fs.J_fly_motor is not None:
            out["J_fly_motor_kg_m2"] = fs.J_fly_motor
        if fs.delta_simulated is not None:
            out["delta_simulated"] = fs.delta_simulated
        return Outcome({k: float(v) for k, v in out.items()})


@dataclass(frozen=True)
class SimulationMetrics:
    """Figures of a forward-dynamics run, computed by a function of its
    :class:`~mechdyn.Trajectory` (:func:`mechdyn.simulate`).

    Parameters
    ----------
    metrics : callable
        ``metrics(trajectory) -> dict`` of column name (with its unit) to value; a
        module-level function, so that it can be sent to worker processes.
    t_end : float or str
        End time of each run, s or with a unit.
    options : dict
        More keywords of :func:`mechdyn.simulate` (``integrator``, ``rtol`` ...).

    Examples
    --------
    >>> SimulationMetrics(len, "50 ms").t_end
    0.05
    """

    metrics: Callable
    t_end: float | str
    options: dict = field(default_factory=dict)
    name: str = field(default="simulation", init=False)

    def __post_init__(self):
        object.__setattr__(self, "t_end", _si(self.t_end, "time", "t_end"))

    def columns(self, model) -> None:
        """None: the names are those ``metrics`` gives, known after a run."""
        return None

    def __call__(self, model, warm=None) -> Outcome:
        from ..simulate.run import simulate

        traj = simulate(model, self.t_end, progress=False, **self.options)
        out = {k: float(v) for k, v in dict(self.metrics(traj)).items()}
        ok = traj.status in ("success", "event")
        return Outcome(out, str(traj.status), "" if ok else traj.message)


@dataclass(frozen=True)
class Combined:
    """Several analyses of each variant, their figures in one row (e.g. the stroke of
    :class:`KinematicSummary` beside the torques of :class:`KinetostaticExtremes`).

    The status is the first that is not a success; the warm state is the first
    analysis'.

    Examples
    --------
    >>> Combined((KinetostaticExtremes("100 rpm"), KinematicSummary())).name
    'kinetostatics+kinematics'
    """

    parts: tuple

    @property
    def name(self) -> str:
        return "+".join(p.name for p in self.parts)

    def columns(self, model) -> tuple[str, ...] | None:
        """The names of the figures of all the parts (None if one part's are unknown)."""
        names = [p.columns(model) for p in self.parts]
        return None if None in names else tuple(c for n in names for c in n)

    def __call__(self, model, warm=None) -> Outcome:
        outs = [p(model, warm if k == 0 else None) for k, p in enumerate(self.parts)]
        figures = {k: v for oc in outs for k, v in oc.figures.items()}
        bad = [oc for oc in outs if oc.status not in (Status.SUCCESS, Status.REDUNDANT)]
        head = bad[0] if bad else outs[0]
        return Outcome(figures, head.status, head.message, outs[0].warm)


def check_figures(analysis, model, names: dict, extra=()) -> None:
    """Check, before a study runs, that every figure it names is a column of the table.

    Parameters
    ----------
    analysis : KinetostaticExtremes, KinematicSummary, FlywheelSize, Combined ...
        Its ``columns(model)`` names the figures (None, or no such method: unknown
        before a run, nothing is checked).
    model : Model
        The compiled base model.
    names : dict of str to str or None
        The option or argument (``"--minimise"``) -> the column it names (None: not
        given).
    extra : sequence of str
        More valid names (the parameters' columns).

    Raises
    ------
    ModelError
        An unknown name: the message names the option and the value and lists the
        valid names.

    Examples
    --------
    >>> check_figures(FlywheelSize(0.05), None, {"--minimise": "J_fly_kg_m2"})
    >>> check_figures(FlywheelSize(0.05), None, {"--minimise": "J_fly"})
    Traceback (most recent call last):
    ...
    mechdyn.errors.ModelError: --minimise: unknown column 'J_fly'; valid column names: ...
    """
    from ..results.plot_columns import check_columns

    given = {flag: name for flag, name in names.items() if name is not None}
    columns = getattr(analysis, "columns", None)  # a plain callable names none
    valid = columns(model) if given and columns is not None else None
    if valid is None:
        return
    for flag, name in given.items():
        check_columns([name], [*valid, *extra], flag)


#: the analyses by their CLI name
ANALYSES = {"kinetostatics": KinetostaticExtremes, "kinematics": KinematicSummary,
            "flywheel": FlywheelSize}
