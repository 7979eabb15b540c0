"""Generalized coordinates, declared by name and meaning."""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass

from ..errors import did_you_mean

__all__ = ["Coordinate", "COORDINATE_KINDS", "coordinate_problems"]

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


def coordinate_problems(kind: str, body: str | None, joint: str | None,
                        bodies: Collection[str], joint_types: Mapping[str, str]):
    """The problems of a coordinate declaration, for the mechanism and the model file.

    Parameters
    ----------
    kind, body, joint : str or None
        As in :class:`Coordinate`.
    bodies : collection of str
        The moving bodies.
    joint_types : mapping of str to str
        Joint name -> ``"revolute"``, ``"prismatic"`` or ``"lock"``.

    Returns
    -------
    list of (str, str)
        (key at fault, ``""`` for the declaration itself; message) pairs.
    """
    if kind not in COORDINATE_KINDS:
        return [("kind", f"unknown kind {kind!r}; valid kinds: "
                 + ", ".join(repr(k) for k in COORDINATE_KINDS))]
    if kind == "angle":
        if joint is not None:
            return [("joint", "kind 'angle' measures a body; give 'body', not 'joint'")]
        if body is None:
            return [("", "kind 'angle' needs a body (it measures the absolute angle of a body)")]
        return [] if body in bodies else [("body", did_you_mean(body, bodies, "body"))]
    want = "revolute" if kind == "relative_angle" else "prismatic"
    if body is not None:
        return [("body", f"kind {kind!r} measures a {want} joint; give 'joint', not 'body'")]
    if joint is None:
        return [("", f"kind {kind!r} needs a {want} joint")]
    if joint not in joint_types:
        return [("joint", did_you_mean(joint, joint_types, "joint"))]
    if joint_types[joint] != want:
        valid = [n for n, t in joint_types.items() if t == want]
        return [("joint", f"{joint!r} is a {joint_types[joint]} joint, but kind {kind!r} needs "
                 f"a {want} joint; {want} joints: " + (", ".join(map(repr, valid)) or "(none)"))]
    return []
