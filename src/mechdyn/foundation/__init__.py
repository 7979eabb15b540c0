"""The supports of a machine: the loads it sends into its frame, shared among anchor
bolts or isolators (rigid frame), and the frame on elastic mounts (natural frequencies,
transmissibility, the response to a frame-load history).  See ``docs/foundation.md``."""

from .frame_loads import FrameLoads, frame_loads
from .isolation import (
    ExcitationWarning,
    Modes,
    MountedResponse,
    excitation_warnings,
    mounted_response,
    natural_frequencies,
    transmissibility,
)
from .rigid import SupportLoads, bolt_forces, distribute, support_loads
from .supports import AnchorBolt, Foundation, Isolator, support_matrix

__all__ = ["AnchorBolt", "Isolator", "Foundation", "support_matrix", "SupportLoads",
           "distribute", "bolt_forces", "support_loads", "FrameLoads", "frame_loads",
           "Modes", "natural_frequencies", "transmissibility", "MountedResponse",
           "mounted_response", "ExcitationWarning", "excitation_warnings"]
