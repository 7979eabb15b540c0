"""mechdyn: kinematics, dynamics and kinetostatics of planar mechanisms.

The public names are re-exported here; see ``docs/`` for the notation, the
model-file format and tutorials.
"""

from . import examples, units
from ._version import __version__ as __version__
from .dynamics.kinetostatics import Kinetostatics, kinetostatics
from .dynamics.reduction import (
                                 FlywheelSizing,
                                 Reduction,
                                 SteadyCycle,
                                 reduce_model,
                                 run_reduced,
                                 size_flywheel,
                                 startup,
                                 steady_state,
)
from .errors import (
                                 AssemblyError,
                                 BranchJumpError,
                                 IntegrationError,
                                 LockupError,
                                 MechdynError,
                                 ModelError,
                                 SingularPositionError,
                                 Status,
                                 UnitError,
)
from .foundation import (
                                 AnchorBolt,
                                 Foundation,
                                 Isolator,
                                 mounted_response,
                                 natural_frequencies,
                                 support_loads,
                                 transmissibility,
)
from .kinematics.sweep import KinematicPoint, KinematicSweep, SweepSummary, analyze, sweep
from .mechanism import (
                                 Body,
                                 Coordinate,
                                 Drive,
                                 Force,
                                 Ground,
                                 Lock,
                                 Mechanism,
                                 Prismatic,
                                 Revolute,
                                 RotarySpring,
                                 Spring,
                                 Table,
                                 Torque,
                                 TorqueSpeedCurve,
                                 pulse,
)
from .mechanism.assembly_mode import AssemblyMode
from .mechanism.contact import Contact, Stop
from .mechanism.motors import ConstantSpeedDrive, DCMotor, GearStage, InductionMotor
from .mechanism.switch import CoordinateLock, Switch
from .model import Model
from .model.state import Mode, State
from .modelfile import load, loads
from .results.trajectory import Trajectory
from .simulate import simulate
from .simulate_events import SwitchEvent, format_events

__all__ = [
    # description
    "Mechanism", "Body", "Ground", "Revolute", "Prismatic", "Lock", "Coordinate", "Spring",
    "RotarySpring", "Force", "Torque", "Table", "pulse", "Drive", "TorqueSpeedCurve",
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
]
