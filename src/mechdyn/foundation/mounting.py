"""Elastic mounting, coupled: the frame becomes a body on its isolators.

:func:`mounted` turns a machine on a fixed frame into the same machine on a movable
base: a new body (the frame and base, the :class:`Foundation`'s mass and inertia at its
centre of mass) takes over every element that was attached to the ground, and the
isolators hold it to the floor, which is the new ground.  ``mechdyn.simulate`` then runs
machine and base together, two-way coupled, on the one engine.

How the base is held
--------------------
The base is a free body: its three coordinates are the pose of its frame, ``<base>_x``
and ``<base>_y`` (coordinate kinds ``"x"`` and ``"y"``: the ground position of the
base frame's origin, which in the sketch is the ground origin, so they are its
displacement, m) and ``<base>_theta`` (kind ``"angle"``, its absolute angle, rad).  No
joint holds it to the floor: it is held by the isolators alone.

Each isolator is a linear :class:`~mechdyn.mechanism.load.Bushing` ``<base>_<isolator>``
from the isolator's point on the floor to the same point on the base, stiffness kx, ky
and damping cx, cy along the floor's axes: the isolator model of
:class:`~mechdyn.foundation.supports.Foundation` exactly, its force computed from the
point's small displacement itself (no long lever whose direction must barely turn, no
cancellation).  The floor takes each isolator's force where the base point is.

The initial base coordinates are the static equilibrium under the weights of the base
and of the machine's bodies in their initial (or sketch) pose, solved with the base's
rotation exact: the base sags by weight / (sum of ky).  A machine that starts moving
then sets the base vibrating about it.

What cannot follow the base
---------------------------
Quantities that the variable grammar measures in the ground frame (``"angle:BODY"``,
``"body.point.x"``, a distance to a ground point) in load tables, stops, coordinate locks
and switches keep being measured against the floor; :func:`mounted` lists them in a
:class:`FloorFrameWarning` (the shift is the base's motion, often well below a mm).  A
:class:`~mechdyn.mechanism.drive.Drive` on the absolute angle of a body pinned to the
ground becomes a drive on the relative angle of that pin (the stator on the base); on the
absolute angle of any other body it would push against the floor, a
:class:`~mechdyn.errors.ModelError`.  Every absolute angle coordinate of a body pinned to
the ground, or to a body that only slides on it (a rocker on a ram), becomes such a
relative angle, equal to the absolute one while the base does not turn: the machine's
coordinates then leave the base's motion to the base's own three (an absolute angle that
also turned with the base could be chosen as independent in its place, and stall where it
turns back).  A joint so used gets the body as its child: its reaction is then reported
with the opposite sign.
"""

from __future__ import annotations

import dataclasses
import re
import warnings
from collections.abc import Sequence

import numpy as np

from ..errors import ModelError, did_you_mean
from ..kernels.planar import cross, rotate
from ..mechanism import (
    GROUND,
    AssemblyMode,
    Body,
    Bushing,
    Coordinate,
    Force,
    Ground,
    Mechanism,
    Prismatic,
    Revolute,
    RotarySpring,
    Spring,
    Torque,
)
from .supports import Foundation

__all__ = ["mounted", "base_coordinates", "isolator_forces", "FloorFrameWarning"]

#: the extras kinds that :func:`mounted` knows how to carry over
_EXTRAS = ("assembly", "stops", "contacts", "coordinate_locks", "switches", "initial")
_FLOOR_VAR = re.compile(r"(^|[\s(,])(angle:\S+|[^\s(,.]+\.[^\s(,.]+\.[xy])($|[\s),])")


class FloorFrameWarning(UserWarning):
    """Elements of a mounted machine whose variables are measured against the floor."""


def base_coordinates(base: str = "base") -> tuple[str, str, str]:
    """Names of the base's coordinates in a :func:`mounted` machine.

    Examples
    --------
    >>> base_coordinates("frame")
    ('frame_x', 'frame_y', 'frame_theta')
    """
    return (f"{base}_x", f"{base}_y", f"{base}_theta")


def _foundation(mechanism: Mechanism, foundation: Foundation | None) -> Foundation:
    f = mechanism.foundation if foundation is None else foundation
    if f is None:
        raise ModelError(f"{mechanism.name}: no foundation: give one (Foundation(supports=["
                         "Isolator(...), ...], mass=..., inertia=..., com=...)) or set the "
                         "mechanism's foundation ([foundation] in the model file)")
    if not isinstance(f, Foundation):
        raise ModelError(f"foundation: expected a Foundation, got {type(f).__name__}")
    f.mass_matrix()  # mass and inertia are needed
    bolts = [s.name for s, bolt in zip(f.supports, f.bolts, strict=True) if bolt]
    if bolts:
        raise ModelError(f"foundation: the elastic mounting needs isolators; "
                         f"{', '.join(map(repr, bolts))} are anchor bolts (use Isolator(name, "
                         "x, y, kx, ky, cx, cy), or the rigid analysis for bolts)")
    return f


def sketch_poses(mech: Mechanism) -> dict:
    """Pose (x, y, theta) of every body of ``mech`` in its sketch, m and rad: as given, or
    (a body without a pose) as the assembly places it, and the ground's.

    Examples
    --------
    >>> m = Mechanism()
    >>> _ = m.add_body("bar", pose=(0.1, 0.0, 0.5))
    >>> sketch_poses(m)["bar"]
    (0.1, 0.0, 0.5)
    """
    poses = {name: getattr(b, "pose", None) for name, b in mech.bodies.items()}
    if any(p is None for p in poses.values()):
        from ..kinematics.assembly import assemble

        model = mech.compile()
        x = getattr(model, "x0", None)
        x = assemble(model) if x is None else x
        poses = {n: tuple(float(v) for v in x[3 * i:3 * i + 3])
                 for i, n in enumerate(model.body_names)}
    poses[GROUND] = (0.0, 0.0, 0.0)
    return poses


def _replace_ground(name: str, base: str) -> str:
    return base if name == GROUND else name


def _check_floor_vars(mech: Mechanism) -> list[str]:
    """Names of elements whose variables measure against the floor."""
    found = []

    def look(where, spec):
        if isinstance(spec, str) and (_FLOOR_VAR.search(spec) or f"{GROUND}." in spec):
            found.append(f"{where} ({spec!r})")

    for ld in mech.loads:
        mag = getattr(ld, "magnitude", None)
        look(f"{type(ld).__name__.lower()} {ld.name!r}", getattr(mag, "variable", None))
    for d in mech.drives:
        look(f"drive {d.name!r}", getattr(getattr(d, "torque", None), "variable", None))
    for kind in ("stops", "coordinate_locks", "switches"):
        for el in mech.extras.get(kind, []):
            look(f"{kind[:-1].replace('_', ' ')} {el.name!r}", el.variable)
            for var, _op, _val in getattr(el, "guard", ()):
                look(f"{kind[:-1].replace('_', ' ')} {el.name!r} guard", var)
    return found


def _turning_with_base(mech: Mechanism, joints: dict, base: str) -> dict:
    """Bodies whose angle is held to the base's by prismatic joints (and the base):
    name -> their angle relative to the base, rad."""
    held = {base: 0.0}
    poses = sketch_poses(mech)
    grew = True
    while grew:
        grew = False
        for j in joints.values():
            if not isinstance(j, Prismatic) or (j.parent in held) == (j.child in held):
                continue
            sketch = (poses[j.child][2] if j.child != base else 0.0) - (
                poses[j.parent][2] if j.parent != base else 0.0)
            rel = sketch if j.angle is None else float(j.angle)  # child - parent
            if j.parent in held:
                held[j.child] = held[j.parent] + rel
            else:
                held[j.parent] = held[j.child] - rel
            grew = True
    return held


def _coordinates(mech: Mechanism, joints: dict, base: str) -> dict:
    """The machine's coordinates, measured against the base where they can be: the
    absolute angle of a body pinned to the base, or to a body that only slides on it,
    becomes the relative angle of that pin (plus the slider's angle to the base), so that
    the machine's coordinates say nothing about the base's motion (and a drive on one
    has its stator on the base)."""
    driven = {d.coordinate: d.name for d in mech.drives}
    held = _turning_with_base(mech, joints, base)
    out = {}
    for c in mech.coordinates.values():
        if c.kind == "angle" and c.body not in held:
            pins = [j for j in joints.values() if isinstance(j, Revolute)
                    and c.body in (j.parent, j.child) and ({j.parent, j.child} - {c.body})
                    <= set(held)]
            # turning a pin round would flip the sign of its angle for its rotary springs
            # and its "joint:NAME" variables: such pins are used only as they stand
            pins = [j for j in pins if j.child == c.body or not _angle_used(mech, j.name)]
            if pins:
                pin = pins[0]
                other = pin.parent if pin.child == c.body else pin.child
                if pin.child != c.body:  # the body as the child: the angle keeps its sign
                    joints[pin.name] = Revolute(pin.name, other, c.body, pin.child_point,
                                                pin.parent_point)
                c = Coordinate(c.name, "relative_angle", joint=pin.name,
                               offset=c.offset + held[other])
            elif c.name in driven:
                raise ModelError(
                    f"drive {driven[c.name]!r}: it drives the absolute angle {c.name!r} of "
                    f"body {c.body!r}, which is pinned neither to the ground nor to a body "
                    f"sliding on it, so on a mounted base its stator would push against the "
                    f"floor; declare {c.name!r} as the relative angle of a revolute joint "
                    f"(kind = 'relative_angle')")
        out[c.name] = c
    return out


def _reactions(mech: Mechanism, names: Sequence[str], base: str) -> list:
    """The reactions on the base of the ``Force`` loads named ``names``."""
    forces = {ld.name: ld for ld in mech.loads if isinstance(ld, Force)}
    poses = sketch_poses(mech) if names else {}
    out = []
    for name in names:
        if name not in forces:
            raise ModelError("reacting: " + did_you_mean(name, list(forces), "force load"))
        ld = forces[name]
        if ld.frame != "ground":
            raise ModelError(f"reacting: force {name!r} turns with its body (frame = 'body'); "
                             "only a force of fixed direction (frame = 'ground') can have its "
                             "reaction on the base")
        b = mech.body(ld.body)
        p = b.point(ld.point) if isinstance(ld.point, str) else tuple(ld.point)
        pose = poses[ld.body]
        at = np.asarray(pose[:2]) + rotate(pose[2], np.asarray(p, float))
        out.append(Force(f"{name}_reaction", base, tuple(float(v) for v in at), ld.magnitude,
                         tuple(-v for v in ld.direction), "ground"))
    return out


def _angle_used(mech: Mechanism, joint: str) -> bool:
    """Whether a rotary spring or a variable (table, stop, lock, switch) uses the relative
    angle of ``joint``."""
    specs = [getattr(getattr(ld, "magnitude", None), "variable", None) for ld in mech.loads]
    for kind in ("stops", "coordinate_locks", "switches"):
        for el in mech.extras.get(kind, []):
            specs += [el.variable, *(g[0] for g in getattr(el, "guard", ()))]
    return (any(isinstance(ld, RotarySpring) and ld.joint == joint for ld in mech.loads)
            or any(isinstance(v, str) and f"joint:{joint}" in v for v in specs))


def _load(ld, base: str):
    if isinstance(ld, Spring | Bushing):
        return dataclasses.replace(ld, body1=_replace_ground(ld.body1, base),
                                   body2=_replace_ground(ld.body2, base))
    if isinstance(ld, Torque):
        return dataclasses.replace(ld, body=_replace_ground(ld.body, base),
                                   reaction_body=None if ld.reaction_body is None
                                   else _replace_ground(ld.reaction_body, base))
    if isinstance(ld, Force | RotarySpring):  # on a moving body / in a joint: unchanged
        return ld
    raise ModelError(f"load {getattr(ld, 'name', ld)!r}: a {type(ld).__name__} cannot be "
                     "carried onto a mounted base; known loads: Spring, Bushing, RotarySpring, "
                     "Force, Torque")


def _extras(mech: Mechanism, base: str) -> dict:
    unknown = [k for k in mech.extras if k not in _EXTRAS]
    if unknown:
        raise ModelError(f"mounted: elements of kind {', '.join(map(repr, unknown))} cannot be "
                         f"carried onto a mounted base; known kinds: {', '.join(_EXTRAS)}")
    out: dict = {}
    for kind, items in mech.extras.items():
        if kind == "initial":
            out[kind] = {k: dict(v or {}) for k, v in (items or {}).items()}
        elif kind == "assembly":
            out[kind] = [AssemblyMode(a.name, tuple((_replace_ground(b, base), p)
                                                    for b, p in a.points), a.turn)
                         for a in items]
        elif kind == "contacts":
            out[kind] = [dataclasses.replace(c, body=_replace_ground(c.body, base),
                                             line_body=_replace_ground(c.line_body, base))
                         for c in items]
        else:
            out[kind] = list(items)
    return out


def mounted(mechanism: Mechanism, foundation: Foundation | None = None, base: str = "base",
            equilibrium: bool = True, load=None, reacting: Sequence[str] = ()) -> Mechanism:
    """The machine on its frame mounted on isolators: one mechanism, the floor its ground.

    Parameters
    ----------
    mechanism : Mechanism
        The machine on a fixed frame (not changed).
    foundation : Foundation, optional
        Isolators, mass, inertia and centre of mass of the frame and base (default the
        mechanism's own ``foundation``).
    base : str
        Name of the new body (its coordinates: :func:`base_coordinates`).
    equilibrium : bool
        Start the base at its static equilibrium under the weights (default); False
        starts it at the sketch position, the isolators unloaded.
    load : (float, float, float), optional
        The machine's load on its frame at the start, (Fx, Fy) N and the moment about the
        base's centre of mass, N m (e.g. the first frame load of a rigid run, inertia
        included), to start the base in its static deflection under it instead of under
        the machine's weights.
    reacting : sequence of str
        Names of :class:`~mechdyn.mechanism.load.Force` loads (direction fixed in the
        ground) whose reaction the frame carries: a cylinder or a spring pack on the frame
        pushing a ram, a punch load on the bed.  Each gets an equal and opposite force
        ``<name>_reaction`` on the base, at the point where the force acts in the sketch:
        exact while that point moves along the force's line (a ram), otherwise with the
        moment error (displacement of the point) x (force).  Without it such a force is
        external to machine and base, as on a rigid frame, and pushes the whole mounted
        machine.

    Returns
    -------
    Mechanism
        A new mechanism: ``base`` with the ground's points (the floor keeps them too, for
        variables such as ``"dist(ground.P, ram.Q)"``), every element once attached
        to the ground on it, the isolator bushings ``<base>_<isolator>`` and
        the base's coordinates ``<base>_x``, ``<base>_y`` (kinds ``"x"``, ``"y"``: its
        origin's displacement from the sketch, m) and ``<base>_theta`` (rad).

    Raises
    ------
    ModelError
        No foundation, no mass or inertia, anchor bolts, a name already used, a drive
        whose stator would push against the floor, an element that cannot be carried
        onto the base (named), a ``reacting`` name that is not a ground-frame force.

    Warns
    -----
    FloorFrameWarning
        Tables, stops, locks and switches that measure in the floor's frame, and absolute
        angle coordinates that stay absolute (they turn with the base too; the engine may
        pick one as independent in place of the base's angle).

    Examples
    --------
    >>> from mechdyn.foundation import Foundation, Isolator
    >>> m = Mechanism("pendulum")
    >>> _ = m.add_body("bar", mass=2.0, inertia=0.05, com=(0.5, 0.0))
    >>> _ = m.add_revolute("O", "ground", "bar")
    >>> _ = m.add_coordinate("theta", kind="angle", body="bar")
    >>> f = Foundation([Isolator("L", -0.5, 0.0, 1e5, 1e5), Isolator("R", 0.5, 0.0, 1e5, 1e5)],
    ...                mass=100.0, inertia=10.0)
    >>> mm = mounted(m, f)
    >>> mm.dof, list(mm.coordinates)
    (4, ['theta', 'base_x', 'base_y', 'base_theta'])
    >>> round(mm.extras["initial"]["q"]["base_y"] * 1e3, 6)  # 102 kg * 9.81 / 2e5 N/m, in mm
    -5.0031
    """
    f = _foundation(mechanism, foundation)
    names = [base, *base_coordinates(base)]
    taken = [n for n in names if n in mechanism.bodies or n in mechanism.joints
             or n in mechanism.coordinates]
    if taken:
        raise ModelError(f"mounted: the name(s) {', '.join(map(repr, taken))} are taken by the "
                         f"mechanism; pass another base=... (now {base!r})")
    com = f.com
    out = Mechanism(name=mechanism.name, gravity=tuple(mechanism.gravity),
                    description=mechanism.description,
                    ground=Ground(points=dict(mechanism.ground.points)))
    out.add(Body(base, mass=float(f.mass), inertia=float(f.inertia), com=com,
                 points=dict(mechanism.ground.points), pose=(0.0, 0.0, 0.0)))
    for b in mechanism.bodies.values():
        out.add(b)
    joints = {}
    for j in mechanism.joints.values():
        joints[j.name] = dataclasses.replace(j, parent=_replace_ground(j.parent, base),
                                             child=_replace_ground(j.child, base))
    coords = _coordinates(mechanism, joints, base)
    floor_vars = _check_floor_vars(mechanism) + [
        f"coordinate {c.name!r} (absolute angle of {c.body!r})" for c in coords.values()
        if c.kind == "angle"]
    if floor_vars:
        warnings.warn("on the mounted base these still measure against the floor: "
                      + "; ".join(floor_vars), FloorFrameWarning, stacklevel=2)
    for j in joints.values():
        out.add(j)
    for c in coords.values():
        out.add(c)
    for ld in mechanism.loads:
        out.add(_load(ld, base))
    for ld in _reactions(mechanism, reacting, base):
        out.add(ld)
    for d in mechanism.drives:
        out.add(d)
    out.extras = _extras(mechanism, base)
    # the base is a free body: its coordinates are its frame's pose (sketch pose 0, 0, 0)
    cx, cy, cth = base_coordinates(base)
    out.add(Coordinate(cx, "x", body=base))
    out.add(Coordinate(cy, "y", body=base))
    out.add(Coordinate(cth, "angle", body=base))
    for s, k, c in zip(f.supports, f.stiffnesses(), f.dampings(), strict=True):
        at = (float(s.x), float(s.y))
        out.add(Bushing(f"{base}_{s.name}", GROUND, at, base, at, kx=float(k[0]),
                        ky=float(k[1]), cx=float(c[0]), cy=float(c[1])))
    out.foundation = f
    if equilibrium:
        u0 = static_equilibrium(mechanism, f, load)
        init = out.extras.setdefault("initial", {})
        q = init.setdefault("q", {})
        q.update({cx: float(u0[0]), cy: float(u0[1]), cth: float(u0[2])})
    return out


def isolator_forces(foundation: Foundation, u, v=None, pivot=(0.0, 0.0)) -> np.ndarray:
    """Forces of the isolators of a :func:`mounted` base on the floor, shape (..., n, 2), N,
    for the displacement ``u`` (..., 3) of the base's ``pivot`` from the sketch (m, m,
    rad) and its rate ``v`` (without it, the elastic part alone): K delta + C delta' of
    each isolator point's displacement delta, acting where the base point is.

    Examples
    --------
    >>> from mechdyn.foundation import Isolator
    >>> f = Foundation([Isolator("L", -0.5, 0.0, 1e5, 2e5), Isolator("R", 0.5, 0.0, 1e5, 2e5)])
    >>> isolator_forces(f, [0.0, -1e-3, 0.0]).tolist()
    [[0.0, -200.0], [0.0, -200.0]]
    """
    u = np.asarray(u, float)
    pivot = np.asarray(pivot, float)
    shape = u.shape[:-1] + (1,)
    s = foundation.positions() - pivot
    rr = rotate(u[..., 2].reshape(shape), s)  # (..., n, 2)
    F = foundation.stiffnesses() * (rr - s + u[..., None, :2])
    if v is not None:
        v = np.asarray(v, float)
        w = v[..., 2].reshape(shape)
        vp = v[..., None, :2] + np.stack([-w * rr[..., 1], w * rr[..., 0]], axis=-1)
        F = F + foundation.dampings() * vp
    return F


def to_centre_of_mass(foundation: Foundation, u, v=None, pivot=(0.0, 0.0)):
    """Displacement (and rate) of the base's centre of mass, shape (..., 3), from those of
    its ``pivot`` (the base coordinates of :func:`mounted`)."""
    u = np.asarray(u, float)
    r = np.asarray(foundation.com, float) - np.asarray(pivot, float)
    rr = rotate(u[..., 2], r)
    uc = np.array(u)
    uc[..., :2] += rr - r
    if v is None:
        return uc
    v = np.asarray(v, float)
    vc = np.array(v)
    vc[..., 0] -= v[..., 2] * rr[..., 1]
    vc[..., 1] += v[..., 2] * rr[..., 0]
    return uc, vc


def static_equilibrium(mechanism: Mechanism, foundation: Foundation,
                       weights: Sequence | None = None, pivot=(0.0, 0.0)) -> np.ndarray:
    """Displacement (x, y, theta) of the base's ``pivot`` (m, m, rad) at rest on its
    isolators under the weights of the base and of the machine's bodies (in their sketch
    pose, turning with the base), the base's rotation exact as in :func:`mounted`.

    ``weights`` (Fx, Fy, M about the base's centre of mass), N, N, N m, replaces the
    machine's part of the load.

    Examples
    --------
    >>> from mechdyn.foundation import Foundation, Isolator
    >>> f = Foundation([Isolator("L", -0.5, 0.0, 1e5, 2e5), Isolator("R", 0.5, 0.0, 1e5, 2e5)],
    ...                mass=400.0, inertia=10.0)
    >>> u = static_equilibrium(Mechanism(), f)
    >>> round(float(u[1] / (-400.0 * 9.81 / 4e5)), 9)
    1.0
    """
    g = np.asarray(mechanism.gravity, float)
    pivot = np.asarray(pivot, float)
    com = np.asarray(foundation.com, float)
    points, forces = [com], [foundation.mass * g]  # loads at points that turn with the base
    if weights is not None:
        w = np.asarray(weights, float)
        points.append(com)
        forces.append(w[:2])
        moment = float(w[2])
    else:
        moment = 0.0
        poses = sketch_poses(mechanism)
        for b in mechanism.bodies.values():
            pose = poses[b.name]
            points.append(np.asarray(pose[:2]) + rotate(pose[2], np.asarray(b.com)))
            forces.append(b.mass * g)
    r0, F0 = np.array(points) - pivot, np.array(forces)
    r_iso = foundation.positions() - pivot

    def residual(u):
        F = isolator_forces(foundation, u, pivot=pivot)  # what the base pushes
        a = rotate(u[2], r_iso)
        r = rotate(u[2], r0)
        m = np.sum(cross(a, F))
        m_load = np.sum(cross(r, F0)) + moment
        return np.array([*(F.sum(axis=0) - F0.sum(axis=0)), m - m_load])

    K = foundation.stiffness_matrix(pivot)
    u = np.linalg.solve(K, -residual(np.zeros(3)))
    for _ in range(20):
        r = residual(u)
        J = np.empty((3, 3))
        for i in range(3):
            h = 1e-7 * max(1.0, abs(u[i]))
            du = np.zeros(3)
            du[i] = h
            J[:, i] = (residual(u + du) - residual(u - du)) / (2 * h)
        step = np.linalg.solve(J, -r)
        u = u + step
        if np.all(np.abs(step) <= 1e-15 * (1.0 + np.abs(u))):
            break
    return u
