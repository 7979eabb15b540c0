"""Switchable constraints and the switches that engage and release them.

A *variable-structure* mechanism keeps one set of bodies, joints and declared
coordinates; what changes while it runs is the set of active constraints, the
*mode* (``State.mode``): the names of the engaged locks and the closed stops
and contacts.  The elements here are frozen data; ``mechdyn.simulate.segments``
runs them.

Variables
---------
Switch conditions, coordinate locks and stops name a measured quantity by a
short *variable* string: ``"t"``, a coordinate ``"phi"``, its rate
``"phi_dot"``, ``"joint:C"``, ``"angle:rocker"``, ``"rocker.B.x"``,
``"dist(rocker.B, slider.P)"``; the grammar and its one parser are
:mod:`mechdyn.model.variable`.  Time, rates and distances are allowed in switch
conditions only (a coordinate lock or a stop holds a constraint row).

Elements are stored in ``Mechanism.extras`` under the key given by their
``extra_kind`` (``"coordinate_locks"``, ``"switches"``); :func:`add_element`
files them there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError

__all__ = ["CoordinateLock", "Switch", "add_element", "SWITCH_ACTIONS", "GUARD_OPERATORS"]

#: what a switch can do to its target lock
SWITCH_ACTIONS = ("engage", "release", "toggle")
#: comparison operators allowed in switch guards
GUARD_OPERATORS = ("<", "<=", ">", ">=")


@dataclass(frozen=True)
class CoordinateLock:
    """A lock that holds one measured quantity (a relative angle, a travel, ...).

    It adds one constraint equation ``variable(x) = value`` while engaged.  It is
    the minimal lock for a pair of bodies already joined by a revolute or a
    prismatic joint (a full :class:`~mechdyn.mechanism.joint.Lock` weld there
    would add two redundant equations).

    Parameters
    ----------
    name : str
        Unique name (it appears in ``State.mode`` while engaged).
    variable : str
        The held quantity (see the module docstring; not ``t``, rates or distances).
    engaged : bool
        Whether the lock is engaged in the initial mode.
    value : float or None
        Held value (rad or m); None holds the value measured when the lock engages.
    frees : tuple of str
        Declared coordinates that this lock makes dependent when it engages
        (dropped from the independent set).  Empty: chosen automatically by the
        largest pivots of the constraint matrix in coordinate space.
    """

    name: str
    variable: str
    engaged: bool = False
    value: float | None = None
    frees: tuple = ()
    extra_kind = "coordinate_locks"

    def __post_init__(self):
        frees = (self.frees,) if isinstance(self.frees, str) else self.frees
        object.__setattr__(self, "frees", tuple(str(f) for f in frees))
        if self.value is not None:
            object.__setattr__(self, "value", float(self.value))


@dataclass(frozen=True)
class Switch:
    """A switch: when its condition is met, it engages or releases a lock.

    The condition is either a *crossing* (``variable`` passes ``value`` in
    ``direction``) or a *schedule* (``times``, an external command list).
    Events are located to machine precision on the integrator's dense output.

    Parameters
    ----------
    name : str
    action : {"engage", "release", "toggle"}
    target : str
        A :class:`~mechdyn.mechanism.joint.Lock` or :class:`CoordinateLock` name.
    variable : str or None
        The watched quantity (see the module docstring); ``"t"`` for a time.
    value : float
        The crossing level, SI (s, rad, m, rad/s, m/s).
    direction : {+1, -1, 0}
        +1: fires when the variable rises through ``value``; -1 when it falls;
        0 either way.
    times : tuple of float
        Command times, s (instead of ``variable``); the switch fires at each.
    guard : tuple of (variable, operator, value)
        Extra conditions checked at the crossing; the switch fires only if all
        hold (e.g. ``(("s", "<", -1e-3),)``).
    once : bool
        Fire at most once in a run.
    """

    name: str
    action: str
    target: str
    variable: str | None = None
    value: float = 0.0
    direction: int = 0
    times: tuple = ()
    guard: tuple = ()
    once: bool = False
    extra_kind = "switches"

    def __post_init__(self):
        object.__setattr__(self, "times", tuple(sorted(float(t) for t in self.times)))
        object.__setattr__(self, "value", float(self.value))
        object.__setattr__(self, "direction", int(np.sign(self.direction)))
        object.__setattr__(self, "guard", tuple((str(var), str(op), float(val))
                                                for var, op, val in self.guard))

    @property
    def is_scheduled(self) -> bool:
        """True for a command schedule (``times``), False for a crossing condition."""
        return self.variable is None

    def problems(self, where=None) -> list[str]:
        """Problems that can be found without the mechanism; ``where(key)`` names the
        place of a key in the messages (default ``"switch 'NAME': key"``)."""
        where = where or (lambda key: f"switch {self.name!r}" + (f": {key}" if key else ""))
        out = []
        if self.action not in SWITCH_ACTIONS:
            out.append(f"{where('action')}: must be one of {', '.join(SWITCH_ACTIONS)}, "
                       f"got {self.action!r}")
        if (self.variable is None) == (not self.times):
            out.append(f"{where('')}: give either a crossing 'variable' (with 'value' and "
                       "'direction') or a list of command 'times', not both or neither")
        for var, op, _ in self.guard:
            if op not in GUARD_OPERATORS:
                out.append(f"{where('guard')}: {var!r}: operator must be one of "
                           f"{', '.join(GUARD_OPERATORS)}, got {op!r}")
        return out


def add_element(mechanism, element):
    """File a switch, coordinate lock, stop or contact in ``mechanism.extras``.

    Parameters
    ----------
    mechanism : Mechanism
    element : CoordinateLock, Switch, Stop or Contact
        Any object with an ``extra_kind`` attribute.

    Returns
    -------
    The element.
    """
    kind = element.extra_kind
    lst = mechanism.extras.setdefault(kind, [])
    if any(e.name == element.name for e in lst):
        raise ModelError(f"{kind[:-1].replace('_', ' ')} {element.name!r} is defined twice")
    lst.append(element)
    return element
