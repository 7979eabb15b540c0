"""Running the reduced equation of motion in time: time histories, the energy form
and the start-up from rest.

``J(phi) domega/dt + 1/2 omega^2 dJ/dphi = M_red(phi, omega, t)`` of a
:class:`~mechdyn.reduction.machine.ReducedMachine` is integrated in time
with :mod:`mechdyn.integrate`, or, when M_red depends on the position only,
solved by its energy form ``J omega^2 / 2 = J_0 omega_0^2 / 2 + integral M_red dphi``.

Public names
------------
ReducedRun, run_reduced, energy_speed
    A time history of the reduced machine, the time integration and the energy form.
StartupResult, startup
    The run from rest (or a given speed) by the motor, the time to settle on the
    steady cycle, peak drive and motor torques and the speed dip under load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..brief import brief, number, status_text
from ..errors import ModelError, Status
from ..fieldmap import FieldMapping
from ..integrate import make_integrator, solve
from .flywheel import SteadyCycle, steady_state
from .machine import ReducedMachine, _Motion, _Record

__all__ = ["ReducedRun", "run_reduced", "energy_speed", "StartupResult", "StartupSummary",
           "startup"]


@dataclass(frozen=True, repr=False)
class ReducedRun(_Motion):
    """A time history of the reduced machine.

    Attributes
    ----------
    t, phi, omega, epsilon : ndarray, shape (n,)
        Time (s), position (rad), speed (rad/s), acceleration (rad/s^2).
    J, M, M_drive : ndarray, shape (n,)
        Total reduced inertia (kg m^2), reduced torque and drive torque (N m).
    M_motor : ndarray or None
        Motor-side torque through a gear stage, N m.
    """

    M_drive: np.ndarray
    M_motor: np.ndarray | None = None

    def _figures(self) -> tuple[str, ...]:
        peak = float(np.max(np.abs(self.M_drive))) if self.M_drive.size else None
        return (f"peak M_drive {number(peak, 'N m')}",)


def run_reduced(machine: ReducedMachine, t_end: float, *, phi0: float = 0.0,
                omega0: float = 0.0, t0: float = 0.0, integrator: str = "dop853",
                t_eval=None, events=None, **options) -> ReducedRun:
    """Integrate the reduced equation of motion in time.

    Parameters
    ----------
    machine : ReducedMachine
    t_end : float
        End time, s.
    phi0, omega0 : float
        Initial position (rad) and speed (rad/s).
    t0 : float
        Start time, s.
    integrator : str
        A name of :data:`mechdyn.integrate.INTEGRATORS` (``"wilson"``, ``"rk4"``,
        ``"dop853"``, ...).
    t_eval : array_like, optional
        Output times (default every step).
    events : optional
        Event functions ``g(t, q, qdot)`` (see :mod:`mechdyn.integrate.events`).
    **options
        Integrator options (``steps``/``dt`` for fixed-step ones; ``rtol``, ``atol``,
        ``max_step`` for the adaptive ones).

    Returns
    -------
    ReducedRun
    """
    sol = solve(integrator, machine.rhs, t0, [phi0], [omega0], t_end, t_eval=t_eval,
                events=events, **options)
    t, phi, omega = sol.t, sol.q[:, 0], sol.qdot[:, 0]
    J, dJ = np.array([machine.inertia(p) for p in phi], dtype=float).reshape(-1, 2).T
    M = np.array([machine.torque(*s) for s in zip(t, phi, omega, strict=True)], dtype=float)
    md = np.array([machine.drive_torque(w) for w in omega], dtype=float)
    mm = None if machine.drive is None else np.array([machine.motor_torque(w) for w in omega])
    eps = (M - 0.5 * dJ * omega**2) / J
    return ReducedRun(t, phi, omega, eps, J, M, md, mm, status=sol.status,
                      events=tuple(sol.events), stats=sol.stats)


def energy_speed(machine: ReducedMachine, phi, *, phi0: float = 0.0, omega0: float,
                 t: float = 0.0, rtol: float = 1e-11) -> np.ndarray:
    """Speed from the energy form ``J omega^2/2 = J_0 omega_0^2/2 + int M dphi``.

    Valid when the reduced torque depends on the position only: it is evaluated
    at time ``t`` and speed ``omega0``.  The work ``int M dphi`` is integrated by the
    package's DOP853 (:mod:`mechdyn.integrate`, the default integrator, never SciPy's)
    from ``phi0`` to the farthest target on each side, the targets read off its dense
    output of order 7.

    Parameters
    ----------
    phi : array_like, shape (n,)
        Positions, rad (any order, on either side of ``phi0``).
    phi0, omega0 : float
        Reference position (rad) and speed there (rad/s).
    t : float
        Time at which the torque is evaluated, s.
    rtol : float
        Relative tolerance of the work integral; its absolute tolerance is
        ``1e-12 max(1, J_0 omega_0^2)`` J.

    Returns
    -------
    ndarray, shape (n,)
        omega(phi), rad/s; NaN where the kinetic energy would be negative (the
        machine cannot reach that position).

    Examples
    --------
    >>> import numpy as np
    >>> from mechdyn.reduction.machine import ReducedMachine
    >>> mach = ReducedMachine.constant(0.5, 1.0)  # J = 0.5 kg m^2, M = 1 N m
    >>> w = energy_speed(mach, [0.0, 2.0, -0.5], omega0=2.0)  # w^2 = 4 + 4 phi
    >>> np.round(w, 12).tolist()
    [2.0, 3.464101615138, 1.414213562373]
    """
    phi = np.asarray(phi, dtype=float).reshape(-1)
    j0, _ = machine.inertia(phi0)
    atol = 1e-12 * max(1.0, j0 * omega0**2)
    out = np.empty_like(phi)
    for sel, sign in ((phi >= phi0, 1.0), (phi < phi0, -1.0)):  # each side from phi0 on
        target = phi[sel]
        w = sign * _work(lambda u, sign=sign: machine.torque(t, phi0 + sign * u, omega0),
                         sign * (target - phi0), rtol, atol)
        e2 = j0 * omega0**2 + 2.0 * w
        with np.errstate(invalid="ignore"):
            out[sel] = np.where(e2 >= 0, np.sqrt(np.maximum(e2, 0) / machine.inertia_along(target)),
                                np.nan)
    return out


def _work(integrand, s, rtol: float, atol: float) -> np.ndarray:
    """``int_0^s integrand(u) du`` at the distances ``s >= 0`` (any order): the quadrature
    state w of the package's DOP853 over [0, max s], each ``s`` read off the dense output
    of the step that holds it."""
    s = np.asarray(s, dtype=float)
    w = np.zeros(s.size)
    if not s.size or s.max() == 0.0:
        return w
    order = np.argsort(s)
    k = int(np.searchsorted(s[order], 0.0, side="right"))  # s = 0: no work
    integ = make_integrator("dop853", rtol=rtol, atol=atol)
    for step in integ.integrate(lambda u, q, v: (np.zeros(0), [integrand(u)]), 0.0, [], [],
                                float(s.max()), w0=[0.0]):
        while k < s.size and s[order[k]] <= step.t:
            sk = s[order[k]]
            w[order[k]] = step.w[0] if sk == step.t else step.dense(sk)[2][0]
            k += 1
    return w


@dataclass(frozen=True, repr=False)
class StartupResult(_Record):
    """Start-up of a machine from rest by its motor, and its steady regime.

    Attributes
    ----------
    run : ReducedRun
        The time history (t, phi, omega, torques).
    steady : SteadyCycle
        The steady cycle the run approaches.
    t_steady : float or None
        First time after which the speed stays within ``tol * omega_mean`` of the
        steady cycle at the same position, s (None if not reached by t_end).
    peak_drive_torque : float
        Largest drive torque on the link during the run, N m.
    peak_motor_torque : float or None
        Largest motor-side torque (through the gear stage), N m.
    speed_dip : float
        omega_max - omega_min of the steady cycle, rad/s (the dip when the load
        acts, or between ``load_window`` start and the minimum after it).
    phi_dip : float
        Position of the minimum speed of the steady cycle, rad.
    omega_mean : float
        Mean speed of the steady cycle, rad/s.
    """

    run: ReducedRun
    steady: SteadyCycle
    t_steady: float | None
    peak_drive_torque: float
    peak_motor_torque: float | None
    speed_dip: float
    phi_dip: float
    omega_mean: float
    tol: float

    def __repr__(self) -> str:
        return brief(self, f"{self.run.t.size} samples", status_text(self),
                     f"t_steady {number(self.t_steady, 's')}",
                     f"omega_mean {number(self.omega_mean, 'rad/s')}",
                     f"peak_motor_torque {number(self.peak_motor_torque, 'N m')}",
                     f"speed_dip {number(self.speed_dip, 'rad/s')}")

    def to_dataframe(self):
        """The run's time history (see :meth:`ReducedRun.to_dataframe`)."""
        return self.run.to_dataframe()

    def summary(self) -> StartupSummary:
        """The headline figures in SI units (a :class:`StartupSummary`, which also reads
        as the dict it used to be: ``summary()["t_steady_s"]``)."""
        return StartupSummary(self.t_steady, self.peak_drive_torque, self.peak_motor_torque,
                              self.omega_mean, self.speed_dip, math.degrees(self.phi_dip),
                              self.steady.delta)


@dataclass(frozen=True, repr=False)
class StartupSummary(FieldMapping):
    """The headline figures of a :class:`StartupResult` (:meth:`StartupResult.summary`).

    Read as a mapping it has the keys of the dict it used to be, but for the figures
    that are None (``t_steady_s`` of a run that does not settle, ``peak_motor_torque_Nm``
    without a gear stage).

    Attributes
    ----------
    t_steady_s : float or None
        Time to the steady regime, s.
    peak_drive_torque_Nm, peak_motor_torque_Nm : float (or None)
        Largest drive torque on the link, and on the motor shaft, N m.
    omega_mean_rad_s, speed_dip_rad_s : float
        Mean speed and speed dip of the steady cycle, rad/s.
    phi_dip_deg : float
        Where the speed is least, deg.
    delta : float
        Coefficient of speed fluctuation of the steady cycle.

    Examples
    --------
    >>> s = StartupSummary(0.065, 72.0, 22.3, 45.46, 5.15, 170.0, 0.113)
    >>> s["t_steady_s"], s.delta
    (0.065, 0.113)
    >>> print(s)  # doctest: +NORMALIZE_WHITESPACE
    t_steady 0.065 s, peak drive torque 72 N m, peak motor torque 22.3 N m,
    omega_mean 45.46 rad/s, speed dip 5.15 rad/s at 170 deg, delta 0.113
    """

    t_steady_s: float | None
    peak_drive_torque_Nm: float
    peak_motor_torque_Nm: float | None
    omega_mean_rad_s: float
    speed_dip_rad_s: float
    phi_dip_deg: float
    delta: float

    def __str__(self) -> str:
        motor = f", peak motor torque {number(self.peak_motor_torque_Nm, 'N m')}" \
            if self.peak_motor_torque_Nm is not None else ""
        return (f"t_steady {number(self.t_steady_s, 's')}, peak drive torque "
                f"{number(self.peak_drive_torque_Nm, 'N m')}{motor}, omega_mean "
                f"{number(self.omega_mean_rad_s, 'rad/s')}, speed dip "
                f"{number(self.speed_dip_rad_s, 'rad/s')} at {number(self.phi_dip_deg, 'deg')}"
                f", delta {number(self.delta)}")

    def __repr__(self) -> str:
        return brief(self, str(self))


def startup(machine: ReducedMachine, t_end: float, *, phi0: float = 0.0, omega0: float = 0.0,
            tol: float = 0.01, load_window: tuple[float, float] | None = None,
            samples_per_second: float = 4000.0, integrator: str = "dop853",
            steady: SteadyCycle | None = None, **options) -> StartupResult:
    """Start the machine from rest (or ``omega0``) and measure the transient.

    Parameters
    ----------
    machine : ReducedMachine
        With a speed-dependent drive (a motor).
    t_end : float
        Length of the run, s.
    phi0, omega0 : float
        Initial position (rad) and speed (rad/s).
    tol : float
        Band around the steady cycle, as a fraction of its mean speed, that
        defines "steady".
    load_window : (float, float), optional
        Positions (rad, within one period) where the working load acts; the speed
        dip is then measured from the speed at the window start to the minimum
        after it.  Default: omega_max - omega_min of the steady cycle.
    samples_per_second : float
        Output sampling, 1/s.
    integrator : str
        As for :func:`run_reduced` (options passed on).
    steady : SteadyCycle, optional
        A steady cycle computed before (else found here).

    Returns
    -------
    StartupResult
    """
    if not t_end > 0:
        raise ModelError(f"t_end must be > 0 s, got {t_end!r}")
    te = np.linspace(0.0, float(t_end), max(2, int(samples_per_second * t_end) + 1))
    run = run_reduced(machine, t_end, phi0=phi0, omega0=omega0, integrator=integrator,
                      t_eval=te, **options)
    if steady is None:
        steady = steady_state(machine, omega_guess=max(run.omega[-1], 1e-6), phi0=phi0)
    per = machine.period
    ref = np.interp(run.phi, steady.phi, steady.omega, period=per)  # at the same position
    outside = np.flatnonzero(np.abs(run.omega - ref) > tol * steady.omega_mean)
    k = outside[-1] + 1 if outside.size else 0  # the first sample after the last one outside
    t_steady = float(run.t[k]) if k < run.t.size else None
    if load_window is None:
        dip = steady.omega_max - steady.omega_min
        phi_dip = steady.phi_at_min
    else:
        a, b = load_window  # the minimum may come after the window
        grid = a + np.linspace(0.0, (b - a) % per + 0.5 * per, 721)
        w = np.interp(grid, steady.phi, steady.omega, period=per)
        k = int(np.argmin(w))
        dip = w[0] - w[k]
        phi_dip = steady.phi[0] + (grid[k] - steady.phi[0]) % per
    msg = "" if t_steady is not None else (f"the speed has not settled within {tol:.3g} of "
                                           f"the steady cycle by t = {t_end:g} s")
    pm = None if run.M_motor is None else float(np.max(run.M_motor))
    return StartupResult(run=run, steady=steady, t_steady=t_steady,
                         peak_drive_torque=float(np.max(run.M_drive)), peak_motor_torque=pm,
                         speed_dip=float(dip), phi_dip=float(phi_dip),
                         omega_mean=steady.omega_mean, tol=float(tol),
                         status=Status.SUCCESS if t_steady is not None else Status.NOT_SETTLED,
                         message=msg, stats=run.stats)
