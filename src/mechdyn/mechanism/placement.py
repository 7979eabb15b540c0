"""Start poses of bodies whose ``pose`` is omitted: placement through their joints.

A body given without a pose (``Body(..., pose=None)``, or no ``pose`` key in a model
file) is placed by the initial assembly.  This module gives the assembly its start:
walking from the ground (and from the bodies whose pose is given) through the joints,

* the angle of a body comes from an ``angle`` coordinate of it (its initial value; a
  coordinate without one counts as 0), a prismatic joint or a lock to a placed body, a
  ``relative_angle`` coordinate of a revolute to a placed body, or two revolutes to
  placed bodies (their points aimed);
* its position from its ``x`` and ``y`` coordinates (their initial values; one of them
  alone sets that component only), else from a revolute to a placed body (the joint
  point), a prismatic joint (the point on the line at the initial ``travel``) or a lock;
* a body joined by one revolute only, with nothing fixing its angle, is placed at that
  pin with angle 0 (the assembly then turns it), one joined to nothing placed at the
  origin.

The start is rough; :func:`mechdyn.kinematics.assembly.assemble` pulls it onto the
constraints and chooses the branch.  Pure geometry on the mechanism's data: no solver.
"""

from __future__ import annotations

import math

from .body import GROUND
from .joint import Lock, Prismatic, Revolute

__all__ = ["start_poses", "initial_values"]


def initial_values(mechanism) -> dict[str, float]:
    """The initial coordinates declared with the mechanism (``extras["initial"]["q"]``,
    the model file's ``[initial]`` table), SI, by coordinate name."""
    init = (mechanism.extras or {}).get("initial") or {}
    q = init.get("q") or {}
    return {str(k): float(v) for k, v in dict(q).items()}


def _rot(th: float, p) -> tuple[float, float]:
    c, s = math.cos(th), math.sin(th)
    return (c * p[0] - s * p[1], s * p[0] + c * p[1])


def _world(pose, p) -> tuple[float, float]:
    d = _rot(pose[2], p)
    return (pose[0] + d[0], pose[1] + d[1])


def _local(mechanism, body: str, ref) -> tuple[float, float]:
    if isinstance(ref, str):
        return tuple(mechanism.body(body).point(ref))
    return (float(ref[0]), float(ref[1]))


def start_poses(mechanism, q0: dict | None = None) -> dict[str, tuple[float, float, float]]:
    """Start pose (x m, y m, theta rad) of every moving body, given or placed.

    Parameters
    ----------
    mechanism : Mechanism
    q0 : mapping of str to float, optional
        Initial coordinates (rad or m) by name; default :func:`initial_values`.  A
        coordinate without a value counts as 0.

    Returns
    -------
    dict
        Body name -> pose; the given poses as they are, the others placed through
        their joints as the module describes (a rough start for the assembly).

    Examples
    --------
    >>> from mechdyn import Mechanism
    >>> m = Mechanism("pendulum")
    >>> _ = m.add_ground({"O": (0.1, 0.0)})
    >>> _ = m.add_body("bar", mass=1.0, points={"P": (0.2, 0.0)})
    >>> _ = m.add_revolute("O", "ground", "bar", "O", "P")
    >>> _ = m.add_coordinate("theta", kind="angle", body="bar")
    >>> [round(v, 6) for v in start_poses(m, {"theta": math.pi / 2})["bar"]]
    [0.1, -0.2, 1.570796]
    """
    q0 = {**{c: 0.0 for c in mechanism.coordinates},
          **(initial_values(mechanism) if q0 is None else dict(q0))}
    placed: dict[str, tuple[float, float, float]] = {GROUND: (0.0, 0.0, 0.0)}
    placed.update({n: tuple(b.pose) for n, b in mechanism.bodies.items() if b.pose is not None})
    todo = [n for n in mechanism.bodies if n not in placed]
    while todo:
        for strict in (True, False):
            done = [n for n in todo if _place(mechanism, n, placed, q0, strict)]
            if done:
                break
        else:
            # joined to nothing placed yet: at the origin, or where its coordinates say
            _put(placed, todo[0], 0.0, 0.0, 0.0, _position(mechanism, todo[0], q0))
            done = [todo[0]]
        todo = [n for n in todo if n not in done]
    return {n: placed[n] for n in mechanism.bodies}


def _angle(mechanism, name: str, placed: dict, q0: dict):
    """The angle of body ``name`` fixed by a coordinate or a joint to a placed body."""
    for c in mechanism.coordinates.values():
        if c.kind == "angle" and c.body == name and c.name in q0:
            return q0[c.name] - c.offset
    for j in mechanism.joints.values():
        other = j.parent if j.child == name else j.child if j.parent == name else None
        if other not in placed:
            continue
        sign = 1.0 if j.child == name else -1.0
        if isinstance(j, Prismatic):
            return placed[other][2] + sign * (j.angle or 0.0)
        if isinstance(j, Lock) and j.offset is not None:
            return placed[other][2] + sign * j.offset[2]
        if isinstance(j, Revolute):
            for c in mechanism.coordinates.values():
                if c.kind == "relative_angle" and c.joint == j.name and c.name in q0:
                    return placed[other][2] + sign * (q0[c.name] - c.offset)
    return None


def _position(mechanism, name: str, q0: dict) -> list:
    """[x, y] of the origin of body ``name`` set by its ``x`` / ``y`` coordinates (None for
    a component without one)."""
    out = [None, None]
    for c in mechanism.coordinates.values():
        if c.kind in ("x", "y") and c.body == name and c.name in q0:
            out["xy".index(c.kind)] = q0[c.name] - c.offset
    return out


def _put(placed: dict, name: str, x: float, y: float, th: float, pos: list) -> bool:
    """Place ``name`` at (x, y, th), its ``x`` / ``y`` coordinates overriding."""
    placed[name] = (x if pos[0] is None else pos[0], y if pos[1] is None else pos[1], th)
    return True


def _pins(mechanism, name: str, placed: dict) -> list:
    """(point of ``name``, world point) of its revolutes to placed bodies."""
    out = []
    for j in mechanism.joints.values():
        if isinstance(j, Revolute) and name in (j.parent, j.child):
            mine, other = ("child", "parent") if j.child == name else ("parent", "child")
            ob = getattr(j, other)
            if ob in placed:
                there = _local(mechanism, ob, getattr(j, other + "_point"))
                out.append((_local(mechanism, name, getattr(j, mine + "_point")),
                            _world(placed[ob], there)))
    return out


def _place(mechanism, name: str, placed: dict, q0: dict, strict: bool) -> bool:
    """Place body ``name`` if its joints to placed bodies allow (``strict``: only when
    its angle is known too); returns whether it was placed."""
    th = _angle(mechanism, name, placed, q0)
    pins = _pins(mechanism, name, placed)
    pos = _position(mechanism, name, q0)
    if th is None and len(pins) >= 2:
        (s1, w1), (s2, w2) = pins[0], pins[1]
        if math.hypot(s2[0] - s1[0], s2[1] - s1[1]) > 0:
            th = (math.atan2(w2[1] - w1[1], w2[0] - w1[0])
                  - math.atan2(s2[1] - s1[1], s2[0] - s1[0]))
            th = math.atan2(math.sin(th), math.cos(th))
    free = None not in pos  # the coordinates place it without a joint
    if th is None:
        if strict or not (pins or free):
            return False
        th = 0.0
    if free:
        return _put(placed, name, 0.0, 0.0, th, pos)
    if pins:
        s, w = pins[0]
        d = _rot(th, s)
        return _put(placed, name, w[0] - d[0], w[1] - d[1], th, pos)
    for j in mechanism.joints.values():
        if isinstance(j, Prismatic) and name in (j.parent, j.child):
            other = j.parent if j.child == name else j.child
            if other not in placed:
                continue
            travel = next((q0[c.name] - c.offset for c in mechanism.coordinates.values()
                           if c.kind == "travel" and c.joint == j.name and c.name in q0), 0.0)
            sp, sc = _local(mechanism, j.parent, j.parent_point), \
                _local(mechanism, j.child, j.child_point)
            n = math.hypot(*j.axis)
            if j.child == name:
                p = _world(placed[other], (sp[0] + travel * j.axis[0] / n,
                                           sp[1] + travel * j.axis[1] / n))
                d = _rot(th, sc)
            else:
                p = _world(placed[other], sc)
                d = _rot(th, (sp[0] + travel * j.axis[0] / n, sp[1] + travel * j.axis[1] / n))
            return _put(placed, name, p[0] - d[0], p[1] - d[1], th, pos)
        if isinstance(j, Lock) and j.offset is not None and name in (j.parent, j.child):
            other = j.parent if j.child == name else j.child
            if other not in placed:
                continue
            o = j.offset
            if j.child == name:
                p = _world(placed[other], o[:2])
            else:
                d = _rot(th, o[:2])
                p = (placed[other][0] - d[0], placed[other][1] - d[1])
            return _put(placed, name, p[0], p[1], th, pos)
    return False


def describe_poses(poses: dict) -> str:
    """Poses as text, x and y in mm and the angle in deg (wrapped to (-180, 180]).

    Examples
    --------
    >>> describe_poses({"rocker": (0.1, 0.0, 2 * math.pi + 1.0)})
    'rocker at (100 mm, 0 mm, 57.2958 deg)'
    """
    out = []
    for n, (x, y, th) in poses.items():
        deg = math.degrees(math.atan2(math.sin(th), math.cos(th)))
        out.append(f"{n} at ({1e3 * x:.6g} mm, {1e3 * y:.6g} mm, {deg:.6g} deg)")
    return ", ".join(out)


def _turn_sign(poses: dict, pts) -> float:
    """Sign of the turn P -> Q -> R of (body, local point) triples at ``poses``."""
    (P, Q, R) = (_world(poses[b], s) for b, s in pts)
    a, b = (Q[0] - P[0], Q[1] - P[1]), (R[0] - Q[0], R[1] - Q[1])
    cross = a[0] * b[1] - a[1] * b[0]
    scale = math.hypot(*a) * math.hypot(*b)
    return 0.0 if scale == 0 or abs(cross) < 1e-6 * scale else math.copysign(1.0, cross)


def _named_points(mechanism, joint, body: str) -> list:
    """(body, point name, local point) naming where ``joint`` meets ``body``: its own
    point there, or for a revolute the coincident point of the other body."""
    sides = [("parent", joint.parent), ("child", joint.child)]
    sides.sort(key=lambda side: side[1] != body)
    out = []
    for role, b in sides:
        ref = getattr(joint, role + "_point")
        if isinstance(ref, str) and (b == body or isinstance(joint, Revolute)):
            out.append((b, ref, _local(mechanism, b, ref)))
    return out


def suggest_assembly_mode(mechanism, *branches: dict) -> str:
    """Assembly modes that tell branches apart, as model-file and Python text.

    Each mode is a revolute Q between bodies i and j, a joint P of body i and a joint R
    of body j (points with names) whose turn P -> Q -> R is not straight in any branch;
    modes are added until every two branches differ in one of them.

    Parameters
    ----------
    mechanism : Mechanism
    *branches : dict
        The poses of each branch, ``{body: (x, y, theta)}`` (the ground may be left out).

    Returns
    -------
    str
        The text, or "" when the named points cannot tell the branches apart.

    Examples
    --------
    >>> from mechdyn import Mechanism
    >>> m = Mechanism()
    >>> _ = m.add_ground({"O": (0, 0), "C": (0.1, 0)})
    >>> pts = {"crank": {"A": (0.04, 0)}, "coupler": {"B": (0.12, 0)}, "rocker": {"B": (0.08, 0)}}
    >>> for b, p in pts.items():
    ...     _ = m.add_body(b, points=p)
    >>> _ = m.add_revolute("O", "ground", "crank", "O")
    >>> _ = m.add_revolute("A", "crank", "coupler", "A")
    >>> _ = m.add_revolute("B", "coupler", "rocker", "B", "B")
    >>> _ = m.add_revolute("C", "ground", "rocker", "C")
    >>> up = {"crank": (0, 0, 1.047198), "coupler": (0.02, 0.034641, 0.320724),
    ...       "rocker": (0.1, 0, 1.133469)}
    >>> down = {"crank": (0, 0, 1.047198), "coupler": (0.02, 0.034641, -1.137998),
    ...         "rocker": (0.1, 0, -1.950753)}
    >>> text = suggest_assembly_mode(m, up, down)
    >>> text[text.index("points"):text.index(" with turn")]
    'points = ["crank.A", "coupler.B", "ground.C"]'
    >>> text[text.index("turn"):text.index(";")]
    'turn = "right" (branch 1) or "left" (branch 2)'
    """
    poses = [{GROUND: (0.0, 0.0, 0.0), **b} for b in branches]
    chosen: list = []  # (P, Q, R, signs by branch)
    for a in range(len(poses)):
        for b in range(a + 1, len(poses)):
            if any(c[3][a] != c[3][b] for c in chosen):
                continue
            for P, Q, R in _triples(mechanism):
                pts = [(P[0], P[2]), (Q[0], Q[2]), (R[0], R[2])]
                signs = [_turn_sign(p, pts) for p in poses]
                if 0.0 not in signs and signs[a] != signs[b]:
                    chosen.append((P, Q, R, signs))
                    break
            else:
                return ""
    return _modes_text(chosen) if chosen else ""


def _triples(mechanism):
    """Every (P, Q, R) of named joint points: Q a revolute, P and R joints of its bodies."""
    joints = list(mechanism.joints.values())
    for jq in joints:
        if not isinstance(jq, Revolute):
            continue
        i, j = jq.parent, jq.child
        for jp in (x for x in joints if x is not jq and i in (x.parent, x.child)):
            for jr in (x for x in joints if x is not jq and j in (x.parent, x.child)):
                for P in _named_points(mechanism, jp, i):
                    for Q in _named_points(mechanism, jq, i):
                        for R in _named_points(mechanism, jr, j):
                            yield P, Q, R


def _modes_text(chosen: list) -> str:
    turn = {1.0: "left", -1.0: "right"}
    parts = []
    for P, Q, R, signs in chosen:
        names = ", ".join(f'"{b}.{p}"' for b, p, _ in (P, Q, R))
        by_turn = {}
        for k, sg in enumerate(signs, 1):
            by_turn.setdefault(turn[sg], []).append(str(k))
        alts = " or ".join(f'"{t}" (branch{"es" if len(ks) > 1 else ""} {", ".join(ks)})'
                           for t, ks in by_turn.items())
        parts.append(f"[[assembly]] points = [{names}] with turn = {alts}")
    P, Q, R, signs = chosen[0]
    args = ", ".join(f'("{b}", "{p}")' for b, p, _ in (P, Q, R))
    return (f"declare the branch with {'an assembly mode' if len(parts) == 1 else 'assembly modes'}"
            f": in the model file {'; '.join(parts)}; in Python mech.add_assembly_mode("
            f'"mode", {args}, turn="{turn[signs[0]]}")')
