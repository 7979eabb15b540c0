"""The source paper's dynamic case: the clutchless press idling (docs/references.md [1]).

The paper integrates the 2-DOF press (crank angle phi, rocker angle psi) over
T = 0.05 s in N = 40 steps of the linear-acceleration method, from
phi = -64.1 deg, psi = -46.34 deg, omega1 = 43.5 rad/s, rocker at rest
(the bundled model file ``clutchless_press.toml`` holds the geometry, masses
and that initial state).  What the paper does not give, the drive torque
``DRIVE_TORQUE`` and the spring ``SUPPORT_STIFFNESS`` that holds the ram in
idle, is filled in here as in ``clutchless_press_paper.toml`` (the same case as
a model file), whose header gives the reasons.
"""

from __future__ import annotations

from ..mechanism import Drive, Spring, TorqueSpeedCurve
from . import load

__all__ = ["DRIVE_TORQUE", "SUPPORT_STIFFNESS", "T_END", "WILSON_STEPS", "press_idle",
           "motor_curve"]

#: constant drive torque on the crank, N m (1.5 kW / 43.5 rad/s)
DRIVE_TORQUE = 34.5
#: stiffness of the elastic support of the ram in idle mode, N/m
SUPPORT_STIFFNESS = 1.0e7
#: the paper's interval, s, and number of steps of the linear-acceleration method
T_END = 0.05
WILSON_STEPS = 40


def motor_curve():
    """A linear stand-in for a motor characteristic at the crank (assumption): 34.5 N m at
    43.5 rad/s, zero at 50 rad/s (no-load speed), 265 N m at stall, braking above 50 rad/s.
    Used for runs longer than the paper's 0.05 s, where a constant torque would speed the
    unloaded press up without bound."""
    return TorqueSpeedCurve((0.0, 43.5, 50.0, 60.0), (265.0, 34.5, 0.0, -53.0))


def press_idle(mechanism=None, *, drive_torque=DRIVE_TORQUE,
               support_stiffness: float | None = SUPPORT_STIFFNESS):
    """The clutchless press with the drive torque and the idle support of the ram.

    Parameters
    ----------
    mechanism : Mechanism, optional
        The press (default: the bundled ``clutchless_press`` example, loaded anew).
    drive_torque : float or TorqueSpeedCurve
        Torque on the crank coordinate ``phi``: constant (N m) or a characteristic
        (e.g. :func:`motor_curve`).
    support_stiffness : float or None
        Stiffness of the ram's support spring, N/m (along the ram axis from a ground
        point 1 m beyond the pin C, its free length set so that it carries the ram's
        weight at the initial position); None leaves the ram free (it falls).

    Returns
    -------
    Mechanism
    """
    if mechanism is None:
        mechanism = load("clutchless_press")
    if not callable(drive_torque):
        drive_torque = float(drive_torque)
    mechanism.add(Drive("motor", "phi", drive_torque))
    if support_stiffness:
        slider = mechanism.bodies["slider"]
        x_c, y_c, _ = slider.pose
        weight = slider.mass * abs(mechanism.gravity[0])
        mechanism.add_ground({**mechanism.ground.points, "support": (x_c + 1.0, y_c)})
        mechanism.add(Spring("ram_support", "ground", "support", "slider", (0.0, 0.0),
                             stiffness=float(support_stiffness),
                             free_length=1.0 - weight / float(support_stiffness)))
    return mechanism
