"""Reading the ``[bodies]``, ``[joints]`` and ``[coordinates]`` tables of a model file."""

from __future__ import annotations

import math

from ..kernels.inertia import centroidal_inertia
from ..mechanism import GROUND, Body, Coordinate, Lock, Prismatic, Revolute
from ..mechanism.body import unknown_point
from ..mechanism.coordinate import LENGTH_KINDS, coordinate_problems
from ..mechanism.joint import ELASTIC_FIELDS, FRICTION_FIELDS
from .reader import _Failed, _Reader

_POSE_KINDS = ("length", "length", "angle")


class _BodiesJoints(_Reader):
    """Reads the elements of the ``[bodies]``, ``[joints]`` and ``[coordinates]`` tables."""

    def body(self, bname: str, spec: dict) -> Body:
        P = ("bodies", bname)
        mass = self.opt(spec, "mass", "mass", *P, nonneg=True)
        inertia = self.opt(spec, "inertia", "inertia", *P, nonneg=True)
        points = self.points(self.doc["bodies"][bname].get("points"), *P, "points",
                             hint=" for the centre of mass; use the key 'com' of the body")
        com = self.opt(spec, "com", "length", *P, default=(0.0, 0.0), read=self.vector)

        if spec.get("frame", "body") == "sketch":
            if "pose" in spec:
                self.problem(f"{self.where(*P, 'pose')}: a body with frame = 'sketch' takes its "
                             "pose from 'frame_points'; remove 'pose'")
                self.failed = True
            pose = (0.0, 0.0, 0.0)
            fp = spec.get("frame_points")
            if fp is not None:
                for k, pn in enumerate(fp):
                    if pn not in points:
                        self.problem(f"{self.where(*P, 'frame_points')}[{k}]: "
                                     + unknown_point(pn, bname, points))
                        self.failed = True
                self.check()
                (ox, oy), (x1, y1) = points[fp[0]], points[fp[1]]
                if math.hypot(x1 - ox, y1 - oy) == 0:
                    self.problem(f"{self.where(*P, 'frame_points')}: {fp!r}: the two points "
                                 "coincide, so they give no x axis")
                    raise _Failed
                pose = (ox, oy, math.atan2(y1 - oy, x1 - ox))
            self.sketch_frames[bname] = pose
            points = {k: self.to_body_frame(bname, v) for k, v in points.items()}
            com = self.to_body_frame(bname, com)
        else:
            if "frame_points" in spec:
                self.problem(f"{self.where(*P, 'frame_points')}: only used with "
                             "frame = 'sketch'")
                self.failed = True
            pose = self.opt(spec, "pose", _POSE_KINDS, *P, default=None, read=self.vector)

        about = spec.get("inertia_about", "com")
        if about != "com" and not self.failed:
            if about not in points:
                self.problem(f"{self.where(*P, 'inertia_about')}: "
                             + unknown_point(about, bname, ["com", *points]))
                raise _Failed
            d = (points[about][0] - com[0], points[about][1] - com[1])
            jc = float(centroidal_inertia(inertia, mass, d))
            if jc < -1e-12 * max(inertia, 1e-30):
                self.problem(f"{self.where(*P, 'inertia')}: {spec['inertia']!r} about point "
                             f"{about!r} is less than mass * distance^2 = {inertia - jc:.6g} "
                             "kg*m^2 from the centre of mass: the centroidal inertia would be "
                             "negative")
                raise _Failed
            inertia = max(jc, 0.0)
        self.check()
        return Body(bname, mass=mass, inertia=inertia, com=com, points=points, pose=pose)

    def joint(self, jname: str, spec: dict):
        P = ("joints", jname)
        parent = self.soft(self.body_name, spec["parent"], *P, "parent")
        child = self.soft(self.body_name, spec["child"], *P, "child")
        if parent is not None and parent == child:
            self.problem(f"{self.where(*P)}: parent and child are the same body {parent!r}")
            raise _Failed

        def ref(body, key):
            if body is None or key not in spec:
                return (0.0, 0.0)
            return self.soft(self.point_ref, body, spec[key], *P, key, default=(0.0, 0.0))

        if spec["type"] == "revolute":
            both = "point" in spec  # one point name on both bodies
            for role in ("parent_point", "child_point"):
                if both and role in spec:
                    self.problem(f"{self.where(*P, role)}: give either 'point' or "
                                 "'parent_point'/'child_point', not both")
                    self.failed = True
            pp = ref(parent, "point" if both else "parent_point")
            cp = ref(child, "point" if both else "child_point")
            fr = self.friction(spec, "revolute", *P)
            if fr.get("friction", 0.0) > 0 and not fr.get("pin_radius", 0.0) > 0:
                self.problem(f"{self.where(*P, 'friction')}: a pin with friction needs its "
                             "radius: add pin_radius (e.g. \"15 mm\")")
                self.failed = True
            self.check()
            return Revolute(jname, parent, child, pp, cp, **fr)
        if spec["type"] == "prismatic":
            pp, cp = ref(parent, "parent_point"), ref(child, "child_point")
            axis = (1.0, 0.0)
            if "axis" in spec and parent is not None:
                axis = self.soft(self.direction, parent, spec["axis"], *P, "axis", default=axis)
            angle = self.opt(spec, "angle", "angle", *P, default=None)
            fr = self.friction(spec, "prismatic", *P)
            self.check()
            return Prismatic(jname, parent, child, pp, axis, cp, angle, **fr)
        offset = self.opt(spec, "offset", _POSE_KINDS, *P, default=None, read=self.vector)
        self.check()
        return Lock(jname, parent, child, bool(spec.get("engaged", True)), offset)

    def friction(self, spec: dict, jtype: str, *P) -> dict:
        """The friction (and elastic) keys of a joint present in ``spec``, in SI, each
        >= 0."""
        return {f: self.opt(spec, f, kind, *P, nonneg=True)
                for f, kind in (*FRICTION_FIELDS[jtype], *ELASTIC_FIELDS[jtype]) if f in spec}

    def coordinate(self, cname: str, spec: dict) -> Coordinate:
        P = ("coordinates", cname)
        kind, body, joint = spec["kind"], spec.get("body"), spec.get("joint")
        bodies = [b for b in self.body_points if b != GROUND]
        for key, msg in coordinate_problems(kind, body, joint, bodies, self.joint_types):
            self.problem(f"{self.where(*P, key)}: {msg}")
            raise _Failed
        offset = self.opt(spec, "offset", "length" if kind in LENGTH_KINDS else "angle", *P)
        return Coordinate(cname, kind, body, joint, offset)
