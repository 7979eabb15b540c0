"""Applied loads: springs, dampers, forces and torques (gravity is ``Mechanism.gravity``).

A load's magnitude is a *value*: a constant (SI), a :class:`Table` interpolated in
time, a coordinate, a coordinate rate or a point coordinate (optionally periodic in
it, e.g. over the crank angle every revolution), or a callable that
receives a :class:`mechdyn.model.forces.LoadContext` (attributes ``t``, ``q``,
``qdot`` and methods ``coord``, ``rate``, ``point``, ``velocity``) and returns a
float.  The elements are frozen data; ``mechdyn.model.forces`` evaluates them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = ["Table", "Spring", "Bushing", "RotarySpring", "Force", "Torque", "Value", "pulse"]


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
    period : float or None
        If given, the table repeats: the variable s is first wrapped into
        ``[x[0], x[0] + period)`` (s -> x[0] + (s - x[0]) mod period), then
        interpolated; on ``(x[-1], x[0] + period)`` the end value (or ``outside``)
        applies.  In the variable's unit (rad for an angle: ``2 pi`` for once per
        revolution).  Must be > 0 and >= ``x[-1] - x[0]``.  None: not periodic.

    Raises
    ------
    ValueError
        For unequal or too short x and y, x not strictly increasing, values that
        are not finite, or a bad ``period``; the message names the variable.

    Examples
    --------
    A punch force over the crank angle, 120 to 150 deg of every revolution:

    >>> import numpy as np
    >>> f = Table(np.deg2rad([120, 121, 149, 150]), [0, 5e3, 5e3, 0], "phi",
    ...           outside=0.0, period=2 * np.pi)
    >>> f(np.deg2rad(135.0 + 3 * 360.0)), f(np.deg2rad(135.0 - 360.0))
    (5000.0, 5000.0)
    """

    x: tuple
    y: tuple
    variable: str = "t"
    outside: float | None = None
    period: float | None = None

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
        if self.period is not None:
            per = self.period
            if isinstance(per, bool) or not isinstance(per, int | float | np.integer
                                                       | np.floating):
                raise ValueError(f"table over {self.variable!r}: period must be a number, "
                                 f"got {per!r}")
            per = float(per)
            span = float(x[-1] - x[0])
            if not (math.isfinite(per) and per > 0):
                raise ValueError(f"table over {self.variable!r}: period must be finite and "
                                 f"> 0, got {per!r}")
            if per < span * (1.0 - 1e-12):
                raise ValueError(f"table over {self.variable!r}: period {per!r} is shorter "
                                 f"than the table's span x[-1] - x[0] = {span!r}")
            object.__setattr__(self, "period", per)
        object.__setattr__(self, "x", tuple(x))
        object.__setattr__(self, "y", tuple(y))

    def wrap(self, s):
        """The variable ``s`` wrapped into ``[x[0], x[0] + period)`` (``s`` itself if
        the table is not periodic); float or array like ``s``."""
        if self.period is None:
            return s
        x0, per = self.x[0], self.period
        u = np.mod(np.asarray(s, dtype=float) - x0, per)
        u = np.where(u >= per, 0.0, u)  # mod of a tiny negative number rounds up to per
        return x0 + u

    def __call__(self, s):
        """The value at ``s`` (a float, or an array of the shape of an array ``s``)."""
        s = np.asarray(self.wrap(np.asarray(s, dtype=float)))
        y = np.interp(s, self.x, self.y)
        if self.outside is not None:
            y = np.where((s < self.x[0]) | (s > self.x[-1]), self.outside, y)
        return float(y) if y.ndim == 0 else y


Value = float | Table | Callable


def pulse(magnitude: float, start: float, duration: float, variable: str = "t",
          ramp: float = 0.0, period: float | None = None) -> Table:
    """A rectangular (or trapezoidal, with ``ramp``) pulse as a :class:`Table`.

    Parameters
    ----------
    magnitude : float
        Value during the pulse, SI.
    start, duration : float
        ``magnitude`` acts for ``start <= variable <= start + duration``; zero
        elsewhere.  In the variable's unit.
    variable : str
        As for :class:`Table`.
    ramp : float
        With ``ramp`` > 0 the value rises (before ``start``) and falls (after
        ``start + duration``) linearly over that width.
    period : float or None
        Repeat the pulse every ``period`` of the variable (see :class:`Table`);
        it must be > ``duration`` and >= ``duration + 2 ramp``.

    Returns
    -------
    Table
    """
    if duration <= 0:
        raise ValueError(f"pulse over {variable!r}: duration must be > 0, got {duration!r}")
    if ramp < 0:
        raise ValueError(f"pulse over {variable!r}: ramp must be >= 0, got {ramp!r}")
    r = max(float(ramp), 1e-12 * max(abs(duration), 1.0))
    if period is not None:
        if not period > 0 or period <= duration or period < duration + 2 * float(ramp):
            raise ValueError(f"pulse over {variable!r}: period must be > duration and >= "
                             f"duration + 2 ramp = {duration + 2 * float(ramp)!r}, "
                             f"got {period!r}")
        r = min(r, 0.5 * (period - duration))  # the vanishing ramps of a rectangular pulse
    xs = (start - r, start, start + duration, start + duration + r)
    return Table(xs, (0.0, magnitude, magnitude, 0.0), variable, outside=0.0, period=period)


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
class Bushing:
    """Linear bushing: a point of ``body2`` held elastically to a point of ``body1`` along
    the two axes of ``body1``'s frame (the ground's for a mount on the floor).

    With d = A1^T (r2 - r1) the offset of point2 from point1 in body1's axes (m) and
    d' its rate, the force on ``body2`` at point2 is -A1 (kx dx + cx dx', ky dy + cy dy')
    and its opposite acts on ``body1`` at the same place (so the pair has no moment:
    a stiff housing of body1 around point2).  Unloaded where the two points coincide;
    it stores 0.5 (kx dx^2 + ky dy^2).  Unlike a :class:`Spring` it has no direction to
    turn with the deflection, so an isolator under a static load keeps its stiffness
    exactly and its small deflection is computed without cancellation.

    Parameters
    ----------
    name : str
    body1, point1, body2, point2 : str and point (name or (x, y) in the body frame, m)
    kx, ky : float
        Stiffness along body1's x and y axes, N/m (>= 0).
    cx, cy : float
        Damping along them, N s/m (>= 0).

    Examples
    --------
    >>> Bushing("mount", "ground", (0.5, 0.0), "base", (0.5, 0.0), kx=1e6, ky=2e6).ky
    2000000.0
    """

    name: str
    body1: str
    point1: object
    body2: str
    point2: object
    kx: float = 0.0
    ky: float = 0.0
    cx: float = 0.0
    cy: float = 0.0


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
