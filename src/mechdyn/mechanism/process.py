"""Process (working) loads: the punch force of a press and other technological forces.

These helpers build ordinary :class:`~mechdyn.mechanism.load.Force` elements whose
magnitude depends on the position of a point, on time, or on both; the dynamics
(``mechdyn.model.forces``) evaluates them like any other load, and the
kinetostatic analysis evaluates them for a whole cycle at once (the magnitude
objects here are *vectorized*: they accept a context whose attributes are arrays).

Nothing here knows about solvers: a magnitude receives a context with the
methods ``point(body, point)`` and ``velocity(body, point)`` (see
:class:`mechdyn.model.forces.LoadContext`) and returns a number, or an array
for a batch of positions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .load import Force, Table, pulse

__all__ = ["StrokeWindow", "punch_load", "position_load", "time_pulse_load"]

_AXES = {"x": 0, "y": 1}


@dataclass(frozen=True)
class StrokeWindow:
    """A magnitude that acts only near the end of a point's working stroke.

    The force is ``magnitude`` while the point is within ``travel`` of the stroke
    end ``end`` (and, with ``approaching_only``, while it still moves towards
    it), and zero elsewhere.  With ``ramp`` > 0 it rises linearly over the first
    ``ramp`` metres of the window (a trapezoidal pulse in position).

    Parameters
    ----------
    magnitude : float
        Value inside the window (N).
    body : str
        The body that carries the point (e.g. the slider).
    point : str or (float, float)
        The point whose position is watched (name or body-frame coordinates, m).
    end : float
        Value of the watched coordinate of the point at the stroke end (m),
        e.g. the height of the punch at bottom dead centre.
    travel : float
        Length of the window before the stroke end (m), e.g. 0.003.
    coordinate : {"x", "y"}
        Which ground coordinate of the point is watched.
    towards : {-1, +1}
        Direction in which the coordinate moves during the working stroke:
        -1 when the stroke ends at a minimum (a punch moving down to BDC).
    approaching_only : bool
        If True the window is open only while the point moves towards the end
        (before the dead centre), not on the way back.
    ramp : float
        Rise length of the force at the window entry (m); 0 gives a sharp step.

    Notes
    -----
    The distance to the end is ``dist = (c - end) * (-towards)`` (>= 0 before the
    end); the window is ``-tol <= dist <= travel``, with ``tol`` = 1e-12 m so that
    the dead centre itself still belongs to the window when ``approaching_only``
    is False.
    """

    magnitude: float
    body: str
    point: object
    end: float
    travel: float
    coordinate: str = "y"
    towards: int = -1
    approaching_only: bool = True
    ramp: float = 0.0

    #: tells the kinetostatic analysis that the callable accepts array contexts
    vectorized = True

    def __post_init__(self):
        if self.coordinate not in _AXES:
            raise ValueError(f"stroke window: coordinate must be 'x' or 'y', "
                             f"got {self.coordinate!r}")
        if self.towards not in (-1, 1):
            raise ValueError(f"stroke window: towards must be -1 or +1, got {self.towards!r}")
        if not self.travel > 0:
            raise ValueError(f"stroke window: travel must be > 0 m, got {self.travel!r}")
        if self.ramp < 0:
            raise ValueError(f"stroke window: ramp must be >= 0 m, got {self.ramp!r}")

    def factor(self, c, v) -> np.ndarray:
        """Shape factor in [0, 1] for coordinate ``c`` (m) and its rate ``v`` (m/s)."""
        c = np.asarray(c, dtype=float)
        v = np.asarray(v, dtype=float)
        dist = (c - self.end) * (-self.towards)
        inside = (dist >= -1e-12) & (dist <= self.travel)
        if self.approaching_only:
            inside &= v * self.towards > 0
        shape = np.ones_like(dist)
        if self.ramp > 0:
            shape = np.clip((self.travel - dist) / self.ramp, 0.0, 1.0)
        return np.where(inside, shape, 0.0)

    def __call__(self, ctx):
        k = _AXES[self.coordinate]
        p = np.asarray(ctx.point(self.body, self.point))
        v = np.asarray(ctx.velocity(self.body, self.point))
        out = self.magnitude * self.factor(p[..., k], v[..., k])
        return float(out) if np.ndim(out) == 0 else out


def punch_load(name: str, body: str, point, magnitude: float, *, end: float,
               travel: float = 0.003, coordinate: str = "y", towards: int = -1,
               approaching_only: bool = True, ramp: float = 0.0) -> Force:
    """The working force of a punch (or any tool) near the end of its stroke.

    A positive ``magnitude`` resists the working stroke: the force points
    opposite to ``towards`` along the watched ground axis (upwards for a punch
    moving down).

    Parameters
    ----------
    name : str
        Name of the load.
    body, point :
        Where the force acts (e.g. ``"slider"``, ``"F"``).
    magnitude : float
        Force while the punch works, N (> 0 resists the motion).
    end : float
        Ground coordinate (m) of the point at the end of the stroke (BDC).
    travel : float
        Length (m) of the working window before the end (default 3 mm).
    coordinate, towards, approaching_only, ramp :
        See :class:`StrokeWindow`.

    Returns
    -------
    Force
        A :class:`~mechdyn.mechanism.load.Force` with a :class:`StrokeWindow`
        magnitude and a fixed ground direction.

    Examples
    --------
    >>> f = punch_load("punch", "slider", "F", 5000.0, end=-0.40)
    >>> [float(v) for v in f.direction]   # resists a downward stroke
    [0.0, 1.0]
    """
    win = StrokeWindow(float(magnitude), body, point, float(end), float(travel), coordinate,
                       int(towards), bool(approaching_only), float(ramp))
    d = (0.0, -float(towards)) if coordinate == "y" else (-float(towards), 0.0)
    return Force(name, body, point, win, d, "ground")


def position_load(name: str, body: str, point, positions, values, *, coordinate: str = "y",
                  direction=(0.0, 1.0), frame: str = "ground",
                  outside: float | None = 0.0) -> Force:
    """A force whose magnitude is tabulated against a ground coordinate of its point.

    Parameters
    ----------
    positions, values : sequence of float
        Table of the point's ground ``coordinate`` (m, increasing) and the
        force magnitude there (N), linearly interpolated.
    outside : float or None
        Value outside the table (None holds the end values).
    direction, frame :
        As for :class:`~mechdyn.mechanism.load.Force`.
    """
    if coordinate not in _AXES:
        raise ValueError(f"position load {name!r}: coordinate must be 'x' or 'y', "
                         f"got {coordinate!r}")
    if not isinstance(point, str):
        raise ValueError(f"position load {name!r}: the watched point must be a named point "
                         f"of body {body!r} (tables refer to 'body.point.{coordinate}')")
    tab = Table(tuple(positions), tuple(values), f"{body}.{point}.{coordinate}", outside)
    return Force(name, body, point, tab, tuple(direction), frame)


def time_pulse_load(name: str, body: str, point, magnitude: float, start: float,
                    duration: float, *, direction=(0.0, 1.0), frame: str = "ground",
                    ramp: float = 0.0) -> Force:
    """An impulse: ``magnitude`` (N) for ``duration`` seconds from ``start`` (s).

    Built on :func:`mechdyn.mechanism.load.pulse`; the impulse is
    ``magnitude * duration`` N s (plus the ramps).
    """
    return Force(name, body, point, pulse(float(magnitude), float(start), float(duration),
                                          "t", ramp), tuple(direction), frame)
