"""Running the reduced equation of motion: time histories and the energy form.

``J(phi) domega/dt + 1/2 omega^2 dJ/dphi = M_red(phi, omega, t)`` of a
:class:`~mechdyn.dynamics.reduced_machine.ReducedMachine`, integrated in time
with :mod:`mechdyn.integrate`, or, when M_red depends on the position only,
solved by its energy form ``J omega^2 / 2 = J_0 omega_0^2 / 2 + integral M_red dphi``.

Public names
------------
ReducedRun
    A time history of the reduced machine (read-only arrays).
run_reduced, energy_speed
    Time integration of the reduced equation and the energy form.

All three are importable from :mod:`mechdyn.dynamics.reduced_machine` as well.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..integrate import solve

if TYPE_CHECKING:
    from .reduced_machine import ReducedMachine

__all__ = ["ReducedRun", "run_reduced", "energy_speed"]


def _frozen(a) -> np.ndarray:
    a = np.array(a, dtype=float, copy=True)
    a.setflags(write=False)
    return a


@dataclass(frozen=True)
class ReducedRun:
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

    t: np.ndarray
    phi: np.ndarray
    omega: np.ndarray
    epsilon: np.ndarray
    J: np.ndarray
    M: np.ndarray
    M_drive: np.ndarray
    M_motor: np.ndarray | None = None
    status: str = "success"
    message: str = ""
    events: tuple = ()
    stats: dict = field(default_factory=dict)

    def to_dataframe(self):
        """Columns ``t_s, phi_deg, omega_rad_s, epsilon_rad_s2, J_kgm2, M_red_Nm, ...``."""
        import pandas as pd

        cols = {"t_s": self.t, "phi_deg": np.degrees(self.phi), "phi_rad": self.phi,
                "omega_rad_s": self.omega, "epsilon_rad_s2": self.epsilon,
                "J_total_kgm2": self.J, "M_red_Nm": self.M, "M_drive_Nm": self.M_drive}
        if self.M_motor is not None:
            cols["M_motor_Nm"] = self.M_motor
        return pd.DataFrame(cols)


def _history(machine: ReducedMachine, t, phi, omega, **kw) -> ReducedRun:
    n = t.size
    J = np.empty(n)
    M = np.empty(n)
    eps = np.empty(n)
    md = np.empty(n)
    mm = np.empty(n) if machine.drive is not None else None
    for i in range(n):
        j, dj = machine.inertia(phi[i])
        J[i] = j
        M[i] = machine.torque(t[i], phi[i], omega[i])
        eps[i] = (M[i] - 0.5 * dj * omega[i] ** 2) / j
        md[i] = machine.drive_torque(omega[i])
        if mm is not None:
            mm[i] = machine.motor_torque(omega[i])
    return ReducedRun(_frozen(t), _frozen(phi), _frozen(omega), _frozen(eps), _frozen(J),
                      _frozen(M), _frozen(md), None if mm is None else _frozen(mm), **kw)


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
    return _history(machine, sol.t, sol.q[:, 0], sol.qdot[:, 0],
                    status="success" if sol.status == "success" else sol.status,
                    events=tuple(sol.events), stats=dict(sol.stats))


def energy_speed(machine: ReducedMachine, phi, *, phi0: float = 0.0, omega0: float,
                 t: float = 0.0, rtol: float = 1e-11) -> np.ndarray:
    """Speed from the energy form ``J omega^2/2 = J_0 omega_0^2/2 + int M dphi``.

    Valid when the reduced torque depends on the position only: it is evaluated
    at time ``t`` and speed ``omega0``.

    Parameters
    ----------
    phi : array_like, shape (n,)
        Positions, rad (any order, on either side of ``phi0``).
    phi0, omega0 : float
        Reference position (rad) and speed there (rad/s).

    Returns
    -------
    ndarray, shape (n,)
        omega(phi), rad/s; NaN where the kinetic energy would be negative (the
        machine cannot reach that position).
    """
    from scipy.integrate import solve_ivp

    phi = np.asarray(phi, dtype=float).reshape(-1)
    j0, _ = machine.inertia(phi0)
    out = np.empty_like(phi)
    for sign in (1.0, -1.0):
        sel = (phi >= phi0) if sign > 0 else (phi < phi0)
        if not np.any(sel):
            continue
        target = phi[sel]
        end = target.max() if sign > 0 else target.min()
        if end == phi0:
            w = np.zeros(target.size)
        else:
            sol = solve_ivp(lambda p, y: [machine.torque(t, p, omega0)], (phi0, end), [0.0],
                            method="DOP853", rtol=rtol, atol=1e-12 * max(1.0, j0 * omega0**2),
                            dense_output=True)
            w = sol.sol(target)[0]
        jt = machine.inertia_along(target)
        e2 = j0 * omega0**2 + 2.0 * w
        with np.errstate(invalid="ignore"):
            out[sel] = np.where(e2 >= 0, np.sqrt(np.maximum(e2, 0) / jt), np.nan)
    return out
