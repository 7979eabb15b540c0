"""Reading the ``[[loads]]`` and ``[[drives]]`` tables of a model file.

A load or drive value is a constant, a ``{x, y, variable}`` table (over time, a
coordinate or its rate, a joint, a body angle, a point coordinate or a
distance) or a ``{pulse, start, duration}`` pulse; a drive is a torque (or a
torque-speed curve) on a coordinate, or a motor model read by
:func:`mechdyn.modelfile.drives.drive_from_table`.  :class:`_LoadsDrives` reads
one load or drive; ``_LOAD_REQUIRED`` holds the keys each type of load needs.
"""

from __future__ import annotations

from typing import Any

from ..errors import did_you_mean
from ..mechanism import GROUND
from ..mechanism.coordinate import LENGTH_KINDS
from ..mechanism.drive import Drive, TorqueSpeedCurve
from ..mechanism.load import Bushing, Force, RotarySpring, Spring, Table, Torque, pulse
from .drives import drive_from_table
from .reader import _Failed, _Reader

_LOAD_REQUIRED = {"spring": ("body1", "point1", "body2", "point2"),
                  "damper": ("body1", "point1", "body2", "point2"),
                  "rotary_spring": ("joint",), "rotary_damper": ("joint",),
                  "force": ("body", "magnitude"), "torque": ("body", "magnitude")}


class _LoadsDrives(_Reader):
    """Reads the elements of the ``[[loads]]`` and ``[[drives]]`` tables."""

    def value(self, raw: Any, kind: str, *path):
        """A constant, a ``{x, y, variable}`` table or a ``{pulse, start, duration}`` pulse
        (either with an optional ``period`` of the variable)."""
        if not isinstance(raw, dict):
            return self.quantity(raw, kind, *path)
        var = raw.get("variable", "t")
        vkind = self.variable_kind(var, *path, "variable")
        period = self.opt(raw, "period", vkind, *path, default=None)
        bad_period = "period" in raw and period is None
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
        xs, ys = self.columns(raw, (("x", vkind), ("y", kind)), *path)
        outside = (self.quantity(raw["outside"], kind, *path, "outside")
                   if "outside" in raw else None)
        if bad_period or xs is None:
            raise _Failed
        if period is not None and len(xs) >= 2 and period < (xs[-1] - xs[0]) * (1 - 1e-12):
            self.problem(f"{self.where(*path, 'period')}: the period of the table over {var!r} "
                         f"({raw.get('period')!r} = {period:.6g} SI) is shorter than the "
                         f"table's span x[-1] - x[0] = {xs[-1] - xs[0]:.6g} SI")
            raise _Failed
        try:
            return Table(tuple(xs), tuple(ys), var, outside, period)
        except ValueError as exc:
            self.problem(f"{self.where(*path)}: {exc}")
            raise _Failed from None

    def columns(self, raw: dict, cols, *path):
        """The lists ``raw[key]`` of the two (key, kind) ``cols`` in SI, of equal length, the
        first strictly increasing; (None, None) if a value could not be read."""
        (kx, x_kind), (ky, y_kind) = cols
        xs = [self.soft(self.quantity, v, x_kind, *path, kx, i) for i, v in enumerate(raw[kx])]
        ys = [self.soft(self.quantity, v, y_kind, *path, ky, i) for i, v in enumerate(raw[ky])]
        if None in xs or None in ys:
            return None, None
        if len(xs) != len(ys):
            self.problem(f"{self.where(*path)}: {kx} has {len(xs)} values but {ky} has "
                         f"{len(ys)}")
            raise _Failed
        if any(b <= a for a, b in zip(xs, xs[1:], strict=False)):
            self.problem(f"{self.where(*path, kx)}: the values must increase strictly")
            raise _Failed
        return xs, ys

    def load(self, k: int, spec: dict):
        P = ("loads", k)
        typ = spec["type"]
        name = spec.get("name", f"{typ}_{k + 1}")

        def q(key, kind, nonneg=False):
            return self.opt(spec, key, kind, *P, nonneg=nonneg)

        def body_point(bkey, pkey):
            b = self.soft(self.body_name, spec[bkey], *P, bkey)
            if b is None or pkey not in spec:
                return b, (None if b is None else "com")
            return b, self.soft(self.point_ref, b, spec[pkey], *P, pkey)

        def no_stiffness(damper, spring, extra):
            if typ == damper and "stiffness" in spec:
                self.problem(f"{self.where(*P, 'stiffness')}: a {damper} has no stiffness; use "
                             f"type = '{spring}' with a damping value{extra}")
                self.failed = True

        if typ in ("spring", "damper"):
            b1, p1 = body_point("body1", "point1")
            b2, p2 = body_point("body2", "point2")
            stiff = q("stiffness", "stiffness", nonneg=True)
            no_stiffness("damper", "spring", " for a spring-damper")
            free = q("free_length", "length", nonneg=True)
            damp = q("damping", "damping", nonneg=True)
            pre = q("preload", "force")
            if b1 is not None and b1 == b2:
                self.problem(f"{self.where(*P)}: body1 and body2 are the same body {b1!r}")
                self.failed = True
            self.check()
            return Spring(name, b1, p1, b2, p2, stiff, free, damp, pre)
        if typ == "bushing":
            b1, p1 = body_point("body1", "point1")
            b2, p2 = body_point("body2", "point2")
            kx, ky = (q(k, "stiffness", nonneg=True) for k in ("kx", "ky"))
            cx, cy = (q(k, "damping", nonneg=True) for k in ("cx", "cy"))
            if b1 is not None and b1 == b2:
                self.problem(f"{self.where(*P)}: body1 and body2 are the same body {b1!r}")
                self.failed = True
            self.check()
            return Bushing(name, b1, p1, b2, p2, kx, ky, cx, cy)
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
                self.failed = True
            stiff = q("stiffness", "rotational_stiffness", nonneg=True)
            no_stiffness("rotary_damper", "rotary_spring", "")
            free = q("free_angle", "angle")
            damp = q("damping", "rotational_damping", nonneg=True)
            pre = q("preload", "torque")
            self.check()
            return RotarySpring(name, joint, stiff, free, damp, pre)
        if typ == "force":
            b, p = body_point("body", "point")
            mag = self.soft(self.value, spec["magnitude"], "force", *P, "magnitude")
            frame = spec.get("frame", "ground")
            direction = (1.0, 0.0)
            if "direction" in spec and b is not None:
                direction = self.soft(self.direction, b if frame == "body" else GROUND,
                                      spec["direction"], *P, "direction", default=direction)
            self.check()
            return Force(name, b, p, mag, direction, frame)
        b = self.soft(self.body_name, spec["body"], *P, "body", ground_ok=False)
        rb = None
        if "reaction_body" in spec:
            rb = self.soft(self.body_name, spec["reaction_body"], *P, "reaction_body")
        mag = self.soft(self.value, spec["magnitude"], "torque", *P, "magnitude")
        self.check()
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
            return self.recorded(drive_from_table, {"name": name, **spec}, where=self.where(*P))
        travel = self.coord_kinds[coord] in LENGTH_KINDS  # a force drives it
        tkind = "force" if travel else "torque"
        raw = spec["torque"]
        if isinstance(raw, dict) and "omega" in raw:
            wkind = "velocity" if travel else "angular_velocity"
            ws, ms = self.columns(raw, (("omega", wkind), ("torque", tkind)), *P, "torque")
            self.check()
            return Drive(name, coord, TorqueSpeedCurve(tuple(ws), tuple(ms)))
        return Drive(name, coord, self.value(raw, tkind, *P, "torque"))
