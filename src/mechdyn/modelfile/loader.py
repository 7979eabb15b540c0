"""Read a TOML model file into a :class:`~mechdyn.mechanism.Mechanism`.

The file is checked in three passes, and every problem found is reported at
once in one :class:`~mechdyn.errors.ModelError`:

1. structure (tables, keys, TOML types) against ``schema.json``;
2. units and values (``"15 kg"`` for a length, a negative mass, unknown body,
   joint, point or coordinate names, which list the valid names);
3. the mechanism itself (:meth:`Mechanism.validate`: degrees of freedom,
   assembly of the sketch, independent coordinates), whose messages are
   prefixed with the file name.

The format is described in ``docs/model-file.md``.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..errors import MechdynError, ModelError, UnitError, did_you_mean
from ..mechanism import (
    GROUND,
    Body,
    Coordinate,
    Drive,
    Force,
    Ground,
    Lock,
    Mechanism,
    Prismatic,
    Revolute,
    RotarySpring,
    Spring,
    Table,
    Torque,
    TorqueSpeedCurve,
    pulse,
)
from ..model.variable import parse
from ..units import parse_quantity, parse_vector
from .drives import drive_from_table
from .schema import locate, schema_problems
from .switches import TABLES as SWITCH_TABLES
from .switches import parse_switches

__all__ = ["load", "loads", "build", "read_document"]

_POSE_KINDS = ("length", "length", "angle")
_LOAD_REQUIRED = {"spring": ("body1", "point1", "body2", "point2"),
                  "damper": ("body1", "point1", "body2", "point2"),
                  "rotary_spring": ("joint",), "rotary_damper": ("joint",),
                  "force": ("body", "magnitude"), "torque": ("body", "magnitude")}


def load(path: str | Path) -> Mechanism:
    """Read a model file.

    Parameters
    ----------
    path : str or Path
        A TOML model file (see ``docs/model-file.md``).

    Returns
    -------
    Mechanism
        The validated mechanism; initial coordinates and rates given in the file
        are in ``mechanism.extras["initial"] = {"q": {name: value}, "qdot": {...}}``
        (SI: rad, m, rad/s, m/s).

    Raises
    ------
    ModelError
        Every problem of the file, each citing the file, the table and the key.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ModelError(f"{path}: cannot read the model file: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise ModelError(f"{path.name}: the model file is not UTF-8 text: {exc.reason} "
                         f"at byte {exc.start}") from None
    return loads(text, name=path.name, default_title=path.stem)


def loads(text: str, name: str = "<string>", *, default_title: str | None = None) -> Mechanism:
    """Read a model from TOML text.

    Parameters
    ----------
    text : str
        The TOML text.
    name : str
        Shown as the file name in error messages.
    default_title : str, optional
        Mechanism name when the file has no ``[model] name``.

    Returns
    -------
    Mechanism
    """
    doc = read_document(text, name)
    return build(doc, name, default_title=default_title)


def read_document(text: str, name: str = "<string>") -> dict:
    """Parse TOML text, turning a syntax error into a :class:`ModelError`."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"{name}: not valid TOML: {exc}") from None


def build(doc: dict, name: str = "<string>", *, default_title: str | None = None) -> Mechanism:
    """Build and validate a mechanism from a parsed model document (see :func:`loads`)."""
    msgs, bad_paths = schema_problems(doc, name)
    builder = _Builder(doc, name, bad_paths)
    builder.problems.extend(msgs)
    mech = builder.run(default_title)
    if builder.problems:
        # all problems about units: raise the more specific UnitError (a ModelError)
        only_units = all(p in builder.unit_problems for p in builder.problems)
        raise (UnitError if only_units else ModelError)(builder.problems)
    try:
        mech.validate()
    except ModelError as exc:
        raise ModelError([f"{name}: {p}" for p in exc.problems]) from None
    except MechdynError as exc:  # assembly or other analysis errors
        raise ModelError(f"{name}: {exc}") from None
    return mech


class _Failed(Exception):
    """A value could not be read; its problem is already recorded."""


class _Builder:
    """Turns a document into mechanism elements, recording every problem."""

    def __init__(self, doc: dict, fname: str, bad_paths: Sequence[tuple]):
        self.doc = doc if isinstance(doc, dict) else {}
        self.fname = fname
        self.bad = [tuple(p) for p in bad_paths]
        self.problems: list[str] = []
        self.unit_problems: set[str] = set()
        self.body_points: dict[str, list[str]] = {}
        #: sketch frame -> body frame of each body given with frame = "sketch": (ox, oy, theta)
        self.sketch_frames: dict[str, tuple[float, float, float]] = {}
        self.joint_types: dict[str, str] = {}
        self.coord_kinds: dict[str, str] = {}

    # ------------------------------------------------------------ helpers
    def where(self, *path) -> str:
        return locate(self.fname, path, self.doc)

    def broken(self, *path) -> bool:
        """True if the schema already reported a problem at or below ``path``."""
        n = len(path)
        return any(p[:n] == tuple(path) for p in self.bad)

    def element(self, fn, path: tuple, spec: dict, required: Sequence[str]):
        """Build one element from the keys of ``spec`` that passed the schema check.

        Keys with a schema problem are left out (so that the other keys are still
        checked); the element is not built if a required key is missing or any
        problem was found in it.
        """
        clean = {k: v for k, v in spec.items() if not self.broken(*path, k)}
        if any(k not in clean for k in required):
            raise _Failed
        try:
            el = fn(path[-1], clean)
        except (ValueError, TypeError) as exc:  # an element's own check; keep it readable
            self.problem(f"{self.where(*path)}: {exc}")
            raise _Failed from None
        if self.broken(*path):
            raise _Failed
        return el

    def problem(self, msg: str):
        if msg not in self.problems:
            self.problems.append(msg)

    def quantity(self, value: Any, kind: str, *path) -> float:
        try:
            return parse_quantity(value, kind, where=self.where(*path))
        except UnitError as exc:
            self.problem(str(exc))
            self.unit_problems.add(str(exc))
            raise _Failed from None

    def vector(self, value: Any, kind, *path, size: int | None = None) -> tuple[float, ...]:
        try:
            return parse_vector(value, kind, self.where(*path), size=size)
        except UnitError as exc:
            self.problem(str(exc))
            self.unit_problems.add(str(exc))
            raise _Failed from None

    def nonneg(self, value: float, raw: Any, unit: str, *path) -> float:
        if value < 0:
            self.problem(f"{self.where(*path)}: {raw!r}: {path[-1]} must be >= 0 {unit}")
            raise _Failed
        return value

    def body_name(self, value: str, *path, ground_ok: bool = True) -> str:
        valid = [b for b in self.body_points if b != GROUND] + ([GROUND] if ground_ok else [])
        if value not in valid:
            self.problem(f"{self.where(*path)}: " + did_you_mean(value, valid, "body"))
            raise _Failed
        return value

    def point_ref(self, body: str, value: Any, *path):
        """A point of ``body``: its name (checked) or coordinates (in the body's input frame)."""
        if isinstance(value, str) and not value.lstrip().startswith("("):
            names = self.body_points.get(body, [])
            if value not in names:
                self.problem(f"{self.where(*path)}: unknown point {value!r} of body {body!r}; "
                             "valid point names: " + ", ".join(repr(p) for p in names))
                raise _Failed
            return value
        xy = self.vector(value, "length", *path)
        return self.to_body_frame(body, xy)

    def to_body_frame(self, body: str, xy) -> tuple[float, float]:
        """Coordinates given in a body's input frame -> its body frame."""
        fr = self.sketch_frames.get(body)
        if fr is None:
            return (float(xy[0]), float(xy[1]))
        ox, oy, th = fr
        dx, dy = xy[0] - ox, xy[1] - oy
        c, s = math.cos(th), math.sin(th)
        return (c * dx + s * dy, -s * dx + c * dy)

    def direction(self, body: str, value: Any, *path) -> tuple[float, float]:
        """A direction: [x, y] numbers or an angle string, in the body's input frame."""
        if isinstance(value, str):
            a = self.quantity(value, "angle", *path)
            d = (math.cos(a), math.sin(a))
        else:
            d = (float(value[0]), float(value[1]))
            if not all(math.isfinite(v) for v in d) or math.hypot(*d) == 0:
                self.problem(f"{self.where(*path)}: {value!r}: must be a non-zero direction "
                             "[x, y]")
                raise _Failed
        th = self.sketch_frames.get(body, (0.0, 0.0, 0.0))[2]
        c, s = math.cos(th), math.sin(th)
        return (c * d[0] + s * d[1], -s * d[0] + c * d[1])

    def section(self, key: str, kind: type = dict):
        val = self.doc.get(key, kind())
        return val if isinstance(val, kind) else kind()

    # ------------------------------------------------------------ passes
    def run(self, default_title: str | None) -> Mechanism:
        model = self.section("model")
        title = model.get("name") if isinstance(model.get("name"), str) else None
        desc = model.get("description") if isinstance(model.get("description"), str) else ""
        mech = Mechanism(name=title or default_title or "mechanism", description=desc)
        if "gravity" in model and not self.broken("model", "gravity"):
            try:
                mech.gravity = self.vector(model["gravity"], "acceleration", "model", "gravity")
            except _Failed:
                pass

        ground = self.section("ground")
        gpoints = ground.get("points", {}) if isinstance(ground.get("points"), dict) else {}
        pts = {}
        for pname, val in gpoints.items():
            if self.broken("ground", "points", pname):
                continue
            if pname == "com":
                self.problem(f"{self.where('ground', 'points', pname)}: the point name 'com' is "
                             "reserved; choose another name")
                continue
            try:
                pts[pname] = self.vector(val, "length", "ground", "points", pname)
            except _Failed:
                pass
        self.body_points[GROUND] = ["com", *gpoints]
        mech.add(Ground(points=pts))

        bodies = self.section("bodies")
        # names first, so that joints may refer to any body
        for bname, spec in bodies.items():
            spec = spec if isinstance(spec, dict) else {}
            points = spec.get("points", {})
            self.body_points[bname] = ["com", *(points if isinstance(points, dict) else {})]
        if GROUND in bodies:
            self.problem(f"{self.where('bodies', GROUND)}: the name {GROUND!r} is reserved for "
                         "the fixed frame; put its points in [ground.points]")
        for bname, spec in bodies.items():
            if bname == GROUND or not isinstance(spec, dict):
                continue
            try:
                mech.add(self.element(self.body, ("bodies", bname), spec, ("mass", "inertia")))
            except _Failed:
                pass

        for jname, spec in self.section("joints").items():
            if isinstance(spec, dict) and isinstance(spec.get("type"), str):
                self.joint_types[jname] = spec["type"]
            if jname in bodies or jname == GROUND:
                self.problem(f"{self.where('joints', jname)}: the name {jname!r} is already "
                             "used by a body; joints and bodies need different names")
                continue
            if not isinstance(spec, dict) or self.broken("joints", jname, "type") \
                    or "type" not in spec:
                continue
            try:
                mech.add(self.element(self.joint, ("joints", jname), spec,
                                      ("type", "parent", "child")))
            except _Failed:
                pass

        for cname, spec in self.section("coordinates").items():
            if isinstance(spec, dict) and isinstance(spec.get("kind"), str):
                self.coord_kinds[cname] = spec["kind"]
            if not isinstance(spec, dict) or self.broken("coordinates", cname, "kind") \
                    or "kind" not in spec:
                continue
            try:
                mech.add(self.element(self.coordinate, ("coordinates", cname), spec, ("kind",)))
            except _Failed:
                pass

        initial = {"q": self.initial("initial", rate=False),
                   "qdot": self.initial("initial_speed", rate=True)}
        if initial["q"] or initial["qdot"]:
            mech.extras["initial"] = initial

        names: set[str] = set()
        for section in ("loads", "drives"):
            for k, spec in enumerate(self.section(section, list)):
                if not isinstance(spec, dict):
                    continue
                if section == "loads" and ("type" not in spec
                                           or self.broken(section, k, "type")):
                    continue
                try:
                    if section == "loads":
                        el = self.element(self.load, (section, k), spec,
                                          _LOAD_REQUIRED.get(spec["type"], ()))
                    else:
                        el = self.element(self.drive, (section, k), spec,
                                          ("coordinate", "type") if "type" in spec
                                          else ("coordinate", "torque"))
                except _Failed:
                    continue
                if el.name in names:
                    self.problem(f"{self.where(section, k)}: name {el.name!r} is used by another "
                                 "load or drive")
                    continue
                names.add(el.name)
                mech.add(el)
        for k, spec in enumerate(self.section("assembly", list)):
            if isinstance(spec, dict) and not self.broken("assembly", k):
                self.assembly_mode(mech, k, spec)
        if any(k in self.doc for k in SWITCH_TABLES):
            for p in parse_switches(self.doc, mech, self.fname):
                self.problem(p)
        return mech

    # ------------------------------------------------------------ assembly modes
    def assembly_mode(self, mech: Mechanism, k: int, spec: dict) -> None:
        """An [[assembly]] entry: points "body.point" P, Q, R and the turn at Q."""
        pts = []
        for i, text in enumerate(spec.get("points", [])):
            body, _, point = str(text).partition(".")
            if not point:
                self.problem(f"{self.where('assembly', k, 'points', i)}: {text!r}: write a "
                             "point as \"body.point\", e.g. \"rod.B\"")
                return
            pts.append((body, point))
        if len(pts) != 3 or "turn" not in spec:
            return
        name = spec.get("name") or f"{pts[1][0]}.{pts[1][1]}"
        mech.add_assembly_mode(name, *pts, turn=spec["turn"])

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

    def coord_value_kind(self, cname: str, rate: bool) -> str:
        travel = self.coord_kinds.get(cname) == "travel"
        if rate:
            return "velocity" if travel else "angular_velocity"
        return "length" if travel else "angle"

    def initial(self, section: str, rate: bool) -> dict[str, float]:
        out: dict[str, float] = {}
        for cname, val in self.section(section).items():
            if self.broken(section, cname):
                continue
            if cname not in self.coord_kinds:
                self.problem(f"{self.where(section, cname)}: "
                             + did_you_mean(cname, self.coord_kinds, "coordinate"))
                continue
            try:
                out[cname] = self.quantity(val, self.coord_value_kind(cname, rate),
                                           section, cname)
            except _Failed:
                pass
        return out

    # ------------------------------------------------------------ loads and drives
    def variable_kind(self, var: str, *path) -> str:
        """Kind of quantity of a table's variable (:func:`mechdyn.model.variable.parse`):
        time, a coordinate or its rate, a joint, an angle, a point coordinate, a distance."""
        try:
            v = parse(var, self.coord_kinds)
        except ModelError:
            valid = ["t", *self.coord_kinds, *(f"{c}_dot" for c in self.coord_kinds),
                     "joint:NAME", "angle:BODY", "BODY.POINT.x", "BODY.POINT.y",
                     "dist(BODY.POINT, BODY.POINT)"]
            self.problem(f"{self.where(*path)}: {var!r}: unknown variable; valid variables: "
                         + ", ".join(repr(v) for v in valid))
            raise _Failed from None
        if v.kind == "time":
            return "time"
        if v.kind == "coordinate":
            return self.coord_value_kind(v.name, v.rate)
        if v.kind == "joint":
            kinds = {"revolute": "angle", "prismatic": "length"}
            if self.joint_types.get(v.name) not in kinds:
                self.problem(f"{self.where(*path)}: {var!r}: " + did_you_mean(
                    v.name, [j for j, t in self.joint_types.items() if t in kinds],
                    "revolute or prismatic joint"))
                raise _Failed
            return kinds[self.joint_types[v.name]]
        if v.kind == "angle":
            self.body_name(v.name, *path)
            return "angle"
        for body, point in v.points:
            self.point_ref(self.body_name(body, *path), point, *path)
        return "length"

    def value(self, raw: Any, kind: str, *path):
        """A constant, a ``{x, y, variable}`` table or a ``{pulse, start, duration}`` pulse
        (either with an optional ``period`` of the variable)."""
        if not isinstance(raw, dict):
            return self.quantity(raw, kind, *path)
        var = raw.get("variable", "t")
        vkind = self.variable_kind(var, *path, "variable")
        period, bad_period = None, False
        if "period" in raw:
            try:
                period = self.quantity(raw["period"], vkind, *path, "period")
            except _Failed:
                bad_period = True
            if period is not None and not period > 0:
                self.problem(f"{self.where(*path, 'period')}: the period of the table over "
                             f"{var!r} must be > 0, got {raw['period']!r}")
                period, bad_period = None, True
        if "pulse" in raw:
            mag = self.quantity(raw["pulse"], kind, *path, "pulse")
            start = self.quantity(raw["start"], vkind, *path, "start")
            dur = self.quantity(raw["duration"], vkind, *path, "duration")
            ramp = self.quantity(raw["ramp"], vkind, *path, "ramp") if "ramp" in raw else 0.0
            if dur <= 0 or ramp < 0:
                self.problem(f"{self.where(*path)}: the pulse needs duration > 0 and ramp >= 0")
                raise _Failed
            if bad_period:
                raise _Failed
            if period is not None and (period <= dur or period < dur + 2 * ramp):
                self.problem(f"{self.where(*path, 'period')}: the period of the pulse over "
                             f"{var!r} ({raw['period']!r}) must be longer than its duration "
                             f"and >= duration + 2 ramp ({raw['duration']!r}"
                             + (f" + 2 x {raw['ramp']!r}" if "ramp" in raw else "") + ")")
                raise _Failed
            return pulse(mag, start, dur, var, ramp, period)
        xs, ys, failed = [], [], bad_period
        for key, kk, out in (("x", vkind, xs), ("y", kind, ys)):
            for i, v in enumerate(raw[key]):
                try:
                    out.append(self.quantity(v, kk, *path, key, i))
                except _Failed:
                    failed = True
        outside = None
        if "outside" in raw:
            outside = self.quantity(raw["outside"], kind, *path, "outside")
        if failed:
            raise _Failed
        return self.table(xs, ys, var, outside, *path, period=period,
                          period_text=raw.get("period"))

    def table(self, xs, ys, var, outside, *path, period=None, period_text=None):
        if len(xs) != len(ys):
            self.problem(f"{self.where(*path)}: x has {len(xs)} values but y has {len(ys)}")
            raise _Failed
        if any(b <= a for a, b in zip(xs, xs[1:], strict=False)):
            self.problem(f"{self.where(*path, 'x')}: the values must increase strictly")
            raise _Failed
        if period is not None and len(xs) >= 2 and period < (xs[-1] - xs[0]) * (1 - 1e-12):
            self.problem(f"{self.where(*path, 'period')}: the period of the table over {var!r} "
                         f"({period_text!r} = {period:.6g} SI) is shorter than the table's "
                         f"span x[-1] - x[0] = {xs[-1] - xs[0]:.6g} SI")
            raise _Failed
        try:
            return Table(tuple(xs), tuple(ys), var, outside, period)
        except ValueError as exc:
            self.problem(f"{self.where(*path)}: {exc}")
            raise _Failed from None

    def load(self, k: int, spec: dict):
        P = ("loads", k)
        typ = spec["type"]
        name = spec.get("name", f"{typ}_{k + 1}")
        failed = False

        def q(key, kind, default=0.0, nonneg=False, unit=""):
            nonlocal failed
            if key not in spec:
                return default
            try:
                v = self.quantity(spec[key], kind, *P, key)
                return self.nonneg(v, spec[key], unit, *P, key) if nonneg else v
            except _Failed:
                failed = True
                return default

        def body_point(bkey, pkey, default="com"):
            nonlocal failed
            try:
                b = self.body_name(spec[bkey], *P, bkey)
            except _Failed:
                failed = True
                return None, None
            if pkey not in spec:
                return b, default
            try:
                return b, self.point_ref(b, spec[pkey], *P, pkey)
            except _Failed:
                failed = True
                return b, None

        if typ in ("spring", "damper"):
            b1, p1 = body_point("body1", "point1")
            b2, p2 = body_point("body2", "point2")
            stiff = q("stiffness", "stiffness", nonneg=True, unit="N/m")
            if typ == "damper" and "stiffness" in spec:
                self.problem(f"{self.where(*P, 'stiffness')}: a damper has no stiffness; use "
                             "type = 'spring' with a damping value for a spring-damper")
                failed = True
            free = q("free_length", "length", nonneg=True, unit="m")
            damp = q("damping", "damping", nonneg=True, unit="N*s/m")
            pre = q("preload", "force")
            if b1 is not None and b1 == b2:
                self.problem(f"{self.where(*P)}: body1 and body2 are the same body {b1!r}")
                failed = True
            if failed:
                raise _Failed
            return Spring(name, b1, p1, b2, p2, stiff, free, damp, pre)
        if typ in ("rotary_spring", "rotary_damper"):
            joint = spec["joint"]
            if self.joint_types.get(joint) != "revolute":
                revs = [n for n, t in self.joint_types.items() if t == "revolute"]
                if joint in self.joint_types:
                    self.problem(f"{self.where(*P, 'joint')}: {joint!r} is a "
                                 f"{self.joint_types[joint]} joint; a {typ} acts in a revolute "
                                 "joint; revolute joints: " + (", ".join(map(repr, revs))
                                                               or "(none)"))
                else:
                    self.problem(f"{self.where(*P, 'joint')}: "
                                 + did_you_mean(joint, revs, "revolute joint"))
                failed = True
            stiff = q("stiffness", "rotational_stiffness", nonneg=True, unit="N*m/rad")
            if typ == "rotary_damper" and "stiffness" in spec:
                self.problem(f"{self.where(*P, 'stiffness')}: a rotary_damper has no stiffness; "
                             "use type = 'rotary_spring' with a damping value")
                failed = True
            free = q("free_angle", "angle")
            damp = q("damping", "rotational_damping", nonneg=True, unit="N*m*s/rad")
            pre = q("preload", "torque")
            if failed:
                raise _Failed
            return RotarySpring(name, joint, stiff, free, damp, pre)
        if typ == "force":
            b, p = body_point("body", "point")
            mag = None
            try:
                mag = self.value(spec["magnitude"], "force", *P, "magnitude")
            except _Failed:
                failed = True
            direction = (1.0, 0.0)
            frame = spec.get("frame", "ground")
            if "direction" in spec and b is not None:
                try:
                    direction = self.direction(b if frame == "body" else GROUND,
                                               spec["direction"], *P, "direction")
                except _Failed:
                    failed = True
            if failed:
                raise _Failed
            return Force(name, b, p, mag, direction, frame)
        # torque
        try:
            b = self.body_name(spec["body"], *P, "body", ground_ok=False)
        except _Failed:
            b, failed = None, True
        rb = None
        if "reaction_body" in spec:
            try:
                rb = self.body_name(spec["reaction_body"], *P, "reaction_body")
            except _Failed:
                failed = True
        mag = None
        try:
            mag = self.value(spec["magnitude"], "torque", *P, "magnitude")
        except _Failed:
            failed = True
        if failed:
            raise _Failed
        return Torque(name, b, mag, rb)

    def drive(self, k: int, spec: dict) -> Drive:
        P = ("drives", k)
        name = spec.get("name", f"drive_{k + 1}")
        coord = spec["coordinate"]
        if coord not in self.coord_kinds:
            self.problem(f"{self.where(*P, 'coordinate')}: "
                         + did_you_mean(coord, self.coord_kinds, "coordinate"))
            raise _Failed
        if "type" in spec:  # a motor model (induction motor, DC motor, ...)
            table = dict(spec)
            table.setdefault("name", name)
            try:
                return drive_from_table(table, where=self.where(*P))
            except ModelError as exc:
                for p in exc.problems:
                    self.problem(p)
                    if isinstance(exc, UnitError):
                        self.unit_problems.add(p)
                raise _Failed from None
        travel = self.coord_kinds[coord] == "travel"
        tkind = "force" if travel else "torque"
        raw = spec["torque"]
        if isinstance(raw, dict) and "omega" in raw:
            wkind = "velocity" if travel else "angular_velocity"
            ws, ms, failed = [], [], False
            for key, kk, out in (("omega", wkind, ws), ("torque", tkind, ms)):
                for i, v in enumerate(raw[key]):
                    try:
                        out.append(self.quantity(v, kk, *P, "torque", key, i))
                    except _Failed:
                        failed = True
            if failed:
                raise _Failed
            if len(ws) != len(ms):
                self.problem(f"{self.where(*P, 'torque')}: omega has {len(ws)} values but "
                             f"torque has {len(ms)}")
                raise _Failed
            if any(b <= a for a, b in zip(ws, ws[1:], strict=False)):
                self.problem(f"{self.where(*P, 'torque', 'omega')}: the speeds must increase "
                             "strictly")
                raise _Failed
            return Drive(name, coord, TorqueSpeedCurve(tuple(ws), tuple(ms)))
        return Drive(name, coord, self.value(raw, tkind, *P, "torque"))
