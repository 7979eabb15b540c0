"""Start-up of a reduced machine from rest, and its load transients.

Public names
------------
StartupResult, startup
    The run from rest (or a given speed) by the motor, the time to settle on the
    steady cycle, peak drive and motor torques and the speed dip under load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError, Status
from .flywheel import SteadyCycle, steady_state
from .reduced_machine import ReducedMachine, ReducedRun, run_reduced

__all__ = ["StartupResult", "startup"]


@dataclass(frozen=True)
class StartupResult:
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
    status: str = "success"
    message: str = ""
    events: tuple = ()
    stats: dict = field(default_factory=dict)

    def to_dataframe(self):
        """The run's time history (see
        :meth:`~mechdyn.dynamics.reduced_machine.ReducedRun.to_dataframe`)."""
        return self.run.to_dataframe()

    def summary(self) -> dict:
        """The headline figures in SI units."""
        return {"t_steady_s": self.t_steady, "peak_drive_torque_Nm": self.peak_drive_torque,
                "peak_motor_torque_Nm": self.peak_motor_torque,
                "omega_mean_rad_s": self.omega_mean, "speed_dip_rad_s": self.speed_dip,
                "phi_dip_deg": math.degrees(self.phi_dip), "delta": self.steady.delta}


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
        As for :func:`~mechdyn.dynamics.reduced_machine.run_reduced` (options passed on).
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
    # deviation from the steady cycle at the same position
    per = machine.period

    def wrap(p):  # the position within the steady cycle
        return steady.phi[0] + (p - steady.phi[0]) % per

    ref = np.interp(wrap(run.phi), steady.phi, steady.omega)
    dev = np.abs(run.omega - ref) / steady.omega_mean
    outside = np.flatnonzero(dev > tol)
    if outside.size == 0:
        t_steady = float(run.t[0])
    elif outside[-1] == run.t.size - 1:
        t_steady = None
    else:
        t_steady = float(run.t[outside[-1] + 1])
    if load_window is None:
        dip = steady.omega_max - steady.omega_min
        phi_dip = steady.phi_at_min
    else:
        a, b = load_window
        pa = wrap(a)
        w_a = float(np.interp(pa, steady.phi, steady.omega))
        pb = pa + ((b - a) % per) + 0.5 * per  # the minimum may come after the window
        grid = np.linspace(pa, pb, 721)
        w = np.interp(wrap(grid), steady.phi, steady.omega)
        k = int(np.argmin(w))
        dip = w_a - float(w[k])
        phi_dip = float(wrap(grid[k]))
    msg = "" if t_steady is not None else (f"the speed has not settled within {tol:.3g} of "
                                           f"the steady cycle by t = {t_end:g} s")
    pm = None if run.M_motor is None else float(np.max(run.M_motor))
    return StartupResult(run=run, steady=steady, t_steady=t_steady,
                         peak_drive_torque=float(np.max(run.M_drive)), peak_motor_torque=pm,
                         speed_dip=float(dip), phi_dip=float(phi_dip),
                         omega_mean=steady.omega_mean, tol=float(tol),
                         status=Status.SUCCESS if t_steady is not None else Status.NOT_SETTLED,
                         message=msg, stats=dict(run.stats))
