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

The tables are read by :mod:`.bodies_joints`, :mod:`.loads_drives`,
:mod:`.switches` and :mod:`.foundation`, on the shared reader of :mod:`.reader`; this
module holds the entry points, the order of the passes and the ``[initial]``, ``[initial_speed]``
and ``[[assembly]]`` readers.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import MechdynError, ModelError, UnitError, did_you_mean
from ..mechanism import GROUND, Ground, Mechanism
from .bodies_joints import _BodiesJoints
from .foundation import _FoundationReader
from .loads_drives import _LOAD_REQUIRED, _LoadsDrives
from .reader import _Failed
from .schema import schema_problems
from .switches import TABLES as SWITCH_TABLES
from .switches import parse_switches

if TYPE_CHECKING:
    from ..model import Model

__all__ = ["load", "loads", "build", "build_model", "read_document"]


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
    return build(read_document(text, name), name, default_title=default_title)


#: tables and arrays nested deeper than this are refused (a model file needs about 4)
MAX_DEPTH = 16


def read_document(text: str, name: str = "<string>") -> dict:
    """Parse TOML text, turning a syntax error, or tables and arrays nested deeper than
    :data:`MAX_DEPTH`, into a :class:`ModelError`."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"{name}: not valid TOML: {exc}") from None
    except RecursionError:
        raise ModelError(f"{name}: tables or arrays nested too deeply (more than "
                         f"{MAX_DEPTH} levels)") from None
    stack = [(doc, ())]
    while stack:  # without recursion: the depth is what is being checked
        node, path = stack.pop()
        if len(path) > MAX_DEPTH:
            raise ModelError(f"{name}: {'.'.join(map(str, path[:4]))}...: tables or arrays "
                             f"nested deeper than {MAX_DEPTH} levels")
        items = node.items() if isinstance(node, dict) else enumerate(node) \
            if isinstance(node, list) else ()
        stack.extend((v, (*path, k)) for k, v in items if isinstance(v, dict | list))
    return doc


def build(doc: dict, name: str = "<string>", *, default_title: str | None = None,
          schema: bool = True) -> Mechanism:
    """Build and validate a mechanism from a parsed model document (see :func:`loads`).

    Parameters
    ----------
    doc : dict
        The parsed TOML document (:func:`read_document`).
    name : str
        Shown as the file name in error messages.
    default_title : str, optional
        Mechanism name when the file has no ``[model] name``.
    schema : bool
        Check the structure against the JSON schema (pass 1).  ``False`` only for a
        document whose structure is known good: one that differs from a document
        that passed the schema only in quantity values at keys that took such values
        (the variants of a design study, :mod:`mechdyn.study`).  The units, values,
        names and the mechanism itself (passes 2 and 3) are always checked.

    Returns
    -------
    Mechanism
        The validated mechanism (:func:`build_model` also gives its compiled Model).

    Raises
    ------
    ModelError
        Every problem of the document (a :class:`~mechdyn.errors.UnitError` when all
        are about units).

    Examples
    --------
    >>> doc = read_document('''
    ... [bodies.bar]
    ... mass = "2 kg"
    ... inertia = "0.05 kg*m^2"
    ... points = { P = ["0.5 m", "0 m"] }
    ... [joints.O]
    ... type = "revolute"
    ... parent = "ground"
    ... child = "bar"
    ... [coordinates.theta]
    ... kind = "angle"
    ... body = "bar"
    ... ''', "pendulum.toml")
    >>> build(doc, "pendulum.toml").bodies["bar"].mass
    2.0
    >>> doc["bodies"]["bar"]["mass"] = "-2 kg"
    >>> build(doc, "pendulum.toml", schema=False)
    Traceback (most recent call last):
    ...
    mechdyn.errors.ModelError: pendulum.toml: [bodies.bar] mass: '-2 kg': mass must be >= 0 kg
    """
    return build_model(doc, name, default_title=default_title, schema=schema).mechanism


def build_model(doc: dict, name: str = "<string>", *, default_title: str | None = None,
                schema: bool = True) -> Model:
    """Build and validate a mechanism from a parsed model document, and give the
    compiled :class:`~mechdyn.model.Model` that validation made (its ``mechanism`` is
    the one :func:`build` returns), so that it is not compiled a second time.

    Parameters and Raises as :func:`build`.

    Returns
    -------
    Model
        Compiled and frozen (:func:`mechdyn.compiler.compile_mechanism`).

    Examples
    --------
    >>> from mechdyn import examples
    >>> path = examples.path("slider_crank")
    >>> model = build_model(read_document(path.read_text(), path.name), path.name)
    >>> model.coordinate_names, model.mechanism.name
    (('phi',), 'slider-crank')
    """
    msgs, bad_paths = schema_problems(doc, name) if schema else ([], [])
    builder = _Builder(doc, name, bad_paths)
    builder.problems.extend(msgs)
    mech = builder.run(default_title)
    if builder.problems:
        # all problems about units: raise the more specific UnitError (a ModelError)
        only_units = all(p in builder.unit_problems for p in builder.problems)
        raise (UnitError if only_units else ModelError)(builder.problems)
    try:
        return mech.compile()  # what Mechanism.validate does, keeping the Model
    except ModelError as exc:
        raise ModelError([f"{name}: {p}" for p in exc.problems]) from None
    except MechdynError as exc:  # assembly or other analysis errors
        raise ModelError(f"{name}: {exc}") from None


class _Builder(_BodiesJoints, _LoadsDrives, _FoundationReader):
    """Turns a document into mechanism elements, recording every problem."""

    def run(self, default_title: str | None) -> Mechanism:
        model = self.section("model")
        title = model.get("name") if isinstance(model.get("name"), str) else None
        desc = model.get("description") if isinstance(model.get("description"), str) else ""
        mech = Mechanism(name=title or default_title or "mechanism", description=desc)
        if not self.broken("model", "gravity"):
            mech.gravity = self.opt(model, "gravity", "acceleration", "model",
                                    default=mech.gravity, read=self.vector)

        ground = self.section("ground")
        gpoints = ground.get("points", {}) if isinstance(ground.get("points"), dict) else {}
        self.body_points[GROUND] = ["com", *gpoints]
        mech.add(Ground(points=self.points(gpoints, "ground", "points",
                                           hint="; choose another name")))

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
            if bname != GROUND:
                self.add(mech, self.body, ("bodies", bname), spec, ("mass", "inertia"))

        for jname, spec in self.section("joints").items():
            if isinstance(spec, dict) and isinstance(spec.get("type"), str):
                self.joint_types[jname] = spec["type"]
            if jname in bodies or jname == GROUND:
                self.problem(f"{self.where('joints', jname)}: the name {jname!r} is already "
                             "used by a body; joints and bodies need different names")
                continue
            self.add(mech, self.joint, ("joints", jname), spec, ("type", "parent", "child"))

        for cname, spec in self.section("coordinates").items():
            if isinstance(spec, dict) and isinstance(spec.get("kind"), str):
                self.coord_kinds[cname] = spec["kind"]
            self.add(mech, self.coordinate, ("coordinates", cname), spec, ("kind",))

        initial = {"q": self.initial("initial", rate=False),
                   "qdot": self.initial("initial_speed", rate=True)}
        if initial["q"] or initial["qdot"]:
            mech.extras["initial"] = initial

        names: set[str] = set()  # of the loads and drives
        for k, spec in enumerate(self.section("loads", list)):
            if isinstance(spec, dict) and "type" in spec and not self.broken("loads", k, "type"):
                self.add(mech, self.load, ("loads", k), spec,
                         _LOAD_REQUIRED.get(spec["type"], ()), names)
        for k, spec in enumerate(self.section("drives", list)):
            if isinstance(spec, dict):
                self.add(mech, self.drive, ("drives", k), spec,
                         ("coordinate", "type" if "type" in spec else "torque"), names)
        for k, spec in enumerate(self.section("assembly", list)):
            if isinstance(spec, dict) and not self.broken("assembly", k):
                self.assembly_mode(mech, k, spec)
        if any(k in self.doc for k in SWITCH_TABLES):
            for p in parse_switches(self.doc, mech, self.fname, self.bad):
                self.problem(p)
        if "foundation" in self.doc:
            mech.foundation = self.soft(self.foundation)
        return mech

    def add(self, mech: Mechanism, read, path: tuple, spec, required: tuple,
            names: set[str] | None = None):
        """Add the element ``read`` builds from the table ``spec`` (see :meth:`element`);
        ``names``: those taken by the loads and drives, which must differ."""
        el = (self.soft(self.element, read, path, spec, required)
              if isinstance(spec, dict) else None)
        if el is not None and names is not None and el.name in names:
            self.problem(f"{self.where(*path)}: name {el.name!r} is used by another load or "
                         "drive")
        elif el is not None:
            mech.add(el)
            if names is not None:
                names.add(el.name)

    def initial(self, section: str, rate: bool) -> dict[str, float]:
        """The SI values by coordinate name of ``[initial]`` or ``[initial_speed]``."""
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
