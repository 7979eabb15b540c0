"""The mechanism: bodies, joints, coordinates, loads and drives, as plain data.

``Mechanism`` is a builder: add elements, then call :meth:`Mechanism.validate`
(which reports every problem at once) or :meth:`Mechanism.compile`, which
validates and returns the constant :class:`mechdyn.model.Model` that every
analysis uses (built by :func:`mechdyn.compiler.compile_mechanism`).  Nothing
here knows about solvers or time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError, did_you_mean
from .assembly_mode import AssemblyMode
from .body import GROUND, Body, Ground, unknown_point
from .coordinate import Coordinate, coordinate_problems
from .joint import ELASTIC_FIELDS, FRICTION_FIELDS, Joint, Lock, Prismatic, Revolute
from .supports import Foundation

__all__ = ["Mechanism"]


@dataclass
class Mechanism:
    """A planar mechanism described by its elements.

    Parameters
    ----------
    name : str
        A title used in reports.
    gravity : (float, float)
        Gravitational acceleration vector in the ground frame, m/s^2
        (default (0, -9.81): y is up).
    description : str
        Free text kept with the model (shown by ``mechdyn examples``).
    foundation : Foundation or None
        The supports of the frame (anchor bolts, isolators; the base's mass and
        inertia), used by :mod:`mechdyn.foundation` and ``mechdyn foundation``; None
        (default) when not given.  Set it with :meth:`add_foundation`, ``add(Foundation(
        ...))`` or ``mech.foundation = ...``; it does not change the motion.

    Examples
    --------
    >>> m = Mechanism("pendulum")
    >>> _ = m.add_body("bar", mass=2.0, inertia=0.05, com=(0.5, 0.0))
    >>> _ = m.add_revolute("O", "ground", "bar")
    >>> _ = m.add_coordinate("theta", kind="angle", body="bar")
    >>> m.dof
    1
    """

    name: str = "mechanism"
    gravity: tuple[float, float] = (0.0, -9.81)
    description: str = ""
    ground: Ground = field(default_factory=Ground)
    bodies: dict[str, Body] = field(default_factory=dict)
    joints: dict[str, Joint] = field(default_factory=dict)
    coordinates: dict[str, Coordinate] = field(default_factory=dict)
    loads: list = field(default_factory=list)
    drives: list = field(default_factory=list)
    #: optional extra elements (switches, contacts, process loads ...) by kind
    extras: dict[str, list] = field(default_factory=dict)
    foundation: Foundation | None = None

    # ------------------------------------------------------------------ building
    def add(self, element):
        """Add a body, ground, joint, coordinate, load, drive or the foundation; returns it."""
        if isinstance(element, Ground):
            self.ground = element
        elif isinstance(element, Foundation):
            self.foundation = element
        elif isinstance(element, Body):
            self._check_new(element.name)
            self.bodies[element.name] = element
        elif isinstance(element, Joint):
            self._check_new(element.name)
            self.joints[element.name] = element
        elif isinstance(element, Coordinate):
            if element.name in self.coordinates:
                raise ModelError(f"coordinate {element.name!r} is defined twice")
            self.coordinates[element.name] = element
        elif getattr(element, "extra_kind", None):
            self.extras.setdefault(element.extra_kind, []).append(element)
        elif getattr(element, "is_drive", False):
            self.drives.append(element)
        else:
            self.loads.append(element)
        return element

    def _check_new(self, name: str):
        if name == GROUND or name in self.bodies or name in self.joints:
            raise ModelError(f"name {name!r} is already used by another body or joint")

    def add_ground(self, points=None) -> Ground:
        """Set the named points of the fixed frame (ground frame coordinates, m)."""
        return self.add(Ground(points=dict(points or {})))

    def add_foundation(self, supports, mass=None, inertia=None, com=(0.0, 0.0)) -> Foundation:
        """Set the supports of the frame: a :class:`~mechdyn.mechanism.supports.Foundation`
        of ``supports`` (``AnchorBolt``, ``Isolator``), with the base's mass (kg), inertia
        about its centre of mass (kg m^2) and centre of mass ``com`` (m, ground frame).

        Examples
        --------
        >>> from mechdyn.mechanism.supports import AnchorBolt
        >>> m = Mechanism("press")
        >>> f = m.add_foundation([AnchorBolt("b1", -0.4, 0.0, 2e8, 1e8),
        ...                       AnchorBolt("b2", 0.4, 0.0, 2e8, 1e8)], mass=800.0)
        >>> m.foundation.names
        ('b1', 'b2')
        """
        return self.add(Foundation(supports, mass=mass, inertia=inertia, com=com))

    def add_body(self, name: str, **kwargs) -> Body:
        """Add a :class:`Body`; keyword arguments as for ``Body``."""
        return self.add(Body(name, **kwargs))

    def add_revolute(self, name, parent, child, parent_point=(0.0, 0.0),
                     child_point=(0.0, 0.0), **friction) -> Revolute:
        """Add a :class:`Revolute` joint (pin) between two bodies; ``friction``,
        ``pin_radius``, ``viscous``, ``smoothing`` and ``compliance`` as for
        ``Revolute``."""
        _check_options("revolute", name, friction)
        return self.add(Revolute(name, parent, child, parent_point, child_point, **friction))

    def add_prismatic(self, name, parent, child, parent_point=(0.0, 0.0), axis=(1.0, 0.0),
                      child_point=(0.0, 0.0), angle=None, **friction) -> Prismatic:
        """Add a :class:`Prismatic` joint: ``child`` slides along a line of ``parent``;
        ``friction``, ``guide_length``, ``viscous`` and ``smoothing`` as for ``Prismatic``."""
        _check_options("prismatic", name, friction)
        return self.add(Prismatic(name, parent, child, parent_point, tuple(axis),
                                  child_point, angle, **friction))

    def add_lock(self, name, parent, child, engaged=True, offset=None) -> Lock:
        """Add a switchable weld (:class:`Lock`) between two bodies."""
        return self.add(Lock(name, parent, child, engaged, offset))

    def add_assembly_mode(self, name, p, q, r, turn="left"):
        """Declare the assembly branch of a loop: the turn P -> Q -> R at Q.

        ``p``, ``q``, ``r`` are (body, point) pairs; ``turn`` is "left" or "right"
        (see :class:`~mechdyn.mechanism.assembly_mode.AssemblyMode`).
        """
        return self.add(AssemblyMode(name, (tuple(p), tuple(q), tuple(r)), turn))

    def add_coordinate(self, name, kind="angle", body=None, joint=None,
                       offset=0.0) -> Coordinate:
        """Declare a generalized coordinate (see :class:`Coordinate`)."""
        return self.add(Coordinate(name, kind, body, joint, float(offset)))

    def set_initial(self, q=None, qdot=None) -> dict:
        """Set initial coordinates and rates by name (as a model file's ``[initial]`` and
        ``[initial_speed]``), SI (rad, m, rad/s, m/s); returns ``extras["initial"]``.

        They start the runs (:func:`mechdyn.initial_state.initial_state`) and place the
        bodies given without a pose.  Values given replace earlier ones of the same name.

        Examples
        --------
        >>> m = Mechanism("pendulum")
        >>> _ = m.add_body("bar", mass=2.0, points={"P": (0.5, 0.0)})
        >>> _ = m.add_revolute("O", "ground", "bar")
        >>> _ = m.add_coordinate("theta", kind="angle", body="bar")
        >>> m.set_initial(q={"theta": 0.5}, qdot={"theta": 2.0})
        {'q': {'theta': 0.5}, 'qdot': {'theta': 2.0}}
        >>> m.compile().found_poses["bar"]
        (0.0, 0.0, 0.5)
        """
        init = self.extras.setdefault("initial", {})
        for key, given in (("q", q), ("qdot", qdot)):
            values = dict(init.get(key) or {})
            values.update({str(k): float(v) for k, v in dict(given or {}).items()})
            init[key] = values
        return init

    # ------------------------------------------------------------------ queries
    def body(self, name: str) -> Body:
        """The body (or the ground) of that name; a clear error lists valid names."""
        if name == GROUND or name == self.ground.name:
            return self.ground
        try:
            return self.bodies[name]
        except KeyError:
            raise ModelError(did_you_mean(name, [GROUND, *self.bodies], "body")) from None

    @property
    def all_bodies(self) -> dict[str, Body]:
        """Ground first, then the moving bodies."""
        return {GROUND: self.ground, **self.bodies}

    @property
    def n_equations(self) -> int:
        """Number of constraint equations with the initially engaged locks."""
        return sum(j.n_equations for j in self.joints.values()
                   if not (isinstance(j, Lock) and not j.engaged))

    @property
    def dof(self) -> int:
        """Degrees of freedom by Gruebler's count, 3 n_bodies - equations."""
        return 3 * len(self.bodies) - self.n_equations

    # ------------------------------------------------------------------ checks
    def problems(self) -> list[str]:
        """Every problem of the description that can be found without solving."""
        out: list[str] = []
        for b in self.bodies.values():
            out += _body_problems(b)
        g = np.asarray(self.gravity, dtype=float)
        if g.shape != (2,) or not np.all(np.isfinite(g)):
            out.append(f"gravity must be a finite vector (gx, gy) in m/s^2, got {self.gravity!r}")
        for j in self.joints.values():
            out += self._joint_problems(j)
        out += reserved_names(self.bodies, self.coordinates,
                              {b.name: list(b.points) for b in self.bodies.values()})
        out += self._coordinate_problems()
        for am in self.extras.get("assembly", []):
            for role, (bname, ref) in zip("PQR", am.points, strict=True):
                where = f"assembly mode {am.name!r}: point {role}"
                out += self._point_problems(bname, ref, where, where)
        if self.foundation is not None and not isinstance(self.foundation, Foundation):
            out.append(f"foundation: expected a Foundation (supports, mass, inertia, com), "
                       f"got {type(self.foundation).__name__}")
        out += self._count_problems()
        return out

    def _point_problems(self, bname, ref, where_body, where_point) -> list[str]:
        """An unknown body ``bname``, or an unknown point ``ref`` of it (a name; a
        coordinate pair is not checked here)."""
        names = [GROUND, *self.bodies]
        if bname not in names:
            return [f"{where_body}: " + did_you_mean(bname, names, "body")]
        if isinstance(ref, str) and ref not in self.body(bname).point_names():
            return [f"{where_point}: " + unknown_point(ref, bname, self.body(bname).point_names())]
        return []

    def _joint_problems(self, j: Joint) -> list[str]:
        """The problems of one joint: its bodies and points, and its own values."""
        out: list[str] = []
        where = f"{type(j).__name__.lower()} joint {j.name!r}"
        for role in ("parent", "child"):
            out += self._point_problems(getattr(j, role), getattr(j, f"{role}_point", None),
                                        f"{where}: {role}", f"{where}: {role}_point")
        if j.parent == j.child:
            out.append(f"{where}: parent and child are the same body {j.parent!r}")
        return out + _joint_value_problems(j, where)

    def _coordinate_problems(self) -> list[str]:
        """The problems of the declared coordinates (kind, body or joint)."""
        joint_types = {n: type(j).__name__.lower() for n, j in self.joints.items()}
        out: list[str] = []
        for c in self.coordinates.values():
            for key, msg in coordinate_problems(c.kind, c.body, c.joint, self.bodies,
                                                joint_types):
                out.append(f"coordinate {c.name!r}: " + (f"{key}: " if key else "") + msg)
        return out

    def _count_problems(self) -> list[str]:
        """No moving bodies, no coordinates, or a coordinate count that differs from
        Gruebler's count of the degrees of freedom."""
        out: list[str] = []
        if not self.bodies:
            out.append("the mechanism has no moving bodies")
        if not self.coordinates:
            out.append("no generalized coordinates are declared")
        elif self.bodies and self.dof != len(self.coordinates):
            out.append(
                f"degrees of freedom by Gruebler's count: 3 x {len(self.bodies)} bodies - "
                f"{self.n_equations} equations = {self.dof}, but {len(self.coordinates)} "
                f"coordinate(s) are declared ({', '.join(self.coordinates)})")
        return out

    def validate(self) -> Mechanism:
        """Check the whole description and raise one :class:`ModelError` listing all problems.

        Besides the checks that need no solving (names, masses, DOF count), the
        sketch is assembled and the coordinates are checked to be independent.
        Returns the mechanism itself so calls can be chained.
        """
        self.compile()
        return self

    def compile(self):
        """Validate and build the constant :class:`mechdyn.model.Model`
        (:func:`mechdyn.compiler.compile_mechanism`, which lists every problem found)."""
        # The one import of mechanism/ upwards, deferred and declared in the import
        # contracts (pyproject.toml): compiling needs the model, the assembly and the load
        # evaluators, which all import mechanism/; this convenience hands itself to them.
        from ..compiler import compile_mechanism

        return compile_mechanism(self)

    def __repr__(self) -> str:
        return (f"Mechanism({self.name!r}: {len(self.bodies)} bodies, {len(self.joints)} joints, "
                f"coordinates {list(self.coordinates)})")


def _body_problems(b: Body) -> list[str]:
    """The problems of one body's numbers: mass, inertia, pose and points."""
    out: list[str] = []
    if not np.isfinite(b.mass) or b.mass < 0:
        out.append(f"body {b.name!r}: mass must be >= 0 kg, got {b.mass!r}")
    if not np.isfinite(b.inertia) or b.inertia < 0:
        out.append(f"body {b.name!r}: inertia must be >= 0 kg*m^2, got {b.inertia!r}")
    if b.pose is not None and not np.all(np.isfinite(b.pose)):
        out.append(f"body {b.name!r}: pose must be finite (x, y, theta), got {b.pose!r}")
    for k, v in [("com", b.com), *b.points.items()]:
        if not np.all(np.isfinite(v)):
            out.append(f"body {b.name!r}: point {k!r} is not finite: {v!r}")
    return out


def _joint_value_problems(j: Joint, where: str) -> list[str]:
    """The problems of one joint's own values (``where`` names it): its friction and
    elastic fields, a pin's friction without a radius, a slider's axis."""
    out: list[str] = []
    jtype = type(j).__name__.lower()
    for key, _ in (*FRICTION_FIELDS.get(jtype, ()), *ELASTIC_FIELDS.get(jtype, ())):
        v = getattr(j, key)
        if not (isinstance(v, int | float) and math.isfinite(v) and v >= 0):
            out.append(f"{where}: {key} must be a finite number >= 0, got {v!r}")
    if (isinstance(j, Revolute) and isinstance(j.friction, int | float)
            and j.friction > 0
            and not (isinstance(j.pin_radius, int | float) and j.pin_radius > 0)):
        out.append(f"{where}: friction = {j.friction:g} needs the pin's radius "
                   "(pin_radius > 0, m)")
    if isinstance(j, Prismatic):
        ax = np.asarray(j.axis, dtype=float)
        if ax.shape != (2,) or not np.all(np.isfinite(ax)) or np.hypot(*ax) == 0:
            out.append(f"{where}: axis must be a non-zero direction (x, y), "
                       f"got {j.axis!r}")
    return out


#: names the variable grammar gives a meaning (time; the centre of mass of a body)
RESERVED = ("t", "com", GROUND)


def reserved_names(bodies, coordinates, points) -> list[str]:
    """Names that the variables of loads, switches and tables could not tell apart: a body
    or coordinate named ``t``, ``com`` or ``ground``, a coordinate named like a rate
    (``..._dot``) or a body, a point named ``com``, and characters of the grammar.

    Examples
    --------
    >>> reserved_names(["t"], ["phi_dot"], {"t": ["com"]})[0]
    "body 't': the name is reserved (t, com, ground); choose another"
    """
    out = []
    for kind, names in (("body", bodies), ("coordinate", coordinates)):
        for n in names:
            if n in RESERVED:
                out.append(f"{kind} {n!r}: the name is reserved ({', '.join(RESERVED)}); "
                           f"choose another")
            elif any(c in n for c in ".:()@, "):
                out.append(f"{kind} {n!r}: the name may not contain . : ( ) @ , or spaces")
    for n in coordinates:
        if n.endswith("_dot"):
            out.append(f"coordinate {n!r}: a name ending in '_dot' would read as the rate of "
                       f"{n[:-4]!r}; choose another")
        elif n in bodies:
            out.append(f"coordinate {n!r}: a body has the same name; choose another")
    for b, pts in points.items():
        if "com" in pts:
            out.append(f"body {b!r}: point 'com': the name is reserved for the centre of mass")
    return out


def _check_options(jtype: str, name: str, options: dict) -> None:
    """Raise a ModelError naming the joint for a keyword that is not one of its friction
    or elastic fields (a typo, or compliance on a prismatic)."""
    valid = [k for k, _ in (*FRICTION_FIELDS[jtype], *ELASTIC_FIELDS[jtype])]
    for key in options:
        if key not in valid:
            raise ModelError(f"{jtype} joint {name!r}: "
                             + did_you_mean(key, valid, "keyword argument"))
