"""Generalized coordinates, declared by name and meaning."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Coordinate", "COORDINATE_KINDS"]

#: kind -> what it measures
COORDINATE_KINDS = {
    "angle": "absolute angle of a body, rad (theta_body + offset)",
    "relative_angle": "relative angle of a revolute joint, rad "
                      "(theta_child - theta_parent + offset)",
    "travel": "travel of a prismatic joint along its axis, m (from the axis point, + offset)",
}


@dataclass(frozen=True)
class Coordinate:
    """One generalized coordinate.

    Parameters
    ----------
    name : str
        Name used in results and on the command line (``phi``, ``psi``, ...).
    kind : {"angle", "relative_angle", "travel"}
        What the coordinate measures.
    body : str
        For ``kind="angle"``: the body whose absolute angle it is.
    joint : str
        For ``kind="relative_angle"`` (a revolute) and ``kind="travel"`` (a prismatic).
    offset : float
        Added to the measured value (rad or m), so that e.g. a crank angle can be
        measured from a line other than the body's x axis.
    """

    name: str
    kind: str = "angle"
    body: str | None = None
    joint: str | None = None
    offset: float = 0.0

    @property
    def is_angle(self) -> bool:
        return self.kind in ("angle", "relative_angle")
