"""Joints: the bilateral constraints between two bodies.

A joint joins a *parent* body to a *child* body; its reaction is reported as the
force (and moment) on the child from the parent (see ``docs/notation.md``).
Points are given either by name (a named point of the body, or ``"com"``) or
as coordinates (x, y) in the body frame, in m.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Joint", "Revolute", "Prismatic", "Lock", "PointRef"]

PointRef = str | tuple[float, float]


@dataclass(frozen=True)
class Joint:
    """Base of all joints.

    Parameters
    ----------
    name : str
        Unique name of the joint.
    parent, child : str
        Names of the two bodies (``"ground"`` for the frame).
    """

    name: str
    parent: str
    child: str

    #: number of constraint equations the joint adds
    n_equations = 0

    @property
    def bodies(self) -> tuple[str, str]:
        return (self.parent, self.child)


@dataclass(frozen=True)
class Revolute(Joint):
    """A pin: ``parent_point`` of the parent coincides with ``child_point`` of the child.

    Two equations; reaction: a force (Fx, Fy) on the child at the pin.
    """

    parent_point: PointRef = (0.0, 0.0)
    child_point: PointRef = (0.0, 0.0)
    n_equations = 2


@dataclass(frozen=True)
class Prismatic(Joint):
    """The child slides along a line fixed in the parent, without relative rotation.

    Parameters
    ----------
    parent_point : point
        A point of the line, in the parent frame (origin of the travel).
    axis : (float, float)
        Direction of the line in the parent frame (need not be unit length).
    child_point : point
        The point of the child that stays on the line.
    angle : float or None
        Relative angle theta_child - theta_parent held by the joint, rad; None
        takes it from the sketch poses.

    Two equations; reaction: a force normal to the line and a moment.
    """

    parent_point: PointRef = (0.0, 0.0)
    axis: tuple[float, float] = (1.0, 0.0)
    child_point: PointRef = (0.0, 0.0)
    angle: float | None = None
    n_equations = 2


@dataclass(frozen=True)
class Lock(Joint):
    """A weld between two bodies, which can be engaged and released.

    Parameters
    ----------
    engaged : bool
        Whether the lock is active in the initial mode.
    offset : (float, float, float) or None
        Pose of the child frame in the parent frame held by the lock (m, m, rad);
        None takes it from the sketch poses (or, for a lock engaged during a run,
        from the state at the moment it engages).

    Three equations; reaction: a force at the child frame's origin and a moment.
    """

    engaged: bool = True
    offset: tuple[float, float, float] | None = None
    n_equations = 3
