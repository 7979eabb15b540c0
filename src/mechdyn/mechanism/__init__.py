"""Mechanism description: frozen elements in SI units, no time, no solver."""

from .assembly_mode import AssemblyMode
from .body import GROUND, Body, Ground
from .coordinate import COORDINATE_KINDS, Coordinate
from .drive import Drive, TorqueSpeedCurve
from .joint import Joint, Lock, Prismatic, Revolute
from .load import Bushing, Force, RotarySpring, Spring, Table, Torque, pulse
from .mechanism import Mechanism
from .supports import AnchorBolt, Foundation, Isolator

__all__ = ["AssemblyMode", "GROUND", "Body", "Ground", "Coordinate", "COORDINATE_KINDS", "Joint",
           "Revolute", "Prismatic", "Lock", "Mechanism", "Drive", "TorqueSpeedCurve", "Force",
           "Bushing",
           "RotarySpring", "Spring", "Table", "Torque", "pulse", "AnchorBolt", "Isolator",
           "Foundation"]
