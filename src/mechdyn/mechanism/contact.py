"""Unilateral constraints: coordinate stops and point-on-line contacts.

A unilateral constraint has a *gap* g(x) >= 0 and a force lambda >= 0 that
pushes to open the gap; force and gap obey complementarity (lambda g = 0).
Whether it is closed is part of the mode (``State.mode``), never a change of
the mechanism: a closed stop on side ``lower`` appears as ``"name@lower"``,
a closed contact as ``"name@contact"`` (with ``"name:stick"``, ``"name:slip+"`` or
``"name:slip-"`` for its friction state when it has friction).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError

__all__ = ["Stop", "Contact"]


def _store_nonneg(el, what: str, fld: str, high: float | None = None):
    """Store the field ``fld`` of ``el`` as a float in [0, ``high``]; ValueError otherwise."""
    v = float(getattr(el, fld))
    if not (np.isfinite(v) and v >= 0 and (high is None or v <= high)):
        bound = ">= 0" if high is None else f"in [0, {high:g}]"
        raise ValueError(f"{what}: {fld} must be {bound}, got {v!r}")
    object.__setattr__(el, fld, v)


@dataclass(frozen=True)
class Stop:
    """Limits on a measured quantity, e.g. the travel of a slider or a joint angle.

    Parameters
    ----------
    name : str
    variable : str
        The limited quantity: a declared coordinate, ``"joint:NAME"`` (relative
        angle or travel), ``"angle:BODY"`` or ``"body.point.x|y"``; see
        :mod:`mechdyn.mechanism.switch`.
    lower, upper : float or None
        The limits, rad or m (None: no limit on that side).
    restitution : float
        Newton's coefficient of restitution e in [0, 1] (0: plastic, the stop
        stays closed after the impact).
    friction : float
        Coulomb coefficient mu >= 0 of the tangential impulse in an impact on the stop
        (:mod:`mechdyn.simulate.impact`); only for a stop on a point coordinate
        ``"body.point.x|y"``, whose tangent is the other ground axis.  It acts during
        impacts only: while the stop stays closed the point slides along it without
        friction (use a :class:`Contact` for lasting friction).

    Raises
    ------
    ModelError
        ``friction > 0`` on a variable that is not a point coordinate, naming the stop,
        its variable and the valid forms.
    ValueError
        A restitution outside [0, 1], a negative friction, no limit, or limits in the
        wrong order.
    """

    name: str
    variable: str
    lower: float | None = None
    upper: float | None = None
    restitution: float = 0.0
    friction: float = 0.0
    extra_kind = "stops"

    def __post_init__(self):
        _store_nonneg(self, f"stop {self.name!r}", "restitution", 1.0)
        _store_nonneg(self, f"stop {self.name!r}", "friction")
        if self.friction > 0 and self.tangent_variable() is None:
            raise ModelError(f"stop {self.name!r}: friction needs a stop on a point "
                             f"coordinate 'body.point.x' or 'body.point.y' (its tangent is "
                             f"the other axis), got variable {self.variable!r}; a stop on "
                             f"a coordinate, 'joint:NAME' or 'angle:BODY' takes no friction "
                             f"(use friction = 0, or a Contact)")
        for side in ("lower", "upper"):
            v = getattr(self, side)
            if v is not None:
                object.__setattr__(self, side, float(v))
        if self.lower is None and self.upper is None:
            raise ValueError(f"stop {self.name!r}: give a lower or an upper limit (or both)")
        if self.lower is not None and self.upper is not None and self.lower >= self.upper:
            raise ValueError(f"stop {self.name!r}: lower limit {self.lower!r} must be below the "
                             f"upper limit {self.upper!r}")

    def sides(self) -> list[str]:
        """The limited sides, ``"lower"`` and/or ``"upper"``."""
        return [s for s in ("lower", "upper") if getattr(self, s) is not None]

    def tangent_variable(self) -> str | None:
        """The variable along the stop's face: ``"body.point.y"`` for a stop on
        ``"body.point.x"`` and the reverse; None for other variables (no tangent)."""
        parts = str(self.variable).strip().split(".")
        if len(parts) != 3 or parts[2] not in ("x", "y") or not (parts[0] and parts[1]):
            return None
        return f"{parts[0]}.{parts[1]}.{'y' if parts[2] == 'x' else 'x'}"


@dataclass(frozen=True)
class Contact:
    """A point of one body against a line of another (gap >= 0), optionally with friction.

    The gap is ``n . (p - a)``: ``p`` the contact point, ``a`` the line point,
    ``n`` the unit normal obtained by turning ``line_direction`` by +90 deg
    (the free side is to the left of the direction).  The tangent is the line
    direction; the slip velocity is the tangential velocity of ``p`` relative to
    the line body.

    Parameters
    ----------
    name : str
    body : str
        The body carrying the contact point.
    point : str or (float, float)
        The contact point, named or in the body frame (m).
    line_body : str
        The body carrying the line (``"ground"`` for the frame).
    line_point : str or (float, float)
        A point of the line in ``line_body``'s frame, m.
    line_direction : (float, float)
        Direction of the line in ``line_body``'s frame.
    friction : float
        Coulomb coefficient mu >= 0 (same for sticking and sliding).
    restitution : float
        Newton's coefficient e in [0, 1] for impacts on closing.
    compliance : float
        Contact compliance c >= 0, (m/s^2)/N: added to the diagonal of the
        contact (Delassus) matrix, G + C, so that statically indeterminate
        contact sets get unique forces (the cyclic-automata document's
        influence-coefficient matrix C, taken diagonal).  Within a mode the
        forces of redundant contacts are shared in inverse proportion to it.
    """

    name: str
    body: str
    point: object
    line_body: str
    line_point: object = (0.0, 0.0)
    line_direction: tuple = (1.0, 0.0)
    friction: float = 0.0
    restitution: float = 0.0
    compliance: float = 0.0
    extra_kind = "contacts"

    def __post_init__(self):
        d = np.asarray(self.line_direction, dtype=float).reshape(-1)
        if d.shape != (2,) or not np.all(np.isfinite(d)) or np.hypot(*d) == 0:
            raise ValueError(f"contact {self.name!r}: line_direction must be a non-zero (x, y), "
                             f"got {self.line_direction!r}")
        object.__setattr__(self, "line_direction", tuple(d / np.hypot(*d)))
        for fld, high in (("restitution", 1.0), ("friction", None), ("compliance", None)):
            _store_nonneg(self, f"contact {self.name!r}", fld, high)
