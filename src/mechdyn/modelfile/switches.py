"""Model-file tables of variable-structure elements: locks, stops, contacts, switches.

The tables (arrays of tables, one entry per element; quantities with units)::

    [[coordinate_locks]]           # a lock holding one measured quantity
    name = "rocker_lock"
    variable = "joint:C"           # coordinate, joint:NAME, angle:BODY, body.point.x|y
    engaged = false                # default false
    value = "0 deg"                # optional; default: the value when it engages
    frees = ["psi"]                # optional: coordinates it makes dependent

    [[stops]]
    name = "ram_stop"
    variable = "joint:guide"
    upper = "28 mm"                # lower and/or upper
    restitution = 0.2              # default 0 (plastic)

    [[contacts]]
    name = "piston_on_ram"
    body = "piston"
    point = [0, 0]                 # or a point name of the body
    line_body = "slider"
    line_point = "ear"             # default [0, 0]
    line_direction = [0, -1]       # free side to the left of the direction
    friction = 0.0                 # Coulomb mu
    restitution = 0.0
    compliance = 0.0               # (m/s^2)/N, regularizes indeterminate contact sets

    [[switches]]
    name = "lock_on"
    action = "engage"              # engage | release | toggle
    target = "rocker_lock"         # a [joints.X] lock or a [[coordinate_locks]] entry
    variable = "psi"               # a crossing: variable, value, direction ...
    value = "0 deg"
    direction = "rising"           # rising | falling | both
    guard = [["joint:guide", "<", "24.5 mm"]]
    # times = ["0.1 s", "0.5 s"]   # ... or a command schedule instead of a crossing
    once = false

Values of ``value``, limits and guards carry the unit of their variable (an
angle for angle coordinates and revolute joints, a length for travels and point
coordinates, a time for ``t``, a speed for ``_dot`` rates).  A bare number is
SI.  :func:`parse_switches` adds the elements to ``mech.extras`` and returns
every problem found (it never raises for a problem of the file).
"""

from __future__ import annotations

from ..errors import ModelError, UnitError, did_you_mean
from ..mechanism.contact import Contact, Stop
from ..mechanism.switch import GUARD_OPERATORS, SWITCH_ACTIONS, CoordinateLock, Switch
from ..model.variable import parse, quantity
from ..units import parse_quantity, parse_vector

__all__ = ["parse_switches", "TABLES", "variable_kind"]

#: the top-level tables this module reads, with their allowed keys
TABLES = {
    "coordinate_locks": ("name", "variable", "engaged", "value", "frees", "description"),
    "stops": ("name", "variable", "lower", "upper", "restitution", "description"),
    "contacts": ("name", "body", "point", "line_body", "line_point", "line_direction",
                 "friction", "restitution", "compliance", "description"),
    "switches": ("name", "action", "target", "variable", "value", "direction", "times",
                 "guard", "once", "description"),
}
_DIRECTIONS = {"rising": 1, "up": 1, "falling": -1, "down": -1, "both": 0, "either": 0,
               1: 1, -1: -1, 0: 0}


def variable_kind(mech, variable: str) -> str:
    """The quantity kind (for units) of a variable string of a mechanism
    (:func:`mechdyn.model.variable.parse` and :func:`~mechdyn.model.variable.quantity`).

    Raises
    ------
    ModelError
        An unknown variable, joint, body or point (the message lists the valid names).
    """
    return quantity(parse(variable, mech.coordinates), mech)


def parse_switches(doc: dict, mech, where: str = "") -> list[str]:
    """Read the variable-structure tables of a model document into ``mech.extras``.

    Parameters
    ----------
    doc : dict
        The parsed TOML document.
    mech : Mechanism
        The mechanism built from the rest of the document (bodies, joints and
        coordinates must be there already).
    where : str
        The file name, used as the prefix of every message.

    Returns
    -------
    list of str
        One message per problem (empty when all is well); each names the file,
        the table, the entry and the key.
    """
    probs: list[str] = []
    pre = f"{where}: " if where else ""

    def loc(table, k, name, key=None):
        n = f" {name!r}" if name else ""
        return f"{pre}[[{table}]] #{k + 1}{n}" + (f" {key}" if key else "")

    def entries(table):
        val = doc.get(table, [])
        if isinstance(val, dict):
            val = [dict(v, name=v.get("name", n)) for n, v in val.items()]
        if not isinstance(val, list):
            probs.append(f"{pre}{table}: expected an array of tables ([[{table}]])")
            return []
        out = []
        for k, e in enumerate(val):
            if not isinstance(e, dict):
                probs.append(f"{pre}[[{table}]] #{k + 1}: expected a table")
                continue
            unknown = [key for key in e if key not in TABLES[table]]
            for key in unknown:
                probs.append(f"{loc(table, k, e.get('name'), key)}: unknown key; valid keys: "
                             + ", ".join(TABLES[table]))
            if not isinstance(e.get("name"), str) or not e.get("name"):
                probs.append(f"{loc(table, k, None, 'name')}: a name (string) is required")
                continue
            out.append((k, e))
        return out

    def qty(value, kind, w):
        try:
            return parse_quantity(value, kind, where=w)
        except UnitError as exc:
            probs.append(str(exc))
            return None

    def kind_of(var, w):
        if not isinstance(var, str):
            probs.append(f"{w}: expected a variable name (string), got {var!r}")
            return None
        try:
            return variable_kind(mech, var)
        except ModelError as exc:
            probs.append(f"{w}: {exc}")
            return None

    def add(kind, element):
        mech.extras.setdefault(kind, []).append(element)

    for k, e in entries("coordinate_locks"):
        name = e["name"]
        w = loc("coordinate_locks", k, name, "variable")
        kd = kind_of(e.get("variable"), w)
        if kd is None:
            continue
        value = None
        if "value" in e:
            value = qty(e["value"], kd, loc("coordinate_locks", k, name, "value"))
        frees = e.get("frees", [])
        if isinstance(frees, str):
            frees = [frees]
        for f in frees:
            if f not in mech.coordinates:
                probs.append(f"{loc('coordinate_locks', k, name, 'frees')}: "
                             + did_you_mean(f, mech.coordinates, "coordinate"))
        add("coordinate_locks", CoordinateLock(name, e["variable"], bool(e.get("engaged", False)),
                                               value, tuple(frees)))

    for k, e in entries("stops"):
        name = e["name"]
        kd = kind_of(e.get("variable"), loc("stops", k, name, "variable"))
        if kd is None:
            continue
        lims = {}
        for side in ("lower", "upper"):
            if side in e:
                lims[side] = qty(e[side], kd, loc("stops", k, name, side))
        e_r = qty(e.get("restitution", 0.0), "dimensionless", loc("stops", k, name,
                                                                   "restitution"))
        if None in lims.values() or e_r is None:
            continue
        try:
            add("stops", Stop(name, e["variable"], lims.get("lower"), lims.get("upper"), e_r))
        except ValueError as exc:
            probs.append(f"{loc('stops', k, name)}: {exc}")

    for k, e in entries("contacts"):
        name = e["name"]
        bad = False
        for key in ("body", "line_body"):
            b = e.get(key)
            if b not in ("ground", *mech.bodies):
                probs.append(f"{loc('contacts', k, name, key)}: "
                             + did_you_mean(str(b), ["ground", *mech.bodies], "body"))
                bad = True
        pts = {}
        for key, body in (("point", e.get("body")), ("line_point", e.get("line_body"))):
            v = e.get(key, [0.0, 0.0])
            if isinstance(v, str):
                if not bad and v not in mech.body(body).point_names():
                    probs.append(f"{loc('contacts', k, name, key)}: unknown point {v!r} of "
                                 f"body {body!r}; valid point names: "
                                 + ", ".join(repr(p) for p in mech.body(body).point_names()))
                    bad = True
                pts[key] = v
            else:
                try:
                    pts[key] = parse_vector(v, "length", loc("contacts", k, name, key))
                except UnitError as exc:
                    probs.append(str(exc))
                    bad = True
        try:
            d = parse_vector(e.get("line_direction", [1.0, 0.0]), "dimensionless",
                             loc("contacts", k, name, "line_direction"))
        except UnitError as exc:
            probs.append(str(exc))
            bad = True
        nums = {key: qty(e.get(key, 0.0), "dimensionless", loc("contacts", k, name, key))
                for key in ("friction", "restitution")}
        nums["compliance"] = qty(e.get("compliance", 0.0), "dimensionless",
                                 loc("contacts", k, name, "compliance"))
        if bad or None in nums.values():
            continue
        try:
            add("contacts", Contact(name, e["body"], pts["point"], e["line_body"],
                                    pts["line_point"], d, **nums))
        except ValueError as exc:
            probs.append(f"{loc('contacts', k, name)}: {exc}")

    lock_names = {n for n, j in mech.joints.items() if type(j).__name__ == "Lock"} | {
        c.name for c in mech.extras.get("coordinate_locks", [])}
    for k, e in entries("switches"):
        name = e["name"]
        ok = True
        action = e.get("action")
        if action not in SWITCH_ACTIONS:
            probs.append(f"{loc('switches', k, name, 'action')}: must be one of "
                         f"{', '.join(SWITCH_ACTIONS)}, got {action!r}")
            ok = False
        target = e.get("target")
        if target not in lock_names:
            probs.append(f"{loc('switches', k, name, 'target')}: "
                         + did_you_mean(str(target), lock_names, "lock"))
            ok = False
        var = e.get("variable")
        value, direction, times = 0.0, 0, ()
        if (var is None) == ("times" not in e):
            probs.append(f"{loc('switches', k, name)}: give either 'variable' (with 'value' "
                         "and 'direction') or 'times'")
            ok = False
        elif var is not None:
            kd = kind_of(var, loc("switches", k, name, "variable"))
            if kd is None:
                ok = False
            else:
                value = qty(e.get("value", 0.0), kd, loc("switches", k, name, "value"))
                ok = ok and value is not None
            dval = e.get("direction", "both")
            if dval not in _DIRECTIONS:
                probs.append(f"{loc('switches', k, name, 'direction')}: must be 'rising', "
                             f"'falling' or 'both', got {dval!r}")
                ok = False
            else:
                direction = _DIRECTIONS[dval]
        else:
            raw = e["times"] if isinstance(e["times"], list) else [e["times"]]
            times = tuple(qty(v, "time", loc("switches", k, name, "times")) for v in raw)
            ok = ok and None not in times
        guards = []
        for g in e.get("guard", []):
            w = loc("switches", k, name, "guard")
            if not (isinstance(g, list) and len(g) == 3):
                probs.append(f"{w}: each guard is [variable, operator, value], got {g!r}")
                ok = False
                continue
            kd = kind_of(g[0], w)
            if g[1] not in GUARD_OPERATORS:
                probs.append(f"{w}: operator must be one of {', '.join(GUARD_OPERATORS)}, "
                             f"got {g[1]!r}")
                ok = False
            gv = qty(g[2], kd, w) if kd is not None else None
            if kd is None or gv is None:
                ok = False
                continue
            guards.append((g[0], g[1], gv))
        if ok:
            add("switches", Switch(name, action, target, var, value, direction, times,
                                   tuple(guards), bool(e.get("once", False))))
    return probs

