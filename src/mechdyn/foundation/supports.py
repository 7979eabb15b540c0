"""The supports of a machine's base: anchor bolts, isolators, and the :class:`Foundation`.

They are part of the machine's description (``Mechanism.foundation``, the model file's
``[foundation]`` table), so they live in :mod:`mechdyn.mechanism.supports`, whose
docstring gives the plane, the signs and the stiffness of the base; this module
exports them to the analyses of :mod:`mechdyn.foundation`, with :func:`shift_moment`,
the loads on the base with their moment taken about another point.
"""

import numpy as np

from ..kernels.planar import cross
from ..mechanism.supports import AnchorBolt, Foundation, Isolator, support_matrix

__all__ = ["AnchorBolt", "Isolator", "Foundation", "support_matrix", "shift_moment"]


def shift_moment(F, point, to) -> np.ndarray:
    """Loads (Fx, Fy, M about ``point``) with the moment taken about ``to``: M + (point -
    to) x (Fx, Fy) (:func:`mechdyn.kernels.planar.cross`).

    Parameters
    ----------
    F : array_like, shape (..., 3)
        Forces (N) and moments about ``point`` (N m); real, or complex amplitudes.
    point, to : array_like, shape (2,)
        The point the moments are about and the one they are to be about, m.

    Returns
    -------
    ndarray, shape (..., 3)
        Of the type of ``F`` (complex stays complex).

    Examples
    --------
    >>> shift_moment([0.0, 10.0, 0.0], (1.0, 0.0), (0.0, 0.0)).tolist()
    [0.0, 10.0, 10.0]
    """
    out = np.array(F, dtype=np.result_type(np.asarray(F), float))  # complex stays complex
    d = np.asarray(point, float) - np.asarray(to, float)
    out[..., 2] += cross(d, out[..., :2])
    return out
