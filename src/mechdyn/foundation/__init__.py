"""The supports of a machine: the loads it sends into its frame, shared among anchor
bolts or isolators (rigid frame), and the frame on elastic mounts (natural frequencies,
transmissibility, the response to a frame-load history), and the machine on its isolators
coupled in one simulation (:func:`mounted`, :func:`compare_mounting`).
See ``docs/foundation.md``."""

from .coupled import MountingComparison, compare_mounting, floor_forces
from .frame_loads import FrameLoads, frame_loads
from .isolation import transmissibility
from .modes import ExcitationWarning, Modes, excitation_warnings, natural_frequencies
from .mounting import FloorFrameWarning, base_coordinates, mounted, static_equilibrium
from .response import MountedResponse, mounted_response
from .rigid import SupportLoads, bolt_forces, distribute, support_loads
from .supports import AnchorBolt, Foundation, Isolator, shift_moment, support_matrix

__all__ = ["AnchorBolt", "Isolator", "Foundation", "support_matrix", "shift_moment",
           "SupportLoads", "distribute", "bolt_forces", "support_loads", "FrameLoads",
           "frame_loads", "Modes", "natural_frequencies", "transmissibility",
           "MountedResponse", "mounted_response", "ExcitationWarning", "excitation_warnings",
           "mounted", "base_coordinates", "static_equilibrium", "FloorFrameWarning",
           "floor_forces", "MountingComparison", "compare_mounting"]
