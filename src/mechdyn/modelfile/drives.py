"""Drives of a model file: a ``[[drives]]`` table with a ``type`` -> a :class:`Drive`.

:func:`drive_from_table` reads the table's quantities with their units
(:mod:`mechdyn.units`) and builds one of the motors of
:mod:`mechdyn.mechanism.motors` (an induction motor possibly named from the
catalogue :mod:`mechdyn.mechanism.catalogue`, a DC motor, a constant-speed drive
or a tabulated characteristic), wrapped in a
:class:`~mechdyn.mechanism.motors.GearStage` when a gear ratio is given.  The
loader (:mod:`mechdyn.modelfile.loader`) and ``mechdyn reduce --motor`` use it;
``docs/reduction-and-drives.md`` describes the keys.
"""

from __future__ import annotations

from collections.abc import Mapping

from ..errors import ModelError, did_you_mean
from ..mechanism.catalogue import induction_motor
from ..mechanism.drive import Drive
from ..mechanism.motors import (
    ConstantSpeedDrive,
    DCMotor,
    GearStage,
    InductionMotor,
    TabulatedMotor,
)
from ..units import parse_quantity, parse_vector

__all__ = ["drive_from_table", "DRIVE_TYPES"]

#: drive types of the model file and the keys each accepts (besides name, coordinate, type)
DRIVE_TYPES: dict[str, tuple[str, ...]] = {
    "induction_motor": ("catalogue", "rated_power", "synchronous_speed", "rated_speed",
                        "rated_slip", "breakdown_ratio", "starting_ratio", "rotor_inertia",
                        "characteristic", "source"),
    "dc_motor": ("no_load_speed", "stall_torque", "rated_power", "rated_speed",
                 "rotor_inertia", "source"),
    "constant_speed": ("speed", "stiffness"),
    "torque_speed": ("omega", "torque", "rotor_inertia", "extrapolate", "source"),
}
_GEAR_KEYS = ("gear_ratio", "efficiency", "gear_input_inertia", "gear_output_inertia")
_COMMON_KEYS = ("name", "coordinate", "type", "description")


#: the quantity kind of each key that holds one quantity
_KINDS = {"rated_power": "power", "synchronous_speed": "angular_velocity",
          "rated_speed": "angular_velocity", "rated_slip": "ratio", "breakdown_ratio": "ratio",
          "starting_ratio": "ratio", "rotor_inertia": "inertia",
          "no_load_speed": "angular_velocity", "stall_torque": "torque",
          "speed": "angular_velocity", "stiffness": "rotational_damping", "gear_ratio": "ratio",
          "efficiency": "ratio", "gear_input_inertia": "inertia", "gear_output_inertia": "inertia"}


def drive_from_table(table: Mapping, where: str = "drives") -> Drive:
    """Build a :class:`Drive` from a model-file ``[[drives]]`` table with a ``type``.

    Parameters
    ----------
    table : mapping
        The TOML table, values as written (quantities as strings with units,
        e.g. ``"1.5 kW"``, ``"1500 rpm"``; bare numbers are SI).
    where : str
        Location for messages, e.g. ``"press.toml: drives[0]"``.

    Returns
    -------
    Drive
        Its ``torque`` is the motor, wrapped in a :class:`GearStage` when
        ``gear_ratio`` is given.

    Raises
    ------
    ModelError
        Naming the key at fault; unknown keys and types list the valid ones.

    Examples
    --------
    The source paper's press drive (motor 4A80B4U3 through a 3.4 : 1 stage)::

        [[drives]]
        name = "motor"
        coordinate = "phi"
        type = "induction_motor"
        catalogue = "4A80B4U3"
        characteristic = "extended"
        gear_ratio = 3.4
        efficiency = 0.95
    """
    try:
        return _drive(dict(table))
    except ModelError as exc:  # UnitError stays a UnitError
        raise type(exc)([f"{where}: {p}" for p in exc.problems]) from None


def _drive(t: dict) -> Drive:
    """:func:`drive_from_table` without the location in the messages."""
    kind = t.get("type")
    if kind not in DRIVE_TYPES:
        raise ModelError("type: " + did_you_mean(str(kind), DRIVE_TYPES, "drive type"))
    name = str(t.get("name", kind))
    problems = []
    if "coordinate" not in t:
        problems.append("coordinate: missing (the driven generalized coordinate)")
    allowed = set(_COMMON_KEYS) | set(DRIVE_TYPES[kind]) | set(_GEAR_KEYS)
    for key in t:
        if key not in allowed:
            problems.append(did_you_mean(key, sorted(allowed), f"key of a {kind!r} drive"))
    if problems:
        raise ModelError(problems)

    q = {k: parse_quantity(v, _KINDS[k], where=k) for k, v in t.items() if k in _KINDS}
    source = str(t.get("source", ""))
    if kind == "induction_motor":
        motor = _induction_from_table(t, q, name)
    elif kind == "dc_motor":
        if "no_load_speed" not in q:
            raise ModelError("no_load_speed: missing (rad/s, e.g. \"3000 rpm\")")
        jr = q.get("rotor_inertia", 0.0)
        if "stall_torque" in q:
            motor = DCMotor(name, q["no_load_speed"], q["stall_torque"], jr, source)
        elif "rated_power" in q and "rated_speed" in q:
            motor = DCMotor.from_rated(name, q["rated_power"], q["rated_speed"],
                                       q["no_load_speed"], jr, source)
        else:
            raise ModelError("give stall_torque, or rated_power and rated_speed")
    elif kind == "constant_speed":
        if "speed" not in q:
            raise ModelError("speed: missing (e.g. \"43.5 rad/s\")")
        motor = ConstantSpeedDrive(name, q["speed"], q.get("stiffness"))
    else:
        om, tq = t.get("omega"), t.get("torque")
        if not isinstance(om, list) or not isinstance(tq, list):
            raise ModelError("omega and torque must be lists of quantities")
        motor = TabulatedMotor(name, parse_vector(om, "angular_velocity", "omega", size=len(om)),
                               parse_vector(tq, "torque", "torque", size=len(tq)),
                               q.get("rotor_inertia", 0.0), bool(t.get("extrapolate", True)),
                               source)
    if not any(k in t for k in _GEAR_KEYS):
        return Drive(name, str(t["coordinate"]), motor)
    if "gear_ratio" not in t:
        raise ModelError("gear_ratio: missing (the efficiency and gear inertias need a gear "
                         "ratio omega_motor/omega_driven)")
    return Drive(name, str(t["coordinate"]), GearStage(
        motor, q["gear_ratio"], q.get("efficiency", 1.0), q.get("gear_input_inertia", 0.0),
        q.get("gear_output_inertia", 0.0), name=f"{name} gear"))


def _induction_from_table(t, q, name) -> InductionMotor:
    data = {k: v for k, v in q.items() if k in DRIVE_TYPES["induction_motor"]}
    data["characteristic"] = str(t.get("characteristic", "kloss"))
    data.update((k, str(t[k])) for k in ("name", "source") if t.get(k))
    if "catalogue" in t:
        return induction_motor(str(t["catalogue"]), **data)
    missing = [k for k in ("rated_power", "synchronous_speed", "breakdown_ratio") if k not in data]
    if "rated_speed" not in data and "rated_slip" not in data:
        missing.append("rated_speed (or rated_slip)")
    if missing:
        raise ModelError(f"missing {', '.join(missing)} (or name a motor with "
                         f"catalogue = \"4A80B4U3\")")
    return InductionMotor(**{"name": name, **data})
