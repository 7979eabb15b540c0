"""Rigid bodies of a planar mechanism.

A body has its own frame: ``points`` and ``com`` are given in that frame, in m.
Its ``pose`` is where the frame sits in the initial *sketch* of the mechanism
(x, y in m, theta in rad); the sketch chooses the assembly branch, which is then
kept by continuity.  A pose may be omitted (None): the initial assembly then places
the body from its joints, the coordinates' initial values and the declared assembly
modes (:mod:`mechdyn.mechanism.placement`, :func:`mechdyn.kinematics.assembly.assemble`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

__all__ = ["Body", "Ground", "GROUND", "unknown_point"]

GROUND = "ground"


def unknown_point(ref, body: str, valid) -> str:
    """The message for a point ``ref`` that ``body``, with the point names ``valid``, lacks."""
    return (f"unknown point {ref!r} of body {body!r}; valid point names: "
            + ", ".join(repr(p) for p in valid))


def _vec(value, what: str, form: str = "a pair of numbers (x, y)") -> tuple[float, ...]:
    """``value`` as a tuple of floats with as many items as ``form`` names, or a ValueError."""
    try:
        arr = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.shape != (form.count(",") + 1,):
        raise ValueError(f"{what} must be {form}, got {value!r}")
    return tuple(float(v) for v in arr)


@dataclass(frozen=True)
class Body:
    """A rigid link.

    Parameters
    ----------
    name : str
        Unique name of the body.
    mass : float
        Mass in kg (zero is allowed: massless links).
    inertia : float
        Moment of inertia about the centre of mass, kg m^2 (zero is allowed).
    com : (float, float)
        Centre of mass in the body frame, m.
    points : mapping of str to (float, float)
        Named points in the body frame, m.
    pose : (float, float, float) or None
        Position (m) and angle (rad) of the body frame in the initial sketch; None
        (default): not given, the initial assembly finds it (the compiled model lists
        it in ``found_poses``).

    Examples
    --------
    >>> Body("crank", mass=1.0, points={"A": (0.04, 0.0)}).pose is None
    True
    >>> Body("crank", pose=(0.0, 0.0, 0.5)).pose
    (0.0, 0.0, 0.5)
    """

    name: str
    mass: float = 0.0
    inertia: float = 0.0
    com: tuple[float, float] = (0.0, 0.0)
    points: dict = field(default_factory=dict)
    pose: tuple[float, float, float] | None = None

    def __post_init__(self):
        object.__setattr__(self, "com", _vec(self.com, f"body {self.name!r}: com"))
        pts = {str(k): _vec(v, f"body {self.name!r}: point {k!r}")
               for k, v in dict(self.points).items()}
        object.__setattr__(self, "points", MappingProxyType(pts))
        if self.pose is not None:
            object.__setattr__(self, "pose", _vec(self.pose, f"body {self.name!r}: pose",
                                                  "(x, y, theta)"))
        object.__setattr__(self, "mass", float(self.mass))
        object.__setattr__(self, "inertia", float(self.inertia))

    def point(self, name: str) -> tuple[float, float]:
        """Coordinates of a named point in the body frame (``"com"`` is the centre of mass)."""
        if name == "com":
            return self.com
        return self.points[name]

    def point_names(self) -> list[str]:
        """Names of the points of this body, ``"com"`` included."""
        return ["com", *self.points]


@dataclass(frozen=True)
class Ground(Body):
    """The fixed frame. Its frame is the ground (world) frame; it has no mass."""

    name: str = GROUND

    def __post_init__(self):
        super().__post_init__()
        object.__setattr__(self, "pose", (0.0, 0.0, 0.0))
