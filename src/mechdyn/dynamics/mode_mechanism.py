"""A variable-structure mechanism in one mode, as a mechanism of its own.

Public names
------------
mode_mechanism
    A copy of a mechanism with locks engaged and the coordinates they freeze
    dropped, e.g. the press in its 1-DOF working mode, for the reduction method;
    importable from :mod:`mechdyn.dynamics.reduced_machine` as well.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

from ..errors import ModelError, did_you_mean
from ..mechanism.joint import Lock

__all__ = ["mode_mechanism"]


def mode_mechanism(mechanism, *, engage: Sequence[str] = (), offsets: dict | None = None,
                   drop: Sequence[str] = ()):
    """A copy of a mechanism with locks engaged and the coordinates they freeze removed.

    The reduction method needs one degree of freedom; a variable-structure
    machine has it in some modes only (the clutchless press in its working mode:
    rocker locked onto the slider).  This builds that mode as a mechanism of its
    own.

    Parameters
    ----------
    mechanism : Mechanism
    engage : sequence of str
        Locks to engage.
    offsets : dict, optional
        Lock name -> pose (x m, y m, theta rad) of the child frame in the parent
        frame held by the lock; default the lock's own offset (or the sketch).
    drop : sequence of str
        Coordinates to remove (those the engaged locks freeze).

    Returns
    -------
    Mechanism
        The original is not changed; initial values of dropped coordinates are
        removed from ``extras["initial"]``.
    """
    offsets = dict(offsets or {})
    joints = dict(mechanism.joints)
    probs = []
    for name in engage:
        j = joints.get(name)
        if not isinstance(j, Lock):
            locks = [n for n, jj in joints.items() if isinstance(jj, Lock)]
            probs.append(did_you_mean(name, locks, "lock"))
            continue
        off = offsets.pop(name, j.offset)
        joints[name] = dataclasses.replace(j, engaged=True,
                                           offset=None if off is None else tuple(map(float, off)))
    for name in offsets:
        probs.append(f"offsets: lock {name!r} is not in engage")
    coords = {k: v for k, v in mechanism.coordinates.items() if k not in set(drop)}
    for name in drop:
        if name not in mechanism.coordinates:
            probs.append(did_you_mean(name, mechanism.coordinates, "coordinate"))
    if probs:
        raise ModelError(probs)
    extras = dict(mechanism.extras)
    init = extras.get("initial")
    if isinstance(init, dict):
        extras["initial"] = {k: {c: v for c, v in dict(d or {}).items() if c in coords}
                             for k, d in init.items()}
    return dataclasses.replace(mechanism, joints=joints, coordinates=coords,
                               loads=list(mechanism.loads), drives=list(mechanism.drives),
                               extras=extras)
