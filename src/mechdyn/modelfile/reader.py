"""The base of the model-file loader's table readers: the document, its problems and names,
and helpers that read one value and record its problem (then raise :class:`_Failed`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from ..errors import ModelError, UnitError, did_you_mean
from ..mechanism.body import GROUND, unknown_point
from ..mechanism.coordinate import LENGTH_KINDS
from ..model.variable import parse
from ..units import KINDS, parse_quantity, parse_vector
from .schema import locate


class _Failed(Exception):
    """A value could not be read; its problem is already recorded."""


class _Reader:
    """A document being read: its problems so far, the names read, and the helpers."""

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
        #: a problem was recorded in the element being read
        self.failed = False

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
        self.failed = False
        try:
            el = fn(path[-1], clean)
        except (ValueError, TypeError) as exc:  # an element's own check; keep it readable
            self.problem(f"{self.where(*path)}: {exc}")
            raise _Failed from None
        if self.failed or self.broken(*path):
            raise _Failed
        return el

    def soft(self, fn, *args, default=None, **kwargs):
        """``fn(*args, **kwargs)``, or ``default`` if it fails: the problem is recorded
        and the element being read is marked :attr:`failed`."""
        try:
            return fn(*args, **kwargs)
        except _Failed:
            self.failed = True
            return default

    def check(self):
        """Raise :class:`_Failed` if a problem was recorded in the element being read."""
        if self.failed:
            raise _Failed

    def opt(self, spec: dict, key: str, kind, *path, default=0.0, read=None, **kwargs):
        """``spec[key]`` read at ``path`` by ``read`` (default :meth:`quantity`) as ``kind``;
        ``default`` if the key is absent or unreadable (then the element is failed)."""
        if key not in spec:
            return default
        return self.soft(read or self.quantity, spec[key], kind, *path, key, default=default,
                         **kwargs)

    def problem(self, msg: str):
        if msg not in self.problems:
            self.problems.append(msg)

    def recorded(self, fn, *args, **kwargs):
        """``fn(*args, **kwargs)``, its ModelError's problems recorded (a UnitError's as unit
        problems)."""
        try:
            return fn(*args, **kwargs)
        except ModelError as exc:
            for p in exc.problems:
                self.problem(p)
                if isinstance(exc, UnitError):
                    self.unit_problems.add(p)
            raise _Failed from None

    def quantity(self, value: Any, kind: str, *path, nonneg: bool = False) -> float:
        try:  # the place is needed only for a message: read again with it (the points of a
            out = parse_quantity(value, kind)  # long table are read without building it)
        except ModelError:
            out = self.recorded(parse_quantity, value, kind, where=self.where(*path))
        if nonneg and out < 0:
            self.problem(f"{self.where(*path)}: {value!r}: {path[-1]} must be >= 0 "
                         f"{KINDS[kind].si}")
            raise _Failed
        return out

    def vector(self, value: Any, kind, *path, size: int | None = None) -> tuple[float, ...]:
        return self.recorded(parse_vector, value, kind, self.where(*path), size=size)

    def points(self, raw: Any, *path, hint: str) -> dict[str, tuple[float, float]]:
        """The named points of the table ``raw`` at ``path`` (m); ``"com"`` is reserved."""
        pts = {}
        for pname, val in (raw if isinstance(raw, dict) else {}).items():
            if pname == "com" and not self.broken(*path, pname):
                self.problem(f"{self.where(*path, pname)}: the point name 'com' is reserved{hint}")
            if pname == "com" or self.broken(*path, pname):
                self.failed = True
                continue
            xy = self.soft(self.vector, val, "length", *path, pname)
            if xy is not None:
                pts[pname] = xy
        return pts

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
                self.problem(f"{self.where(*path)}: " + unknown_point(value, body, names))
                raise _Failed
            return value
        xy = self.vector(value, "length", *path)
        return self.to_body_frame(body, xy)

    def to_body_frame(self, body: str, xy, origin: bool = True) -> tuple[float, float]:
        """Coordinates (a direction, without ``origin``) in a body's input frame -> its frame."""
        ox, oy, th = self.sketch_frames.get(body, (0.0, 0.0, 0.0))
        dx, dy = (float(xy[0]) - ox, float(xy[1]) - oy) if origin else xy
        c, s = math.cos(th), math.sin(th)
        return (c * dx + s * dy, -s * dx + c * dy)

    def direction(self, body: str, value: Any, *path) -> tuple[float, float]:
        """A direction: [x, y] numbers or an angle string, in the body's input frame."""
        if isinstance(value, str):
            a = self.quantity(value, "angle", *path)
            return self.to_body_frame(body, (math.cos(a), math.sin(a)), origin=False)
        try:
            d = (float(value[0]), float(value[1]))
        except OverflowError:
            d = (math.inf, math.inf)
        if not all(math.isfinite(v) for v in d) or math.hypot(*d) == 0:
            self.problem(f"{self.where(*path)}: {value!r}: must be a non-zero direction [x, y]")
            raise _Failed
        return self.to_body_frame(body, d, origin=False)

    def variable_kind(self, var, *path) -> str:
        """Kind of quantity of a table's variable (:func:`mechdyn.model.variable.parse`):
        time, a coordinate or its rate, a joint, an angle, a point coordinate, a distance."""
        if not isinstance(var, str):
            self.problem(f"{self.where(*path)}: expected a variable name (string), got {var!r}")
            raise _Failed
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

    def section(self, key: str, kind: type = dict):
        val = self.doc.get(key, kind())
        return val if isinstance(val, kind) else kind()

    def coord_value_kind(self, cname: str, rate: bool) -> str:
        travel = self.coord_kinds.get(cname) in LENGTH_KINDS
        if rate:
            return "velocity" if travel else "angular_velocity"
        return "length" if travel else "angle"
