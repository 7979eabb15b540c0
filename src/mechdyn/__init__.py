"""mechdyn: kinematics, dynamics and kinetostatics of planar mechanisms."""

from .errors import (AssemblyError, BranchJumpError, IntegrationError, LockupError, MechdynError,
                     ModelError, SingularPositionError, UnitError)
from .mechanism import Body, Coordinate, Ground, Lock, Mechanism, Prismatic, Revolute
from .model import Model
from .state import State

__version__ = "0.1.0"

__all__ = ["AssemblyError", "BranchJumpError", "IntegrationError", "LockupError",
           "MechdynError", "ModelError", "SingularPositionError", "UnitError", "Body",
           "Coordinate", "Ground", "Lock", "Mechanism", "Prismatic", "Revolute", "Model", "State"]
