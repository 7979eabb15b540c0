"""Joints: the bilateral constraints between two bodies.

A joint joins a *parent* body to a *child* body; its reaction is reported as the
force (and moment) on the child from the parent (see ``docs/notation.md``).
Points are given either by name (a named point of the body, or ``"com"``) or
as coordinates (x, y) in the body frame, in m.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Joint", "Revolute", "Prismatic", "Lock", "PointRef", "FRICTION_FIELDS",
           "ELASTIC_FIELDS", "has_friction"]

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

    Parameters
    ----------
    friction : float
        Coulomb coefficient mu of the pin (0: frictionless). The friction moment on
        the child is mu * pin_radius * |R| against the relative rotation (friction
        circle), R the pin's reaction force, N.
    pin_radius : float
        Radius of the pin, m (needed when ``friction`` > 0).
    viscous : float
        Viscous moment coefficient, N*m*s/rad, against the relative angular velocity.
    smoothing : float
        0 for true stick-slip; otherwise the relative angular velocity, rad/s, over
        which the Coulomb moment is regularised (tanh).
    compliance : float
        Compliance of the pin, m/N (0: rigid): its deflection per unit reaction force,
        the same in every direction.  Used where the pin is one of redundant joints
        (statically indeterminate reactions): the kinetostatic analysis then shares the
        reactions by the compliances (least complementary energy) instead of by the
        minimum norm (``docs/indeterminacy.md``).
    """

    parent_point: PointRef = (0.0, 0.0)
    child_point: PointRef = (0.0, 0.0)
    friction: float = 0.0
    pin_radius: float = 0.0
    viscous: float = 0.0
    smoothing: float = 0.0
    compliance: float = 0.0
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
    friction : float
        Coulomb coefficient mu of the guide (0: frictionless): a force against the
        sliding of magnitude mu times the sum of the normal loads.
    guide_length : float
        Length of the guide (gib), m, centred on ``child_point``: 0 takes the normal
        force N as one load (friction mu |N|); > 0 resolves N and the transverse
        moment into the two edge loads N/2 -+ M/L that the gibs carry (friction
        mu (|N/2 - M/L| + |N/2 + M/L|)).
    viscous : float
        Viscous force coefficient, N*s/m, against the sliding velocity.
    smoothing : float
        0 for true stick-slip; otherwise the sliding speed, m/s, over which the
        Coulomb force is regularised (tanh).

    Two equations; reaction: a force normal to the line and a moment.
    """

    parent_point: PointRef = (0.0, 0.0)
    axis: tuple[float, float] = (1.0, 0.0)
    child_point: PointRef = (0.0, 0.0)
    angle: float | None = None
    friction: float = 0.0
    guide_length: float = 0.0
    viscous: float = 0.0
    smoothing: float = 0.0
    n_equations = 2


#: the friction fields of each joint type: (field, unit kind of the model file)
FRICTION_FIELDS: dict[str, tuple[tuple[str, str], ...]] = {
    "revolute": (("friction", "dimensionless"), ("pin_radius", "length"),
                 ("viscous", "rotational_damping"), ("smoothing", "angular_velocity")),
    "prismatic": (("friction", "dimensionless"), ("guide_length", "length"),
                  ("viscous", "damping"), ("smoothing", "velocity")),
}


#: the elastic fields of each joint type: (field, unit kind of the model file)
ELASTIC_FIELDS: dict[str, tuple[tuple[str, str], ...]] = {
    "revolute": (("compliance", "compliance"),),
    "prismatic": (),
}


def has_friction(joint: Joint) -> bool:
    """Whether a joint dissipates: a Coulomb coefficient or a viscous term set."""
    return getattr(joint, "friction", 0.0) > 0.0 or getattr(joint, "viscous", 0.0) > 0.0


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
