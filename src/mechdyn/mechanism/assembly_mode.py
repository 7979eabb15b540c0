"""Explicit assembly modes: which of a loop's two closures the user means.

A closed loop of links can usually be assembled in two ways (an "open" and a
"crossed" four-bar, the slider on either side of the crank).  The initial sketch
chooses one, and continuity keeps it.  An :class:`AssemblyMode` states the
choice explicitly: walking from point P over Q to R, the path turns ``"left"``
(counter-clockwise) or ``"right"`` (clockwise) at Q.  The initial assembly
enforces it (re-assembling from the mirror image of the sketch if needed) and
reports an error if the declared mode cannot be reached.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["AssemblyMode", "TURNS"]

#: declared turn -> sign of the planar cross product (Q - P) x (R - Q)
TURNS = {"left": 1.0, "ccw": 1.0, "right": -1.0, "cw": -1.0}


@dataclass(frozen=True)
class AssemblyMode:
    """The turn P -> Q -> R of a loop, fixing its assembly branch.

    Parameters
    ----------
    name : str
        A name for messages (e.g. the loop or the joint at Q).
    points : ((str, point), (str, point), (str, point))
        (body, point) pairs of P, Q and R; a point is a name or (x, y) in the body
        frame, m.  Q is the joint whose side decides the branch, P and R the
        joints at the ends of the two links that meet there.
    turn : {"left", "right"}
        Direction of the turn at Q ("ccw"/"cw" are accepted too).
    """

    name: str
    points: tuple
    turn: str = "left"
    extra_kind = "assembly"

    def __post_init__(self):
        pts = tuple(tuple(p) for p in self.points)
        if len(pts) != 3 or any(len(p) != 2 for p in pts):
            raise ValueError(f"assembly mode {self.name!r}: points must be three "
                             f"(body, point) pairs P, Q, R, got {self.points!r}")
        object.__setattr__(self, "points", pts)
        if self.turn not in TURNS:
            raise ValueError(f"assembly mode {self.name!r}: turn must be one of "
                             + ", ".join(repr(t) for t in TURNS) + f", got {self.turn!r}")

    @property
    def sign(self) -> float:
        """+1 for a left (counter-clockwise) turn, -1 for a right turn."""
        return TURNS[self.turn]
