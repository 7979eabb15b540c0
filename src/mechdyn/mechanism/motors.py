"""Motors and transmissions: mechanical characteristics M(omega) for drives.

Every class here is frozen data in SI units with one method the dynamics calls,
``torque_at(omega)`` (N m at the shaft speed ``omega``, rad/s; scalars give a
float, arrays an array), and ``extra_inertia()`` (kg m^2), the moment of
inertia the drive adds to the coordinate it drives (rotor, gears: reduced to
the driven shaft).  A drive on a coordinate is ``Drive(name, coordinate,
torque=<one of these>)`` (see :mod:`mechdyn.mechanism.drive`): an
:class:`InductionMotor` (Kloss's formula or its extended form), a :class:`DCMotor`, a
:class:`ConstantSpeedDrive`, a :class:`TabulatedMotor`, or any of them behind a
:class:`GearStage`.

:func:`mechdyn.modelfile.drives.drive_from_table` builds a
:class:`~mechdyn.mechanism.drive.Drive` with one of these from a model-file
``[[drives]]`` table (see ``docs/reduction-and-drives.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError

__all__ = ["InductionMotor", "DCMotor", "ConstantSpeedDrive", "TabulatedMotor", "GearStage",
           "kloss_critical_slip", "fit_extended_kloss", "extra_inertia_by_coordinate",
           "CHARACTERISTICS"]

#: forms of the induction-motor characteristic
CHARACTERISTICS = ("kloss", "extended")


def _out(value):
    """float for a scalar result, ndarray otherwise."""
    arr = np.asarray(value, dtype=float)
    return float(arr) if arr.ndim == 0 else arr


def _finite(x) -> bool:
    try:
        return bool(np.isfinite(float(x)))
    except (TypeError, ValueError):
        return False


def _at_least(p: list[str], name: str, value, low: float, unit: str = "",
              strict: bool = True) -> bool:
    """Whether ``value`` is a finite number > ``low`` (>= unless ``strict``); if not,
    record ``"name must be > low unit, got value"`` in ``p``."""
    if _finite(value) and (value > low if strict else value >= low):
        return True
    p.append(f"{name} must be {'>' if strict else '>='} {low:g}{' ' * bool(unit)}{unit}, "
             f"got {value!r}")
    return False


def _raise(where: str, problems: list[str]):
    if problems:
        raise ModelError([f"{where}: {p}" for p in problems])


def _set(obj, *floats, **values):
    """Set fields of a frozen dataclass: ``values``, and ``floats`` as floats (None stays)."""
    values.update((n, float(getattr(obj, n))) for n in floats if getattr(obj, n) is not None)
    for name, value in values.items():
        object.__setattr__(obj, name, value)


class _DirectDrive:
    """A motor on the driven shaft itself: it adds its ``rotor_inertia``."""

    def extra_inertia(self) -> float:
        """Rotor inertia added to the driven coordinate, kg m^2 (direct drive)."""
        return float(self.rotor_inertia)


def kloss_critical_slip(rated_slip: float, breakdown_ratio: float) -> float:
    """Critical slip of Kloss's formula through the rated point.

    From ``M_n / M_k = 2 / (s_n/s_k + s_k/s_n)`` with ``lambda = M_k / M_n``:
    ``s_k = s_n (lambda + sqrt(lambda^2 - 1))`` (the root above ``s_n``).

    Parameters
    ----------
    rated_slip : float
        s_n, in (0, 1).
    breakdown_ratio : float
        lambda = M_k / M_n, > 1.
    """
    lam = float(breakdown_ratio)
    return float(rated_slip) * (lam + math.sqrt(lam * lam - 1.0))


def _extended_q(slip, torque_ratio, sk):
    """q = a s_k that puts the extended curve through (slip, torque_ratio * M_k)."""
    f = slip / sk + sk / slip
    return (torque_ratio * f / 2.0 - 1.0) / (1.0 - torque_ratio)


def fit_extended_kloss(rated_slip: float, breakdown_ratio: float,
                       starting_ratio: float) -> tuple[float, float]:
    """Fit the extended Kloss formula to the rated, breakdown and starting torques.

    Solves for ``s_k`` and ``a`` in
    ``M(s) = 2 M_k (1 + a s_k) / (s/s_k + s_k/s + 2 a s_k)`` so that
    ``M(s_n) = M_n``, ``M(1) = M_start``; its maximum is ``M_k`` at ``s = s_k``
    for any ``a`` with ``1 + a s_k > 0``.

    Parameters
    ----------
    rated_slip : float
        s_n, in (0, 1).
    breakdown_ratio, starting_ratio : float
        M_k / M_n (> 1) and M_start / M_n (0 < ... < breakdown_ratio).

    Returns
    -------
    (s_k, a) : tuple of float
        Critical slip (dimensionless) and the stator-resistance term a.

    Raises
    ------
    ModelError
        When no curve of this form passes through the three points (the message
        says why); Kloss's formula (``characteristic = "kloss"``) still fits the
        rated and breakdown points.
    """
    from scipy.optimize import brentq

    sn, lam, mst = float(rated_slip), float(breakdown_ratio), float(starting_ratio)
    mu_n, mu_s = 1.0 / lam, mst / lam

    def h(sk):
        return _extended_q(sn, mu_n, sk) - _extended_q(1.0, mu_s, sk)

    grid = np.geomspace(sn * (1 + 1e-9), 1.0 - 1e-9, 4001)
    vals = np.array([h(s) for s in grid])
    roots = []
    for k in np.flatnonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) < 0):
        sk = brentq(h, grid[k], grid[k + 1], xtol=1e-15, rtol=1e-14)
        q = _extended_q(sn, mu_n, sk)
        if q > -1.0 + 1e-12:
            roots.append((sk, q / sk))
    sk_k = kloss_critical_slip(sn, lam)
    if not roots:
        m1 = 2 * lam / (1.0 / sk_k + sk_k)
        raise ModelError(
            f"no extended Kloss curve M = 2 M_k (1 + a s_k)/(s/s_k + s_k/s + 2 a s_k) passes "
            f"through the rated torque at slip {sn:.4g}, the breakdown torque "
            f"{lam:.4g} M_n and the starting torque {mst:.4g} M_n with 1 + a s_k > 0 and "
            f"s_n < s_k < 1 (Kloss's formula gives M_start = {m1:.4g} M_n); use "
            f"characteristic = 'kloss' or check the catalogue data")
    # several admissible roots are not expected; take the one closest to Kloss's s_k
    sk, a = min(roots, key=lambda r: abs(r[0] - sk_k))
    return float(sk), float(a)


@dataclass(frozen=True)
class InductionMotor(_DirectDrive):
    """A squirrel-cage induction motor from catalogue data.

    Kloss's formula ``M = 2 M_k / (s/s_k + s_k/s)``, or the extended formula with the
    stator-resistance term ``a``, ``M = 2 M_k (1 + a s_k) / (s/s_k + s_k/s + 2 a s_k)``,
    which also passes through the starting torque.

    Parameters
    ----------
    name : str
        Designation, e.g. ``"4A80B4U3"``.
    rated_power : float
        P_n, W (shaft output at rated load).
    synchronous_speed : float
        omega_0, rad/s (1500 rpm = 157.08 rad/s).
    rated_slip : float, optional
        s_n = (omega_0 - omega_n) / omega_0, in (0, 1).  Give this or ``rated_speed``.
    rated_speed : float, optional
        omega_n, rad/s, below ``synchronous_speed``.
    breakdown_ratio : float
        M_k / M_n (> 1): breakdown (maximum) torque over rated torque.
    starting_ratio : float, optional
        M_start / M_n: torque at standstill (s = 1) over rated torque; needed for
        ``characteristic="extended"``.
    rotor_inertia : float
        Moment of inertia of the rotor, kg m^2 (>= 0).
    characteristic : {"kloss", "extended"}
        Kloss's formula (through the rated and breakdown torques) or the extended
        formula with the stator-resistance term (also through the starting torque).
    source : str
        Where the data come from (free text, kept in reports).

    Attributes
    ----------
    rated_torque : float
        M_n = P_n / omega_n, N m.
    breakdown_torque : float
        M_k, N m.
    critical_slip : float
        s_k of the chosen form.
    a : float
        Stator-resistance term of the extended form (0 for Kloss's formula).

    Examples
    --------
    >>> import math
    >>> m = InductionMotor("4A80B4U3", rated_power=1500.0,
    ...                    synchronous_speed=1500 * math.pi / 30, rated_slip=0.058,
    ...                    breakdown_ratio=2.2, starting_ratio=2.0)
    >>> round(m.torque_at(m.rated_speed) / m.rated_torque, 12)
    1.0
    """

    name: str
    rated_power: float
    synchronous_speed: float
    rated_slip: float | None = None
    rated_speed: float | None = None
    breakdown_ratio: float = 2.0
    starting_ratio: float | None = None
    rotor_inertia: float = 0.0
    characteristic: str = "kloss"
    source: str = ""
    rated_torque: float = field(init=False, repr=False, default=0.0)
    breakdown_torque: float = field(init=False, repr=False, default=0.0)
    critical_slip: float = field(init=False, repr=False, default=0.0)
    a: float = field(init=False, repr=False, default=0.0)

    def __post_init__(self):
        where = f"induction motor {self.name!r}"
        p: list[str] = []
        _at_least(p, "rated_power", self.rated_power, 0, "W")
        _at_least(p, "synchronous_speed", self.synchronous_speed, 0, "rad/s")
        if (self.rated_slip is None) == (self.rated_speed is None):
            p.append("give exactly one of rated_slip and rated_speed "
                     f"(got rated_slip={self.rated_slip!r}, rated_speed={self.rated_speed!r})")
        if self.rated_slip is not None and (not _finite(self.rated_slip)
                                            or not 0.0 < self.rated_slip < 1.0):
            p.append(f"rated_slip must lie in (0, 1), got {self.rated_slip!r}")
        if self.rated_speed is not None and _at_least(p, "rated_speed", self.rated_speed, 0,
                                                      "rad/s"):
            if _finite(self.synchronous_speed) and self.rated_speed >= self.synchronous_speed:
                p.append(f"rated_speed {self.rated_speed:.6g} rad/s must be below the "
                         f"synchronous_speed {self.synchronous_speed:.6g} rad/s (a motor "
                         f"runs with positive slip)")
        if not _finite(self.breakdown_ratio) or self.breakdown_ratio <= 1.0:
            p.append(f"breakdown_ratio (M_k/M_n) must be > 1: the breakdown torque cannot be "
                     f"below the rated torque; got {self.breakdown_ratio!r}")
        if self.starting_ratio is not None and _at_least(p, "starting_ratio (M_start/M_n)",
                                                         self.starting_ratio, 0):
            if _finite(self.breakdown_ratio) and self.starting_ratio >= self.breakdown_ratio:
                p.append(f"starting_ratio {self.starting_ratio!r} must be below "
                         f"breakdown_ratio {self.breakdown_ratio!r} (the breakdown torque is "
                         f"the maximum of the characteristic)")
        _at_least(p, "rotor_inertia", self.rotor_inertia, 0, "kg*m^2", strict=False)
        if self.characteristic not in CHARACTERISTICS:
            p.append(f"characteristic must be one of {', '.join(map(repr, CHARACTERISTICS))}, "
                     f"got {self.characteristic!r}")
        elif self.characteristic == "extended" and self.starting_ratio is None:
            p.append("characteristic 'extended' needs starting_ratio (M_start/M_n)")
        _raise(where, p)

        _set(self, "rated_power", "synchronous_speed", "rated_slip", "rated_speed",
             "breakdown_ratio", "rotor_inertia", "starting_ratio")
        w0 = self.synchronous_speed
        if self.rated_slip is None:
            _set(self, rated_slip=(w0 - self.rated_speed) / w0)
        else:
            _set(self, rated_speed=w0 * (1.0 - self.rated_slip))
        if self.characteristic == "kloss":
            sk, a = kloss_critical_slip(self.rated_slip, self.breakdown_ratio), 0.0
        else:
            try:
                sk, a = fit_extended_kloss(self.rated_slip, self.breakdown_ratio,
                                           self.starting_ratio)
            except ModelError as exc:
                raise ModelError(f"{where}: {exc}") from None
        mn = self.rated_power / self.rated_speed
        _set(self, rated_torque=mn, breakdown_torque=self.breakdown_ratio * mn,
             critical_slip=float(sk), a=float(a))

    @property
    def starting_torque(self) -> float:
        """Torque of the model at standstill (s = 1), N m."""
        return self.torque_at_slip(1.0)

    def slip(self, omega):
        """Slip s = (omega_0 - omega) / omega_0 at shaft speed ``omega`` (rad/s)."""
        if isinstance(omega, float):
            return (self.synchronous_speed - omega) / self.synchronous_speed
        return _out((self.synchronous_speed - np.asarray(omega, float)) / self.synchronous_speed)

    def torque_at_slip(self, s):
        """Electromagnetic torque at slip ``s`` (N m), written without the pole at s = 0:
        ``M = 2 M_k (1 + a s_k) s s_k / (s^2 + s_k^2 + 2 a s_k^2 s)``."""
        sk, a = self.critical_slip, self.a
        x = s if isinstance(s, float) else np.asarray(s, dtype=float)  # floats: the fast path
        m = (2.0 * self.breakdown_torque * (1.0 + a * sk) * x * sk
             / (x * x + sk * sk + 2.0 * a * sk * sk * x))
        return m if isinstance(s, float) else _out(m)

    def torque_at(self, omega):
        """Shaft torque (N m) at shaft speed ``omega`` (rad/s); scalar or array."""
        return self.torque_at_slip(self.slip(omega))


@dataclass(frozen=True)
class DCMotor(_DirectDrive):
    """A separately excited DC motor: ``M = M_stall (1 - omega / omega_0)``.

    Parameters
    ----------
    name : str
    no_load_speed : float
        omega_0 > 0, rad/s (torque zero).
    stall_torque : float
        M_stall > 0, N m (torque at standstill).
    rotor_inertia : float
        kg m^2, >= 0.
    source : str
    """

    name: str
    no_load_speed: float
    stall_torque: float
    rotor_inertia: float = 0.0
    source: str = ""

    def __post_init__(self):
        p: list[str] = []
        _at_least(p, "no_load_speed", self.no_load_speed, 0, "rad/s")
        _at_least(p, "stall_torque", self.stall_torque, 0, "N*m")
        _at_least(p, "rotor_inertia", self.rotor_inertia, 0, "kg*m^2", strict=False)
        _raise(f"DC motor {self.name!r}", p)

    @classmethod
    def from_rated(cls, name: str, rated_power: float, rated_speed: float,
                   no_load_speed: float, rotor_inertia: float = 0.0,
                   source: str = "") -> DCMotor:
        """From the rated point (P_n W, omega_n rad/s) and the no-load speed (rad/s)."""
        p: list[str] = []
        _at_least(p, "rated_power", rated_power, 0, "W")
        if _at_least(p, "rated_speed", rated_speed, 0, "rad/s") and _finite(no_load_speed) \
                and rated_speed >= no_load_speed:
            p.append(f"rated_speed {rated_speed!r} rad/s must be below no_load_speed "
                     f"{no_load_speed!r} rad/s")
        _raise(f"DC motor {name!r}", p)
        mn = rated_power / rated_speed
        return cls(name, float(no_load_speed), mn / (1.0 - rated_speed / no_load_speed),
                   rotor_inertia, source)

    def torque_at(self, omega):
        """Shaft torque (N m) at shaft speed ``omega`` (rad/s)."""
        return _out(self.stall_torque * (1.0 - np.asarray(omega, float) / self.no_load_speed))


@dataclass(frozen=True)
class ConstantSpeedDrive:
    """An ideal drive holding the coordinate at a constant speed.

    For kinetostatics (the crank turns at ``speed``; the driving torque is the
    unknown the analysis finds) and for ideal drives in simulation.  In forward
    dynamics a perfectly rigid speed is a constraint, not a torque: give
    ``stiffness`` (N m s/rad) to model it as a stiff speed governor
    ``M = stiffness (speed - omega)``; without it ``torque_at`` raises.

    Parameters
    ----------
    name : str
    speed : float
        rad/s (m/s on a travel coordinate).
    stiffness : float, optional
        N m s/rad, > 0.
    """

    name: str
    speed: float
    stiffness: float | None = None

    def __post_init__(self):
        p: list[str] = []
        if not _finite(self.speed):
            p.append(f"speed must be a finite number in rad/s, got {self.speed!r}")
        if self.stiffness is not None:
            _at_least(p, "stiffness", self.stiffness, 0, "N*m*s/rad")
        _raise(f"constant-speed drive {self.name!r}", p)

    def torque_at(self, omega):
        """``stiffness (speed - omega)``, N m; raises without a stiffness."""
        if self.stiffness is None:
            raise ModelError(
                f"constant-speed drive {self.name!r}: an ideal constant speed has no torque "
                f"characteristic; use it for kinetostatics (prescribed motion), or give "
                f"'stiffness' (N*m*s/rad) to model a stiff speed governor in dynamics")
        return _out(self.stiffness * (self.speed - np.asarray(omega, float)))

    def extra_inertia(self) -> float:
        """No inertia is added, kg m^2."""
        return 0.0


@dataclass(frozen=True)
class TabulatedMotor(_DirectDrive):
    """A mechanical characteristic M(omega) from a table, linearly interpolated.

    Parameters
    ----------
    name : str
    omega : sequence of float
        Shaft speeds, rad/s, strictly increasing (at least two).
    torque : sequence of float
        Torques at those speeds, N m.
    rotor_inertia : float
        kg m^2, >= 0.
    extrapolate : bool
        Linear extrapolation outside the table (default); False holds the end values.
    source : str
    """

    name: str
    omega: tuple
    torque: tuple
    rotor_inertia: float = 0.0
    extrapolate: bool = True
    source: str = ""

    def __post_init__(self):
        w = np.asarray(self.omega, dtype=float).reshape(-1)
        m = np.asarray(self.torque, dtype=float).reshape(-1)
        p = []
        if w.size < 2 or w.size != m.size:
            p.append(f"omega and torque need the same length >= 2, got {w.size} and {m.size}")
        elif not np.all(np.diff(w) > 0):
            p.append("omega must increase strictly")
        if not (np.all(np.isfinite(w)) and np.all(np.isfinite(m))):
            p.append("omega and torque must be finite")
        _at_least(p, "rotor_inertia", self.rotor_inertia, 0, "kg*m^2", strict=False)
        _raise(f"tabulated motor {self.name!r}", p)
        _set(self, omega=tuple(w), torque=tuple(m))

    def torque_at(self, omega):
        """Interpolated torque (N m) at shaft speed ``omega`` (rad/s)."""
        w = np.asarray(self.omega)
        m = np.asarray(self.torque)
        om = np.asarray(omega, dtype=float)
        out = np.interp(om, w, m)
        if self.extrapolate:
            lo = (m[1] - m[0]) / (w[1] - w[0])
            hi = (m[-1] - m[-2]) / (w[-1] - w[-2])
            out = np.where(om < w[0], m[0] + lo * (om - w[0]), out)
            out = np.where(om > w[-1], m[-1] + hi * (om - w[-1]), out)
        return _out(out)


@dataclass(frozen=True)
class GearStage:
    """A speed-reducing stage between a motor and the driven coordinate.

    ``ratio`` i = omega_motor / omega_driven.  The driven-side torque is
    ``eta i M_motor(i omega)`` while the motor drives the machine, and
    ``i M_motor / eta`` when power flows back (the losses always oppose the
    power flow).  The rotating parts add the reduced inertia
    ``(J_motor + J_input) i^2 + J_output`` to the driven coordinate.

    Parameters
    ----------
    motor : object with ``torque_at(omega)`` (and optionally ``extra_inertia()``)
        The motor (or another stage).
    ratio : float
        i > 0.
    efficiency : float
        eta in (0, 1].
    input_inertia, output_inertia : float
        Inertia of the gear parts on the motor shaft and on the driven shaft,
        kg m^2 (pulleys, pinion, gear wheel, couplings).
    name : str
    """

    motor: object
    ratio: float
    efficiency: float = 1.0
    input_inertia: float = 0.0
    output_inertia: float = 0.0
    name: str = "gear"

    def __post_init__(self):
        p: list[str] = []
        if not hasattr(self.motor, "torque_at"):
            p.append(f"motor must have a method torque_at(omega), got {type(self.motor)!r}")
        _at_least(p, "ratio (omega_motor/omega_driven)", self.ratio, 0)
        if not _finite(self.efficiency) or not 0.0 < self.efficiency <= 1.0:
            p.append(f"efficiency must lie in (0, 1], got {self.efficiency!r}")
        for fld in ("input_inertia", "output_inertia"):
            _at_least(p, fld, getattr(self, fld), 0, "kg*m^2", strict=False)
        _raise(f"gear stage {self.name!r}", p)
        _set(self, "ratio", "efficiency", "input_inertia", "output_inertia")

    def motor_speed(self, omega):
        """Motor shaft speed (rad/s) at driven speed ``omega`` (rad/s)."""
        if isinstance(omega, float):
            return self.ratio * omega
        return _out(self.ratio * np.asarray(omega, float))

    def motor_torque(self, omega):
        """Motor torque (N m) at driven speed ``omega`` (rad/s)."""
        return self.motor.torque_at(self.motor_speed(omega))

    def torque_at(self, omega):
        """Torque on the driven coordinate (N m) at its speed ``omega`` (rad/s)."""
        m = self.motor_torque(omega)
        eta, i = self.efficiency, self.ratio  # the losses always oppose the power flow
        if isinstance(omega, float) and isinstance(m, float):
            return eta * i * m if m * omega >= 0.0 else i * m / eta
        m = np.asarray(m, dtype=float)
        forward = m * np.asarray(omega, dtype=float) >= 0.0  # power flows motor -> machine
        return _out(np.where(forward, eta * i * m, i * m / eta))

    def extra_inertia(self) -> float:
        """``(J_motor + J_input) i^2 + J_output``, kg m^2, on the driven coordinate."""
        jm = float(self.motor.extra_inertia()) if hasattr(self.motor, "extra_inertia") else 0.0
        return (jm + self.input_inertia) * self.ratio**2 + self.output_inertia


def extra_inertia_by_coordinate(mechanism) -> dict[str, float]:
    """Inertia the drives add to their coordinates, kg m^2 (kg on travels).

    The hook for the dynamics: ``A[k, k] += extra[name_k]``.  Drives whose
    torque has no ``extra_inertia()`` add nothing.

    Parameters
    ----------
    mechanism : Mechanism

    Returns
    -------
    dict
        Coordinate name -> added inertia (only coordinates with a non-zero value).
    """
    out: dict[str, float] = {}
    for dr in mechanism.drives:
        j = float(getattr(dr.torque, "extra_inertia", lambda: 0.0)())
        if j:
            out[dr.coordinate] = out.get(dr.coordinate, 0.0) + j
    return out
