"""Reading the ``[bodies]``, ``[joints]`` and ``[coordinates]`` tables of a model file.

Private names
-------------
_BodiesJoints
    The readers of one body (with its points, its sketch frame and the inertia
    about a point), one joint (revolute, prismatic, lock) and one coordinate,
    each returning the :mod:`mechdyn.mechanism` element or raising
    :class:`~mechdyn.modelfile.reader._Failed` with the problem recorded.
"""

from __future__ import annotations

import math

from ..errors import did_you_mean
from ..mechanism import Body, Coordinate, Lock, Prismatic, Revolute
from .reader import _Failed, _Reader

_POSE_KINDS = ("length", "length", "angle")


class _BodiesJoints(_Reader):
    """Reads the elements of the ``[bodies]``, ``[joints]`` and ``[coordinates]`` tables."""

    # ------------------------------------------------------------ bodies
    def body(self, bname: str, spec: dict) -> Body:
        P = ("bodies", bname)
        failed = False

        def get(key, fn, default=None):
            nonlocal failed
            if key not in spec:
                return default
            try:
                return fn(spec[key])
            except _Failed:
                failed = True
                return default

        mass = get("mass", lambda v: self.nonneg(self.quantity(v, "mass", *P, "mass"), v, "kg",
                                                 *P, "mass"), 0.0)
        inertia = get("inertia", lambda v: self.nonneg(self.quantity(v, "inertia", *P, "inertia"),
                                                       v, "kg*m^2", *P, "inertia"), 0.0)
        frame = spec.get("frame", "body")
        raw_points = self.doc["bodies"][bname].get("points", {})
        raw_points = raw_points if isinstance(raw_points, dict) else {}
        points = {}
        for pname, val in raw_points.items():
            if self.broken(*P, "points", pname):
                failed = True
                continue
            if pname == "com":
                self.problem(f"{self.where(*P, 'points', pname)}: the point name 'com' is "
                             "reserved for the centre of mass; use the key 'com' of the body")
                failed = True
                continue
            try:
                points[pname] = self.vector(val, "length", *P, "points", pname)
            except _Failed:
                failed = True
        com = get("com", lambda v: self.vector(v, "length", *P, "com"), (0.0, 0.0))

        if frame == "sketch":
            if "pose" in spec:
                self.problem(f"{self.where(*P, 'pose')}: a body with frame = 'sketch' takes its "
                             "pose from 'frame_points'; remove 'pose'")
                failed = True
            ox, oy, th = 0.0, 0.0, 0.0
            fp = spec.get("frame_points")
            if fp is not None:
                for k, pn in enumerate(fp):
                    if pn not in points:
                        self.problem(f"{self.where(*P, 'frame_points')}[{k}]: unknown point "
                                     f"{pn!r} of body {bname!r}; valid point names: "
                                     + ", ".join(repr(p) for p in points))
                        failed = True
                if failed:
                    raise _Failed
                (ox, oy), (x1, y1) = points[fp[0]], points[fp[1]]
                if math.hypot(x1 - ox, y1 - oy) == 0:
                    self.problem(f"{self.where(*P, 'frame_points')}: {fp!r}: the two points "
                                 "coincide, so they give no x axis")
                    raise _Failed
                th = math.atan2(y1 - oy, x1 - ox)
            self.sketch_frames[bname] = (ox, oy, th)
            points = {k: self.to_body_frame(bname, v) for k, v in points.items()}
            com = self.to_body_frame(bname, com)
            pose = (ox, oy, th)
        else:
            if "frame_points" in spec:
                self.problem(f"{self.where(*P, 'frame_points')}: only used with "
                             "frame = 'sketch'")
                failed = True
            pose = get("pose", lambda v: self.vector(v, _POSE_KINDS, *P, "pose"),
                       (0.0, 0.0, 0.0))

        about = spec.get("inertia_about", "com")
        if about != "com" and not failed:
            if about not in points:
                self.problem(f"{self.where(*P, 'inertia_about')}: unknown point {about!r} of "
                             f"body {bname!r}; valid point names: "
                             + ", ".join(repr(p) for p in ["com", *points]))
                raise _Failed
            d2 = (points[about][0] - com[0]) ** 2 + (points[about][1] - com[1]) ** 2
            jc = inertia - mass * d2
            if jc < -1e-12 * max(inertia, 1e-30):
                self.problem(f"{self.where(*P, 'inertia')}: {spec['inertia']!r} about point "
                             f"{about!r} is less than mass * distance^2 = {mass * d2:.6g} "
                             "kg*m^2 from the centre of mass: the centroidal inertia would be "
                             "negative")
                raise _Failed
            inertia = max(jc, 0.0)
        if failed:
            raise _Failed
        return Body(bname, mass=mass, inertia=inertia, com=com, points=points, pose=pose)

    # ------------------------------------------------------------ joints
    def joint(self, jname: str, spec: dict):
        P = ("joints", jname)
        failed = False
        try:
            parent = self.body_name(spec["parent"], *P, "parent")
        except _Failed:
            parent, failed = None, True
        try:
            child = self.body_name(spec["child"], *P, "child")
        except _Failed:
            child, failed = None, True
        if parent is not None and parent == child:
            self.problem(f"{self.where(*P)}: parent and child are the same body {parent!r}")
            raise _Failed
        jtype = spec["type"]

        def ref(body, key, default=(0.0, 0.0)):
            nonlocal failed
            if body is None or key not in spec:
                return default
            try:
                return self.point_ref(body, spec[key], *P, key)
            except _Failed:
                failed = True
                return default

        if jtype == "revolute":
            if "point" in spec:
                both = spec["point"]
                for role, body in (("parent_point", parent), ("child_point", child)):
                    if role in spec:
                        self.problem(f"{self.where(*P, role)}: give either 'point' or "
                                     "'parent_point'/'child_point', not both")
                        failed = True
                    elif body is not None and both not in self.body_points.get(body, []):
                        self.problem(f"{self.where(*P, 'point')}: unknown point {both!r} of "
                                     f"body {body!r}; valid point names: "
                                     + ", ".join(repr(p) for p in self.body_points[body]))
                        failed = True
                pp = cp = both
            else:
                pp = ref(parent, "parent_point")
                cp = ref(child, "child_point")
            if failed:
                raise _Failed
            return Revolute(jname, parent, child, pp, cp)
        if jtype == "prismatic":
            pp = ref(parent, "parent_point")
            cp = ref(child, "child_point")
            axis = (1.0, 0.0)
            if "axis" in spec and parent is not None:
                try:
                    axis = self.direction(parent, spec["axis"], *P, "axis")
                except _Failed:
                    failed = True
            angle = None
            if "angle" in spec:
                try:
                    angle = self.quantity(spec["angle"], "angle", *P, "angle")
                except _Failed:
                    failed = True
            if failed:
                raise _Failed
            return Prismatic(jname, parent, child, pp, axis, cp, angle)
        # lock
        offset = None
        if "offset" in spec:
            try:
                offset = self.vector(spec["offset"], _POSE_KINDS, *P, "offset")
            except _Failed:
                failed = True
        if failed:
            raise _Failed
        return Lock(jname, parent, child, bool(spec.get("engaged", True)), offset)

    # ------------------------------------------------------------ coordinates
    def coordinate(self, cname: str, spec: dict) -> Coordinate:
        P = ("coordinates", cname)
        kind = spec["kind"]
        body = joint = None
        if kind == "angle":
            if "joint" in spec:
                self.problem(f"{self.where(*P, 'joint')}: kind 'angle' measures a body; "
                             "give 'body', not 'joint'")
                raise _Failed
            if "body" not in spec:
                self.problem(f"{self.where(*P)}: missing key 'body' (kind 'angle' measures the "
                             "absolute angle of a body)")
                raise _Failed
            body = self.body_name(spec["body"], *P, "body", ground_ok=False)
        else:
            want = "revolute" if kind == "relative_angle" else "prismatic"
            if "body" in spec:
                self.problem(f"{self.where(*P, 'body')}: kind {kind!r} measures a {want} "
                             "joint; give 'joint', not 'body'")
                raise _Failed
            if "joint" not in spec:
                self.problem(f"{self.where(*P)}: missing key 'joint' (kind {kind!r} needs a "
                             f"{want} joint)")
                raise _Failed
            joint = spec["joint"]
            if joint not in self.joint_types:
                self.problem(f"{self.where(*P, 'joint')}: "
                             + did_you_mean(joint, self.joint_types, "joint"))
                raise _Failed
            if self.joint_types[joint] != want:
                valid = [n for n, t in self.joint_types.items() if t == want]
                self.problem(f"{self.where(*P, 'joint')}: {joint!r} is a "
                             f"{self.joint_types[joint]} joint, but kind {kind!r} needs a {want} "
                             f"joint; {want} joints: "
                             + (", ".join(repr(v) for v in valid) or "(none)"))
                raise _Failed
        offset = 0.0
        if "offset" in spec:
            qkind = "length" if kind == "travel" else "angle"
            offset = self.quantity(spec["offset"], qkind, *P, "offset")
        return Coordinate(cname, kind, body, joint, offset)
