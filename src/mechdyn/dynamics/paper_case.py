"""Moved to :mod:`mechdyn.examples.paper_case`: the source paper's case is an example
(it loads a bundled model file), not dynamics.  Its names are re-exported here so
that ``from mechdyn.dynamics.paper_case import press_idle`` keeps working; this is
the one import of an example by dynamics/, declared in the import contracts
(pyproject.toml).
"""

from ..examples.paper_case import (
    DRIVE_TORQUE,
    SUPPORT_STIFFNESS,
    T_END,
    WILSON_STEPS,
    motor_curve,
    press_idle,
)

__all__ = ["DRIVE_TORQUE", "SUPPORT_STIFFNESS", "T_END", "WILSON_STEPS", "press_idle",
           "motor_curve"]
