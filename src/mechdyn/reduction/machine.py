"""The reduced 1-DOF machine (lecture notes eq. 7.12).

``J(phi) domega/dt + 1/2 omega^2 dJ/dphi = M_red(phi, omega, t)`` with
``J = J_red + J_extra`` (rotor and gears reduced to the link, flywheel).

Public names
------------
ReducedMachine, Member, MemberLoad
    The reduced machine: from a model, from a :class:`~mechdyn.reduction.reduce.Reduction`
    table, from a transmission of velocity ratios (belt drives, gear trains), or
    from plain functions.
"""

from __future__ import annotations

import bisect
import copy
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, fields
from types import SimpleNamespace
from typing import Protocol

import numpy as np

from ..brief import brief, span, status_text
from ..errors import IntegrationError, ModelError
from ..fieldmap import FieldMapping
from ..mechanism.drive import TorqueSpeedCurve
from ..mechanism.load import Table
from ..model import Model, as_model
from ..model.inertia import drive_inertia
from ..results.records import ReductionStats
from .kinematics import _ModelEvaluator


class ReductionTable(Protocol):
    """What :meth:`ReducedMachine.from_reduction` reads of a
    :class:`~mechdyn.reduction.reduce.Reduction` (which imports this module)."""

    link: str | None
    coordinate: str
    phi: np.ndarray
    J_red: np.ndarray
    M_forces: np.ndarray
    stats: ReductionStats

__all__ = ["ReducedMachine", "Member", "MemberLoad"]

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True, kw_only=True)
class _Record:
    """The fields every record has: ``status``, ``message``, ``events``, ``stats`` (the
    typed stats of the record, :mod:`mechdyn.results.records`); its array fields are kept
    as read-only float copies."""

    status: str = "success"
    message: str = ""
    events: tuple = ()
    stats: FieldMapping

    def __post_init__(self):
        for f in fields(self):
            if isinstance(v := getattr(self, f.name), np.ndarray):
                a = np.array(v, dtype=float, copy=True)
                a.setflags(write=False)
                object.__setattr__(self, f.name, a)


@dataclass(frozen=True)
class _Motion(_Record):
    """Samples of a motion of the reduced machine (arrays of shape (n,))."""

    t: np.ndarray
    phi: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    J: np.ndarray
    M: np.ndarray

    def __repr__(self) -> str:
        times = span(self.t[[0, -1]], "s") if self.t.size else ""
        return brief(self, f"{self.t.size} samples" + (f", t = {times}" if times else ""),
                     f"omega = {span(self.omega, 'rad/s')}" if self.t.size else "",
                     status_text(self), *self._figures())

    def _figures(self) -> tuple[str, ...]:
        """The key figures of the repr (after the sizes and the status)."""
        return ()

    def to_dataframe(self):
        """Columns ``t_s, phi_deg, phi_rad, omega_rad_s, epsilon_rad_s2, J_total_kgm2,
        M_red_Nm`` (and ``M_drive_Nm``, ``M_motor_Nm`` of a run)."""
        import pandas as pd

        cols = {"t_s": self.t, "phi_deg": np.degrees(self.phi), "phi_rad": self.phi,
                "omega_rad_s": self.omega, "epsilon_rad_s2": self.epsilon,
                "J_total_kgm2": self.J, "M_red_Nm": self.M}
        for name in ("M_drive", "M_motor"):
            if getattr(self, name, None) is not None:
                cols[f"{name}_Nm"] = getattr(self, name)
        return pd.DataFrame(cols)


def _extra_inertia(value, model: Model | None = None) -> float:
    """``value`` as an added inertia, kg m^2 (checked finite and >= 0); None: the inertia
    of the model's drives (rotor and gear)."""
    if value is None:
        return float(drive_inertia(model)[0])
    j = float(value)
    if not math.isfinite(j) or j < 0:
        raise ModelError(f"extra_inertia must be >= 0 kg*m^2, got {value!r}")
    return j


def _drive_torque(drive, omega) -> float:
    """Torque of a drive at ``omega`` (its ``torque_at``), N m; 0 without a drive."""
    return 0.0 if drive is None else float(drive.torque_at(omega))


# ============================================================================ the machine
@dataclass(frozen=True)
class Member:
    """A moving member of a transmission, given by its velocity ratio to the input.

    Parameters
    ----------
    name : str
    inertia : float
        Moment of inertia about its axis (kg m^2) for ``kind="rotation"``, mass
        (kg) for ``kind="translation"``.
    ratio : float or callable
        ``omega_i / omega`` (rotation) or ``v_i / omega`` (translation, m/rad):
        a constant, or a function of the input position phi.
    ratio_derivative : float or callable, optional
        d(ratio)/dphi; default 0 for a constant ratio, a central difference for
        a callable.
    kind : {"rotation", "translation"}
    """

    name: str
    inertia: float
    ratio: float | Callable = 1.0
    ratio_derivative: float | Callable | None = None
    kind: str = "rotation"

    def __post_init__(self):
        if self.kind not in ("rotation", "translation"):
            raise ModelError(f"member {self.name!r}: kind must be 'rotation' or "
                             f"'translation', got {self.kind!r}")
        if not math.isfinite(float(self.inertia)) or float(self.inertia) < 0:
            unit = "kg*m^2" if self.kind == "rotation" else "kg"
            raise ModelError(f"member {self.name!r}: inertia must be >= 0 {unit}, "
                             f"got {self.inertia!r}")


@dataclass(frozen=True)
class MemberLoad:
    """A torque (or force) on a member, reduced by equal power.

    Parameters
    ----------
    name : str
    value : float or callable
        N m (or N) in the member's positive direction of motion; a constant or
        ``value(t, phi, omega) -> float`` of the input's position and speed.
    ratio : float or callable
        The member's velocity ratio to the input (as in :class:`Member`).
    """

    name: str
    value: float | Callable = 0.0
    ratio: float | Callable = 1.0


def _value(f, *args) -> float:
    """``f(*args)`` of a callable, else the constant ``f``, as a float."""
    return float(f(*args)) if callable(f) else float(f)


def _dratio(m: Member, phi, h=1e-6):
    if m.ratio_derivative is not None:
        return _value(m.ratio_derivative, phi)
    if not callable(m.ratio):
        return 0.0
    return (_value(m.ratio, phi + h) - _value(m.ratio, phi - h)) / (2 * h)


class ReducedMachine:
    """A one-degree-of-freedom machine reduced to one link.

    Equation of motion: ``J(phi) phi'' + 1/2 J'(phi) phi'^2 = M(t, phi, phi')``
    with ``J = J_red(phi) + extra_inertia``.

    Parameters
    ----------
    inertia : callable
        ``inertia(phi) -> (J_red, dJ_red/dphi)``, kg m^2 and kg m^2/rad.
    torque : callable
        ``torque(t, phi, omega) -> M_red``, N m (forces and drives).
    extra_inertia : float
        Constant inertia added on the link (rotor through the gear, flywheel), kg m^2.
    drive : object, optional
        The drive on the link (an object with ``torque_at``; a
        :class:`~mechdyn.mechanism.motors.GearStage` also gives the motor-side
        torque in :func:`~mechdyn.reduction.run.startup`).  Informational: its
        torque must already be part of ``torque``.
    period : float
        Angle of one cycle, rad (2 pi for a crank).
    name : str
    coordinate : str
        Name of the coordinate of the link of reduction (for reports).
    nominal_speed : float, optional
        A speed near the working point, rad/s (start of the steady-state search);
        default from the drive (rated speed through the gear).

    Build one with :meth:`from_model`, :meth:`from_reduction`,
    :meth:`from_transmission` or :meth:`constant`.
    """

    def __init__(self, inertia: Callable, torque: Callable, *, extra_inertia: float = 0.0,
                 drive=None, period: float = TWO_PI, name: str = "machine",
                 coordinate: str = "phi", nominal_speed: float | None = None):
        if not (math.isfinite(float(period)) and period > 0):
            raise ModelError(f"period must be > 0 rad, got {period!r}")
        self._inertia = inertia
        self._torque = torque
        self.extra_inertia = _extra_inertia(extra_inertia)
        self.drive = drive
        self.period = float(period)
        self.name = name
        self.coordinate = coordinate
        self.nominal_speed = nominal_speed if nominal_speed is not None else _nominal(drive)

    # ------------------------------------------------------------------ evaluation
    def inertia(self, phi: float) -> tuple[float, float]:
        """(J, dJ/dphi) of the whole machine (extra inertia included), kg m^2 and kg m^2/rad."""
        j, dj = self._inertia(float(phi))
        return float(j) + self.extra_inertia, float(dj)

    def inertia_along(self, phi) -> np.ndarray:
        """J of the whole machine at each of the positions ``phi`` (in order), kg m^2."""
        return np.array([self.inertia(p)[0] for p in phi])

    def torque(self, t: float, phi: float, omega: float) -> float:
        """Reduced torque of forces and drives, N m."""
        return float(self._torque(float(t), float(phi), float(omega)))

    def acceleration(self, t: float, phi: float, omega: float) -> float:
        """phi'' = (M - 1/2 J' omega^2) / J, rad/s^2."""
        j, dj = self.inertia(phi)
        if not j > 0:
            raise IntegrationError(f"reduced inertia J = {j:.6g} kg*m^2 is not positive",
                                   t=t, q=[phi])
        return (self.torque(t, phi, omega) - 0.5 * dj * omega * omega) / j

    def rhs(self, t, q, qdot):
        """The right-hand side q'' = f(t, q, q') for :mod:`mechdyn.integrate`."""
        return np.array([self.acceleration(t, q[0], qdot[0])])

    def drive_torque(self, omega: float) -> float:
        """Torque of the drive on the link (N m), 0 without a drive."""
        return _drive_torque(self.drive, omega)

    def motor_torque(self, omega: float) -> float | None:
        """Motor-side torque (N m) when the drive is a gear stage, else the drive torque."""
        if self.drive is None:
            return None
        fn = getattr(self.drive, "motor_torque", None)
        return float(fn(omega)) if fn is not None else self.drive_torque(omega)

    def speed_dependent(self, t: float = 0.0) -> bool:
        """Whether the reduced torque changes with the speed (a motor, a damper)."""
        for p in np.linspace(0.0, self.period, 7)[:-1]:
            a = self.torque(t, p, 10.0)
            b = self.torque(t, p, 20.0)
            if abs(a - b) > 1e-9 * max(1.0, abs(a)):
                return True
        return False

    def with_driving_torque(self, torque: float) -> ReducedMachine:
        """A copy with a constant driving torque ``torque`` (N m) added on the link."""
        new = copy.copy(self)
        base = self._torque
        new._torque = lambda t, p, w: base(t, p, w) + torque
        return new

    def with_extra_inertia(self, added: float) -> ReducedMachine:
        """A copy with ``added`` kg m^2 more on the link (a flywheel)."""
        new = copy.copy(self)
        new.extra_inertia = self.extra_inertia + float(added)
        return new

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_model(cls, model: Model, *, coordinate: str | None = None,
                   extra_inertia: float | None = None, mode=None, x0=None,
                   period: float | None = None) -> ReducedMachine:
        """The exact reduced machine of a 1-DOF model.

        Every evaluation solves the position (continued from the last one, so
        the assembly branch is kept), the exact analogs and the generalized
        force of all loads and drives; ``extra_inertia`` defaults to the
        drives' rotor and gear inertia.
        """
        model = as_model(model)  # a Mechanism is compiled (and validated) here
        ev = _ModelEvaluator(model, coordinate, mode=mode, x0=x0)
        motors = [d.torque for d in model.mechanism.drives
                  if d.coordinate == ev.coordinate and hasattr(d.torque, "torque_at")]
        drive = motors[0] if len(motors) == 1 else None  # for reports
        if period is None:
            period = TWO_PI if ev.is_angle else 1.0
        return cls(ev.inertia, ev.torque, extra_inertia=_extra_inertia(extra_inertia, model),
                   drive=drive, period=period, name=model.mechanism.name,
                   coordinate=ev.coordinate)

    @classmethod
    def from_reduction(cls, red: ReductionTable, model: Model | None = None, *,
                       extra_inertia: float | None = None, drive=None) -> ReducedMachine:
        """A fast machine interpolating a one-cycle
        :class:`~mechdyn.reduction.reduce.Reduction` table.

        J_red is a periodic cubic spline (its derivative the spline's), the
        applied-force torque M_forces is interpolated linearly (punch loads are
        discontinuous) and periodically; the drive torque is evaluated live from
        ``drive`` (default: the model's drive on the coordinate), so the table's
        M_drive is not used.  Valid when the loads depend on the position only.
        """
        from scipy.interpolate import CubicSpline

        if red.link is not None:
            raise ModelError("from_reduction: reduce to the coordinate (link=None) to build a "
                             "machine")
        phi = np.asarray(red.phi)
        period = phi[-1] - phi[0]
        if not period > 0 or not np.all(np.diff(phi) > 0):
            raise ModelError("from_reduction: the table must cover one cycle with increasing "
                             "positions (first and last position one period apart)")
        jj = np.array(red.J_red, dtype=float)
        jj[-1] = jj[0]
        spline = CubicSpline(phi, jj, bc_type="periodic")
        coef = spline.c.T.tolist()  # per interval: c3, c2, c1, c0 in powers of (u - phi_i)
        xs = phi.tolist()
        mf = np.array(red.M_forces, dtype=float).tolist()
        n_int = len(xs) - 1
        if drive is None and model is not None:
            drive = _speed_drive(model, red.coordinate)

        def locate(p):
            u = xs[0] + (p - xs[0]) % period
            return u, min(max(bisect.bisect_right(xs, u) - 1, 0), n_int - 1)

        def inertia(p):
            u, i = locate(p)
            d = u - xs[i]
            c3, c2, c1, c0 = coef[i]
            return ((c3 * d + c2) * d + c1) * d + c0, (3.0 * c3 * d + 2.0 * c2) * d + c1

        def torque(t, p, w):
            u, i = locate(p)
            r = (u - xs[i]) / (xs[i + 1] - xs[i])
            m = mf[i] + r * (mf[i + 1] - mf[i])
            return m + _drive_torque(drive, w)

        if extra_inertia is None:
            extra_inertia = float(red.stats.extra_inertia_coordinate)
        return cls(inertia, torque, extra_inertia=extra_inertia, drive=drive, period=period,
                   coordinate=red.coordinate)

    @classmethod
    def from_transmission(cls, members: Sequence[Member], loads: Sequence[MemberLoad] = (),
                          drive=None, *, period: float = TWO_PI,
                          name: str = "transmission") -> ReducedMachine:
        """A machine given by the velocity ratios of its members (lecture notes §6).

        ``J_red = sum I_i r_i^2``, ``dJ_red/dphi = 2 sum I_i r_i r_i'``,
        ``M_red = sum M_j r_j + drive.torque_at(omega)``.  This is the honest way
        to reduce a belt drive or a gear train: mechdyn has no belt or gear-mesh
        joint, but their velocity ratios are exactly what the reduction needs.

        Parameters
        ----------
        members : sequence of Member
        loads : sequence of MemberLoad
        drive : object with ``torque_at(omega)``, optional
            A motor on the input (its ``extra_inertia()`` is added).
        """
        members = list(members)
        loads = list(loads)
        names = [m.name for m in members]
        if len(set(names)) != len(names):
            raise ModelError(f"transmission: member names must be unique, got {names}")

        def inertia(p):
            j = sum(m.inertia * _value(m.ratio, p) ** 2 for m in members)
            dj = sum(2.0 * m.inertia * _value(m.ratio, p) * _dratio(m, p) for m in members)
            return j, dj

        def torque(t, p, w):
            tot = sum(_value(ld.value, t, p, w) * _value(ld.ratio, p) for ld in loads)
            return tot + _drive_torque(drive, w)

        extra = float(drive.extra_inertia()) if hasattr(drive, "extra_inertia") else 0.0
        return cls(inertia, torque, extra_inertia=extra, drive=drive, period=period, name=name)

    @classmethod
    def constant(cls, inertia: float, torque: Callable | float, *, drive=None,
                 period: float = TWO_PI, name: str = "machine") -> ReducedMachine:
        """A machine of constant inertia (kg m^2) and torque ``torque(t, phi, omega)`` (N m)
        or a constant; a ``drive`` adds its ``torque_at(omega)``."""
        if not inertia > 0:
            raise ModelError(f"inertia must be > 0 kg*m^2, got {inertia!r}")
        j = float(inertia)

        def tq(t, p, w):
            return _value(torque, t, p, w) + _drive_torque(drive, w)

        return cls(lambda p: (j, 0.0), tq, drive=drive, period=period, name=name)


def _speed_drive(model: Model, coordinate: str):
    """The drives of a coordinate as a function of its speed only (None without drives)."""
    drives = [d for d in model.mechanism.drives if d.coordinate == coordinate]
    parts = []
    for d in drives:
        tq = d.torque
        if hasattr(tq, "torque_at"):
            parts.append(tq.torque_at)
        elif isinstance(tq, TorqueSpeedCurve):
            parts.append(tq)
        elif isinstance(tq, Table) or callable(tq):
            raise ModelError(f"drive {d.name!r}: its torque depends on more than the speed of "
                             f"{coordinate!r}; use the exact machine "
                             f"(ReducedMachine.from_model, or --exact on the command line)")
        else:
            parts.append(lambda omega, v=float(tq): v)
    if len(drives) == 1 and hasattr(drives[0].torque, "torque_at"):
        return drives[0].torque
    # one torque_at(omega): the sum of the drives' functions of omega
    return SimpleNamespace(torque_at=lambda w: sum(float(p(w)) for p in parts)) if parts else None


def _nominal(drive) -> float | None:
    """A speed at which a drive runs near its rated point, rad/s (None if unknown)."""
    ratio = 1.0
    while hasattr(drive, "ratio") and hasattr(drive, "motor"):  # through the gear stages
        ratio *= drive.ratio
        drive = drive.motor
    for attr, share in (("rated_speed", 1.0), ("speed", 1.0), ("no_load_speed", 0.5)):
        v = getattr(drive, attr, None)
        if v is not None:
            return share * float(v) / ratio
    return None
