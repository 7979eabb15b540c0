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

The tables are read by :mod:`.bodies_joints`, :mod:`.loads_drives` and
:mod:`.initial_assembly`, on the shared reader of :mod:`.reader`; this module
holds the entry points and the order of the passes.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

from ..errors import MechdynError, ModelError, UnitError
from ..mechanism import GROUND, Ground, Mechanism
from .bodies_joints import _BodiesJoints
from .initial_assembly import _InitialAssembly
from .loads_drives import _LOAD_REQUIRED, _LoadsDrives
from .reader import _Failed
from .schema import schema_problems
from .switches import TABLES as SWITCH_TABLES
from .switches import parse_switches

__all__ = ["load", "loads", "build", "read_document"]


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


class _Builder(_BodiesJoints, _LoadsDrives, _InitialAssembly):
    """Turns a document into mechanism elements, recording every problem."""

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
