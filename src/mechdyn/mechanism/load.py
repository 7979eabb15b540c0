"""Applied loads: springs, dampers, forces and torques (gravity is ``Mechanism.gravity``).

A load's magnitude is a *value*: a constant (SI), a :class:`Table` interpolated in
time, a coordinate, a coordinate rate or a point coordinate, or a callable that
receives a :class:`mechdyn.dynamics.forces.LoadContext` (attributes ``t``, ``q``,
``qdot`` and methods ``coord``, ``rate``, ``point``, ``velocity``) and returns a
float.  The elements are frozen data; ``mechdyn.dynamics.forces`` evaluates them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Table", "Spring", "RotarySpring", "Force", "Torque", "Value", "pulse"]


@dataclass(frozen=True)
class Table:
    """A tabulated function y(variable), linearly interpolated, held constant outside.

    Parameters
    ----------
    x, y : sequence of float
        Abscissae (increasing) and values, SI.
    variable : str
        ``"t"`` (time, s), a coordinate name (``"phi"``), its rate (``"phi_dot"``),
        or a point coordinate ``"body.point.x"`` / ``"body.point.y"`` (m).
    outside : float or None
        Value outside the table; None holds the end values.
    """

    x: tuple
    y: tuple
    variable: str = "t"
    outside: float | None = None

    def __post_init__(self):
        x = np.asarray(self.x, dtype=float).reshape(-1)
        y = np.asarray(self.y, dtype=float).reshape(-1)
        if x.size < 2 or x.size != y.size:
            raise ValueError(f"table over {self.variable!r}: x and y need the same length >= 2, "
                             f"got {x.size} and {y.size}")
        if not np.all(np.diff(x) > 0):
            raise ValueError(f"table over {self.variable!r}: x values must increase strictly")
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
            raise ValueError(f"table over {self.variable!r}: values must be finite")
        object.__setattr__(self, "x", tuple(x))
        object.__setattr__(self, "y", tuple(y))

    def __call__(self, s):
        """The value at ``s`` (a float, or an array of the shape of an array ``s``)."""
        s = np.asarray(s, dtype=float)
        y = np.interp(s, self.x, self.y)
        if self.outside is not None:
            y = np.where((s < self.x[0]) | (s > self.x[-1]), self.outside, y)
        return float(y) if y.ndim == 0 else y


Value = float | Table | Callable


def pulse(magnitude: float, start: float, duration: float, variable: str = "t",
          ramp: float = 0.0) -> Table:
    """A rectangular (or trapezoidal, with ``ramp``) pulse as a :class:`Table`.

    ``magnitude`` acts for ``start <= variable <= start + duration``; zero elsewhere.
    With ``ramp`` > 0 the value rises and falls linearly over that width.
    """
    if duration <= 0:
        raise ValueError(f"pulse: duration must be > 0, got {duration!r}")
    r = max(float(ramp), 1e-12 * max(abs(duration), 1.0))
    xs = (start - r, start, start + duration, start + duration + r)
    return Table(xs, (0.0, magnitude, magnitude, 0.0), variable, outside=0.0)


@dataclass(frozen=True)
class Spring:
    """Linear spring and damper between two points (tension positive).

    Force along the line P1-P2: f = stiffness (L - free_length) + damping dL/dt + preload;
    it pulls the points together when f > 0.

    Parameters
    ----------
    name : str
    body1, point1, body2, point2 : str and point (name or (x, y) in the body frame, m)
    stiffness : float, N/m
    free_length : float, m
    damping : float, N s/m
    preload : float, N (tension at the free length)
    """

    name: str
    body1: str
    point1: object
    body2: str
    point2: object
    stiffness: float = 0.0
    free_length: float = 0.0
    damping: float = 0.0
    preload: float = 0.0


@dataclass(frozen=True)
class RotarySpring:
    """Rotational spring/damper in a revolute joint.

    Torque on the child: -(stiffness (dtheta - free_angle) + damping dtheta/dt + preload),
    the opposite on the parent, with dtheta = theta_child - theta_parent.
    """

    name: str
    joint: str
    stiffness: float = 0.0
    free_angle: float = 0.0
    damping: float = 0.0
    preload: float = 0.0


@dataclass(frozen=True)
class Force:
    """A force of given magnitude at a body point.

    Parameters
    ----------
    name : str
    body : str
    point : point (name or (x, y) in the body frame)
    magnitude : value
        N; constant, :class:`Table` or callable (see module docstring).
    direction : (float, float)
        Direction of a positive magnitude (normalised).
    frame : {"ground", "body"}
        Whether ``direction`` is fixed in the ground or follows the body.
    """

    name: str
    body: str
    point: object = "com"
    magnitude: object = 0.0
    direction: tuple = (1.0, 0.0)
    frame: str = "ground"

    def __post_init__(self):
        d = np.asarray(self.direction, dtype=float).reshape(-1)
        if d.shape != (2,) or not np.all(np.isfinite(d)) or np.hypot(*d) == 0:
            raise ValueError(f"force {self.name!r}: direction must be a non-zero (x, y), "
                             f"got {self.direction!r}")
        object.__setattr__(self, "direction", tuple(d / np.hypot(*d)))
        if self.frame not in ("ground", "body"):
            raise ValueError(f"force {self.name!r}: frame must be 'ground' or 'body', "
                             f"got {self.frame!r}")


@dataclass(frozen=True)
class Torque:
    """A torque (N m, CCW positive) on a body, the opposite on ``reaction_body`` if given."""

    name: str
    body: str
    magnitude: object = 0.0
    reaction_body: str | None = None


@dataclass(frozen=True)
class _Extra:
    data: dict = field(default_factory=dict)
