"""Physical quantities at the edge of mechdyn: text such as ``"15 mm"`` to SI floats.

pint is used here (and in ``modelfile/`` and the command line) only; everything
inside mechdyn works with plain floats and arrays in SI units.

Rules
-----
* A string with a unit is converted to the SI unit of the expected *kind*
  (``"15 mm"`` as a length gives ``0.015``; ``"-64.1 deg"`` as an angle gives
  ``-1.11876...``).  A unit of the wrong dimension raises :class:`UnitError`
  naming where the value came from, the value, the expected dimension and an
  example.
* A pint ``Quantity`` (of any registry) is converted the same way, by its unit.
* A bare number (``0.015``, or a string without a unit such as ``"0.015"``) is
  taken as already being in SI units.  **This includes angles and angular
  speeds**: a bare ``1.2`` for an angle means 1.2 rad, not 1.2 deg, and a bare
  ``43.5`` for an angular velocity means 43.5 rad/s.  Write ``"1.2 deg"`` or
  ``"100 rpm"`` to use other units.
* Angles are dimensionless to pint, so ``"10 Hz"`` would silently become
  ``10 rad/s``.  To prevent this, angle-like kinds (``angle``,
  ``angular_velocity``, ``angular_acceleration``) demand an angle unit
  (``rad``, ``deg``, ``turn``, ``rpm``, ...) whenever a unit is given, and the
  non-angular kinds refuse angle units.  ``frequency`` accepts both ``"50 Hz"``
  and ``"3000 rpm"`` (= 50 Hz).
* ``"%"`` (or ``percent``) is accepted for ``dimensionless``/``ratio``.
* A model file is data, not code: a value is ONE number followed by a unit
  (``"15 mm"``, ``"0.034 kg*m^2"``, ``"4.53 N/mm"``, ``"1e-3 s"``); the unit may
  use ``*``, ``/``, ``^`` (or ``**``) with integer powers, nothing else.
  Arithmetic (``"2*3 mm"``, ``"2**2**2 mm"``), a second number (``"250.5.5 mm"``),
  quotes and brackets are refused with a :class:`UnitError`, and so are values
  longer than :data:`MAX_TEXT` characters and numbers beyond the float range.
  Text is Unicode-normalised (NFKC) first, so the compatibility character
  ``"㎜"`` reads as ``"mm"``.

Examples
--------
>>> parse_quantity("15 mm", "length", where="demo")
0.015
>>> round(parse_quantity("100 rpm", "angular_velocity", where="demo"), 6)
10.471976
>>> parse_quantity("1.5 kW", "power", where="demo")
1500.0
"""

from __future__ import annotations

import math
import re
import unicodedata
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

from .errors import UnitError

__all__ = ["KINDS", "Kind", "parse_quantity", "parse_vector", "format_quantity", "registry",
           "is_quantity", "MAX_TEXT"]

#: the longest quantity text accepted, characters
MAX_TEXT = 100
#: one number, then optionally a unit: names (letters, µ, °, %) joined by *, / and
#: integer powers (^ or **)
_NUMBER = r"[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|nan|inf)"
_NAME = r"(?:[^\W\d_]+|%|°)(?:\s*(?:\^|\*\*)\s*[+-]?\d+)?"
_QUANTITY_RE = re.compile(rf"^(?P<num>{_NUMBER})\s*(?P<unit>{_NAME}(?:\s*[*/]?\s*{_NAME})*)?$")


@dataclass(frozen=True)
class Kind:
    """A kind of quantity: its SI unit, a human name and an example."""

    si: str
    name: str
    example: str
    #: power of radian the unit must carry: 1 for angle-like kinds, 0 for the others;
    #: ``None``: any power of radian is accepted (rotational stiffness "N*m" or "N*m/rad")
    angle_power: int | None = 0


#: every kind of quantity the model file and the command line understand
KINDS: dict[str, Kind] = {
    "length": Kind("m", "length (m)", '"15 mm"'),
    "angle": Kind("rad", "angle (rad)", '"-64.1 deg"', 1),
    "mass": Kind("kg", "mass (kg)", '"4.6 kg"'),
    "inertia": Kind("kg*m^2", "moment of inertia (kg*m^2)", '"0.034 kg*m^2"'),
    "angular_velocity": Kind("rad/s", "angular velocity (rad/s)", '"43.5 rad/s" or "100 rpm"', 1),
    "angular_acceleration": Kind("rad/s^2", "angular acceleration (rad/s^2)", '"10 rad/s^2"', 1),
    "velocity": Kind("m/s", "velocity (m/s)", '"0.5 m/s"'),
    "acceleration": Kind("m/s^2", "acceleration (m/s^2)", '"-9.81 m/s^2"'),
    "force": Kind("N", "force (N)", '"250 N" or "1.2 kN"'),
    "torque": Kind("N*m", "torque (N*m)", '"0.033 N*m"'),
    "stiffness": Kind("N/m", "stiffness (N/m)", '"4530 N/m" or "4.53 N/mm"'),
    "damping": Kind("N*s/m", "damping coefficient (N*s/m)", '"20 N*s/m"'),
    "compliance": Kind("m/N", "compliance (m/N)", '"2e-9 m/N" or "2 um/kN"'),
    "bending_stiffness": Kind("N*m^2", "bending stiffness (N*m^2)",
                              '"2e6 N*m^2" or "2 MN*m^2"'),
    "rotational_stiffness": Kind("N*m/rad", "rotational stiffness (N*m/rad)", '"12 N*m/rad"',
                                 None),
    "rotational_damping": Kind("N*m*s/rad", "rotational damping (N*m*s/rad)",
                               '"0.05 N*m*s/rad"', None),
    "time": Kind("s", "time (s)", '"0.05 s" or "20 ms"'),
    "power": Kind("W", "power (W)", '"1.5 kW"'),
    "energy": Kind("J", "energy (J)", '"12 J"'),
    "dimensionless": Kind("", "dimensionless number", '"0.3" or "30 %"'),
    "frequency": Kind("Hz", "frequency (Hz)", '"50 Hz" or "3000 rpm"', None),
}
KINDS["ratio"] = KINDS["dimensionless"]

@lru_cache(maxsize=1)
def registry():
    """The one shared pint ``UnitRegistry`` of mechdyn (built on first use: it is slow)."""
    import pint

    ureg = pint.UnitRegistry()
    ureg.define("rev = turn")
    return ureg


def _kind(kind: str) -> Kind:
    try:
        return KINDS[kind]
    except KeyError:
        raise ValueError(f"unknown quantity kind {kind!r}; valid kinds: "
                         + ", ".join(sorted(KINDS))) from None


def _problem(where: str, value: Any, kind: Kind, why: str) -> UnitError:
    shown = f"{value!r}" if isinstance(value, str) else f"{value}"
    prefix = f"{where}: " if where else ""
    article = "an" if kind.name[0] in "aeiou" else "a"
    return UnitError(f"{prefix}{shown}: {why}; expected {article} {kind.name}, "
                     f"e.g. {kind.example}")


def parse_quantity(value: Any, kind: str, *, where: str = "") -> float:
    """Convert a quantity to a float in the SI unit of ``kind``.

    Parameters
    ----------
    value : str or float or int or pint.Quantity
        ``"15 mm"``, ``"-64.1 deg"``, ``"0.034 kg*m^2"``, ``"100 rpm"``, ``"1.5 kW"``,
        ``"30 %"``, a scalar pint quantity, or a bare number, which is taken as SI
        (angles: rad; angular speeds: rad/s).
    kind : str
        One of :data:`KINDS` (``"length"``, ``"angle"``, ``"mass"``, ...).
    where : str
        Where the value came from, for the error message (e.g.
        ``"press.toml: [bodies.rod] mass"``).

    Returns
    -------
    float
        The value in the SI unit of the kind (``KINDS[kind].si``).

    Raises
    ------
    UnitError
        The text cannot be parsed, the unit has the wrong dimension, or the value
        is not finite.
    """
    k = _kind(kind)
    if is_quantity(value):
        return _from_quantity(value, kind, where)
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise _problem(where, value, k, f"not a number or a quantity string "
                       f"(got {type(value).__name__})")
    if isinstance(value, (int, float)):
        try:
            out = float(value)
        except OverflowError:
            raise _problem(where, f"{str(value)[:20]}... ({len(str(value))} digits)", k,
                           "too large a number") from None
        if not math.isfinite(out):
            raise _problem(where, value, k, "not a finite number")
        return out
    text = unicodedata.normalize("NFKC", value).strip()
    if not text:
        raise _problem(where, value, k, "empty text")
    if len(text) > MAX_TEXT:
        raise _problem(where, value[:40] + "...", k, f"longer than {MAX_TEXT} characters")
    if any(c in text for c in ",;()[]{}"):
        raise _problem(where, value, k, "one quantity expected (no commas or brackets)")
    m = _QUANTITY_RE.match(text)
    if m is None:
        why = ("expected one number followed by a unit (arithmetic, a second number and "
               "quotes are not read)")
        if re.fullmatch(r"[^\W\d_]+", text):
            import pint

            ureg = registry()
            try:
                ureg.parse_units(text)
                why = "a unit without a number"
            except pint.errors.UndefinedUnitError:
                why = f"unknown unit ({text!r})"
        raise _problem(where, value, k, f"cannot be read as a quantity: {why}")
    # a bare number in a string is SI
    factor, why = _unit_factor(m["unit"], kind) if m["unit"] else (1.0, "")
    if why:
        raise _problem(where, value, k, why)
    out = float(m["num"]) * factor
    if not math.isfinite(out):
        raise _problem(where, value, k, "not a finite value")
    return out


def is_quantity(value: Any) -> bool:
    """Whether ``value`` is a pint ``Quantity`` (of any registry; pint is not imported).

    Examples
    --------
    >>> is_quantity(registry().Quantity(60.0, "rpm")), is_quantity("60 rpm"), is_quantity(1.0)
    (True, False, False)
    """
    return hasattr(value, "magnitude") and hasattr(value, "units") and hasattr(value, "to")


def _from_quantity(value: Any, kind: str, where: str) -> float:
    """A scalar pint quantity in the SI unit of ``kind`` (the checks of a unit text)."""
    k = KINDS[kind]
    try:
        mag = float(value.magnitude)
    except (TypeError, ValueError):
        raise _problem(where, value, k, "one quantity expected (its magnitude is not a "
                       "number)") from None
    factor, why = _unit_factor(str(value.units), kind)
    if why:
        raise _problem(where, value, k, why)
    out = mag * factor
    if not math.isfinite(out):
        raise _problem(where, value, k, "not a finite value")
    return out


@lru_cache(maxsize=1024)
def _unit_factor(unit: str, kind: str) -> tuple[float, str]:
    """(SI factor, "") of a unit text for a kind, or (nan, why it does not fit): the
    conversions are linear, so each unit is read by pint once."""
    import pint

    ureg, k = registry(), KINDS[kind]
    try:
        q = ureg.Quantity(1.0, ureg.parse_units(unit))
    except Exception as exc:  # noqa: BLE001 - pint's parser raises many kinds; report them all
        why = str(exc).strip() or "malformed unit"
        if isinstance(exc, pint.errors.UndefinedUnitError):
            why = f"unknown unit ({why})"
        return math.nan, f"cannot be read as a quantity: {why}"
    shown = f"{q.units:~}" if q._units else unit  # units that cancel: the text
    root = q.to_root_units()
    rad_power = dict(root._units).get("radian", 0)
    target = ureg.Unit(k.si) if k.si else ureg.dimensionless
    dim = root.dimensionality
    if dim != target.dimensionality:  # named after the kind of that dimension if there is one
        what = next((f"{c.name.split(' (')[0]} unit" for c in KINDS.values()
                     if c.si and c.angle_power != 1 and ureg.Unit(c.si).dimensionality == dim),
                    f"unit of dimension {dim}")
        return math.nan, f"the unit {shown} is a {what}"
    if k.angle_power == 1 and rad_power != 1:
        return math.nan, (f"the unit {shown} has no angle unit (use rad, deg, turn or rpm; "
                          "a frequency in Hz is not an angular velocity)")
    if k.angle_power == 0 and rad_power != 0:
        return math.nan, f"the unit {shown} carries an angle unit"
    if kind == "frequency" and rad_power == 1:
        return float(root.magnitude) / (2.0 * math.pi), ""
    if kind == "frequency" and rad_power not in (0, 1):
        return math.nan, f"the unit {shown} is not a frequency"
    return (float(q.to(target).magnitude) if k.si else float(q.to("").magnitude)), ""



_VECTOR_RE = re.compile(r"^\s*\((?P<body>[^()]*)\)\s*(?P<unit>.*?)\s*$")


def parse_vector(value: Any, kind: str | Sequence[str], where: str = "",
                 *, size: int | None = None) -> tuple[float, ...]:
    """Convert a vector of quantities to a tuple of SI floats.

    Parameters
    ----------
    value : sequence or str
        A list such as ``["10 mm", "0 mm"]`` or ``[0.01, 0]``, or one string
        ``"(10, 0) mm"`` (one unit for all components) or ``"(10 mm, 0 mm, 30 deg)"``.
    kind : str or sequence of str
        The kind of every component, or one kind per component (e.g.
        ``("length", "length", "angle")`` for a pose).
    where : str
        Where the value came from, for the error message.
    size : int, optional
        Number of components; default ``len(kind)`` for a sequence of kinds, else 2.

    Returns
    -------
    tuple of float, length ``size``

    Raises
    ------
    UnitError
        Wrong number of components, or any component as in :func:`parse_quantity`.
    """
    kinds = [kind] * (size or 2) if isinstance(kind, str) else list(kind)
    n = size or len(kinds)
    names = ", ".join(dict.fromkeys(KINDS[k].name for k in kinds))
    example = "[" + ", ".join(KINDS[k].example.split(" or ")[0] for k in kinds) + "]"
    prefix = f"{where}: " if where else ""
    if isinstance(value, str):
        m = _VECTOR_RE.match(value)
        if m is None:
            raise UnitError(f"{prefix}{value!r}: cannot be read as a vector; write {example} "
                            f"or \"(x, y) unit\" ({names})")
        parts = [p.strip() for p in m.group("body").split(",")]
        unit = m.group("unit")
        items: list[Any] = [f"{p} {unit}".strip() for p in parts]
    elif isinstance(value, (list, tuple)):
        items = list(value)
    else:
        raise UnitError(f"{prefix}{value!r}: expected a list of {n} components, e.g. {example} "
                        f"({names})")
    if len(items) != n:
        raise UnitError(f"{prefix}{value!r}: expected {n} components, got {len(items)}; "
                        f"e.g. {example}")
    return tuple(parse_quantity(v, k, where=f"{where}[{i}]" if where else f"[{i}]")
                 for i, (v, k) in enumerate(zip(items, kinds, strict=True)))


def format_quantity(value: float, kind: str, unit: str | None = None, *,
                    digits: int = 6) -> str:
    """Format an SI value for display, e.g. ``format_quantity(0.015, "length", "mm")``
    gives ``"15 mm"``.

    Parameters
    ----------
    value : float
        The value in the SI unit of ``kind``.
    kind : str
        One of :data:`KINDS`.
    unit : str, optional
        Display unit (``"mm"``, ``"deg"``, ``"rpm"``, ``"kN"``, ...); default the SI unit.
    digits : int
        Significant digits.

    Returns
    -------
    str
    """
    k = _kind(kind)
    if unit is None or unit == k.si:
        return f"{value:.{digits}g} {k.si}".rstrip()
    factor, why = _unit_factor(unit, kind)  # the unit -> SI factor parse_quantity uses
    if why:
        raise UnitError(f"cannot show a {k.name} in {unit!r}: {why}")
    return f"{float(value) / factor:.{digits}g} {unit}"
