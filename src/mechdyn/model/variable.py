"""The variable grammar: the one parser of the strings that name a measured quantity.

Switch conditions, guards, coordinate locks, stops and load tables name what
they depend on by a short string:

``"t"``
    time, s;
``"phi"``
    a declared generalized coordinate (rad or m);
``"phi_dot"``
    its rate (rad/s or m/s);
``"joint:C"``
    the relative angle of revolute joint ``C`` (theta_child - theta_parent, rad)
    or the travel of prismatic joint ``C`` along its axis (m);
``"angle:rocker"``
    the absolute angle of a body, rad;
``"rocker.B.x"`` / ``"rocker.B.y"``
    a ground coordinate of a body point, m;
``"dist(rocker.B, slider.P)"``
    the distance between two body points, m.

:func:`parse` reads the string (it needs only the coordinate names, to tell a
coordinate called ``"a_dot"`` from the rate of ``"a"``); :func:`quantity`
checks the names against a :class:`~mechdyn.mechanism.Mechanism` and gives the
kind of quantity (for units); :func:`lower` turns a variable into constraint
rows of a compiled :class:`~mechdyn.model.Model` (:mod:`mechdyn.model.rows`),
and :func:`parse_variable` into a :class:`Measure` evaluated by
:mod:`mechdyn.kernels.rows_numpy`.  Nothing else in the package reads these
strings.
"""

from __future__ import annotations

import re
from collections.abc import Collection
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError, did_you_mean
from ..kernels import rows_numpy
from ..mechanism.joint import Prismatic, Revolute
from . import rows as R
from .rows import Rows

__all__ = ["Variable", "parse", "quantity", "lower", "FORMS", "Measure", "RateMeasure",
           "DistanceMeasure", "TimeMeasure", "parse_variable"]

#: the forms of a variable, for messages
FORMS = ("'<coordinate>', '<coordinate>_dot', 'joint:NAME', 'angle:BODY', 'body.point.x', "
         "'body.point.y', 'dist(body.point, body.point)' or 't'")

_DIST = re.compile(r"^dist\(\s*([^,\s]+)\s*,\s*([^,\s)]+)\s*\)$")


@dataclass(frozen=True)
class Variable:
    """A parsed variable string.

    Attributes
    ----------
    text : str
        The string as given (stripped).
    kind : {"time", "coordinate", "joint", "angle", "point", "distance"}
    name : str
        The coordinate, joint or body named (empty for the others).
    rate : bool
        True for ``"<coordinate>_dot"``.
    points : tuple of (str, str)
        (body, point) of a ``"point"`` (one) or a ``"distance"`` (two).
    comp : int
        0 for ``.x``, 1 for ``.y`` (kind ``"point"``).

    Examples
    --------
    >>> parse("phi_dot", ["phi"])
    Variable(text='phi_dot', kind='coordinate', name='phi', rate=True, points=(), comp=0)
    >>> parse("dist(rod.B, slider.ear)", []).points
    (('rod', 'B'), ('slider', 'ear'))
    """

    text: str
    kind: str
    name: str = ""
    rate: bool = False
    points: tuple = ()
    comp: int = 0


def _point_ref(ref: str, spec: str) -> tuple[str, str]:
    parts = ref.split(".")
    if len(parts) != 2 or not all(parts):
        raise ModelError(f"variable {spec!r}: point reference {ref!r} must be 'body.point'")
    return parts[0], parts[1]


def parse(spec: str, coordinates: Collection[str]) -> Variable:
    """Read a variable string (the grammar of the module docstring).

    Parameters
    ----------
    spec : str
        The variable.
    coordinates : collection of str
        The declared coordinate names (a coordinate name wins over a rate).

    Returns
    -------
    Variable

    Raises
    ------
    ModelError
        The string has none of the forms; the message lists the forms and the
        coordinate names.
    """
    s = str(spec).strip()
    if s == "t":
        return Variable(s, "time")
    if s in coordinates:
        return Variable(s, "coordinate", s)
    if s.endswith("_dot") and s[:-4] in coordinates:
        return Variable(s, "coordinate", s[:-4], rate=True)
    for head, kind in (("joint:", "joint"), ("angle:", "angle")):
        if s.startswith(head) and s[len(head):].strip():
            return Variable(s, kind, s[len(head):].strip())
    if m := _DIST.match(s):
        return Variable(s, "distance", points=tuple(_point_ref(g, s) for g in m.groups()))
    parts = s.split(".")
    if len(parts) == 3 and parts[2] in ("x", "y") and parts[0] and parts[1]:
        return Variable(s, "point", points=((parts[0], parts[1]),), comp="xy".index(parts[2]))
    names = ", ".join(repr(c) for c in coordinates) or "none declared"
    raise ModelError(f"unknown variable {s!r}; valid variables: {FORMS} (coordinates: "
                     f"{names})")


def quantity(var: Variable, mech) -> str:
    """The kind of quantity of a variable of a mechanism, for units: ``"time"``,
    ``"angle"``, ``"length"``, ``"angular_velocity"`` or ``"velocity"``.

    Raises
    ------
    ModelError
        A body, point or joint the mechanism does not have (the message lists
        the valid names).
    """
    if var.kind == "time":
        return "time"
    if var.kind == "coordinate":
        ang = mech.coordinates[var.name].is_angle
    elif var.kind == "joint":
        j = mech.joints.get(var.name)
        if not isinstance(j, (Revolute, Prismatic)):
            valid = [n for n, jj in mech.joints.items() if isinstance(jj, (Revolute, Prismatic))]
            raise ModelError(did_you_mean(var.name, valid, "revolute or prismatic joint"))
        ang = isinstance(j, Revolute)
    else:
        bodies = mech.all_bodies
        refs = [(var.name, None)] if var.kind == "angle" else list(var.points)
        for body, point in refs:
            if body not in bodies:
                raise ModelError(did_you_mean(body, bodies, "body"))
            names = bodies[body].point_names()
            if point is not None and point not in names:
                raise ModelError(f"unknown point {point!r} of body {body!r}; valid point names: "
                                 + ", ".join(repr(p) for p in names))
        ang = var.kind == "angle"
    if var.rate:
        return "angular_velocity" if ang else "velocity"
    return "angle" if ang else "length"


def _body_point(model, ref) -> tuple[int, np.ndarray]:
    body, point = ref
    return model.body_index(body), model.point_local(body, point)


def lower(model, var: Variable) -> Rows | None:
    """The constraint rows of a variable of a compiled model (None for time).

    One row for a coordinate (its rate is the rate of that row), a joint, an
    angle or a point; two rows (ground x and y of p1 - p2) for a distance.

    Raises
    ------
    ModelError
        An unknown joint, body or point (the message lists the valid names).
    """
    nb = model.n_bodies
    if var.kind == "time":
        return None
    if var.kind == "coordinate":
        return model.coordinate_rows.take([model.coordinate_index(var.name)])
    if var.kind == "joint":
        return model.joint_variable(var.text, var.name)
    if var.kind == "angle":
        return R.angle(var.text, model.body_index(var.name), nb=nb)
    if var.kind == "point":
        return R.point(var.text, *_body_point(model, var.points[0]), var.comp, nb=nb)
    # the separation of two points: the two rows of a pin joint between them
    (b1, s1), (b2, s2) = (_body_point(model, p) for p in var.points)
    return R.revolute(var.text, b1, s1, b2, s2, nb=nb)


# ============================================================================ measures
def _pose(X, nb: int) -> np.ndarray:
    """The pose vector (n_x,) of ``X``: a pose vector or body poses (nb [+ 1], 3)."""
    X = np.asarray(X, dtype=float)
    return X[:nb].reshape(-1) if X.ndim == 2 else X


class Measure:
    """A scalar of the pose: one constraint row m(x) (:mod:`mechdyn.model.rows`).

    Poses ``X`` (and rates ``V``) may be given as vectors (n_x,) or as body poses
    with the ground appended (n_bodies + 1, 3).

    Attributes
    ----------
    rows : Rows
        The row (one).
    label : str
    is_angle : bool
        True for rad, False for m.
    needs_velocity : bool
        True if :meth:`value` needs the rates ``V`` too.
    """

    needs_velocity = False

    def __init__(self, rows: Rows, label: str | None = None):
        self.rows = rows
        self.label = rows.labels[0] if label is None else label
        self.is_angle = bool(rows.is_angle[0])

    def value(self, X, V=None) -> float:
        """m(x), m or rad."""
        return float(rows_numpy.values(self.rows, _pose(X, self.rows.nb))[0])

    def rate(self, X, V, nb: int | None = None) -> float:
        """dm/dt = m_x xdot, m/s or rad/s."""
        n = self.rows.nb
        return float(rows_numpy.jacobian(self.rows, _pose(X, n))[0] @ _pose(V, n))


class RateMeasure(Measure):
    """The time derivative of another measure, m/s or rad/s (switch conditions only)."""

    needs_velocity = True

    def __init__(self, base: Measure, label: str):
        super().__init__(base.rows, label)

    def value(self, X, V=None) -> float:
        return self.rate(X, V)


class DistanceMeasure(Measure):
    """Distance between two body points, m (switch conditions only); ``rows`` are the
    ground x and y of their separation."""

    def value(self, X, V=None) -> float:
        return float(np.hypot(*rows_numpy.values(self.rows, _pose(X, self.rows.nb))))

    def rate(self, X, V, nb: int | None = None) -> float:
        d, J, _ = rows_numpy.evaluate(self.rows, _pose(X, self.rows.nb))
        r = float(np.hypot(*d))
        return float(d @ (J @ _pose(V, self.rows.nb))) / r if r else 0.0


class TimeMeasure:
    """Time, s (the value is supplied by the caller)."""

    label = "t"
    is_angle = False
    needs_velocity = False


def parse_variable(model, spec: str, *, allow_time: bool = False, allow_rate: bool = False,
                   allow_distance: bool = False):
    """The :class:`Measure` named by a variable string, on a compiled model.

    Parameters
    ----------
    model : Model
    spec : str
        A variable (see the module docstring).
    allow_time, allow_rate, allow_distance : bool
        Whether ``"t"``, ``"<coordinate>_dot"`` and ``"dist(...)"`` are allowed
        (switch conditions and guards: yes; constraint rows: no).

    Returns
    -------
    Measure or TimeMeasure

    Raises
    ------
    ModelError
        The string names nothing known, or a form not allowed here; the message
        lists the valid forms or names.
    """
    var = parse(spec, model.coordinate_names)
    for bad, what in ((var.kind == "time" and not allow_time, "variable 't' (time)"),
                      (var.kind == "distance" and not allow_distance,
                       f"distance variable {var.text!r}"),
                      (var.rate and not allow_rate, f"rate variable {var.text!r}")):
        if bad:
            raise ModelError(f"{what} is allowed only in switch conditions")
    if var.kind == "time":
        return TimeMeasure()
    rows = lower(model, var)
    if var.kind == "distance":
        return DistanceMeasure(rows, var.text)
    base = Measure(rows.renamed(var.text))
    return RateMeasure(base, var.text) if var.rate else base
