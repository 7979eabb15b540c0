"""Model-file tables of variable-structure elements: locks, stops, contacts, switches.

The four arrays of tables ``[[coordinate_locks]]``, ``[[stops]]``, ``[[contacts]]``
and ``[[switches]]``, their keys and units are described in ``docs/model-file.md``
("Switchable elements").  :func:`parse_switches` adds the elements to
``mech.extras`` and returns every problem found (it never raises for a problem of
the file); the private :class:`_Switches` reads them on the loader's
:class:`~.reader._Reader`.
"""

from __future__ import annotations

from ..errors import did_you_mean
from ..mechanism import Lock
from ..mechanism.contact import Contact, Stop
from ..mechanism.switch import CoordinateLock, Switch
from ..model.variable import parse, quantity
from .reader import _Reader
from .schema import schema

__all__ = ["parse_switches", "TABLES", "variable_kind"]

#: the top-level tables this module reads, with their allowed keys (from the schema)
TABLES = {t: tuple(schema()["properties"][t]["items"]["properties"])
          for t in ("coordinate_locks", "stops", "contacts", "switches")}
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


def parse_switches(doc: dict, mech, where: str = "", bad_paths=()) -> list[str]:
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
    bad_paths : sequence of tuple
        Paths where the schema found a problem (:func:`.schema.schema_problems`): those
        entries are not read again.

    Returns
    -------
    list of str
        One message per problem (empty when all is well); each names the file,
        the table, the entry and the key.
    """
    reader = _Switches(doc, mech, where, bad_paths)
    reader.locks()
    reader.stops()
    reader.contacts()
    reader.switches()
    return reader.problems


class _Switches(_Reader):
    """Reads the ``[[coordinate_locks]]``, ``[[stops]]``, ``[[contacts]]`` and
    ``[[switches]]`` of a document into a mechanism built from the rest of it."""

    def __init__(self, doc: dict, mech, fname: str, bad_paths=()):
        doc = dict(doc)
        for table in TABLES:  # [table.NAME] sub-tables are read like [[table]] entries
            if isinstance(doc.get(table), dict):
                doc[table] = [dict(v, name=v.get("name", n)) for n, v in doc[table].items()]
        super().__init__(doc, fname, bad_paths)
        self.mech = mech
        self.body_points = {n: b.point_names() for n, b in mech.all_bodies.items()}
        self.joint_types = {n: type(j).__name__.lower() for n, j in mech.joints.items()}
        self.coord_kinds = {n: c.kind for n, c in mech.coordinates.items()}
        #: the table of each name read so far, and the names of each table
        self.names: dict[str, str] = {}
        self.seen: dict[str, set] = {t: set() for t in TABLES}

    def entries(self, table: str):
        """(index, entry) of each named entry of ``table``; unknown keys are problems."""
        val = self.doc.get(table, [])
        if not isinstance(val, list):
            self.problem(f"{self.where(table)}: expected an array of tables ([[{table}]])")
            return
        for k, e in enumerate(val):
            if not isinstance(e, dict):
                self.problem(f"{self.where(table, k)}: expected a table")
                continue
            if self.broken(table, k):  # the schema has named what is wrong with it
                continue
            for key in e:
                if key not in TABLES[table]:
                    self.problem(f"{self.where(table, k, key)}: unknown key; valid keys: "
                                 + ", ".join(TABLES[table]))
            if not isinstance(e.get("name"), str) or not e.get("name"):
                self.problem(f"{self.where(table, k, 'name')}: a name (string) is required")
                continue
            taken = self.names.setdefault(e["name"], table)
            if taken != table or e["name"] in self.seen[table]:
                self.problem(f"{self.where(table, k, 'name')}: {e['name']!r} is already the "
                             f"name of an entry of [[{taken}]]; names must be unique")
                continue
            self.seen[table].add(e["name"])
            self.failed = False
            yield (table, k), e

    def add(self, cls, path: tuple, *args, **kwargs):
        """File ``cls(*args, **kwargs)`` in ``mech.extras``; its own check is a problem."""
        try:
            el = cls(*args, **kwargs)
        except ValueError as exc:
            self.problem(f"{self.where(*path)}: {exc}")
            return
        self.mech.extras.setdefault(el.extra_kind, []).append(el)

    def locks(self):
        for P, e in self.entries("coordinate_locks"):
            kd = self.soft(self.variable_kind, e.get("variable"), *P, "variable")
            if kd is None:
                continue
            value = self.opt(e, "value", kd, *P, default=None)
            frees = e.get("frees", [])
            frees = [frees] if isinstance(frees, str) else frees
            for f in frees:
                if f not in self.mech.coordinates:
                    self.problem(f"{self.where(*P, 'frees')}: "
                                 + did_you_mean(f, self.mech.coordinates, "coordinate"))
            self.add(CoordinateLock, P, e["name"], e["variable"], bool(e.get("engaged", False)),
                     value, tuple(frees))

    def stops(self):
        for P, e in self.entries("stops"):
            kd = self.soft(self.variable_kind, e.get("variable"), *P, "variable")
            if kd is None:
                continue
            lower = self.opt(e, "lower", kd, *P, default=None)
            upper = self.opt(e, "upper", kd, *P, default=None)
            restitution = self.opt(e, "restitution", "dimensionless", *P)
            friction = self.opt(e, "friction", "dimensionless", *P)
            if not self.failed:
                self.add(Stop, P, e["name"], e["variable"], lower, upper, restitution,
                         friction)

    def contacts(self):
        for P, e in self.entries("contacts"):
            bodies = [self.soft(self.body_name, str(e.get(key)), *P, key)
                      for key in ("body", "line_body")]
            pts = {}
            for key, body in zip(("point", "line_point"), bodies, strict=True):
                v = e.get(key, [0.0, 0.0])
                if None in bodies and isinstance(v, str):
                    continue  # a point name of an unknown body
                pts[key] = self.soft(self.point_ref, body, v, *P, key)
            d = self.opt(e, "line_direction", "dimensionless", *P, default=(1.0, 0.0),
                         read=self.vector)
            nums = {key: self.opt(e, key, "dimensionless", *P)
                    for key in ("friction", "restitution", "compliance")}
            if not self.failed:
                self.add(Contact, P, e["name"], e["body"], pts["point"], e["line_body"],
                         pts["line_point"], d, **nums)

    def switches(self):
        mech = self.mech
        locks = {n for n, j in mech.joints.items() if isinstance(j, Lock)} | {
            c.name for c in mech.extras.get("coordinate_locks", [])}
        for P, e in self.entries("switches"):
            target, var, dval = e.get("target"), e.get("variable"), e.get("direction", "both")
            if target not in locks:
                self.problem(f"{self.where(*P, 'target')}: "
                             + did_you_mean(str(target), locks, "lock"))
                self.failed = True
            kd = self.soft(self.variable_kind, var, *P, "variable") if var is not None else None
            value = self.opt(e, "value", kd, *P) if kd is not None else 0.0
            if dval not in _DIRECTIONS:
                self.problem(f"{self.where(*P, 'direction')}: must be 'rising', "
                             f"'falling' or 'both', got {dval!r}")
                self.failed = True
            times = e.get("times", [])
            times = [self.soft(self.quantity, t, "time", *P, "times")
                     for t in (times if isinstance(times, list) else [times])]
            guards = []
            for g in e.get("guard", []):
                if not (isinstance(g, list) and len(g) == 3):
                    self.problem(f"{self.where(*P, 'guard')}: each guard is [variable, "
                                 f"operator, value], got {g!r}")
                    self.failed = True
                    continue
                kd = self.soft(self.variable_kind, g[0], *P, "guard")
                gv = self.soft(self.quantity, g[2], kd, *P, "guard") if kd is not None else None
                guards.append((g[0], g[1], 0.0 if gv is None else gv))
            sw = Switch(e["name"], e.get("action"), target, var, value,
                        _DIRECTIONS.get(dval, 0), [t for t in times if t is not None],
                        tuple(guards), bool(e.get("once", False)))
            for p in sw.problems(lambda key, P=P: self.where(*P, key)):
                self.problem(p)
                self.failed = True
            if not self.failed:
                self.mech.extras.setdefault("switches", []).append(sw)
