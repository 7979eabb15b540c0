"""mechdyn: kinematics, dynamics and kinetostatics of planar mechanisms.

The public names are re-exported here; see ``docs/`` for the notation, the
model-file format and tutorials.  They are imported on first use (PEP 562), so
that ``import mechdyn`` stays fast: NumPy, SciPy, pandas, matplotlib, Numba and
pint are loaded only by the functions that need them.
"""

from __future__ import annotations

import importlib
import sys
import types

from ._version import __version__ as __version__

#: where each public name lives (a submodule relative to this package); ``None`` for a
#: name that is itself a submodule
_WHERE: dict[str, str | None] = {
    "examples": None, "units": None,
    "Kinetostatics": ".kinetostatics.inverse", "kinetostatics": ".kinetostatics.inverse",
    **dict.fromkeys(("FlywheelSizing", "Reduction", "SteadyCycle", "reduce_model",
                     "run_reduced", "size_flywheel", "startup", "steady_state"),
                    ".reduction.reduce"),
    **dict.fromkeys(("AssemblyError", "BranchJumpError", "IntegrationError", "LockupError",
                     "MechdynError", "ModelError", "SingularPositionError", "Status",
                     "UnitError"), ".errors"),
    **dict.fromkeys(("AnchorBolt", "Foundation", "Isolator", "mounted_response",
                     "natural_frequencies", "support_loads", "transmissibility"),
                    ".foundation"),
    **dict.fromkeys(("KinematicPoint", "KinematicSweep", "SweepSummary", "analyze", "sweep"),
                    ".kinematics.sweep"),
    **dict.fromkeys(("Body", "Bushing", "Coordinate", "Drive", "Force", "Ground", "Lock",
                     "Mechanism", "Prismatic", "Revolute", "RotarySpring", "Spring", "Table",
                     "Torque", "TorqueSpeedCurve", "pulse"), ".mechanism"),
    "AssemblyMode": ".mechanism.assembly_mode",
    "Contact": ".mechanism.contact", "Stop": ".mechanism.contact",
    **dict.fromkeys(("ConstantSpeedDrive", "DCMotor", "GearStage", "InductionMotor"),
                    ".mechanism.motors"),
    "CoordinateLock": ".mechanism.switch", "Switch": ".mechanism.switch",
    "Model": ".model", "Mode": ".model.state", "State": ".model.state",
    "load": ".modelfile", "loads": ".modelfile",
    "Trajectory": ".results.trajectory",
    "simulate": ".simulate.run",
    "SwitchEvent": ".simulate.segments", "format_events": ".simulate.segments",
    "warmup": ".compiler",
}

__all__ = [
    # description
    "Mechanism", "Body", "Ground", "Revolute", "Prismatic", "Lock", "Coordinate", "Spring",
    "Bushing", "RotarySpring", "Force", "Torque", "Table", "pulse", "Drive", "TorqueSpeedCurve",
    "InductionMotor", "DCMotor", "ConstantSpeedDrive", "GearStage", "Model", "Mode", "State",
    "AssemblyMode", "CoordinateLock", "Switch", "Stop", "Contact",
    "load", "loads", "examples", "units",
    # analyses and their records
    "sweep", "analyze", "KinematicSweep", "KinematicPoint", "SweepSummary",
    "simulate", "Trajectory", "SwitchEvent", "format_events",
    "kinetostatics", "Kinetostatics", "Status",
    "reduce_model", "Reduction", "run_reduced", "steady_state", "SteadyCycle", "size_flywheel",
    "FlywheelSizing", "startup",
    # supports: the loads a machine sends into its building
    "Foundation", "AnchorBolt", "Isolator", "support_loads", "transmissibility",
    "natural_frequencies", "mounted_response",
    # errors
    "MechdynError", "ModelError", "UnitError", "AssemblyError", "SingularPositionError",
    "BranchJumpError", "LockupError", "IntegrationError",
    # the compiled kernels ahead of time
    "warmup",
]


def __getattr__(name: str):
    """Import a public name on first use and keep it (PEP 562).

    Examples
    --------
    >>> import mechdyn
    >>> mechdyn.Mechanism.__name__
    'Mechanism'
    """
    try:
        where = _WHERE[name]
    except KeyError:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    if where is None:
        value = importlib.import_module(f".{name}", __name__)
    else:
        value = getattr(importlib.import_module(where, __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The module's names, the public ones not yet imported included."""
    return sorted(set(globals()) | set(__all__))


class _Package(types.ModuleType):
    """This package's module type: importing a submodule that shares its name with a
    public name of another kind (``mechdyn.simulate``, the module of the function) leaves
    the public name as it is, as the eager imports of the past did."""

    def __setattr__(self, name: str, value) -> None:
        if isinstance(value, types.ModuleType) and _WHERE.get(name) is not None:
            return  # the import system binding the submodule: the public name stays
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
