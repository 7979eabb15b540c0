"""Elastic mounting: the frame and base as one rigid body on its supports, linear.

Coordinates u = (x, y, theta) of the base's centre of mass (small displacements from
the static position), with M = diag(m, m, J) and the stiffness K and damping C of the
supports about the centre of mass (:class:`~mechdyn.foundation.supports.Foundation`):

    M u'' + C u' + K u = f(t),

f = (Fx, Fy, M about the centre of mass) of the load on the base.  The force passed to
the floor is the supports' K u + C u' (the floor pushes back with the opposite).  For a
harmonic load f e^{i w t} the transmitted load is (K + i w C)(K - w^2 M + i w C)^-1 f:
its ratio to the load is the transmissibility (Den Hartog, *Mechanical Vibrations*,
ch. 3, for one degree of freedom).
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from .supports import Foundation, shift_moment

__all__ = ["transmissibility"]

_DIRECTIONS = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "theta": (0.0, 0.0, 1.0)}


def _load_vector(direction) -> np.ndarray:
    if isinstance(direction, str):
        if direction not in _DIRECTIONS:
            raise ModelError(f"transmissibility: unknown direction {direction!r}; use 'x', "
                             f"'y', 'theta' or a load vector (Fx, Fy, M)")
        return np.array(_DIRECTIONS[direction])
    e = np.asarray(direction, float)
    if e.shape != (3,) or not np.all(np.isfinite(e)) or not np.any(e):
        raise ModelError(f"transmissibility: a load vector is (Fx, Fy, M), finite and not "
                         f"zero, got {direction!r}")
    return e / np.linalg.norm(e)


def transmissibility(foundation: Foundation, omega, direction="y", point=None,
                     resultant: bool = False) -> np.ndarray:
    """Force transmitted to the floor per unit harmonic load on the base.

    Parameters
    ----------
    foundation : Foundation
        With ``mass`` and ``inertia``.
    omega : float or array_like, shape (n,)
        Angular frequencies of the load, rad/s.
    direction : {"x", "y", "theta"} or array_like, shape (3,)
        The load: a force along x or y at ``point``, a moment, or a load vector
        (Fx, Fy, M about ``point``), normalised to unit length.
    point : (float, float), optional
        Where the load acts (and the point of the moments), m; default the centre of mass.
    resultant : bool
        Return the whole transmitted load (Fx, Fy, M about ``point``) per unit load,
        shape (n, 3), instead of its component along ``direction``.

    Returns
    -------
    ndarray of complex, shape (n,) (or (n, 3), or scalar for a scalar ``omega``)
        The complex frequency response; ``abs`` of it is the transmissibility.

    Raises
    ------
    ModelError
        ``mass`` or ``inertia`` missing, a bad direction, a negative frequency.

    Examples
    --------
    Symmetric isolators, vertical load at the centre of mass: 1-DOF transmissibility
    sqrt(1 + (2 zeta r)^2) / sqrt((1 - r^2)^2 + (2 zeta r)^2):

    >>> from mechdyn.foundation import Foundation, Isolator
    >>> f = Foundation([Isolator("L", -0.5, 0.0, 1e5, 1e5, cy=400.0),
    ...                 Isolator("R", 0.5, 0.0, 1e5, 1e5, cy=400.0)], mass=200.0, inertia=25.0)
    >>> wn = np.sqrt(2e5 / 200.0); zeta = 800.0 / (2 * np.sqrt(2e5 * 200.0))
    >>> r = 2.0
    >>> closed = np.sqrt(1 + (2 * zeta * r)**2) / np.sqrt((1 - r**2)**2 + (2 * zeta * r)**2)
    >>> bool(abs(abs(transmissibility(f, r * wn, "y")) - closed) < 1e-12)
    True
    """
    w = np.asarray(omega, float)
    if np.any(~np.isfinite(w)) or np.any(w < 0):
        raise ModelError("transmissibility: omega must be finite and >= 0 rad/s")
    e = _load_vector(direction)
    com = foundation.com
    point = com if point is None else point
    Mm = foundation.mass_matrix()
    K, C = foundation.stiffness_matrix(com), foundation.damping_matrix(com)
    ww = np.atleast_1d(w)[:, None, None]
    support = K + 1j * ww * C  # (n, 3, 3)
    f = np.broadcast_to(shift_moment(e, point, com), (ww.shape[0], 3))
    u = np.linalg.solve(support - ww**2 * Mm, f[..., None])
    R = shift_moment((support @ u)[..., 0], com, point)
    out = R if resultant else R @ e
    return out[0] if w.ndim == 0 else out
