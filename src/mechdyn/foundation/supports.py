"""The supports of a machine's base: anchor bolts, isolators, and the :class:`Foundation`.

They are part of the machine's description (``Mechanism.foundation``, the model file's
``[foundation]`` table), so they live in :mod:`mechdyn.mechanism.supports`, whose
docstring gives the plane, the signs and the stiffness of the base; this module
exports them to the analyses of :mod:`mechdyn.foundation`.
"""

from ..mechanism.supports import AnchorBolt, Foundation, Isolator, shift_moment, support_matrix

__all__ = ["AnchorBolt", "Isolator", "Foundation", "support_matrix", "shift_moment"]
