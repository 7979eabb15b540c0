"""Study parameters named by their model-file path, and the variant models they make.

A parameter is a dotted path into the TOML document of a model file:
``bodies.crank.points.A.x`` (a vector component by ``.x``, ``.y`` or ``.theta``, or
its index), ``bodies.rod.mass``, ``drives.motor.gear_ratio`` (an entry of an array
of tables by its ``name``, or by its index), ``initial.phi`` (a coordinate's
initial value).  A variant sets each parameter to a value with its unit (written
back as ``"0.045 m"``), so the loader's unit checks apply, and builds the model with
:func:`mechdyn.modelfile.loader.build_model` (without the JSON-schema pass when the
structure is known good: :meth:`BaseModel.structure_known`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import ModelError, UnitError, did_you_mean
from ..modelfile.loader import build_model, read_document
from ..modelfile.schema import schema_problems
from ..units import KINDS, parse_quantity

__all__ = ["BaseModel", "Parameter", "column_name", "unit_suffix", "shown_unit", "to_shown",
           "KIND_ORDER"]

#: vector components by name
_COMPONENTS = {"x": 0, "y": 1, "theta": 2}
#: kinds tried, in this order, to tell what a model-file value measures
KIND_ORDER = ("length", "angle", "mass", "inertia", "force", "torque", "stiffness",
              "rotational_stiffness", "damping", "rotational_damping", "angular_velocity",
              "velocity", "acceleration", "time", "power", "energy", "dimensionless")
#: the unit shown in table columns (angles in degrees, everything else SI)
_SHOWN = {"angle": "deg", "angular_velocity": "rpm"}


def unit_suffix(unit: str) -> str:
    """Column suffix of a unit: ``"kg*m^2"`` -> ``"kg_m2"``, ``"N*m"`` -> ``"Nm"``.

    Examples
    --------
    >>> [unit_suffix(u) for u in ("m", "kg*m^2", "N*m", "rad/s", "")]
    ['m', 'kg_m2', 'Nm', 'rad_s', '']
    """
    return unit.replace("N*m", "Nm").replace("*", "_").replace("/", "_").replace("^", "")


def shown_unit(kind: str) -> str:
    """The unit a table shows a quantity of ``kind`` in (deg, rpm, else SI).

    Examples
    --------
    >>> shown_unit("angle"), shown_unit("inertia")
    ('deg', 'kg*m^2')
    """
    return _SHOWN.get(kind, KINDS[kind].si)


def column_name(name: str, kind: str) -> str:
    """Table column of a quantity: its name and its shown unit.

    Examples
    --------
    >>> column_name("bodies.crank.points.A.x", "length")
    'bodies.crank.points.A.x_m'
    >>> column_name("initial.phi", "angle")
    'initial.phi_deg'
    >>> column_name("drives.motor.gear_ratio", "ratio")
    'drives.motor.gear_ratio'
    """
    suffix = unit_suffix(shown_unit(kind))
    return f"{name}_{suffix}" if suffix else name


def to_shown(value: float, kind: str) -> float:
    """An SI value in the unit :func:`shown_unit` gives (deg for angles, rpm for speeds).

    Examples
    --------
    >>> to_shown(3.141592653589793, "angle"), to_shown(0.05, "length")
    (180.0, 0.05)
    """
    factor = {"angle": 180.0 / 3.141592653589793, "angular_velocity": 30.0 / 3.141592653589793}
    return float(value) * factor.get(kind, 1.0)


@dataclass(frozen=True)
class Parameter:
    """One model-file value varied by a study.

    Attributes
    ----------
    path : str
        Dotted model-file path, e.g. ``"bodies.crank.points.A.x"``.
    kind : str
        What it measures (a :data:`mechdyn.units.KINDS` name: ``"length"``, ``"mass"`` ...).
    """

    path: str
    kind: str

    @property
    def column(self) -> str:
        """Its table column, e.g. ``"bodies.crank.points.A.x_m"``."""
        return column_name(self.path, self.kind)

    def text(self, value: float) -> str:
        """The SI value as model-file text with its unit.

        Examples
        --------
        >>> Parameter("bodies.rod.mass", "mass").text(1.5)
        '1.5 kg'
        """
        unit = KINDS[self.kind].si
        return f"{float(value)!r} {unit}".rstrip()


def _key(node, key: str, where: list[str]):
    """(index, child): the child ``key`` of a table (dict) or of an array of tables (by
    name or index), and its key or index in ``node``."""
    here = ".".join(where) or "(top level)"
    if isinstance(node, dict):
        if key in node:
            return key, node[key]
        raise ModelError(f"study parameter: no key {key!r} at {here}; "
                         + did_you_mean(key, list(node), "key"))
    if isinstance(node, list):
        names = [e.get("name") for e in node if isinstance(e, dict)]
        if key in names:
            k = names.index(key)
            k = [i for i, e in enumerate(node) if isinstance(e, dict)][k]
            return k, node[k]
        if key.isdigit() and int(key) < len(node):
            return int(key), node[int(key)]
        valid = [n for n in names if n] or [str(i) for i in range(len(node))]
        raise ModelError(f"study parameter: no entry {key!r} in {here}; "
                         + did_you_mean(key, valid, "entry"))
    raise ModelError(f"study parameter: {here} is a value, not a table: it has no key {key!r}")


def _locate(doc: dict, path: str, copy: bool = False):
    """(container, index) of the value at ``path``: a dict and key, or a list and index.

    With ``copy``, each table and array on the way (not ``doc`` itself) is replaced in
    its parent by a shallow copy, so that the value can be set without changing what
    ``doc`` shares with another document.
    """
    parts = path.split(".")
    if not path or any(not p for p in parts):
        raise ModelError(f"study parameter {path!r}: write a dotted model-file path, e.g. "
                         f"bodies.crank.points.A.x")
    node, where = doc, []
    for part in parts[:-1]:
        index, child = _key(node, part, where)
        if copy and isinstance(child, dict | list):
            child = node[index] = type(child)(child)
        node = child
        where.append(part)
    last = parts[-1]
    if isinstance(node, list) and node and not isinstance(node[0], dict):  # a vector
        index = _COMPONENTS.get(last, int(last) if last.isdigit() else None)
        if index is None or index >= len(node):
            valid = [c for c, i in _COMPONENTS.items() if i < len(node)]
            raise ModelError(f"study parameter {path!r}: {'.'.join(where)} is a vector; "
                             f"choose a component: {', '.join(valid)}")
        return node, index
    index, child = _key(node, last, where)
    if isinstance(child, dict | list):
        keys = list(child) if isinstance(child, dict) else list(_COMPONENTS)[:len(child)]
        raise ModelError(f"study parameter {path!r} is a table or vector, not a value; "
                         f"valid keys below it: {', '.join(map(str, keys))}")
    return node, index


def _kind_of(old, sample: str | None, path: str) -> str:
    """The kind of the value ``old`` (model-file text or number) that also reads ``sample``."""
    for kind in KIND_ORDER:
        try:
            if isinstance(old, str):
                parse_quantity(old, kind, where=path)
                if kind == "dimensionless" and any(c.isalpha() for c in old):
                    continue
            elif kind != "dimensionless" or isinstance(old, bool):
                continue
            if sample is not None:
                parse_quantity(sample, kind, where=path)
            return kind
        except UnitError:
            continue
    if sample is None:
        raise ModelError(f"study parameter {path!r}: the model's value {old!r} is not a number "
                         f"or a quantity")
    raise ModelError(f"study parameter {path!r}: the value {sample!r} does not fit the "
                     f"model's value {old!r} (a different dimension)")


class BaseModel:
    """The model file a study varies: its document, and variants built from it.

    Parameters
    ----------
    spec : str or Path
        A model file (.toml) or the name of a bundled example (``"slider_crank"``).

    Raises
    ------
    ModelError
        A file that is not there or not valid TOML, or an unknown example name.

    Examples
    --------
    >>> base = BaseModel("slider_crank")
    >>> p = base.parameter("bodies.crank.points.A.x", "45 mm")
    >>> p.kind, p.column
    ('length', 'bodies.crank.points.A.x_m')
    >>> mech = base.build({p: 0.045})
    >>> float(mech.bodies["crank"].points["A"][0])
    0.045
    """

    def __init__(self, spec: str | Path):
        from .. import examples  # the bundled models, by name

        path = Path(spec)
        if not path.is_file():
            if path.suffix == ".toml" or path.parent != Path("."):
                raise ModelError(f"no model file {str(spec)!r}")
            path = examples.path(str(spec))  # a ModelError lists the bundled examples
        self.spec = str(spec)
        self.name = path.name
        self.title = path.stem
        self.doc = read_document(path.read_text(encoding="utf-8"), path.name)
        #: :meth:`structure_known` by set of parameters
        self._structure: dict[tuple, bool] = {}

    def parameter(self, path: str, sample: str | float | None = None) -> Parameter:
        """The :class:`Parameter` at ``path``; its kind is what the model's value measures
        (checked against ``sample``, a value with its unit, if given).

        Raises
        ------
        ModelError
            An unknown path (listing the valid keys at that level), a table instead of
            a value, or a sample of another dimension.
        """
        node, index = _locate(self.doc, path)
        return Parameter(path, _kind_of(node[index], None if sample is None else str(sample),
                                        path))

    def document(self, values: dict[Parameter, float]) -> dict:
        """A copy of the document with each parameter set to its SI value (written with
        its unit; a dimensionless one as a number).

        Only the tables and arrays on the parameters' paths are copied; the rest is
        shared with :attr:`doc`, which is never changed (nor may the copy's shared
        parts be).
        """
        doc = dict(self.doc)
        for p, v in values.items():
            node, index = _locate(doc, p.path, copy=True)
            # a pure number as a TOML number (a vector's component, a ratio), else with
            # its unit
            node[index] = float(v) if p.kind == "dimensionless" else p.text(v)
        return doc

    def structure_known(self, parameters) -> bool:
        """True if every variant of ``parameters`` has a known good structure, so that its
        documents need no JSON-schema pass (:func:`~mechdyn.modelfile.loader.build` with
        ``schema=False``): the base document passes the schema, and so does it with each
        parameter written as a value with its unit.

        A variant differs from that probe only in the numbers of those values, which
        the schema does not read (it checks tables, keys, TOML types and names; units
        and values are the loader's second pass, which every variant goes through).
        The answer is kept for each set of parameters; :attr:`doc` must not change
        after it.

        Examples
        --------
        >>> base = BaseModel("slider_crank")
        >>> base.structure_known([base.parameter("bodies.rod.mass")])
        True
        """
        key = tuple(sorted({p.path: p for p in parameters}.items()))
        if key not in self._structure:
            probe = self.document({p: 1.0 for _, p in key})
            self._structure[key] = not schema_problems(probe, self.name)[0]
        return self._structure[key]

    def build(self, values: dict[Parameter, float]):
        """The validated :class:`~mechdyn.mechanism.Mechanism` of one variant.

        Raises
        ------
        ModelError
            The variant is not a valid model (its sketch cannot be assembled ...).
        """
        return self.compile(values).mechanism

    def compile(self, values: dict[Parameter, float]):
        """The compiled :class:`~mechdyn.model.Model` of one variant: the one its
        validation made (:func:`~mechdyn.modelfile.loader.build_model`); the JSON-schema
        pass is skipped when :meth:`structure_known`.

        Raises
        ------
        ModelError
            The variant is not a valid model (a value out of range, its sketch cannot
            be assembled ...), naming the file, the table and the key.

        Examples
        --------
        >>> base = BaseModel("slider_crank")
        >>> model = base.compile({base.parameter("bodies.rod.mass"): 2.0})
        >>> model.mechanism.bodies["rod"].mass
        2.0
        """
        return build_model(self.document(values), self.name, default_title=self.title,
                           schema=not self.structure_known(values))
