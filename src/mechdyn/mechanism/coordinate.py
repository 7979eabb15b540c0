"""Generalized coordinates, declared by name and meaning."""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass

from ..errors import did_you_mean

__all__ = ["Coordinate", "COORDINATE_KINDS", "BODY_KINDS", "LENGTH_KINDS", "coordinate_problems"]

#: kind -> what it measures
COORDINATE_KINDS = {
    "angle": "absolute angle of a body, rad (theta_body + offset)",
    "relative_angle": "relative angle of a revolute joint, rad "
                      "(theta_child - theta_parent + offset)",
    "travel": "travel of a prismatic joint along its axis, m (from the axis point, + offset)",
    "x": "ground x of a body's origin, m (x_body + offset)",
    "y": "ground y of a body's origin, m (y_body + offset)",
}
#: the kinds that measure a body (``body=``); the others measure a joint (``joint=``)
BODY_KINDS = ("angle", "x", "y")
#: the kinds measured in m (their rates in m/s); the others in rad
LENGTH_KINDS = ("travel", "x", "y")


@dataclass(frozen=True)
class Coordinate:
    """One generalized coordinate.

    Parameters
    ----------
    name : str
        Name used in results and on the command line (``phi``, ``psi``, ...).
    kind : {"angle", "relative_angle", "travel", "x", "y"}
        What the coordinate measures (:data:`COORDINATE_KINDS`).
    body : str
        For ``kind="angle"``: the body whose absolute angle it is; for ``kind="x"`` and
        ``kind="y"``: the body whose origin's ground x or y it is.
    joint : str
        For ``kind="relative_angle"`` (a revolute) and ``kind="travel"`` (a prismatic).
    offset : float
        Added to the measured value (rad or m), so that e.g. a crank angle can be
        measured from a line other than the body's x axis.

    Examples
    --------
    >>> Coordinate("h", "y", body="block").is_angle
    False
    """

    name: str
    kind: str = "angle"
    body: str | None = None
    joint: str | None = None
    offset: float = 0.0

    @property
    def is_angle(self) -> bool:
        """Whether the coordinate is an angle (rad), not a length (m)."""
        return self.kind not in LENGTH_KINDS


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
    if kind in BODY_KINDS:
        what = "absolute angle" if kind == "angle" else f"ground {kind} of the origin"
        if joint is not None:
            return [("joint", f"kind {kind!r} measures a body; give 'body', not 'joint'")]
        if body is None:
            return [("", f"kind {kind!r} needs a body (it measures the {what} of a body)")]
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
