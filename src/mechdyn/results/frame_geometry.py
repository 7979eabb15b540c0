"""What a frame of a mechanism's motion shows, as coordinates: bodies through their
points, joints, ground anchors, slider guides, springs, stops, loads and joint forces, and
a traced point (:func:`frame_geometry`), for :mod:`mechdyn.results.animate` to draw and
for the tests to compare with :func:`mechdyn.model.constraints.point_position`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from ..kernels import rows_numpy
from ..kernels.planar import rotate
from ..mechanism.load import Force, Spring
from ..model.constraints import extend, point_position, travel_rows
from ..model.state import side_token
from ..model.variable import parse as parse_variable
from .table import deg_or_mm

__all__ = ["frame_geometry", "frame_indices", "MechanismDrawing", "MAX_FRAMES"]

#: largest number of frames drawn by default
MAX_FRAMES = 200


@dataclass(frozen=True)
class MechanismDrawing:
    """What to draw of a model, in body-frame coordinates (built once per record).

    Attributes
    ----------
    bodies : dict str -> (ndarray (k, 2), str)
        Outline of each moving body in its frame, m, and its style: ``"polygon"``
        (closed), ``"bar"`` (open polyline), ``"block"`` (closed slider block) or
        ``"disc"`` (one point).
    revolutes, locks : dict str -> (str, ndarray (2,))
        Child body and the joint point in the child frame (a lock: the child
        frame origin), m.
    anchors : dict str -> ndarray (2,)
        Ground points of joints to the ground, ground frame, m (by joint name).
    guides : dict str -> (str, ndarray (2, 2))
        Parent body (or ``"ground"``) and the guide segment's two ends in the
        parent frame, m.
    size : float
        Drawing size of joint circles, blocks and anchors, m.
    springs : dict str -> ((str, ndarray (2,)), (str, ndarray (2,)))
        The two ends of every linear spring: body and point in its frame, m.
    stops : dict str -> (str, ndarray (2, 2))
        Every limit of a stop on a travel or an angle (``"<stop>@lower"``,
        ``"<stop>@upper"``): the body it is fixed to and a short bar (travel) or ray
        (angle) at the limit in that body's frame, m.
    loads : dict str -> (str, ndarray (2,), ndarray (2,), bool)
        Every force load: body, point in its frame, direction of a positive magnitude,
        and whether the direction turns with the body.
    """

    bodies: dict
    revolutes: dict
    locks: dict
    anchors: dict
    guides: dict
    size: float
    springs: dict = field(default_factory=dict)
    stops: dict = field(default_factory=dict)
    loads: dict = field(default_factory=dict)


def _drawing(model, x: np.ndarray) -> MechanismDrawing:
    """Build the :class:`MechanismDrawing` of a model for poses ``x`` (n, n_x)."""
    mech = model.mechanism
    ground = "ground"
    tol = 1e-9 * model.length_scale
    pts = {b: [np.asarray(p, dtype=float) for p in mech.bodies[b].points.values()]
           for b in model.body_names}
    revolutes, locks, anchors, guides = {}, {}, {}, {}
    guided: dict[str, np.ndarray] = {}
    for name, j in mech.joints.items():
        kind = model.joint_kind(name)
        if kind == "lock":
            locks[name] = (j.child if j.child != ground else j.parent, np.zeros(2))
            continue
        pp = model.point_local(j.parent, j.parent_point)
        cp = model.point_local(j.child, j.child_point)
        if j.parent != ground:
            pts[j.parent].append(pp)
        if j.child != ground:
            pts[j.child].append(cp)
        if kind == "revolute":
            revolutes[name] = (j.child, cp) if j.child != ground else (j.parent, pp)
            if ground in (j.parent, j.child):
                anchors[name] = pp if j.parent == ground else cp
        else:  # prismatic: a guide line on the parent, a block on the child
            k = model.pri.names.index(name)
            u = model.pri.ui[k]
            if j.child != ground:  # the guide's direction in the child frame
                guided[j.child] = rotate(-model.pri.angle[k], u)
            guides[name] = (j.parent, pp, u, j.child)

    # the symbols' size follows the region swept by all points and body origins
    allp = [_world(model, x, b, np.array([*p, np.zeros(2)])).reshape(-1, 2)
            for b, p in pts.items()]
    span = float(np.max(np.ptp(np.concatenate(allp), axis=0))) if allp else 0.0
    size = 0.035 * (span if span > 0 else model.length_scale)
    bodies = {}
    for b in model.body_names:
        p: list[np.ndarray] = []
        for a in pts[b]:  # the distinct points
            if all(np.hypot(*(a - q)) > tol for q in p):
                p.append(a)
        if len(p) >= 3:  # ordered around their centroid: a simple polygon
            d = np.array(p) - np.mean(p, axis=0)
            bodies[b] = (np.array(p)[np.argsort(np.arctan2(d[:, 1], d[:, 0]))], "polygon")
        elif len(p) == 2:
            bodies[b] = (np.array(p), "bar")
        else:
            c = p[0] if p else np.asarray(model.com[model.body_index(b)], dtype=float)
            if b in guided:
                u = guided[b]  # the block's corners along the guide and across it
                corners = np.array([[1.6, 0.9], [-1.6, 0.9], [-1.6, -0.9], [1.6, -0.9]]) * size
                bodies[b] = (c + corners @ np.array([u, [-u[1], u[0]]]), "block")
            else:
                bodies[b] = (c[None, :], "disc")
    # guide segments: the travel range of the child point over the motion, plus margins
    out_guides = {}
    for name, (parent, pp, u, child) in guides.items():
        if child == ground or parent == child:
            continue
        s = rows_numpy.values(travel_rows(model, name), x)[:, 0]
        lo, hi = float(np.min(s)), float(np.max(s))
        m = max(2.5 * size, 0.1 * (hi - lo))
        out_guides[name] = (parent, np.array([pp + (lo - m) * u, pp + (hi + m) * u]))
    springs = {ld.name: ((ld.body1, model.point_local(ld.body1, ld.point1)),
                         (ld.body2, model.point_local(ld.body2, ld.point2)))
               for ld in mech.loads if isinstance(ld, Spring)}
    loads = {ld.name: (ld.body, model.point_local(ld.body, ld.point),
                       np.asarray(ld.direction, float), ld.frame == "body")
             for ld in mech.loads if isinstance(ld, Force)}
    return MechanismDrawing(bodies, revolutes, locks, anchors, out_guides, size, springs,
                            _stops(model, bodies, size), loads)


def _stops(model, bodies: dict, size: float) -> dict:
    """The limits of the stops on a travel (a bar across the guide) or an angle (a ray from
    the pivot along the body's arm at the limit), each in the frame of the body it is fixed
    to; stops on other quantities (a point's x or y) are not drawn."""
    mech = model.mechanism
    out = {}
    for stop in (mech.extras or {}).get("stops", []):
        var = parse_variable(stop.variable, model.coordinate_names)
        offset, joint, body = 0.0, None, None
        if var.kind == "coordinate":
            c = mech.coordinates[var.name]
            if c.kind in ("x", "y"):
                continue  # a body's position, like a point's x or y
            offset, joint, body = c.offset, c.joint, c.body
        elif var.kind == "joint":
            joint = var.name
        elif var.kind == "angle":
            body = var.name
        else:
            continue
        for side in stop.sides():
            limit = getattr(stop, side) - offset
            seg = _limit_mark(model, bodies, size, joint, body, limit)
            if seg is not None:
                out[side_token(stop.name, side)] = seg
    return out


def _limit_mark(model, bodies, size, joint, body, limit):
    """(body, segment (2, 2)) marking the limit ``limit`` of a travel or an angle."""
    mech = model.mechanism
    if joint is not None and model.joint_kind(joint) == "prismatic":
        j = mech.joints[joint]
        k = model.pri.names.index(joint)
        u = model.pri.ui[k]
        c = model.point_local(j.parent, j.parent_point) + limit * u
        n = np.array([-u[1], u[0]]) * 2.2 * size
        return j.parent, np.array([c - n, c + n])
    if joint is not None:  # a revolute: the child's arm at the relative angle, in the parent
        j = mech.joints[joint]
        pivot = model.point_local(j.parent, j.parent_point)
        arm = _arm(model, bodies, j.child, model.point_local(j.child, j.child_point))
        frame, angle = j.parent, limit
    elif body is not None:  # an absolute angle: the arm from the body's pivot, in the ground
        js = [j for j in mech.joints.values() if model.joint_kind(j.name) == "revolute"
              and body in (j.parent, j.child)]
        j = next((j for j in js if "ground" in (j.parent, j.child)), js[0] if js else None)
        if j is None:
            return None
        local = model.point_local(body, j.child_point if j.child == body else j.parent_point)
        other = (j.parent if j.child == body else j.child)
        pivot = (model.point_local(other, j.parent_point if j.child == body else j.child_point)
                 if other == "ground" else None)
        if pivot is None:
            return None  # the pivot moves: no fixed mark
        arm, frame, angle = _arm(model, bodies, body, local), "ground", limit
    else:
        return None
    a = angle + np.arctan2(arm[1], arm[0])
    r = max(float(np.hypot(*arm)), 4.0 * size)
    return frame, np.array([pivot, pivot + r * np.array([np.cos(a), np.sin(a)])])


def _arm(model, bodies, body, pivot_local) -> np.ndarray:
    """From a pivot to the body's farthest outline point, in the body's frame."""
    pts = np.asarray(bodies.get(body, (np.zeros((1, 2)), ""))[0], float) - pivot_local
    far = pts[np.argmax(np.hypot(pts[:, 0], pts[:, 1]))] if len(pts) else np.zeros(2)
    return far if np.hypot(*far) > 0 else np.array([1.0, 0.0]) * model.length_scale


def _world(model, x: np.ndarray, body: str, local: np.ndarray) -> np.ndarray:
    """Ground-frame positions (n, k, 2) of body-frame points ``local`` (k, 2) over ``x``."""
    pose = extend(model, x)[:, model.body_index(body)]
    return pose[:, None, :2] + rotate(pose[:, 2, None], local)


def trace_spec(model, trace, what: str = "trace") -> tuple[str, object] | None:
    """(body, point) of ``"BODY.POINT"`` or a pair, checked against the model; None for None."""
    if trace is None:
        return None
    if isinstance(trace, str):
        body, sep, point = trace.partition(".")
        if not sep or not point:
            raise ModelError(f"{what} {trace!r}: write it as BODY.POINT (e.g. 'rod.B' or "
                             "'rod.com')")
        trace = (body, point)
    body, point = trace
    model.point_local(body, point)  # clear error for unknown names
    return body, point


def _record_parts(record):
    """(model, x (n, n_x)) of a record, or a clear error."""
    model = getattr(record, "model", None)
    x = getattr(record, "x", None)
    if model is None or x is None:
        raise ModelError(f"cannot animate a {type(record).__name__}: it needs body poses 'x' "
                         "and its compiled 'model' (a KinematicSweep, Trajectory or "
                         "Kinetostatics)")
    x = np.atleast_2d(np.asarray(x, dtype=float))
    if x.shape[0] == 0:
        raise ModelError(f"the {type(record).__name__} has no positions to draw "
                         f"(status {getattr(record, 'status', '?')!r})")
    return model, x


def _labels(record, idx: np.ndarray) -> list[str]:
    over = getattr(record, "over", None)
    t = getattr(record, "t", None)
    if over is not None and getattr(record, "values", None) is not None:
        v, unit = deg_or_mm(np.asarray(record.values)[idx], record.over_is_angle)
        digits = 2 if record.over_is_angle else 3
        return [f"{over} = {a:8.{digits}f} {unit}" for a in v]
    if t is not None:
        tt = np.asarray(t)[idx]
        span = float(np.ptp(np.asarray(t))) if np.size(t) else 0.0
        if 0 < span < 1.0:
            return [f"t = {a * 1e3:9.3f} ms" for a in tt]
        return [f"t = {a:9.4f} s" for a in tt]
    return [f"frame {i}" for i in idx]


def frame_indices(record, frames: int | None = None) -> np.ndarray:
    """Indices of the samples drawn: at most ``frames`` (default ``min(n, 200)``).

    For a record with increasing times (a trajectory) the frames are equally spaced
    in time (the sample nearest to each frame time); otherwise equally spaced in
    index.  The first and the last sample are always drawn.
    """
    _, x = _record_parts(record)
    n = x.shape[0]
    m = min(n, MAX_FRAMES) if frames is None else int(frames)
    if m < 1:
        raise ModelError(f"frames must be at least 1, got {frames}")
    m = min(m, n)
    t = getattr(record, "t", None)
    if t is not None and np.size(t) == n and n > 1 and np.all(np.diff(t) >= 0) and t[-1] > t[0]:
        t = np.asarray(t, dtype=float)
        goal = np.linspace(t[0], t[-1], m)
        idx = np.clip(np.searchsorted(t, goal), 0, n - 1)
        prev = np.clip(idx - 1, 0, n - 1)
        idx = np.where(np.abs(t[prev] - goal) < np.abs(t[idx] - goal), prev, idx)
    else:
        idx = np.round(np.linspace(0, n - 1, m)).astype(int)
    return np.unique(idx)


def frame_geometry(record, index=None, *, trace=None) -> dict:
    """Ground-frame drawing coordinates of frames of a record (what :func:`animate` draws).

    Parameters
    ----------
    record : KinematicSweep, Trajectory or Kinetostatics
        Anything with body poses ``x`` (n, n_x) and its compiled ``model``.
    index : int or array_like of int, optional
        Samples (default all).
    trace : "BODY.POINT" or (body, point), optional
        Add the path of this point.

    Returns
    -------
    dict
        ``bodies``: name -> (m, k, 2) outline (m frames, k points; style in
        ``styles``); ``revolutes``, ``locks``: joint -> (m, 2) joint point;
        ``anchors``: joint -> (2,) ground point; ``guides``: joint -> (m, 2, 2)
        guide segment; ``springs``: spring -> (m, 2, 2) its two ends; ``stops``:
        ``"<stop>@<side>"`` -> (m, 2, 2) the bar (travel) or ray (angle) at the limit;
        ``loads``: force load -> (m, 2, 2) tail (the point) and head of an arrow along a
        positive magnitude; ``reactions``: joint -> (m, 2, 2) the joint force of a
        kinetostatic record as an arrow from the joint point (``force_scale`` m/N; empty
        for other records); ``trace``: (m, 2) or absent; ``limits``: ((xmin, xmax),
        (ymin, ymax)) over the whole motion; ``size``: symbol size; all in m.
    """
    model, x = _record_parts(record)
    drawing, spec = _drawing(model, x), trace_spec(model, trace)
    g = _geometry(model, x, drawing, index, spec)
    every = g if index is None else _geometry(model, x, drawing, None, spec)  # all frames
    s = g["size"]
    arrs = [a.reshape(-1, 2) for kind in ("bodies", "guides", "springs", "stops", "loads")
            for a in every[kind].values()]
    _reactions(record, g, every, np.concatenate(arrs), index)
    arrs += [a.reshape(-1, 2) for a in every["reactions"].values()]
    for a in every["anchors"].values():  # the anchor triangles and their ground lines
        arrs.append(np.asarray(a).reshape(1, 2) + [[-1.8 * s, -1.8 * s], [1.8 * s, 0.0]])
    if "trace" in every:
        arrs.append(every["trace"])
    P = np.concatenate(arrs)
    lo, hi = P.min(axis=0) - 1.5 * s, P.max(axis=0) + 1.5 * s
    g["limits"] = ((float(lo[0]), float(hi[0])), (float(lo[1]), float(hi[1])))
    return g


def _reactions(record, g, every, points, index) -> None:
    """The joint forces of a kinetostatic record as arrows from the joint points (tail at
    the point, force on the child from the parent), scaled so that the largest is a fifth
    of the drawing's size: ``reactions`` (m, 2, 2) and ``force_scale`` (m/N) in ``g``
    (and ``every``); none for other records."""
    forces = getattr(record, "reactions", None)
    where = getattr(record, "joint_points", None)
    for h in (g, every):
        h["reactions"], h["force_scale"] = {}, 0.0
    if not forces or not where:
        return
    peak = max((float(np.nanmax(np.hypot(f[:, 0], f[:, 1]))) for f in forces.values()
                if np.isfinite(f).any()), default=0.0)
    if peak <= 0:
        return
    scale = 0.2 * float(np.max(np.ptp(points, axis=0))) / peak
    sel = slice(None) if index is None else np.atleast_1d(np.asarray(index, int))
    for j, f in forces.items():
        p, f = np.asarray(where[j], float), np.nan_to_num(np.asarray(f, float)[:, :2])
        arrow = np.stack([p, p + scale * f], axis=1)
        every["reactions"][j], g["reactions"][j] = arrow, arrow[sel]
    g["force_scale"] = every["force_scale"] = scale


def _geometry(model, x, drawing: MechanismDrawing, index, trace) -> dict:
    sel = np.arange(x.shape[0]) if index is None else np.atleast_1d(np.asarray(index, int))
    xs = x[sel]
    g: dict = {"bodies": {}, "styles": {}, "revolutes": {}, "locks": {}, "guides": {},
               "anchors": dict(drawing.anchors), "size": drawing.size, "springs": {},
               "stops": {}, "loads": {}}
    for b, (local, style) in drawing.bodies.items():
        g["bodies"][b] = _world(model, xs, b, local)
        g["styles"][b] = style
    for kind in ("revolutes", "locks"):
        for j, (b, p) in getattr(drawing, kind).items():
            g[kind][j] = point_position(model, xs, b, p)
    for j, (b, seg) in drawing.guides.items():
        g["guides"][j] = np.array(_world(model, xs, b, seg))
    for name, ((b1, p1), (b2, p2)) in drawing.springs.items():
        g["springs"][name] = np.stack([point_position(model, xs, b1, p1),
                                       point_position(model, xs, b2, p2)], axis=1)
    for name, (b, seg) in drawing.stops.items():
        g["stops"][name] = _world(model, xs, b, seg)
    for name, (b, p, d, turns) in drawing.loads.items():
        tail = point_position(model, xs, b, p)
        if turns:
            d = rotate(extend(model, xs)[:, model.body_index(b), 2], d)
        g["loads"][name] = np.stack([tail, tail + 4.0 * drawing.size * np.broadcast_to(
            d, tail.shape)], axis=1)
    if trace is not None:
        body, point = trace
        g["trace"] = point_position(model, xs, body, point)
    return g


def _zigzag(a: np.ndarray, b: np.ndarray, size: float, turns: int = 7) -> np.ndarray:
    """A spring's zigzag from ``a`` to ``b`` (k, 2): straight ends, ``turns`` zigs between."""
    d = np.asarray(b, float) - np.asarray(a, float)
    length = float(np.hypot(*d))
    if length == 0:
        return np.array([a, b], float)
    u = d / length
    n = np.array([-u[1], u[0]])
    t = np.linspace(0.2, 0.8, 2 * turns + 1)
    side = np.where(np.arange(t.size) % 2 == 1, 1.0, 0.0) * np.where(
        np.arange(t.size) % 4 == 1, 1.0, -1.0)
    pts = a + np.outer(t * length, u) + np.outer(side * 0.7 * size, n)
    return np.vstack([a, pts, b])
